"""The spec's bridge side: mappings and their field links, devices with their ports, and layouts."""

from __future__ import annotations

from sam_codegen.frontend.bus import parse_bus
from sam_codegen.frontend.device_params import parse_parameters
from sam_codegen.frontend.element_links import element_link
from sam_codegen.frontend.expr_parser import ExprSyntaxError, parse_expr
from sam_codegen.frontend.reading import Reader, map_items, number, scalar, seq_items, str_list, text_of
from sam_codegen.frontend.routing import node_ids_or_any
from sam_codegen.frontend.traffic import TRAFFIC_KEYS, parse_traffic
from sam_codegen.frontend.yaml_source import YMap, YNode, YScalar
from sam_codegen.model.diagnostics import NOWHERE, Diagnostics, Pos
from sam_codegen.model.expr import ExprSource, PNum, UavcanExpr
from sam_codegen.model.protocols.registry import default_protocol, protocol_names
from sam_codegen.model.protocols.registry import protocol as protocol_of
from sam_codegen.model.spec import (
    DIRECTIONS,
    ROS_TO_UAVCAN,
    UAVCAN_TO_ROS,
    Device,
    FieldLink,
    Layout,
    Mapping,
    Port,
    Scalar,
    V0Port,
)

__all__ = ["parse_device", "parse_layout", "parse_link", "parse_mapping"]


def _expression(node: YNode | None, what: str, diag: Diagnostics) -> ExprSource | None:
    """A mapping expression (model.expr), parsed; a syntax error is reported at its column."""
    if node is None:
        return None
    text = scalar(node, str, what, diag)
    if text is None:
        return None
    assert isinstance(node, YScalar)
    start = node.pos if not node.quoted else Pos(node.pos.file, node.pos.line, node.pos.column + 1)
    try:
        tree = parse_expr(text)
    except ExprSyntaxError as exc:
        diag.error(ExprSource(text, PNum(0, 0), start).at(exc.col), f"{what}: {exc.message}")
        return None
    return ExprSource(text, tree, start)


def _link(ros_path: str, pos: Pos, node: YNode, mapping: str, diag: Diagnostics) -> FieldLink | None:
    what = f"field {ros_path!r} of mapping {mapping!r}"
    if isinstance(node, YScalar):
        path = scalar(node, str, what, diag)
        return FieldLink(ros_path, path, pos=pos) if path is not None else None
    r = Reader(node, what, diag, ("from", "scale", "offset", "table", "value", "limits", "round", "expr", "each",
                                  "fields", "ignore", "uavcan_values", "on_out_of_range"))
    if not r.ok:
        return None
    wrap = _line_wrap(r, what, diag)
    for key in ("each", "value"):
        if wrap and r.node(key) is not None:
            diag.error(r.key_pos("on_out_of_range"), f"on_out_of_range 'wrap' of {what}: wrap applies to an integer "
                       f"field as it is or an `expr`, not to a line with {key!r}",
                       "wrap on the element mapping's own lines" if key == "each" else "no wrap on a constant")
            return None
    if any(r.node(key) is not None for key in ("each", "fields", "ignore", "uavcan_values")):
        return element_link(ros_path, pos, r, mapping, diag, _link)
    if r.node("expr") is not None:
        others = [key for key in ("from", "scale", "offset", "table", "value", "limits", "round")
                  if r.node(key) is not None]
        if others:
            diag.error(pos, f"{what} has 'expr' and " + ", ".join(repr(k) for k in others),
                       "'expr' alone (it says the whole conversion)")
            return None
        expr = _expression(r.node("expr"), f"the expression of {what}", diag)
        return FieldLink(ros_path, pos=pos, expr=expr, wrap=wrap) if expr is not None else None
    uavcan_path = r.get("from", str, None)
    scale = number(r.node("scale"), f"'scale' of {what}", diag)
    offset = number(r.node("offset"), f"'offset' of {what}", diag)
    if scale == 0:
        diag.error(r.key_pos("scale"), f"'scale' of {what} must not be 0 (the reverse conversion divides by it)")
    value = None
    if r.node("value") is not None:
        value = r.get("value", (bool, int, float, str))
        if uavcan_path is not None:
            diag.error(pos, f"{what} has both 'from' and 'value'", "one of them")
    elif uavcan_path is None:
        diag.error(pos, f"{what} needs 'from' (a UAVCAN field) or 'value' (a constant)")
    table_node = r.node("table")
    table: dict[int, int] | None = None
    table_default = None
    if table_node is not None:
        table = {}
        for key, key_pos, value_node in map_items(table_node, f"'table' of {what}", diag):
            if key == "default":  # every UAVCAN value the table does not list
                table_default = scalar(value_node, int, f"table default of {what}", diag)
                continue
            try:
                source = int(key)
            except ValueError:
                diag.error(key_pos, f"table key {key!r} of {what} is not an integer", "an integer or `default`")
                continue
            target = scalar(value_node, int, f"table value of {what}", diag)
            if target is not None:
                table[source] = target
    limits_node = r.node("limits")
    limits = None
    if limits_node is not None:
        values = [number(n, f"'limits' of {what}", diag) for n in seq_items(limits_node, f"'limits' of {what}", diag)]
        if len(values) != 2 or None in values or values[0] >= values[1]:  # type: ignore[operator]
            diag.error(limits_node.pos, f"'limits' of {what} must be [low, high] with low < high")
        else:
            limits = (values[0], values[1])
    return FieldLink(ros_path, uavcan_path, scale, offset, table, table_default, value, limits,  # type: ignore[arg-type]
                     pos, bool(r.get("round", bool, False)), wrap=wrap)


def _line_wrap(r: Reader, what: str, diag: Diagnostics) -> bool:
    """A line's own `on_out_of_range`: only `wrap` (C's modulo 2**bits store), opted into line by line; saturate
    and reject are the whole mapping's."""
    policy = r.get("on_out_of_range", str, None)
    if policy is None:
        return False
    if policy != "wrap":
        diag.error(r.key_pos("on_out_of_range"), f"on_out_of_range {policy!r} of {what}: a line takes only `wrap`",
                   "wrap (modulo 2**bits, as C stores), or saturate / reject for the whole mapping")
        return False
    return True


_MAPPING_KEYS = (
    "direction", "topic", "subject_id", "source_node_ids", "destination_node_id", "frame_id",
    "fields", "ignore", "uavcan_values", "on_out_of_range", "uavcan_exprs", "ros_defaults", *TRAFFIC_KEYS, "pass_nan",
)
# A DroneCAN message is keyed by its data type (no subject id) and broadcast (destinations, not one destination).
_DRONECAN_MAPPING_KEYS = (
    "direction", "topic", "data_type", "select", "source_node_ids", "destination_node_ids", "frame_id",
    "fields", "ignore", "uavcan_values", "on_out_of_range", "uavcan_exprs", "ros_defaults",
    "shares_data_type", *TRAFFIC_KEYS, "pass_nan",
)


def parse_mapping(name: str, pos: Pos, node: YNode, diag: Diagnostics, protocol: str = "cyphal") -> Mapping | None:
    entry = protocol_of(protocol)
    dronecan = entry.v0
    what = f"{entry.mapping_noun} {name!r}"
    r = Reader(node, what, diag, _DRONECAN_MAPPING_KEYS if dronecan else _MAPPING_KEYS)
    if not r.ok:
        return None
    direction = r.get("direction", str)
    if direction not in (None, *DIRECTIONS):
        diag.error(r.node("direction").pos, f"direction {direction!r} of {what} is unknown",  # type: ignore[union-attr]
                   f"{UAVCAN_TO_ROS} or {ROS_TO_UAVCAN}")
        direction = None
    policy = r.get("on_out_of_range", str, "saturate")
    if policy == "wrap":  # never a whole mapping's: it reverses a thruster at 200000 rpm into an int18
        diag.error(r.key_pos("on_out_of_range"), f"on_out_of_range 'wrap' of {what} is per line, not per mapping",
                   "`{from: ..., on_out_of_range: wrap}` or `{expr: ..., on_out_of_range: wrap}` on the lines "
                   "that must wrap; saturate or reject here")
    elif policy not in ("saturate", "reject"):
        diag.error(r.key_pos("on_out_of_range"), f"on_out_of_range {policy!r} of {what} is unknown",
                   "saturate or reject")
    source_node_ids, any_node, any_pos = node_ids_or_any(r, "source_node_ids", what, diag)
    destination_node_id = None if dronecan else r.get("destination_node_id", int, None)
    data_type, select_pos = "", NOWHERE
    destination_node_ids: list[int] = []
    select: dict[str, Scalar] = {}
    if dronecan:
        data_type = r.get("data_type", str) or ""
        destination_node_ids, any_dest, dest_pos = node_ids_or_any(r, "destination_node_ids", what, diag)
        any_node, any_pos = any_node or any_dest, any_pos if any_node else dest_pos
        select_pos = r.key_pos("select")
        for path, _, value_node in map_items(r.node("select"), f"select of {what}", diag):
            value = scalar(value_node, (bool, int), f"select value {path!r} of {what}", diag)
            if value is not None:
                select[path] = value
    fields = r.node("fields")
    auto = isinstance(fields, YScalar) and fields.value == "auto"
    links = []
    if not auto and fields is not None:
        for ros_path, key_pos, link_node in map_items(fields, f"the fields of {what}", diag):
            link = _link(ros_path, key_pos, link_node, name, diag)
            if link is not None:
                links.append(link)
    elif fields is None and r.ok:
        diag.error(pos, f"missing field 'fields' in {what}", "a mapping of ros_field: uavcan_field, or `auto`")
    ignore = [p for p, _ in str_list(r.node("ignore"), f"ignore of {what}", diag)]
    uavcan_values: dict[str, Scalar] = {}
    for path, _, value_node in map_items(r.node("uavcan_values"), f"uavcan_values of {what}", diag):
        value = scalar(value_node, (bool, int, float), f"uavcan value {path!r} of {what}", diag)
        if value is not None:
            uavcan_values[path] = value
    uavcan_exprs: list[UavcanExpr] = []
    for path, key_pos, value_node in map_items(r.node("uavcan_exprs"), f"uavcan_exprs of {what}", diag):
        wrap = False
        if isinstance(value_node, YMap):  # `{expr: "...", on_out_of_range: wrap}`
            er = Reader(value_node, f"UAVCAN field {path!r} in uavcan_exprs of {what}", diag,
                        ("expr", "on_out_of_range"))
            if not er.ok:
                continue
            wrap = _line_wrap(er, f"UAVCAN field {path!r} in uavcan_exprs of {what}", diag)
            expr_node = er.node("expr")
            if expr_node is None:
                diag.error(key_pos, f"missing field 'expr' in UAVCAN field {path!r} in uavcan_exprs of {what}")
                continue
            value_node = expr_node
        expr = _expression(value_node, f"the expression of UAVCAN field {path!r} in uavcan_exprs of {what}", diag)
        if expr is not None:
            uavcan_exprs.append(UavcanExpr(path, expr, key_pos, wrap))
    ros_defaults = [p for p, _ in str_list(r.node("ros_defaults"), f"ros_defaults of {what}", diag)]
    mapping = Mapping(
        name, direction or UAVCAN_TO_ROS, r.get("topic", str) or "", 0 if dronecan else r.get("subject_id", int) or 0,
        source_node_ids, destination_node_id, r.get("frame_id", str, None), links, ignore, uavcan_values, auto,
        policy if policy in ("saturate", "reject") else "saturate", pos, protocol, data_type, destination_node_ids,
        select, select_pos, any_node, any_pos, bool(dronecan and r.get("shares_data_type", bool, False)),
        **vars(parse_traffic(r, what, direction, diag)), uavcan_exprs=uavcan_exprs, ros_defaults=ros_defaults,
        pass_nan=bool(r.get("pass_nan", bool, False)),
        pass_nan_pos=r.key_pos("pass_nan") if r.node("pass_nan") is not None else None,
    )
    if direction == UAVCAN_TO_ROS and r.node("pass_nan") is not None:
        diag.error(r.key_pos("pass_nan"), f"{what} goes UAVCAN->ROS: pass_nan is for commands (ros_to_uavcan); a "
                   "UAVCAN->ROS mapping passes a float NaN on as it is", "no pass_nan here")
    destination = "destination_node_ids" if dronecan else "destination_node_id"
    if direction == UAVCAN_TO_ROS and r.node(destination) is not None:
        diag.error(r.key_pos(destination), f"{what} goes UAVCAN->ROS: it has sources, not a destination",
                   "source_node_ids")
    if direction == ROS_TO_UAVCAN and r.node("source_node_ids") is not None:
        diag.error(r.key_pos("source_node_ids"), f"{what} goes ROS->UAVCAN: it has a destination, not sources",
                   destination)
    if direction == UAVCAN_TO_ROS and not mapping.source_node_ids and not any_node:
        diag.error(pos, f"{what} needs source_node_ids: the node ids whose messages it accepts")
    if direction == ROS_TO_UAVCAN and not dronecan and mapping.destination_node_id is None:
        diag.error(pos, f"{what} needs destination_node_id: the node its commands are meant for")
    if direction == ROS_TO_UAVCAN and dronecan and not mapping.destination_node_ids and not any_node:
        diag.error(pos, f"{what} needs destination_node_ids: the nodes its broadcast commands are meant for")
    return mapping


def _ports(node: YNode | None, what: str, diag: Diagnostics) -> list[Port]:
    ports = []
    for item in seq_items(node, what, diag):
        r = Reader(item, f"a port of {what}", diag, ("subject_id", "type", "rate_hz"))
        subject, type_ = r.get("subject_id", int), r.get("type", str)
        rate = number(r.node("rate_hz"), f"rate_hz of {what}", diag) if r.node("rate_hz") else None
        if r.ok and r.node("rate_hz") is None:
            diag.error(item.pos, f"missing field 'rate_hz' in a port of {what}", "the nominal rate in Hz")
        if rate is not None and rate <= 0:
            diag.error(r.key_pos("rate_hz"), f"rate_hz of {what} must be positive")
        if subject is not None and type_ is not None:
            ports.append(Port(subject, type_, float(rate or 0.0), item.pos))
    return ports


def _v0_ports(node: YNode | None, what: str, diag: Diagnostics) -> list[V0Port]:
    ports = []
    for item in seq_items(node, what, diag):
        r = Reader(item, f"a DroneCAN port of {what}", diag, ("type", "rate_hz"))
        type_ = r.get("type", str)
        rate = number(r.node("rate_hz"), f"rate_hz of {what}", diag) if r.node("rate_hz") else None
        if r.ok and r.node("rate_hz") is None:
            diag.error(item.pos, f"missing field 'rate_hz' in a DroneCAN port of {what}", "the nominal rate in Hz")
        if rate is not None and rate <= 0:
            diag.error(r.key_pos("rate_hz"), f"rate_hz of {what} must be positive")
        if type_ is not None:
            ports.append(V0Port(type_, float(rate or 0.0), item.pos))
    return ports


_DEVICE_KEYS = ("node_id", "description", "protocol", "publishes", "subscribes", "parameters")  # and each protocol's


def parse_device(key: str, pos: Pos, node: YNode, diag: Diagnostics) -> Device:
    """A device: its ports in its `protocol` (cyphal by default), and under the other protocol's name the ports of
    its firmware for that protocol."""
    what = f"device {key!r}"
    known = protocol_names()
    r = Reader(node, what, diag, (*_DEVICE_KEYS, *known))
    node_id = r.get("node_id", int)
    protocol = r.get("protocol", str, default_protocol().name)
    protocol_pos = {protocol: pos}

    def device(ports: dict[str, list[Port]], v0_ports: dict[str, list[V0Port]], protocols: tuple[str, ...]) -> Device:
        return Device(key, node_id if node_id is not None else -1, text_of(r, "description"),
                      ports.get("publishes", []), ports.get("subscribes", []), pos, protocol, protocols,
                      v0_ports.get("publishes", []), v0_ports.get("subscribes", []), protocol_pos,
                      parse_parameters(r.node("parameters"), key, protocols, diag))

    if protocol not in known:
        diag.error(r.key_pos("protocol"), f"protocol {protocol!r} of {what} is unknown", " or ".join(known))
        return device({}, {}, ())  # its ports would be read in the wrong protocol
    sides = [(protocol, r.map)]
    if r.node(protocol) is not None:
        diag.error(r.key_pos(protocol), f"{what} speaks {protocol}: its {protocol} ports are its `publishes` and "
                   "`subscribes`", f"a section for the other protocol ({', '.join(set(known) - {protocol})})")
    for other in known:
        section = r.node(other)
        if other != protocol and section is not None:
            sub = Reader(section, f"the {other} ports of {what}", diag, ("publishes", "subscribes"))
            sides.append((other, sub.map))
            protocol_pos[other] = r.key_pos(other)
    cyphal: dict[str, list[Port]] = {}
    v0: dict[str, list[V0Port]] = {}
    for side, ports in sides:
        for key_ in ("publishes", "subscribes"):
            if not protocol_of(side).v0:
                cyphal[key_] = _ports(ports.entries.get(key_), what, diag)
            else:
                v0[key_] = _v0_ports(ports.entries.get(key_), what, diag)
    return device(cyphal, v0, tuple(side for side, _ in sides))


def parse_layout(key: str, pos: Pos, node: YNode, diag: Diagnostics) -> Layout:
    what = f"layout {key!r}"
    r = Reader(node, what, diag, ("description", "protocol", "devices", "bus"))
    layout_protocol = r.get("protocol", str, None)
    known = protocol_names()
    if layout_protocol is not None and layout_protocol not in known:
        diag.error(r.key_pos("protocol"), f"protocol {layout_protocol!r} of {what} is unknown", " or ".join(known))
        layout_protocol = None
    devices: dict[str, str] = {}
    device_pos: dict[str, Pos] = {}
    for device, key_pos, value in map_items(r.node("devices"), f"the devices of {what}", diag):
        protocol = scalar(value, str, f"the protocol of device {device!r} in {what}", diag)
        if protocol is not None and protocol not in known:
            diag.error(value.pos, f"protocol {protocol!r} of device {device!r} in {what} is unknown",
                       " or ".join(protocol_names()))
        elif protocol is not None:
            devices[device] = protocol
            device_pos[device] = key_pos
    return Layout(key, text_of(r, "description"), layout_protocol, devices, device_pos, pos,
                  parse_bus(r.node("bus"), f"the bus of {what}", diag))


# A service mapping's request and response lines are a mapping's lines (frontend.services reads them with this).
parse_link = _link
