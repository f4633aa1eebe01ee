"""The lowering: each resolved mapping's links (validate.mapping_rules.Step) into the operations of both
directions, with the range checks into each target type, mapping expressions and element mappings."""

from __future__ import annotations

import math

from sam_codegen.conversion_plan.operations import (
    TO_ROS,
    TO_UAVCAN,
    Clamp,
    Convert,
    DecodeUtf8,
    ElementMapping,
    EncodeUtf8,
    Evaluate,
    FieldSet,
    FixedLength,
    Limits,
    LinkPlan,
    MappingPlan,
    MaxLength,
    Offset,
    Op,
    Pad,
    PlanDirection,
    ReceiveTime,
    RejectNaN,
    RequireItem,
    RequireLength,
    Round,
    Scale,
    SetConstant,
    StaticFrameId,
    Table,
    TimestampFromRos,
    TimestampToRos,
    Utf8Length,
    Wrap,
)
from sam_codegen.conversion_plan.value_ranges import (
    FLOAT32_MAX,
    TIME_US_MAX_FROM_ROS,
    TIME_US_MAX_TO_ROS,
    TIME_US_MIN,
    ValueRange,
    dsdl_range,
    is_int_dsdl,
    ros_range,
)
from sam_codegen.model.expr import ENode
from sam_codegen.model.spec import ROS_TO_UAVCAN, Mapping, Scalar
from sam_codegen.model.types import ROS_FLOAT_BITS, ROS_INT_RANGES, DsdlType, RosType
from sam_codegen.validate.mapping_rules import Key, ResolvedMapping, Step


def range_ops(value_is_float: bool, value_range: ValueRange | None, target: DsdlType,
              limits: tuple[Scalar, Scalar] | None, reject: bool, wrap: bool = False, *,
              reject_nan: bool = False) -> list[Op]:
    """What makes a value acceptable to a DSDL scalar of type `target`, after the `limits` if any.

    `value_range` is the finite range the value is known to lie in (None: unknown); a float value may also be NaN
    or infinite. Nothing is planned for what cannot happen. NaN is rejected on its way into an integer or a limited
    field (it fits neither), and into a float field too with `reject_nan` (a command: NaN is not a setpoint).

    >>> range_ops(False, (0, 255), DsdlType("uint", 8), None, False)
    []
    >>> range_ops(False, (-128, 127), DsdlType("uint", 8), None, True)
    [Clamp(mode='integer', low=0, high=None, reject=True)]
    >>> range_ops(True, None, DsdlType("int", 8), None, False)
    [RejectNaN(), Clamp(mode='round', low=-128, high=127, reject=False)]
    >>> range_ops(True, (-3.4028234663852886e+38, 3.4028234663852886e+38), DsdlType("float", 16), (0, 100), False)
    [RejectNaN(), Limits(low=0.0, high=100.0, declared=(0, 100), reject=False)]
    """
    out: list[Op] = []
    if target.kind == "bool":
        return out
    integer = is_int_dsdl(target)
    nonfinite = value_is_float
    if value_is_float and (integer or limits is not None or reject_nan):
        out.append(RejectNaN())
    if limits is not None:
        low, high = (float(v) if not integer or not float(v).is_integer() else int(v) for v in limits)
        out.append(Limits(low, high, (limits[0], limits[1]), reject))
        value_range = (low, high) if value_range is None else (max(low, value_range[0]), min(high, value_range[1]))
        nonfinite = False
        value_is_float = value_is_float or isinstance(low, float) or isinstance(high, float)
    rng = dsdl_range(target)
    assert rng is not None
    lo, hi = rng
    beyond = value_range is None or value_range[0] < lo or value_range[1] > hi
    if integer:
        lo, hi = int(lo), int(hi)
        if value_is_float:
            if value_range is not None and not nonfinite and lo - 0.5 < value_range[0] and value_range[1] < hi + 0.5:
                out.append(Round())
            else:  # only what rounds into the range is rounded: round() would raise on inf
                out.append(Clamp("round", lo, hi, reject))
        elif beyond and wrap:  # the line's `on_out_of_range: wrap` (validated: an integer value)
            out.append(Wrap(target.bits, target.kind == "int"))
        elif beyond:
            out.append(Clamp("integer",
                             lo if value_range is None or value_range[0] < lo else None,
                             hi if value_range is None or value_range[1] > hi else None, reject))
    elif target.bits == 16:
        if nonfinite or beyond:
            out.append(Clamp("float16", lo, hi, reject))
    elif target.bits == 32 and beyond:
        out.append(Clamp("float32", lo, hi, reject))
    return out


def ros_value(ros_base: str, transformed: bool) -> tuple[bool, ValueRange | None]:
    """(float-valued, finite range if known) of a ROS element, after an inverse scale/offset if `transformed`.

    >>> ros_value("int16", False), ros_value("float64", False), ros_value("int16", True)
    ((False, (-32768, 32767)), (True, None), (True, None))
    """
    if transformed:
        return True, None
    value_range = ros_range(ros_base)
    if value_range is not None and not math.isfinite(value_range[1]):
        value_range = None
    return ros_base in ROS_FLOAT_BITS, value_range


def float32_overflow(step: Step, uav: DsdlType, ros_base: str) -> bool:
    """Whether a scaled / offset UAVCAN value can exceed a ROS float32's finite range."""
    if ros_base != "float32" or (step.scale is None and step.offset is None):
        return False
    rng = dsdl_range(uav)
    if rng is None:
        return False
    bound = max(abs(rng[0]), abs(rng[1])) * abs(step.scale if step.scale is not None else 1.0)
    return bound + abs(step.offset or 0.0) > FLOAT32_MAX


def _convert(src: str, dst: str) -> list[Op]:
    return [Convert(src, dst)] if src != dst else []


def expr_target(t: DsdlType | RosType) -> DsdlType:
    """The DSDL scalar whose range an expression's value must fit into a field of type `t` (ROS or DSDL).

    >>> str(expr_target(RosType("int16"))), str(expr_target(RosType("uint8"))), expr_target(RosType("float64")).bits
    ('int16', 'uint8', 64)
    """
    if isinstance(t, DsdlType):
        return t
    if t.base == "bool":
        return DsdlType("bool", 1)
    if t.base in ROS_FLOAT_BITS:
        return DsdlType("float", ROS_FLOAT_BITS[t.base])
    lo, hi = ROS_INT_RANGES[t.base]
    return DsdlType("int" if lo < 0 else "uint", (hi - lo).bit_length())


def lower_expr(tree: ENode, target: DsdlType, reject: bool, wrap: bool = False, *, pass_nan: bool = False
               ) -> list[Op]:
    """An expression into a target scalar: evaluated, a NaN result dropped (passed on into a float field of a
    command mapping with `pass_nan`), then into the target's range.

    >>> from sam_codegen.model.expr import EField
    >>> lower_expr(EField((("p", None),), "p", DsdlType("int", 7), "int", (-64, 63)), DsdlType("uint", 5), False)[1:]
    [Clamp(mode='integer', low=0, high=31, reject=False)]
    """
    as_float = target.kind == "float" and tree.kind == "int"
    ops: list[Op] = [Evaluate(tree, as_float)]
    if tree.kind == "bool":
        return ops
    if tree.kind == "float" and not (pass_nan and target.kind == "float"):
        ops.append(RejectNaN())
    ops += [op for op in range_ops(tree.kind == "float", tree.range, target, None, reject, wrap)
            if not isinstance(op, RejectNaN)]
    return ops


def _lower_to_ros(s: Step, reject: bool) -> list[Op]:
    if s.kind == "expr":
        if s.uavcan_path:  # a ROS -> UAVCAN expression: nothing to say towards ROS
            return []
        assert s.expr is not None
        return lower_expr(s.expr, expr_target(s.ros_type), reject, s.wrap)
    if s.kind == "value":
        return [SetConstant(s.value)]  # type: ignore[arg-type]
    uav = s.uavcan_type
    assert uav is not None
    if s.kind == "time":
        lo, hi = uav.range
        return [TimestampToRos(TIME_US_MAX_TO_ROS if hi > TIME_US_MAX_TO_ROS else None,
                               TIME_US_MIN if lo < TIME_US_MIN else None, reject)]
    if s.kind == "table":
        return [Table(s.table, s.table_default, inverse=False)]
    if s.kind == "string":
        return [DecodeUtf8()]
    ros_base = s.ros_type.base
    elem = uav.element if s.kind == "array" else uav
    ops: list[Op] = _convert(elem.base_name, ros_base)
    if s.scale is not None:
        ops.append(Scale(s.scale))
    if s.offset is not None:
        ops.append(Offset(s.offset))
    if s.kind == "number" and elem.kind == "float" and ros_base in ROS_INT_RANGES:  # `round: true`
        lo, hi = ROS_INT_RANGES[ros_base]
        ops.extend(range_ops(True, None, DsdlType("int" if lo < 0 else "uint", (hi - lo).bit_length()), None, reject))
    elif float32_overflow(s, elem, ros_base):
        ops.append(Clamp("float32", -FLOAT32_MAX, FLOAT32_MAX, reject))
    if s.kind == "array" and s.ros_type.array == "fixed" and uav.array == "bounded":
        ops.append(Pad(s.ros_type.capacity or 0))
    return ops


def _lower_to_uavcan(s: Step, reject: bool, pass_nan: bool) -> list[Op]:
    """A ROS -> UAVCAN link (a command): a float NaN is rejected unless the mapping says `pass_nan` (issue 29)."""
    uav = s.uavcan_type
    assert uav is not None
    if s.kind == "expr":
        assert s.expr is not None
        return lower_expr(s.expr, uav, reject, s.wrap, pass_nan=pass_nan)
    if s.kind == "time":
        lo, hi = uav.range
        return [TimestampFromRos(hi if TIME_US_MAX_FROM_ROS > hi else None, lo if TIME_US_MIN < lo else None,
                                 reject)]
    if s.kind == "table":
        return [Table(s.table, None, inverse=True)]
    if s.kind == "string":
        return [EncodeUtf8(), Utf8Length(uav.capacity or 0, reject)]
    ros_base = s.ros_type.base
    transformed = s.scale is not None or s.offset is not None
    transform: list[Op] = []
    if s.offset is not None:
        transform.append(Offset(s.offset, inverse=True))
    if s.scale is not None:
        transform.append(Scale(s.scale, inverse=True))
    if s.kind == "number":
        value_is_float, value_range = ros_value(ros_base, transformed)
        if s.limits is not None and transformed:
            # limits are in ROS units: checked before the inverse scale/offset
            ros_is_float, ros_rng = ros_value(ros_base, False)
            limit_type = DsdlType("float", 64) if ros_is_float else DsdlType("int", 64)
            ops = range_ops(ros_is_float, ros_rng, limit_type, s.limits, reject)
            return [*ops, *transform, *_convert(ros_base, uav.base_name),
                    *range_ops(value_is_float, value_range, uav, None, reject)]
        return [*transform, *_convert(ros_base, uav.base_name),
                *range_ops(value_is_float, value_range, uav, s.limits, reject, s.wrap, reject_nan=not pass_nan)]
    # array: the length first, then the elements
    elem = uav.element
    value_is_float, value_range = ros_value(ros_base, transformed)
    ops = [*transform, *_convert(ros_base, elem.base_name)]
    cap = uav.capacity or 0
    ros_fixed = s.ros_type.array == "fixed"
    if uav.array == "fixed":
        if not ros_fixed:
            ops.append(FixedLength(cap, reject))
    elif s.ros_type.array == "dynamic" or (s.ros_type.capacity or 0) > cap:
        ops.append(MaxLength(cap, ros_fixed, reject))
    return [*ops, *range_ops(value_is_float, value_range, elem, None, reject, reject_nan=not pass_nan)]


def lower_link(step: Step, direction: PlanDirection, mapping: str, reject: bool, pass_nan: bool = False) -> LinkPlan:
    """The operations of one link in one direction (`mapping`: the mapping's name, for the stats key; `pass_nan`:
    the mapping's, ROS -> UAVCAN only)."""
    if step.kind == "elements":
        return lower_elements(step, direction, mapping, reject)
    if direction == TO_ROS:
        return LinkPlan(step, TO_ROS, f"{mapping}.{step.ros}", tuple(_lower_to_ros(step, reject)), reject)
    return LinkPlan(step, TO_UAVCAN, f"{mapping}.{step.uavcan}", tuple(_lower_to_uavcan(step, reject, pass_nan)),
                    reject)


def passes_nan(m: Mapping) -> bool:
    """Whether the mapping's ROS -> UAVCAN converter lets a float NaN through: only a command mapping rejects it (a
    UAVCAN -> ROS mapping's reverse converter, which the simulated devices use, keeps a sensor's NaN, e.g. "no
    bottom lock"), and only unless it says `pass_nan: true`."""
    return m.pass_nan or m.direction != ROS_TO_UAVCAN


def lower_mapping(rm: ResolvedMapping) -> MappingPlan:
    """Both converters of a mapping, planned."""
    m = rm.mapping
    reject = m.on_out_of_range == "reject"
    ros_fields: list[FieldSet] = []
    if rm.has_header and not rm.stamp_from_source:
        ros_fields.append(FieldSet((("header", None), ("stamp", None)), RosType("builtin_interfaces/Time"),
                                   ReceiveTime()))
    if rm.has_header and m.frame_id:  # frame_id '': the message's own empty one, no frame prefix before it
        ros_fields.append(FieldSet((("header", None), ("frame_id", None)), RosType("string"),
                                   StaticFrameId(m.frame_id)))
    required: list[RequireItem | RequireLength] = []
    for array_path, uses in rm.elements.items():
        if uses and isinstance(uses[0], Key):
            required.extend(RequireItem(array_path, k) for k in uses)
        else:
            required.append(RequireLength(array_path, max(uses) + 1))
    return MappingPlan(
        name=m.name, direction=m.direction, reject=reject, ros_fields=tuple(ros_fields),
        to_ros=tuple(lower_link(s, TO_ROS, m.name, reject) for s in rm.steps if s.ros_path),
        to_uavcan=tuple(lower_link(s, TO_UAVCAN, m.name, reject, passes_nan(m)) for s in rm.steps if s.uavcan_path),
        uavcan_fields=tuple([*(FieldSet(p, t, SetConstant(v)) for p, t, v in rm.uavcan_values),
                             *(FieldSet(p, t, SetConstant(v, select=True)) for p, t, v in rm.select)]),
        required=tuple(required),
    )


def lower_elements(step: Step, direction: PlanDirection, mapping: str, reject: bool) -> LinkPlan:
    """An element mapping in one direction: the element plan, then the array's length (to UAVCAN: beyond a bounded
    array's capacity cut (saturate) or rejected; into a fixed one padded with default elements or cut)."""
    assert step.elements is not None and step.uavcan_type is not None
    uav = step.uavcan_type
    element = ElementMapping(lower_mapping(step.elements), step.ros_type.base, uav.composite or "")
    if direction == TO_ROS:
        return LinkPlan(step, TO_ROS, f"{mapping}.{step.ros}", (element,), reject)
    ops: list[Op] = [element]
    cap = uav.capacity or 0
    ros_fixed = step.ros_type.array == "fixed"
    if uav.array == "fixed":
        if not (ros_fixed and step.ros_type.capacity == cap):
            ops.append(FixedLength(cap, reject))
    elif step.ros_type.array == "dynamic" or (step.ros_type.capacity or 0) > cap:
        ops.append(MaxLength(cap, False, reject))
    return LinkPlan(step, TO_UAVCAN, f"{mapping}.{step.uavcan}", tuple(ops), reject)
