"""Element mappings in the spec: `ros_array: {each: uavcan_array, fields: {element_field: link, ...}, ignore: [...]}`.

An array of composites is converted element by element: `each` names the UAVCAN array, `fields` maps the fields of
one element (paths relative to the element, each with today's link syntax: a path, or from/scale/offset/table/
limits/value/round), `ignore` lists UAVCAN element fields no ROS field receives (UAVCAN -> ROS) and
`uavcan_values` gives UAVCAN element fields a constant (ROS -> UAVCAN). Parsed here, checked against the
types by validate.element_mappings. The same form serves both directions and both protocols.
"""

from __future__ import annotations

from collections.abc import Callable

from sam_codegen.frontend.reading import Reader, map_items, scalar, str_list
from sam_codegen.frontend.yaml_source import YNode
from sam_codegen.model.diagnostics import Diagnostics, Pos
from sam_codegen.model.spec import FieldLink, Scalar

__all__ = ["ELEMENT_KEYS", "element_link"]

ELEMENT_KEYS = ("each", "fields", "ignore", "uavcan_values")
_LINK_ONLY = ("from", "scale", "offset", "table", "value", "limits", "round")

LinkParser = Callable[[str, Pos, YNode, str, Diagnostics], "FieldLink | None"]


def element_link(ros_path: str, pos: Pos, r: Reader, mapping: str, diag: Diagnostics,
                 parse_link: LinkParser) -> FieldLink | None:
    """The element mapping of `ros_path` from its already opened reader `r` (keys checked by the caller)."""
    what = f"field {ros_path!r} of mapping {mapping!r}"
    ok = True
    for key in _LINK_ONLY:
        if r.node(key) is not None:
            diag.error(r.key_pos(key), f"{what} maps elements (`each`): {key!r} belongs to its element fields",
                       f"`{key}` inside `fields`")
            ok = False
    each = r.get("each", str, None)
    if each is None:
        diag.error(pos, f"{what} has `fields` but no `each` (the UAVCAN array whose elements it maps)",
                   "each: <UAVCAN array of composites>")
        ok = False
    fields = r.node("fields")
    if fields is None:
        diag.error(pos, f"{what} maps elements of {each!r} but has no `fields`",
                   "fields: {<ROS element field>: <UAVCAN element field>}")
        ok = False
    links: list[FieldLink] = []
    for element_path, key_pos, link_node in map_items(fields, f"the element fields of {what}", diag):
        link = parse_link(element_path, key_pos, link_node, mapping, diag)
        if link is not None:
            links.append(link)
    ignore = tuple(p for p, _ in str_list(r.node("ignore"), f"ignore of {what}", diag))
    values: list[tuple[str, Scalar]] = []
    for path, _, value_node in map_items(r.node("uavcan_values"), f"uavcan_values of {what}", diag):
        value = scalar(value_node, (bool, int, float), f"uavcan value {path!r} of {what}", diag)
        if value is not None:
            values.append((path, value))
    if not ok:
        return None
    return FieldLink(ros_path, each, pos=pos, each=each, element_links=tuple(links), element_ignore=ignore,
                     element_values=tuple(values))
