"""The bridge's service mappings as data: ``python/<vehicle>_bridge/services.py`` (standard library only), for a
spec with `bridge.service_mappings`. The runtime (sam_runtime.bridge.backends.dronecan_services and
cyphal_services, by each mapping's `protocol`) converts a ROS
request into the UAVCAN request and the UAVCAN response back with these links, each field by one rule: numbers
scaled (target = (source - offset) / scale to UAVCAN, source * scale + offset back), rounded half to even into an
integer and saturated to the target's range; bools as bools; a string as the bytes of a uint8 array, cut at its
capacity.

Invariant: the module is emitted only when there are service mappings, so the other specs' output is unchanged.
"""

from __future__ import annotations

import math
from pathlib import Path

from sam_codegen.render.filters import py_number, py_str
from sam_codegen.render.templating import render
from sam_codegen.validate.resolve import Resolved
from sam_codegen.validate.services import ServiceLink

__all__ = ["emit"]

_F32_MAX = 3.4028234663852886e38


def _link(link: ServiceLink) -> str:
    def num(value: float | None) -> str:
        if value is None:
            return "None"
        named = {_F32_MAX: "_F32_MAX", -_F32_MAX: "-_F32_MAX", math.inf: "_INF", -math.inf: "-_INF"}
        return named.get(float(value), py_number(float(value)))  # (short lines)

    value = "None" if link.value is None else repr(link.value)
    return (f"ServiceLinkInfo({py_str(link.target)}, {py_str(link.source) if link.source else 'None'}, "
            f"{py_str(link.kind)}, {value}, {num(link.scale)}, {num(link.offset)}, {num(link.lo)}, {num(link.hi)})")


def emit(resolved: Resolved) -> dict[str, str]:
    if not resolved.service_mappings:
        return {}
    spec = resolved.spec
    package = f"{spec.vehicle}_bridge"
    by_id = spec.devices_by_node_id()
    mappings = []
    for rm in resolved.service_mappings:
        m, srv = rm.mapping, rm.srv
        response_names = {f.name: f for f in srv.response}
        # The fields that tell the caller of a failure (timeout, link down): a bool `success` set False and a
        # string `message` with the reason, when the srv has them (std_srvs' convention).
        success = response_names.get("success")
        if m.duty is not None and success is None:  # a duty's srv may say `ok` (SMARC's UavcanRestartNode)
            success = response_names.get("ok")
        message = response_names.get("message")
        mappings.append({
            "name": py_str(m.name), "service": py_str(m.service), "ros_module": py_str(f"{srv.package}.srv"),
            "ros_class": py_str(srv.name), "ros_type": py_str(f"{srv.package}/srv/{srv.name}"),
            "data_type": py_str(rm.data_type), "data_type_id": rm.service_id,
            "signature": f"0x{rm.struct.signature:016X}" if rm.struct is not None else "0",
            "protocol": py_str(m.protocol), "duty": py_str(m.duty) if m.duty is not None else "None",
            "destination_node_id": m.destination_node_id,
            "device": py_str(by_id[m.destination_node_id].name if m.destination_field is None else ""),
            "destination_field": py_str(m.destination_field) if m.destination_field is not None else "None",
            "timeout_s": py_number(m.timeout_s),
            "request": [_link(link) for link in rm.request], "response": [_link(link) for link in rm.response],
            "success_field": py_str(success.name) if success is not None and str(success.type) == "bool" else "None",
            "message_field": py_str(message.name) if message is not None and str(message.type) == "string"
            else "None",
        })
    return {f"python/{package}/services.py": render("python/services.py.j2", spec_name=Path(spec.file).name,
                                                    mappings=mappings)}
