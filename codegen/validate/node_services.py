"""The device duties of `bridge.node_services` (frontend.node_services) checked and made service mappings: one
:class:`ResolvedServiceMapping` per duty that is on and per protocol some device has ports for, so the runtime serves
them with the spec's own service mappings (one implementation of calls, timeouts, failure responses, counters and
/diagnostics: sam_runtime.bridge.backends.service_mappings).

The protocols' services:

- get_node_info: DroneCAN uavcan.protocol.GetNodeInfo; Cyphal uavcan.node.GetInfo.1.0 (430), which has no uptime,
  health, mode or vendor code: those come from the node's last Heartbeat the bridge heard (0 if none).
- restart_node: DroneCAN uavcan.protocol.RestartNode (magic_number 0xACCE551B1E; `ok`); Cyphal
  uavcan.node.ExecuteCommand.1.1 (435), COMMAND_RESTART (status 0 is success).
- get_transport_stats: DroneCAN uavcan.protocol.GetTransportStats; Cyphal uavcan.node.GetTransportStatistics.0.1
  (434): transfer_statistics.num_emitted, num_received, num_errored.

Invariants: the srv (the default or the spec's own) has an integer request field `node_id`, which names the device
at each call; the duty writes the response fields it knows by name (:data:`DUTY_FIELDS`; `ok` is an alias of
`success`, as SMARC's UavcanRestartNode has it) and leaves the others at their defaults; a known field of an
incompatible type is an error with its position. The mapping's name is `node_services.<duty>` (a dot: no spec
mapping's name can take it); its service name is unique among the service mappings' and the duties'.
"""

from __future__ import annotations

from collections.abc import Callable

from sam_codegen.model.diagnostics import Diagnostics
from sam_codegen.model.protocols.registry import protocol as protocol_of
from sam_codegen.model.ros_names import ros_name_problem
from sam_codegen.model.spec import NodeService, RosService, ServiceMapping, Spec, V0Struct
from sam_codegen.model.types import ROS_INT_RANGES, RosType
from sam_codegen.validate.service_coverage import Lookup, check_response_written, response_leaf, response_leaves
from sam_codegen.validate.services import ResolvedServiceMapping, ServiceLink, bridge_written

__all__ = ["DUTY_FIELDS", "DUTY_TYPES", "resolve_node_services"]

DRONECAN_RESTART_MAGIC = 0xACCE551B1E
CYPHAL_COMMAND_RESTART = 65535

# (data type, Cyphal service id or None (DroneCAN: the catalog's data type id)) per duty and protocol
DUTY_TYPES: dict[tuple[str, str], tuple[str, int | None]] = {
    ("get_node_info", "dronecan"): ("uavcan.protocol.GetNodeInfo", None),
    ("restart_node", "dronecan"): ("uavcan.protocol.RestartNode", None),
    ("get_transport_stats", "dronecan"): ("uavcan.protocol.GetTransportStats", None),
    ("get_node_info", "cyphal"): ("uavcan.node.GetInfo.1.0", 430),
    ("restart_node", "cyphal"): ("uavcan.node.ExecuteCommand.1.1", 435),
    ("get_transport_stats", "cyphal"): ("uavcan.node.GetTransportStatistics.0.1", 434),
}

# ROS response field -> (kind, DroneCAN source, Cyphal source). Kinds: "int" (any ROS integer, saturated), "bool",
# "text" (a string), "bytes" (a uint8 array of 16 or more), "ok_if_zero" (a bool: the source is 0). A source
# "heartbeat.<x>" is the node's last heartbeat the bridge heard; None: the constant True (the device answered).
DUTY_FIELDS: dict[str, dict[str, tuple[str, str | None, str | None]]] = {
    "get_node_info": {
        "success": ("bool", None, None),
        "name": ("text", "name", "name"),
        "uptime_sec": ("int", "status.uptime_sec", "heartbeat.uptime_s"),
        "health": ("int", "status.health", "heartbeat.health"),
        "mode": ("int", "status.mode", "heartbeat.mode"),
        "vendor_specific_status_code": ("int", "status.vendor_specific_status_code", "heartbeat.vssc"),
        "software_version_major": ("int", "software_version.major", "software_version.major"),
        "software_version_minor": ("int", "software_version.minor", "software_version.minor"),
        "hardware_version_major": ("int", "hardware_version.major", "hardware_version.major"),
        "hardware_version_minor": ("int", "hardware_version.minor", "hardware_version.minor"),
        "software_vcs_revision_id": ("int", "software_version.vcs_commit", "software_vcs_revision_id"),
        "unique_id": ("bytes", "hardware_version.unique_id", "unique_id"),
    },
    "restart_node": {
        "success": ("bool", "ok", "status"),
    },
    "get_transport_stats": {
        "success": ("bool", None, None),
        "transfers_tx": ("int", "transfers_tx", "transfer_statistics.num_emitted"),
        "transfers_rx": ("int", "transfers_rx", "transfer_statistics.num_received"),
        "transfer_errors": ("int", "transfer_errors", "transfer_statistics.num_errored"),
    },
}
_EXPECTED = {"int": "an integer", "bool": "bool", "text": "string", "bytes": "uint8[16] (or a longer uint8 array)",
             "ok_if_zero": "bool"}


def _fits(kind: str, t: RosType) -> bool:
    if kind == "bytes":
        return t.base in ("uint8", "byte", "char") and bool(t.array) and (t.capacity is None or t.capacity >= 16)
    if t.array:
        return False
    return {"int": t.base in ROS_INT_RANGES, "bool": t.base == "bool", "text": t.base == "string"}[kind]


def _duty_protocols(spec: Spec) -> list[str]:
    """The protocols some device has ports for (each bridge serves its own protocol's devices)."""
    found = {p for d in spec.devices.values() for p in d.protocols}
    return [p for p in ("dronecan", "cyphal") if p in found]


def resolve_node_services(spec: Spec, diag: Diagnostics, signed: Callable[[str], V0Struct | None],
                          lookup: Lookup = lambda name: None) -> list[ResolvedServiceMapping]:
    """`signed`: the V0Catalog's ``signed`` (a DroneCAN type's data type id and signature)."""
    if spec.bridge is None:
        return []
    taken = {m.service: f"service mapping {m.name!r}" for m in spec.bridge.service_mappings}
    out: list[ResolvedServiceMapping] = []
    for ns in spec.bridge.node_services:
        if not ns.enabled:
            continue
        what = f"node service {ns.duty!r}"
        problem = ros_name_problem(ns.service)
        if problem is not None:
            diag.error(ns.pos, f"service name {ns.service!r} of {what} is not a valid ROS name: {problem}",
                       "a ROS name, e.g. uavcan_get_node_info or core/uavcan_get_node_info")
            continue
        if ns.service in taken:
            diag.error(ns.pos, f"service {ns.service} of {what} is already served by {taken[ns.service]}",
                       "a name of its own")
            continue
        taken[ns.service] = what
        srv = spec.services.get(ns.type)
        if srv is None:
            diag.error(ns.type_pos, f"unknown service type {ns.type!r} of {what}",
                       "a type of `services` or `external_services` (pkg/Name)")
            continue
        response = _response_fields(ns, srv, what, diag, lookup)
        if response is None:
            continue
        for protocol in _duty_protocols(spec):
            resolved = _mapping(ns, srv, protocol, response, signed, lookup)
            if resolved is not None:
                out.append(resolved)
    return out


def _response_fields(ns: NodeService, srv: RosService, what: str, diag: Diagnostics, lookup: Lookup
                     ) -> list[str] | None:
    """The known response fields the srv has, nested ones by their path (`status.uptime_sec`: a srv whose
    response holds a message of them), checked; every other leaf must be in the duty's response_defaults (issue
    27: never a silent zero); None after reporting a problem."""
    node_id = next((f for f in srv.request if f.name == "node_id"), None)
    ok = True
    if node_id is None or not isinstance(node_id.type, RosType) or node_id.type.array \
            or node_id.type.base not in ROS_INT_RANGES:
        diag.error(ns.type_pos, f"the request of {srv.full_name} ({what}) has no integer field 'node_id'",
                   "a request field `node_id` of an integer type (uint16: Cyphal/UDP node ids exceed 255)")
        ok = False
    known = DUTY_FIELDS[ns.duty]
    found = []
    names = {f.name for f in srv.response}
    for path, _, _ in response_leaves(srv, lookup):
        f = response_leaf(srv, path, lookup)
        assert f is not None
        name = "success" if path == "ok" and "success" not in names else f.name  # SMARC's `bool ok`
        if name not in known or (name == "success" and "." in path):
            continue
        kind = known[name][0]
        assert isinstance(f.type, RosType)
        if not _fits(kind, f.type):
            diag.error(f.pos if f.pos.line else ns.type_pos,
                       f"response field {path!r} ({f.type}) of {srv.full_name} cannot hold {name} of {what}",
                       _EXPECTED[kind])
            ok = False
            continue
        found.append(path)
    if ok and not check_response_written(diag, ns.type_pos, srv, set(found) | bridge_written(srv, duty=True),
                                         ns.response_defaults, what,
                                         "a field the duty writes (" + ", ".join(known) + ")", lookup,
                                         at_field=not ns.type_pos.line):
        ok = False
    return found if ok else None


def _mapping(ns: NodeService, srv: RosService, protocol: str, fields: list[str],
             signed: Callable[[str], V0Struct | None], lookup: Lookup) -> ResolvedServiceMapping | None:
    data_type, service_id = DUTY_TYPES[(ns.duty, protocol)]
    struct = None
    v0 = protocol_of(protocol).v0
    if v0:
        struct = signed(data_type)
        if struct is None:  # the standard definitions could not be read: reported by the catalog
            return None
        service_id = struct.data_type_id
    known = DUTY_FIELDS[ns.duty]
    response = []
    for name in fields:  # a path: `status.uptime_sec` is uptime_sec
        key = "success" if name == "ok" else name.rsplit(".", 1)[-1]
        kind, dronecan_source, cyphal_source = known[key]
        source = dronecan_source if v0 else cyphal_source
        if source == "status":  # Cyphal ExecuteCommand: status 0 is success
            kind = "ok_if_zero"
        if source is None:
            response.append(ServiceLink(name, None, kind, True))
        else:
            lo, hi = (-float("inf"), float("inf"))
            if kind == "int":
                f = response_leaf(srv, name, lookup)
                assert f is not None and isinstance(f.type, RosType)
                lo, hi = ROS_INT_RANGES[f.type.base]
            response.append(ServiceLink(name, source, kind, None, None, None, lo, hi))
    request: list[ServiceLink] = []
    if ns.duty == "restart_node" and v0:
        request.append(ServiceLink("magic_number", None, "int", DRONECAN_RESTART_MAGIC, lo=0, hi=2 ** 40 - 1))
    elif ns.duty == "restart_node":
        request += [ServiceLink("command", None, "int", CYPHAL_COMMAND_RESTART, lo=0, hi=65535),
                    ServiceLink("parameter", None, "text", "", lo=0, hi=255)]
    mapping = ServiceMapping(f"node_services.{ns.duty}", ns.service, srv.full_name, data_type, 0, ns.timeout_s,
                             protocol=protocol, pos=ns.pos, destination_field="node_id", service_id=service_id,
                             duty=ns.duty)
    return ResolvedServiceMapping(mapping, srv, struct, request, response, data_type, service_id or 0)
