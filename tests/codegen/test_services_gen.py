"""Service types (issue 19): the spec's DroneCAN service types come out as v0 DSDL that dronecan's own parser reads
with the same id, kind, fields and signature as the generator computed; the spec's `services` come out as .srv
files listed in the package's CMakeLists, which rosidl builds and rclpy imports and serializes (with the device
duties' default srvs, UavcanGetNodeInfo...)."""

from __future__ import annotations

import json
import textwrap
from pathlib import Path

import pytest

from sam_codegen.build import generate
from sam_codegen.frontend.loader import load_spec_file
from sam_codegen.validate.resolve import validate

SPEC = Path(__file__).parents[1] / "specs" / "auv_services.yaml"


def test_v0_service_type_as_dronecan_parses_it(tmp_path: Path) -> None:
    dsdl = pytest.importorskip("dronecan.dsdl")
    files = generate(SPEC)
    text = files["dsdl_v0/lolo/power/201.UpdateBattery.uavcan"]
    assert "\n---\n" in text and "service, data type id 201" in text
    folder = tmp_path / "lolo" / "power"
    folder.mkdir(parents=True)
    (folder / "201.UpdateBattery.uavcan").write_text(text)
    (parsed,) = dsdl.parse_namespaces([str(tmp_path / "lolo")])
    resolved = validate(load_spec_file(SPEC))
    (ours,) = resolved.dronecan_types
    assert parsed.kind == parsed.KIND_SERVICE and parsed.default_dtid == 201 == ours.data_type_id
    assert parsed.get_data_type_signature() == ours.signature != 0
    assert [f.name for f in parsed.request_fields] == ["command", "charge"]
    assert [f.name for f in parsed.response_fields] == ["success"]
    assert [c.name for c in parsed.request_constants] == ["COMMAND_RECALIBRATE"]


def test_standard_service_types_have_their_response() -> None:
    """The catalog reads a standard service's response too (what a service mapping links)."""
    pytest.importorskip("dronecan")
    resolved = validate(load_spec_file(SPEC))
    assert resolved.dronecan is not None
    info = resolved.dronecan.get("uavcan.protocol.GetNodeInfo")
    assert info is not None and info.service and info.fields == []
    assert [f.name for f in info.response] == ["status", "software_version", "hardware_version", "name"]


def test_srv_file_and_cmake_list() -> None:
    files = generate(SPEC)
    srv = files["ros/lolo_msgs/srv/UpdateBattery.srv"]
    body = [line for line in srv.splitlines() if line and not line.startswith("#")]
    assert body == ["uint8 command", "float32 charge_percent", "---", "bool success", "uint8 status"]
    assert '"srv/UpdateBattery.srv"' in files["ros/lolo_msgs/CMakeLists.txt"]
    assert files == generate(SPEC)  # deterministic


_SRV_SCRIPT = textwrap.dedent(
    """\
    import json

    from rclpy.serialization import deserialize_message, serialize_message

    from lolo_msgs.srv import UpdateBattery

    request = UpdateBattery.Request(command=1, charge_percent=42.5)
    back = deserialize_message(serialize_message(request), UpdateBattery.Request)
    response = UpdateBattery.Response()
    from lolo_msgs.srv import UavcanGetNodeInfo, UavcanGetTransportStats, UavcanRestartNode

    info = deserialize_message(serialize_message(UavcanGetNodeInfo.Request(node_id=300)), UavcanGetNodeInfo.Request)
    stats = UavcanGetTransportStats.Response(transfers_tx=2**63)
    stats = deserialize_message(serialize_message(stats), UavcanGetTransportStats.Response)
    print("RESULT " + json.dumps({"command": back.command, "charge": back.charge_percent,
                                  "success": response.success, "status": response.status,
                                  "duties": [info.node_id, len(UavcanGetNodeInfo.Response().unique_id),
                                             stats.transfers_tx, UavcanRestartNode.Response().success]}))
    """
)


@pytest.mark.ros
@pytest.mark.slow
def test_srv_builds_with_rosidl_and_imports(tmp_path: Path) -> None:
    from helpers.ros_packages import run_child
    from helpers.spec_build import built_spec

    built = built_spec("auv_services")
    script = tmp_path / "srv_check.py"
    script.write_text(_SRV_SCRIPT)
    proc = run_child([str(script)], built.prefix, "0", timeout=120)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    lines = [line for line in proc.stdout.splitlines() if line.startswith("RESULT ")]
    assert lines, proc.stdout + proc.stderr
    assert json.loads(lines[-1].removeprefix("RESULT ")) == {"command": 1, "charge": 42.5, "success": False,
                                                            "status": 0, "duties": [300, 16, 2**63, False]}


def test_docs_list_the_services() -> None:
    """The interface reference has the srv types, the DroneCAN service type with its response, and each service
    mapping with its target, timeout, failure fields and field rows."""
    md = generate(SPEC)["docs/interfaces.md"]
    section = md[md.index("\n## Services\n"):]
    assert "#### `lolo_msgs/srv/UpdateBattery`" in section and "| response | `status` | `uint8` |" in section
    assert "Service data type id 201, signature `0x45BD5887DCE2B78B`." in section
    assert ("- Service: `/bms/update_battery` (`lolo_msgs/srv/UpdateBattery`) → `lolo.power.UpdateBattery` (id 201) "
            "to node 30 (bms), timeout 0.5 s") in section
    assert "| `uptime_sec` | ← | `status.uptime_sec` | rounded, saturated to \\[0, 4294967295\\] |" in section
    assert "- Failure shown in: `success`, `message`" in section
    assert "#### `lolo.power.SetChargeLimits.1.0`\n\nEach half extent 64 bytes." in section
    assert "| response | — | `void7` | — |" in section


def test_specs_without_services_have_no_services_output(tmp_path: Path) -> None:
    """A spec without services and with the device duties off (`node_services: false`) has no services output; by
    default it has the duties' srvs and their mappings only."""
    base = Path(__file__).parents[1] / "specs" / "minimal_v0.yaml"
    files = generate(base)
    assert sorted(p for p in files if "/srv/" in p) == [
        f"ros/skiff_msgs/srv/Uavcan{n}.srv" for n in ("GetNodeInfo", "GetTransportStats", "RestartNode")]
    spec = tmp_path / "minimal_v0.yaml"
    spec.write_text(base.read_text().replace("bridge:\n", "bridge:\n  node_services: false\n", 1))
    files = generate(spec)
    assert "\n## Services\n" not in files["docs/interfaces.md"]
    assert not any(p.endswith("/services.py") or "/srv/" in p for p in files)


def test_cyphal_service_type_as_pydsdl_reads_it(tmp_path: Path) -> None:
    """A `dsdl_types` entry with request and response is a Cyphal service type: emitted with `---` between its
    halves (each with the extent), read by pydsdl as a service with those fields."""
    pydsdl = pytest.importorskip("pydsdl")
    from sam_codegen.project.cyphal_path import dsdl_lookup_roots

    files = generate(SPEC)
    rel = "dsdl/lolo/power/SetChargeLimits.1.0.dsdl"
    (tmp_path / rel).parent.mkdir(parents=True)
    (tmp_path / rel).write_text(files[rel])
    (service,) = pydsdl.read_namespace(tmp_path / "dsdl" / "lolo", [str(r) for r in dsdl_lookup_roots()])
    assert isinstance(service, pydsdl.ServiceType) and service.full_name == "lolo.power.SetChargeLimits"
    assert [f.name for f in service.request_type.fields_except_padding] == ["low_percent", "high_percent"]
    assert [f.name for f in service.response_type.fields_except_padding] == ["accepted", "reason"]
    assert service.request_type.extent == service.response_type.extent == 64 * 8
    assert [c.name for c in service.request_type.constants] == ["MAX_PERCENT"]


def test_pydsdl_rejects_a_service_type_at_its_position(tmp_path: Path) -> None:
    """A Cyphal service type pydsdl refuses (its response outgrows the extent) is an error at the type's line."""
    pytest.importorskip("pydsdl")
    from sam_codegen.model.diagnostics import SpecError

    path = tmp_path / "auv_services.yaml"
    path.write_text(SPEC.read_text().replace('{name: reason, type: "uint8[<=32]"}', '{name: reason, type: '
                                             '"uint8[<=80]"}', 1))
    with pytest.raises(SpecError) as info:
        generate(path)
    (diagnostic,) = info.value.diagnostics
    assert str(diagnostic).startswith(f"{path}:8:3: error: DSDL type lolo.power.SetChargeLimits.1.0 is rejected by "
                                      "pydsdl: The specified extent of 512 bits is too small")
