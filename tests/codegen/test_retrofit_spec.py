"""tests/specs/retrofit.yaml's no-frame and no-header mappings (issue 27, class 1) through the generated wire codecs,
bound to a namespace's frame prefix as the bridge binds them (sam_runtime.genpkg.bound_codec), and the bridge's
object path told the same (sam_runtime.bridge.wiring): no process, no ROS package needed.

- `frame_id: ''`: the message's frame id is empty, also under a frame prefix (REP 105 tools key on the empty one);
  the stamp is the receive time as for every header;
- `ros_defaults: [header]`: the header stays at its default, zero stamp and empty frame id, under a prefix too;
- the generated docs say both, and say what a wrapping line does;
- class 3: a service type of another package (`external_services`) with constants, generated as that package;
  a DroneCAN service response with constants, read back by dronecan.
"""

from __future__ import annotations

import importlib
import struct
import sys
from pathlib import Path
from types import ModuleType, SimpleNamespace

import pytest

from sam_codegen.frontend.loader import load_spec_file
from sam_codegen.targets import docs, dsdl_v0
from sam_codegen.targets import ros as ros_target
from sam_codegen.targets.python import convert
from sam_codegen.targets.wire import codec, codec_v0
from sam_codegen.validate.resolve import Resolved, validate
from sam_runtime.bridge.wiring import writes_header
from sam_runtime.genpkg import bound_codec

SPEC = Path(__file__).resolve().parents[1] / "specs" / "retrofit.yaml"
RECEIVE_NS = 1_700_000_000_123_456_789


@pytest.fixture(scope="module")
def resolved() -> Resolved:
    return validate(load_spec_file(SPEC))


@pytest.fixture(scope="module")
def codecs(resolved: Resolved, tmp_path_factory: pytest.TempPathFactory) -> tuple[ModuleType, ModuleType]:
    folder = tmp_path_factory.mktemp("retrofit_codecs")
    package = folder / "retrofit_frames"
    package.mkdir()
    (package / "__init__.py").write_text("", encoding="utf-8")
    for files in (convert.emit(resolved), codec.emit(resolved), codec_v0.emit(resolved)):
        for path, text in files.items():
            if Path(path).name in ("conversion_support.py", "codec.py", "codec_v0.py"):
                (package / Path(path).name).write_text(text, encoding="utf-8")
    sys.path.insert(0, str(folder))
    try:
        return importlib.import_module("retrofit_frames.codec"), importlib.import_module("retrofit_frames.codec_v0")
    finally:
        sys.path.remove(str(folder))


class Stats:
    def saturate(self, key: str) -> None:
        raise AssertionError(f"saturated {key}")

    def reject(self, key: str) -> None:
        raise AssertionError(f"rejected {key}")


def _f32(x: float) -> float:
    return float(struct.unpack("<f", struct.pack("<f", x))[0])


def _temperature(cdr: bytes) -> tuple[int, int, str, float, float]:
    """sensor_msgs/Temperature's CDR: (sec, nanosec, frame_id, temperature, variance)."""
    sec, nanosec, length = struct.unpack_from("<iII", cdr, 4)
    frame = cdr[16:16 + length - 1].decode()
    at = 16 + length
    at += -(at - 4) % 8  # float64 alignment, from the encapsulation header's end
    temperature, variance = struct.unpack_from("<dd", cdr, at)
    return sec, nanosec, frame, temperature, variance


@pytest.mark.parametrize("prefix", ["", "sam1/"])
def test_empty_frame_id_is_never_prefixed(codecs: tuple[ModuleType, ModuleType], prefix: str) -> None:
    cyphal, dronecan = (bound_codec(m, prefix) for m in codecs)
    payload = struct.pack("<f", 300.0) + (5).to_bytes(3, "little")
    cdr, _ = cyphal.thermo_wire_to_ros(payload, RECEIVE_NS, Stats())
    sec, nanosec, frame, temperature, _variance = _temperature(bytes(cdr))
    assert (frame, sec * 1_000_000_000 + nanosec) == ("", RECEIVE_NS)  # stamped, never framed
    assert temperature == _f32(300.0 - _f32(273.15)) == 26.850006103515625  # C: 300.0f - 273.15f
    # DroneCAN StaticTemperature (float16 static_temperature, float16 variance): 300 K
    cdr, _ = dronecan.air_temp_wire_to_ros(struct.pack("<ee", 300.0, 0.5), RECEIVE_NS, Stats())
    assert _temperature(bytes(cdr))[2] == ""


@pytest.mark.parametrize("prefix", ["", "sam1/"])
def test_header_left_at_its_default(codecs: tuple[ModuleType, ModuleType], prefix: str) -> None:
    cyphal = bound_codec(codecs[0], prefix)
    payload = struct.pack("<f", 300.0) + (5).to_bytes(3, "little")
    cdr, _ = cyphal.thermo_raw_wire_to_ros(payload, RECEIVE_NS, Stats())
    assert _temperature(bytes(cdr))[:3] == (0, 0, "")


def test_the_object_path_leaves_the_default_header_alone(resolved: Resolved) -> None:
    """The bridge stamps and frames a header only where the spec has the bridge write it (wiring.writes_header):
    the object converters' messages of `ros_defaults: [header]` keep the zero stamp too."""
    header_cls = SimpleNamespace(get_fields_and_field_types=lambda: {"header": "std_msgs/Header"})
    by_name = {rm.mapping.name: rm.mapping for rm in [*resolved.mappings, *resolved.dronecan_mappings]}
    assert writes_header(header_cls, SimpleNamespace(frame_id=by_name["thermo"].frame_id))  # ''
    assert not writes_header(header_cls, SimpleNamespace(frame_id=by_name["thermo_raw"].frame_id))  # None


def test_docs_say_it(resolved: Resolved) -> None:
    (text,) = (t for p, t in docs.emit(resolved).items() if p.endswith("interfaces.md"))
    assert "`''` (empty)" in text
    assert "WRAPS modulo 2^18 beyond the range (two’s complement), never saturates" in text  # the thruster
    assert r"= trunc(float32(r \* 80)) &gt;&gt; 3 → uint8" in text


def test_a_service_type_of_another_package_with_constants(resolved: Resolved) -> None:
    """Class 3: `external_services` is generated as its own package (exactly as declared, constants at the top of
    the request as rosidl reads them), built before the packages that need it, and the duty answers with it; the
    spec's own srv takes constants too."""
    files = ros_target.emit(resolved)
    assert files["ros/uavcan_ros_msgs/srv/UavcanGetNodeInfo.srv"].splitlines()[2:5] == [
        "uint8 HEALTH_OK=0", "uint8 HEALTH_WARNING=1", "uint16 node_id"]
    assert "ros/retrofit_msgs/srv/UavcanGetNodeInfo.srv" not in files  # the duty's default srv is not generated
    assert "<name>uavcan_ros_msgs</name>" in files["ros/uavcan_ros_msgs/package.xml"]
    assert "srv/UavcanGetNodeInfo.srv" in files["ros/uavcan_ros_msgs/CMakeLists.txt"]
    assert "srv/UavcanGetNodeInfo.srv" not in files["ros/retrofit_msgs/CMakeLists.txt"]
    assert "uint8 MODE_ZERO=1\nuint8 MODE_SPAN=2\nuint8 mode\n---\n" in files["ros/retrofit_msgs/srv/Calibrate.srv"]
    assert set(ros_target.build_order(resolved)) == {"retrofit_msgs", "uavcan_ros_msgs"}
    duties = {m.srv.full_name for m in resolved.service_mappings if m.mapping.duty == "get_node_info"}
    assert duties == {"uavcan_ros_msgs/UavcanGetNodeInfo"}


def test_a_dronecan_service_response_with_constants(resolved: Resolved, tmp_path: Path) -> None:
    """Class 3: a v0 service type's `response_constants` are emitted after `---`; dronecan's own parser reads them
    (and the request's `constants`) and computes the signature the generator wrote."""
    dsdl = pytest.importorskip("dronecan.dsdl")
    for path, text in dsdl_v0.emit(resolved).items():
        (tmp_path / path).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / path).write_text(text, encoding="utf-8")
    (found,) = (t for t in dsdl.parse_namespaces([str(tmp_path / "dsdl_v0" / "retrofit")])
                if t.full_name == "retrofit.power.Calibrate")
    assert [(c.name, c.value) for c in found.request_constants] == [("MODE_ZERO", 1)]
    assert [(c.name, c.value) for c in found.response_constants] == [("RESULT_OK", 0), ("RESULT_BUSY", 3)]
    (declared,) = (s for s in resolved.dronecan_types if s.name == "retrofit.power.Calibrate")
    assert found.get_data_type_signature() == declared.signature
