"""YAML spec -> model: structure, field names and value types. Cross-references are checked in validate."""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar

from .diagnostics import Diagnostics, Pos, SpecError
from .model import (
    DURABILITIES,
    PROTOCOLS,
    QOS_PROFILES,
    RELIABILITIES,
    Bridge,
    Constant,
    Device,
    DsdlStruct,
    Field,
    FieldLink,
    Frame,
    Layout,
    Mapping,
    Node,
    NodeParameter,
    NodeTopic,
    NodeTransform,
    Parameter,
    ParameterRule,
    Port,
    Qos,
    RosMessage,
    RosPackageInfo,
    Scalar,
    Spec,
    Topic,
    Transform,
    V0Port,
    V0Struct,
)
from .typesys import DsdlType, parse_dsdl_type, parse_ros_type, parse_v0_type
from .yaml_source import YMap, YNode, YScalar, YSeq, load_yaml

T = TypeVar("T")
_MISSING = object()


def _kind(node: YNode) -> str:
    if isinstance(node, YMap):
        return "a mapping"
    if isinstance(node, YSeq):
        return "a list"
    value = node.value
    return "null" if value is None else f"{type(value).__name__} {value!r}"


class _Reader:
    """Typed access to a YAML mapping that records what is wrong instead of raising."""

    def __init__(self, node: YNode, what: str, diag: Diagnostics, allowed: tuple[str, ...]) -> None:
        self.diag = diag
        self.what = what
        self.ok = isinstance(node, YMap)
        self.map = node if isinstance(node, YMap) else YMap(node.pos)
        self.pos = node.pos
        if not self.ok:
            diag.error(node.pos, f"{what} must be a mapping, found {_kind(node)}", "a mapping")
            return
        _report_duplicates(self.map, what, diag)
        for key, key_pos in self.map.key_pos.items():
            if key not in allowed:
                diag.error(key_pos, f"unknown field {key!r} in {what}", "one of " + ", ".join(allowed))

    def node(self, key: str) -> YNode | None:
        return self.map.entries.get(key)

    def key_pos(self, key: str) -> Pos:
        return self.map.key_pos.get(key, self.pos)

    def get(self, key: str, kind: type | tuple[type, ...], default: Any = _MISSING) -> Any:
        node = self.map.entries.get(key)
        if node is None:
            if default is _MISSING:
                if self.ok:
                    self.diag.error(self.pos, f"missing field {key!r} in {self.what}")
                return None
            return default
        return scalar(node, kind, f"{key!r} of {self.what}", self.diag)


def scalar(node: YNode, kind: type | tuple[type, ...], what: str, diag: Diagnostics) -> Any:
    kinds = kind if isinstance(kind, tuple) else (kind,)
    if isinstance(node, YScalar) and isinstance(node.value, kinds):
        # bool is an int in Python; a spec's `true` is never a number.
        if isinstance(node.value, bool) and bool not in kinds:
            pass
        else:
            return node.value
    names = " or ".join("number" if k is float else k.__name__ for k in kinds)
    diag.error(node.pos, f"{what} must be {names}, found {_kind(node)}", names)
    return None


def _report_duplicates(node: YMap, what: str, diag: Diagnostics) -> None:
    for key, pos, _ in node.duplicates:
        diag.error(pos, f"duplicate key {key!r} in {what} (first at line {node.key_pos[key].line})", "unique keys")


def _items(
    node: YNode | None, what: str, diag: Diagnostics, duplicates: bool = True
) -> list[tuple[str, Pos, YNode]]:
    if node is None:
        return []
    if not isinstance(node, YMap):
        diag.error(node.pos, f"{what} must be a mapping, found {_kind(node)}", "a mapping")
        return []
    if duplicates:
        _report_duplicates(node, what, diag)
    return [(k, node.key_pos[k], v) for k, v in node.entries.items()]


def _list(node: YNode | None, what: str, diag: Diagnostics) -> list[YNode]:
    if node is None:
        return []
    if not isinstance(node, YSeq):
        diag.error(node.pos, f"{what} must be a list, found {_kind(node)}", "a list")
        return []
    return node.items


def _str_list(node: YNode | None, what: str, diag: Diagnostics) -> list[tuple[str, Pos]]:
    result = []
    for item in _list(node, what, diag):
        value = scalar(item, str, f"an entry of {what}", diag)
        if value is not None:
            result.append((value, item.pos))
    return result


def _text(reader: _Reader, key: str) -> str:
    value = reader.get(key, str, "")
    return value if isinstance(value, str) else ""


def _parse_type(text: str | None, pos: Pos, parse: Callable[[str], T], diag: Diagnostics) -> T | None:
    if text is None:
        return None
    try:
        return parse(text)
    except ValueError as exc:
        diag.error(pos, str(exc))
        return None


_FIELD_KEYS = ("name", "type", "comment", "default")
_CONST_KEYS = ("name", "type", "value", "comment")


def _fields(node: YNode | None, what: str, parse: Callable[[str], Any], diag: Diagnostics) -> list[Field]:
    """The fields of a message or DSDL type; DSDL void padding comes as a Field without a name."""
    result = []
    for item in _list(node, f"the fields of {what}", diag):
        r = _Reader(item, f"a field of {what}", diag, _FIELD_KEYS)
        type_text = r.get("type", str)
        type_ = _parse_type(type_text, r.key_pos("type"), parse, diag)
        if type_ is None and parse in (parse_dsdl_type, parse_v0_type) and str(type_text).strip().startswith("void"):
            continue  # padding with a bad type (reported): it has no name to miss
        if isinstance(type_, DsdlType) and type_.kind == "void":
            # DSDL padding has no name (`void3`); it is kept for the layout and mapped by no one.
            if r.node("name") is not None:
                diag.error(r.key_pos("name"), f"void padding in {what} has no name in DSDL",
                           f"{{type: {type_}}} without a name")
            if r.node("default") is not None:
                diag.error(r.key_pos("default"), f"void padding in {what} has no value")
            result.append(Field("", type_, _text(r, "comment"), item.pos))
            continue
        name = r.get("name", str)
        default = r.get("default", (bool, int, float, str), None)
        if name is not None and type_ is not None:
            result.append(Field(name, type_, _text(r, "comment"), item.pos, default))
    return result


def _constants(node: YNode | None, what: str, parse: Callable[[str], Any], diag: Diagnostics) -> list[Constant]:
    result = []
    for item in _list(node, f"the constants of {what}", diag):
        r = _Reader(item, f"a constant of {what}", diag, _CONST_KEYS)
        name, type_text = r.get("name", str), r.get("type", str)
        value = r.get("value", (bool, int, float, str))
        type_ = _parse_type(type_text, r.key_pos("type"), parse, diag)
        if name is not None and type_ is not None and value is not None:
            result.append(Constant(name, type_, value, _text(r, "comment"), item.pos))
    return result


def _ros_message(key: str, pos: Pos, node: YNode, package: str, external: bool, diag: Diagnostics) -> RosMessage:
    what = f"message {key!r}"
    r = _Reader(node, what, diag, ("description", "fields", "constants", "derive_from"))
    pkg, _, name = key.rpartition("/")
    pkg = pkg.replace("/msg", "") or package

    def parse(text: str) -> Any:
        return parse_ros_type(text, pkg)

    derive = r.get("derive_from", str, None)
    if derive is not None and r.node("fields") is not None:
        diag.error(r.key_pos("fields"), f"{what} is derived from {derive}: it cannot also list fields")
    fields = _fields(r.node("fields"), what, parse, diag)
    if derive is None and not fields and r.ok and not external:
        diag.error(pos, f"{what} has no fields", "a `fields` list or `derive_from`")
    return RosMessage(
        pkg, name, fields, _constants(r.node("constants"), what, parse, diag),
        _text(r, "description"), derive, external, pos,
    )


def _dsdl_struct(key: str, pos: Pos, node: YNode, diag: Diagnostics) -> DsdlStruct:
    what = f"DSDL type {key!r}"
    r = _Reader(node, what, diag, ("description", "fields", "constants", "sealed", "extent"))
    sealed = r.get("sealed", bool, False)
    extent = r.get("extent", int, None)
    if r.ok and not sealed and extent is None:
        diag.error(pos, f"{what} needs `sealed: true` or `extent: <bytes>`", "sealed or extent (DSDL requires one)")
    if sealed and extent is not None:
        diag.error(r.key_pos("extent"), f"{what} cannot be both sealed and have an extent")
    layout = _fields(r.node("fields"), what, parse_dsdl_type, diag)
    fields = [f for f in layout if f.name]
    return DsdlStruct(
        key, fields, _constants(r.node("constants"), what, parse_dsdl_type, diag),
        _text(r, "description"), bool(sealed), extent, pos=pos, layout=layout if len(fields) < len(layout) else [],
    )


def _number(node: YNode | None, what: str, diag: Diagnostics) -> float | None:
    if node is None:
        return None
    value = scalar(node, (int, float), what, diag)
    if value is not None and not math.isfinite(value):
        diag.error(node.pos, f"{what} must be finite")
        return None
    return value


def _link(ros_path: str, pos: Pos, node: YNode, mapping: str, diag: Diagnostics) -> FieldLink | None:
    what = f"field {ros_path!r} of mapping {mapping!r}"
    if isinstance(node, YScalar):
        path = scalar(node, str, what, diag)
        return FieldLink(ros_path, path, pos=pos) if path is not None else None
    r = _Reader(node, what, diag, ("from", "scale", "offset", "table", "value", "limits", "round"))
    if not r.ok:
        return None
    link = FieldLink(ros_path, r.get("from", str, None), pos=pos, round=bool(r.get("round", bool, False)))
    link.scale = _number(r.node("scale"), f"'scale' of {what}", diag)
    link.offset = _number(r.node("offset"), f"'offset' of {what}", diag)
    if link.scale == 0:
        diag.error(r.key_pos("scale"), f"'scale' of {what} must not be 0 (the reverse conversion divides by it)")
    if r.node("value") is not None:
        link.value = r.get("value", (bool, int, float, str))
        if link.uavcan_path is not None:
            diag.error(pos, f"{what} has both 'from' and 'value'", "one of them")
    elif link.uavcan_path is None:
        diag.error(pos, f"{what} needs 'from' (a UAVCAN field) or 'value' (a constant)")
    table_node = r.node("table")
    if table_node is not None:
        table: dict[int, int] = {}
        for key, key_pos, value_node in _items(table_node, f"'table' of {what}", diag):
            if key == "default":  # every UAVCAN value the table does not list
                link.table_default = scalar(value_node, int, f"table default of {what}", diag)
                continue
            try:
                source = int(key)
            except ValueError:
                diag.error(key_pos, f"table key {key!r} of {what} is not an integer", "an integer or `default`")
                continue
            target = scalar(value_node, int, f"table value of {what}", diag)
            if target is not None:
                table[source] = target
        link.table = table
    limits_node = r.node("limits")
    if limits_node is not None:
        values = [_number(n, f"'limits' of {what}", diag) for n in _list(limits_node, f"'limits' of {what}", diag)]
        if len(values) != 2 or None in values or values[0] >= values[1]:  # type: ignore[operator]
            diag.error(limits_node.pos, f"'limits' of {what} must be [low, high] with low < high")
        else:
            link.limits = (values[0], values[1])  # type: ignore[assignment]
    return link


_MAPPING_KEYS = (
    "direction", "topic", "subject_id", "source_node_ids", "destination_node_id", "frame_id",
    "fields", "ignore", "uavcan_values", "on_out_of_range",
)
# A DroneCAN message is keyed by its data type (no subject id) and broadcast (destinations, not one destination).
_DRONECAN_MAPPING_KEYS = (
    "direction", "topic", "data_type", "select", "source_node_ids", "destination_node_ids", "frame_id",
    "fields", "ignore", "uavcan_values", "on_out_of_range",
)


def _mapping(name: str, pos: Pos, node: YNode, diag: Diagnostics, protocol: str = "cyphal") -> Mapping | None:
    dronecan = protocol == "dronecan"
    what = f"DroneCAN mapping {name!r}" if dronecan else f"mapping {name!r}"
    r = _Reader(node, what, diag, _DRONECAN_MAPPING_KEYS if dronecan else _MAPPING_KEYS)
    if not r.ok:
        return None
    direction = r.get("direction", str)
    if direction not in (None, "uavcan_to_ros", "ros_to_uavcan"):
        diag.error(r.node("direction").pos, f"direction {direction!r} of {what} is unknown",  # type: ignore[union-attr]
                   "uavcan_to_ros or ros_to_uavcan")
        direction = None
    policy = r.get("on_out_of_range", str, "saturate")
    if policy not in ("saturate", "reject"):
        diag.error(r.key_pos("on_out_of_range"), f"on_out_of_range {policy!r} of {what} is unknown",
                   "saturate or reject")
    mapping = Mapping(
        name, direction or "uavcan_to_ros", r.get("topic", str) or "",
        0 if dronecan else r.get("subject_id", int) or 0,
        _int_list(r.node("source_node_ids"), "source_node_ids", what, diag),
        None if dronecan else r.get("destination_node_id", int, None), r.get("frame_id", str, None),
        on_out_of_range=policy if policy in ("saturate", "reject") else "saturate", pos=pos, protocol=protocol,
    )
    if dronecan:
        mapping.data_type = r.get("data_type", str) or ""
        mapping.destination_node_ids = _int_list(r.node("destination_node_ids"), "destination_node_ids", what, diag)
        mapping.select_pos = r.key_pos("select")
        for path, _, value_node in _items(r.node("select"), f"select of {what}", diag):
            value = scalar(value_node, (bool, int), f"select value {path!r} of {what}", diag)
            if value is not None:
                mapping.select[path] = value
    fields = r.node("fields")
    if isinstance(fields, YScalar) and fields.value == "auto":
        mapping.auto = True
    elif fields is not None:
        for ros_path, key_pos, link_node in _items(fields, f"the fields of {what}", diag):
            link = _link(ros_path, key_pos, link_node, name, diag)
            if link is not None:
                mapping.links.append(link)
    elif r.ok:
        diag.error(pos, f"missing field 'fields' in {what}", "a mapping of ros_field: uavcan_field, or `auto`")
    mapping.ignore = [p for p, _ in _str_list(r.node("ignore"), f"ignore of {what}", diag)]
    for path, _, value_node in _items(r.node("uavcan_values"), f"uavcan_values of {what}", diag):
        value = scalar(value_node, (bool, int, float), f"uavcan value {path!r} of {what}", diag)
        if value is not None:
            mapping.uavcan_values[path] = value
    destination = "destination_node_ids" if dronecan else "destination_node_id"
    if direction == "uavcan_to_ros" and r.node(destination) is not None:
        diag.error(r.key_pos(destination), f"{what} goes UAVCAN->ROS: it has sources, not a destination",
                   "source_node_ids")
    if direction == "ros_to_uavcan" and r.node("source_node_ids") is not None:
        diag.error(r.key_pos("source_node_ids"), f"{what} goes ROS->UAVCAN: it has a destination, not sources",
                   destination)
    if direction == "uavcan_to_ros" and not mapping.source_node_ids:
        diag.error(pos, f"{what} needs source_node_ids: the node ids whose messages it accepts")
    if direction == "ros_to_uavcan" and not dronecan and mapping.destination_node_id is None:
        diag.error(pos, f"{what} needs destination_node_id: the node its commands are meant for")
    if direction == "ros_to_uavcan" and dronecan and not mapping.destination_node_ids:
        diag.error(pos, f"{what} needs destination_node_ids: the nodes its broadcast commands are meant for")
    return mapping


def _int_list(node: YNode | None, key: str, what: str, diag: Diagnostics) -> list[int]:
    items = (scalar(i, int, f"an entry of {key} of {what}", diag) for i in _list(node, f"{key} of {what}", diag))
    return [n for n in items if n is not None]


def _ports(node: YNode | None, what: str, diag: Diagnostics) -> list[Port]:
    ports = []
    for item in _list(node, what, diag):
        r = _Reader(item, f"a port of {what}", diag, ("subject_id", "type", "rate_hz"))
        subject, type_ = r.get("subject_id", int), r.get("type", str)
        rate = _number(r.node("rate_hz"), f"rate_hz of {what}", diag) if r.node("rate_hz") else None
        if r.ok and r.node("rate_hz") is None:
            diag.error(item.pos, f"missing field 'rate_hz' in a port of {what}", "the nominal rate in Hz")
        if rate is not None and rate <= 0:
            diag.error(r.key_pos("rate_hz"), f"rate_hz of {what} must be positive")
        if subject is not None and type_ is not None:
            ports.append(Port(subject, type_, float(rate or 0.0), item.pos))
    return ports


def _v0_ports(node: YNode | None, what: str, diag: Diagnostics) -> list[V0Port]:
    ports = []
    for item in _list(node, what, diag):
        r = _Reader(item, f"a DroneCAN port of {what}", diag, ("type", "rate_hz"))
        type_ = r.get("type", str)
        rate = _number(r.node("rate_hz"), f"rate_hz of {what}", diag) if r.node("rate_hz") else None
        if r.ok and r.node("rate_hz") is None:
            diag.error(item.pos, f"missing field 'rate_hz' in a DroneCAN port of {what}", "the nominal rate in Hz")
        if rate is not None and rate <= 0:
            diag.error(r.key_pos("rate_hz"), f"rate_hz of {what} must be positive")
        if type_ is not None:
            ports.append(V0Port(type_, float(rate or 0.0), item.pos))
    return ports


_DEVICE_KEYS = ("node_id", "description", "protocol", "publishes", "subscribes", *PROTOCOLS)


def _device(key: str, pos: Pos, node: YNode, diag: Diagnostics) -> Device:
    """A device: its ports in its `protocol` (cyphal by default), and under the other protocol's name the ports of
    its firmware for that protocol."""
    what = f"device {key!r}"
    r = _Reader(node, what, diag, _DEVICE_KEYS)
    node_id = r.get("node_id", int)
    protocol = r.get("protocol", str, "cyphal")
    device = Device(key, node_id if node_id is not None else -1, _text(r, "description"), pos=pos,
                    protocol=protocol, protocol_pos={protocol: pos}, protocols=())
    if protocol not in PROTOCOLS:
        diag.error(r.key_pos("protocol"), f"protocol {protocol!r} of {what} is unknown", " or ".join(PROTOCOLS))
        return device  # its ports would be read in the wrong protocol
    sides = [(protocol, r.map)]
    if r.node(protocol) is not None:
        diag.error(r.key_pos(protocol), f"{what} speaks {protocol}: its {protocol} ports are its `publishes` and "
                   "`subscribes`", f"a section for the other protocol ({', '.join(set(PROTOCOLS) - {protocol})})")
    for other in PROTOCOLS:
        section = r.node(other)
        if other != protocol and section is not None:
            sub = _Reader(section, f"the {other} ports of {what}", diag, ("publishes", "subscribes"))
            sides.append((other, sub.map))
            device.protocol_pos[other] = r.key_pos(other)
    for side, ports in sides:
        if side == "cyphal":
            device.publishes = _ports(ports.entries.get("publishes"), what, diag)
            device.subscribes = _ports(ports.entries.get("subscribes"), what, diag)
        else:
            device.dronecan_publishes = _v0_ports(ports.entries.get("publishes"), what, diag)
            device.dronecan_subscribes = _v0_ports(ports.entries.get("subscribes"), what, diag)
    device.protocols = tuple(side for side, _ in sides)
    return device


def _dronecan_type(key: str, pos: Pos, node: YNode, diag: Diagnostics) -> V0Struct:
    what = f"DroneCAN type {key!r}"
    r = _Reader(node, what, diag, ("id", "description", "fields", "constants"))
    layout = _fields(r.node("fields"), what, parse_v0_type, diag)
    fields = [f for f in layout if f.name]
    return V0Struct(
        key, fields, _constants(r.node("constants"), what, parse_v0_type, diag), _text(r, "description"),
        pos=pos, layout=layout if len(fields) < len(layout) else [], data_type_id=r.get("id", int, None),
    )


def _layout(key: str, pos: Pos, node: YNode, diag: Diagnostics) -> Layout:
    what = f"layout {key!r}"
    r = _Reader(node, what, diag, ("description", "protocol", "devices"))
    layout = Layout(key, _text(r, "description"), r.get("protocol", str, None), pos=pos)
    if layout.protocol is not None and layout.protocol not in PROTOCOLS:
        diag.error(r.key_pos("protocol"), f"protocol {layout.protocol!r} of {what} is unknown", " or ".join(PROTOCOLS))
        layout.protocol = None
    for device, device_pos, value in _items(r.node("devices"), f"the devices of {what}", diag):
        protocol = scalar(value, str, f"the protocol of device {device!r} in {what}", diag)
        if protocol is not None and protocol not in PROTOCOLS:
            diag.error(value.pos, f"protocol {protocol!r} of device {device!r} in {what} is unknown",
                       " or ".join(PROTOCOLS))
        elif protocol is not None:
            layout.devices[device] = protocol
            layout.device_pos[device] = device_pos
    return layout


_TOP_KEYS = (
    "spec_version", "vehicle", "ros", "cyphal", "external_messages", "messages", "dsdl_types", "dronecan_types",
    "frames", "transforms", "topics", "parameters", "parameter_rules", "devices", "layouts", "bridge", "nodes",
)


def parse_spec(root: YNode, file: str) -> Spec:
    """Build the model from a YAML tree; raises SpecError with every structural problem found."""
    diag = Diagnostics()
    top = _Reader(root, "the spec", diag, _TOP_KEYS)
    if not top.ok:
        diag.check()
    version = top.get("spec_version", int)
    if version is not None and version != 1:
        diag.error(top.key_pos("spec_version"), f"spec_version {version} is not supported", "1")
    vehicle = _Reader(top.node("vehicle") or YMap(top.pos), "vehicle", diag, ("name", "description"))
    ros = _Reader(top.node("ros") or YMap(top.pos), "ros", diag,
                  ("package", "version", "description", "maintainer", "maintainer_email", "license"))
    cyphal = _Reader(top.node("cyphal") or YMap(top.pos), "cyphal", diag, ("root_namespace",))
    package = ros.get("package", str) or ""
    spec = Spec(
        file, vehicle.get("name", str) or "", _text(vehicle, "description"),
        RosPackageInfo(package, ros.get("version", str, "0.1.0"), _text(ros, "description"),
                       ros.get("maintainer", str, "maintainer"),
                       ros.get("maintainer_email", str, "maintainer@example.org"), ros.get("license", str, "MIT")),
        cyphal.get("root_namespace", str) or "",
    )
    for key, pos, node in _items(top.node("external_messages"), "external_messages", diag):
        if "/" not in key:
            diag.error(pos, f"external message {key!r} needs its package", "pkg/Name")
            continue
        message = _ros_message(key, pos, node, package, True, diag)
        spec.external_messages[message.full_name] = message
    for key, pos, node in _items(top.node("messages"), "messages", diag):
        if "/" in key:
            diag.error(pos, f"message {key!r} is declared in package {package}: give its bare name", "Name")
            continue
        message = _ros_message(key, pos, node, package, False, diag)
        spec.messages[message.full_name] = message
    for key, pos, node in _items(top.node("dsdl_types"), "dsdl_types", diag):
        spec.dsdl_types[key] = _dsdl_struct(key, pos, node, diag)
    for key, pos, node in _items(top.node("frames"), "frames", diag):
        spec.frames[key] = _frame(key, pos, node, diag)
    for item in _list(top.node("transforms"), "transforms", diag):
        r = _Reader(item, "a transform", diag, ("parent", "child", "publisher", "description"))
        parent, child, publisher = r.get("parent", str), r.get("child", str), r.get("publisher", str)
        if parent and child and publisher:
            spec.transforms.append(Transform(parent, child, publisher, _text(r, "description"), item.pos))
    topics = top.node("topics")
    if isinstance(topics, YMap):
        for key, pos, again in topics.duplicates:
            first = topics.entries[key]
            types = [n.entries["type"].value for n in (first, again)
                     if isinstance(n, YMap) and isinstance(n.entries.get("type"), YScalar)]
            diag.error(pos, f"topic {key!r} is declared twice (first at line {topics.key_pos[key].line}"
                       + (f", types {' and '.join(map(str, types))}" if types else "")
                       + "): two types on one topic", "one type per topic; give the second its own topic")
    for key, pos, node in _items(topics, "topics", diag, duplicates=False):
        r = _Reader(node, f"topic {key!r}", diag, ("type", "description", "section", "qos"))
        type_ = r.get("type", str)
        qos_node = r.node("qos")
        qos = parse_qos(qos_node, f"the QoS of topic {key!r}", diag) if qos_node is not None else None
        if type_ is not None:
            spec.topics[key] = Topic(key, type_.replace("/msg/", "/"), _text(r, "description"),
                                     str(r.get("section", (str, float, int), "")), pos, qos,
                                     qos_node.pos if qos_node is not None else pos)
    for key, pos, node in _items(top.node("parameters"), "parameters", diag):
        _parameter(spec, key, pos, node, diag)
    for item in _list(top.node("parameter_rules"), "parameter_rules", diag):
        r = _Reader(item, "a parameter rule", diag, ("left", "op", "right", "description"))
        left, op, right = r.get("left", str), r.get("op", str), r.get("right", str)
        if op is not None and op not in ("<", "<=", ">", ">="):
            diag.error(r.key_pos("op"), f"parameter rule operator {op!r} is unknown", "<, <=, > or >=")
        elif left and op and right:
            spec.parameter_rules.append(ParameterRule(left, op, right, _text(r, "description"), item.pos))
    for key, pos, node in _items(top.node("dronecan_types"), "dronecan_types", diag):
        spec.dronecan_types[key] = _dronecan_type(key, pos, node, diag)
    for key, pos, node in _items(top.node("devices"), "devices", diag):
        spec.devices[key] = _device(key, pos, node, diag)
    for key, pos, node in _items(top.node("layouts"), "layouts", diag):
        spec.layouts[key] = _layout(key, pos, node, diag)
    bridge_node = top.node("bridge")
    if bridge_node is not None:
        r = _Reader(bridge_node, "bridge", diag, ("name", "node_id", "mappings", "dronecan_mappings"))
        bridge = Bridge(r.get("name", str) or "bridge", r.get("node_id", int) or 0, pos=bridge_node.pos)
        for key, pos, node in _items(r.node("mappings"), "bridge mappings", diag):
            mapping = _mapping(key, pos, node, diag)
            if mapping is not None:
                bridge.mappings.append(mapping)
        for key, pos, node in _items(r.node("dronecan_mappings"), "bridge dronecan_mappings", diag):
            mapping = _mapping(key, pos, node, diag, "dronecan")
            if mapping is not None:
                bridge.dronecan_mappings.append(mapping)
        spec.bridge = bridge
    for key, pos, node in _items(top.node("nodes"), "nodes", diag):
        _node(spec, key, pos, node, diag)
    diag.check()
    return spec


def _parameter(spec: Spec, key: str, pos: Pos, node: YNode, diag: Diagnostics) -> None:
    what = f"parameter {key!r}"
    r = _Reader(node, what, diag, ("type", "unit", "default", "min", "max", "description", "section"))
    type_ = r.get("type", str)
    kinds: dict[str, tuple[type, ...]] = {
        "double": (int, float), "integer": (int,), "bool": (bool,), "string": (str,),
    }
    if type_ is not None and type_ not in kinds:
        diag.error(r.key_pos("type"), f"type {type_!r} of {what} is unknown", "double, integer, bool or string")
        return
    if type_ is None:
        return
    default: Scalar | None = r.get("default", kinds[type_])
    minimum = _number(r.node("min"), f"min of {what}", diag)
    maximum = _number(r.node("max"), f"max of {what}", diag)
    if (minimum is not None or maximum is not None) and type_ not in ("double", "integer"):
        diag.error(pos, f"{what} of type {type_} cannot have a range")
    if minimum is not None and maximum is not None and minimum > maximum:
        diag.error(r.key_pos("min"), f"{what}: min {minimum} is above max {maximum}")
    if isinstance(default, (int, float)) and not isinstance(default, bool):
        if (minimum is not None and default < minimum) or (maximum is not None and default > maximum):
            diag.error(r.key_pos("default"), f"default {default} of {what} is outside its range",
                       f"a value in [{minimum}, {maximum}]")
    if default is not None:
        spec.parameters[key] = Parameter(
            key, type_, float(default) if type_ == "double" else default, r.get("unit", str, ""),
            minimum, maximum, _text(r, "description"), str(r.get("section", (str, int, float), "")), pos,
        )


_QOS_KEYS = ("reliability", "durability", "depth")
QOS_DEPTH_MAX = 10000  # a deeper keep-last history is a mistake rather than a need (and costs memory per endpoint)


def parse_qos(node: YNode, what: str, diag: Diagnostics) -> Qos | None:
    """`qos:` as a profile name (sensor_data, reliable, latched, tf) or a {reliability, durability, depth} mapping."""
    if isinstance(node, YScalar) and isinstance(node.value, str):
        profile = QOS_PROFILES.get(node.value)
        if profile is None:
            diag.error(node.pos, f"unknown QoS profile {node.value!r} in {what}",
                       "one of " + ", ".join(QOS_PROFILES) + ", or a mapping {reliability, durability, depth}")
        return profile
    if not isinstance(node, YMap):
        diag.error(node.pos, f"{what} must be a profile name or a mapping, found {_kind(node)}",
                   "one of " + ", ".join(QOS_PROFILES) + ", or a mapping {reliability, durability, depth}")
        return None
    r = _Reader(node, what, diag, _QOS_KEYS)
    reliability, durability, depth = r.get("reliability", str), r.get("durability", str), r.get("depth", int)
    ok = r.ok
    if reliability is not None and reliability not in RELIABILITIES:
        diag.error(r.key_pos("reliability"), f"reliability {reliability!r} in {what} is unknown",
                   " or ".join(RELIABILITIES))
        ok = False
    if durability is not None and durability not in DURABILITIES:
        diag.error(r.key_pos("durability"), f"durability {durability!r} in {what} is unknown",
                   " or ".join(DURABILITIES))
        ok = False
    if depth is not None and not 1 <= depth <= QOS_DEPTH_MAX:
        diag.error(r.key_pos("depth"), f"depth {depth} in {what} is out of range", f"1..{QOS_DEPTH_MAX}")
        ok = False
    if not ok or reliability is None or durability is None or depth is None:
        return None
    return Qos(reliability, durability, depth)


def _vector3(node: YNode | None, what: str, diag: Diagnostics) -> tuple[float, float, float] | None:
    if node is None:
        return None
    items = _list(node, what, diag)
    values = [_number(item, f"an element of {what}", diag) for item in items]
    if isinstance(node, YSeq) and len(items) != 3:
        diag.error(node.pos, f"{what} must have 3 elements, found {len(items)}", "[x, y, z]")
        return None
    if len(values) != 3 or any(v is None for v in values):
        return None
    return (float(values[0]), float(values[1]), float(values[2]))  # type: ignore[arg-type]


def _frame(key: str, pos: Pos, node: YNode, diag: Diagnostics) -> Frame:
    what = f"frame {key!r}"
    r = _Reader(node, what, diag, ("parent", "description", "xyz", "rpy"))
    frame = Frame(key, r.get("parent", str, None), _text(r, "description"), pos)
    for attr in ("xyz", "rpy"):
        value = _vector3(r.node(attr), f"{attr} of {what}", diag)
        if value is None:
            continue
        if frame.parent is None:
            diag.error(r.key_pos(attr), f"{what} has no parent: its {attr} would offset it from nothing",
                       "a `parent` for a static child frame")
        setattr(frame, attr, value)
    return frame


def _node_topics(node: YNode | None, what: str, diag: Diagnostics, with_qos: bool) -> list[NodeTopic]:
    """Entries `/topic` or `{topic: /topic, type: pkg/Name}` (subscriptions also `qos: ...`)."""
    items = []
    keys = ("topic", "type", "qos") if with_qos else ("topic", "type")
    for item in _list(node, what, diag):
        if isinstance(item, YMap):
            r = _Reader(item, f"an entry of {what}", diag, keys)
            topic, type_ = r.get("topic", str), r.get("type", str, None)
            qos_node = r.node("qos")
            qos = parse_qos(qos_node, f"the QoS of {topic or '?'} in {what}", diag) if qos_node is not None else None
            if topic is not None:
                items.append(NodeTopic(topic, qos, item.pos, type_.replace("/msg/", "/") if type_ else None))
            continue
        topic = scalar(item, str, f"an entry of {what}", diag)
        if topic is not None:
            items.append(NodeTopic(topic, None, item.pos))
    return items


def _node_transforms(node: YNode | None, what: str, diag: Diagnostics) -> list[NodeTransform]:
    result = []
    for text, item_pos in _str_list(node, what, diag):
        parent, sep, child = text.partition("->")
        if not sep or not parent.strip() or not child.strip():
            diag.error(item_pos, f"transform {text!r} in {what} is not parent->child", "parent->child")
            continue
        result.append(NodeTransform(parent.strip(), child.strip(), item_pos))
    return result


_NODE_KEYS = ("description", "publishes", "subscribes", "parameters", "transforms", "reads_transforms")


def _node(spec: Spec, key: str, pos: Pos, node: YNode, diag: Diagnostics) -> None:
    what = f"node {key!r}"
    r = _Reader(node, what, diag, _NODE_KEYS)
    spec.nodes[key] = Node(
        key, _text(r, "description"),
        _node_topics(r.node("publishes"), f"publishes of {what}", diag, with_qos=False),
        _node_topics(r.node("subscribes"), f"subscribes of {what}", diag, with_qos=True),
        [NodeParameter(t, p) for t, p in _str_list(r.node("parameters"), f"parameters of {what}", diag)],
        _node_transforms(r.node("transforms"), f"transforms of {what}", diag),
        _node_transforms(r.node("reads_transforms"), f"reads_transforms of {what}", diag),
        pos,
    )


def load_spec_file(path: Path) -> Spec:
    """Read and structurally parse a spec file (no cross-reference checks)."""
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        from .diagnostics import Diagnostic

        raise SpecError([Diagnostic(Pos(str(path)), f"cannot read the spec: {exc}")]) from None
    return parse_spec(load_yaml(text, str(path)), str(path))
