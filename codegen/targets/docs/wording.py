"""The docs target's words for numbers and conversions: how a value, a rate, a field link and a mapping's field table
read in the interface reference.

Holds fmt_number and fmt_rate (numbers as a reader expects them), describe_link / describe_step (one field link in
words) and field_rows (the field table of one Cyphal or DroneCAN mapping).

Invariants:

- The words come from the conversion plan (conversion_plan.lower_link / lower_mapping), the same operations the
  generated converters run, so the reference cannot describe a conversion the bridge does not do.
- Every conversion is worded in the direction the bridge runs it (UAVCAN -> ROS or ROS -> UAVCAN), and out-of-range
  handling follows the mapping's on_out_of_range ("rejected" or the saturating / cutting policy).
- The text here is plain: nothing is escaped for Markdown or XML. The templates escape everything that comes from the
  spec (md_cell / md_code / xml_text).
- Pure functions of their arguments: no state, no I/O.
"""

from __future__ import annotations

import json
import math
from decimal import Decimal

from sam_codegen.conversion_plan import (
    Clamp,
    Convert,
    DecodeUtf8,
    ElementMapping,
    Evaluate,
    FixedLength,
    Limits,
    LinkPlan,
    MaxLength,
    Offset,
    Pad,
    PlanDirection,
    ReceiveTime,
    RejectNaN,
    Scale,
    SetConstant,
    StaticFrameId,
    Table,
    TimestampFromRos,
    TimestampToRos,
    Utf8Length,
    Wrap,
    lower_link,
    lower_mapping,
)
from sam_codegen.model.expr import EBinary, ECall, ENode, EUnary, fields_of, spell
from sam_codegen.model.spec import Scalar
from sam_codegen.targets.docs.graph import UAVCAN_TO_ROS
from sam_codegen.validate.mapping_rules import ResolvedMapping, Step, format_path


def fmt_number(value: Scalar | None) -> str:
    """A number as a reader expects it: exact, short, powers of ten as 1e-4.

    >>> [fmt_number(v) for v in (1.0e-4, 1.0e-8, 0.01, -273.15, 5.0, 100, float("nan"), True, "ok")]
    ['1e-4', '1e-8', '0.01', '-273.15', '5.0', '100', 'NaN', 'true', '"ok"']
    """
    if value is None:
        return ""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, float):
        if math.isnan(value):
            return "NaN"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        if value != 0 and (abs(value) < 1e-3 or abs(value) >= 1e6):
            return format(Decimal(repr(value)).normalize(), "e")
        return repr(value)
    return repr(value)


def fmt_rate(rate: float) -> str:
    """A nominal rate.

    >>> fmt_rate(100.0), fmt_rate(2.5)
    ('100 Hz', '2.5 Hz')
    """
    return f"{int(rate) if float(rate).is_integer() else rate} Hz"


def _arithmetic(op: Scale | Offset) -> str:
    """Scale and offset as the bridge applies them: ros = uavcan × scale + offset, and the inverse."""
    if isinstance(op, Scale):
        return f"{'÷' if op.inverse else '×'} {fmt_number(op.factor)}"
    subtract = (op.amount < 0) != op.inverse
    return ("- " if subtract else "+ ") + fmt_number(abs(op.amount))


def _policy(link: LinkPlan, saturated: str) -> str:
    return "rejected" if link.reject else saturated


def describe_link(link: LinkPlan) -> str:
    """The conversion of one field link in words, from its planned operations (conversion_plan), in the
    direction the bridge runs it. Out-of-range handling follows the mapping's on_out_of_range."""
    step, ops, to_ros = link.step, link.ops, link.to_ros
    first = ops[0] if ops else None
    if isinstance(first, ElementMapping):
        return describe_elements(link, first)
    if isinstance(first, SetConstant):
        return f"constant {fmt_number(first.value)}"
    if isinstance(first, Evaluate):
        return describe_expression(link, first)
    ros = step.ros_type
    uav = step.uavcan_type
    assert uav is not None
    if isinstance(first, TimestampToRos):
        return f"usec → {ros.base} (0 = receive time)"
    if isinstance(first, TimestampFromRos):
        return f"{ros.base} → usec"
    src, dst = (str(uav), str(ros)) if to_ros else (str(ros), str(uav))
    if isinstance(first, DecodeUtf8):
        return f"{src} → {dst} (invalid UTF-8 replaced)"
    cut = link.first(Utf8Length)
    if isinstance(cut, Utf8Length):
        return f"{src} → {dst} (longer than {cut.capacity} bytes {_policy(link, 'cut')})"
    src_elem, dst_elem = (uav.base_name, ros.base) if to_ros else (ros.base, uav.base_name)
    text = f"{src} → {dst}" if step.kind == "array" else f"{src_elem} → {dst_elem}"
    notes: list[str] = []
    if isinstance(first, Table):
        pairs = ", ".join(f"{k}: {v}" for k, v in first.pairs)
        if first.default is not None:  # the inverse rejects what has no key
            pairs += f", default: {first.default}"
        text += f" inverse of table {{{pairs}}}" if first.inverse else f" table {{{pairs}}}"
        if not step.exact:
            notes.append("not one to one")
        return text + (f" ({', '.join(notes)})" if notes else "")
    arithmetic: list[str] = []
    for op in [*ops, None]:
        if isinstance(op, (Scale, Offset)):
            arithmetic.append(_arithmetic(op))
            continue
        if arithmetic:  # a run of scale / offset: "× s + o" to ROS, "- o, then ÷ s" to UAVCAN
            text += " " + (" " if to_ros else ", then ").join(arithmetic)
            arithmetic = []
        if isinstance(op, Limits):  # in ROS units, before the inverse scale / offset
            text += f" limits [{fmt_number(op.declared[0])}, {fmt_number(op.declared[1])}]"
    convert = link.first(Convert)
    change = convert.change if isinstance(convert, Convert) else ""
    if change in ("narrowed", "rounded") or (change and not link.has(Scale, Offset)):
        notes.append(change)
    if link.has(Limits, Clamp):  # values beyond the limits or the target's range
        policy = "out of range rejected" if link.reject else "saturating"
        notes = [f"{notes[0]}, {policy}"] if notes else [policy]
    wrap = link.first(Wrap)
    if isinstance(wrap, Wrap):
        notes.append(_wrapping(wrap))
    if link.has(RejectNaN) and not to_ros and uav.element.kind == "float" and not link.has(Limits):
        notes.append("NaN rejected")  # a command: NaN is no setpoint (`pass_nan: true` lets it through)
    for op in ops:
        if isinstance(op, Pad):
            notes.append(f"padded to {op.size}")
        elif isinstance(op, FixedLength):
            notes.append(f"other lengths {_policy(link, 'padded or cut')}")
        elif isinstance(op, MaxLength):
            notes.append(f"over {op.capacity} elements {_policy(link, 'cut')}")
    return text + (f" ({', '.join(notes)})" if notes else "")


def describe_expression(link: LinkPlan, op: Evaluate) -> str:
    """An expression link: the expression in the spec's syntax, then what can happen to its value."""
    target = str(link.step.ros_type) if link.to_ros else str(link.step.uavcan_type)
    notes: list[str] = []
    calls = _calls(op.tree)
    if link.has(RejectNaN) or calls & {"trunc", "round"}:
        notes.append("NaN rejected")
    if calls & {"trunc", "round"}:
        notes.append(" and ".join(sorted(calls & {"trunc", "round"})) + " beyond int64 "
                     + _policy(link, "saturated"))
    if link.has(Clamp):  # into the target's range, worded as every other link's
        notes.append("out of range rejected" if link.reject else "saturating")
    wrap = link.first(Wrap)
    if isinstance(wrap, Wrap):
        notes.append(_wrapping(wrap))
    return f"= {spell(op.tree)} → {target}" + (f" ({', '.join(notes)})" if notes else "")


def _wrapping(op: Wrap) -> str:
    """`on_out_of_range: wrap`, said as what it does (the docs warn the reader as the README does)."""
    return f"WRAPS modulo 2^{op.bits} beyond the range{' (two’s complement)' if op.signed else ''}, never saturates"


def _calls(node: ENode) -> set[str]:
    if isinstance(node, ECall):
        return {node.func}.union(*(_calls(a) for a in node.args))
    if isinstance(node, EUnary):
        return _calls(node.arg)
    if isinstance(node, EBinary):
        return _calls(node.left) | _calls(node.right)
    return set()


def describe_step(step: Step, direction: str, on_out_of_range: str, pass_nan: bool = False) -> str:
    """The conversion of one field link in words, in the direction the bridge runs it (its plan, described)."""
    plan_direction: PlanDirection = "to_ros" if direction == UAVCAN_TO_ROS else "to_uavcan"
    return describe_link(lower_link(step, plan_direction, "", on_out_of_range == "reject",
                                    pass_nan or direction == UAVCAN_TO_ROS))


def field_rows(rm: ResolvedMapping) -> list[dict[str, object]]:
    """The field table of a mapping (Cyphal or DroneCAN), worded from its conversion plan in the mapping's direction:
    DroneCAN's select, the header the bridge fills, then each link, the constants it sets and the ignored fields."""
    m = rm.mapping
    plan = lower_mapping(rm)
    to_ros = m.direction == UAVCAN_TO_ROS
    arrow = "←" if to_ros else "→"
    rows: list[dict[str, object]] = [
        {"ros": None, "arrow": "", "uavcan": format_path(list(fs.path)), "conversion": f"select {fs.op.value}"}
        for fs in plan.uavcan_fields if isinstance(fs.op, SetConstant) and fs.op.select]

    def link_row(link: LinkPlan) -> dict[str, object]:
        step = link.step
        reads = ", ".join(f.text for f in fields_of(step.expr)) if step.expr is not None else ""  # an expression's
        return {"ros": step.ros or reads or None, "arrow": arrow, "uavcan": step.uavcan or reads or None,
                "conversion": describe_link(link)}

    links = list(plan.to_ros if to_ros else plan.to_uavcan)
    if to_ros and rm.has_header:
        stamp = next((link for link in links if link.step.ros == "header.stamp"), None)
        if stamp is not None:
            links.remove(stamp)
            rows.append(link_row(stamp))
        for fs in plan.ros_fields:  # the receive-time stamp (when no link sets it), the frame id
            text = "receive time" if isinstance(fs.op, ReceiveTime) else f"constant {fs.op.value}"
            rows.append({"ros": format_path(list(fs.path)), "arrow": arrow, "uavcan": None, "conversion": text})
    for link in links:
        rows.append(link_row(link))
        rows.extend(element_rows(link, arrow))  # an element mapping: its element fields, one row each
    for name in m.ros_defaults:  # kept at the type's default on purpose
        rows.append({"ros": name, "arrow": "", "uavcan": None,
                     "conversion": "default (0, false, empty) where nothing writes it"})
    for fs in plan.uavcan_fields:
        if isinstance(fs.op, SetConstant) and not fs.op.select:
            rows.append({"ros": None, "arrow": arrow, "uavcan": format_path(list(fs.path)),
                         "conversion": f"constant {fmt_number(fs.op.value)}"})
    for ignored in m.ignore:
        rows.append({"ros": None, "arrow": "", "uavcan": ignored, "conversion": "ignored"})
    return rows


def describe_elements(link: LinkPlan, element: ElementMapping) -> str:
    """An element mapping: element by element, the element header, the array's length rule."""
    src, dst = ((element.uavcan_element, element.ros_element) if link.to_ros
                else (element.ros_element, element.uavcan_element))
    notes: list[str] = []
    if link.to_ros and any(isinstance(fs.op, (ReceiveTime, StaticFrameId)) for fs in element.plan.ros_fields):
        notes.append("each element's header: the message's stamp and frame id")
    for op in link.ops[1:]:
        if isinstance(op, FixedLength):
            notes.append(f"other lengths {_policy(link, 'padded or cut')}")
        elif isinstance(op, MaxLength):
            notes.append(f"over {op.capacity} elements {_policy(link, 'cut')}")
    notes.append("an element rejected drops the message")
    return f"element by element, {src} → {dst} ({', '.join(notes)})"


def element_rows(link: LinkPlan, arrow: str) -> list[dict[str, object]]:
    """The rows of an element mapping's element fields (`array[].field`), after the array's own row."""
    first = link.ops[0] if link.ops else None
    if not isinstance(first, ElementMapping):
        return []
    ros, uav = link.step.ros, link.step.uavcan
    plan = first.plan
    rows: list[dict[str, object]] = []
    for inner in plan.to_ros if link.to_ros else plan.to_uavcan:
        rows.append({"ros": f"{ros}[].{inner.step.ros}", "arrow": arrow,
                     "uavcan": f"{uav}[].{inner.step.uavcan}" if inner.step.uavcan else None,
                     "conversion": describe_link(inner)})
    if not link.to_ros:
        for fs in plan.uavcan_fields:
            if isinstance(fs.op, SetConstant):
                rows.append({"ros": None, "arrow": arrow, "uavcan": f"{uav}[].{format_path(list(fs.path))}",
                             "conversion": f"constant {fmt_number(fs.op.value)}"})
    else:
        for ignored in link.step.elements.mapping.ignore if link.step.elements is not None else []:
            rows.append({"ros": None, "arrow": "", "uavcan": f"{uav}[].{ignored}", "conversion": "ignored"})
    return rows


__all__ = ["describe_elements", "describe_link", "describe_step", "element_rows", "field_rows", "fmt_number",
           "fmt_rate"]
