"""The DroneCAN (UAVCAN v0) part of the interface reference (docs/interfaces.md): the layouts, the devices' DroneCAN
firmware, the spec's own v0 types and the DroneCAN mappings.

dronecan_context gives the template's `dronecan` variable, None when the spec has no DroneCAN at all (one layout, no
DroneCAN device, type or mapping), so a Cyphal-only reference has no DroneCAN section. A mapping's field table is
worded by wording.field_rows, as for Cyphal mappings. Imported only by the package (emit).
"""

from __future__ import annotations

from sam_codegen.model.protocols.dronecan import DRONECAN
from sam_codegen.targets.docs.graph import UAVCAN_TO_ROS
from sam_codegen.targets.docs.traffic import traffic_words
from sam_codegen.targets.docs.wording import field_rows, fmt_number, fmt_rate
from sam_codegen.validate.mapping_rules import format_path
from sam_codegen.validate.panic_duty import panic_duty
from sam_codegen.validate.resolve import Resolved


def dronecan_context(resolved: Resolved) -> dict[str, object]:
    """{"dronecan": the DroneCAN sections of the reference, or None when there is nothing to show}."""
    spec = resolved.spec
    devices_by_id = spec.devices_by_node_id()
    layouts = [{
        "name": layout.name, "description": layout.description,
        "cyphal": layout.devices("cyphal"), "dronecan": layout.devices("dronecan"),
        "mappings": len(layout.cyphal_mappings) + len(layout.dronecan_mappings),
    } for layout in resolved.layouts]
    devices = [{
        "name": d.name, "node_id": d.node_id, "default": d.protocol,
        "publishes": [f"{p.type} at {fmt_rate(p.rate_hz)}" for p in d.dronecan_publishes],
        "subscribes": [f"{p.type} at {fmt_rate(p.rate_hz)}" for p in d.dronecan_subscribes],
    } for d in spec.devices.values() if DRONECAN.name in d.protocols]
    types = [{
        "name": t.name, "id": t.data_type_id, "signature": f"0x{t.signature:016X}", "description": t.description,
        "fields": [{"name": f.name, "type": str(f.type), "comment": f.comment or ("padding" if not f.name else "")}
                   for f in t.declared_fields],
        "constants": [{"name": c.name, "type": str(c.type), "value": fmt_number(c.value), "comment": c.comment}
                      for c in t.constants],
    } for t in resolved.dronecan_types]

    def nodes(ids: list[int]) -> list[str]:
        return [f"{n} ({devices_by_id[n].name})" if n in devices_by_id else str(n) for n in ids]

    mappings = []
    commanding: dict[str, list[str]] = {}  # data type -> the ROS->UAVCAN mappings that opted in to share it
    for rm in resolved.dronecan_mappings:
        if rm.mapping.shares_data_type and rm.mapping.direction != UAVCAN_TO_ROS:
            commanding.setdefault(rm.mapping.data_type, []).append(rm.mapping.name)
    for rm in resolved.dronecan_mappings:
        m = rm.mapping
        to_ros = m.direction == UAVCAN_TO_ROS
        rows = field_rows(rm)  # select rows first
        mappings.append({
            "name": m.name, "to_ros": to_ros, "direction": "UAVCAN → ROS" if to_ros else "ROS → UAVCAN",
            "data_type": m.data_type, "topic": m.topic, "ros_type": rm.ros_message.full_name,
            "data_type_id": getattr(rm.dsdl_struct, "data_type_id", None),
            "nodes": ["any node"] if m.any_node else nodes(m.source_node_ids if to_ros else m.destination_node_ids),
            "any_node": m.any_node,
            "shares_with": [n for n in commanding.get(m.data_type, []) if n != m.name] if m.shares_data_type else [],
            "select": ", ".join(f"{format_path(list(p))} = {v}" for p, _, v in rm.select),
            "elements": [f"{format_path(list(path))}[{u}]" for path, uses in rm.elements.items() for u in uses],
            "frame_id": m.frame_id, "rate": fmt_rate(rm.rate_hz), "auto": m.auto,
            "on_out_of_range": m.on_out_of_range, "rows": rows, "traffic": traffic_words(m),
        })
    chosen = spec.dronecan_namespaces
    namespaces = (f"{', '.join(f'`{n}`' for n in resolved.dronecan.namespaces)} (`dronecan_namespaces`: the data "
                  "type ids of the other namespaces are free for the spec's own types)"
                  if chosen is not None and resolved.dronecan is not None
                  else "every namespace the `dronecan` package bundles (the default: their data type ids stay taken)")
    duty = panic_duty(spec)
    bridge = spec.bridge.name if spec.bridge is not None else "bridge"
    builtin = f"the bridge's built-in duty (`/{bridge}/panic` broadcast three times, `/{bridge}/panic_received`)"
    own = "the spec's DroneCAN mappings of `uavcan.protocol.Panic`"
    panic = {"builtin": builtin, "mappings": f"{own} (`panic_duty: mappings`; the built-in duty is off)",
             "both": f"{own} and {builtin} (`panic_duty: both`)"}[duty]
    return {"dronecan": {"layouts": layouts, "devices": devices, "types": types, "mappings": mappings,
                         "namespaces": namespaces, "panic": panic}
            if devices or types or mappings or len(layouts) > 1 else None}


__all__ = ["dronecan_context"]
