"""The benchmark session of issue 5 (`nox -s bench`; not part of the tests), with issue 10's DroneCAN part and
issue 12's wire codecs.

    python -m bench.run [--quick] [--parts generator,converters,codec,bridge,dronecan,cpu] [--transports udp,can]
                        [--out DIR]

Runs the parts, prints the tables, writes DIR/results.md, DIR/results.json and DIR/scaling.png
(DIR default bench/results). Every figure is a ratio against a reference measured in the same run, with the
absolute numbers beside it. About 23 minutes on the project's 2-core machine, half of it the CPU section
(``--quick``: about 7).

Parts: ``generator``, ``converters``, ``codec`` (every generated wire codec against the object pipeline it
replaces, Cyphal and DroneCAN, bench/codec.py: ~15 s), ``bridge`` (Cyphal/UDP and Cyphal/CAN FD, bench/bridge.py:
the bridge on its wire path, then on its object path, each against raw pycyphal: ~6 min) and ``dronecan`` (the
bridge on DroneCAN, layout ``dronecan``, both paths against raw dronecan on the loopback multicast bus,
bench/bridge_dronecan.py: ~2.5 min, ``--quick`` ~1) and ``cpu`` (issue 26: ``sam-codegen bridge`` beside a raw
receiver at SAM's nominal traffic and idle, both protocols, each run in a network namespace of its own, and the
regression guard against the committed results, bench/cpu.py: ~12 min, ``--quick`` ~2). One part alone, e.g. the
DroneCAN one:

    python -m bench.run --parts dronecan [--quick] [--out DIR]

(--out another directory to keep bench/results/ of a whole run: results.md and results.json hold what was run.)
The ``cpu`` part alone is merged instead: its section of results.json and results.md is replaced, the rest kept:

    python -m bench.run --parts cpu [--cpu-runs N] [--cpu-warm S] [--cpu-window S] [--cpu-protocols cyphal,dronecan]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path
from typing import Any

import bench.common  # noqa: F401  (ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST before anything can import rclpy)
from bench.common import RESULTS, generated_package, log, machine
from bench.report_cpu import cpu_markdown, splice
from bench.report_fmt import num as _f
from bench.report_fmt import ok as _ok
from bench.report_fmt import table
from bench.report_notes import notes
from bench.report_wire import (
    TARGET_CYPHAL,
    TARGET_DRONECAN,
    TRANSPORT_HEADER,
    block_method,
    blocks,
    bridge_rows,
    codec_markdown,
    codec_rows,
    cpu_split_rows,
    transport_rows,
)

DEFAULT_PARTS = "generator,converters,codec,bridge,dronecan,cpu"


def loadavg() -> list[float]:
    try:
        return [float(x) for x in Path("/proc/loadavg").read_text().split()[:3]]
    except OSError:
        return []


# ----------------------------------------------------------------------------------------------- markdown
def summary_rows(res: dict[str, Any]) -> list[list[str]]:
    rows: list[list[str]] = []
    gen = res.get("generator")
    if gen:
        sam = next(r for r in gen["rows"] if not r["types"])
        big = max((r for r in gen["rows"] if r["types"]), key=lambda r: r["types"])
        g = gen["growth"].get("sam-codegen build", {})
        rows.append(["Generator: `sam-codegen build`, SAM spec", f"{sam['build_s']:.2f} s",
                     f"pycyphal compile {sam['pycyphal_compile_s']:.2f} s", f"{sam['ratio_vs_pycyphal']:.2f}x time",
                     "-", "-"])
        rows.append([f"Generator: synthetic spec of {big['types']} types", f"{big['build_s']:.2f} s",
                     f"pycyphal compile {big['pycyphal_compile_s']:.2f} s", f"{big['ratio_vs_pycyphal']:.2f}x time",
                     "-", "-"])
        if g:
            rows.append([f"Generator: growth of t(N) - t(1), N = {', '.join(map(str, g.get('fit_sizes', [])))}",
                         f"exponent {g['fitted_exponent']}, {g['per_type_ms'].get(str(big['types']))} ms/type",
                         f"pycyphal: exponent {gen['growth']['pycyphal compile']['fitted_exponent']}, "
                         f"{gen['growth']['pycyphal compile']['per_type_ms'].get(str(big['types']))} ms/type", "-",
                         "linear (exponent <= 1.1)", _ok(g["fitted_exponent"] <= 1.1)])
    conv = res.get("converters")
    if conv:
        s = conv["summary"]["all"]
        t = conv["targets"]
        rows.append([f"Converters vs hand-written ({s['converters']} = {s['converters'] // 2} mappings x 2 "
                     "directions)",
                     f"geomean {s['geomean_vs_handwritten']:.2f}x, min {s['min_vs_handwritten']:.2f}x",
                     "doc-style hand-written",
                     f"{s['meet_hand_target']}/{s['converters']} at >= {t['vs_handwritten']}x",
                     f">= {t['vs_handwritten']}x", _ok(s["meet_hand_target"] == s["converters"])])
        rows.append(["Converters vs generic reflection copier",
                     f"geomean {s['geomean_vs_generic']:.2f}x, min {s['min_vs_generic']:.2f}x", "generic copier",
                     f"{s['meet_generic_target']}/{s['converters']} at >= {t['vs_generic']}x",
                     f">= {t['vs_generic']}x", _ok(s["meet_generic_target"] == s["converters"])])
    rows += codec_rows(res.get("codec"))
    br = res.get("bridge") or {}
    for kind in ("udp", "can"):
        b = br.get(kind)
        if not b or "throughput" not in b:
            continue
        rows += bridge_rows(b, "raw pycyphal", TARGET_CYPHAL)
        mix = b.get("sensor_mix")
        if mix:
            rows.append([f"SAM sensor mix, zero loss, {b['transport']}",
                         f"{_f(mix['max_sustained_msg_per_s'], 0)} msg/s",
                         f"nominal {mix['nominal_msg_per_s']:.0f} msg/s",
                         f"{mix['max_sustained_k']:g}x nominal", "-", "-"])
    dc = res.get("dronecan")
    if dc and "throughput" in dc:
        rows += bridge_rows(dc, "raw dronecan", TARGET_DRONECAN, (" (RawIMU -> /imu)",
                                                                  " (/thruster_angles -> ArrayCommand)"))
        lat = dc.get("latency")
        if lat:
            def pp(x: dict[str, Any]) -> str:
                return f"{x['p50_us'] / 1e3:.2f} / {x['p99_us'] / 1e3:.2f} ms"

            rows.append([f"Latency p50 / p99 at {lat['rate_hz']:g} msg/s, {dc['transport']}",
                         f"UAVCAN->ROS {pp(lat['u2r_bridge'])}; ROS->UAVCAN {pp(lat['r2u_bridge'])}",
                         f"raw {pp(lat['u2r_raw'])}; {pp(lat['r2u_raw'])}", "-", "-", "-"])
        z = dc.get("zero_loss")
        if z:
            rows.append([f"RawIMU zero loss, {dc['transport']}",
                         f"{_f(z['max_sustained_msg_per_s'], 0)} msg/s = {_f(z['max_sustained_frames_per_s'])} "
                         "CAN frames/s",
                         f"saturated 1 Mbit/s classic CAN: {_f(z['bus_frames_per_s_nominal'])} frames/s "
                         f"({_f(z['bus_frames_per_s_worst_case'])} worst-case stuffing) = "
                         f"{_f(z['bus_raw_imu_per_s_nominal'])} ({_f(z['bus_raw_imu_per_s_worst_case'])}) RawIMU/s",
                         f"{z['share_of_bus_nominal']:.2f}x a saturated bus ({z['share_of_bus_worst_case']:.2f}x)",
                         "-", "-"])
    return rows


def markdown(res: dict[str, Any], command: str) -> str:
    m = res["machine"]
    dronecan_version = f", dronecan {m['packages']['dronecan']}" if m["packages"].get("dronecan") else ""
    lines = [
        "# Benchmark results",
        "",
        f"Taken {m['date']} on {m['cpu']}, {m['cores']} cores, {m['memory_gib']} GiB, {m['os']} "
        f"(kernel {m['kernel']}), "
        f"Python {m['python']}; pycyphal {m['packages']['pycyphal']}, nunavut {m['packages']['nunavut']}, "
        f"pydsdl {m['packages']['pydsdl']}, python-can {m['packages']['python-can']}, rclpy {m['packages']['rclpy']}"
        f"{dronecan_version} "
        f"(ROS 2 Jazzy wheels, {m['rmw']}); commit {m['commit']}. Load average before/after: "
        f"{res['loadavg_before']} / {res['loadavg_after']}. Session wall time {res['wall_s']:.0f} s.",
        "",
        f"Command: `{command}`. Every ratio is against a reference measured in the same run; absolute figures "
        "beside it.",
        "",
        "## Summary",
        "",
        table(["figure", "measured", "reference (same run)", "ratio", "target", ""], summary_rows(res)),
    ]
    gen = res.get("generator")
    if gen:
        lines += ["", "## 1. Generator", "",
                  f"Minimum of {gen['method']['reps']} runs (other processes only add time), each a fresh process: "
                  "`sam-codegen build --spec S --out NEW` "
                  "(every file written) against `pycyphal.dsdl.compile` of the DSDL namespace it emitted "
                  "(nunavut 2.3; `uavcan` lookup-only). Synthetic specs: bench/synthetic.py (half derived UAVCAN->ROS "
                  "mappings with `fields: auto`, half declared ROS->UAVCAN ones line by line; up to 100 devices).", ""]
        rows = []
        for r in gen["rows"]:
            rows.append([r["spec"], _f(r["types"]), _f(r["files_generated"]), f"{r['build_s']:.2f}",
                         f"{r['pycyphal_compile_s']:.2f}", f"{r['ratio_vs_pycyphal']:.2f}",
                         _f(r.get("build_per_type_ms")), _f(r.get("compile_per_type_ms"))])
        lines.append(table(["spec", "types", "files", "build s", "pycyphal compile s", "build / compile",
                            "build ms/type", "compile ms/type"], rows))
        g = gen["growth"]
        if g:
            lines += ["", "Growth of t(N) - t(1) with N: " + "; ".join(
                f"{name}: fitted exponent {v['fitted_exponent']} over N = {', '.join(map(str, v['fit_sizes']))} "
                f"(local {', '.join(f'{k}: {_f(e)}' for k, e in v['local_exponents'].items())}), "
                f"fixed cost t(1) = {v['fixed_s']:.2f} s" for name, v in g.items())
                + ". The fit is weighted by each margin's precision (" + gen["method"].get("fit", "")
                + "), so the small sizes, whose margins are within a process start's noise, count for little."]
        by_size = gen.get("stages_by_size") or {}
        st = gen.get("stages_at_largest") or {}
        if by_size:
            sizes = sorted(by_size, key=int)
            keys = list(dict.fromkeys(k for n in sizes for k in by_size[n]))
            lines += ["", f"Where the time goes at N = {', '.join(sizes)} (in one process, imports warm):", "",
                      table(["stage", *(f"s at N = {n}" for n in sizes)],
                            [[k.strip(), *(_f(by_size[n].get(k)) for n in sizes)] for k in keys])]
        elif st.get("seconds"):
            lines += ["", f"Where the time goes at N = {st['types']} (in one process, imports warm):", "",
                      table(["stage", "s"], [[k.strip(), f"{v:.2f}"] for k, v in st["seconds"].items()])]
    conv = res.get("converters")
    if conv:
        lines += ["", "## 2. Converters", "",
                  "Conversions per second of each generated converter (generated/python/sam_bridge/convert.py) against "
                  "(a) hand-written converters in the design document's RawIMU->Imu style (bench/handwritten.py) and "
                  "(b) a generic copier that walks the spec's field links at run time with getattr/setattr and "
                  "coerces by looking at the destination (bench/generic.py). All three give the same output on the "
                  f"same input (checked first). Best ns/call of {conv['method']['rounds']} interleaved rounds "
                  "(other processes "
                  "only add time; medians are in results.json). "
                  "`bridge` = the direction the bridge runs for that mapping; `class ctor` = the destination "
                  "class's constructor alone (`Imu()`), which the hand-written and generic converters call; "
                  "`generated ctor` = convert.py's own constructor of that class, which the generated converters "
                  "call (proved at import to build the same object).", ""]
        rows = []
        for r in conv["rows"]:
            rows.append([r["mapping"], r["direction"], "yes" if r["bridge_runs_it"] else "",
                         _f(r["per_s"]["generated"]), _f(r["per_s"]["handwritten"]), _f(r["per_s"]["generic"]),
                         f"{r['vs_handwritten']:.2f}", f"{r['vs_generic']:.2f}", _f(r["ctor_ns"], 0),
                         _f(r.get("generated_ctor_ns"), 0)])
        lines.append(table(["mapping", "direction", "bridge", "generated /s", "hand-written /s", "generic /s",
                            "gen/hand", "gen/generic", "class ctor ns", "generated ctor ns"], rows))
        s = conv["summary"]
        lines += ["", table(["direction", "converters", "geomean gen/hand", "min", "geomean gen/generic", "min"],
                            [[d, str(v["converters"]), f"{v['geomean_vs_handwritten']:.2f}",
                              f"{v['min_vs_handwritten']:.2f}", f"{v['geomean_vs_generic']:.2f}",
                              f"{v['min_vs_generic']:.2f}"]
                             for d, v in s.items()])]
    codec = res.get("codec")
    if codec:
        lines += codec_markdown(codec, "3")
    br = res.get("bridge") or {}
    if br:
        meth = br["method"]
        lines += ["", "## 4. Bridge", "",
                  "The bridge (runtime/bridge.py, public API, default settings) and the pycyphal device and receiver "
                  "nodes share one process and asyncio loop (python-can's virtual bus exists only inside one process); "
                  "the ROS side (subscribers of the bridged topics, the command publisher) is a separate process, as "
                  "ROS consumers are in a deployment. Raw reference: pycyphal publisher -> pycyphal subscriber of the "
                  "same DSDL type in the same process, no bridge. Throughput: at most "
                  f"{meth['window_in_flight']} messages in flight for {meth['window_s']} s, nothing lost; "
                  f"{meth['reps']} repetitions, each a bridge run and a raw run back to back (in alternating order): "
                  "msg/s are medians, the ratio is the median of the repetitions' ratios (their range in brackets). "
                  "UAVCAN->ROS: sam.sensor.RawIMU (120 bytes, one "
                  "UDP datagram, 2 CAN FD frames) -> /imu; ROS->UAVCAN: sam_msgs/ThrusterAngles on /thruster_angles -> "
                  f"subject 1202. Latency at {meth['latency_hz']:g} msg/s for {meth['latency_s']} s "
                  f"({meth.get('latency_reps', meth['reps'] - 1)} repetitions): "
                  "UAVCAN publish -> ROS callback and ROS publish -> UAVCAN receive. CPU: this process (all its "
                  "threads) per 1000 messages; the ROS process beside it.", ""]
        for kind in ("udp", "can"):
            b = br.get(kind)
            if not b or "throughput" not in b:
                continue
            lines += [f"### {b['transport']}", "", block_method(b, meth), "",
                      table(TRANSPORT_HEADER, transport_rows(b))]
            lines += ["", "CPU ms per 1000 messages by thread (throughput runs):", "",
                      table(["run", "main (asyncio loop)", "bridge rclpy thread", "other threads (DDS, transport I/O)",
                             "ROS process"], cpu_split_rows(b))]
            rss = b["rss"]
            lines += ["", f"Resident memory: {rss['before_bridge_kib'] / 1024:.0f} MiB before the bridge starts "
                      f"(pycyphal, rclpy, nodes imported), {rss['after_bridge_start_kib'] / 1024:.0f} MiB after "
                      f"(bridge footprint {rss['bridge_footprint_mib']} MiB), "
                      f"{rss['after_bridged_kib'] / 1024:.0f} MiB "
                      f"after {b['bridged_messages']:,} bridged messages: {rss['growth_kib_per_1000_bridged']} KiB "
                      "per 1000 bridged messages."]
            mix = b.get("sensor_mix")
            if mix:
                rows = [[f"{t['k']:g}", _f(t["target_msg_per_s"], 0), _f(t["offered_msg_per_s"], 0),
                         f"{t['ros_msgs_received']:,}/{t['ros_msgs_expected']:,}", str(t["bridge_dropped"]),
                         _f(t["publisher_late_max_ms"], 1), _f(t["drained_in_s"], 3),
                         _f(t.get("imu_latency_p99_ms")), "yes" if t["sustained"] else "no"]
                        for t in mix["trials"]]
                lines += ["", f"SAM sensor mix ({mix['device_nodes']} device nodes, every UAVCAN->ROS port at k x its "
                          f"nominal rate, nominal total {mix['nominal_msg_per_s']:.0f} msg/s on Cyphal, "
                          f"{mix['nominal_ros_msg_per_s']:.0f} on ROS): largest sustained k = "
                          f"**{mix['max_sustained_k']:g}** ({_f(mix['max_sustained_msg_per_s'], 0)} msg/s).", "",
                          table(["k", "target msg/s", "offered msg/s", "at ROS", "bridge drops",
                                 "publisher late max ms", "drained in s", "IMU p99 ms", "sustained"], rows)]
            pm = b.get("per_message_us")
            if pm:
                lines += ["", "Per-message steps, each alone in a loop (us):", "",
                          table(["step", "us"], [[k.strip(), f"{v:.1f}"] for k, v in pm.items()])]
            lines.append("")
    dc = res.get("dronecan")
    if dc and "throughput" in dc:
        lines += dronecan_markdown(dc)
    if res.get("cpu"):
        lines += [*cpu_markdown(res["cpu"]), ""]
    notes = res.get("notes")
    if notes:
        lines += ["## What limits the figures", "", *notes]
    return "\n".join(lines).rstrip() + "\n"


def dronecan_markdown(dc: dict[str, Any]) -> list[str]:
    """Section 4: the bridge on DroneCAN (bench/bridge_dronecan.py)."""
    meth, lat, z = dc["method"], dc["latency"], dc.get("zero_loss")
    fr = dc["frames"]
    lines = ["", "## 5. Bridge on DroneCAN", "",
             f"The bridge with the spec's `dronecan` layout (`Bridge(gen, layout=\"dronecan\", "
             f"dronecan_iface=...)`: node {dc.get('bridge_node_id', 100)}, FrameGate and NodeLoop on the asyncio "
             "loop) and plain `dronecan` nodes (`dronecan.node.Node` on sam_runtime's LoopbackMulticastDriver, "
             "spun from the same loop) in this process; the ROS side in a separate process (as for Cyphal). "
             f"Transport: {dc['transport']}, `mcast-lo:<bus>:<port>`, one private bus for the bridge and one for "
             "the raw reference (another port). Every plain node is behind an acceptance filter of what it listens "
             f"to ({', '.join(dc.get('acceptance_filters', []))}), as a device's CAN controller filters in hardware "
             "(dronecan decodes every transfer a node receives). UAVCAN->ROS: uavcan.equipment.ahrs.RawIMU "
             f"({fr['raw_imu']['payload_bytes']} B, {fr['raw_imu']['frames']} classic CAN frames) broadcast by "
             "the IMU's node 11 -> /imu; ROS->UAVCAN: sam_msgs/ThrusterAngles on /thruster_angles -> "
             f"uavcan.equipment.actuator.ArrayCommand (actuator ids 0 and 1, {fr['array_command']['payload_bytes']} "
             f"B, {fr['array_command']['frames']} frames) broadcast by the bridge -> the thrust vector's node 23. "
             "Raw reference: a dronecan publisher -> a dronecan subscriber of the same types on the raw bus, no "
             "bridge; the raw sender sets the values of one message and broadcasts it (as bench/bridge.py's raw "
             "sender), the raw RawIMU receiver reads the values the bridge's converter reads (dronecan converts a "
             f"value when it is read). Throughput: at most {meth['window_in_flight']} in flight for "
             f"{meth['window_s']} s, {meth['reps']} repetitions of raw and bridge back to back (alternating "
             "order): msg/s are medians, the ratio the median of the repetitions' ratios (range in brackets). "
             f"Latency: paced at {lat['rate_hz']:g} msg/s for {lat['seconds']} s "
             f"({meth['latency_reps']} repetition(s)), with the CPU of both processes over it.", ""]
    lines += [block_method(dc, meth), "", table(TRANSPORT_HEADER, transport_rows(dc))]
    lines += ["", "CPU ms per 1000 messages by thread (throughput runs):", "",
              table(["run", "main (asyncio loop)", "bridge rclpy thread", "other threads (DDS, I/O)", "ROS process"],
                    cpu_split_rows(dc))]
    paced = [[f"{d} {w}" + (f" ({'codec' if name.startswith('wire') else name.split()[0]})" if w == "bridge" else ""),
              _f(bl["latency"][f"{d}_{w}"]["cpu_percent"]["process"], 1),
              _f(bl["latency"][f"{d}_{w}"]["cpu_percent"]["ROS process"], 1),
              _f(bl["latency"][f"{d}_{w}"]["cpu_ms_per_1000"]["process"], 0),
              _f(bl["latency"][f"{d}_{w}"]["cpu_ms_per_1000"]["ROS process"], 0)]
             for name, bl in blocks(dc) for d in ("u2r", "r2u") for w in ("bridge", "raw")
             if "cpu_percent" in bl["latency"][f"{d}_{w}"]]
    lines += ["", f"CPU at {lat['rate_hz']:g} msg/s (paced runs; the process's idle work, its timers and the "
              "nodes' NodeStatus, included):", "",
              table(["run", "this process % of a core", "ROS process % of a core", "this process ms/1000",
                     "ROS process ms/1000"], paced)]
    rss = dc.get("rss")
    if rss:
        lines += ["", f"Resident memory: {rss['before_bridge_kib'] / 1024:.0f} MiB before the bridge starts, "
                  f"{rss['after_bridge_start_kib'] / 1024:.0f} MiB after (bridge footprint "
                  f"{rss['bridge_footprint_mib']} MiB), {rss['after_bridged_kib'] / 1024:.0f} MiB after "
                  f"{dc['bridged_messages']:,} bridged messages: {rss['growth_kib_per_1000_bridged']} KiB per 1000."]
    if z:
        rows = [[_f(t["rate_msg_per_s"], 0), _f(t["frames_per_s"]), _f(t["offered_msg_per_s"], 0),
                 f"{t['at_ros']:,}/{t['sent']:,}", str(t["bridge_dropped"]), _f(t["publisher_late_max_ms"], 1),
                 _f(t["drained_in_s"], 3), _f(t["cpu_percent"]["process"], 0), _f(t["cpu_percent"]["ROS process"], 0),
                 "yes" if t["sustained"] else "no"] for t in z["trials"]]
        lines += ["", f"Zero loss: RawIMU alone from node 11, paced at R msg/s for {meth['trial_s']} s; the device "
                  "sends frames encoded once per transfer id (its encoder is firmware on a real bus; dronecan's "
                  "costs ~0.1 ms a message in this process), so the figure is the bridge's process, not the "
                  "device's. Sustained = every message at ROS, no drop by the bridge (its mapping, its driver and "
                  f"FrameGate), the device on schedule (never 0.25 s behind) and drained within {meth['drain_s']} s. "
                  f"R doubles from {z['trials'][0]['rate_msg_per_s']:g} until a trial fails, then is bisected. "
                  f"Largest sustained: **{_f(z['max_sustained_msg_per_s'], 0)} RawIMU/s** "
                  f"({z['max_sustained_x_nominal']:g}x the spec's {z['nominal_rate_hz']:g} Hz) = "
                  f"**{_f(z['max_sustained_frames_per_s'])} classic CAN frames/s** ({z['frames_per_message']} "
                  f"a message), against {_f(z['bus_frames_per_s_nominal'])} frames/s on a saturated 1 Mbit/s bus "
                  f"({_f(z['bus_frames_per_s_worst_case'])} with worst-case bit stuffing: bus_load.frame_bits), "
                  f"i.e. {_f(z['bus_raw_imu_per_s_nominal'])} ({_f(z['bus_raw_imu_per_s_worst_case'])}) RawIMU/s: "
                  f"{z['share_of_bus_nominal']:.2f}x ({z['share_of_bus_worst_case']:.2f}x) what the bus carries.", "",
                  table(["R msg/s", "frames/s", "offered msg/s", "at ROS", "bridge drops", "device late max ms",
                         "drained in s", "this process CPU %", "ROS process CPU %", "sustained"], rows)]
    pm = dc.get("per_message_us")
    if pm:
        lines += ["", "Per-message steps, each alone in a loop (us):", "",
                  table(["step", "us"], [[k.strip(), f"{v:.1f}"] for k, v in pm.items()])]
    lines.append("")
    return lines


# ----------------------------------------------------------------------------------------------- main
def write_plot(res: dict[str, Any], out: Path) -> None:
    """scaling.png, where the results have what it shows (the generator's growth, the sensor mix)."""
    if not (res.get("generator") or res.get("bridge")):
        return
    try:
        from bench.plot import plot

        plot(res, out / "scaling.png")
    except ImportError as ex:
        log(f"no PNG: {ex} (pip install matplotlib)")


def merge_cpu(cpu: dict[str, Any], out: Path) -> int:
    """The cpu part run alone: its section replaces the one in OUT/results.json and results.md, the rest is kept."""
    out.mkdir(parents=True, exist_ok=True)
    res_path, md_path = out / "results.json", out / "results.md"
    res = json.loads(res_path.read_text()) if res_path.is_file() else {}
    res["cpu"] = cpu
    res_path.write_text(json.dumps(res, indent=1, default=str) + "\n")
    section = cpu_markdown(cpu)
    md_path.write_text(splice(md_path.read_text() if md_path.is_file() else "# Benchmark results\n", section))
    print("\n".join(section))
    log(f"merged the CPU section into {res_path} and {md_path}")
    return 0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m bench.run", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="fewer repetitions and shorter windows (~5 min)")
    ap.add_argument("--parts", default=DEFAULT_PARTS, help=f"comma-separated, of {DEFAULT_PARTS}")
    ap.add_argument("--transports", default="udp,can")
    ap.add_argument("--out", type=Path, default=RESULTS)
    ap.add_argument("--cpu-runs", type=int, default=None, help="cpu part: runs per protocol (default 3, --quick 1)")
    ap.add_argument("--cpu-warm", type=float, default=None, help="cpu part: warm-up s (default 15, --quick 5)")
    ap.add_argument("--cpu-window", type=float, default=None, help="cpu part: window s (default 40, --quick 15)")
    ap.add_argument("--cpu-protocols", default="cyphal,dronecan")
    ap.add_argument("--cpu-label", default=None, help="cpu part: what these figures are (e.g. 'BEFORE issue 26')")
    ap.add_argument("--render", action="store_true",
                    help="only rewrite results.md and scaling.png from the results.json in --out (with --parts cpu: "
                         "only results.md's CPU section)")
    args = ap.parse_args(argv)
    if args.render and args.parts == "cpu":  # the CPU section alone, spliced into results.md
        res = json.loads((args.out / "results.json").read_text())
        md_path = args.out / "results.md"
        md_path.write_text(splice(md_path.read_text() if md_path.is_file() else "", cpu_markdown(res["cpu"])))
        return 0
    if args.render:
        res = json.loads((args.out / "results.json").read_text())
        res["notes"] = notes(res)
        (args.out / "results.json").write_text(json.dumps(res, indent=1, default=str) + "\n")
        (args.out / "results.md").write_text(markdown(res, res.get("command", "python -m bench.run")))
        write_plot(res, args.out)
        return 0
    parts = [p.strip() for p in args.parts.split(",") if p.strip()]
    command = "python -m bench.run" + (" --quick" if args.quick else "") + (
        f" --parts {args.parts}" if args.parts != DEFAULT_PARTS else "")
    t0 = time.monotonic()
    res: dict[str, Any] = {"machine": machine(), "loadavg_before": loadavg(), "quick": args.quick}
    log(f"machine: {res['machine']['cpu']}, {res['machine']['cores']} cores; load {res['loadavg_before']}")
    if "generator" in parts:
        from bench import generator

        log("part 1: generator")
        res["generator"] = generator.run(reps=1 if args.quick else 5, sizes=(1, 10, 100) if args.quick
                                         else generator.SIZES)
    unknown = set(parts) - set(DEFAULT_PARTS.split(","))
    if unknown:
        ap.error(f"unknown part(s) {', '.join(sorted(unknown))}; parts: {DEFAULT_PARTS}")
    gen = generated_package() if {"converters", "codec", "bridge", "dronecan"} & set(parts) else None
    if "converters" in parts:
        from bench import converters

        log("part 2: converters")
        res["converters"] = converters.run(gen, rounds=5 if args.quick else 15, batch_s=0.005)
    if "codec" in parts:
        from bench import codec

        log("part 3: wire codecs")
        res["codec"] = codec.run(gen, rounds=5 if args.quick else 15, batch_s=0.005)
        res["codec"]["namespaced"] = codec.run_namespaced(gen, rounds=5 if args.quick else 15, batch_s=0.005)
    if "bridge" in parts:
        from bench import bridge

        log("part 4: bridge")
        kinds = tuple(k.strip() for k in args.transports.split(",") if k.strip())
        res["bridge"] = bridge.run(gen, kinds, reps=2 if args.quick else 5, window_s=1.5 if args.quick else 2.0,
                                   latency_s=1.5 if args.quick else 2.5, mix_s=2.0 if args.quick else 3.0,
                                   object_reps=2 if args.quick else 3)
    if "dronecan" in parts:
        from bench import bridge_dronecan

        log("part 5: bridge on DroneCAN")
        res["dronecan"] = bridge_dronecan.run(gen, **(bridge_dronecan.QUICK if args.quick else {}))
    if "cpu" in parts:
        from bench import cpu

        log("part 6: bridge CPU at nominal traffic")
        res["cpu"] = cpu.run(tuple(p.strip() for p in args.cpu_protocols.split(",") if p.strip()),
                             runs=args.cpu_runs or (1 if args.quick else 3),
                             warm_s=args.cpu_warm if args.cpu_warm is not None else 5.0 if args.quick else 15.0,
                             window_s=args.cpu_window if args.cpu_window is not None else 15.0 if args.quick else 40.0,
                             label=args.cpu_label)
        for line in cpu.guard_lines(res["cpu"]["guard"]):
            log(line)
        if parts == ["cpu"]:
            return merge_cpu(res["cpu"], args.out)
    res["loadavg_after"] = loadavg()
    res["wall_s"] = time.monotonic() - t0
    res["notes"] = notes(res)
    res["command"] = command
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "results.json").write_text(json.dumps(res, indent=1, default=str) + "\n")
    md = markdown(res, command)
    (args.out / "results.md").write_text(md)
    write_plot(res, args.out)
    print(md)
    png = ", scaling.png" if res.get("generator") or res.get("bridge") else ""
    log(f"wrote {args.out / 'results.md'}, results.json{png} in {res['wall_s']:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
