"""Part 1: wall time of `sam-codegen build` on the SAM spec and on synthetic specs of 1, 10, 100 and 1000 message
types (bench/synthetic.py), against nunavut/pycyphal compiling the same DSDL alone.

Both are timed as the commands a developer runs, each a fresh process: ``sam-codegen build --spec S --out NEW``
into a folder that does not exist yet (so every file is written), and ``python -c "pycyphal.dsdl.compile(root,
[root, uavcan], output_directory=NEW)"`` on the DSDL root namespace that build emitted (only that namespace is
compiled; the standard ``uavcan`` types are lookup-only, as for the generator, whose DSDL check reads them too).
``reps`` repetitions, build and compile alternating; medians. Growth: per-type time = (t(N) - t(1)) / N, and the
exponent k of t(N) - t(1) ~ N^k fitted by least squares in log-log over the sizes whose t(N) - t(1) is at least
0.25 s (above the noise of a process start; N = 100, 300, 1000 here) (k = 1: linear).
An in-process breakdown by stage (YAML, parse, validate, each emitter, the pydsdl check) is taken once at the
largest N, with libyaml's composer beside PyYAML's pure-Python one.
"""

from __future__ import annotations

import itertools
import math
import shutil
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

from bench.common import SPEC, TMP, log, median, ratio
from bench.synthetic import validate_spec, write_spec

SIZES = (1, 10, 100, 300, 1000)
COMPILE = (
    "import sys, warnings; warnings.simplefilter('ignore'); import pycyphal.dsdl; from pathlib import Path; "
    "root = Path(sys.argv[1]); pycyphal.dsdl.compile(root, [root, Path(sys.argv[2])], output_directory=sys.argv[3])"
)


def _uavcan_root() -> Path:
    from sam_codegen.cyphal_path import dsdl_lookup_roots

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


def _fit_exponent(ns: list[int], ts: list[float]) -> float:
    pts = [(math.log(n), math.log(t)) for n, t in zip(ns, ts, strict=True) if t > 0]
    if len(pts) < 2:
        return math.nan
    mx = sum(x for x, _ in pts) / len(pts)
    my = sum(y for _, y in pts) / len(pts)
    return sum((x - mx) * (y - my) for x, y in pts) / sum((x - mx) ** 2 for x, _ in pts)


def stages(spec_path: Path) -> dict[str, float]:
    """Seconds per stage of generate(), in this process (imports warm)."""
    import yaml

    from sam_codegen.build import emitters, verify_dsdl
    from sam_codegen.spec_loader import parse_spec
    from sam_codegen.validate import validate
    from sam_codegen.yaml_source import _Converter

    text = spec_path.read_text(encoding="utf-8")
    out: dict[str, float] = {}
    t = time.perf_counter()
    node = yaml.compose(text, Loader=yaml.SafeLoader)
    out["YAML compose (PyYAML, pure Python: what the loader uses)"] = time.perf_counter() - t
    if getattr(yaml, "__with_libyaml__", False):
        t = time.perf_counter()
        yaml.compose(text, Loader=yaml.CSafeLoader)
        out["  for comparison: YAML compose with libyaml (CSafeLoader)"] = time.perf_counter() - t
    t = time.perf_counter()
    tree = _Converter(str(spec_path)).convert(node)
    spec = parse_spec(tree, str(spec_path))
    out["nodes with positions + parse"] = time.perf_counter() - t
    t = time.perf_counter()
    resolved = validate(spec)
    out["validate (cross-references, mapping rules)"] = time.perf_counter() - t
    files: dict[str, str] = {}
    for emit in emitters():
        t = time.perf_counter()
        files.update(emit(resolved))
        out[f"emit {emit.__module__.rsplit('.', 1)[-1]}"] = time.perf_counter() - t
    t = time.perf_counter()
    verify_dsdl(resolved, files)
    out["verify_dsdl (pydsdl reads the emitted DSDL)"] = time.perf_counter() - t
    return {k: round(v, 3) for k, v in out.items()}


def run(*, reps: int = 3, sizes: tuple[int, ...] = SIZES) -> dict[str, Any]:
    work = TMP / "generator"
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
    for label, n, spec in specs:
        build_s: list[float] = []
        compile_s: list[float] = []
        root_name = None
        files = 0
        for r in range(reps):
            out = work / f"out-{label.replace(' ', '_')}-{r}"
            build_s.append(_timed([*cg, "build", "--spec", str(spec), "--out", str(out)]))
            if root_name is None:
                root_name = next(p.name for p in (out / "dsdl").iterdir() if p.is_dir())
                files = sum(1 for p in out.rglob("*") if p.is_file())
            cout = work / f"pyc-{label.replace(' ', '_')}-{r}"
            compile_s.append(_timed([sys.executable, "-c", COMPILE, str(out / "dsdl" / root_name), str(uavcan),
                                     str(cout)]))
            shutil.rmtree(cout, ignore_errors=True)
            if r:
                shutil.rmtree(out, ignore_errors=True)
        b, c = median(build_s), median(compile_s)
        rows.append({"spec": label, "types": n, "files_generated": files, "build_s": round(b, 3),
                     "build_runs_s": [round(x, 3) for x in build_s], "pycyphal_compile_s": round(c, 3),
                     "compile_runs_s": [round(x, 3) for x in compile_s], "ratio_vs_pycyphal": round(ratio(b, c), 2)})
        log(f"  generator {label}: build {b:.2f} s, pycyphal compile {c:.2f} s")
    syn = [r for r in rows if r["types"]]
    base = next((r for r in syn if r["types"] == 1), None)
    fit_n = [r["types"] for r in syn if r["types"] and r["types"] > 1]
    growth: dict[str, Any] = {}
    if base is not None:
        for key, name in (("build_s", "sam-codegen build"), ("pycyphal_compile_s", "pycyphal compile")):
            marg = [max(1e-6, next(r[key] for r in syn if r["types"] == n) - base[key]) for n in fit_n]
            per_type_ms = {str(n): round(m / n * 1e3, 2) for n, m in zip(fit_n, marg, strict=True)}
            fit = [(n, m) for n, m in zip(fit_n, marg, strict=True) if m >= 0.25]
            local = {f"{a}->{b}": round(math.log(mb / ma) / math.log(b / a), 2)
                     for (a, ma), (b, mb) in itertools.pairwise(fit)}
            growth[name] = {"fixed_s": base[key], "per_type_ms": per_type_ms, "fit_sizes": [n for n, _ in fit],
                            "fitted_exponent": round(_fit_exponent([n for n, _ in fit], [m for _, m in fit]), 2),
                            "local_exponents": local}
        for r in syn:
            if r["types"] > 1:
                r["build_per_type_ms"] = round(max(0.0, r["build_s"] - base["build_s"]) / r["types"] * 1e3, 2)
                r["compile_per_type_ms"] = round(max(0.0, r["pycyphal_compile_s"] - base["pycyphal_compile_s"])
                                                 / r["types"] * 1e3, 2)
    biggest = max((r for r in specs if r[1]), key=lambda s: s[1] or 0, default=None)
    breakdown = stages(biggest[2]) if biggest else {}
    shutil.rmtree(work, ignore_errors=True)
    log(f"generator: done in {time.monotonic() - t_start:.1f} s")
    return {
        "method": {"reps": reps, "statistic": "median wall time of a fresh process", "command": " ".join(cg)
                   + " build --spec S --out NEW", "reference": "python -c pycyphal.dsdl.compile(root, [root, uavcan])"},
        "rows": rows,
        "growth": growth,
        "stages_at_largest": {"types": biggest[1] if biggest else None, "seconds": breakdown},
    }


if __name__ == "__main__":
    import json

    print(json.dumps(run(reps=int(sys.argv[1]) if len(sys.argv) > 1 else 3), indent=1))
