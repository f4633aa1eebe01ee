"""The spec's service mappings (`bridge.service_mappings`): a ROS service the bridge serves by a UAVCAN request to
one device, its request and response fields linked with a mapping's `ros_field: uavcan_field` lines.

Structure only (keys, value kinds, a positive timeout); what the names refer to is checked in validate.services.
"""

from __future__ import annotations

from sam_codegen.frontend.bridge import parse_link
from sam_codegen.frontend.reading import Reader, map_items, number, scalar, str_list
from sam_codegen.frontend.yaml_source import YNode
from sam_codegen.model.diagnostics import Diagnostics, Pos
from sam_codegen.model.protocols.registry import protocol_names
from sam_codegen.model.spec import FieldLink, Scalar, ServiceMapping

__all__ = ["DEFAULT_TIMEOUT_S", "parse_service_mapping"]

DEFAULT_TIMEOUT_S = 1.0  # dronecan's own default request timeout
_KEYS = ("service", "type", "data_type", "protocol", "destination_node_id", "timeout", "request", "response",
         "uavcan_values", "service_id", "response_defaults")


def parse_service_mapping(name: str, pos: Pos, node: YNode, diag: Diagnostics) -> ServiceMapping | None:
    what = f"service mapping {name!r}"
    r = Reader(node, what, diag, _KEYS)
    if not r.ok:
        return None
    protocol = r.get("protocol", str, "dronecan")
    if protocol not in protocol_names():
        diag.error(r.key_pos("protocol"), f"protocol {protocol!r} of {what} is unknown", " or ".join(protocol_names()))
    service_id = r.get("service_id", int, None)
    timeout = DEFAULT_TIMEOUT_S
    if r.node("timeout") is not None:
        value = number(r.node("timeout"), f"'timeout' of {what}", diag)
        if value is not None and not 0 < value <= 60:
            diag.error(r.key_pos("timeout"), f"'timeout' of {what} is {value} s", "0 < timeout <= 60 (seconds)")
        elif value is not None:
            timeout = float(value)
    links: dict[str, list[FieldLink]] = {"request": [], "response": []}
    for part in ("request", "response"):
        for ros_path, key_pos, link_node in map_items(r.node(part), f"the {part} fields of {what}", diag):
            link = parse_link(ros_path, key_pos, link_node, name, diag)
            if link is not None:
                links[part].append(link)
    uavcan_values: dict[str, Scalar] = {}
    for path, _, value_node in map_items(r.node("uavcan_values"), f"uavcan_values of {what}", diag):
        value = scalar(value_node, (bool, int, float), f"uavcan value {path!r} of {what}", diag)
        if value is not None:
            uavcan_values[path] = value
    service, type_, data_type = r.get("service", str), r.get("type", str), r.get("data_type", str)
    # a node id, or the ROS request field that gives it at each call
    destination = r.get("destination_node_id", (int, str))
    if service is None or type_ is None or data_type is None or destination is None:
        return None
    field = destination if isinstance(destination, str) else None
    return ServiceMapping(name, service, type_.replace("/srv/", "/"), data_type,
                          0 if field is not None else int(destination), timeout, links["request"], links["response"],
                          uavcan_values, protocol, pos, field, service_id,
                          response_defaults=tuple(p for p, _ in str_list(r.node("response_defaults"),
                                                                         f"response_defaults of {what}", diag)))
