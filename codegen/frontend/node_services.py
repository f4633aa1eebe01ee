"""The device duties as typed ROS services (`bridge.node_services`, issue 19): GetNodeInfo, RestartNode and
GetTransportStats of any device, by the node id in the request, on the protocol of the bridge that serves them.

    bridge:
      node_services:                       # optional; absent: all three on, with the defaults below
        get_node_info: {service: uavcan_get_node_info, type: UavcanGetNodeInfo, timeout: 1.0}
        restart_node: false                # off
        get_transport_stats: {}            # on, the defaults

`node_services: false` turns all three off. Each duty is `false` (off), `true` or a mapping (on) with optional
`service` (a ROS name; relative names resolve under the run's namespace; default `uavcan_<duty>`), `type` (a srv of
the spec's `services`, bare or pkg/Name; default `<package>/Uavcan<Duty>`) and `timeout` (seconds, 0 < t <= 60,
default 1).

Invariants: structure only here (validate.node_services checks the names, the srv's fields and builds the service
mappings the runtime serves). The default srv types (:data:`DEFAULT_SRVS`) are added to the spec's services when a
duty that uses one is on and the spec declares no srv of that name: a spec that declares `UavcanGetNodeInfo` itself
has its own used (and checked as a `type:`), so SMARC's srv files can be copied in unchanged.
"""

from __future__ import annotations

from sam_codegen.frontend.reading import Reader, number, str_list
from sam_codegen.frontend.yaml_source import YNode, YScalar
from sam_codegen.model.diagnostics import Diagnostics, Pos
from sam_codegen.model.spec import Bridge, Field, NodeService, RosService
from sam_codegen.model.types import parse_ros_type

__all__ = ["DEFAULT_SRVS", "DUTIES", "parse_node_services", "with_duty_srvs"]

DUTIES = ("get_node_info", "restart_node", "get_transport_stats")
_DEFAULT_TIMEOUT_S = 1.0
_KEYS = ("service", "type", "timeout", "response_defaults")

# The default srv types (SMARC's uavcan_ros_bridge names them so), node id 16 bits (Cyphal/UDP node ids exceed 255).
_COMMON = [("success", "bool", "false when the device did not answer or is no device of this bridge's protocol"),
           ("message", "string", "why it failed (empty on success)")]
DEFAULT_SRVS: dict[str, tuple[str, str, list[tuple[str, str, str]]]] = {
    "get_node_info": ("UavcanGetNodeInfo", "A device's GetNodeInfo (DroneCAN) or GetInfo (Cyphal).", [
        *_COMMON,
        ("name", "string", "the node's name, e.g. org.sam.imu"),
        ("uptime_sec", "uint32", "Cyphal: from the node's last heartbeat the bridge heard (0 if none)"),
        ("health", "uint8", "0 nominal, 1 advisory, 2 caution, 3 warning (Cyphal: from its last heartbeat)"),
        ("mode", "uint8", "0 operational, 1 initialization, 2 maintenance, 3 software update"),
        ("vendor_specific_status_code", "uint16", "Cyphal: the heartbeat's vendor_specific_status_code"),
        ("software_version_major", "uint8", ""),
        ("software_version_minor", "uint8", ""),
        ("hardware_version_major", "uint8", ""),
        ("hardware_version_minor", "uint8", ""),
        ("software_vcs_revision_id", "uint64", "DroneCAN: software_version.vcs_commit"),
        ("unique_id", "uint8[16]", "the node's 128-bit unique id"),
    ]),
    "restart_node": ("UavcanRestartNode", "Restart a device (DroneCAN RestartNode, Cyphal ExecuteCommand RESTART).",
                     [*_COMMON]),
    "get_transport_stats": ("UavcanGetTransportStats", "A device's transfer counters (DroneCAN GetTransportStats, "
                            "Cyphal GetTransportStatistics).", [
                                *_COMMON,
                                ("transfers_tx", "uint64", "transfers the node sent"),
                                ("transfers_rx", "uint64", "transfers the node received"),
                                ("transfer_errors", "uint64", "transfers it could not receive"),
                            ]),
}


def parse_node_services(node: YNode | None, bridge_pos: Pos, package: str, diag: Diagnostics) -> list[NodeService]:
    """The three duties, in :data:`DUTIES` order; absent keys (or an absent section) are on with the defaults."""
    entries: dict[str, YNode] = {}
    if isinstance(node, YScalar) and node.value is False:  # `node_services: false`: every duty off
        return [NodeService(d, False, f"uavcan_{d}", f"{package}/{DEFAULT_SRVS[d][0]}", _DEFAULT_TIMEOUT_S, node.pos)
                for d in DUTIES]
    if node is not None:
        r = Reader(node, "bridge node_services", diag, DUTIES)
        entries = {d: n for d in DUTIES if (n := r.node(d)) is not None}
    out = []
    for duty in DUTIES:
        srv_name = DEFAULT_SRVS[duty][0]
        default = NodeService(duty, True, f"uavcan_{duty}", f"{package}/{srv_name}",
                              _DEFAULT_TIMEOUT_S, node.pos if node is not None else bridge_pos)
        entry = entries.get(duty)
        if entry is None:
            out.append(default)
            continue
        what = f"node service {duty!r}"
        if isinstance(entry, YScalar) and isinstance(entry.value, bool):
            out.append(NodeService(duty, entry.value, default.service, default.type, default.timeout_s, entry.pos))
            continue
        r = Reader(entry, what, diag, _KEYS)
        if not r.ok:
            continue
        service = r.get("service", str, default.service)
        type_ = r.get("type", str, None)
        timeout = default.timeout_s
        if r.node("timeout") is not None:
            value = number(r.node("timeout"), f"'timeout' of {what}", diag)
            if value is not None and not 0 < value <= 60:
                diag.error(r.key_pos("timeout"), f"'timeout' of {what} is {value} s", "0 < timeout <= 60 (seconds)")
            elif value is not None:
                timeout = float(value)
        full = default.type
        if type_ is not None:
            full = type_.replace("/srv/", "/") if "/" in type_ else f"{package}/{type_}"
        defaults = tuple(p for p, _ in str_list(r.node("response_defaults"), f"response_defaults of {what}", diag))
        out.append(NodeService(duty, True, service or default.service, full, timeout, entry.pos,
                               r.key_pos("type") if type_ is not None else entry.pos, type_ is not None, defaults))
    return out


def with_duty_srvs(services: dict[str, RosService], bridge: Bridge | None, package: str) -> dict[str, RosService]:
    """``services`` with the default srv of each duty that is on and names it, unless the spec declares one of
    that name itself (then the spec's own is the duty's type)."""
    if bridge is None:
        return services
    out = dict(services)
    for ns in bridge.node_services:
        name, description, response = DEFAULT_SRVS[ns.duty]
        full = f"{package}/{name}"
        if not ns.enabled or ns.type_given or ns.type != full or full in out:
            continue
        out[full] = RosService(package, name, [Field("node_id", parse_ros_type("uint16"), "the device's node id")],
                               [Field(n, parse_ros_type(t), c) for n, t, c in response], description)
    return out
