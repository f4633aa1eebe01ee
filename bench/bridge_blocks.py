"""The measurement blocks every bridge part runs on its rig (Cyphal: bench/bridge.py; DroneCAN:
bench/bridge_dronecan.py): throughput and latency of the bridge and the raw reference back to back, the object
path's block, and the summaries (medians of the repetitions, the per-pair ratios)."""

from __future__ import annotations

import asyncio
import time
from typing import Any

from bench.bridge_rig import Rig
from bench.common import log, median, ratio

# ----------------------------------------------------------------------------------------------- driver
PATHS = ("u2r_raw", "u2r_bridge", "r2u_raw", "r2u_bridge")


async def run_block(rig: Rig, *, reps: int, window_s: float, latency_reps: int, latency_hz: float, latency_s: float,
                    paths: tuple[str, ...] = PATHS) -> tuple[dict[str, list[Any]], dict[str, list[Any]], int]:
    """Throughput (``reps`` repetitions) then latency (``latency_reps``) of the four paths on the running bridge;
    raw and bridge back to back in alternating order. Returns the runs by path and the messages bridged."""
    paced = getattr(rig, "paced_cpu", rig.paced)
    for p in paths:  # warm-up
        await rig.windowed(p, 0.3, cpu=False)
    tp: dict[str, list[dict[str, Any]]] = {p: [] for p in PATHS}
    bridged = 0
    for r in range(reps):
        for direction in ("u2r", "r2u"):
            for which in (("raw", "bridge") if r % 2 == 0 else ("bridge", "raw")):
                res = await rig.windowed(f"{direction}_{which}", window_s)
                tp[f"{direction}_{which}"].append(res)
                bridged += res["received"] if which == "bridge" else 0
                await asyncio.sleep(0.1)
    log(f"  {rig.kind} ({rig.bridge.wire} path): throughput " + ", ".join(
        f"{k} {median([x['msg_per_s'] for x in v]):.0f}/s" for k, v in tp.items()))
    lat: dict[str, list[dict[str, Any]]] = {p: [] for p in PATHS}
    for r in range(latency_reps):
        for direction in ("u2r", "r2u"):
            for which in (("raw", "bridge") if r % 2 == 0 else ("bridge", "raw")):
                lat[f"{direction}_{which}"].append(await paced(f"{direction}_{which}", latency_hz, latency_s))
                bridged += lat[f"{direction}_{which}"][-1]["received"] if which == "bridge" else 0
                await asyncio.sleep(0.1)
    return tp, lat, bridged


async def object_block(rig: Rig, *, reps: int, window_s: float, latency_reps: int, latency_hz: float,
                       latency_s: float) -> dict[str, Any]:
    """The same measurement with the bridge on the object path (``wire="object"``), against raw again."""
    t0 = time.monotonic()
    await rig.swap_bridge("object")
    tp, lat, bridged = await run_block(rig, reps=reps, window_s=window_s, latency_reps=latency_reps,
                                       latency_hz=latency_hz, latency_s=latency_s, paths=("u2r_bridge", "r2u_bridge"))
    return {"wire": rig.bridge.wire, "reps": reps, "latency_reps": latency_reps, "bridged_messages": bridged,
            "throughput": summarize_throughput(tp), "latency": summarize_latency(lat, latency_hz, latency_s),
            "wall_s": round(time.monotonic() - t0, 1)}


def codec_vs_object(codec: dict[str, Any], obj: dict[str, Any]) -> dict[str, float]:
    """Bridge msg/s of the codec path over the object path's, each normalised by the raw runs of its own block
    (the blocks run one after the other: the machine's load may differ).

    >>> codec_vs_object({"u2r_ratio": 1.2, "r2u_ratio": 0.9}, {"u2r_ratio": 0.6, "r2u_ratio": 0.6})
    {'u2r': 2.0, 'r2u': 1.5}
    """
    return {d: round(ratio(codec[f"{d}_ratio"], obj[f"{d}_ratio"]), 2) for d in ("u2r", "r2u")}


def summarize_throughput(tp: dict[str, list[dict[str, Any]]]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for name, runs in tp.items():
        n = sum(r["received"] for r in runs)
        keys = list(runs[0]["cpu_s"]) if runs and runs[0]["cpu_s"] else []
        out[name] = {
            "msg_per_s": round(median([r["msg_per_s"] for r in runs])),
            "runs_msg_per_s": [round(r["msg_per_s"]) for r in runs],
            "lost": sum(r["lost"] for r in runs),
            "messages": n,
            "cpu_ms_per_1000": {k: round(sum(r["cpu_s"][k] for r in runs) / max(1, n) * 1e6, 1) for k in keys},
        }
    for d in ("u2r", "r2u"):
        b, r = out[f"{d}_bridge"], out[f"{d}_raw"]
        # Each repetition runs bridge and raw back to back: the ratio of a pair is taken under the same load, and
        # the median over the pairs is the figure (the machine's load drifts between repetitions).
        pairs = [ratio(x["msg_per_s"], y["msg_per_s"]) for x, y in zip(tp[f"{d}_bridge"], tp[f"{d}_raw"], strict=True)]
        out[f"{d}_ratio"] = round(median(pairs), 3)
        out[f"{d}_ratio_runs"] = [round(x, 3) for x in pairs]
        out[f"{d}_cpu_ratio"] = round(ratio(b["cpu_ms_per_1000"].get("process", 0),
                                            r["cpu_ms_per_1000"].get("process", 0)), 2)
    return out


def summarize_latency(lat: dict[str, list[dict[str, Any]]], hz: float, seconds: float) -> dict[str, Any]:
    out: dict[str, Any] = {"rate_hz": hz, "seconds": seconds}
    for name, runs in lat.items():
        out[name] = {
            "p50_us": round(median([r["p50_us"] for r in runs])),
            "p99_us": round(median([r["p99_us"] for r in runs])),
            "max_us": round(max(r["max_us"] or 0 for r in runs)),
            "samples": sum(r["samples"] for r in runs),
            "lost": sum(r["lost"] for r in runs),
        }
        for key in ("cpu_ms_per_1000", "cpu_percent"):  # paced runs that measured the CPU (bench.bridge_dronecan)
            if runs and key in runs[0]:
                out[name][key] = {k: round(median([x[key][k] for x in runs]), 1) for k in runs[0][key]}
    return out
