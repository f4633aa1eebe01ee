"""The worker half of tests/test_codec_cyphal.py: its tests with the real classes, defined only in a child process
started with SAM_CODEC_WORKER (the build: spec, generated python, compiled DSDL, ROS prefix) and the ROS
package's environment. test_codec_cyphal.py imports them from here in that child; anywhere else this module is
empty.
"""

from __future__ import annotations

import os

WORKER = os.environ.get("SAM_CODEC_WORKER")

if WORKER:
    import importlib
    import json
    import sys
    from pathlib import Path
    from typing import Any

    import pycyphal.dsdl
    import pytest
    from hypothesis import HealthCheck, given, settings
    from hypothesis import strategies as st
    from rclpy.serialization import deserialize_message, serialize_message

    from helpers.codec_support import (
        FRAME_PREFIXES,
        bad_lengths,
        corruptions,
        dsdl_plain,
        dsdl_strategy,
        ros_plain,
        ros_strategy,
        same,
        with_frame_prefix,
    )
    from sam_codegen.frontend.loader import load_spec_file
    from sam_codegen.model.spec import DsdlStruct
    from sam_codegen.targets.python.names import LocalNames, py_class_name, py_module, ros_closure
    from sam_codegen.targets.wire.cdr_layout import flatten
    from sam_codegen.targets.wire.cdr_write import Constants, cdr_reader, cdr_writer
    from sam_codegen.validate.mapping_rules import ResolvedMapping
    from sam_codegen.validate.resolve import validate
    from sam_runtime.genpkg import bound_codec

    CONFIG = json.loads(WORKER)
    RESOLVED = validate(load_spec_file(Path(CONFIG["spec"])))
    sys.path.insert(0, CONFIG["dsdl"])
    sys.path.insert(0, CONFIG["python"])
    convert = importlib.import_module(f"{CONFIG['package']}.convert")
    codec = importlib.import_module(f"{CONFIG['package']}.codec")
    BOUND = {"": codec, **{p: bound_codec(codec, p) for p in FRAME_PREFIXES}}  # as a namespaced bridge takes it
    MAPPINGS: dict[str, ResolvedMapping] = {rm.mapping.name: rm for rm in RESOLVED.mappings}
    EXAMPLES = int(os.environ.get("SAM_CODEC_EXAMPLES", "40"))
    SETTINGS = settings(max_examples=EXAMPLES, deadline=None, database=None,
                        suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
    FEWER = settings(SETTINGS, max_examples=max(4, EXAMPLES // 5))  # each example checks hundreds of payloads
    RECEIVE_NS = 1_700_000_000_123_456_789

    def dsdl_class(struct: DsdlStruct) -> type:
        return getattr(importlib.import_module(py_module(struct.namespace)), py_class_name(struct))

    def ros_class(full_name: str) -> type:
        package, name = full_name.split("/")
        return getattr(importlib.import_module(f"{package}.msg"), name)

    def uavcan_strategy(rm: ResolvedMapping) -> st.SearchStrategy[Any]:
        """Whole-range objects; timestamps often 0 (unknown), table fields often a key of the table."""
        special: dict[str, st.SearchStrategy[Any]] = {}
        for s in rm.steps:
            if s.kind == "time":
                special[s.uavcan] = st.one_of(st.just(0), st.integers(*s.uavcan_type.range))  # type: ignore[union-attr]
            elif s.kind == "table":
                special[s.uavcan] = st.one_of(st.sampled_from([k for k, _ in s.table]),
                                              st.integers(*s.uavcan_type.range))  # type: ignore[union-attr]
        return dsdl_strategy(rm.dsdl_struct, RESOLVED.dsdl.get, dsdl_class, special)

    def decode(struct: DsdlStruct, payload: bytes) -> Any:
        """What pycyphal's deserialize gives, None where it refuses (its bit length assertion too)."""
        try:
            return pycyphal.dsdl.deserialize(dsdl_class(struct), [memoryview(bytearray(payload))])
        except AssertionError:
            return None

    def counters(stats: Any) -> tuple[dict[str, int], dict[str, int]]:
        return dict(stats.saturated), dict(stats.rejected)

    def ros_wire(msg: Any) -> Any:
        return deserialize_message(serialize_message(msg), type(msg))

    # ---------------------------------------------------------------------------------------- both paths

    def check_wire_to_ros(rm: ResolvedMapping, payload: bytes, prefix: str = "") -> bool:
        """The codec against the object path for one payload; returns whether pycyphal refused it. `prefix`: the
        codec bound to that frame prefix, against the object path's message with it before every frame id."""
        to_ros = convert.CONVERTERS[rm.mapping.name][0]
        wire_to_ros = BOUND[prefix].CODECS[rm.mapping.name][0]
        received = decode(rm.dsdl_struct, payload)
        so, sc = convert.ConversionStats(), convert.ConversionStats()
        try:
            out = wire_to_ros(payload, RECEIVE_NS, sc)
        except codec.WireError:
            assert received is None, f"the codec refused what pycyphal reads: {payload.hex()}"
            assert counters(sc) == ({}, {})
            return True
        assert received is not None, f"the codec read what pycyphal refuses: {payload.hex()}"
        ref = to_ros(received, RECEIVE_NS, so)
        assert counters(sc) == counters(so), payload.hex()
        assert (out is None) == (ref is None), payload.hex()
        if ref is None:
            return False
        cdr, stamp = out
        assert isinstance(cdr, bytes) and cdr[:4] == b"\x00\x01\x00\x00"
        for view in (memoryview(bytearray(payload)), bytearray(payload)):  # what transports hand over
            assert wire_to_ros(view, RECEIVE_NS, convert.ConversionStats()) == out
        want = ros_wire(with_frame_prefix(ref, prefix))
        got = deserialize_message(cdr, type(ref))
        assert same(ros_plain(got), ros_plain(want)), (payload.hex(), ros_plain(got), ros_plain(want))
        header = getattr(want, "header", None)
        assert stamp == (-1 if header is None else header.stamp.sec * 1_000_000_000 + header.stamp.nanosec)
        return False

    def check_ros_to_wire(rm: ResolvedMapping, cdr: bytes, strict: bool = True) -> bool:
        """The codec against the object path for CDR bytes; returns whether the codec refused them. `strict`: it
        refuses exactly what rclpy refuses; else it may refuse more (a string without its NUL, a bound exceeded,
        which rclpy lets through) but reads nothing rclpy refuses."""
        to_uavcan = convert.CONVERTERS[rm.mapping.name][1]
        ros_to_wire = codec.CODECS[rm.mapping.name][1]
        cls = ros_class(rm.ros_message.full_name)
        try:
            received = deserialize_message(cdr, cls)
        except Exception:  # rclpy's RMWError (Fast CDR's exceptions)
            received = None
        so, sc = convert.ConversionStats(), convert.ConversionStats()
        try:
            out = ros_to_wire(cdr, sc)
        except codec.WireError:
            assert not strict or received is None, f"the codec refused what rclpy reads: {cdr.hex()}"
            return True
        assert received is not None, f"the codec read what rclpy refuses: {cdr.hex()}"
        ref = to_uavcan(received, so)
        assert counters(sc) == counters(so), cdr.hex()
        assert (out is None) == (ref is None), cdr.hex()
        if ref is not None:
            assert isinstance(out, bytes)
            assert ros_to_wire(memoryview(cdr), convert.ConversionStats()) == out  # a raw subscription's buffer
            got = decode(rm.dsdl_struct, out)
            assert got is not None, out.hex()
            want = decode(rm.dsdl_struct, b"".join(bytes(x) for x in pycyphal.dsdl.serialize(ref)))
            lookup = RESOLVED.dsdl.get
            assert same(dsdl_plain(got, rm.dsdl_struct, lookup), dsdl_plain(want, rm.dsdl_struct, lookup)), cdr.hex()
        return False

    # ---------------------------------------------------------------------------------------- the properties

    @pytest.mark.parametrize("name", sorted(MAPPINGS))
    @SETTINGS
    @given(data=st.data())
    def test_wire_to_ros_equals_the_object_path(name: str, data: st.DataObject) -> None:
        rm = MAPPINGS[name]
        obj = data.draw(uavcan_strategy(rm), label="uavcan")
        assert not check_wire_to_ros(rm, b"".join(bytes(x) for x in pycyphal.dsdl.serialize(obj)))

    @pytest.mark.parametrize("name", sorted(MAPPINGS))
    @SETTINGS
    @given(data=st.data())
    def test_ros_to_wire_equals_the_object_path(name: str, data: st.DataObject) -> None:
        rm = MAPPINGS[name]
        msg = data.draw(ros_strategy(rm.ros_message, RESOLVED.ros.get, ros_class), label="ros")
        assert not check_ros_to_wire(rm, serialize_message(msg))

    @pytest.mark.parametrize("name", sorted(MAPPINGS))
    @FEWER
    @given(data=st.data())
    def test_malformed_payloads_refused_as_pycyphal_refuses(name: str, data: st.DataObject) -> None:
        rm = MAPPINGS[name]
        obj = data.draw(uavcan_strategy(rm), label="uavcan")
        noise = data.draw(st.binary(min_size=1, max_size=24), label="noise")
        payload = b"".join(bytes(x) for x in pycyphal.dsdl.serialize(obj))
        for case in corruptions(payload, noise):
            check_wire_to_ros(rm, case)
        for case in bad_lengths(payload, rm.dsdl_struct, obj, RESOLVED.dsdl.get):
            check_wire_to_ros(rm, case)

    @pytest.mark.parametrize("name", sorted(MAPPINGS))
    @FEWER
    @given(data=st.data())
    def test_malformed_cdr_refused(name: str, data: st.DataObject) -> None:
        rm = MAPPINGS[name]
        cdr = serialize_message(data.draw(ros_strategy(rm.ros_message, RESOLVED.ros.get, ros_class), label="ros"))
        for cut in range(len(cdr)):
            check_ros_to_wire(rm, cdr[:cut])
        noise = data.draw(st.binary(min_size=1, max_size=24), label="noise")
        for case in corruptions(cdr, noise):
            check_ros_to_wire(rm, case, strict=False)

    @pytest.mark.parametrize("name", sorted(MAPPINGS))
    @FEWER
    @given(data=st.data())
    def test_frame_prefixes_of_every_length(name: str, data: st.DataObject) -> None:
        """A namespaced run's codecs (bound to a frame prefix of each length modulo 8: the padding after a frame id
        depends on it): UAVCAN -> ROS, the object path's message with the prefix before its frame ids, malformed
        payloads refused alike; ROS -> UAVCAN, the unbound codec's payload (no frame id is read)."""
        rm = MAPPINGS[name]
        obj = data.draw(uavcan_strategy(rm), label="uavcan")
        payload = b"".join(bytes(x) for x in pycyphal.dsdl.serialize(obj))
        msg = data.draw(ros_strategy(rm.ros_message, RESOLVED.ros.get, ros_class), label="ros")
        cdr = serialize_message(msg)
        noise = data.draw(st.binary(min_size=1, max_size=8), label="noise")
        for prefix in FRAME_PREFIXES:
            assert not check_wire_to_ros(rm, payload, prefix)
            for case in list(corruptions(payload, noise))[::7]:
                check_wire_to_ros(rm, case, prefix)
            assert not check_ros_to_wire(rm, cdr)
            stats = convert.ConversionStats()
            assert BOUND[prefix].CODECS[name][1](cdr, stats) == codec.CODECS[name][1](cdr, convert.ConversionStats())

    def test_every_mapping_has_both_codecs() -> None:
        assert sorted(codec.CODECS) == sorted(MAPPINGS) == sorted(convert.CONVERTERS)
        assert issubclass(codec.WireError, ValueError)

    # ---------------------------------------------------------------------------------------- the CDR layer

    @pytest.mark.parametrize("full_name", ros_closure(RESOLVED))
    @SETTINGS
    @given(data=st.data())
    def test_cdr_layer_against_rclpy(full_name: str, data: st.DataObject) -> None:
        """wire_cdr alone, every leaf of a ROS message the mappings use: its reader decodes rclpy's bytes, and
        rclpy decodes its writer's bytes, to the message's values (sequences of messages: written empty)."""
        message, lookup = RESOLVED.ros.get(full_name), RESOLVED.ros.get
        assert message is not None
        leaves = [leaf for leaf in flatten(message, lookup) if leaf.kind != "msgseq"]
        consts = Constants()
        read_lines, found = cdr_reader(message, [leaf.path for leaf in leaves], lookup, LocalNames(set()), consts, "p")
        write_lines, expr = cdr_writer(message, {leaf.path: f"v[{i}]" for i, leaf in enumerate(leaves)}, lookup,
                                       LocalNames(set()), consts)
        source = "\n".join(["import struct as _struct", "from array import array as _array", "_ZEROS = bytes(64)",
                            *consts.lines(), "def read(p):", *("    " + line for line in read_lines),
                            f"    return [{', '.join(found[leaf.path] for leaf in leaves)}]",
                            "def write(v):", *("    " + line for line in write_lines), f"    return {expr}"])
        space: dict[str, Any] = {"WireError": ValueError}
        exec(compile(source, full_name, "exec"), space)  # the generated code under test
        msg = data.draw(ros_strategy(message, lookup, ros_class), label="ros")
        for leaf in flatten(message, lookup):
            if leaf.kind == "msgseq":
                setattr(_parent(msg, leaf.path), leaf.path[-1][0], [])
        msg = ros_wire(msg)
        values = [_get(msg, leaf.path) for leaf in leaves]
        read = space["read"](serialize_message(msg))
        for leaf, got, value in zip(leaves, read, values, strict=True):
            want = [b[0] for b in value] if leaf.base == "byte" and leaf.kind != "prim" else ros_plain(value)
            assert same(ros_plain(got), want), (leaf.path, got, want)
        written = space["write"](values)
        assert same(ros_plain(deserialize_message(written, type(msg))), ros_plain(msg))

    def _parent(msg: Any, path: tuple) -> Any:
        for name, index in path[:-1]:
            msg = getattr(msg, name)
            if index is not None:
                msg = msg[index]
        return msg

    def _get(msg: Any, path: tuple) -> Any:
        value = getattr(_parent(msg, path), path[-1][0])
        return value[path[-1][1]] if path[-1][1] is not None else value

    # ---------------------------------------------------------------------------------------- spec specifics

    if RESOLVED.spec.vehicle == "barge":

        @pytest.mark.parametrize("extra", [1, 40, 120, 400])
        def test_delimited_field_longer_than_its_extent(extra: int) -> None:
            """A newer version's longer nested Hold: read (truncated) while the whole stays within the Manifest's
            largest size, refused (as pycyphal's bit length check refuses it) beyond."""
            rm = MAPPINGS["hold_state"]
            cls = dsdl_class(rm.dsdl_struct)
            payload = b"".join(bytes(x) for x in pycyphal.dsdl.serialize(cls()))
            at = 7  # after the 56-bit timestamp: the Hold's delimiter header
            length = int.from_bytes(payload[at:at + 4], "little")
            longer = (payload[:at] + (length + extra).to_bytes(4, "little") + payload[at + 4:at + 4 + length]
                      + bytes(extra) + payload[at + 4 + length:])
            refused = check_wire_to_ros(rm, longer)
            assert refused == (decode(rm.dsdl_struct, longer) is None)
            assert check_wire_to_ros(rm, longer[:at] + (len(longer)).to_bytes(4, "little") + longer[at + 4:])
