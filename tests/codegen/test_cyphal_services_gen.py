"""Cyphal service mappings in the generated output (issue 19): tests/specs/auv_cyphal_services.yaml's table
(``python/ran_bridge/services.py``) that the runtime's CyphalServices interprets, and the interface reference."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from sam_codegen.build import generate

SPEC = Path(__file__).parents[1] / "specs" / "auv_cyphal_services.yaml"


def _table() -> dict[str, Any]:
    namespace: dict[str, Any] = {}
    source = generate(SPEC)["python/ran_bridge/services.py"]
    exec(compile(source, "services.py", "exec"), namespace)  # standard library only
    return {m.name: m for m in namespace["SERVICE_MAPPINGS"]}


def test_the_table_has_the_protocol_service_ids_and_links() -> None:
    table = _table()
    limits, info = table["set_charge_limits"], table["get_node_info"]
    assert (limits.protocol, limits.data_type, limits.data_type_id) == ("cyphal", "ran.power.SetChargeLimits.1.0",
                                                                        200)
    assert (info.protocol, info.data_type, info.data_type_id) == ("cyphal", "uavcan.node.GetInfo.1.0", 430)
    assert limits.device == "charger" and limits.timeout_s == 0.5 and info.destination_field == "node_id"
    low = limits.request[0]
    assert (low.target, low.source, low.kind, low.lo, low.hi) == ("low_percent", "low", "int", 0, 255)
    reason = next(link for link in limits.response if link.target == "reason")
    assert (reason.source, reason.kind) == ("reason", "text")  # uint8[<=32] -> string
    assert [(link.target, link.source) for link in info.response][1:] == [
        ("name", "name"), ("software_major", "software_version.major"),
        ("software_minor", "software_version.minor")]
    assert (limits.success_field, limits.message_field) == ("success", "message")


def test_docs_name_the_cyphal_service_id() -> None:
    md = generate(SPEC)["docs/interfaces.md"]
    assert ("- Service: `/charger/set_limits` (`ran_msgs/srv/SetChargeLimits`) → `ran.power.SetChargeLimits.1.0` "
            "(Cyphal service id 200) to node 31 (charger), timeout 0.5 s") in md
    assert "`uavcan.node.GetInfo.1.0` (Cyphal service id 430) to the node named by the request's node\\_id" in md
