"""Element mappings (issue 17, class 4): arrays of composites converted element by element, tests/specs/power_v0.yaml.

In this process: the spec is valid, each POWER_CASES row of tests/broken_cases.py gives its exact errors, a Cyphal
mapping with `each` (tests/specs/barge.yaml with HoldState.tags <- Manifest.history) generates element functions in
convert.py, the plan holds an ElementMapping with the array's length rule,
the docs word the element fields, the DroneCAN wire codec converts power_v0's element mappings (cut and saturation
counted as the object converter counts them; an element type a record cannot hold stays on the object converters)
and so does the Cyphal one (an element type a record cannot hold stays on the object converters: OBJECT_ONLY says
why; the runtime's warning, or the offline bridge's error, quotes it).

In a child process with the spec's ROS package built (hypothesis, dronecan's transport and rclpy's serialization as
the oracles): ConsumedChargeArray -> ConsumedCharges gives every element's values and the message's header in every
element; Commands -> ArrayCommand gives the first 15 elements (float16 saturated and counted), the cut counted once
under `actuators.commands`; with on_out_of_range: reject, more than 15 elements or a value beyond float16 drops the
message, counted. Likewise on Cyphal with pycyphal's compiled classes: Manifest.history (Tag[<=3]) -> HoldState.tags
and back, the cut beyond 3 and uint24 saturation counted, by the object converters and by the wire codec (the same
message, pycyphal's payload bytes, the same counts).
"""

from __future__ import annotations

import importlib
import importlib.util
import json
import math
import os
import sys
from pathlib import Path
from typing import Any

import pytest

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "tests" / "specs" / "power_v0.yaml"
WORKER_ENV = "SAM_ELEMENT_MAPPINGS_WORKER"
WORKER = os.environ.get(WORKER_ENV)
CYPHAL_WORKER_ENV = "SAM_ELEMENT_MAPPINGS_CYPHAL_WORKER"
CYPHAL_WORKER = os.environ.get(CYPHAL_WORKER_ENV)
BARGE_EDITS = (
    ("messages:\n", "messages:\n  TagMsg:\n    description: A tag.\n    fields:\n"
     "      - {name: code, type: uint32}\n      - {name: checked, type: bool}\n"),
    ("      - {name: name, type: string}\n  HoldOrder:",
     "      - {name: name, type: string}\n      - {name: tags, type: \"barge_msgs/TagMsg[]\"}\n  HoldOrder:"),
    ("        name: name\n      ignore: [hold.open, tag.checked, faults, history]",
     "        name: name\n        tags: {each: history, fields: {code: code, checked: checked}}\n"
     "      ignore: [hold.open, tag.checked, faults]"),
)


def barge_with_tags() -> str:
    """tests/specs/barge.yaml with HoldState.tags (TagMsg[]) mapped element by element from Manifest.history
    (barge.cargo.Tag.1.0[<=3]): a Cyphal element mapping."""
    text = (ROOT / "tests" / "specs" / "barge.yaml").read_text(encoding="utf-8")
    for old, new in BARGE_EDITS:
        assert text.count(old) == 1, old
        text = text.replace(old, new, 1)
    return text


REJECT = ("      destination_node_ids: [31]\n", "      destination_node_ids: [31]\n      on_out_of_range: reject\n")


# ============================================================================================ parent

if not WORKER and not CYPHAL_WORKER:
    from broken_cases import POWER_CASES, Case

    from sam_codegen.conversion_plan import ElementMapping, MaxLength, lower_mapping
    from sam_codegen.frontend.loader import load_spec_file
    from sam_codegen.model.diagnostics import SpecError
    from sam_codegen.validate.resolve import validate

    BASE = SPEC.read_text(encoding="utf-8")

    def _errors(path: Path) -> list[str]:
        try:
            validate(load_spec_file(path))
        except SpecError as exc:
            return [str(d).replace(str(path), path.name) for d in exc.diagnostics]
        return []

    def _registry_and_object_only(spec: Path, tmp_path: Path, codec: str) -> list[str]:
        """The CODECS and OBJECT_ONLY parts of a codec module built from `spec` (python/<codec>)."""
        from sam_codegen.build import build

        build(spec, tmp_path / "generated")
        text = (tmp_path / "generated" / "python" / codec).read_text(encoding="utf-8")
        return text.split("CODECS:")[1].split("OBJECT_ONLY:")

    def test_power_spec_is_valid() -> None:
        assert _errors(SPEC) == []

    @pytest.mark.parametrize("case", POWER_CASES, ids=lambda c: c.name)
    def test_broken_power_spec(case: Case, tmp_path: Path) -> None:
        assert BASE.count(case.old) == 1, f"case {case.name} no longer applies to power_v0.yaml"
        path = tmp_path / "power_v0.yaml"
        path.write_text(BASE.replace(case.old, case.new, 1), encoding="utf-8")
        assert _errors(path) == list(case.errors)

    def test_cyphal_element_mapping_generates_converters_and_codecs(tmp_path: Path) -> None:
        """The same construct in a Cyphal mapping: element functions in convert.py and, on records, in codec.py
        (the mapping is in CODECS, nothing in OBJECT_ONLY)."""
        from sam_codegen.build import build

        spec = tmp_path / "spec" / "barge.yaml"
        spec.parent.mkdir()
        spec.write_text(barge_with_tags(), encoding="utf-8")
        assert _errors(spec) == []
        build(spec, tmp_path / "generated")
        python = tmp_path / "generated" / "python" / "barge_bridge"
        convert = (python / "convert.py").read_text(encoding="utf-8")
        assert "def _hold_state_tags_item_to_ros(" in convert and "for element in list(src.history):" in convert
        codec = (python / "codec.py").read_text(encoding="utf-8")
        assert "'hold_state': (hold_state_wire_to_ros, hold_state_ros_to_wire)" in codec.split("CODECS:")[1]
        assert "def _hold_state_tags_item_to_ros(src: tuple, receive_ns: int, stats: Any) -> tuple | None:" in codec
        assert "for element in list(history):" in codec and "OBJECT_ONLY" not in codec

    def test_cyphal_elements_a_record_cannot_hold_stay_on_the_object_path(tmp_path: Path) -> None:
        """A Cyphal element type holding an array: no codec for its mapping, OBJECT_ONLY says why; the others
        keep theirs."""

        spec = tmp_path / "spec" / "barge.yaml"
        spec.parent.mkdir()
        text = barge_with_tags().replace("      - {name: checked, type: bool}\n  barge.cargo.Hold.1.0:",
                                         "      - {name: checked, type: bool}\n"
                                         "      - {name: marks, type: \"uint2[2]\"}\n  barge.cargo.Hold.1.0:", 1)
        text = text.replace("tags: {each: history, fields: {code: code, checked: checked}}",
                            "tags: {each: history, fields: {code: code, checked: checked}, ignore: [marks]}", 1)
        text = text.replace("      ignore: [hold.open, tag.checked, faults]",
                            "      ignore: [hold.open, tag.checked, tag.marks, faults]", 1)
        text = text.replace("        tag.checked: true\n", "        tag.checked: true\n        \"tag.marks[0]\": 1\n"
                            "        \"tag.marks[1]\": 2\n", 1)
        spec.write_text(text, encoding="utf-8")
        assert text.count("marks") == 5
        assert _errors(spec) == []
        registry, object_only = _registry_and_object_only(spec, tmp_path, "barge_bridge/codec.py")
        assert "'hold_state'" not in registry and "'hold_order'" in registry
        assert ("'hold_state': \"arrays of composites converted element by element: history's element type holds "
                "arrays or a union\"," in object_only)

    def test_plan_holds_the_element_mapping() -> None:
        resolved = validate(load_spec_file(SPEC))
        by_name = {rm.mapping.name: rm for rm in resolved.dronecan_mappings}
        plan = lower_mapping(by_name["actuators"])
        (link,) = plan.to_uavcan
        element, cut = link.ops
        assert isinstance(element, ElementMapping) and element.uavcan_element == "uavcan.equipment.actuator.Command"
        assert cut == MaxLength(15, False, False)
        keys = [inner.key for inner in element.plan.to_uavcan]
        assert keys == ["actuators.commands[].actuator_id", "actuators.commands[].command_type",
                        "actuators.commands[].command_value"]
        to_ros = lower_mapping(by_name["charges"]).to_ros
        elements = next(link for link in to_ros if link.step.kind == "elements")
        assert [type(op) for op in elements.ops] == [ElementMapping]

    def test_fixed_uavcan_array_is_cut_before_and_padded_after(tmp_path: Path) -> None:
        """Into a fixed UAVCAN array: longer cut before the elements are converted, shorter padded with default
        elements after; counted once under the array either way."""
        from sam_codegen.build import build
        from sam_codegen.conversion_plan import FixedLength

        spec = tmp_path / "power_v0.yaml"
        spec.write_text(BASE.replace('"power.ConsumedCharge[<=15]"', '"power.ConsumedCharge[3]"', 1), encoding="utf-8")
        resolved = validate(load_spec_file(spec))
        (rm,) = [rm for rm in resolved.dronecan_mappings if rm.mapping.name == "charges"]
        link = next(link for link in lower_mapping(rm).to_uavcan if link.step.kind == "elements")
        assert [type(op) for op in link.ops] == [ElementMapping, FixedLength] and link.ops[1] == FixedLength(3, False)
        build(spec, tmp_path / "generated")
        code = (tmp_path / "generated" / "python" / "power_bridge" / "convert_v0.py").read_text(encoding="utf-8")
        body = code.split("def charges_to_uavcan(")[1].split("\ndef ")[0]
        cut, loop, pad = (body.index("del charges_items[3:]"), body.index("for element in charges_items:"),
                          body.index("[_TYPENAMES['power.ConsumedCharge']()] * 3"))
        assert cut < loop < pad and body.count("stats.saturate('charges.charges')") == 2  # one of the two runs

    def test_docs_and_codec_module(tmp_path: Path) -> None:
        from sam_codegen.build import build

        build(SPEC, tmp_path / "generated")
        docs = (tmp_path / "generated" / "docs" / "interfaces.md").read_text(encoding="utf-8")
        assert ("| `commands[].value` | → | `commands[].command_value` | float32 → float16 (narrowed, saturating, "
                "NaN rejected) |" in docs)
        assert "element by element, power\\_msgs/Command → uavcan.equipment.actuator.Command (over 15 elements cut" \
            in docs
        assert "each element's header: the message's stamp and frame id" in docs
        codec = (tmp_path / "generated" / "python" / "power_bridge" / "codec_v0.py").read_text(encoding="utf-8")
        registry = codec.split("CODECS:")[1]
        assert "'charges': (charges_wire_to_ros, charges_ros_to_wire)" in registry
        assert "'actuators': (actuators_wire_to_ros, actuators_ros_to_wire)" in registry
        assert "OBJECT_ONLY" not in codec

    def test_elements_a_record_cannot_hold_stay_on_the_object_path(tmp_path: Path) -> None:
        """An element type holding an array: no DroneCAN codec, OBJECT_ONLY says why (bools and bit-width integers
        have one: tests/specs/hopper_v0.yaml in tests/codegen/test_codec_v0.py)."""
        spec = tmp_path / "power_v0.yaml"
        text = BASE.replace("      - {name: charge, type: float32}\n",
                            "      - {name: charge, type: float32}\n      - {name: ok, type: \"bool[2]\"}\n", 1)
        text = text.replace("            charge: charge\n    actuators:",
                            "            charge: charge\n          ignore: [ok]\n    actuators:", 1)
        assert text.count("ignore: [ok]") == 1 and text.count("name: ok") == 1
        spec.write_text(text, encoding="utf-8")
        registry, object_only = _registry_and_object_only(spec, tmp_path, "power_bridge/codec_v0.py")
        assert "'charges'" not in registry and "'actuators'" in registry
        assert ("'charges': \"arrays of composites converted element by element: charges's element type holds "
                "arrays or a union\"," in object_only)

    def test_the_codec_cuts_and_saturates_as_counted(tmp_path: Path) -> None:
        """ROS Command[20] -> ArrayCommand: cut to 15 (counted once), a value beyond float16 saturated (counted per
        element under commands[].command_value); dronecan's bytes of the same message. And back: the elements."""
        dronecan = pytest.importorskip("dronecan")
        import struct

        from sam_codegen.build import build

        build(SPEC, tmp_path / "generated")
        sys.path.insert(0, str(tmp_path / "generated" / "python"))
        try:
            codec = importlib.import_module("power_bridge.codec_v0")
        finally:
            sys.path.pop(0)
            for name in [m for m in sys.modules if m.startswith("power_bridge")]:
                del sys.modules[name]
        values = [float(i) for i in range(18)] + [1e6, -1e6]
        values[3] = 1e6
        cdr = b"\0\1\0\0" + struct.pack("<I", 20) + b"".join(struct.pack("<BBxxf", i, 1, v)
                                                          for i, v in enumerate(values))
        stats = codec.ConversionStats()
        payload = codec.CODECS["actuators"][1](cdr, stats)
        assert dict(stats.saturated) == {"actuators.commands": 1, "actuators.commands[].command_value": 1}
        msg = dronecan.uavcan.equipment.actuator.ArrayCommand(commands=[
            dronecan.uavcan.equipment.actuator.Command(actuator_id=i, command_type=1,
                                                       command_value=min(v, 65504.0))
            for i, v in enumerate(values[:15])])
        assert payload == bytes(dronecan.transport.Transfer(payload=msg).payload)
        back, stamp = codec.CODECS["actuators"][0](payload, 5, codec.ConversionStats())
        assert stamp == -1 and struct.unpack_from("<I", back, 4) == (15,) and len(back) == 8 + 15 * 8
        assert struct.unpack_from("<BBxxf", back, 8 + 3 * 8) == (3, 1, 65504.0)

    def test_the_runtime_says_why_a_mapping_has_no_codec() -> None:
        from types import SimpleNamespace

        from sam_runtime.bridge.wiring import codec_gaps, missing_codecs

        codec = SimpleNamespace(CODECS={"a": None}, OBJECT_ONLY={"charges": "arrays of composites converted element "
                                                                           "by element"})
        mappings = [SimpleNamespace(name=n) for n in ("a", "charges", "old")]
        missing = missing_codecs(codec, mappings)
        assert missing == ["charges", "old"]
        assert codec_gaps(codec, missing) == (
            "charges (arrays of composites converted element by element); "
            "old (built by an older sam-codegen? run `sam-codegen build`)")
        assert codec_gaps(None, ["x"]) == "any mapping (built by an older sam-codegen? run `sam-codegen build`)"

    GOLDEN = ROOT / "tests" / "golden" / "elements"

    def test_golden_converters_and_docs(tmp_path: Path) -> None:
        """power_v0's DroneCAN converters and its mapping docs, byte for byte (SAM_UPDATE_GOLDEN=1 rewrites them)."""
        from sam_codegen.build import build

        build(SPEC, tmp_path / "generated")
        produced = {
            "convert_v0.py.golden": (tmp_path / "generated" / "python" / "power_bridge" / "convert_v0.py"),
            "codec_v0.py.golden": (tmp_path / "generated" / "python" / "power_bridge" / "codec_v0.py"),
            "interfaces.md.golden": tmp_path / "generated" / "docs" / "interfaces.md",
        }
        for name, path in produced.items():
            text = path.read_text(encoding="utf-8")
            if os.environ.get("SAM_UPDATE_GOLDEN") == "1":
                GOLDEN.mkdir(parents=True, exist_ok=True)
                (GOLDEN / name).write_text(text, encoding="utf-8")
            assert text == (GOLDEN / name).read_text(encoding="utf-8"), f"{name} differs from its golden copy"

    from helpers.ros_packages import missing_tools, run_child
    from helpers.runtime_support import domain_id

    @pytest.mark.ros
    @pytest.mark.slow
    @pytest.mark.skipif(missing_tools() is not None, reason=str(missing_tools()))
    def test_element_converters_with_dronecan_and_rclpy(tmp_path: Path) -> None:
        pytest.importorskip("dronecan")
        from helpers.spec_build import built_spec

        from sam_codegen.build import build

        built = built_spec("power_v0")
        strict_spec = tmp_path / "power_v0.yaml"
        strict_spec.write_text(BASE.replace(*REJECT, 1), encoding="utf-8")
        build(strict_spec, tmp_path / "strict")
        config = {"generated": str(built.generated), "strict": str(tmp_path / "strict")}
        proc = run_child(["-m", "pytest", __file__, "-q", "-p", "no:cacheprovider", "--rootdir", str(ROOT),
                          "-W", "error::RuntimeWarning"], built.prefix, domain_id(77),
                         {WORKER_ENV: json.dumps(config), "ROS_PYTHON_CHECK_FIELDS": "1"}, timeout=900)
        report = proc.stdout[-12000:] + proc.stderr[-4000:]
        assert proc.returncode == 0, f"worker tests failed:\n{report}"
        assert " passed" in proc.stdout and " skipped" not in proc.stdout and " failed" not in proc.stdout, report


    @pytest.mark.ros
    @pytest.mark.slow
    @pytest.mark.skipif(missing_tools() is not None, reason=str(missing_tools()))
    def test_cyphal_element_converters_with_pycyphal_and_rclpy(tmp_path: Path) -> None:
        pytest.importorskip("pycyphal")
        from helpers.ros_packages import built_prefix

        from sam_codegen.build import build
        from sam_runtime.cyphal_io.dsdl_cache import ensure_compiled

        spec = tmp_path / "spec" / "barge.yaml"
        spec.parent.mkdir()
        spec.write_text(barge_with_tags(), encoding="utf-8")
        generated = tmp_path / "generated"
        build(spec, generated)
        saved = list(sys.path)
        try:  # compiled here (cached by content); the worker only puts it on its path
            dsdl = ensure_compiled([generated / "dsdl" / "barge"], ROOT / ".cache" / "dsdl")
        finally:
            sys.path[:] = saved
        prefix = built_prefix([generated / "ros" / "barge_msgs"])
        config = {"python": str(generated / "python"), "dsdl": str(dsdl)}
        proc = run_child(["-m", "pytest", __file__, "-q", "-p", "no:cacheprovider", "--rootdir", str(ROOT),
                          "-W", "error::RuntimeWarning"], prefix, domain_id(78),
                         {CYPHAL_WORKER_ENV: json.dumps(config), "ROS_PYTHON_CHECK_FIELDS": "1"}, timeout=900)
        report = proc.stdout[-12000:] + proc.stderr[-4000:]
        assert proc.returncode == 0, f"worker tests failed:\n{report}"
        assert " passed" in proc.stdout and " skipped" not in proc.stdout and " failed" not in proc.stdout, report


# ============================================================================================ workers

if CYPHAL_WORKER:
    import numpy as np
    import pycyphal.dsdl
    from hypothesis import HealthCheck, given, settings
    from hypothesis import strategies as st
    from rclpy.serialization import deserialize_message, serialize_message

    CYPHAL_CONFIG = json.loads(CYPHAL_WORKER)
    sys.path.insert(0, CYPHAL_CONFIG["dsdl"])
    sys.path.insert(0, CYPHAL_CONFIG["python"])
    barge_convert = importlib.import_module("barge_bridge.convert")
    barge_codec = importlib.import_module("barge_bridge.codec")
    import barge.cargo
    from barge_msgs.msg import HoldState, TagMsg
    from helpers.codec_support import FRAME_PREFIXES, with_frame_prefix

    from sam_runtime.genpkg import bound_codec

    C_SETTINGS = settings(max_examples=int(os.environ.get("SAM_CONVERTERS_EXAMPLES", "60")), deadline=None,
                          database=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
    C_RECEIVE_NS = 1_700_000_000_123_456_789

    def cyphal_wire(obj: Any) -> Any:
        """What the receiver of `obj` gets: serialized and deserialized by pycyphal."""
        return pycyphal.dsdl.deserialize(type(obj), list(pycyphal.dsdl.serialize(obj)))

    @C_SETTINGS
    @given(tags=st.lists(st.tuples(st.integers(0, 2**24 - 1), st.booleans()), max_size=3),
           usec=st.integers(1, 2**40))
    def test_manifest_history_to_ros_tags(tags: list[tuple[int, bool]], usec: int) -> None:
        manifest = barge.cargo.Manifest_1_0(
            history=[barge.cargo.Tag_1_0(code=c, checked=k) for c, k in tags])
        manifest.timestamp.microsecond = usec
        stats = barge_convert.ConversionStats()
        ros = barge_convert.hold_state_to_ros(cyphal_wire(manifest), C_RECEIVE_NS, stats)
        assert ros is not None, stats.rejected
        ros = deserialize_message(serialize_message(ros), HoldState)
        assert [(t.code, t.checked) for t in ros.tags] == tags
        # the wire codec: the same message (rclpy leaves its padding bytes unset: compared decoded) and stamp
        payload = b"".join(bytes(x) for x in pycyphal.dsdl.serialize(manifest))
        codec_stats = barge_convert.ConversionStats()
        cdr, stamp = barge_codec.CODECS["hold_state"][0](payload, C_RECEIVE_NS, codec_stats)
        assert deserialize_message(cdr, HoldState) == ros and stamp == usec * 1000
        assert not codec_stats.saturated and not codec_stats.rejected and not stats.saturated
        for prefix in FRAME_PREFIXES:  # a namespaced run's codec: the prefix before the frame id, the rest alike
            cdr, stamp = bound_codec(barge_codec, prefix).CODECS["hold_state"][0](
                payload, C_RECEIVE_NS, barge_convert.ConversionStats())
            want = with_frame_prefix(deserialize_message(serialize_message(ros), HoldState), prefix)
            assert deserialize_message(cdr, HoldState) == want and stamp == usec * 1000
            assert want.header.frame_id == f"{prefix}hold_link"

    @C_SETTINGS
    @given(tags=st.lists(st.tuples(st.integers(0, 2**32 - 1), st.booleans()), max_size=6))
    def test_hold_state_tags_to_history(tags: list[tuple[int, bool]]) -> None:
        msg = HoldState(tags=[TagMsg(code=c, checked=k) for c, k in tags])
        stats = barge_convert.ConversionStats()
        out = barge_convert.hold_state_to_uavcan(deserialize_message(serialize_message(msg), HoldState), stats)
        assert out is not None, stats.rejected
        got = [(int(t.code), bool(t.checked)) for t in cyphal_wire(out).history]
        kept = tags[:3]
        assert got == [(min(c, 2**24 - 1), k) for c, k in kept]
        assert stats.saturated.get("hold_state.history", 0) == (1 if len(tags) > 3 else 0)
        assert stats.saturated.get("hold_state.tags[].code", 0) == sum(c > 2**24 - 1 for c, _ in kept)
        assert not stats.rejected
        assert np.all(np.asarray([t.code for t in out.history], dtype=np.int64) < 2**24)
        # the wire codec: pycyphal's bytes of the object converter's result, counted the same (the cut once)
        codec_stats = barge_convert.ConversionStats()
        payload = barge_codec.CODECS["hold_state"][1](serialize_message(msg), codec_stats)
        assert payload == b"".join(bytes(x) for x in pycyphal.dsdl.serialize(out))
        assert dict(codec_stats.saturated) == dict(stats.saturated) and not codec_stats.rejected


if WORKER:
    import dronecan
    import numpy as np
    from dronecan.transport import Transfer
    from hypothesis import HealthCheck, given, settings
    from hypothesis import strategies as st
    from rclpy.serialization import deserialize_message, serialize_message

    CONFIG = json.loads(WORKER)
    GENERATED = Path(CONFIG["generated"])
    sys.path.insert(0, str(GENERATED / "python"))
    convert = importlib.import_module("power_bridge.convert_v0")
    convert.load_types(GENERATED)
    _strict_spec = importlib.util.spec_from_file_location(
        "power_bridge.convert_v0_strict", Path(CONFIG["strict"]) / "python" / "power_bridge" / "convert_v0.py")
    assert _strict_spec is not None and _strict_spec.loader is not None
    strict = importlib.util.module_from_spec(_strict_spec)
    sys.modules["power_bridge.convert_v0_strict"] = strict
    _strict_spec.loader.exec_module(strict)
    from helpers.codec_support import FRAME_PREFIXES, with_frame_prefix
    from power_msgs.msg import Command, Commands

    from sam_runtime.genpkg import bound_codec

    codec_v0 = importlib.import_module("power_bridge.codec_v0")

    SETTINGS = settings(max_examples=int(os.environ.get("SAM_CONVERTERS_EXAMPLES", "60")), deadline=None,
                        database=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
    RECEIVE_NS = 1_700_000_000_123_456_789
    F32 = st.floats(width=32, allow_nan=True, allow_infinity=True)
    RCLPY_F32 = st.floats(width=32, allow_nan=True, allow_infinity=True).filter(
        lambda x: not math.isfinite(x) or abs(x) < float(np.finfo(np.float32).max))

    def wire(msg: Any) -> Any:
        """The message through dronecan's frames and back (what the bridge receives or sends)."""
        frames = Transfer(payload=msg, source_node_id=30, transfer_id=3).to_frames()
        received = Transfer()
        received.data_type_id = dronecan.get_dronecan_data_type(msg).default_dtid
        received.service_not_message = False
        received.from_frames(frames)
        return received.payload

    def same(a: float, b: float) -> bool:
        return (math.isnan(a) and math.isnan(b)) or a == b

    @SETTINGS
    @given(usec=st.one_of(st.just(0), st.integers(1, 2**56 - 1)),
           items=st.lists(st.tuples(st.integers(0, 2**16 - 1), F32), max_size=15))
    def test_consumed_charges_to_ros(usec: int, items: list[tuple[int, float]]) -> None:
        types = dronecan.TYPENAMES
        msg = types["power.ConsumedChargeArray"](
            timestamp=types["uavcan.Timestamp"](usec=usec),
            charges=[types["power.ConsumedCharge"](circuit_id=c, charge=q) for c, q in items])
        received = wire(msg)  # dronecan's cast included: a float32 beyond its range becomes +-FLT_MAX
        stats = convert.ConversionStats()
        ros = convert.charges_to_ros(received, RECEIVE_NS, stats)
        assert ros is not None, stats.rejected
        ros = deserialize_message(serialize_message(ros), type(ros))
        assert len(ros.charges) == len(items)
        stamp = ros.header.stamp
        expected_ns = RECEIVE_NS if usec == 0 else min(usec * 1000, (2**31 - 1) * 10**9 + 999_999_999)
        assert stamp.sec * 10**9 + stamp.nanosec == expected_ns
        for element, sent, (circuit, _) in zip(ros.charges, received.charges, items, strict=True):
            assert element.circuit_id == circuit
            assert same(element.charge, sent.charge)
            assert element.header == ros.header  # the message's stamp and frame id
        assert ros.header.frame_id == "base_link"
        assert not stats.rejected and not stats.saturated
        payload = bytes(Transfer(payload=msg).payload)
        for prefix in FRAME_PREFIXES:  # a namespaced run's codec: the prefix before every element's frame id too
            out = bound_codec(codec_v0, prefix).CODECS["charges"][0](payload, RECEIVE_NS, convert.ConversionStats())
            assert out is not None
            got = deserialize_message(out[0], type(ros))
            want = with_frame_prefix(deserialize_message(serialize_message(ros), type(ros)), prefix)
            assert [e.header.frame_id for e in want.charges] == [f"{prefix}base_link"] * len(items)
            assert got.header == want.header and len(got.charges) == len(want.charges)
            for a, b in zip(got.charges, want.charges, strict=True):
                assert (a.header, a.circuit_id) == (b.header, b.circuit_id) and same(a.charge, b.charge)
        back = convert.charges_to_uavcan(ros, stats)  # and back: the same payload
        assert back is not None
        if usec != 0 and usec * 1000 == expected_ns:  # a stamp Time holds: the same payload
            assert Transfer(payload=back).payload == Transfer(payload=msg).payload

    COMMANDS = st.lists(st.tuples(st.integers(0, 255), st.integers(0, 255), RCLPY_F32), max_size=30)

    def _commands(items: list[tuple[int, int, float]]) -> Commands:
        return Commands(commands=[Command(actuator_id=a, command_type=t, value=v) for a, t, v in items])

    @SETTINGS
    @given(items=COMMANDS)
    def test_commands_to_array_command(items: list[tuple[int, int, float]]) -> None:
        ros = deserialize_message(serialize_message(_commands(items)), Commands)
        stats = convert.ConversionStats()
        out = convert.actuators_to_uavcan(ros, stats)
        assert out is not None, stats.rejected
        received = wire(out)
        kept = items[:15]
        assert len(received.commands) == len(kept)
        assert stats.saturated.get("actuators.commands", 0) == (1 if len(items) > 15 else 0)
        beyond = 0
        for cmd, (actuator, kind, value) in zip(received.commands, kept, strict=True):
            value = float(np.float32(value))
            expected = value if math.isnan(value) else max(-65504.0, min(65504.0, value))
            beyond += not math.isnan(value) and abs(value) > 65504.0
            assert (cmd.actuator_id, cmd.command_type) == (actuator, kind)
            assert same(cmd.command_value, float(np.float16(expected)))
        assert stats.saturated.get("actuators.commands[].command_value", 0) == beyond
        assert not stats.rejected

    @SETTINGS
    @given(items=COMMANDS)
    def test_commands_rejected_beyond_capacity_or_range(items: list[tuple[int, int, float]]) -> None:
        ros = deserialize_message(serialize_message(_commands(items)), Commands)
        stats = strict.ConversionStats()
        out = strict.actuators_to_uavcan(ros, stats)
        kept_beyond = any(not math.isnan(v) and abs(float(np.float32(v))) > 65504.0 for _, _, v in items)
        if len(items) > 15:
            assert out is None and stats.rejected == {"actuators.commands": 1}
        elif kept_beyond:
            assert out is None and stats.rejected == {"actuators.commands[].command_value": 1}
        else:
            assert out is not None and len(wire(out).commands) == len(items) and not stats.rejected
        assert not stats.saturated

    def test_sixteen_commands_cut_to_fifteen_and_counted() -> None:
        stats = convert.ConversionStats()
        out = convert.actuators_to_uavcan(_commands([(i, 0, float(i)) for i in range(16)]), stats)
        assert out is not None
        assert [c.actuator_id for c in wire(out).commands] == list(range(15))
        assert stats.saturated == {"actuators.commands": 1}
