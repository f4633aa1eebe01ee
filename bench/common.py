"""Shared plumbing of the benchmarks: environment, the generated package, sample messages, statistics."""

from __future__ import annotations

import os

# Every process that may start rclpy keeps DDS discovery on loopback (must precede any rclpy import).
os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] or "LOCALHOST"

import math
import platform
import random
import statistics
import struct
import subprocess
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
BENCH = REPO / "bench"
RESULTS = BENCH / "results"
TMP = RESULTS / "tmp"  # git-ignored scratch space
SPEC = REPO / "spec" / "interfaces.yaml"


# A sequence number (below 2048**2) travels in the thrust vector's two float16 angles: each half as a float16
# normal's bit pattern 0x0400 + half (2**-14 .. 0.00025 rad), exact in float16, float32 and float64 and well inside
# the spec's limits (+-0.12 rad, which saturate anything larger).
def seq_angles(seq: int) -> tuple[float, float]:
    """The two angles of ``seq``.

    >>> [angles_seq(*seq_angles(s)) for s in (0, 1, 2047, 2048, 2048 * 2048 - 1)], max(seq_angles(2048 * 2048 - 1))
    ([0, 1, 2047, 2048, 4194303], 0.00024402141571044922)
    """
    hi, lo = divmod(seq, 2048)
    return (struct.unpack("<e", struct.pack("<H", 0x0400 + hi))[0],
            struct.unpack("<e", struct.pack("<H", 0x0400 + lo))[0])


def angles_seq(vertical: float, horizontal: float) -> int:
    """The sequence number of :func:`seq_angles`' two angles."""
    def half(x: float) -> int:
        return int(struct.unpack("<H", struct.pack("<e", float(x)))[0]) - 0x0400

    return half(vertical) * 2048 + half(horizontal)


def log(msg: str) -> None:
    print(f"[bench {time.strftime('%H:%M:%S')}] {msg}", file=sys.stderr, flush=True)


def median(xs: Sequence[float]) -> float:
    return float(statistics.median(xs)) if xs else math.nan


def percentile(xs: Sequence[float], q: float) -> float:
    """Nearest-rank percentile (q in 0..100) of a non-empty sequence."""
    if not xs:
        return math.nan
    s = sorted(xs)
    k = max(0, min(len(s) - 1, math.ceil(q / 100.0 * len(s)) - 1))
    return float(s[k])


def ratio(a: float, b: float) -> float:
    return a / b if b else math.nan


def generated_package() -> Any:
    """The repo's generated package with its DSDL compiled and on sys.path (before uavcan is imported)."""
    from sam_runtime.genpkg import GeneratedPackage

    gen = GeneratedPackage(REPO / "generated")
    gen.compile_dsdl()
    return gen


def machine() -> dict[str, Any]:
    """What the figures were taken on."""
    cpu = "?"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    mem_gib = math.nan
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemTotal:"):
                mem_gib = int(line.split()[1]) / 1024 / 1024
    except OSError:
        pass
    os_name = platform.platform()
    try:
        for line in Path("/etc/os-release").read_text().splitlines():
            if line.startswith("PRETTY_NAME="):
                os_name = line.split("=", 1)[1].strip('"')
    except OSError:
        pass
    from importlib.metadata import version

    def ver(dist: str) -> str:
        try:
            return version(dist)
        except Exception:
            return "?"

    commit = "?"
    try:
        commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=REPO, capture_output=True, text=True,
                                timeout=5).stdout.strip() or "?"
    except (OSError, subprocess.SubprocessError):
        pass
    return {
        "cpu": cpu,
        "cores": os.cpu_count(),
        "memory_gib": round(mem_gib, 1),
        "os": os_name,
        "kernel": platform.release(),
        "python": platform.python_version(),
        "packages": {d: ver(d) for d in ("pycyphal", "nunavut", "pydsdl", "python-can", "rclpy", "numpy",
                                          "dronecan")},
        "rmw": os.environ.get("RMW_IMPLEMENTATION", "rmw_fastrtps_cpp (default)"),
        "commit": commit,
        "date": time.strftime("%Y-%m-%d %H:%M:%S %Z"),
    }


# ----------------------------------------------------------------------------------------------- samples
def sample_uavcan(gen: Any, port: Any, seed: int = 0, t: float = 12.5) -> Any:
    """A realistic pycyphal object of a port's type: the simulator's generic values, then its SAM physics."""
    from sam_runtime.sim.simulator import PHYSICS, DeviceState, VehicleState, generic_fill, physics_key

    dtype = gen.dsdl_class(port)
    veh = VehicleState(rng=random.Random(seed))
    obj = dtype()
    generic_fill(obj, t, veh.now_us(), seed=port.subject_id)
    physics = PHYSICS.get(physics_key(port.dsdl_type))
    if physics is not None:
        physics(obj, DeviceState("bench", 0), veh, t, 0.01, veh.rng)
    if hasattr(obj, "percent"):
        obj.percent = 37.5  # commands within their limits: no saturation path in the timings
    if hasattr(obj, "rpm"):
        obj.rpm = 1234
    # As received: float16/float32 values rounded by the wire format.
    import pycyphal.dsdl

    return pycyphal.dsdl.deserialize(dtype, [memoryview(b"".join(pycyphal.dsdl.serialize(obj)))])


def plain(msg: Any) -> Any:
    """A ROS message or pycyphal object as nested dicts/lists of Python numbers (for equality checks)."""
    if hasattr(msg, "get_fields_and_field_types"):
        return {name: plain(getattr(msg, name)) for name in msg.get_fields_and_field_types()}
    if hasattr(msg, "_serialize_") or type(msg).__module__.split(".")[0] in ("sam", "uavcan"):
        import pycyphal.dsdl

        return pycyphal.dsdl.to_builtin(msg)
    if isinstance(msg, bytes | bytearray):
        return list(msg)
    if hasattr(msg, "tolist"):
        return msg.tolist()
    if isinstance(msg, list | tuple) or type(msg).__name__ == "array":
        return [plain(x) for x in msg]
    if isinstance(msg, float) and math.isnan(msg):
        return "nan"
    return msg


def same(a: Any, b: Any, rel: float = 1e-12) -> bool:
    """Deep equality with a relative tolerance on floats (NaN equals NaN)."""
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(same(a[k], b[k], rel) for k in a)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(same(x, y, rel) for x, y in zip(a, b, strict=True))
    if isinstance(a, bool) or isinstance(b, bool):
        return bool(a) == bool(b)
    if isinstance(a, int | float) and isinstance(b, int | float):
        if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
            return True
        return a == b or abs(a - b) <= rel * max(abs(a), abs(b))
    return a == b
