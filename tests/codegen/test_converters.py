"""The generated converters (convert.py), exercised with real classes: pycyphal-compiled DSDL and a built ROS package.

How the real classes are obtained
---------------------------------
A session fixture validates a spec, emits its DSDL, ROS package and Python bridge into a temporary folder,
compiles the DSDL (plus ``uavcan``) with ``sam_runtime.cyphal_io.dsdl_cache.ensure_compiled`` into the content-addressed
cache ``.cache/dsdl`` and builds the ROS package with CMake into a prefix cached by content under
``.cache/ros-prefix/<package>-<hash>`` (a rebuild only when the generated package changes; ~20 s per package).

A ROS package installed outside the venv is only usable by a process started with LD_LIBRARY_PATH set
(the loader reads it at start), so the checks that need the classes run in a child pytest: this same file,
started with ``ros_runtime_env(prefix)`` and ``SAM_CONVERTERS_WORKER`` set to the build's description. In
worker mode the module defines the round-trip tests (hypothesis) and the spec-specific checks; in the parent
they do not exist and one test per spec starts the child and shows its report when it fails.
Three specs are exercised: the SAM spec, tests/specs/rover.yaml (other widths, utf8/byte arrays, a nested
composite, a derived message, both out-of-range policies, uavcan_values) and tests/specs/tractor.yaml (void
padding, int3/int5/int7 arrays, per-element links into fixed arrays of composites, a table with a default).
"""

from __future__ import annotations

import importlib
import importlib.util
import json
import math
import os
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest
from helpers.ros_packages import built_prefix

from sam_codegen.frontend.loader import load_spec_file
from sam_codegen.targets import dsdl as emit_dsdl
from sam_codegen.targets import ros as emit_ros
from sam_codegen.targets.python import convert as emit_python
from sam_codegen.validate.resolve import Resolved, validate

ROOT = Path(__file__).resolve().parents[2]
SPECS = {"sam": ROOT / "spec" / "interfaces.yaml",
         "rover": Path(__file__).resolve().parents[1] / "specs" / "rover.yaml",
         "tractor": Path(__file__).resolve().parents[1] / "specs" / "tractor.yaml"}
WORKER_ENV = "SAM_CONVERTERS_WORKER"
WORKER = os.environ.get(WORKER_ENV)


# ============================================================================================ parent: build


def _missing_tools() -> str | None:
    if shutil.which("cmake") is None:
        return "cmake is not installed"
    for module, extra in (("rclpy", "runtime"), ("pycyphal", "runtime"), ("hypothesis", "test")):
        if importlib.util.find_spec(module) is None:
            return f"{module} is not installed (pip extra {extra!r})"
    if not (Path(sys.prefix) / "share" / "rosidl_default_generators" / "package.xml").is_file():
        return "rosidl_default_generators is not installed in this environment (pip extra 'rosbuild')"
    return None


needs_tools = pytest.mark.skipif(_missing_tools() is not None, reason=str(_missing_tools()))


def _write(files: dict[str, str], out: Path) -> None:
    for path, text in files.items():
        target = out / path
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text(text, encoding="utf-8")


def _build(spec: Path, out: Path) -> dict[str, str]:
    """Generate, compile and build one spec; returns the worker's configuration."""
    from sam_runtime.cyphal_io.dsdl_cache import ensure_compiled

    resolved = validate(load_spec_file(spec))
    for emitter in (emit_dsdl, emit_ros, emit_python):
        _write(emitter.emit(resolved), out / "generated")
    saved = list(sys.path)
    try:  # compiled here once (cached); the worker only activates the cache entry
        dsdl = ensure_compiled([out / "generated" / "dsdl" / resolved.spec.dsdl_root], ROOT / ".cache" / "dsdl")
    finally:
        sys.path[:] = saved
    prefix = built_prefix([out / "generated" / "ros" / resolved.spec.ros.name])
    return {"spec": str(spec), "python": str(out / "generated" / "python"), "dsdl": str(dsdl),
            "prefix": str(prefix), "package": f"{resolved.spec.vehicle}_bridge"}


@pytest.fixture(scope="session")
def built(tmp_path_factory: pytest.TempPathFactory) -> Any:
    cache: dict[str, dict[str, str]] = {}

    def get(name: str) -> dict[str, str]:
        if name not in cache:
            cache[name] = _build(SPECS[name], tmp_path_factory.mktemp(f"converters-{name}"))
        return cache[name]

    return get


if not WORKER:

    @pytest.mark.ros
    @pytest.mark.slow
    @needs_tools
    @pytest.mark.parametrize("check_fields", ["1", "0"], ids=["rclpy-checks", "fast-constructors"])
    @pytest.mark.parametrize("spec", sorted(SPECS))
    def test_converters_with_real_classes(spec: str, check_fields: str, built: Any) -> None:
        """Run this file's worker tests for `spec` in a child pytest that can load the built ROS package.

        Twice: with ROS_PYTHON_CHECK_FIELDS=1, rclpy's setters check every value the converters set (and the
        converters use the message classes); without, the converters' own fast constructors are in use.
        """
        from sam_codegen.project.ros_install import ros_runtime_env

        config = built(spec)
        env = ros_runtime_env(Path(config["prefix"]))
        env[WORKER_ENV] = json.dumps(config)
        env["ROS_PYTHON_CHECK_FIELDS"] = check_fields
        env.pop("PYTEST_ADDOPTS", None)
        proc = subprocess.run(
            [sys.executable, "-m", "pytest", __file__, "-q", "-p", "no:cacheprovider", "--rootdir", str(ROOT),
             "-W", "error::RuntimeWarning"],
            cwd=ROOT, env=env, capture_output=True, text=True, timeout=900, check=False,
        )
        report = proc.stdout[-12000:] + proc.stderr[-4000:]
        assert proc.returncode == 0, f"worker tests for {spec} failed:\n{report}"
        assert " passed" in proc.stdout and " skipped" not in proc.stdout, report


# ============================================================================================ worker

if WORKER:
    import numpy as np
    import pycyphal.dsdl
    from hypothesis import HealthCheck, given, settings
    from hypothesis import strategies as st
    from rclpy.serialization import deserialize_message, serialize_message

    from sam_codegen.conversion_plan import FLOAT16_MAX, FLOAT32_MAX, TIME_US_MAX_TO_ROS
    from sam_codegen.model.spec import DsdlStruct
    from sam_codegen.model.types import ROS_INT_RANGES, DsdlType
    from sam_codegen.targets.python.names import py_attr, py_class_name, py_module
    from sam_codegen.validate.mapping_rules import ResolvedMapping, Step

    CONFIG = json.loads(WORKER)
    RESOLVED: Resolved = validate(load_spec_file(Path(CONFIG["spec"])))
    SPEC_NAME = RESOLVED.spec.vehicle
    sys.path.insert(0, CONFIG["dsdl"])
    sys.path.insert(0, CONFIG["python"])
    convert = importlib.import_module(f"{CONFIG['package']}.convert")
    tables = importlib.import_module(f"{CONFIG['package']}.tables")
    MAPPINGS: dict[str, ResolvedMapping] = {rm.mapping.name: rm for rm in RESOLVED.mappings}
    INFOS = {m.name: m for m in tables.MAPPINGS}
    SETTINGS = settings(max_examples=int(os.environ.get("SAM_CONVERTERS_EXAMPLES", "60")), deadline=None, database=None,
                        suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
    RECEIVE_NS = 1_700_000_000_123_456_789

    # ---------------------------------------------------------------------------------------- classes

    def dsdl_class(struct: DsdlStruct) -> type:
        return getattr(importlib.import_module(py_module(struct.namespace)), py_class_name(struct))

    def ros_class(full_name: str) -> type:
        package, name = full_name.split("/")
        return getattr(importlib.import_module(f"{package}.msg"), name)

    def dsdl_wire(obj: Any) -> Any:
        """What the receiver of `obj` gets: serialized and deserialized by pycyphal."""
        return pycyphal.dsdl.deserialize(type(obj), list(pycyphal.dsdl.serialize(obj)))

    def ros_wire(msg: Any) -> Any:
        """What a ROS subscriber gets: CDR-serialized and deserialized by rclpy."""
        return deserialize_message(serialize_message(msg), type(msg))

    def plain(value: Any) -> Any:
        if isinstance(value, np.ndarray):
            return value.tolist()
        if isinstance(value, np.generic):
            return value.item()
        if hasattr(value, "tolist"):  # array.array
            return value.tolist()
        if isinstance(value, list):
            return [plain(v) for v in value]
        return value

    def dsdl_get(obj: Any, path: tuple) -> Any:
        for name, index in path:
            obj = getattr(obj, py_attr(name))
            if index is not None:
                obj = obj[index]
        return plain(obj)

    def ros_get(msg: Any, path: tuple) -> Any:
        for name, index in path:
            msg = getattr(msg, name)
            if index is not None:
                msg = msg[index]
        if hasattr(msg, "sec") and hasattr(msg, "nanosec"):
            return (msg.sec, msg.nanosec)
        return plain(msg)

    def ros_set(msg: Any, path: tuple, value: Any) -> None:
        *parents, (name, index) = path
        for parent, parent_index in parents:
            msg = getattr(msg, parent)
            if parent_index is not None:
                msg = msg[parent_index]
        if index is None:
            setattr(msg, name, value)
        else:
            getattr(msg, name)[index] = value

    # ---------------------------------------------------------------------------------------- strategies

    # rclpy's float32 setters check |x| <= 3.402823466e+38, a decimal just below FLT_MAX (3.4028234663852886e+38):
    # with ROS_PYTHON_CHECK_FIELDS=1 a float32 field refuses +-FLT_MAX itself (it still serializes fine, and the
    # fast constructors, the default, set it). The checked run stays inside rclpy's bound: the float32 below FLT_MAX.
    RCLPY_FLOAT32_MAX = float(np.nextafter(np.float32(FLOAT32_MAX), np.float32(0))) \
        if os.environ.get("ROS_PYTHON_CHECK_FIELDS") == "1" else FLOAT32_MAX

    def float_range_strategy(width: int, lo: float = -math.inf, hi: float = math.inf) -> st.SearchStrategy[float]:
        bound = {16: FLOAT16_MAX, 32: RCLPY_FLOAT32_MAX, 64: sys.float_info.max}[width]
        lo, hi = max(lo, -bound), min(hi, bound)
        if width < 64:  # a spec's limits (+-0.12) need not be floats of the width: the nearest ones inside them
            kind = np.float16 if width == 16 else np.float32
            f_lo, f_hi = kind(lo), kind(hi)
            lo = float(f_lo if f_lo >= lo else np.nextafter(f_lo, kind(math.inf)))
            hi = float(f_hi if f_hi <= hi else np.nextafter(f_hi, kind(-math.inf)))
        return st.floats(lo, hi, allow_nan=False, allow_infinity=False, width=width)

    def utf8_strategy(capacity: int) -> st.SearchStrategy[str]:
        """Text that fits `capacity` bytes of UTF-8; no NUL, which ends a ROS (CDR) string."""
        return st.text(st.characters(codec="utf-8", exclude_characters="\x00"), max_size=capacity).filter(
            lambda s: len(s.encode()) <= capacity)

    def dsdl_scalar_strategy(t: DsdlType) -> st.SearchStrategy[Any]:
        if t.kind == "bool":
            return st.booleans()
        if t.kind in ("int", "uint", "byte"):
            return st.integers(*t.range)
        if t.kind == "float":
            return float_range_strategy(t.bits)
        if t.kind == "composite":
            return struct_strategy(RESOLVED.dsdl.get(t.composite), "", {})  # type: ignore[arg-type]
        raise AssertionError(t)

    def dsdl_field_strategy(t: DsdlType, path: str, overrides: dict[str, Any]) -> st.SearchStrategy[Any]:
        if path in overrides:
            return overrides[path]
        if t.kind == "utf8":
            return utf8_strategy(t.capacity or 0).map(str.encode)
        if t.array:
            low = t.capacity if t.array == "fixed" else 0
            return st.lists(dsdl_scalar_strategy(t.element), min_size=low, max_size=t.capacity)
        if t.kind == "composite":
            return struct_strategy(RESOLVED.dsdl.get(t.composite), path + ".", overrides)  # type: ignore[arg-type]
        return dsdl_scalar_strategy(t)

    def struct_strategy(struct: DsdlStruct, prefix: str, overrides: dict[str, Any]) -> st.SearchStrategy[Any]:
        fields = {py_attr(f.name): dsdl_field_strategy(f.type, prefix + f.name, overrides)  # type: ignore[arg-type]
                  for f in struct.fields}
        return st.fixed_dictionaries(fields).map(lambda kwargs: dsdl_class(struct)(**kwargs))

    def uavcan_strategy(rm: ResolvedMapping) -> st.SearchStrategy[Any]:
        """Random valid UAVCAN objects whose conversion to ROS needs no saturation nor rejection."""
        overrides: dict[str, Any] = {}
        for s in rm.steps:
            if s.kind == "time":  # 0 means unknown (receive time), and Time holds int32 seconds
                overrides[s.uavcan] = st.integers(1, min(s.uavcan_type.range[1], TIME_US_MAX_TO_ROS))  # type: ignore[union-attr]
            elif s.kind == "table":
                overrides[s.uavcan] = st.sampled_from([k for k, _ in s.table])
            elif s.limits is not None:  # ROS -> UAVCAN keeps values inside the limits
                t = s.uavcan_type
                assert t is not None
                overrides[s.uavcan] = (float_range_strategy(t.bits, *s.limits) if t.kind == "float"
                                       else st.integers(max(t.range[0], math.ceil(s.limits[0])),
                                                        min(t.range[1], math.floor(s.limits[1]))))
        return struct_strategy(rm.dsdl_struct, "", overrides)

    def ros_number_strategy(s: Step, ros_base: str, uav: DsdlType) -> st.SearchStrategy[Any]:
        """ROS values that fit the UAVCAN field after the inverse scale/offset (and inside the limits)."""
        if ros_base == "bool":
            return st.booleans()
        if uav.kind == "float":
            lo, hi = {16: (-FLOAT16_MAX, FLOAT16_MAX), 32: (-FLOAT32_MAX, FLOAT32_MAX)}.get(uav.bits, (-1e300, 1e300))
        else:
            lo, hi = uav.range
            lo, hi = (lo + 1, hi - 1) if s.scale is not None or s.offset is not None else (lo, hi)
        if s.limits is not None:
            lo, hi = max(lo, s.limits[0]), min(hi, s.limits[1])
        scale, offset = s.scale if s.scale is not None else 1.0, s.offset or 0.0
        lo, hi = sorted((lo * scale + offset, hi * scale + offset)) if (s.scale or s.offset) else (lo, hi)
        if ros_base in ROS_INT_RANGES:
            r_lo, r_hi = ROS_INT_RANGES[ros_base]
            values = st.integers(max(math.ceil(lo), r_lo), min(math.floor(hi), r_hi))
            return values.map(lambda v: bytes((v,))) if ros_base == "byte" else values
        if ros_base == "float32":  # bounds a float32 holds, inside the range
            return float_range_strategy(32, float32_inside(lo), float32_inside(hi))
        return float_range_strategy(64, lo, hi)

    def float32_inside(bound: float) -> float:
        f = np.float32(bound)
        if abs(float(f)) > abs(bound):
            f = np.nextafter(f, np.float32(0))
        return float(f)

    def ros_value_strategy(s: Step) -> st.SearchStrategy[Any]:
        assert s.uavcan_type is not None
        if s.kind == "time":
            return st.tuples(st.integers(0, 2**31 - 1), st.integers(0, 999_999_999)).filter(
                lambda t: t[0] > 0 or t[1] >= 1000)  # 0 us means unknown
        if s.kind == "table":
            return st.sampled_from(sorted({v for _, v in s.table}))
        if s.kind == "string":
            capacity = s.uavcan_type.capacity or 0
            return utf8_strategy(min(capacity, s.ros_type.string_bound or capacity))
        if s.kind == "number":
            return ros_number_strategy(s, s.ros_type.base, s.uavcan_type)
        element = ros_number_strategy(s, s.ros_type.base, s.uavcan_type.element)
        ros_cap, uav_cap = s.ros_type.capacity, s.uavcan_type.capacity or 0
        if s.uavcan_type.array == "fixed":
            return st.lists(element, min_size=uav_cap, max_size=uav_cap)
        if s.ros_type.array == "fixed":  # only zero padding beyond the UAVCAN bound
            base = s.ros_type.base
            zero = b"\x00" if base == "byte" else False if base == "bool" else 0.0 if base.startswith("float") else 0
            size = min(ros_cap or 0, uav_cap)
            return st.lists(element, min_size=size, max_size=size).map(
                lambda v: v + [zero] * ((ros_cap or 0) - len(v)))
        return st.lists(element, max_size=min(ros_cap or uav_cap, uav_cap))

    def ros_message_strategy(rm: ResolvedMapping) -> st.SearchStrategy[tuple[Any, dict[str, Any]]]:
        steps = [s for s in rm.steps if s.uavcan_path]
        cls = ros_class(rm.ros_message.full_name)

        def build(values: list[Any]) -> Any:
            msg = cls()
            for s, value in zip(steps, values, strict=True):
                if s.kind == "time":
                    stamp = ros_get_object(msg, s.ros_path)
                    stamp.sec, stamp.nanosec = value
                else:
                    ros_set(msg, s.ros_path, value)
            return ros_wire(msg)

        return st.tuples(*[ros_value_strategy(s) for s in steps]).map(lambda values: build(list(values)))

    def ros_get_object(msg: Any, path: tuple) -> Any:
        for name, index in path:
            msg = getattr(msg, name)
            if index is not None:
                msg = msg[index]
        return msg

    # ---------------------------------------------------------------------------------------- round trips

    def quantum(s: Step, uav: DsdlType, x: float) -> float:
        """How far a ROS value may move through the UAVCAN type: half a step of the UAVCAN representation."""
        scale = abs(s.scale) if s.scale is not None else 1.0
        v = abs(x - (s.offset or 0.0)) / scale
        if uav.kind in ("int", "uint", "byte"):
            # a fraction (scaled, or a ROS float) is rounded to the nearest integer
            q = 0.5 if (s.scale is not None or s.offset is not None or s.ros_type.base.startswith("float")) else 0.0
        else:
            q = {16: v * 2**-11 + 2**-25, 32: v * 2**-24 + 2**-150}.get(uav.bits, v * 2**-53)
        ros_rounding = abs(x) * 2**-24 if s.ros_type.base == "float32" else abs(x) * 2**-52
        return q * scale * (1 + 1e-9) + ros_rounding + 1e-300

    @pytest.mark.parametrize("name", sorted(MAPPINGS))
    @SETTINGS
    @given(data=st.data())
    def test_uavcan_ros_uavcan(name: str, data: st.DataObject) -> None:
        """Random UAVCAN values survive UAVCAN -> ROS -> UAVCAN: exactly for exact fields, else as documented."""
        rm, info = MAPPINGS[name], INFOS[name]
        to_ros, to_uavcan = convert.CONVERTERS[name]
        src = dsdl_wire(data.draw(uavcan_strategy(rm), label="uavcan"))
        stats = convert.ConversionStats()
        ros = to_ros(src, RECEIVE_NS, stats)
        assert ros is not None, stats.rejected
        ros = ros_wire(ros)
        back = to_uavcan(ros, stats)
        assert back is not None, stats.rejected
        back = dsdl_wire(back)
        assert not stats.rejected
        exact = set(info.exact_uavcan_fields)
        for s in rm.steps:
            if not s.uavcan_path:
                continue
            before, after = dsdl_get(src, s.uavcan_path), dsdl_get(back, s.uavcan_path)
            if s.uavcan in exact:
                assert after == before, f"{s.uavcan}: {before!r} -> {ros_get(ros, s.ros_path)!r} -> {after!r}"
            elif s.kind == "table":
                inverse: dict[int, int] = {}
                for key, value in s.table:
                    inverse.setdefault(value, key)
                assert after == inverse[dict(s.table)[before]]
            elif s.kind == "array" and s.ros_type.array == "fixed" and s.uavcan_type.array == "bounded":  # type: ignore[union-attr]
                padded = before + [0] * (min(s.ros_type.capacity, s.uavcan_type.capacity) - len(before))  # type: ignore[operator, type-var]
                assert after == padded, f"{s.uavcan}: {before!r} -> {after!r}"
        # Whatever the relation, one more trip changes nothing on the ROS side.
        again = ros_wire(to_ros(back, RECEIVE_NS, stats))
        for s in rm.steps:
            assert ros_get(again, s.ros_path) == ros_get(ros, s.ros_path) or s.kind == "value", s.ros

    @pytest.mark.parametrize("name", sorted(MAPPINGS))
    @SETTINGS
    @given(data=st.data())
    def test_ros_uavcan_ros(name: str, data: st.DataObject) -> None:
        """Random ROS values that fit survive ROS -> UAVCAN -> ROS within the UAVCAN type's precision."""
        rm = MAPPINGS[name]
        to_ros, to_uavcan = convert.CONVERTERS[name]
        src = data.draw(ros_message_strategy(rm), label="ros")
        stats = convert.ConversionStats()
        uav = to_uavcan(src, stats)
        assert uav is not None, stats.rejected
        back = to_ros(dsdl_wire(uav), RECEIVE_NS, stats)
        assert back is not None, stats.rejected
        back = ros_wire(back)
        assert not stats.rejected
        for s in rm.steps:
            if not s.uavcan_path:
                continue
            before, after = ros_get(src, s.ros_path), ros_get(back, s.ros_path)
            what = f"{s.ros}: {before!r} -> {dsdl_get(uav, s.uavcan_path)!r} -> {after!r}"
            if s.kind == "time":
                assert after == (before[0], before[1] // 1000 * 1000), what
            elif s.kind in ("table", "string") or s.ros_type.base in ("bool", "byte"):
                assert after == before, what
            else:
                elem = s.uavcan_type.element if s.kind == "array" else s.uavcan_type  # type: ignore[union-attr]
                pairs = zip(before, after, strict=True) if s.kind == "array" else [(before, after)]
                for x, y in pairs:
                    assert abs(y - x) <= quantum(s, elem, x), what  # type: ignore[arg-type]

    def test_tables_describe_the_mappings() -> None:
        for name, rm in MAPPINGS.items():
            info = INFOS[name]
            assert info.linked_uavcan_fields == tuple(s.uavcan for s in rm.steps if s.uavcan_path)
            assert set(info.exact_uavcan_fields) <= set(info.linked_uavcan_fields)
            assert (getattr(convert, info.to_ros), getattr(convert, info.to_uavcan)) == convert.CONVERTERS[name]
            assert dsdl_class(rm.dsdl_struct) is getattr(importlib.import_module(info.port.dsdl_module),
                                                          info.port.dsdl_class)
            assert ros_class(rm.ros_message.full_name) is getattr(importlib.import_module(info.topic.ros_module),
                                                                  info.topic.ros_class)

    # ---------------------------------------------------------------------------------------- constructors

    def test_fast_constructors_in_use_unless_rclpy_checks_fields() -> None:
        assert convert.FAST_CONSTRUCTORS is (os.environ.get("ROS_PYTHON_CHECK_FIELDS") != "1")

    def with_class_constructors() -> Any:
        """A second copy of convert.py whose converters build messages with the message classes."""
        # In the same package, for its relative import of conversion_support.
        spec = importlib.util.spec_from_file_location(f"{convert.__package__}._classes_convert", convert.__file__)
        assert spec is not None and spec.loader is not None
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        assert module._FACTORIES
        for new, cls in module._FACTORIES:
            setattr(module, new.__name__, cls)
        return module

    CLASSES = with_class_constructors()

    @pytest.mark.parametrize("name", sorted(MAPPINGS))
    @SETTINGS
    @given(data=st.data())
    def test_fast_constructors_build_what_the_classes_build(name: str, data: st.DataObject) -> None:
        """Same message, slot by slot and on the wire, whichever way convert.py constructs it."""
        src = dsdl_wire(data.draw(uavcan_strategy(MAPPINGS[name]), label="uavcan"))
        fast = convert.CONVERTERS[name][0](src, RECEIVE_NS, convert.ConversionStats())
        slow = CLASSES.CONVERTERS[name][0](src, RECEIVE_NS, CLASSES.ConversionStats())
        assert type(fast) is type(slow)
        assert convert._same(fast, slow), (fast, slow)
        assert convert._same(ros_wire(fast), ros_wire(slow))  # (CDR padding bytes are not zeroed: no byte compare)

    @pytest.mark.parametrize("name", sorted(MAPPINGS))
    @SETTINGS
    @given(data=st.data())
    def test_fast_constructors_build_what_the_pycyphal_classes_build(name: str, data: st.DataObject) -> None:
        src = data.draw(ros_message_strategy(MAPPINGS[name]), label="ros")
        fast = convert.CONVERTERS[name][1](src, convert.ConversionStats())
        slow = CLASSES.CONVERTERS[name][1](src, CLASSES.ConversionStats())
        assert convert._same(fast, slow), (fast, slow)
        assert bytes(b"".join(pycyphal.dsdl.serialize(fast))) == bytes(b"".join(pycyphal.dsdl.serialize(slow)))

    # ---------------------------------------------------------------------------------------- SAM checks

    if SPEC_NAME == "sam":
        import sam.actuator
        import sam.power
        import sam.sensor
        import uavcan.time
        from sam_msgs.msg import BallastAngles, PercentStamped, ThrusterAngles, ThrusterRPMs
        from sensor_msgs.msg import BatteryState, Imu, NavSatFix

        def test_rpm_saturates_to_int18_and_is_counted() -> None:
            stats = convert.ConversionStats()
            out = convert.thruster_1_rpm_to_uavcan(ThrusterRPMs(thruster_1_rpm=200000, thruster_2_rpm=5), stats)
            assert out.rpm == 131071
            assert stats.saturated == {"thruster_1_rpm.rpm": 1} and not stats.rejected
            out = convert.thruster_2_rpm_to_uavcan(ThrusterRPMs(thruster_1_rpm=0, thruster_2_rpm=-200000), stats)
            assert out.rpm == -131072
            assert stats.saturated == {"thruster_1_rpm.rpm": 1, "thruster_2_rpm.rpm": 1}
            out = convert.thruster_1_rpm_to_uavcan(ThrusterRPMs(thruster_1_rpm=-131072), stats)
            assert out.rpm == -131072 and sum(stats.saturated.values()) == 2
            assert dsdl_wire(out).rpm == -131072

        def test_nan_into_an_integer_is_rejected_and_counted() -> None:
            stats = convert.ConversionStats()
            fix = NavSatFix(latitude=math.nan, longitude=11.5, altitude=3.0)
            fix.status.status = 0
            assert convert.gps_fix_to_uavcan(fix, stats) is None
            assert stats.rejected == {"gps_fix.latitude_deg_1e8": 1}
            battery = BatteryState(voltage=12.0, percentage=math.nan)
            assert convert.battery_state_to_uavcan(battery, stats) is None
            assert stats.rejected["battery_state.state_of_charge_pct"] == 1
            fix.latitude = math.inf  # infinity is out of range: saturated, not rejected
            assert convert.gps_fix_to_uavcan(fix, stats).latitude_deg_1e8 == 2**36 - 1
            assert stats.saturated == {"gps_fix.latitude_deg_1e8": 1}

        def test_percent_is_limited_to_0_100_and_counted() -> None:
            stats = convert.ConversionStats()
            assert convert.longitudinal_weight_to_uavcan(PercentStamped(percent=150.0), stats).percent == 100.0
            assert convert.buoyancy_piston_to_uavcan(PercentStamped(percent=-3.0), stats).percent == 0.0
            assert convert.buoyancy_piston_to_uavcan(PercentStamped(percent=42.5), stats).percent == 42.5
            assert stats.saturated == {"longitudinal_weight.percent": 1, "buoyancy_piston.percent": 1}
            assert convert.longitudinal_weight_to_uavcan(PercentStamped(percent=math.nan), stats) is None
            assert stats.rejected == {"longitudinal_weight.percent": 1}

        def test_timestamp_zero_is_the_receive_time() -> None:
            stats = convert.ConversionStats()
            imu = sam.sensor.RawIMU_0_1(timestamp=uavcan.time.SynchronizedTimestamp_1_0(microsecond=0))
            msg = convert.imu_to_ros(imu, RECEIVE_NS, stats)
            assert (msg.header.stamp.sec, msg.header.stamp.nanosec) == (1_700_000_000, 123_456_789)
            assert msg.header.frame_id == "imu_link"
            imu.timestamp.microsecond = 1_234_567_891
            msg = convert.imu_to_ros(imu, RECEIVE_NS, stats)
            assert (msg.header.stamp.sec, msg.header.stamp.nanosec) == (1234, 567_891_000)
            assert list(msg.orientation_covariance[:2]) == [-1.0, 0.0]  # REP 145: no orientation
            # Beyond what builtin_interfaces/Time holds (2038): saturated and counted.
            imu.timestamp.microsecond = 2**56 - 1
            msg = convert.imu_to_ros(imu, RECEIVE_NS, stats)
            assert (msg.header.stamp.sec, msg.header.stamp.nanosec) == (2**31 - 1, 999_999_999)
            assert stats.saturated == {"imu.header.stamp": 1}
            # A mapping without a timestamp stamps with the receive time.
            cmd = convert.thruster_1_rpm_to_ros(sam.actuator.ThrusterRPM_0_1(rpm=-5), RECEIVE_NS, stats)
            assert (cmd.header.stamp.sec, cmd.header.stamp.nanosec, cmd.thruster_1_rpm) == (1_700_000_000,
                                                                                           123_456_789, -5)
            # Negative ROS time cannot be a UAVCAN microsecond count.
            imu_msg = Imu()
            imu_msg.header.stamp.sec = -5
            assert convert.imu_to_uavcan(imu_msg, stats).timestamp.microsecond == 0
            assert stats.saturated["imu.timestamp.microsecond"] == 1

        def test_magnetic_field_gauss_to_tesla() -> None:
            stats = convert.ConversionStats()
            src = sam.sensor.MagneticFieldStrength_0_1(magnetic_field_ga=[0.5, -0.25, 1.0],
                                                       magnetic_field_covariance=[1.0, 2.0, 4.0])
            msg = ros_wire(convert.magnetic_field_to_ros(src, RECEIVE_NS, stats))
            assert (msg.magnetic_field.x, msg.magnetic_field.y, msg.magnetic_field.z) == (0.5e-4, -0.25e-4, 1e-4)
            assert list(msg.magnetic_field_covariance) == [1e-8, 2e-8, 4e-8] + [0.0] * 6
            assert msg.header.frame_id == "magnetometer_link"
            back = dsdl_wire(convert.magnetic_field_to_uavcan(msg, stats))
            assert back.magnetic_field_ga.tolist() == [0.5, -0.25, 1.0]
            assert back.magnetic_field_covariance.tolist() == [1.0, 2.0, 4.0] + [0.0] * 6
            msg.magnetic_field.x = 10.0  # 100000 Gauss: beyond float16
            assert convert.magnetic_field_to_uavcan(msg, stats).magnetic_field_ga[0] == 65504.0
            assert stats.saturated == {"magnetic_field.magnetic_field_ga[0]": 1} and not stats.rejected

        def test_gnss_status_table() -> None:
            stats = convert.ConversionStats()
            got = {}
            for status in range(4):
                src = sam.sensor.GNSSFix_0_1(status=status, latitude_deg_1e8=5_934_800_000,
                                             longitude_deg_1e8=1_807_000_000, height_ellipsoid_mm=-1500)
                msg = convert.gps_fix_to_ros(src, RECEIVE_NS, stats)
                got[status] = msg.status.status
            assert got == {0: -1, 1: -1, 2: 0, 3: 0}
            assert (msg.latitude, msg.longitude, msg.altitude) == (59.348, 18.07, -1.5)
            assert (msg.status.service, msg.position_covariance_type) == (1, 3)
            fix = NavSatFix()
            for ros_status, uav_status in ((-1, 0), (0, 2)):  # the first UAVCAN value of each ROS value
                fix.status.status = ros_status
                assert convert.gps_fix_to_uavcan(fix, stats).status == uav_status
            assert not stats.saturated and not stats.rejected
            fix.status.status = 2  # STATUS_GBAS_FIX: no UAVCAN value maps to it
            assert convert.gps_fix_to_uavcan(fix, stats) is None
            assert stats.rejected == {"gps_fix.status": 1}

        def test_float16_saturation_and_nan() -> None:
            stats = convert.ConversionStats()
            # out of range and +-inf saturate to the spec's limits (the nozzle's +-0.12 rad; issue 29: no longer
            # float16's +-65504 rad)
            out = convert.thrust_vector_to_uavcan(
                ThrusterAngles(thruster_vertical_radians=1e6, thruster_horizontal_radians=-math.inf), stats)
            assert (out.vertical_radians, out.horizontal_radians) == (0.12, -0.12)  # (float16 on the wire)
            assert stats.saturated == {"thrust_vector.vertical_radians": 1, "thrust_vector.horizontal_radians": 1}
            out = convert.ballast_to_uavcan(
                BallastAngles(weight_1_offset_radians=math.inf, weight_2_offset_radians=-2.0), stats)
            assert (out.weight_1_offset_radians, out.weight_2_offset_radians) == (1.5708, -1.5708)
            out = convert.thrust_vector_to_uavcan(ThrusterAngles(thruster_vertical_radians=0.0625), stats)
            assert out.vertical_radians == 0.0625  # inside: unchanged, not counted
            assert stats.saturated == {"thrust_vector.vertical_radians": 1, "thrust_vector.horizontal_radians": 1,
                                       "ballast.weight_1_offset_radians": 1, "ballast.weight_2_offset_radians": 1}
            # NaN is a float16 value, but no setpoint: a NaN command is rejected and counted (issue 29)
            assert convert.thrust_vector_to_uavcan(ThrusterAngles(thruster_vertical_radians=math.nan), stats) is None
            assert stats.rejected == {"thrust_vector.vertical_radians": 1}

        def test_battery_units_and_constants() -> None:
            stats = convert.ConversionStats()
            src = sam.power.BatteryInfo_0_1(temperature=300.0, voltage=16.5, current=-2.0, state_of_charge_pct=87,
                                            model_name="SAM pack")
            msg = ros_wire(convert.battery_state_to_ros(src, RECEIVE_NS, stats))
            assert msg.temperature == pytest.approx(26.85, abs=1e-4)  # Kelvin -> Celsius
            assert msg.percentage == pytest.approx(0.87)
            assert math.isnan(msg.charge) and math.isnan(msg.capacity) and msg.present
            info = ros_wire(convert.battery_info_to_ros(src, RECEIVE_NS, stats))
            assert bytes(info.model_name) == b"SAM pack" and info.state_of_charge_pct == 87
            back = convert.battery_state_to_uavcan(msg, stats)
            assert (back.temperature, back.state_of_charge_pct) == (pytest.approx(300.0, abs=0.2), 87)
            assert not stats.saturated and not stats.rejected

    # ---------------------------------------------------------------------------------------- rover checks

    if SPEC_NAME == "rover":
        import rover.drive
        import rover.light
        import rover.nav
        import rover.sensor
        from geometry_msgs.msg import Pose2D
        from rover_msgs.msg import DriveCommand, Environment, WheelStatus
        from std_msgs.msg import UInt8

        def drive_command(**fields: Any) -> Any:
            cmd = DriveCommand(wheel_speed=[0.5, -0.5, 1.25, 0.0], enable=True, gear=-1, max_accel=2.5,
                               steer_trim_deg=3.0, heading=1.5, payload=[b"\x01", b"\xff"], note="ok")
            for key, value in fields.items():
                setattr(cmd, key, value)
            return cmd

        def test_command_fields_and_uavcan_values() -> None:
            stats = convert.ConversionStats()
            out = dsdl_wire(convert.drive_command_to_uavcan(drive_command(), stats))
            assert out.wheel_speed_cm_s.tolist() == [50, -50, 125, 0]
            assert (out.enable, out.gear, out.max_accel, out.steer_trim, out.heading) == (True, 3, 2.5, 4, 1.5)
            assert out.payload.tobytes() == b"\x01\xff" and out.note.tobytes() == b"ok"
            assert (out.protocol, out.checked) == (3, True)  # uavcan_values
            assert not stats.saturated and not stats.rejected
            back = ros_wire(convert.drive_command_to_ros(out, RECEIVE_NS, stats))
            assert back.payload == [b"\x01", b"\xff"] and back.gear == -1 and back.steer_trim_deg == 3.0

        @pytest.mark.parametrize(("field", "value", "key"), [
            ("wheel_speed", [400.0, 0.0, 0.0, 0.0], "wheel_speed_cm_s"),  # 40000 cm/s > int16
            ("wheel_speed", [math.nan, 0.0, 0.0, 0.0], "wheel_speed_cm_s"),
            ("gear", 5, "gear"),  # not in the table
            ("max_accel", 7.0, "max_accel"),  # beyond the limits
            ("steer_trim_deg", 100.0, "steer_trim"),  # int5
            ("heading", 1e39, "heading"),  # beyond float32
            ("payload", [b"\x00"] * 9, "payload"),  # longer than the bound
            ("note", "ünïcödé text", "note"),  # 16 bytes of UTF-8 > utf8[<=12]
        ])
        def test_reject_policy_drops_the_message(field: str, value: Any, key: str) -> None:
            stats = convert.ConversionStats()
            assert convert.drive_command_to_uavcan(drive_command(**{field: value}), stats) is None
            assert stats.rejected == {f"drive_command.{key}": 1} and not stats.saturated

        def test_saturate_policy_and_constant() -> None:
            stats = convert.ConversionStats()
            out = dsdl_wire(convert.headlight_to_uavcan(UInt8(data=200), stats))
            assert (out.level, out.channel) == (7, 2)
            assert stats.saturated == {"headlight.level": 1}

        def test_status_widths_utf8_and_mangled_names() -> None:
            stats = convert.ConversionStats()
            src = dsdl_wire(rover.drive.WheelStatus_1_0(
                mode=rover.drive.WheelStatus_1_0.MODE_FAULT, trim=-16, odometer_mm=2**40 - 1, energy_uj=-(2**63),
                braking=True, wheel_rpm=[2047, -2048, 0, 1], currents=[1.5], raw=b"\x00\x7f", id_=65535,
                label=b"w\xffheel"))
            msg = ros_wire(convert.drive_status_to_ros(src, RECEIVE_NS, stats))
            assert (msg.mode, msg.trim, msg.odometer_mm, msg.energy_uj, msg.braking) == (7, -16, 2**40 - 1,
                                                                                         -(2**63), True)
            assert list(msg.wheel_rpm) == [2047, -2048, 0, 1] and list(msg.currents) == [1.5]
            assert list(msg.raw) == [0, 127] and msg.id == 65535  # `id` is `id_` in pycyphal
            assert msg.label == "w\ufffdheel"  # invalid UTF-8 is replaced, never an exception
            assert WheelStatus.MODE_FAULT == 7
            msg.label = "ß" * 9  # 18 bytes: cut at a character boundary
            msg.trim = 100
            back = convert.drive_status_to_uavcan(msg, stats)
            assert back.label.tobytes().decode() == "ß" * 8 and back.trim == 15 and back.id_ == 65535
            assert stats.saturated == {"drive_status.label": 1, "drive_status.trim": 1}

        def test_nested_composite_padding_and_offset() -> None:
            stats = convert.ConversionStats()
            pose = rover.nav.Pose_1_0(position=rover.common.Point_1_0(x=1.5, y=-2.25), yaw_mrad=-1571)
            msg = convert.pose_to_ros(pose, RECEIVE_NS, stats)
            assert (msg.x, msg.y, msg.theta) == (1.5, -2.25, pytest.approx(-1.571))
            back = convert.pose_to_uavcan(Pose2D(x=1e39, y=0.0, theta=0.0), stats)
            assert back.position.x == FLOAT32_MAX and stats.saturated == {"pose.position.x": 1}
            air = rover.sensor.Air_1_0(gas_halfppm=[2, 5], temperature=21.5, ok=True)
            env = convert.air_to_ros(air, RECEIVE_NS, stats)
            assert list(env.gas_ppm) == [1.0, 2.5, 0.0, 0.0] and env.header.frame_id == "air_sensor"
            back_air = convert.air_to_uavcan(Environment(gas_ppm=[1.0, 2.5, 0.0, 0.0]), stats)
            assert back_air.gas_halfppm.tolist() == [2, 5, 0, 0]
            thermo = convert.temperature_to_ros(rover.sensor.Thermo_1_0(temperature_dk=2981), RECEIVE_NS, stats)
            assert thermo.temperature == pytest.approx(24.95)
            assert convert.temperature_to_uavcan(thermo, stats).temperature_dk == 2981

    # ---------------------------------------------------------------------------------------- tractor checks

    if SPEC_NAME == "tractor":
        import tractor.hitch
        from tractor_msgs.msg import HitchCommand, Section

        def hitch_status(**fields: Any) -> Any:
            sections = [tractor.hitch.Section_1_0(rate=100 * (i + 1), open_=i != 1) for i in range(3)]
            values = {"state": 1, "tilt": [-16, -1, 0, 15], "trim": [-4, 3, 0, -1], "sections": sections, **fields}
            return dsdl_wire(tractor.hitch.Status_1_0(**values))

        def test_table_default_takes_the_values_the_table_does_not_list() -> None:
            stats = convert.ConversionStats()
            got = {state: convert.hitch_status_to_ros(hitch_status(state=state), RECEIVE_NS, stats).state
                   for state in range(8)}
            assert got == {0: 0, 1: 1, 2: 2, 3: 3, 4: -1, 5: -1, 6: -1, 7: -1}
            assert not stats.rejected and not stats.saturated  # nothing dropped: the default says what they are
            msg = convert.hitch_status_to_ros(hitch_status(state=5), RECEIVE_NS, stats)
            assert dsdl_wire(convert.hitch_status_to_uavcan(msg, stats)).state == 7  # -1: its first key

        def test_narrow_signed_arrays_and_elements_of_composite_arrays() -> None:
            stats = convert.ConversionStats()
            msg = ros_wire(convert.hitch_status_to_ros(hitch_status(), RECEIVE_NS, stats))
            assert list(msg.tilt) == [-16, -1, 0, 15] and list(msg.trim) == [-4, 3, 0, -1]
            assert (msg.left.rate, msg.left.open, msg.right_rate) == (100, True, 300)
            back = dsdl_wire(convert.hitch_status_to_uavcan(msg, stats))
            assert back.tilt.tolist() == [-16, -1, 0, 15] and back.trim.tolist() == [-4, 3, 0, -1]
            assert [(s.rate, s.open_) for s in back.sections] == [(100, True), (0, False), (300, False)]
            assert not stats.rejected and not stats.saturated

        def test_command_per_element_links_values_and_saturation() -> None:
            stats = convert.ConversionStats()
            cmd = HitchCommand(lift_pct=42.4, offsets=[-64, -1, 63], mode=-1,
                               sections=[Section(rate=4000, open=True), Section(rate=5000, open=False)])
            out = dsdl_wire(convert.hitch_command_to_uavcan(cmd, stats))
            assert (out.lift_pct, out.offsets.tolist(), out.mode) == (42, [-64, -1, 63], 3)
            assert [(s.rate, s.open_) for s in out.sections] == [(4000, True), (4095, True)]  # uavcan_values
            assert stats.saturated == {"hitch_command.sections[1].rate": 1} and not stats.rejected
            cmd.offsets = [-100, 100]
            out = dsdl_wire(convert.hitch_command_to_uavcan(cmd, stats))
            assert out.offsets.tolist() == [-64, 63] and stats.saturated["hitch_command.offsets"] == 1
            cmd.mode = 5  # no key gives ROS 5: the command is rejected, not guessed
            assert convert.hitch_command_to_uavcan(cmd, stats) is None
            assert stats.rejected == {"hitch_command.mode": 1}
