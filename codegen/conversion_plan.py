"""The conversion plan: every mapping lowered once into typed operations, per link and direction.

`lower_mapping(rm)` decides, for both converters of a mapping (UAVCAN -> ROS and ROS -> UAVCAN), what each link
does to its value, in order: scale and offset, representation changes, NaN rejection, rounding, clamping with its
policy (saturate or reject; finite-only for float32, infinities too for float16, round-into-range for float ->
integer), padding, cutting, tables, timestamps and constants, and mapping expressions (Evaluate: a typed tree of
model.expr, followed by the same checks into the target field). The renderers only word it: targets.python (through
its statements) turns the operations into statements, the wire codecs do the same with their own reads and
writes, and targets.docs words the same operations in the interface reference. Nothing here knows Python syntax.

For an array link the value operations apply to every element; Pad, FixedLength and MaxLength to the array.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Final, Literal

from sam_codegen.model.expr import ENode
from sam_codegen.model.spec import Scalar
from sam_codegen.model.types import ROS_FLOAT_BITS, ROS_INT_RANGES, DsdlType, RosType
from sam_codegen.validate.mapping_rules import Key, PathSeg, ResolvedMapping, Step

TO_ROS: Final = "to_ros"
TO_UAVCAN: Final = "to_uavcan"
PlanDirection = Literal["to_ros", "to_uavcan"]

FLOAT16_MAX = 65504.0
FLOAT32_MAX = 3.4028234663852886e38
INT32_MAX = 2**31 - 1
# builtin_interfaces/Time holds sec as int32 and nanosec as uint32.
TIME_US_MIN = -(2**31) * 1_000_000
TIME_US_MAX_TO_ROS = INT32_MAX * 1_000_000 + 999_999  # the last microsecond a Time can hold
TIME_US_MAX_FROM_ROS = INT32_MAX * 1_000_000 + (2**32 - 1) // 1000  # nanosec may exceed 1e9 in a bad message

ValueRange = tuple[float, float]


# ---- value ranges ------------------------------------------------------------------------------------------


def dsdl_range(t: DsdlType) -> ValueRange | None:
    """Finite value range of a primitive DSDL scalar (None for bool).

    >>> dsdl_range(DsdlType("uint", 7)), dsdl_range(DsdlType("float", 16)), dsdl_range(DsdlType("bool", 1))
    ((0, 127), (-65504.0, 65504.0), None)
    """
    if t.kind in ("int", "uint", "byte"):
        return t.range
    if t.kind == "float":
        return {16: (-FLOAT16_MAX, FLOAT16_MAX), 32: (-FLOAT32_MAX, FLOAT32_MAX)}.get(t.bits, (-math.inf, math.inf))
    return None


def ros_range(base: str) -> ValueRange | None:
    """Value range of a ROS primitive (float64 unbounded, None for bool and strings).

    >>> ros_range("int8"), ros_range("float64"), ros_range("bool")
    ((-128, 127), (-inf, inf), None)
    """
    if base in ROS_INT_RANGES:
        return ROS_INT_RANGES[base]
    if base == "float32":
        return -FLOAT32_MAX, FLOAT32_MAX
    if base == "float64":
        return -math.inf, math.inf
    return None


def is_int_dsdl(t: DsdlType) -> bool:
    return t.kind in ("int", "uint", "byte")


def _bits(type_name: str) -> int:
    match = re.search(r"(\d+)$", type_name)
    return int(match[1]) if match else 0


def _is_int_name(type_name: str) -> bool:
    return bool(re.match(r"^u?int\d+$", type_name)) or type_name in ("byte", "char")


def width_change(src: str, dst: str) -> str:
    """How a scalar of type `src` becomes one of type `dst`: 'widened', 'narrowed', 'as float', 'rounded' or ''.

    >>> width_change("uint7", "uint8"), width_change("float64", "float16"), width_change("int16", "float32")
    ('widened', 'narrowed', 'as float')
    >>> width_change("float32", "int16"), width_change("uint8", "int8")
    ('rounded', '')
    """
    if src == dst:
        return ""
    if _is_int_name(src) and dst.startswith("float"):
        return "as float"
    if src.startswith("float") and _is_int_name(dst):
        return "rounded"
    if _bits(dst) > _bits(src):
        return "widened"
    if _bits(dst) < _bits(src):
        return "narrowed"
    return ""


# ---- operations ------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Convert:
    """The value changes representation (type names of the source and target element); `change` says how."""

    src: str
    dst: str

    @property
    def change(self) -> str:
        return width_change(self.src, self.dst)


@dataclass(frozen=True)
class Scale:
    """value * factor (UAVCAN -> ROS), value / factor (`inverse`, ROS -> UAVCAN); `factor` as the spec wrote it."""

    factor: float
    inverse: bool = False


@dataclass(frozen=True)
class Offset:
    """value + amount (UAVCAN -> ROS), value - amount (`inverse`, ROS -> UAVCAN); `amount` as the spec wrote it."""

    amount: float
    inverse: bool = False


@dataclass(frozen=True)
class RejectNaN:
    """A NaN drops the message (counted as rejected), whatever the policy."""


@dataclass(frozen=True)
class Limits:
    """The spec's `limits` (in ROS units): beyond them the value saturates or the message is rejected.

    `low` and `high` are compared (ints for an integer value, where whole); `declared` as the spec wrote them."""

    low: float
    high: float
    declared: tuple[Scalar, Scalar]
    reject: bool


ClampMode = Literal["integer", "round", "float16", "float32"]


@dataclass(frozen=True)
class Clamp:
    """Into the target's range; beyond it the value saturates to the bound or the message is rejected.

    - integer: checks `high` then `low`, each only where the value can pass it (None: cannot);
    - round: a float into an integer: rounded half to even, what rounds beyond [low, high] saturates;
    - float16: beyond +-65504, infinities included; NaN passes;
    - float32: finite values beyond +-FLOAT32_MAX; infinities and NaN are float32 values and pass.
    """

    mode: ClampMode
    low: float | None
    high: float | None
    reject: bool


@dataclass(frozen=True)
class Round:
    """A float into an integer known to be in range: rounded half to even, nothing to check."""


@dataclass(frozen=True)
class Table:
    """A lookup in the link's table; `inverse` (ROS -> UAVCAN) looks up the first key per value. A miss rejects
    the message, unless there is a `default` (UAVCAN -> ROS only)."""

    pairs: tuple[tuple[int, int], ...]  # (UAVCAN value, ROS value) as declared
    default: int | None
    inverse: bool

    def lookup(self) -> list[tuple[int, int]]:
        """(input, output) pairs in this direction.

        >>> Table(((0, 5), (1, 5), (2, 6)), None, True).lookup()
        [(5, 0), (6, 2)]
        """
        if not self.inverse:
            return list(self.pairs)
        inverse: dict[int, int] = {}
        for key, value in self.pairs:
            inverse.setdefault(value, key)  # first key per value
        return sorted(inverse.items())


@dataclass(frozen=True)
class TimestampToRos:
    """Microseconds (0 = unknown: the receive time) into builtin_interfaces/Time; beyond what Time holds
    (`high`, `low`: None where the source cannot reach) saturates to its limits or rejects."""

    high: int | None
    low: int | None
    reject: bool


@dataclass(frozen=True)
class TimestampFromRos:
    """builtin_interfaces/Time into microseconds; beyond the target integer's `high` / `low` (None: cannot happen)
    saturates or rejects."""

    high: int | None
    low: int | None
    reject: bool


@dataclass(frozen=True)
class DecodeUtf8:
    """UTF-8 bytes into a ROS string; invalid bytes are replaced."""


@dataclass(frozen=True)
class EncodeUtf8:
    """A ROS string into UTF-8 bytes (lone surrogates replaced)."""


@dataclass(frozen=True)
class Utf8Length:
    """Longer than `capacity` bytes: cut at a character boundary (saturate) or rejected."""

    capacity: int
    reject: bool


@dataclass(frozen=True)
class Pad:
    """A bounded UAVCAN array into a fixed ROS array: zeros (unknown) after the elements received."""

    size: int


@dataclass(frozen=True)
class FixedLength:
    """Into a fixed UAVCAN array: other lengths are padded with zeros or cut (saturate) or rejected."""

    size: int
    reject: bool


@dataclass(frozen=True)
class MaxLength:
    """Into a bounded UAVCAN array: elements beyond `capacity` are cut (saturate) or the message is rejected;
    `padded`: the source is a longer fixed ROS array whose zero padding beyond the bound is dropped silently."""

    capacity: int
    padded: bool
    reject: bool


@dataclass(frozen=True)
class SetConstant:
    """A field set to a value from the spec (`value` links; uavcan_values; DroneCAN's `select`)."""

    value: Scalar
    select: bool = False


@dataclass(frozen=True)
class StaticFrameId:
    """header.frame_id: the mapping's frame_id."""

    value: str


@dataclass(frozen=True)
class ReceiveTime:
    """header.stamp: the bridge's receive time (the UAVCAN type has no timestamp)."""


@dataclass(frozen=True)
class RequireItem:
    """DroneCAN: the item of the array with `key` must be present, else the message is not this mapping's
    (rejected under the item's path)."""

    array: tuple[PathSeg, ...]
    key: Key


@dataclass(frozen=True)
class RequireLength:
    """DroneCAN: the array must hold at least `length` elements (the mapping reads element length - 1)."""

    array: tuple[PathSeg, ...]
    length: int


@dataclass(frozen=True)
class Evaluate:
    """The value is an expression of source fields (model.expr's typed tree; its trunc()/round() check their own
    range with the link's policy); `as_float`: an int result stored into a float field. The checks after it
    (RejectNaN for a float result, Clamp into the target) follow as for any value."""

    tree: ENode
    as_float: bool


@dataclass(frozen=True)
class ElementMapping:
    """An array of composites converted element by element: `plan` is the element mapping's own plan (its links
    relative to one element, in the same direction); the array's length ops (MaxLength, FixedLength) follow it.
    An element whose conversion rejects drops the whole message; an element's ROS header is the message's."""

    plan: MappingPlan
    ros_element: str  # the ROS element message (pkg/Name)
    uavcan_element: str  # the UAVCAN element type's full name


Op = (Convert | Scale | Offset | RejectNaN | Limits | Clamp | Round | Table | TimestampToRos | TimestampFromRos
      | DecodeUtf8 | EncodeUtf8 | Utf8Length | Pad | FixedLength | MaxLength | SetConstant | Evaluate | ElementMapping)
EXPRESSION_OPS = (Convert, Scale, Offset)  # pure arithmetic on the value; everything else may drop or fix it
CHECK_OPS = (RejectNaN, Limits, Clamp, Round)


@dataclass(frozen=True)
class LinkPlan:
    """One link in one direction: its operations in the order they apply."""

    step: Step
    direction: PlanDirection
    key: str  # the stats key: "<mapping>.<ROS field>" to ROS, "<mapping>.<UAVCAN field>" to UAVCAN
    ops: tuple[Op, ...]
    reject: bool  # the mapping's on_out_of_range is "reject"

    @property
    def to_ros(self) -> bool:
        return self.direction == TO_ROS

    def has(self, *kinds: type) -> bool:
        return any(isinstance(op, kinds) for op in self.ops)

    def first(self, kind: type) -> Op | None:
        return next((op for op in self.ops if isinstance(op, kind)), None)


@dataclass(frozen=True)
class FieldSet:
    """A field a converter sets without reading the source (a constant, the frame id, the receive time)."""

    path: tuple[PathSeg, ...]
    type: DsdlType | RosType | None
    op: SetConstant | StaticFrameId | ReceiveTime


@dataclass(frozen=True)
class MappingPlan:
    name: str
    direction: str  # the mapping's: uavcan_to_ros | ros_to_uavcan
    reject: bool
    ros_fields: tuple[FieldSet, ...]  # UAVCAN -> ROS: the receive-time stamp, then header.frame_id
    to_ros: tuple[LinkPlan, ...]  # every link, `value` links included
    to_uavcan: tuple[LinkPlan, ...]  # the links with a UAVCAN field
    uavcan_fields: tuple[FieldSet, ...]  # ROS -> UAVCAN: uavcan_values, then DroneCAN's select
    required: tuple[RequireItem | RequireLength, ...]  # DroneCAN: elements a received message must have

    def links(self, direction: PlanDirection) -> tuple[LinkPlan, ...]:
        return self.to_ros if direction == TO_ROS else self.to_uavcan


# ---- lowering --------------------------------------------------------------------------------------------------


def range_ops(value_is_float: bool, value_range: ValueRange | None, target: DsdlType,
              limits: tuple[Scalar, Scalar] | None, reject: bool) -> list[Op]:
    """What makes a value acceptable to a DSDL scalar of type `target`, after the `limits` if any.

    `value_range` is the finite range the value is known to lie in (None: unknown); a float value may also be NaN
    or infinite. Nothing is planned for what cannot happen.

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
    if value_is_float and (integer or limits is not None):
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


def lower_expr(tree: ENode, target: DsdlType, reject: bool) -> list[Op]:
    """An expression into a target scalar: evaluated, a NaN result dropped, then into the target's range.

    >>> from sam_codegen.model.expr import EField
    >>> lower_expr(EField((("p", None),), "p", DsdlType("int", 7), "int", (-64, 63)), DsdlType("uint", 5), False)[1:]
    [Clamp(mode='integer', low=0, high=31, reject=False)]
    """
    as_float = target.kind == "float" and tree.kind == "int"
    ops: list[Op] = [Evaluate(tree, as_float)]
    if tree.kind == "bool":
        return ops
    if tree.kind == "float":
        ops.append(RejectNaN())
    ops += [op for op in range_ops(tree.kind == "float", tree.range, target, None, reject)
            if not isinstance(op, RejectNaN)]
    return ops


def _lower_to_ros(s: Step, reject: bool) -> list[Op]:
    if s.kind == "expr":
        if s.uavcan_path:  # a ROS -> UAVCAN expression: nothing to say towards ROS
            return []
        assert s.expr is not None
        return lower_expr(s.expr, expr_target(s.ros_type), reject)
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


def _lower_to_uavcan(s: Step, reject: bool) -> list[Op]:
    uav = s.uavcan_type
    assert uav is not None
    if s.kind == "expr":
        assert s.expr is not None
        return lower_expr(s.expr, uav, reject)
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
                *range_ops(value_is_float, value_range, uav, s.limits, reject)]
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
    return [*ops, *range_ops(value_is_float, value_range, elem, None, reject)]


def lower_link(step: Step, direction: PlanDirection, mapping: str, reject: bool) -> LinkPlan:
    """The operations of one link in one direction (`mapping`: the mapping's name, for the stats key)."""
    if step.kind == "elements":
        return lower_elements(step, direction, mapping, reject)
    if direction == TO_ROS:
        return LinkPlan(step, TO_ROS, f"{mapping}.{step.ros}", tuple(_lower_to_ros(step, reject)), reject)
    return LinkPlan(step, TO_UAVCAN, f"{mapping}.{step.uavcan}", tuple(_lower_to_uavcan(step, reject)), reject)


def lower_mapping(rm: ResolvedMapping) -> MappingPlan:
    """Both converters of a mapping, planned."""
    m = rm.mapping
    reject = m.on_out_of_range == "reject"
    ros_fields: list[FieldSet] = []
    if rm.has_header and not rm.stamp_from_source:
        ros_fields.append(FieldSet((("header", None), ("stamp", None)), RosType("builtin_interfaces/Time"),
                                   ReceiveTime()))
    if rm.has_header and m.frame_id is not None:
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
        to_uavcan=tuple(lower_link(s, TO_UAVCAN, m.name, reject) for s in rm.steps if s.uavcan_path),
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
