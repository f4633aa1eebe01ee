"""The report of issue 12's figures (bench/run.py's markdown): the wire codecs against the object pipeline
(bench/codec.py), the bridge on its wire path and on its object path (bench/bridge.py, bench/bridge_dronecan.py)."""

from __future__ import annotations

import math
from typing import Any

from bench.report_fmt import num, ok, spread, table

TARGET_CYPHAL = 1.0  # the bridge (wire path) >= 1.0x raw pycyphal, both directions, UDP and CAN FD
TARGET_DRONECAN = 3.0  # the DroneCAN bridge (wire path) >= 3x raw dronecan, both directions
DIRECTIONS = (("u2r", "UAVCAN->ROS"), ("r2u", "ROS->UAVCAN"))
THREADS = ("main (asyncio loop)", "bridge rclpy thread", "other threads", "ROS process")


def path_name(wire: str | None) -> str:
    """What the report calls a bridge's path.

    >>> path_name("codec"), path_name("object")
    ('wire path (codecs)', 'object path')
    """
    return "wire path (codecs)" if wire == "codec" else f"{wire or '?'} path"


def blocks(b: dict[str, Any]) -> list[tuple[str, dict[str, Any]]]:
    """The measured blocks of one transport: (its path's name, {throughput, latency}), the default path first."""
    out = [(path_name(b.get("wire", "object")), b)]
    if b.get("object"):
        out.append(("object path", b["object"]))
    return out


# ----------------------------------------------------------------------------------------------- summary rows
def bridge_rows(b: dict[str, Any], raw: str, target: float, what: tuple[str, str] = ("", "")) -> list[list[str]]:
    """Summary rows of one transport: the bridge on its wire path (the target's) and on the object path."""
    rows: list[list[str]] = []
    ob = (b.get("object") or {}).get("throughput")
    cvo = b.get("codec_vs_object") or {}
    tp = b["throughput"]
    for i, (d, label) in enumerate(DIRECTIONS):
        rows.append([f"Bridge {label}{what[i]}, {b['transport']}, {path_name(b.get('wire', 'object'))}",
                     f"{num(tp[f'{d}_bridge']['msg_per_s'])} msg/s", f"{raw} {num(tp[f'{d}_raw']['msg_per_s'])} msg/s",
                     f"{tp[f'{d}_ratio']:.2f}x" + spread(tp.get(f"{d}_ratio_runs")), f">= {target:g}x",
                     ok(round(tp[f"{d}_ratio"], 2) >= target) if b.get("wire") == "codec" else "-"])
        if ob:
            rows.append([f"Bridge {label}{what[i]}, {b['transport']}, object path",
                         f"{num(ob[f'{d}_bridge']['msg_per_s'])} msg/s",
                         f"{raw} {num(ob[f'{d}_raw']['msg_per_s'])} msg/s",
                         f"{ob[f'{d}_ratio']:.2f}x" + spread(ob.get(f"{d}_ratio_runs"))
                         + (f"; wire path {cvo[d]:.2f}x it" if d in cvo else ""), "-", "-"])
    return rows


REFERENCE = {"cyphal": "pycyphal (de)serialize + converter + rclpy (de)serialize",
             "dronecan": "dronecan (de)serialize + converter + rclpy (de)serialize"}


def codec_rows(c: dict[str, Any] | None) -> list[list[str]]:
    """Summary rows of the codec part: per protocol, the codecs against the object pipeline."""
    if not c:
        return []
    rows: list[list[str]] = []
    for proto, label in (("cyphal", "Cyphal"), ("dronecan", "DroneCAN")):
        s = c["summary"].get(f"{proto} all")
        if not s:
            continue
        t = c["target"]
        missing = f", {s['missing']} mapping(s) without a codec" if s["missing"] else ""
        rows.append([f"Wire codecs vs object pipeline, {label} ({s['codecs']} = {s['codecs'] // 2} mappings x 2 "
                     f"directions; {s['agree']}/{s['codecs']} give the same values{missing})",
                     f"geomean {s['geomean']:.2f}x, min {s['min']:.2f}x", REFERENCE[proto],
                     f"{s['meet_target']}/{s['codecs']} at >= {t:g}x", f">= {t:g}x",
                     ok(s["meet_target"] == s["codecs"] and s["agree"] == s["codecs"] and not s["missing"])])
    return rows + namespaced_rows(c.get("namespaced"))


def namespaced_rows(n: dict[str, Any] | None) -> list[list[str]]:
    """Summary rows of the codecs bound to a frame prefix (a namespaced run, issue 26) against the object pipeline
    with the prefix: conversions per second, UAVCAN->ROS mappings with a header."""
    if not n:
        return []
    return [[f"Wire codecs with frame prefix {n['prefix']!r} (namespaced run) vs object pipeline with it, {label} "
             f"UAVCAN->ROS ({s['mappings']} mappings with a header; {s['agree']}/{s['mappings']} give the same values)",
             f"{num(s['per_s']['codec'])} conversions/s (geomean; no prefix {num(s['per_s']['codec_no_prefix'])})",
             f"{num(s['per_s']['object'])} conversions/s", f"geomean {s['geomean']:.2f}x, min {s['min']:.2f}x",
             "codec path", ok(s["agree"] == s["mappings"])]
            for proto, label in (("cyphal", "Cyphal"), ("dronecan", "DroneCAN")) if (s := n["summary"].get(proto))]


# ----------------------------------------------------------------------------------------------- sections
def _counted(r: dict[str, Any]) -> str:
    """What the spec's rules did to the sample on this direction (the timed path), '' when nothing."""
    sc = r.get("sample_counters") or {}
    return ", ".join([f"saturates {k}" for k in sc.get("saturated", {})] + [f"rejects ({k})" for k in
                                                                          sc.get("rejected", {})])


def codec_markdown(c: dict[str, Any], section: str) -> list[str]:
    """The section of the codec part."""
    meth = c["method"]
    lines = ["", f"## {section}. Wire codecs", "",
             "Each generated wire codec (generated/python/sam_bridge/codec.py for Cyphal, codec_v0.py for DroneCAN) "
             "against the object pipeline it replaces in the bridge, per mapping, both directions. UAVCAN->ROS: "
             "`<m>_wire_to_ros(payload)` against the protocol library's deserializer (`pycyphal.dsdl.deserialize`; "
             "dronecan's `_unpack` of the payload bits, as `Transfer.from_frames` does on classic CAN) + the "
             "generated `<m>_to_ros` + `rclpy.serialization.serialize_message`. ROS->UAVCAN: `<m>_ros_to_wire(cdr)` "
             "against `deserialize_message` + `<m>_to_uavcan` + the library's serializer. Inputs: the simulator's "
             "values of the mapping's type as received (bench/codec.py); the ROS->UAVCAN input is the CDR of the "
             "object path's message of it. Checked first: the codec's CDR deserialized by rclpy and its payload "
             "decoded by the library give the values the object pipeline gives, with the same stamp and counters "
             "(`agree`); `bytes`: the very same bytes (`yes`), or the same but for CDR alignment padding, which the "
             "codec writes as zeros and rclpy's serializer leaves as its buffer held it (`padding`). Best ns per "
             "message of "
             f"{meth['rounds']} interleaved rounds (GC paused; medians in results.json). `bridge` = the direction "
             "the bridge runs for that mapping."
             + (f" This part was re-run alone at {c['rerun']['date']} (load average {c['rerun']['loadavg']}) after the "
                "session, to record the padding-only CDR differences." if c.get("rerun") else ""), ""]
    for proto, label in (("cyphal", "Cyphal"), ("dronecan", "DroneCAN")):
        rows = [r for r in c["rows"] if r["protocol"] == proto]
        if not rows:
            continue
        body = []
        for r in rows:
            if r.get("missing"):
                body.append([r["mapping"], "-", "", "-", "-", "no codec", "-", "-", ""])
                continue
            body.append([r["mapping"], r["direction"], "yes" if r["bridge_runs_it"] else "",
                         num(r["ns_per_msg"]["codec"], 0), num(r["ns_per_msg"]["object"], 0), f"{r['ratio']:.2f}",
                         "yes" if r["agree"] else "**no**: " + "; ".join(r["problems"]),
                         {True: "yes", False: "no", None: "-", "padding": "padding"}[r["bytes_identical"]],
                         _counted(r)])
        lines += [f"{label}:", "", table(["mapping", "direction", "bridge", "codec ns/msg", "object ns/msg",
                                          "object / codec", "agree", "bytes", "the sample on this path"], body), ""]
    s = c["summary"]
    lines.append(table(["codecs", "n", "geomean object / codec", "min", "max", f">= {c['target']:g}x", "agree"],
                       [[k, str(v["codecs"]), f"{v['geomean']:.2f}", f"{v['min']:.2f}", f"{v['max']:.2f}",
                         f"{v['meet_target']}/{v['codecs']}", f"{v['agree']}/{v['codecs']}"] for k, v in s.items()]))
    n = c.get("namespaced")
    if n and n["rows"]:
        lines += ["", f"A namespaced run (frame prefix {n['prefix']!r}, issue 26) stays on the codec path: the codec "
                  "module bound to the prefix at start, against the object pipeline with the prefix (its frame id "
                  "prefixed after `<m>_to_ros`, the path such a run took before) and the codec without a prefix; "
                  "UAVCAN->ROS mappings with a header, conversions per second (best round).", "",
                  table(["protocol", "mapping", "codec with prefix /s", "object with prefix /s", "codec no prefix /s",
                         "object / codec", "agree"],
                        [[r["protocol"], r["mapping"], num(r["per_s"]["codec"]), num(r["per_s"]["object"]),
                          num(r["per_s"]["codec_no_prefix"]), f"{r['ratio']:.2f}", "yes" if r["agree"] else "**no**"]
                         for r in n["rows"]])]
    return lines


def transport_rows(b: dict[str, Any]) -> list[list[str]]:
    """The detailed table's rows of one transport: both directions on each measured path."""
    rows = []
    for name, blk in blocks(b):
        tp, lat = blk["throughput"], blk["latency"]
        for d, label in DIRECTIONS:
            br, raw = tp[f"{d}_bridge"], tp[f"{d}_raw"]
            lb, lr = lat[f"{d}_bridge"], lat[f"{d}_raw"]
            rows.append([f"{label}, {name}", num(br["msg_per_s"]), num(raw["msg_per_s"]),
                         f"{tp[f'{d}_ratio']:.2f}" + spread(tp.get(f"{d}_ratio_runs")),
                         f"{lb['p50_us'] / 1e3:.2f} / {lb['p99_us'] / 1e3:.2f} / {lb['max_us'] / 1e3:.2f}",
                         f"{lr['p50_us'] / 1e3:.2f} / {lr['p99_us'] / 1e3:.2f} / {lr['max_us'] / 1e3:.2f}",
                         num(br["cpu_ms_per_1000"].get("process"), 0), num(raw["cpu_ms_per_1000"].get("process"), 0),
                         num(br["cpu_ms_per_1000"].get("ROS process"), 0), f"{br['lost']} / {lb['lost']}"])
    return rows


TRANSPORT_HEADER = ["direction, bridge path", "bridge msg/s", "raw msg/s", "ratio", "bridge latency p50/p99/max ms",
                    "raw latency p50/p99/max ms", "CPU ms/1000, bridge run", "CPU ms/1000, raw run",
                    "ROS process CPU ms/1000", "lost (throughput / latency runs)"]


def cpu_split_rows(b: dict[str, Any]) -> list[list[str]]:
    """CPU per 1000 messages by thread of the throughput runs, each path's bridge runs and their raw runs."""
    rows = []
    for name, blk in blocks(b):
        tp = blk["throughput"]
        short = "codec" if name.startswith("wire") else name.split()[0]
        rows += [[f"{d} {w}" + (f" ({short})" if w == "bridge" else f" (beside {short})")]
                 + [num(tp[f"{d}_{w}"]["cpu_ms_per_1000"].get(k), 0) for k in THREADS]
                 for d, _ in DIRECTIONS for w in ("bridge", "raw")]
    return rows


def block_method(b: dict[str, Any], meth: dict[str, Any]) -> str:
    """How the two paths were measured (one sentence for the sections' method paragraphs)."""
    ob = b.get("object")
    if not ob:
        return (f"The bridge ran on its {path_name(b.get('wire'))} only (no object-path block in this run).")
    return (f"The bridge runs on its wire path (`Bridge(..., wire=\"codec\")`, the default: raw transport-level "
            "ports, raw ROS publish/subscribe, the generated codecs) for the whole measurement above, then the same "
            f"process closes it and starts one on the object path (`wire=\"object\"`: pycyphal/dronecan objects, the "
            f"object converters, rclpy messages) for {ob['reps']} more throughput repetitions and "
            f"{ob['latency_reps']} latency repetition(s), again each beside a raw run; `wire path Nx it` in the "
            "summary is the ratio of the two paths' ratios to raw (the blocks run one after the other).")


# ----------------------------------------------------------------------------------------------- notes
def step(pm: dict[str, float], prefix: str) -> float:
    """The per-message step whose name starts with ``prefix`` (NaN if none).

    >>> step({"  wire path: x": 1.5}, "wire path"), math.isnan(step({}, "y"))
    (1.5, True)
    """
    return next((v for k, v in pm.items() if k.strip().startswith(prefix)), math.nan)


def cpu(tp: dict[str, Any], run: str, key: str = "process") -> float:
    return float(tp[run]["cpu_ms_per_1000"].get(key, math.nan))


def codec_notes(c: dict[str, Any]) -> list[str]:
    """What bounds the codecs' figures."""
    out = []
    for proto, label in (("cyphal", "Cyphal"), ("dronecan", "DroneCAN")):
        s = c["summary"].get(f"{proto} all")
        if not s:
            continue
        rows = [r for r in c["rows"] if r["protocol"] == proto and not r.get("missing")]
        low = min(rows, key=lambda r: r["ratio"])
        high = max(rows, key=lambda r: r["ratio"])
        bad = [f"{r['mapping']} {r['direction']}" for r in rows if not r["agree"]]
        out.append(
            f"- **Wire codecs, {label}.** Object pipeline / codec: geomean {s['geomean']:.2f}x, from "
            f"{low['ratio']:.2f}x ({low['mapping']} {low['direction']}: codec {num(low['ns_per_msg']['codec'], 0)} "
            f"ns against {num(low['ns_per_msg']['object'], 0)} ns) to {high['ratio']:.2f}x ({high['mapping']} "
            f"{high['direction']}); {s['meet_target']}/{s['codecs']} at >= {c['target']:g}x. "
            + (f"**Disagree with the object pipeline: {', '.join(bad)}.** " if bad else
               f"All {s['codecs']} give the object pipeline's values. ")
            + "The object pipeline pays the library's generic (de)serializer and rclpy's message objects on both "
              "sides of the converter; the codec reads and writes the bytes with precompiled struct formats.")
    return out
