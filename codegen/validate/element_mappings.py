"""Element mappings: an array of composites converted element by element (`ros_array: {each: uavcan_array,
fields: {...}}`), checked against both element types.

Invariants:
- the element fields are resolved exactly as a mapping's fields are (MappingValidator.resolve_body on the element
  types, with the mapping's direction, frame_id and on_out_of_range), so every rule of a link holds for them and
  their errors carry their own file:line:col, prefixed with `<mapping>, elements of '<ros array>'`;
- the result is one Step of kind "elements" whose `elements` is that nested ResolvedMapping; the array's own length
  rules (bounded capacity, fixed size) are the conversion plan's (conversion_plan.lower_elements);
- errors about the element mapping as a whole (an element field left unmapped) point at its line;
- an element's ROS header is the message's: the same stamp (the source timestamp, or the receive time) and the
  mapping's frame_id; UAVCAN -> ROS, every other ROS element field must be set by a line;
- the element mapping is named `<mapping>.<ros array>[]`: its stats keys read `<mapping>.<ros array>[].<field>`;
- an array mapped element by element is named by no other line, value or selection of the mapping;
- element mappings do not nest (an element field with `each` is refused) and index no element (`each: a[0]` is
  refused); they serve Cyphal and DroneCAN mappings alike.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

from sam_codegen.model.spec import UAVCAN_TO_ROS, FieldLink, Mapping, RosMessage
from sam_codegen.model.types import RosType
from sam_codegen.validate.mapping_rules import HEADER, PathSeg, RuleError, Step, format_path, parse_path

__all__ = ["resolve_elements"]


def resolve_elements(v: Any, link: FieldLink, ros_path: list[PathSeg], ros_type: RosType, struct: Any,
                     mapping: Mapping, what: str) -> Step | None:
    """The element mapping `link` of `mapping` (v: the MappingValidator; its state is restored afterwards).

    Raises RuleError for what is wrong with the line itself (reported at the line by the caller); reports the
    element fields' own errors at their lines and returns None then."""
    assert link.each is not None
    if any(index is not None for _, index in ros_path):
        raise RuleError(f"{link.ros_path} names an array element; `each` maps a whole array")
    if ros_type.is_primitive or not ros_type.array:
        raise RuleError(f"`each` maps an array of messages element by element, {link.ros_path} is {ros_type}")
    if ros_type.array == "fixed":
        raise RuleError(f"`each` maps into a ROS sequence (T[] or T[<=N]), {link.ros_path} is a fixed-size array "
                        f"({ros_type})")
    uav_path = _parse_uav(link.each)
    uav_type = v.dsdl_leaf(struct, uav_path, allow_composite=True, record=False)
    if not uav_type.array or uav_type.kind != "composite":
        raise RuleError(f"`each` takes an array of composites, {link.each} is {uav_type}")
    if ros_type.array == "bounded" and (ros_type.capacity or 0) < (uav_type.capacity or 0):
        raise RuleError(f"{link.ros_path} ({ros_type}) holds fewer elements than {link.each} ({uav_type})")
    others = [f"field {other.ros_path!r}" for other in mapping.links if other is not link
              and other.uavcan_path is not None and _under(other.uavcan_path, link.each)]
    others += [f"{key} {path!r}" for key, paths in (("uavcan_values", mapping.uavcan_values),
                                                    ("select", mapping.select)) for path in paths
               if _under(path, link.each)]
    if others:
        raise RuleError(f"{link.each} is mapped element by element here and also named by " + ", ".join(others)
                        + "; one way for one array")
    nested = [inner for inner in link.element_links if inner.each is not None]
    for inner in nested:
        v.error(inner.pos, f"{what}, elements of {link.ros_path!r}, field {inner.ros_path!r}: element mappings "
                "do not nest (an element field with `each`)", "a mapping of its own for the inner array")
    element_message: RosMessage | None = v.ros.get(ros_type.base)
    element_struct = v.types.get(uav_type.composite)
    if element_message is None or element_struct is None or nested:
        return None
    inner_what = f"{what}, elements of {link.ros_path!r}"
    element_mapping = replace(mapping, pos=link.pos, name=f"{mapping.name}.{link.ros_path}[]",
                              links=list(link.element_links),
                              ignore=list(link.element_ignore), uavcan_values=dict(link.element_values),
                              select={}, auto=False)
    saved = {k: getattr(v, k) for k in ("v0", "types", "elements", "failed_paths", "ignored", "element_uses",
                                        "direction") if hasattr(v, k)}
    errors_before = len(v.diag.items)
    resolved = None
    try:
        resolved = v.resolve_body(element_mapping, inner_what, _ElementTopic(ros_type.base), element_struct, 0.0)
        if resolved is not None and mapping.direction == UAVCAN_TO_ROS:
            set_fields = {inner.ros_path.split("[")[0].split(".")[0] for inner in link.element_links}
            for f in element_message.fields:
                header = isinstance(f.type, RosType) and f.type.base == HEADER
                if f.name not in set_fields and not header:
                    v.error(link.pos, f"ROS element field {f.name!r} ({f.type}) of {element_message.full_name} is set "
                            f"by nothing in {inner_what}", f"a `{f.name}: <UAVCAN element field>` line in its fields")
    finally:
        for k, value in saved.items():
            setattr(v, k, value)
    if resolved is None or len(v.diag.items) > errors_before:
        return None
    return Step("elements", tuple(ros_path), ros_type, tuple(uav_path), uav_type, pos=link.pos, elements=resolved,
                exact=all(s.exact for s in resolved.steps))


class _ElementTopic:
    """What resolve_body reads of a topic: the ROS type (of one element)."""

    def __init__(self, type_name: str) -> None:
        self.type = type_name


def _parse_uav(text: str) -> list[PathSeg]:
    path = parse_path(text)
    if any(index is not None for _, index in path):
        raise RuleError(f"{format_path(path)} names an array element; `each` maps a whole array")
    return path



def _under(path: str, array: str) -> bool:
    """`path` names `array` or something in it."""
    return path == array or path.startswith((array + "[", array + "."))
