"""The generated DroneCAN converters (convert_v0.py), exercised with dronecan's own objects and serializer.

Every DroneCAN mapping of SAM's spec and of tests/specs/ferry.yaml goes both ways with hypothesis: random dronecan
messages are sent through dronecan's transport (Transfer.to_frames / from_frames: payload packing, the multi-frame
CRC seeded by the data type signature, unpacking), converted to ROS, CDR-serialized by rclpy, converted back and sent
again; and random ROS messages the other way. Then the documented cases: int18 RPM 200000 -> 131071 and float16
inf -> 65504 saturated and counted, NaN and values beyond `reject` dropped and counted, tables, selections, items by
key, broadcast arrays built with exactly the elements named, and the type check of load_types().

dronecan.load_dsdl() replaces the process's type objects, and SAM's ROS package is usable only by a process started
with its library path: so the checks run in a child pytest (this file with SAM_V0_CONVERTERS_WORKER set, with
ROS_PYTHON_CHECK_FIELDS=1 so that rclpy checks every value the converters set); the parent builds and starts it.
"""

from __future__ import annotations

import importlib
import json
import math
import os
import sys
from pathlib import Path
from typing import Any

import pytest

ROOT = Path(__file__).resolve().parents[2]
SPECS = {"sam": ROOT / "spec" / "interfaces.yaml", "ferry": ROOT / "tests" / "specs" / "ferry.yaml"}
WORKER_ENV = "SAM_V0_CONVERTERS_WORKER"
WORKER = os.environ.get(WORKER_ENV)


# ============================================================================================ parent

if not WORKER:
    from helpers.ros_packages import built_prefix, missing_tools, run_child
    from helpers.runtime_support import domain_id

    @pytest.mark.ros
    @pytest.mark.slow
    @pytest.mark.skipif(missing_tools() is not None, reason=str(missing_tools()))
    @pytest.mark.parametrize("spec", sorted(SPECS))
    def test_v0_converters_with_dronecan(spec: str, tmp_path: Path) -> None:
        pytest.importorskip("dronecan")
        from sam_codegen.build import build
        from sam_codegen.project.ros_install import ros_packages_in_order

        generated = ROOT / "generated"
        if spec != "sam":  # its converters use installed ROS messages only
            generated = tmp_path / "generated"
            build(SPECS[spec], generated)
        prefix = built_prefix(ros_packages_in_order(ROOT / "generated" / "ros"))
        config = {"spec": str(SPECS[spec]), "generated": str(generated)}
        proc = run_child(["-m", "pytest", __file__, "-q", "-p", "no:cacheprovider", "--rootdir", str(ROOT),
                          "-W", "error::RuntimeWarning"], prefix, domain_id(60 + len(spec)),
                         {WORKER_ENV: json.dumps(config), "ROS_PYTHON_CHECK_FIELDS": "1"}, timeout=900)
        report = proc.stdout[-12000:] + proc.stderr[-4000:]
        assert proc.returncode == 0, f"worker tests for {spec} failed:\n{report}"
        assert " passed" in proc.stdout and " skipped" not in proc.stdout and " failed" not in proc.stdout, report


# ============================================================================================ worker

if WORKER:
    import dronecan
    import numpy as np
    from dronecan.transport import Transfer
    from hypothesis import HealthCheck, given, settings
    from hypothesis import strategies as st
    from rclpy.serialization import deserialize_message, serialize_message

    from sam_codegen.conversion_plan import FLOAT16_MAX, FLOAT32_MAX, TIME_US_MAX_TO_ROS
    from sam_codegen.frontend.loader import load_spec_file
    from sam_codegen.model.spec import DsdlStruct
    from sam_codegen.model.types import ROS_INT_RANGES, DsdlType
    from sam_codegen.validate.mapping_rules import Key, ResolvedMapping, Step
    from sam_codegen.validate.resolve import Resolved, validate

    CONFIG = json.loads(WORKER)
    GENERATED = Path(CONFIG["generated"])
    RESOLVED: Resolved = validate(load_spec_file(Path(CONFIG["spec"])))
    SPEC_NAME = RESOLVED.spec.vehicle
    sys.path.insert(0, str(GENERATED / "python"))
    convert = importlib.import_module(f"{SPEC_NAME}_bridge.convert_v0")
    tables = importlib.import_module(f"{SPEC_NAME}_bridge.tables")
    convert.load_types(GENERATED)
    MAPPINGS: dict[str, ResolvedMapping] = {rm.mapping.name: rm for rm in RESOLVED.dronecan_mappings}
    INFOS = {m.name: m for m in tables.DRONECAN_MAPPINGS}
    SETTINGS = settings(max_examples=int(os.environ.get("SAM_CONVERTERS_EXAMPLES", "60")), deadline=None,
                        database=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
    RECEIVE_NS = 1_700_000_000_123_456_789
    # rclpy's float32 check refuses +-FLT_MAX itself (ROS_PYTHON_CHECK_FIELDS=1): stay one float32 inside
    RCLPY_FLOAT32_MAX = float(np.nextafter(np.float32(FLOAT32_MAX), np.float32(0)))

    # ---------------------------------------------------------------------------------------- the wire

    def wire(msg: Any, source_node_id: int = 42) -> Any:
        """What a receiver gets: the message through dronecan's frames (CRC seeded by its signature) and back."""
        frames = Transfer(payload=msg, source_node_id=source_node_id, transfer_id=7).to_frames()
        received = Transfer()
        received.data_type_id = dronecan.get_dronecan_data_type(msg).default_dtid
        received.service_not_message = False
        received.from_frames(frames)
        return received.payload

    def ros_wire(msg: Any) -> Any:
        return deserialize_message(serialize_message(msg), type(msg))

    def plain(value: Any) -> Any:
        if hasattr(value, "tolist"):
            return value.tolist()
        if isinstance(value, dronecan.transport.ArrayValue) or isinstance(value, list):
            return [plain(v) for v in value]
        return value

    def v0_get(obj: Any, path: tuple) -> Any:
        for name, index in path:
            obj = getattr(obj, name)
            if isinstance(index, Key):
                obj = next(x for x in obj if getattr(x, index.field) == index.value)
            elif index is not None:
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

    def ros_object(msg: Any, path: tuple) -> Any:
        for name, index in path:
            msg = getattr(msg, name)
            if index is not None:
                msg = msg[index]
        return msg

    def ros_set(msg: Any, path: tuple, value: Any) -> None:
        *parents, (name, index) = path
        msg = ros_object(msg, tuple(parents))
        if index is None:
            setattr(msg, name, value)
        else:
            getattr(msg, name)[index] = value

    # ---------------------------------------------------------------------------------------- DroneCAN strategies

    def float_strategy(bits: int, lo: float = -math.inf, hi: float = math.inf) -> st.SearchStrategy[float]:
        """Finite floats of `bits` bits in [lo, hi] (the bounds moved inside to values of that width)."""
        bound = {16: FLOAT16_MAX, 32: RCLPY_FLOAT32_MAX, 64: sys.float_info.max}[bits]
        lo, hi = float_inside(max(float(lo), -bound), bits), float_inside(min(float(hi), bound), bits)
        return st.floats(lo, hi, allow_nan=False, allow_infinity=False, width=bits)

    def float_inside(bound: float, bits: int) -> float:
        """The value of `bits` bits nearest to `bound` on the side of 0."""
        if bits == 64:
            return bound
        kind = np.float16 if bits == 16 else np.float32
        f = kind(bound)
        if abs(float(f)) > abs(bound):
            f = np.nextafter(f, kind(0))
        return float(f)

    def scalar_strategy(t: DsdlType) -> st.SearchStrategy[Any]:
        if t.kind == "bool":
            return st.booleans()
        if t.kind in ("int", "uint"):
            return st.integers(*t.range)
        if t.kind == "float":
            return float_strategy(t.bits)
        return struct_strategy(RESOLVED.dronecan.get(t.composite), "", {})  # type: ignore[union-attr, arg-type]

    def field_strategy(t: DsdlType, path: str, overrides: dict[str, Any]) -> st.SearchStrategy[Any]:
        if path in overrides:
            return overrides[path]
        if t.array:
            low = t.capacity if t.array == "fixed" else 0
            return st.lists(scalar_strategy(t.element), min_size=low, max_size=t.capacity)
        if t.kind == "composite":
            return struct_strategy(RESOLVED.dronecan.get(t.composite), path + ".", overrides)  # type: ignore[union-attr, arg-type]
        return scalar_strategy(t)

    def struct_strategy(struct: DsdlStruct, prefix: str, overrides: dict[str, Any]) -> st.SearchStrategy[Any]:
        fields = {f.name: field_strategy(f.type, prefix + f.name, overrides)  # type: ignore[arg-type]
                  for f in struct.fields}
        return st.fixed_dictionaries(fields).map(lambda kwargs: dronecan.TYPENAMES[struct.name](**kwargs))

    def items_strategy(array: DsdlType, keys: list[Key], overrides: dict[str, Any], prefix: str
                       ) -> st.SearchStrategy[list[Any]]:
        """An array of composites holding one item per key (with the values the mapping's steps need), among
        random items of other keys, in a random order."""
        item = RESOLVED.dronecan.get(array.composite)  # type: ignore[union-attr, arg-type]
        ours = [struct_strategy(item, f"{prefix}[{key}].", {**overrides, f"{prefix}[{key}].{key.field}": st.just(
            key.value)}) for key in keys]
        key_field = item.field(keys[0].field).type  # type: ignore[union-attr]
        taken = {k.value for k in keys}
        other = struct_strategy(item, "", {keys[0].field: st.integers(*key_field.range).filter(  # type: ignore[union-attr]
            lambda v: v not in taken)})
        spare = (array.capacity or 0) - len(keys)
        return st.tuples(st.tuples(*ours), st.lists(other, max_size=min(spare, 3)), st.randoms()).map(
            lambda t: t[2].sample([*t[0], *t[1]], len(t[0]) + len(t[1])))

    def uavcan_strategy(rm: ResolvedMapping) -> st.SearchStrategy[Any]:
        """Random messages of the mapping (its selection, the elements it reads) whose conversion to ROS needs no
        rejection."""
        overrides: dict[str, Any] = {}
        for s in rm.steps:
            t = s.uavcan_type
            if t is None:
                continue
            if s.kind == "time":
                overrides[s.uavcan.removesuffix(".usec")] = st.integers(1, TIME_US_MAX_TO_ROS).map(
                    lambda us: dronecan.TYPENAMES["uavcan.Timestamp"](usec=us))
            elif s.kind == "table":
                overrides[s.uavcan] = st.sampled_from([k for k, _ in s.table])
            elif s.kind == "number" and t.kind == "float" and s.ros_type.base in ROS_INT_RANGES:  # round: true
                scale, offset = s.scale or 1.0, s.offset or 0.0
                r_lo, r_hi = ROS_INT_RANGES[s.ros_type.base]
                lo, hi = sorted(((r_lo - offset) / scale, (r_hi - offset) / scale))
                overrides[s.uavcan] = float_strategy(t.bits, lo, hi)  # saturation is a test case of its own
            elif s.limits is not None and s.kind == "number":
                scale, offset = s.scale or 1.0, s.offset or 0.0
                lo, hi = sorted(((s.limits[0] - offset) / scale, (s.limits[1] - offset) / scale))
                overrides[s.uavcan] = (
                    float_strategy(t.bits, lo, hi) if t.kind == "float"
                    else st.integers(max(t.range[0], math.ceil(lo)), min(t.range[1], math.floor(hi))))
        for path, _leaf, value in rm.select:
            overrides[".".join(n for n, _ in path)] = st.just(value)
        for array_path, uses in rm.elements.items():
            name = ".".join(n for n, _ in array_path)
            array = field_type(rm.dsdl_struct, array_path)
            if isinstance(uses[0], Key):
                overrides[name] = items_strategy(array, uses, overrides, name)
            else:
                overrides[name] = st.lists(scalar_strategy(array.element), min_size=max(uses) + 1,
                                           max_size=array.capacity)
        return struct_strategy(rm.dsdl_struct, "", overrides)

    def field_type(struct: DsdlStruct, path: tuple) -> DsdlType:
        t: Any = None
        for name, _ in path:
            f = struct.field(name)
            assert f is not None
            t = f.type
            if t.kind == "composite" and not t.array:
                struct = RESOLVED.dronecan.get(t.composite)  # type: ignore[union-attr, assignment]
        return t

    # ---------------------------------------------------------------------------------------- ROS strategies

    def ros_number_strategy(s: Step, ros_base: str, uav: DsdlType) -> st.SearchStrategy[Any]:
        """ROS values that fit the UAVCAN field after the inverse scale/offset (and inside the limits)."""
        if ros_base == "bool":
            return st.booleans()
        if uav.kind == "float":
            lo, hi = {16: (-FLOAT16_MAX, FLOAT16_MAX), 32: (-FLOAT32_MAX, FLOAT32_MAX)}.get(uav.bits, (-1e300, 1e300))
        else:
            lo, hi = uav.range
            lo, hi = (lo + 1, hi - 1) if s.scale is not None or s.offset is not None else (lo, hi)
        scale, offset = s.scale if s.scale is not None else 1.0, s.offset or 0.0
        lo, hi = sorted((lo * scale + offset, hi * scale + offset)) if (s.scale or s.offset) else (lo, hi)
        if s.limits is not None:
            lo, hi = max(lo, s.limits[0]), min(hi, s.limits[1])
        if ros_base in ROS_INT_RANGES:
            r_lo, r_hi = ROS_INT_RANGES[ros_base]
            return st.integers(max(math.ceil(lo), r_lo), min(math.floor(hi), r_hi))
        return float_strategy(32 if ros_base == "float32" else 64, lo, hi)

    def ros_value_strategy(s: Step) -> st.SearchStrategy[Any]:
        assert s.uavcan_type is not None
        if s.kind == "time":
            return st.tuples(st.integers(0, 2**31 - 1), st.integers(0, 999_999_999)).filter(
                lambda t: t[0] > 0 or t[1] >= 1000)  # 0 us means unknown
        if s.kind == "table":
            return st.sampled_from(sorted({v for _, v in s.table}))
        if s.kind == "number":
            return ros_number_strategy(s, s.ros_type.base, s.uavcan_type)
        element = ros_number_strategy(s, s.ros_type.base, s.uavcan_type.element)
        ros_cap, uav_cap = s.ros_type.capacity, s.uavcan_type.capacity or 0
        if s.uavcan_type.array == "fixed":
            return st.lists(element, min_size=uav_cap, max_size=uav_cap)
        if s.ros_type.array == "fixed":  # only zero padding beyond the UAVCAN bound
            zero = 0.0 if s.ros_type.base.startswith("float") else 0
            size = min(ros_cap or 0, uav_cap)
            return st.lists(element, min_size=size, max_size=size).map(lambda v: v + [zero] * ((ros_cap or 0) - len(v)))
        return st.lists(element, max_size=min(ros_cap or uav_cap, uav_cap))

    def ros_message_strategy(rm: ResolvedMapping) -> st.SearchStrategy[Any]:
        steps = [s for s in rm.steps if s.uavcan_path]
        package, name = rm.ros_message.full_name.split("/")
        cls = getattr(importlib.import_module(f"{package}.msg"), name)

        def build(values: list[Any]) -> Any:
            msg = cls()
            for s, value in zip(steps, values, strict=True):
                if s.kind == "time":
                    stamp = ros_object(msg, s.ros_path)
                    stamp.sec, stamp.nanosec = value
                else:
                    ros_set(msg, s.ros_path, value)
            return ros_wire(msg)

        return st.tuples(*[ros_value_strategy(s) for s in steps]).map(lambda values: build(list(values)))

    def quantum(s: Step, uav: DsdlType, x: float) -> float:
        """How far a ROS value may move through the UAVCAN type: half a step of the UAVCAN representation, and
        half a unit where the ROS side rounds (`round: true`)."""
        scale = abs(s.scale) if s.scale is not None else 1.0
        v = abs(x - (s.offset or 0.0)) / scale
        if uav.kind in ("int", "uint"):
            q = 0.5 if (s.scale is not None or s.offset is not None or s.ros_type.base.startswith("float")) else 0.0
        else:
            q = {16: v * 2**-11 + 2**-25, 32: v * 2**-24 + 2**-150}.get(uav.bits, v * 2**-53)
        ros_rounding = 0.5 if s.ros_type.base in ROS_INT_RANGES and uav.kind == "float" else (
            abs(x) * 2**-24 if s.ros_type.base == "float32" else abs(x) * 2**-52)
        return q * scale * (1 + 1e-9) + ros_rounding + 1e-300

    # ---------------------------------------------------------------------------------------- round trips

    def check_built(rm: ResolvedMapping, msg: Any) -> None:
        """What ROS->UAVCAN builds: the selection set, broadcast arrays with exactly the elements named."""
        for path, _, value in rm.select:
            assert v0_get(msg, path) == value, path
        for array_path, uses in rm.elements.items():
            array = v0_get(msg, array_path) if not isinstance(uses[0], Key) else list(
                getattr(msg, array_path[-1][0]))
            if isinstance(uses[0], Key):
                assert [getattr(item, uses[0].field) for item in array] == [k.value for k in uses]
            else:
                assert len(array) == max(uses) + 1

    @pytest.mark.parametrize("name", sorted(MAPPINGS))
    @SETTINGS
    @given(data=st.data())
    def test_uavcan_ros_uavcan(name: str, data: st.DataObject) -> None:
        """Random DroneCAN messages survive UAVCAN -> ROS -> UAVCAN: exactly for exact fields, else as
        documented; one more trip changes nothing on the ROS side."""
        rm, info = MAPPINGS[name], INFOS[name]
        to_ros, to_uavcan = convert.CONVERTERS[name]
        src = wire(data.draw(uavcan_strategy(rm), label="uavcan"))
        assert convert.MATCHES[name](src)
        stats = convert.ConversionStats()
        ros = to_ros(src, RECEIVE_NS, stats)
        assert ros is not None, stats.rejected
        ros = ros_wire(ros)
        back = to_uavcan(ros, stats)
        assert back is not None, stats.rejected
        back = wire(back)
        assert not stats.rejected
        assert convert.MATCHES[name](back)
        check_built(rm, back)
        exact = set(info.exact_uavcan_fields)
        for s in rm.steps:
            if not s.uavcan_path:
                continue
            before, after = v0_get(src, s.uavcan_path), v0_get(back, s.uavcan_path)
            if s.uavcan in exact:
                assert after == before, f"{s.uavcan}: {before!r} -> {ros_get(ros, s.ros_path)!r} -> {after!r}"
            elif s.kind == "table":
                inverse: dict[int, int] = {}
                for key, value in s.table:
                    inverse.setdefault(value, key)
                assert after == inverse[dict(s.table)[before]]
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
        uav = wire(uav)
        check_built(rm, uav)
        back = to_ros(uav, RECEIVE_NS, stats)
        assert back is not None, stats.rejected
        back = ros_wire(back)
        assert not stats.rejected
        for s in rm.steps:
            if not s.uavcan_path:
                continue
            before, after = ros_get(src, s.ros_path), ros_get(back, s.ros_path)
            what = f"{s.ros}: {before!r} -> {v0_get(uav, s.uavcan_path)!r} -> {after!r}"
            if s.kind == "time":
                assert after == (before[0], before[1] // 1000 * 1000), what
            elif s.kind == "table" or s.ros_type.base == "bool":
                assert after == before, what
            else:
                elem = s.uavcan_type.element if s.kind == "array" else s.uavcan_type  # type: ignore[union-attr]
                pairs = zip(before, after, strict=True) if s.kind == "array" else [(before, after)]
                for x, y in pairs:
                    assert abs(y - x) <= quantum(s, elem, x), what  # type: ignore[arg-type]

    def test_tables_describe_the_mappings() -> None:
        assert [m.name for m in tables.DRONECAN_MAPPINGS] == list(MAPPINGS) == list(convert.CONVERTERS)
        assert set(convert.MATCHES) == set(MAPPINGS)
        for name, rm in MAPPINGS.items():
            info = INFOS[name]
            assert info.linked_uavcan_fields == tuple(s.uavcan for s in rm.steps if s.uavcan_path)
            assert set(info.exact_uavcan_fields) <= set(info.linked_uavcan_fields)
            assert (getattr(convert, info.to_ros), getattr(convert, info.to_uavcan)) == convert.CONVERTERS[name]
            loaded = dronecan.TYPENAMES[info.data_type.name]
            assert (loaded.default_dtid, loaded.get_data_type_signature()) == (info.data_type.data_type_id,
                                                                               info.data_type.signature)

    def test_the_spec_types_are_loaded_as_generated() -> None:
        """load_types() loaded the spec's own types from generated/dsdl_v0: ids and signatures as in the tables."""
        assert convert.check_types() == []
        custom = [t for t in tables.DRONECAN_TYPES if t.custom]
        assert custom and {t.name for t in custom} <= {t.name for t in RESOLVED.dronecan_types}
        for t in tables.DRONECAN_TYPES:
            loaded = dronecan.TYPENAMES[t.name]
            assert (loaded.default_dtid, loaded.get_data_type_signature()) == (t.data_type_id, t.signature), t.name
            assert dronecan.DATATYPES[(t.data_type_id, loaded.KIND_MESSAGE)] is loaded

    def test_load_types_refuses_other_definitions(tmp_path: Path) -> None:
        """A definition of one of the types that differs from the generated one (a field more) is reported."""
        custom = next(t for t in RESOLVED.dronecan_types if t.data_type_id is not None)
        root = custom.name.split(".")[0]
        folder = tmp_path / "dsdl_v0" / root
        source = GENERATED / "dsdl_v0" / root
        for path in source.rglob("*.uavcan"):
            target = folder / path.relative_to(source)
            target.parent.mkdir(parents=True, exist_ok=True)
            text = path.read_text(encoding="utf-8")
            target.write_text(text + ("bool extra\n" if path.name == custom.file_name else ""), encoding="utf-8")
        try:
            with pytest.raises(RuntimeError, match=f"{custom.name} is loaded with data type id "
                                                   f"{custom.data_type_id} and signature 0x"):
                convert.load_types(tmp_path)
        finally:
            convert.load_types(GENERATED)
        assert convert.check_types() == []

    # ---------------------------------------------------------------------------------------- SAM cases

    if SPEC_NAME == "sam":
        from sam_msgs.msg import BallastAngles, PercentStamped, ThrusterAngles, ThrusterRPMs

        def T(name: str) -> Any:  # a type, as dronecan names them
            return dronecan.TYPENAMES[name]

        def test_rpm_saturates_to_int18_in_one_command_of_two_escs() -> None:
            stats = convert.ConversionStats()
            out = wire(convert.thruster_rpms_to_uavcan(ThrusterRPMs(thruster_1_rpm=200000, thruster_2_rpm=-200000),
                                                       stats))
            assert list(out.rpm) == [131071, -131072]
            assert stats.saturated == {"thruster_rpms.rpm[0]": 1, "thruster_rpms.rpm[1]": 1} and not stats.rejected
            out = wire(convert.thruster_rpms_to_uavcan(ThrusterRPMs(thruster_1_rpm=1500, thruster_2_rpm=-7), stats))
            assert list(out.rpm) == [1500, -7]  # ESC index 0 is thruster 1, exactly two elements
            assert sum(stats.saturated.values()) == 2
            assert INFOS["thruster_rpms"].elements == ("rpm[0]", "rpm[1]")
            assert INFOS["thruster_rpms"].destination_node_ids == frozenset({21, 22})

        def test_a_short_rpm_command_is_not_this_mapping() -> None:
            short = wire(T("uavcan.equipment.esc.RPMCommand")(rpm=[100]))
            assert not convert.MATCHES["thruster_rpms"](short)
            stats = convert.ConversionStats()
            assert convert.thruster_rpms_to_ros(short, RECEIVE_NS, stats) is None
            assert stats.rejected == {"thruster_rpms.rpm[1]": 1}
            four = wire(T("uavcan.equipment.esc.RPMCommand")(rpm=[1, 2, 3, 4]))  # a longer one is: it reads 0, 1
            msg = convert.thruster_rpms_to_ros(four, RECEIVE_NS, stats)
            assert (msg.thruster_1_rpm, msg.thruster_2_rpm) == (1, 2)

        def test_float16_infinity_saturates_in_an_actuator_item() -> None:
            stats = convert.ConversionStats()
            cmd = wire(convert.thrust_vector_to_uavcan(
                ThrusterAngles(thruster_vertical_radians=0.0625, thruster_horizontal_radians=math.inf), stats))
            items = {c.actuator_id: (c.command_type, c.command_value) for c in cmd.commands}
            assert items == {0: (1, 0.0625), 1: (1, 0.1199951171875)}  # the spec's limit (+-0.12) as float16
            assert stats.saturated == {"thrust_vector.commands[actuator_id=1].command_value": 1}
            cmd = wire(convert.ballast_to_uavcan(BallastAngles(weight_1_offset_radians=-math.inf), stats))
            assert [(c.actuator_id, c.command_value) for c in cmd.commands] == [(2, -1.5703125), (3, 0.0)]  # -1.5708

        def test_items_by_actuator_id_in_any_order() -> None:
            command = T("uavcan.equipment.actuator.Command")
            mixed = wire(T("uavcan.equipment.actuator.ArrayCommand")(commands=[
                command(actuator_id=5, command_type=0, command_value=0.5),
                command(actuator_id=9, command_type=0, command_value=0.1),
                command(actuator_id=4, command_type=0, command_value=0.25),
            ]))
            stats = convert.ConversionStats()
            assert convert.MATCHES["longitudinal_weight"](mixed) and convert.MATCHES["buoyancy_piston"](mixed)
            assert not convert.MATCHES["thrust_vector"](mixed) and not convert.MATCHES["ballast"](mixed)
            assert convert.longitudinal_weight_to_ros(mixed, RECEIVE_NS, stats).percent == 25.0
            assert convert.buoyancy_piston_to_ros(mixed, RECEIVE_NS, stats).percent == 50.0
            assert convert.ballast_to_ros(mixed, RECEIVE_NS, stats) is None
            assert stats.rejected == {"ballast.commands[actuator_id=2]": 1}

        def test_percent_limits_and_nan() -> None:
            stats = convert.ConversionStats()
            cmd = convert.longitudinal_weight_to_uavcan(PercentStamped(percent=150.0), stats)
            assert [(c.actuator_id, c.command_type, c.command_value) for c in cmd.commands] == [(4, 0, 1.0)]
            assert stats.saturated == {"longitudinal_weight.commands[actuator_id=4].command_value": 1}
            assert convert.buoyancy_piston_to_uavcan(PercentStamped(percent=math.nan), stats) is None
            assert stats.rejected == {"buoyancy_piston.commands[actuator_id=5].command_value": 1}

        def test_esc_status_selected_by_esc_index_and_temperature_rounded() -> None:
            status = T("uavcan.equipment.esc.Status")
            first = wire(status(esc_index=0, rpm=-1234, current=2.5, temperature=300.15), 21)
            second = wire(status(esc_index=1, rpm=99, temperature=10000.0), 22)
            assert convert.MATCHES["thruster_1_feedback"](first) and not convert.MATCHES["thruster_2_feedback"](first)
            assert convert.MATCHES["thruster_2_feedback"](second) and not convert.MATCHES["thruster_1_feedback"](second)
            stats = convert.ConversionStats()
            msg = convert.thruster_1_feedback_to_ros(first, RECEIVE_NS, stats)
            assert (msg.rpm, msg.current, msg.temperature_c) == (-1234, 2.5, 27)  # float16 300.25 K
            assert (msg.header.stamp.sec, msg.header.frame_id) == (1_700_000_000, "base_link")  # no device stamp
            assert convert.thruster_2_feedback_to_ros(second, RECEIVE_NS, stats).temperature_c == 255
            assert stats.saturated == {"thruster_2_feedback.temperature_c": 1}
            assert convert.thruster_1_feedback_to_ros(wire(status(esc_index=0, temperature=math.nan)),
                                                      RECEIVE_NS, stats) is None
            assert stats.rejected == {"thruster_1_feedback.temperature_c": 1}
            back = convert.thruster_2_feedback_to_uavcan(msg, stats)
            assert (back.esc_index, back.rpm, back.temperature) == (1, -1234, 300.25)  # its select; float16(300.15)

        def test_timestamp_zero_is_the_receive_time() -> None:
            stats = convert.ConversionStats()
            imu = wire(T("uavcan.equipment.ahrs.RawIMU")(timestamp=T("uavcan.Timestamp")(usec=0)))
            msg = convert.imu_to_ros(imu, RECEIVE_NS, stats)
            assert (msg.header.stamp.sec, msg.header.stamp.nanosec) == (1_700_000_000, 123_456_789)
            imu = wire(T("uavcan.equipment.ahrs.RawIMU")(timestamp=T("uavcan.Timestamp")(usec=1_234_567_891)))
            msg = convert.imu_to_ros(imu, RECEIVE_NS, stats)
            assert (msg.header.stamp.sec, msg.header.stamp.nanosec) == (1234, 567_891_000)
            assert list(msg.orientation_covariance[:2]) == [-1.0, 0.0]

        def test_custom_feedback_types_by_source_node() -> None:
            feedback = T("sam.actuator.PositionFeedback")
            msg = wire(feedback(timestamp=T("uavcan.Timestamp")(usec=5_000_000), percent=42.5,
                                encoder_count=2**24 - 1), 25)
            stats = convert.ConversionStats()
            ros = convert.longitudinal_weight_feedback_to_ros(msg, RECEIVE_NS, stats)
            assert (ros.percent, ros.encoder_count, ros.header.stamp.sec) == (42.5, 2**24 - 1, 5)
            assert INFOS["longitudinal_weight_feedback"].source_node_ids == frozenset({25})
            assert INFOS["buoyancy_piston_feedback"].source_node_ids == frozenset({26})

    # ---------------------------------------------------------------------------------------- ferry cases

    if SPEC_NAME == "ferry":
        from geometry_msgs.msg import Vector3
        from std_msgs.msg import Float64, UInt8

        def test_raw_command_of_three_escs_rejects_beyond_int14() -> None:
            stats = convert.ConversionStats()
            out = wire(convert.propellers_to_uavcan(Vector3(x=100.4, y=-8192.4, z=8191.0), stats))
            assert list(out.cmd) == [100, -8192, 8191] and not stats.rejected
            assert convert.propellers_to_uavcan(Vector3(x=0.0, y=1e6, z=0.0), stats) is None
            assert convert.propellers_to_uavcan(Vector3(x=math.nan), stats) is None
            assert stats.rejected == {"propellers.cmd[1]": 1, "propellers.cmd[0]": 1} and not stats.saturated

        def test_mode_table_with_select() -> None:
            stats = convert.ConversionStats()
            out = wire(convert.drive_2_mode_to_uavcan(UInt8(data=1), stats))
            assert (out.device_id, out.mode, out.enable) == (2, 5, True)
            assert convert.drive_1_mode_to_uavcan(UInt8(data=3), stats) is None  # no key gives 3
            assert stats.rejected == {"drive_1_mode.mode": 1}
            assert convert.MATCHES["drive_2_mode"](out) and not convert.MATCHES["drive_1_mode"](out)

        def test_ramp_limits_and_rudder_item() -> None:
            stats = convert.ConversionStats()
            out = wire(convert.ramp_to_uavcan(Float64(data=-3.0), stats))
            assert [(c.actuator_id, c.command_type, c.command_value) for c in out.commands] == [(9, 0, -1.0)]
            assert stats.saturated == {"ramp.commands[actuator_id=9].command_value": 1}

        def test_leak_items_nested_with_padding() -> None:
            state = dronecan.TYPENAMES["ferry.hull.LeakState"]
            report = wire(dronecan.TYPENAMES["ferry.hull.LeakReport"](
                device_id=4, pump_duty=1023, compartments=[
                    state(compartment=5, wet=True, level_mm=-3), state(compartment=1, wet=False, level_mm=1023)]), 40)
            stats = convert.ConversionStats()
            assert convert.MATCHES["leak_bow"](report) and convert.MATCHES["leak_stern_wet"](report)
            assert convert.leak_bow_to_ros(report, RECEIVE_NS, stats).range == pytest.approx(1.023)
            assert convert.leak_stern_wet_to_ros(report, RECEIVE_NS, stats).data is True
            other = wire(dronecan.TYPENAMES["ferry.hull.LeakReport"](device_id=3, compartments=[state(compartment=1)]))
            assert not convert.MATCHES["leak_bow"](other)  # another device's report
            assert not convert.MATCHES["leak_stern_wet"](other)  # compartment 5 missing

        def test_round_saturates_the_depth() -> None:
            measurement = dronecan.TYPENAMES["uavcan.equipment.range_sensor.Measurement"]
            stats = convert.ConversionStats()
            assert convert.depth_to_ros(wire(measurement(range=12.34)), RECEIVE_NS, stats).data == 1234
            assert convert.depth_to_ros(wire(measurement(range=-1.0)), RECEIVE_NS, stats).data == 0
            assert convert.depth_to_ros(wire(measurement(range=math.inf)), RECEIVE_NS, stats).data == 65535
            assert stats.saturated == {"depth.data": 2}
