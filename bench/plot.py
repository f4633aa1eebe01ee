"""The scaling curves of a results.json as one PNG (matplotlib, Agg backend).

    python -m bench.plot [bench/results/results.json] [bench/results/scaling.png]
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

from bench.common import RESULTS


def plot(results: dict[str, Any], out: Path) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 2, figsize=(13, 9.5))
    fig.suptitle(f"sam-codegen benchmark - {results.get('machine', {}).get('cpu', '?')}, "
                 f"{results.get('machine', {}).get('cores', '?')} cores - {results.get('machine', {}).get('date', '')}",
                 fontsize=11)

    gen = results.get("generator") or {}
    syn = [r for r in gen.get("rows", []) if r.get("types")]
    ax = axes[0][0]
    if syn:
        n = [r["types"] for r in syn]
        ax.loglog(n, [r["build_s"] for r in syn], "o-", label="sam-codegen build")
        ax.loglog(n, [r["pycyphal_compile_s"] for r in syn], "s--", label="pycyphal/nunavut compile (reference)")
        g = gen.get("growth", {}).get("sam-codegen build", {})
        if g:
            f = g["fixed_s"]
            per = g["per_type_ms"].get(str(max(n)), 0) / 1e3
            ax.loglog(n, [f + per * x for x in n], ":", color="grey", label="fixed + linear in N")
            ax.set_title(f"Generator wall time (fitted exponent of the per-type part: {g['fitted_exponent']})")
        sam = next((r for r in gen.get("rows", []) if not r.get("types")), None)
        if sam:
            ax.axhline(sam["build_s"], color="C2", lw=0.8, ls="-.", label=f"SAM spec: {sam['build_s']:.2f} s")
        ax.set_xlabel("message types in the spec (N)")
        ax.set_ylabel("seconds (minimum of the runs, fresh process)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)

    ax = axes[0][1]
    if syn and gen.get("growth"):
        for name, style in (("sam-codegen build", "o-"), ("pycyphal compile", "s--")):
            g = gen["growth"].get(name)
            if g:
                ns = sorted(int(k) for k in g["per_type_ms"])
                ax.semilogx(ns, [g["per_type_ms"][str(k)] for k in ns], style, label=name)
        ax.set_ylim(bottom=0)
        ax.set_title("Marginal cost per message type: (t(N) - t(1)) / N")
        ax.set_xlabel("message types in the spec (N)")
        ax.set_ylabel("ms per type")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)

    conv = results.get("converters") or {}
    ax = axes[1][0]
    rows = conv.get("rows", [])
    if rows:
        labels = [f"{r['mapping']}.{'ros' if r['direction'] == 'to_ros' else 'uav'}" for r in rows]
        x = range(len(rows))
        ax.bar([i - 0.27 for i in x], [r["per_s"]["generated"] / 1e3 for r in rows], 0.27, label="generated")
        ax.bar(list(x), [r["per_s"]["handwritten"] / 1e3 for r in rows], 0.27, label="hand-written (doc style)")
        ax.bar([i + 0.27 for i in x], [r["per_s"]["generic"] / 1e3 for r in rows], 0.27, label="generic copier")
        ax.set_xticks(list(x))
        ax.set_xticklabels(labels, rotation=90, fontsize=6)
        ax.set_yscale("log")
        ax.set_ylabel("thousand conversions / s")
        ax.set_title("Converters (best of interleaved rounds)")
        ax.legend(fontsize=8)
        ax.grid(True, axis="y", which="both", alpha=0.3)

    ax = axes[1][1]
    bridge = results.get("bridge") or {}
    plotted = False
    for i, kind in enumerate(("udp", "can")):
        mix = (bridge.get(kind) or {}).get("sensor_mix")
        if not mix:
            continue
        trials = sorted(mix["trials"], key=lambda t: t["k"])
        xs = [t["k"] for t in trials]
        delivered = [t["ros_msgs_received"] / max(1, t["ros_msgs_expected"]) * t["offered_msg_per_s"] for t in trials]
        ax.plot(xs, [t["target_msg_per_s"] for t in trials], ":", color=f"C{i}", alpha=0.6)
        ax.plot(xs, delivered, "o-", color=f"C{i}", label=f"{bridge[kind]['transport']}: delivered to ROS")
        for t, d in zip(trials, delivered, strict=True):
            if not t["sustained"]:
                ax.plot([t["k"]], [d], "x", color="red", ms=9)
        ax.axvline(mix["max_sustained_k"], color=f"C{i}", lw=0.8, ls="--")
        plotted = True
    if plotted:
        ax.set_xscale("log", base=2)
        ax.set_yscale("log")
        ax.set_xlabel("k: multiple of the spec's nominal sensor rates (226 msg/s)")
        ax.set_ylabel("msg/s (dotted: offered target; x: not sustained)")
        ax.set_title("SAM sensor mix through the bridge (dashed: largest sustained k)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout(rect=(0, 0, 1, 0.97))
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return out


if __name__ == "__main__":
    src = Path(sys.argv[1]) if len(sys.argv) > 1 else RESULTS / "results.json"
    dst = Path(sys.argv[2]) if len(sys.argv) > 2 else RESULTS / "scaling.png"
    print(plot(json.loads(src.read_text()), dst))
