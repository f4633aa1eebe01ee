"""Part 2: conversions per second of every generated converter, both directions, against (a) hand-written
converters in the design document's style (bench/handwritten.py) and (b) a generic reflection-based copier
(bench/generic.py), all three checked to give the same output on the same realistic input first.

Method: per converter, a batch of K calls (K sized so that one batch of the generated converter takes about
``batch_s``) is timed with perf_counter_ns for each implementation in turn; ``rounds`` rounds, the order of the
three rotating every round (interleaved, so slow drifts of the machine hit all three alike). The figure is the
best round of each (timeit's convention: other processes on the machine only ever add time, and on a shared
2-core machine the spread of a median is tens of percent); the medians are kept in the JSON too. The garbage
collector is paused during a batch (re-enabled between batches, run before each converter's rounds).
Input of to_ros: a pycyphal object of the mapping's type with the simulator's values, as received (serialized
and deserialized); input of to_uavcan: the generated to_ros output of it.
"""

from __future__ import annotations

import gc
import math
import time
from typing import Any

from bench.common import SPEC, log, median, plain, ratio, same, sample_uavcan

IMPLS = ("generated", "handwritten", "generic")
TARGET_VS_HAND = 0.9
TARGET_VS_GENERIC = 3.0
RECEIVE_NS = 1_795_000_000_123_456_789


def _batch_ns(fn: Any, args: tuple[Any, ...], k: int) -> float:
    # GC paused in the batch, collected once per converter (run), not per batch: a full collection with rclpy and
    # pycyphal loaded takes tens of ms, and no converter leaves cycles
    gc.disable()
    try:
        t0 = time.perf_counter_ns()
        for _ in range(k):
            fn(*args)
        return (time.perf_counter_ns() - t0) / k
    finally:
        gc.enable()


def _calibrate(fn: Any, args: tuple[Any, ...], batch_s: float) -> int:
    k = 50
    while True:
        per = _batch_ns(fn, args, k)
        if per * k >= 2e6 or k >= 1_000_000:
            return max(50, int(batch_s * 1e9 / max(per, 1.0)))
        k *= 4


def run(gen: Any, *, rounds: int = 7, batch_s: float = 0.01) -> dict[str, Any]:
    import bench.generic as generic
    import bench.handwritten as handwritten

    convert = gen.convert()
    generics = generic.build(gen, SPEC)
    tables = gen.tables()
    rows: list[dict[str, Any]] = []
    t_start = time.monotonic()
    all_stats: list[Any] = []
    for m in tables.MAPPINGS:
        src = sample_uavcan(gen, m.port)
        stats = convert.ConversionStats()
        all_stats.append(stats)
        impls = {
            "generated": convert.CONVERTERS[m.name],
            "handwritten": handwritten.CONVERTERS[m.name],
            "generic": (generics[m.name].to_ros, generics[m.name].to_uavcan),
        }
        ros_msg = impls["generated"][0](src, RECEIVE_NS, stats)
        # The destination class's constructor, which the hand-written and generic converters call, and the
        # generated module's own constructor of that class (convert._FACTORIES), which the generated ones call.
        ctors = (type(ros_msg), type(src))
        own_ctors = {cls: new for new, cls in getattr(convert, "_FACTORIES", ())}
        for direction, idx, args in (("to_ros", 0, (src, RECEIVE_NS, stats)), ("to_uavcan", 1, (ros_msg, stats))):
            outs = {name: plain(fns[idx](*args)) for name, fns in impls.items()}
            tol = 1e-6 if direction == "to_ros" else 1e-3
            agree = {name: same(outs["generated"], outs[name], tol) for name in IMPLS}
            if not all(agree.values()):
                raise AssertionError(f"{m.name} {direction}: the implementations disagree: {agree}")
            gc.collect()
            k = _calibrate(impls["generated"][idx], args, batch_s)
            samples: dict[str, list[float]] = {name: [] for name in IMPLS}
            ctor_ns: list[float] = []
            own_ns: list[float] = []
            own = own_ctors.get(ctors[idx]) if convert.FAST_CONSTRUCTORS else None
            for r in range(rounds):
                order = IMPLS[r % 3:] + IMPLS[:r % 3]
                for name in order:
                    samples[name].append(_batch_ns(impls[name][idx], args, k))
                ctor_ns.append(_batch_ns(ctors[idx], (), k))
                if own is not None:
                    own_ns.append(_batch_ns(own, (), k))
            ns = {name: min(v) for name, v in samples.items()}
            rate = {name: 1e9 / v for name, v in ns.items()}
            c_ns = min(ctor_ns)
            rows.append({
                "mapping": m.name,
                "direction": direction,
                "bridge_runs_it": (direction == "to_ros") == (m.direction == "uavcan_to_ros"),
                "calls_per_batch": k,
                "ns_per_call": {n: round(v, 1) for n, v in ns.items()},
                "median_ns_per_call": {n: round(median(v), 1) for n, v in samples.items()},
                "per_s": {n: round(v) for n, v in rate.items()},
                "vs_handwritten": round(ratio(rate["generated"], rate["handwritten"]), 3),
                "vs_generic": round(ratio(rate["generated"], rate["generic"]), 3),
                "ctor_ns": round(c_ns, 1),
                "generated_ctor_ns": round(min(own_ns), 1) if own_ns else None,
                "spread_pct": {n: round(100 * (max(v) - min(v)) / median(v), 1) for n, v in samples.items()},
            })
    # Which counters the samples moved (keys only: the timed loops count too): the spec's own rules on the
    # simulator's values (e.g. a table whose default has no inverse); all three implementations agreed on them.
    counted = {kind: sorted({k for st in all_stats for k in getattr(st, kind)}) for kind in ("saturated", "rejected")}
    if counted["saturated"] or counted["rejected"]:
        log(f"converters: saturated / rejected on the samples: {counted}")

    def geo(xs: list[float]) -> float:
        return math.exp(sum(math.log(x) for x in xs) / len(xs)) if xs else math.nan

    summary: dict[str, Any] = {}
    for direction in ("to_ros", "to_uavcan", "all"):
        sel = [r for r in rows if direction == "all" or r["direction"] == direction]
        summary[direction] = {
            "converters": len(sel),
            "geomean_vs_handwritten": round(geo([r["vs_handwritten"] for r in sel]), 3),
            "min_vs_handwritten": min(r["vs_handwritten"] for r in sel),
            "geomean_vs_generic": round(geo([r["vs_generic"] for r in sel]), 3),
            "min_vs_generic": min(r["vs_generic"] for r in sel),
            "meet_hand_target": sum(r["vs_handwritten"] >= TARGET_VS_HAND for r in sel),
            "meet_generic_target": sum(r["vs_generic"] >= TARGET_VS_GENERIC for r in sel),
        }
    log(f"converters: {len(rows)} timed in {time.monotonic() - t_start:.1f} s")
    return {
        "method": {"rounds": rounds, "batch_s": batch_s, "statistic": "best (minimum) ns/call over interleaved rounds"},
        "targets": {"vs_handwritten": TARGET_VS_HAND, "vs_generic": TARGET_VS_GENERIC},
        "rows": rows,
        "summary": summary,
        "sample_counters": counted,
    }


if __name__ == "__main__":
    import json

    from bench.common import generated_package

    res = run(generated_package())
    for r in res["rows"]:
        print(f"{r['mapping']:30s} {r['direction']:10s} gen {r['per_s']['generated']:>9,}/s  "
              f"hand {r['per_s']['handwritten']:>9,}/s  generic {r['per_s']['generic']:>9,}/s  "
              f"x{r['vs_handwritten']:.2f} hand  x{r['vs_generic']:.2f} generic  spread {r['spread_pct']}")
    print(json.dumps(res["summary"], indent=1))
