"""The services part of generated/docs/interfaces.md: the package's .srv types, the spec's DroneCAN service types
(request and response) and the bridge's service mappings with their field rows (empty for a spec without them, so
that its reference is unchanged)."""

from __future__ import annotations

import math
from typing import Any

from sam_codegen.model.protocols.registry import protocol as protocol_of
from sam_codegen.validate.resolve import Resolved
from sam_codegen.validate.services import ServiceLink

__all__ = ["services_context"]


def _conversion(link: ServiceLink, towards_uavcan: bool) -> str:
    if link.source is None:
        return f"the constant {link.value!r}"
    parts = []
    if link.source.startswith("heartbeat."):  # a device duty on Cyphal (validate.node_services)
        parts.append("from the node's last Heartbeat the bridge heard (0 if none)")
    if link.scale is not None or link.offset is not None:
        scale = 1.0 if link.scale is None else link.scale
        offset = 0.0 if link.offset is None else link.offset
        parts.append(f"(ROS - {offset:g}) / {scale:g}" if towards_uavcan else f"UAVCAN × {scale:g} + {offset:g}")
    if link.kind == "int":
        # (an int bound exactly: a uint64's maximum is no float)
        lo, hi = (str(b) if isinstance(b, int) else f"{b:.0f}" for b in (link.lo, link.hi))
        parts.append(f"rounded, saturated to [{lo}, {hi}]")
    elif link.kind == "text":
        parts.append("UTF-8 bytes" + (f", cut at {link.hi:g}" if towards_uavcan else ""))
    elif link.kind == "bool":
        parts.append("non-zero is true")
    elif link.kind == "ok_if_zero":
        parts.append("true when 0 (success)")
    elif link.kind == "bytes":
        parts.append("the bytes as they are")
    elif math.isfinite(link.hi):
        parts.append(f"saturated to ±{link.hi:g}")
    return "; ".join(parts) or "as is"


def services_context(resolved: Resolved) -> dict[str, Any]:
    spec = resolved.spec
    srvs = [{
        "name": f"{s.package}/srv/{s.name}", "description": s.description,
        "request": [{"name": f.name, "type": str(f.type), "comment": f.comment} for f in s.request],
        "response": [{"name": f.name, "type": str(f.type), "comment": f.comment} for f in s.response],
    } for s in resolved.services]
    v0 = [{
        "name": t.name, "id": t.data_type_id, "signature": f"0x{t.signature:016X}", "description": t.description,
        "request": [{"name": f.name, "type": str(f.type), "comment": f.comment} for f in t.declared_fields],
        "response": [{"name": f.name, "type": str(f.type), "comment": f.comment} for f in t.declared_response],
    } for t in resolved.dronecan_types if t.service]
    cyphal = [{
        "name": t.name, "description": t.description,
        "size": "sealed" if t.request.sealed else f"extent {t.request.extent} bytes",
        "request": [{"name": f.name, "type": str(f.type), "comment": f.comment} for f in t.request.declared_fields],
        "response": [{"name": f.name, "type": str(f.type), "comment": f.comment} for f in t.response.declared_fields],
    } for t in resolved.dsdl_services]
    by_id = spec.devices_by_node_id()
    mappings = []
    for rm in resolved.service_mappings:
        m = rm.mapping
        if m.destination_field is not None:
            destination = f"the node named by the request's {m.destination_field}"
        else:
            device = by_id.get(m.destination_node_id)
            destination = f"node {m.destination_node_id}" + (f" ({device.name})" if device else "")
        names = {f.name: str(f.type) for f in rm.srv.response}
        failure = [n for n, t in (("success", "bool"), ("message", "string")) if names.get(n) == t]
        if m.duty is not None and not failure and names.get("ok") == "bool":  # a duty's srv may say `ok`
            failure = ["ok"]
        rows = [{"ros": link.source or "", "arrow": "→", "uavcan": link.target,
                 "conversion": _conversion(link, True)} for link in rm.request]
        rows += [{"ros": link.target, "arrow": "←", "uavcan": link.source or "",
                  "conversion": _conversion(link, False)} for link in rm.response]
        mappings.append({
            "name": m.name, "service": m.service, "srv": f"{rm.srv.package}/srv/{rm.srv.name}",
            "data_type": rm.data_type, "data_type_id": rm.service_id, "protocol": m.protocol,
            "destination": destination,
            "timeout": f"{m.timeout_s:g} s", "failure": failure, "rows": rows,
            "duty": m.duty, "protocol_label": protocol_of(m.protocol).label,
        })
    return {"services": {"srvs": srvs, "v0": v0, "cyphal": cyphal, "mappings": mappings}
            if srvs or v0 or cyphal or mappings else None}
