"""A mapping's routing beyond its fields: which nodes it reaches (static node ids, or `any`), and several ROS->UAVCAN
mappings broadcasting one DroneCAN data type (`shares_data_type`).

Invariants:
- Static node ids stay the default (the design document asks for them). `source_node_ids: any` (both protocols) and
  DroneCAN's `destination_node_ids: any` are an explicit per-mapping choice; such a mapping reaches every device of
  the spec that has its port (for the rate, the layouts and the docs), and at run time the bridge accepts its port
  from every node id, so it routes only on what the message says (`select`, the items it reads).
- Two ROS->UAVCAN DroneCAN mappings of one data type that may command the same thing (no `select` value tells them
  apart, and their items chosen by key are not disjoint) are an error unless both say `shares_data_type: true`;
  with it each mapping still sends its own messages (never merged), so a device sees each topic's commands as they
  come.
"""

from __future__ import annotations

from sam_codegen.model.diagnostics import Diagnostics
from sam_codegen.model.protocols.registry import protocol as protocol_of
from sam_codegen.model.spec import ROS_TO_UAVCAN, UAVCAN_TO_ROS, Mapping, Spec
from sam_codegen.validate.mapping_rules import Key, ResolvedMapping, format_path

__all__ = ["check_routing", "check_shared_broadcasts", "port_users", "routed_node_ids"]


def port_users(spec: Spec, mapping: Mapping) -> list[int]:
    """The node ids of the devices that have `mapping`'s port on its protocol: publishing it for a UAVCAN->ROS
    mapping, subscribing to it for a ROS->UAVCAN one (in node id order)."""
    publishing = mapping.direction == UAVCAN_TO_ROS
    users: set[int] = set()
    for device in spec.devices.values():
        if mapping.protocol not in device.protocols:
            continue
        if protocol_of(mapping.protocol).v0:
            ports = device.dronecan_publishes if publishing else device.dronecan_subscribes
            if any(p.type == mapping.data_type for p in ports):
                users.add(device.node_id)
        else:
            cyphal = device.publishes if publishing else device.subscribes
            if any(p.subject_id == mapping.subject_id for p in cyphal):
                users.add(device.node_id)
    return sorted(users)


def routed_node_ids(spec: Spec, mapping: Mapping) -> list[int]:
    """The nodes `mapping` reaches: its static node ids, or with `any` every device that has its port."""
    if mapping.any_node:
        return port_users(spec, mapping)
    if mapping.direction == UAVCAN_TO_ROS:
        return list(mapping.source_node_ids)
    if protocol_of(mapping.protocol).v0:  # a broadcast: a set of destinations
        return list(mapping.destination_node_ids)
    return [] if mapping.destination_node_id is None else [mapping.destination_node_id]


def check_routing(spec: Spec, diag: Diagnostics) -> None:
    """`any` needs a device with the port (else the mapping reaches nothing, in the simulator and the docs alike);
    `shares_data_type` belongs to a ROS->UAVCAN DroneCAN mapping."""
    if spec.bridge is None:
        return
    for m in spec.bridge.all_mappings:
        entry = protocol_of(m.protocol)
        dronecan = entry.v0
        what = f"{entry.mapping_noun} {m.name!r}"
        if m.any_node and not port_users(spec, m):
            key = "source_node_ids" if m.direction == UAVCAN_TO_ROS else "destination_node_ids"
            verb, ports = ("publishes", "publishes") if m.direction == UAVCAN_TO_ROS else ("subscribes to",
                                                                                          "subscribes")
            port = f"{m.data_type} on DroneCAN" if dronecan else f"subject {m.subject_id}"
            diag.error(m.any_node_pos, f"{what} says `{key}: any`, but no device {verb} {port}",
                       f"a device with `{m.data_type}` in its DroneCAN {ports}" if dronecan
                       else f"a device with subject {m.subject_id} in its {ports}")
        if m.shares_data_type and m.direction == UAVCAN_TO_ROS:
            diag.error(m.pos, f"{what} goes UAVCAN->ROS: `shares_data_type` is for ROS->UAVCAN mappings "
                       "(UAVCAN->ROS mappings of one data type are told apart by source node and select)",
                       "no `shares_data_type`")


def check_shared_broadcasts(resolved: list[ResolvedMapping], diag: Diagnostics) -> None:
    """Two ROS->UAVCAN mappings that broadcast one data type must not command the same thing: they need
    different `select` values, or distinct items chosen by key (ArrayCommand's actuator ids), or both say
    `shares_data_type: true`. A mapping that says it but shares with no one is an error too (a stale opt-in)."""
    claims: dict[str, list[tuple[ResolvedMapping, dict[str, object], set[str] | None]]] = {}
    shared: set[str] = set()
    for rm in resolved:
        if rm.mapping.direction != ROS_TO_UAVCAN:
            continue
        m = rm.mapping
        select: dict[str, object] = {format_path(list(p)): v for p, _, v in rm.select}
        items: set[str] | None = None
        if rm.elements and all(isinstance(e, Key) for es in rm.elements.values() for e in es):
            items = {f"{format_path(list(path))}[{e}]" for path, es in rm.elements.items() for e in es}
        for other, other_select, other_items in claims.get(m.data_type, []):
            if any(k in other_select and other_select[k] != v for k, v in select.items()):
                continue  # different selections: different recipients
            overlap = items & other_items if items is not None and other_items is not None else None
            if overlap is not None and not overlap:
                continue
            if m.shares_data_type and other.mapping.shares_data_type:
                shared.update((m.name, other.mapping.name))
                continue
            what = f" ({', '.join(sorted(overlap))})" if overlap else ""
            lacking = [n.name for n in (other.mapping, m) if not n.shares_data_type]
            diag.error(m.pos, f"DroneCAN mappings {other.mapping.name!r} and {m.name!r} both command "
                       f"{m.data_type}{what}", "distinct `select` values or distinct items chosen by key, or one "
                       "mapping that writes every element, or `shares_data_type: true` in "
                       + " and ".join(repr(n) for n in lacking) + ": each then sends its own messages")
            shared.update((m.name, other.mapping.name))  # reported: no stale opt-in error on top
        claims.setdefault(m.data_type, []).append((rm, select, items))
    for rm in resolved:
        m = rm.mapping
        if m.shares_data_type and m.direction == ROS_TO_UAVCAN and m.name not in shared:
            diag.error(m.pos, f"DroneCAN mapping {m.name!r} says `shares_data_type: true`, but no other mapping "
                       f"commands what it commands of {m.data_type}", "no `shares_data_type`: it shares nothing")
