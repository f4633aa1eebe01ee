"""The child-process half of tests/test_codec_v0.py (imported there in the child, with SAM_CODEC_V0_WORKER set;
anywhere else this module is empty): the property tests of one spec's generated DroneCAN wire codecs against the
object path, in a process with ROS messages.

The object path is what the bridge runs without the codecs: dronecan decodes the payload (``_unpack`` with tail
array optimisation, as ``Transfer.from_frames`` for classic CAN), the generated converter converts, rclpy serializes;
and the other way deserialize, convert, ``Transfer(payload=obj).payload``.
"""

from __future__ import annotations

import os

WORKER = os.environ.get("SAM_CODEC_V0_WORKER")

if WORKER:
    import importlib
    import json
    import math
    import random
    import struct
    from pathlib import Path
    from typing import Any

    import dronecan
    import pytest
    from dronecan import dsdl, transport
    from hypothesis import HealthCheck, given, settings
    from hypothesis import strategies as st
    from rclpy.serialization import deserialize_message, serialize_message

    from helpers.codec_support import FRAME_PREFIXES, with_frame_prefix
    from sam_codegen.frontend.loader import load_spec_file
    from sam_codegen.model.spec import RosMessage
    from sam_codegen.model.types import ROS_INT_RANGES, RosType
    from sam_codegen.validate.mapping_rules import Key, ResolvedMapping
    from sam_codegen.validate.resolve import Resolved, validate
    from sam_runtime.genpkg import GeneratedPackage, bound_codec

    CONFIG = json.loads(WORKER)
    RESOLVED: Resolved = validate(load_spec_file(Path(CONFIG["spec"])))
    VEHICLE = RESOLVED.spec.vehicle
    GEN = GeneratedPackage(Path(CONFIG["generated"]), f"{VEHICLE}_bridge")
    convert = GEN.convert_v0()  # the spec's own v0 types added beside dronecan's (ensure_types), never reloaded
    codec = GEN.codec("dronecan")
    assert codec is not None
    BOUND = {p: bound_codec(codec, p) for p in FRAME_PREFIXES}  # as a namespaced bridge takes it
    MAPPINGS: dict[str, ResolvedMapping] = {rm.mapping.name: rm for rm in RESOLVED.dronecan_mappings}
    SETTINGS = settings(max_examples=int(os.environ.get("SAM_CODEC_EXAMPLES", "80")), deadline=None, database=None,
                        suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
    RECEIVE_NS = 1_700_000_000_123_456_789


    def ros_class(full_name: str) -> type:
        package, name = full_name.split("/")
        return getattr(importlib.import_module(f"{package}.msg"), name)


    # ---------------------------------------------------------------------------------------- comparisons


    def same(a: Any, b: Any) -> bool:
        """Equal, NaN equal to NaN, through ROS messages, lists and numpy arrays."""
        if hasattr(a, "get_fields_and_field_types"):
            fields = a.get_fields_and_field_types()
            return type(a) is type(b) and all(same(getattr(a, f), getattr(b, f)) for f in fields)
        if hasattr(a, "tolist"):
            a = a.tolist()
        if hasattr(b, "tolist"):
            b = b.tolist()
        if isinstance(a, (list, tuple)):
            return isinstance(b, (list, tuple)) and len(a) == len(b) and all(
                same(x, y) for x, y in zip(a, b, strict=True))
        if isinstance(a, float) and isinstance(b, float) and math.isnan(a):
            return math.isnan(b)
        return a == b


    def stamp_of(msg: Any) -> int:
        header = getattr(msg, "header", None)
        if header is None:
            return -1
        return header.stamp.sec * 1_000_000_000 + header.stamp.nanosec


    def counts(stats: Any) -> tuple[dict[str, int], dict[str, int]]:
        return dict(stats.saturated), dict(stats.rejected)


    # ---------------------------------------------------------------------------------------- DroneCAN values


    def v0_scalar(t: Any, rng: random.Random) -> Any:
        if t.kind == t.KIND_BOOLEAN:
            return rng.random() < 0.5
        lo, hi = t.value_range
        if t.kind == t.KIND_FLOAT:
            return rng.choice([0.0, -0.0, 1.0, -2.5, math.nan, lo, hi, 6e-8, 3e-5, 0.1, 273.15, 300.15, 1234.5,
                               rng.uniform(-100.0, 100.0), rng.uniform(lo, hi), rng.uniform(-70000.0, 70000.0)])
        lo, hi = int(lo), int(hi)
        return rng.choice([0, 1, lo, hi, rng.randint(lo, hi), rng.randint(max(lo, -300), min(hi, 300))])


    def v0_value(t: Any, rng: random.Random) -> Any:
        if isinstance(t, dsdl.PrimitiveType):
            return v0_scalar(t, rng)
        if isinstance(t, dsdl.ArrayType):
            sizes = [t.max_size] if t.mode == t.MODE_STATIC else [0, 1, 2, rng.randint(0, t.max_size), t.max_size]
            n = min(t.max_size, rng.choice(sizes))
            return [v0_value(t.value_type, rng) for _ in range(n)]
        obj = transport.CompoundValue(t)
        if not t.union:
            for f in t.fields:
                if not isinstance(f.type, dsdl.VoidType):
                    setattr(obj, f.name, v0_value(f.type, rng))
        return obj


    def v0_get(obj: Any, path: tuple) -> Any:
        for name, _ in path[:-1]:
            obj = getattr(obj, name)
        return obj


    def make_it_match(rm: ResolvedMapping, obj: Any, rng: random.Random) -> None:
        """The mapping's selection values set, the elements and items it reads there (by key: among others)."""
        for path, _, value in rm.select:
            setattr(v0_get(obj, path), path[-1][0], value)
        for array_path, uses in rm.elements.items():
            if any(i is not None for _, i in array_path):
                continue
            parent, name = v0_get(obj, array_path), array_path[-1][0]
            array = getattr(parent, name)
            items = list(array)
            t = array._type
            if isinstance(uses[0], Key):
                for key in uses:
                    if any(getattr(item, key.field) == key.value for item in items):
                        continue
                    item = v0_value(t.value_type, rng)
                    setattr(item, key.field, key.value)
                    if len(items) >= t.max_size:  # replace one that is not the only item of a key read
                        held = [getattr(it, key.field) for it in items]
                        keys = {k.value for k in uses}
                        items[rng.choice([i for i, v in enumerate(held) if v not in keys or held.count(v) > 1])] = item
                    else:
                        items.insert(rng.randint(0, len(items)), item)
            else:
                while len(items) <= max(uses):
                    items.append(v0_value(t.value_type, rng))
            setattr(parent, name, items)


    def mutated(payload: bytes, rng: random.Random) -> bytes:
        how = rng.randrange(5)
        if how == 0:
            return payload[:rng.randint(0, len(payload))]
        if how == 1:
            return payload + bytes(rng.getrandbits(8) for _ in range(rng.randint(1, 40)))
        if how == 2 and payload:
            data = bytearray(payload)
            for _ in range(rng.randint(1, 3)):
                data[rng.randrange(len(data))] ^= 1 << rng.randrange(8)
            return bytes(data)
        if how == 3:
            return payload[:-1] if payload else payload
        return bytes(rng.getrandbits(8) for _ in range(rng.randint(0, 64)))


    def payloads(rm: ResolvedMapping) -> st.SearchStrategy[bytes]:
        """Payloads of the mapping's type: dronecan's bytes of random messages, mostly the mapping's (selection and
        elements there), a fifth of them cut, extended, flipped or random."""
        dtype = dronecan.TYPENAMES[rm.dsdl_struct.name]

        def build(rng: random.Random) -> bytes:
            obj = v0_value(dtype, rng)
            if rng.random() < 0.85:
                make_it_match(rm, obj, rng)
            payload = bytes(transport.Transfer(payload=obj).payload)  # classic CAN: tail array optimisation
            return mutated(payload, rng) if rng.random() < 0.2 else payload

        return st.randoms(use_true_random=False).map(build)


    def dronecan_decode(rm: ResolvedMapping, payload: bytes) -> Any:
        obj = dronecan.TYPENAMES[rm.dsdl_struct.name]()
        obj._unpack(transport.bits_from_bytes(bytearray(payload)), True)
        return obj


    # ---------------------------------------------------------------------------------------- ROS values


    def ros_scalar(base: str, rng: random.Random) -> Any:
        if base == "bool":
            return rng.random() < 0.5
        if base == "byte":
            return bytes((rng.randrange(256),))
        if base == "string":
            return rng.choice(["", "base_link", "x" * rng.randint(1, 9), "é\u20ac", "a\0b"])
        if base in ROS_INT_RANGES:
            lo, hi = ROS_INT_RANGES[base]
            return rng.choice([0, 1, lo, hi, rng.randint(lo, hi), rng.randint(max(lo, -70000), min(hi, 70000)),
                               rng.randint(max(lo, -3), min(hi, 300))])
        value = rng.choice([0.0, -0.0, 1.0, -1.5, math.nan, math.inf, -math.inf, 65504.0, 65520.0, 1e-8, 0.25, 300.15,
                            rng.uniform(-2.0, 2.0), rng.uniform(-1e5, 1e5), rng.uniform(-1e40, 1e40), 1e300, -1e300])
        if base == "float32":  # a float32 value (rclpy would round it)
            try:
                value = struct.unpack("<f", struct.pack("<f", value))[0]
            except OverflowError:
                value = math.copysign(math.inf, value)
        return value


    def ros_value(t: RosType, rng: random.Random) -> Any:
        if t.array:
            # (an unbounded sequence up to 20: beyond a UAVCAN array of 15 it converts into, the cut is counted)
            n = t.capacity if t.array == "fixed" else rng.choice([0, 1, 2, 3, rng.randint(0, t.capacity or 20)])
            return [ros_value(t.element, rng) for _ in range(n or 0)]
        if t.is_primitive:
            return ros_scalar(t.base, rng)
        return ros_message(RESOLVED.ros.get(t.base), rng)  # type: ignore[arg-type]


    def ros_message(message: RosMessage, rng: random.Random) -> Any:
        msg = ros_class(message.full_name)()
        for f in message.fields:
            setattr(msg, f.name, ros_value(f.type, rng))  # type: ignore[arg-type]
        return msg


    def cdrs(rm: ResolvedMapping) -> st.SearchStrategy[bytes]:
        return st.randoms(use_true_random=False).map(lambda rng: serialize_message(ros_message(rm.ros_message, rng)))


    # ---------------------------------------------------------------------------------------- the properties


    @pytest.mark.parametrize("name", sorted(MAPPINGS))
    @SETTINGS
    @given(data=st.data())
    def test_wire_to_ros_is_the_object_path(name: str, data: st.DataObject) -> None:
        """(a), (c): the CDR of the converter's message, its stamp, the same counts; WireError exactly where the object
        path refuses the payload; WIRE_MATCHES as MATCHES."""
        rm = MAPPINGS[name]
        to_ros = convert.CONVERTERS[name][0]
        wire_to_ros = codec.CODECS[name][0]
        payload = data.draw(payloads(rm), label="payload")
        expected, actual = convert.ConversionStats(), convert.ConversionStats()
        try:
            obj = dronecan_decode(rm, payload)
        except Exception:  # dronecan refuses it
            with pytest.raises(codec.WireError):
                wire_to_ros(payload, RECEIVE_NS, actual)
            if name in codec.WIRE_MATCHES:
                with pytest.raises(codec.WireError):
                    codec.WIRE_MATCHES[name](payload)
            return
        if name in codec.WIRE_MATCHES:
            assert codec.WIRE_MATCHES[name](payload) == convert.MATCHES[name](obj)
        else:
            assert convert.MATCHES[name].__name__ == "_always"
        msg = to_ros(obj, RECEIVE_NS, expected)
        try:
            cdr = serialize_message(msg) if msg is not None else None
        except Exception:  # an array beyond its ROS bound: rclpy refuses the message
            with pytest.raises(codec.WireError):
                wire_to_ros(payload, RECEIVE_NS, actual)
            return
        out = wire_to_ros(payload, RECEIVE_NS, actual)
        assert counts(actual) == counts(expected)
        for view in (memoryview(payload), bytearray(payload)):  # what a receiver may hand over
            assert same(wire_to_ros(view, RECEIVE_NS, convert.ConversionStats()), out)
        if msg is None:
            assert out is None
            return
        assert out is not None
        ours, stamp = out
        assert isinstance(ours, bytes) and stamp == stamp_of(msg)
        if ours != cdr:  # NaN payloads may differ; the values may not
            cls = type(msg)
            assert same(deserialize_message(ours, cls), deserialize_message(cdr, cls)), (ours.hex(), cdr.hex())


    @pytest.mark.parametrize("name", sorted(MAPPINGS))
    @SETTINGS
    @given(data=st.data())
    def test_ros_to_wire_is_the_object_path(name: str, data: st.DataObject) -> None:
        """(b): dronecan's bytes of the converter's message (or None), the same counts, for any ROS values."""
        rm = MAPPINGS[name]
        to_uavcan = convert.CONVERTERS[name][1]
        ros_to_wire = codec.CODECS[name][1]
        cdr = data.draw(cdrs(rm), label="cdr")
        expected, actual = convert.ConversionStats(), convert.ConversionStats()
        obj = to_uavcan(deserialize_message(cdr, ros_class(rm.ros_message.full_name)), expected)
        out = ros_to_wire(cdr, actual)
        assert counts(actual) == counts(expected)
        assert ros_to_wire(memoryview(cdr), convert.ConversionStats()) == out
        if obj is None:
            assert out is None
            return
        assert out == bytes(transport.Transfer(payload=obj).payload)


    @pytest.mark.parametrize("name", sorted(MAPPINGS))
    @SETTINGS
    @given(data=st.data())
    def test_bad_cdr_is_a_wire_error(name: str, data: st.DataObject) -> None:
        """(c): CDR cut short, or with bytes flipped or random: WireError where rclpy refuses it, else WireError or what
        the object path gives; never another exception. (rclpy is the laxer: a sequence count beyond the buffer it
        reports on stderr, "sequence size exceeds remaining buffer", and returns a partial message.)"""
        rm = MAPPINGS[name]
        ros_to_wire = codec.CODECS[name][1]
        cdr = data.draw(cdrs(rm), label="cdr")
        rng = data.draw(st.randoms(use_true_random=False), label="rng")
        how = rng.randrange(3)
        if how == 0:
            bad = cdr[:rng.randrange(len(cdr))]
        elif how == 1:
            flipped = bytearray(cdr)
            flipped[rng.randrange(len(cdr))] ^= 1 << rng.randrange(8)
            bad = bytes(flipped)
        else:
            bad = bytes(rng.getrandbits(8) for _ in range(rng.randint(0, 80)))
        try:
            msg = deserialize_message(bad, ros_class(rm.ros_message.full_name))
        except Exception:
            with pytest.raises(codec.WireError):
                ros_to_wire(bad, convert.ConversionStats())
            return
        try:
            out = ros_to_wire(bad, convert.ConversionStats())
        except codec.WireError:
            return  # stricter than rclpy: a count beyond the buffer, a string without its NUL, ...
        obj = convert.CONVERTERS[name][1](msg, convert.ConversionStats())
        assert out == (None if obj is None else bytes(transport.Transfer(payload=obj).payload))


    @pytest.mark.parametrize("name", sorted(MAPPINGS))
    @SETTINGS
    @given(data=st.data())
    def test_frame_prefixes_of_every_length(name: str, data: st.DataObject) -> None:
        """A namespaced run's codecs, bound to a frame prefix of each length modulo 8 (the padding after a frame id
        depends on it): UAVCAN -> ROS, the object path's message with the prefix before its frame ids (element
        headers' too), its stamp, the same counts, WireError where the object path refuses; ROS -> UAVCAN, the
        unbound codec's payload (no frame id is read)."""
        rm = MAPPINGS[name]
        to_ros = convert.CONVERTERS[name][0]
        payload = data.draw(payloads(rm), label="payload")
        cdr_in = data.draw(cdrs(rm), label="cdr")
        for prefix in FRAME_PREFIXES:
            bound = BOUND[prefix]
            assert bound.CODECS[name][1](cdr_in, convert.ConversionStats()) == \
                codec.CODECS[name][1](cdr_in, convert.ConversionStats())
            wire_to_ros = bound.CODECS[name][0]
            expected, actual = convert.ConversionStats(), convert.ConversionStats()
            try:
                obj = dronecan_decode(rm, payload)
                msg = to_ros(obj, RECEIVE_NS, expected)
                cdr = serialize_message(msg) if msg is not None else None
            except Exception:  # dronecan refuses it, or rclpy its values (an array beyond its ROS bound)
                with pytest.raises(codec.WireError):
                    wire_to_ros(payload, RECEIVE_NS, actual)
                continue
            out = wire_to_ros(payload, RECEIVE_NS, actual)
            assert counts(actual) == counts(expected)
            if msg is None:
                assert out is None
                continue
            assert out is not None and cdr is not None
            ours, stamp = out
            assert stamp == stamp_of(msg)
            cls = type(msg)
            want = with_frame_prefix(deserialize_message(cdr, cls), prefix)
            assert same(deserialize_message(ours, cls), want), (prefix, ours.hex(), cdr.hex())
            if msg is not None and getattr(msg, "header", None) is not None and msg.header.frame_id:
                assert deserialize_message(ours, cls).header.frame_id.startswith(prefix)

    def test_every_mapping_has_both_codecs() -> None:
        assert list(codec.CODECS) == list(MAPPINGS) == list(convert.CONVERTERS)
        assert set(codec.WIRE_MATCHES) == {n for n, f in convert.MATCHES.items() if f.__name__ != "_always"}


    # ---------------------------------------------------------------------------------------- SAM cases

    if VEHICLE == "sam":

        def T(name: str) -> Any:
            return dronecan.TYPENAMES[name]

        def payload_of(obj: Any) -> bytes:
            return bytes(transport.Transfer(payload=obj).payload)

        def test_a_tail_array_beyond_the_ros_bound_is_a_wire_error() -> None:
            """dronecan takes 40 bytes of model name (the tail array optimisation has no length); rclpy refuses to
            serialize them into uint8[<=31]: the codec refuses the payload."""
            payload = payload_of(T("uavcan.equipment.power.BatteryInfo")(model_name=list(range(31)))) + bytes(range(9))
            assert len(dronecan_decode(MAPPINGS["battery_info"], payload).model_name) == 40
            with pytest.raises(codec.WireError, match="model_name"):
                codec.battery_info_wire_to_ros(payload, RECEIVE_NS, convert.ConversionStats())
            out = codec.battery_state_wire_to_ros(payload, RECEIVE_NS, convert.ConversionStats())  # it ignores them
            assert out is not None

        def test_a_longer_covariance_keeps_its_first_nine_as_rclpy_does() -> None:
            msg = T("uavcan.equipment.ahrs.MagneticFieldStrength")(magnetic_field_covariance=[1.0] * 9)
            payload = payload_of(msg) + struct.pack("<3e", 7.0, 8.0, 9.0)
            cdr, _ = codec.magnetic_field_wire_to_ros(payload, RECEIVE_NS, convert.ConversionStats())
            ros = deserialize_message(cdr, ros_class("sensor_msgs/MagneticField"))
            assert list(ros.magnetic_field_covariance) == [1e-8] * 9

        def test_rpm_saturates_and_items_by_key() -> None:
            from sam_msgs.msg import ThrusterAngles, ThrusterRPMs

            stats = convert.ConversionStats()
            out = codec.thruster_rpms_ros_to_wire(serialize_message(ThrusterRPMs(thruster_1_rpm=200000,
                                                                                 thruster_2_rpm=-7)), stats)
            assert list(dronecan_decode(MAPPINGS["thruster_rpms"], out).rpm) == [131071, -7]
            assert stats.saturated == {"thruster_rpms.rpm[0]": 1}
            out = codec.thrust_vector_ros_to_wire(serialize_message(ThrusterAngles(thruster_vertical_radians=0.0625,
                                                                                   thruster_horizontal_radians=math.inf)),
                                                  stats)
            cmd = dronecan_decode(MAPPINGS["thrust_vector"], out)
            # +inf: the spec's limit, 0.12 as float16
            got = [(c.actuator_id, c.command_type, c.command_value) for c in cmd.commands]
            assert got == [(0, 1, 0.0625), (1, 1, 0.1199951171875)]
            assert codec.WIRE_MATCHES["thrust_vector"](out) and not codec.WIRE_MATCHES["ballast"](out)

        def test_timestamp_zero_is_the_receive_time() -> None:
            imu = T("uavcan.equipment.ahrs.RawIMU")()
            cdr, stamp = codec.imu_wire_to_ros(payload_of(imu), RECEIVE_NS, convert.ConversionStats())
            assert stamp == RECEIVE_NS
            imu.timestamp.usec = 1_234_567_891
            cdr, stamp = codec.imu_wire_to_ros(payload_of(imu), RECEIVE_NS, convert.ConversionStats())
            assert stamp == 1_234_567_891_000
            ros = deserialize_message(cdr, ros_class("sensor_msgs/Imu"))
            assert (ros.header.frame_id, ros.orientation_covariance[0]) == ("imu_link", -1.0)
