"""The DroneCAN (UAVCAN v0) part of the interface reference (docs/interfaces.md): the layouts, the devices' DroneCAN
firmware, the spec's own v0 types and the DroneCAN mappings.

dronecan_context gives the template's `dronecan` variable, None when the spec has no DroneCAN at all (one layout, no
DroneCAN device, type or mapping), so a Cyphal-only reference has no DroneCAN section. A mapping's field table is
worded by wording.field_rows, as for Cyphal mappings. Imported only by the package (emit).
"""

from __future__ import annotations

from sam_codegen.targets.docs.graph import UAVCAN_TO_ROS
from sam_codegen.targets.docs.traffic import traffic_words
from sam_codegen.targets.docs.wording import field_rows, fmt_number, fmt_rate
from sam_codegen.validate.mapping_rules import format_path
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
    } for d in spec.devices.values() if "dronecan" in d.protocols]
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
    for rm in resolved.dronecan_mappings:
        m = rm.mapping
        to_ros = m.direction == UAVCAN_TO_ROS
        rows = field_rows(rm)  # select rows first
        mappings.append({
            "name": m.name, "to_ros": to_ros, "direction": "UAVCAN → ROS" if to_ros else "ROS → UAVCAN",
            "data_type": m.data_type, "topic": m.topic, "ros_type": rm.ros_message.full_name,
            "data_type_id": getattr(rm.dsdl_struct, "data_type_id", None),
            "nodes": nodes(m.source_node_ids if to_ros else m.destination_node_ids),
            "select": ", ".join(f"{format_path(list(p))} = {v}" for p, _, v in rm.select),
            "elements": [f"{format_path(list(path))}[{u}]" for path, uses in rm.elements.items() for u in uses],
            "frame_id": m.frame_id, "rate": fmt_rate(rm.rate_hz), "auto": m.auto,
            "on_out_of_range": m.on_out_of_range, "rows": rows, "traffic": traffic_words(m),
        })
    return {"dronecan": {"layouts": layouts, "devices": devices, "types": types, "mappings": mappings}
            if devices or types or mappings or len(layouts) > 1 else None}


__all__ = ["dronecan_context"]
