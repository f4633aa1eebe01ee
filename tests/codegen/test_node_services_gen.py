"""The device duties as typed services (`bridge.node_services`, issue 19) in the generated output: the default srv
types in the spec's package, the service mappings per protocol in ``services.py``, the names, types and timeouts the
spec sets, the spec's own srv (its `ok` as `success`), and which protocols get them."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from sam_codegen.build import generate

SPECS = Path(__file__).parents[1] / "specs"
DUTIES = ("get_node_info", "restart_node", "get_transport_stats")


def _table(files: dict[str, str], vehicle: str) -> dict[tuple[str, str], Any]:
    namespace: dict[str, Any] = {}
    exec(compile(files[f"python/{vehicle}_bridge/services.py"], "services.py", "exec"), namespace)
    return {(m.name, m.protocol): m for m in namespace["SERVICE_MAPPINGS"]}


def _spec(tmp_path: Path, name: str, old: str, new: str) -> Path:
    text = (SPECS / f"{name}.yaml").read_text(encoding="utf-8")
    assert text.count(old) == 1
    path = tmp_path / f"{name}.yaml"
    path.write_text(text.replace(old, new, 1), encoding="utf-8")
    return path


def test_default_srvs_in_the_package() -> None:
    pytest.importorskip("dronecan")
    files = generate(SPECS / "auv_services.yaml")
    body = [line for line in files["ros/lolo_msgs/srv/UavcanGetNodeInfo.srv"].splitlines()
            if line and not line.startswith("#")]
    assert body == ["uint16 node_id", "---", "bool success", "string message", "string name", "uint32 uptime_sec",
                    "uint8 health", "uint8 mode", "uint16 vendor_specific_status_code", "uint8 software_version_major",
                    "uint8 software_version_minor", "uint8 hardware_version_major", "uint8 hardware_version_minor",
                    "uint64 software_vcs_revision_id", "uint8[16] unique_id"]
    restart = [line for line in files["ros/lolo_msgs/srv/UavcanRestartNode.srv"].splitlines()
               if line and not line.startswith("#")]
    assert restart == ["uint16 node_id", "---", "bool success", "string message"]
    stats = [line for line in files["ros/lolo_msgs/srv/UavcanGetTransportStats.srv"].splitlines()
             if line and not line.startswith("#")]
    assert stats == ["uint16 node_id", "---", "bool success", "string message", "uint64 transfers_tx",
                     "uint64 transfers_rx", "uint64 transfer_errors"]
    for name in ("GetNodeInfo", "RestartNode", "GetTransportStats"):
        assert f'"srv/Uavcan{name}.srv"' in files["ros/lolo_msgs/CMakeLists.txt"]


def test_dronecan_duties_in_the_table() -> None:
    """auv_services' only device is on DroneCAN: the duties go there, by the standard v0 services."""
    pytest.importorskip("dronecan")
    table = _table(generate(SPECS / "auv_services.yaml"), "lolo")
    duties = {k: m for k, m in table.items() if m.duty is not None}
    assert sorted(duties) == sorted((f"node_services.{d}", "dronecan") for d in DUTIES)
    info = duties["node_services.get_node_info", "dronecan"]
    assert (info.service, info.ros_type, info.data_type, info.data_type_id) == (
        "uavcan_get_node_info", "lolo_msgs/srv/UavcanGetNodeInfo", "uavcan.protocol.GetNodeInfo", 1)
    assert info.destination_field == "node_id" and info.timeout_s == 1.0 and info.duty == "get_node_info"
    links = {link.target: (link.source, link.kind) for link in info.response}
    assert links["unique_id"] == ("hardware_version.unique_id", "bytes")
    assert links["uptime_sec"] == ("status.uptime_sec", "int") and links["success"] == (None, "bool")
    restart = duties["node_services.restart_node", "dronecan"]
    assert [(link.target, link.value) for link in restart.request] == [("magic_number", 0xACCE551B1E)]
    assert [(link.target, link.source, link.kind) for link in restart.response] == [("success", "ok", "bool")]
    assert (restart.success_field, restart.message_field) == ("success", "message")


def test_cyphal_duties_in_the_table() -> None:
    """auv_cyphal_services' device is on Cyphal: GetInfo, ExecuteCommand RESTART, GetTransportStatistics; the
    heartbeat gives what GetInfo lacks."""
    table = _table(generate(SPECS / "auv_cyphal_services.yaml"), "ran")
    duties = {k: m for k, m in table.items() if m.duty is not None}
    assert sorted(duties) == sorted((f"node_services.{d}", "cyphal") for d in DUTIES)
    ids = {k[0]: (m.data_type, m.data_type_id) for k, m in duties.items()}
    assert ids == {"node_services.get_node_info": ("uavcan.node.GetInfo.1.0", 430),
                   "node_services.restart_node": ("uavcan.node.ExecuteCommand.1.1", 435),
                   "node_services.get_transport_stats": ("uavcan.node.GetTransportStatistics.0.1", 434)}
    info = {link.target: link.source for link in duties["node_services.get_node_info", "cyphal"].response}
    assert info["uptime_sec"] == "heartbeat.uptime_s" and info["health"] == "heartbeat.health"
    assert info["software_vcs_revision_id"] == "software_vcs_revision_id"
    restart = duties["node_services.restart_node", "cyphal"]
    assert [(link.target, link.value) for link in restart.request] == [("command", 65535), ("parameter", "")]
    assert [(link.target, link.source, link.kind) for link in restart.response] == [("success", "status",
                                                                                       "ok_if_zero")]
    stats = {link.target: link.source for link in duties["node_services.get_transport_stats", "cyphal"].response}
    assert stats["transfers_tx"] == "transfer_statistics.num_emitted"


def test_both_protocols_for_a_spec_with_both(tmp_path: Path) -> None:
    """SAM's devices have firmware for both protocols: each duty is mapped on both; each bridge serves its own."""
    pytest.importorskip("dronecan")
    table = _table(generate(Path(__file__).parents[2] / "spec" / "interfaces.yaml"), "sam")
    protocols = sorted({(k[0], m.protocol) for k, m in table.items() if m.duty is not None})
    assert protocols == sorted((f"node_services.{d}", p) for d in DUTIES for p in ("cyphal", "dronecan"))


def test_names_types_timeouts_and_off(tmp_path: Path) -> None:
    pytest.importorskip("dronecan")
    spec = _spec(tmp_path, "auv_services", "bridge:\n  name: bridge\n  node_id: 100\n",
                 "bridge:\n  name: bridge\n  node_id: 100\n  node_services:\n"
                 "    get_node_info: {service: core/uavcan_get_node_info, timeout: 0.25}\n"
                 "    restart_node: false\n"
                 "    get_transport_stats: {service: /stats, type: GetTransportStats}\n")
    files = generate(spec)
    duties = {k[0]: m for k, m in _table(files, "lolo").items() if m.duty is not None}
    assert sorted(duties) == ["node_services.get_node_info", "node_services.get_transport_stats"]
    assert duties["node_services.get_node_info"].service == "core/uavcan_get_node_info"
    assert duties["node_services.get_node_info"].timeout_s == 0.25
    stats = duties["node_services.get_transport_stats"]
    assert (stats.service, stats.ros_type) == ("/stats", "lolo_msgs/srv/GetTransportStats")
    # the spec's own srv: uint8 node_id; it has success, message and the counters, all filled
    assert sorted(link.target for link in stats.response) == ["success", "transfer_errors", "transfers_rx",
                                                              "transfers_tx"]
    srvs = sorted(p for p in files if "/srv/Uavcan" in p)  # only the default of the duty that uses it
    assert srvs == ["ros/lolo_msgs/srv/UavcanGetNodeInfo.srv"]


def test_the_specs_own_srv_of_the_default_name_wins_and_ok_is_success(tmp_path: Path) -> None:
    """A spec that declares UavcanRestartNode itself (SMARC's: uint8 node_id -> bool ok) has its own used."""
    pytest.importorskip("dronecan")
    spec = _spec(tmp_path, "auv_services", "services:\n",
                 "services:\n  UavcanRestartNode:\n    request:\n      - {name: node_id, type: uint8}\n"
                 "    response:\n      - {name: ok, type: bool}\n")
    files = generate(spec)
    body = [line for line in files["ros/lolo_msgs/srv/UavcanRestartNode.srv"].splitlines()
            if line and not line.startswith("#")]
    assert body == ["uint8 node_id", "---", "bool ok"]
    restart = _table(files, "lolo")["node_services.restart_node", "dronecan"]
    assert [(link.target, link.source) for link in restart.response] == [("ok", "ok")]
    assert (restart.success_field, restart.message_field) == ("ok", None)


def test_docs_list_the_duties() -> None:
    pytest.importorskip("dronecan")
    md = generate(SPECS / "auv_services.yaml")["docs/interfaces.md"]
    assert ("- Service: `uavcan_restart_node` (`lolo_msgs/srv/UavcanRestartNode`) → `uavcan.protocol.RestartNode` "
            "(id 5) to the node named by the request's node\\_id, timeout 1 s") in md
    assert "| `unique_id` | ← | `hardware_version.unique_id` | the bytes as they are |" in md
