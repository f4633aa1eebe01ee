"""Part 1: wall time of `sam-codegen build` on the SAM spec and on synthetic specs of 1, 10, 30, 100, 300 and 1000
message types (bench/synthetic.py), against nunavut/pycyphal compiling the same DSDL alone.

Both are timed as the commands a developer runs, each a fresh process: ``sam-codegen build --spec S --out NEW``
into a folder that does not exist yet (so every file is written), and ``python -c "pycyphal.dsdl.compile(root,
[root, uavcan], output_directory=NEW)"`` on the DSDL root namespace that build emitted (only that namespace is
compiled; the standard ``uavcan`` types are lookup-only, as for the generator, whose DSDL check reads them too).
Both write to a tmpfs when the system has one (see _scratch): creating a file on this shared VM's disk takes
from 0.03 to 1.4 ms depending on other processes' I/O, which made the figure measure the disk's load.
``reps`` repetitions, build and compile alternating; each repetition goes round every size (forwards, then
backwards), so that a burst of load elsewhere slows one run of several sizes, not every run of one size. The
figure of a size is the minimum of its repetitions: on a shared machine other processes only ever add time, so
the fastest run is the least disturbed one (the median is kept beside it).

Growth: the margin m(N) = t(N) - t(1) (per-type time m(N) / N), and the exponent k of m(N) ~ N^k (k = 1:
linear), fitted by weighted least squares in log-log over every N > 1 (N = 10, 30, 100, 300, 1000). Two things
keep a disturbed run from bending it:
- t(N) is first lowered to the least time of any larger N (more types never take less time, and other processes
  only add time), so a slow t(1) cannot shrink every margin;
- a margin's error is an absolute part delta (how far a typical run of N <= 100 lies above that size's minimum,
  at least 10 ms) plus a relative one (3 %), so a point weighs 1 / ((delta / m)^2 + 0.03^2): sizes whose
  margin is within the noise of a process start count for little, and none is dropped.
The local exponents between neighbouring sizes are reported beside the fit.

An in-process breakdown by stage (YAML, parse, validate, each emitter, the pydsdl check, writing the tree) is
taken at N = 300 and at the largest N, with the cyclic GC paused as ``generate`` does.
"""

from __future__ import annotations

import itertools
import math
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

from bench.common import SPEC, TMP, log, median, ratio
from bench.synthetic import validate_spec, write_spec

SIZES = (1, 10, 30, 100, 300, 1000)
STAGE_SIZES = (300,)  # besides the largest
REL_NOISE = 0.03  # relative error of a margin (machine load)
MIN_ABS_NOISE = 0.01  # least absolute error of a margin, s (process start)
COMPILE = (
    "import sys, warnings; warnings.simplefilter('ignore'); import pycyphal.dsdl; from pathlib import Path; "
    "root = Path(sys.argv[1]); pycyphal.dsdl.compile(root, [root, Path(sys.argv[2])], output_directory=sys.argv[3])"
)


def _uavcan_root() -> Path:
    from sam_codegen.project.cyphal_path import dsdl_lookup_roots

    return next(r for r in dsdl_lookup_roots() if r.name == "uavcan")


def _codegen_cmd() -> list[str]:
    script = Path(sys.executable).parent / "sam-codegen"
    return [str(script)] if script.exists() else [sys.executable, "-m", "sam_codegen.cli"]


def _timed(cmd: list[str]) -> float:
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    dt = time.perf_counter() - t0
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed ({proc.returncode}):\n{proc.stderr[-3000:]}")
    return dt


def _fit_exponent(ns: list[int], ts: list[float], ws: list[float] | None = None) -> float:
    """Slope of log t over log n by (weighted) least squares."""
    pts = [(math.log(n), math.log(t), w) for n, t, w in zip(ns, ts, ws or [1.0] * len(ns), strict=True) if t > 0]
    if len(pts) < 2:
        return math.nan
    sw = sum(w for _, _, w in pts)
    mx = sum(w * x for x, _, w in pts) / sw
    my = sum(w * y for _, y, w in pts) / sw
    return sum(w * (x - mx) * (y - my) for x, y, w in pts) / sum(w * (x - mx) ** 2 for x, _, w in pts)


def _envelope(ts: list[float]) -> list[float]:
    """t(N) for ascending N, each lowered to the least time of any larger N: more types never take less time,
    and other processes only add time, so a size measured slower than a larger one was disturbed.

    >>> _envelope([0.54, 0.37, 0.43, 0.75])
    [0.37, 0.37, 0.43, 0.75]
    """
    out = list(ts)
    for i in range(len(out) - 2, -1, -1):
        out[i] = min(out[i], out[i + 1])
    return out


def _weights(margins: list[float], delta: float) -> list[float]:
    """1 / variance of log(margin) for an absolute error delta plus a relative one of REL_NOISE."""
    return [1.0 / ((delta / m) ** 2 + REL_NOISE**2) for m in margins]


def fit_growth(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """Growth of the synthetic rows' minimum times with N (see the module docstring); also sets each row's
    build_per_type_ms and compile_per_type_ms."""
    syn = sorted((r for r in rows if r["types"]), key=lambda r: r["types"])
    fit_n = [r["types"] for r in syn if r["types"] > 1]
    growth: dict[str, Any] = {}
    if syn and syn[0]["types"] == 1:
        for key, runs, per_row, name in (("build_s", "build_runs_s", "build_per_type_ms", "sam-codegen build"),
                                         ("pycyphal_compile_s", "compile_runs_s", "compile_per_type_ms",
                                          "pycyphal compile")):
            t = _envelope([r[key] for r in syn])
            marg = [max(1e-6, tn - t[0]) for tn in t[1:]]
            per_type_ms = {str(n): round(m / n * 1e3, 2) for n, m in zip(fit_n, marg, strict=True)}
            for r, ms in zip(syn[1:], per_type_ms.values(), strict=True):
                r[per_row] = ms
            # A margin's absolute error: how far a typical run of a small size lies above that size's minimum.
            delta = max(MIN_ABS_NOISE, median([median(r[runs]) - min(r[runs]) for r in syn if r["types"] <= 100]))
            weights = _weights(marg, delta)
            local = {f"{a}->{b}": round(math.log(mb / ma) / math.log(b / a), 2) if min(ma, mb) > 1e-6 else None
                     for (a, ma), (b, mb) in itertools.pairwise(zip(fit_n, marg, strict=True))}
            growth[name] = {"fixed_s": round(t[0], 3), "per_type_ms": per_type_ms, "fit_sizes": fit_n,
                            "fit_times_s": [round(x, 3) for x in t[1:]],
                            "fit_weights": [round(w / max(weights), 3) for w in weights],
                            "noise_s": round(delta, 3),
                            "fitted_exponent": round(_fit_exponent(fit_n, marg, weights), 2),
                            "local_exponents": local}
    return growth


def _scratch() -> Path:
    """Where specs and outputs go: a tmpfs (/dev/shm) when the system has one, else bench/results/tmp. Creating a
    file on this shared VM's disk took from 0.03 to 1.4 ms depending on other processes' I/O, so on the disk the
    2000 files of N = 1000 made the figure mostly a measure of the disk's load at that moment."""
    shm = Path("/dev/shm")
    if shm.is_dir() and os.access(shm, os.W_OK | os.X_OK):
        return shm / f"sam-bench-generator-{os.getuid()}"
    return TMP / "generator"


def stages(spec_path: Path) -> dict[str, float]:
    """Seconds per stage of `sam-codegen build`, in this process (imports warm, cyclic GC paused as in generate)."""
    import gc

    from sam_codegen import build
    from sam_codegen.build import verify_dsdl, write_atomically
    from sam_codegen.frontend.loader import parse_spec
    from sam_codegen.frontend.yaml_source import load_yaml
    from sam_codegen.targets.registry import EMITTERS
    from sam_codegen.validate.resolve import validate

    text = spec_path.read_text(encoding="utf-8")
    out: dict[str, float] = {}
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        t = time.perf_counter()
        tree = load_yaml(text, str(spec_path))
        out["YAML -> nodes with positions (one pass over the parser's events)"] = time.perf_counter() - t
        t = time.perf_counter()
        spec = parse_spec(tree, str(spec_path))
        out["parse (nodes -> model)"] = time.perf_counter() - t
        t = time.perf_counter()
        resolved = validate(spec)
        out["validate (cross-references, mapping rules)"] = time.perf_counter() - t
        files: dict[str, str] = {}
        for emit in EMITTERS:
            t = time.perf_counter()
            files.update(emit(resolved))
            out[f"emit {emit.__module__.rsplit('.', 1)[-1]}"] = time.perf_counter() - t
        t = time.perf_counter()
        verify_dsdl(resolved, files)
        batch = getattr(build, "DSDL_BATCH", None)
        per_call = f"{batch} types per call" if batch else "whole namespace in one call"
        out[f"verify_dsdl (pydsdl reads the emitted DSDL, {per_call})"] = time.perf_counter() - t
        target = _scratch() / f"stages-{spec_path.stem}"
        shutil.rmtree(target, ignore_errors=True)
        t = time.perf_counter()
        write_atomically(files, target)
        out["write the tree (write_atomically, every file)"] = time.perf_counter() - t
        shutil.rmtree(target, ignore_errors=True)
    finally:
        if was_enabled:
            gc.enable()
    return {k: round(v, 3) for k, v in out.items()}


def run(*, reps: int = 3, sizes: tuple[int, ...] = SIZES) -> dict[str, Any]:
    work = _scratch()
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    uavcan = _uavcan_root()
    cg = _codegen_cmd()
    specs: list[tuple[str, int | None, Path]] = [("SAM spec", None, SPEC)]
    for n in sizes:
        p = write_spec(n, work / "specs" / f"syn{n}.yaml")
        validate_spec(p)  # raises SpecError if the synthetic spec were not valid
        specs.append((f"synthetic {n}", n, p))
    rows: list[dict[str, Any]] = []
    t_start = time.monotonic()
    build_s: dict[str, list[float]] = {label: [] for label, _, _ in specs}
    compile_s: dict[str, list[float]] = {label: [] for label, _, _ in specs}
    root_name: dict[str, str] = {}
    files: dict[str, int] = {}
    # Repetitions go round the sizes (forwards, then backwards, ...) rather than one size at a time: a burst of
    # load from another process then slows one run of several sizes instead of every run of one size.
    for r in range(reps):
        for label, _, spec in specs if r % 2 == 0 else specs[::-1]:
            tag = label.replace(" ", "_")
            out = work / f"out-{tag}-{r}"
            build_s[label].append(_timed([*cg, "build", "--spec", str(spec), "--out", str(out)]))
            if label not in root_name:
                root_name[label] = next(p.name for p in (out / "dsdl").iterdir() if p.is_dir())
                files[label] = sum(1 for p in out.rglob("*") if p.is_file())
            cout = work / f"pyc-{tag}-{r}"
            compile_s[label].append(_timed([sys.executable, "-c", COMPILE, str(out / "dsdl" / root_name[label]),
                                            str(uavcan), str(cout)]))
            shutil.rmtree(cout, ignore_errors=True)
            shutil.rmtree(out, ignore_errors=True)
        log(f"  generator: repetition {r + 1} of {reps} done")
    for label, n, _ in specs:
        bs, cs = build_s[label], compile_s[label]
        b, c = min(bs), min(cs)
        rows.append({"spec": label, "types": n, "files_generated": files[label], "build_s": round(b, 3),
                     "build_median_s": round(median(bs), 3), "build_runs_s": [round(x, 3) for x in bs],
                     "pycyphal_compile_s": round(c, 3), "compile_median_s": round(median(cs), 3),
                     "compile_runs_s": [round(x, 3) for x in cs], "ratio_vs_pycyphal": round(ratio(b, c), 2)})
        log(f"  generator {label}: build {b:.2f} s, pycyphal compile {c:.2f} s (min of {reps})")
    growth = fit_growth(rows)
    biggest = max((r for r in specs if r[1]), key=lambda s: s[1] or 0, default=None)
    largest = biggest[1] if biggest else None
    by_size = {str(n): stages(path) for _, n, path in specs if n and (n in STAGE_SIZES or n == largest)}
    breakdown = by_size.get(str(largest), {})
    shutil.rmtree(work, ignore_errors=True)
    log(f"generator: done in {time.monotonic() - t_start:.1f} s")
    return {
        "method": {"reps": reps, "statistic": "minimum wall time of a fresh process",
                   "command": " ".join(cg) + " build --spec S --out NEW",
                   "reference": "python -c pycyphal.dsdl.compile(root, [root, uavcan])",
                   "outputs": str(work),
                   "fit": "weighted least squares of log(t(N) - t(1)) on log N over every N > 1, t(N) lowered to "
                          "the least time of any larger N, weight 1 / ((noise_s / margin)^2 + "
                          f"{REL_NOISE}^2)"},
        "rows": rows,
        "growth": growth,
        "stages_at_largest": {"types": largest, "seconds": breakdown},
        "stages_by_size": by_size,
    }


if __name__ == "__main__":
    import json

    print(json.dumps(run(reps=int(sys.argv[1]) if len(sys.argv) > 1 else 3), indent=1))
