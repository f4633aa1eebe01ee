"""The spec's type sections: ROS messages (own and external), Cyphal DSDL types and DroneCAN (v0) types."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from sam_codegen.frontend.reading import Reader, parse_type, seq_items, text_of
from sam_codegen.frontend.yaml_source import YNode
from sam_codegen.model.diagnostics import Diagnostics, Pos
from sam_codegen.model.spec import Constant, DsdlService, DsdlStruct, Field, RosMessage, RosService, V0Struct
from sam_codegen.model.types import DsdlType, parse_dsdl_type, parse_ros_type, parse_v0_type

__all__ = ["parse_dronecan_type", "parse_dsdl_service", "parse_dsdl_struct", "parse_ros_message",
           "parse_ros_service"]


_FIELD_KEYS = ("name", "type", "comment", "default")
_CONST_KEYS = ("name", "type", "value", "comment")


def _fields(node: YNode | None, what: str, parse: Callable[[str], Any], diag: Diagnostics) -> list[Field]:
    """The fields of a message or DSDL type; DSDL void padding comes as a Field without a name."""
    result = []
    for item in seq_items(node, f"the fields of {what}", diag):
        r = Reader(item, f"a field of {what}", diag, _FIELD_KEYS)
        type_text = r.get("type", str)
        type_ = parse_type(type_text, r.key_pos("type"), parse, diag)
        if type_ is None and parse in (parse_dsdl_type, parse_v0_type) and str(type_text).strip().startswith("void"):
            continue  # padding with a bad type (reported): it has no name to miss
        if isinstance(type_, DsdlType) and type_.kind == "void":
            # DSDL padding has no name (`void3`); it is kept for the layout and mapped by no one.
            if r.node("name") is not None:
                diag.error(r.key_pos("name"), f"void padding in {what} has no name in DSDL",
                           f"{{type: {type_}}} without a name")
            if r.node("default") is not None:
                diag.error(r.key_pos("default"), f"void padding in {what} has no value")
            result.append(Field("", type_, text_of(r, "comment"), item.pos))
            continue
        name = r.get("name", str)
        default = r.get("default", (bool, int, float, str), None)
        if name is not None and type_ is not None:
            result.append(Field(name, type_, text_of(r, "comment"), item.pos, default))
    return result


def _constants(node: YNode | None, what: str, parse: Callable[[str], Any], diag: Diagnostics,
               bool_bits: bool = False) -> list[Constant]:
    """The constants of a message or DSDL type; with `bool_bits` (DSDL v0) a bool constant may be written 0 or 1."""
    result = []
    for item in seq_items(node, f"the constants of {what}", diag):
        r = Reader(item, f"a constant of {what}", diag, _CONST_KEYS)
        name, type_text = r.get("name", str), r.get("type", str)
        value = r.get("value", (bool, int, float, str))
        type_ = parse_type(type_text, r.key_pos("type"), parse, diag)
        if (bool_bits and isinstance(type_, DsdlType) and type_.kind == "bool" and not type_.array
                and isinstance(value, int) and not isinstance(value, bool) and value in (0, 1)):
            # DSDL v0 firmware writes `bool OPEN = 0`, which dronecan's parser reads as 0/1; kept as a bool here so
            # that every emitter (DSDL true/false, docs, converters) sees one form.
            value = bool(value)
        if name is not None and type_ is not None and value is not None:
            result.append(Constant(name, type_, value, text_of(r, "comment"), item.pos))
    return result


def parse_ros_message(key: str, pos: Pos, node: YNode, package: str, external: bool, diag: Diagnostics) -> RosMessage:
    what = f"message {key!r}"
    r = Reader(node, what, diag, ("description", "fields", "constants", "derive_from"))
    pkg, _, name = key.rpartition("/")
    pkg = pkg.replace("/msg", "") or package

    def parse(text: str) -> Any:
        return parse_ros_type(text, pkg)

    derive = r.get("derive_from", str, None)
    if derive is not None and r.node("fields") is not None:
        diag.error(r.key_pos("fields"), f"{what} is derived from {derive}: it cannot also list fields")
    fields = _fields(r.node("fields"), what, parse, diag)
    constants = _constants(r.node("constants"), what, parse, diag)
    # A constants-only message (e.g. a vehicle's Topics.msg of topic names) is valid ROS 2: rosidl's C/C++
    # generators add a placeholder member themselves. Only a message with nothing in it is refused.
    if derive is None and not fields and not constants and r.ok and not external:
        diag.error(pos, f"{what} has neither fields nor constants", "a `fields` list, `constants` or `derive_from`")
    return RosMessage(pkg, name, fields, constants, text_of(r, "description"), derive, external, pos)


def parse_dsdl_struct(key: str, pos: Pos, node: YNode, diag: Diagnostics) -> DsdlStruct:
    what = f"DSDL type {key!r}"
    r = Reader(node, what, diag, ("description", "fields", "constants", "sealed", "extent"))
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
        text_of(r, "description"), bool(sealed), extent, pos=pos, layout=layout if len(fields) < len(layout) else [],
    )


def parse_dronecan_type(key: str, pos: Pos, node: YNode, diag: Diagnostics) -> V0Struct:
    what = f"DroneCAN type {key!r}"
    r = Reader(node, what, diag, ("id", "description", "fields", "constants", "request", "response",
                                  "response_constants"))
    # A service type has `request` and `response` (its two halves, `---` between them in DSDL), not `fields`.
    service = r.node("request") is not None or r.node("response") is not None
    if service and r.node("fields") is not None:
        diag.error(r.key_pos("fields"), f"{what} has `request`/`response` (a service type): it cannot also list "
                   "fields", "`fields` for a message type, or `request` and `response` for a service type")
    if service:
        for part in ("request", "response"):
            if r.node(part) is None:
                diag.error(pos, f"service type {key!r} needs `{part}`", "both `request` and `response` (an empty "
                           "list for an empty half)")
    layout = _fields(r.node("request" if service else "fields"), what, parse_v0_type, diag)
    fields = [f for f in layout if f.name]
    response_layout = _fields(r.node("response"), f"the response of {what}", parse_v0_type, diag) if service else []
    response = [f for f in response_layout if f.name]
    if not service and r.node("response_constants") is not None:
        diag.error(r.key_pos("response_constants"), f"{what} is a message type: it has no response",
                   "`constants`, or `request` and `response` for a service type")
    return V0Struct(
        key, fields, _constants(r.node("constants"), what, parse_v0_type, diag, bool_bits=True),
        text_of(r, "description"),
        pos=pos, layout=layout if len(fields) < len(layout) else [], data_type_id=r.get("id", int, None),
        service=service, response=response,
        response_layout=response_layout if len(response) < len(response_layout) else [],
        response_constants=_constants(r.node("response_constants"), f"the response of {what}", parse_v0_type, diag,
                                      bool_bits=True) if service else [],
    )


def parse_dsdl_service(key: str, pos: Pos, node: YNode, diag: Diagnostics) -> DsdlService:
    """A `dsdl_types` entry with `request` and `response` (field lists): a Cyphal service type."""
    what = f"DSDL service type {key!r}"
    r = Reader(node, what, diag, ("description", "request", "response", "constants", "sealed", "extent"))
    sealed = r.get("sealed", bool, False)
    extent = r.get("extent", int, None)
    if r.ok and not sealed and extent is None:
        diag.error(pos, f"{what} needs `sealed: true` or `extent: <bytes>`", "sealed or extent (DSDL requires one)")
    if sealed and extent is not None:
        diag.error(r.key_pos("extent"), f"{what} cannot be both sealed and have an extent")
    halves = []
    for part in ("request", "response"):
        if r.ok and r.node(part) is None:
            diag.error(pos, f"{what} needs `{part}`", "both `request` and `response` (an empty list for an empty half)")
        layout = _fields(r.node(part), f"the {part} of {what}", parse_dsdl_type, diag)
        fields = [f for f in layout if f.name]
        constants = _constants(r.node("constants"), what, parse_dsdl_type, diag) if part == "request" else []
        halves.append(DsdlStruct(key, fields, constants, "", bool(sealed), extent, pos=pos,
                                 layout=layout if len(fields) < len(layout) else []))
    return DsdlService(key, halves[0], halves[1], text_of(r, "description"), pos)


def parse_ros_service(key: str, pos: Pos, node: YNode, package: str, diag: Diagnostics,
                      external: bool = False) -> RosService:
    """A `services:` entry: a .srv of the spec's package (bare name) with `request` and `response` field lists and
    `constants`; with `external`, an `external_services` entry of `package` (another package's srv)."""
    what = f"service type {key!r}"
    r = Reader(node, what, diag, ("description", "request", "response", "constants"))

    def parse(text: str) -> Any:
        return parse_ros_type(text, package)

    for part in ("request", "response"):
        if r.ok and r.node(part) is None:
            diag.error(pos, f"missing field {part!r} in {what}", "a list of fields (an empty list for none)")
    return RosService(package, key.rsplit("/", 1)[-1],
                      _fields(r.node("request"), f"the request of {what}", parse, diag),
                      _fields(r.node("response"), f"the response of {what}", parse, diag),
                      text_of(r, "description"), pos, _constants(r.node("constants"), what, parse, diag), external)
