"""The document's conversion rules (section IV.B) as pure functions.

- a variable-size UAVCAN integer maps to the next larger ROS integer (uint7 -> uint8, int18 -> int32);
- float16 maps to float32; a bounded array keeps its bound;
- a microsecond timestamp maps to builtin_interfaces/Time (0 means unknown);
and the checks that a ROS field can hold every value of the UAVCAN field it is linked to.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from sam_codegen.model.diagnostics import NOWHERE, Pos
from sam_codegen.model.expr import ENode
from sam_codegen.model.spec import Constant, DsdlStruct, Field, FieldLink, Mapping, RosMessage, Scalar
from sam_codegen.model.types import (
    ROS_FLOAT_BITS,
    ROS_INT_RANGES,
    ROS_SIGNED_INTS,
    ROS_UNSIGNED_INTS,
    DsdlType,
    RosType,
)

TIME = "builtin_interfaces/Time"
HEADER = "std_msgs/Header"
SYNC_TIMESTAMP = "uavcan.time.SynchronizedTimestamp.1.0"
V0_TIMESTAMP = "uavcan.Timestamp"
# The microsecond timestamps (0 = unknown) of both protocols: type -> its microsecond field (truncated uint56).
TIMESTAMPS = {SYNC_TIMESTAMP: "microsecond", V0_TIMESTAMP: "usec"}
FLOAT16_MAX = 65504.0


@dataclass(frozen=True)
class Key:
    """`[field=value]` in a DroneCAN path: the item of an array of composites whose `field` equals `value` (the
    `actuator_id` of uavcan.equipment.actuator.Command in ArrayCommand.commands)."""

    field: str
    value: int

    def __str__(self) -> str:
        return f"{self.field}={self.value}"


PathSeg = tuple[str, "int | Key | None"]
_SEGMENT = re.compile(
    r"^(?P<name>[A-Za-z_][A-Za-z0-9_]*)"
    r"(?:\[(?:(?P<index>[0-9]+)|(?P<key>[A-Za-z_][A-Za-z0-9_]*)=(?P<value>-?[0-9]+))\])?$"
)


class RuleError(ValueError):
    """A mapping line breaks a rule; the message says which and what was expected."""


def parse_path(text: str) -> list[PathSeg]:
    """`a.b[2].c` -> [("a", None), ("b", 2), ("c", None)]; `commands[actuator_id=3]` selects an item by key.

    >>> parse_path("linear_acceleration.x"), parse_path("rate_gyro_latest[0]")
    ([('linear_acceleration', None), ('x', None)], [('rate_gyro_latest', 0)])
    >>> format_path(parse_path("commands[actuator_id=3].command_value"))
    'commands[actuator_id=3].command_value'
    """
    segments: list[PathSeg] = []
    for part in text.split("."):
        match = _SEGMENT.fullmatch(part)
        if not match:
            raise RuleError(f"{text!r} is not a field path (name, name.sub, name[index] or name[key=value])")
        if match["key"] is not None:
            segments.append((match["name"], Key(match["key"], int(match["value"]))))
        else:
            segments.append((match["name"], int(match["index"]) if match["index"] is not None else None))
    return segments


def format_path(path: list[PathSeg]) -> str:
    return ".".join(name if index is None else f"{name}[{index}]" for name, index in path)


def widen_int(kind: str, bits: int) -> str:
    """The ROS integer a UAVCAN integer maps to: the next size that holds it.

    >>> [widen_int(k, b) for k, b in (("uint", 7), ("int", 13), ("int", 18), ("uint", 24), ("uint", 8))]
    ['uint8', 'int16', 'int32', 'uint32', 'uint8']
    """
    names = ROS_SIGNED_INTS if kind == "int" else ROS_UNSIGNED_INTS
    return next(name for name in names if int(name.lstrip("uint")) >= bits)


def derive_ros_type(t: DsdlType) -> RosType:
    """The ROS type a UAVCAN field becomes in a derived message.

    >>> str(derive_ros_type(DsdlType("float", 16, array="bounded", capacity=36)))
    'float32[<=36]'
    >>> str(derive_ros_type(DsdlType("int", 18)))
    'int32'
    """
    if t.kind == "bool":
        base = "bool"
    elif t.kind in ("int", "uint"):
        base = widen_int(t.kind, t.bits)
    elif t.kind == "byte":
        base = "uint8"
    elif t.kind == "float":
        base = "float64" if t.bits == 64 else "float32"
    elif t.kind == "utf8":
        return RosType("string", string_bound=t.capacity)
    elif t.kind == "composite" and t.composite in TIMESTAMPS and not t.array:
        base = TIME
    else:
        raise RuleError(f"a {t} field cannot be derived automatically; declare the ROS message by hand")
    return RosType(base, t.array, t.capacity)


def _is_sync_timestamp(t: DsdlType) -> bool:
    """A microsecond timestamp of either protocol (a scalar field)."""
    return t.kind == "composite" and t.composite in TIMESTAMPS and not t.array


def derive_message(struct: DsdlStruct, package: str, name: str, description: str, pos: Pos) -> RosMessage:
    """A ROS message derived from a DSDL type: a header, then every field widened; constants kept."""
    has_stamp = any(isinstance(f.type, DsdlType) and _is_sync_timestamp(f.type) for f in struct.fields)
    stamp = ("Stamp from the device's timestamp (the receive time when it is 0)." if has_stamp
             else "Stamp: the bridge's receive time (the UAVCAN type has no timestamp).")
    fields = [Field("header", RosType(HEADER), stamp, pos)]
    stamp_taken = False
    for f in struct.fields:
        assert isinstance(f.type, DsdlType)
        if _is_sync_timestamp(f.type) and not stamp_taken:
            stamp_taken = True  # it becomes header.stamp
            continue
        try:
            fields.append(Field(f.name, derive_ros_type(f.type), f.comment, pos))
        except RuleError as exc:
            raise RuleError(f"cannot derive {package}/{name} from {struct.name}: field {f.name!r}: {exc}") from None
    constants = []
    for c in struct.constants:
        assert isinstance(c.type, DsdlType)
        constants.append(Constant(c.name, derive_ros_type(c.type), c.value, c.comment, pos))
    return RosMessage(package, name, fields, constants, description or struct.description, struct.name, pos=pos)


def auto_links(struct: DsdlStruct, pos: Pos) -> list[FieldLink]:
    """The links of `fields: auto`: by name, the first synchronized timestamp into header.stamp."""
    links = []
    stamp_taken = False
    for f in struct.fields:
        assert isinstance(f.type, DsdlType)
        if _is_sync_timestamp(f.type) and not stamp_taken:
            stamp_taken = True
            links.append(FieldLink("header.stamp", f"{f.name}.{TIMESTAMPS[f.type.composite or '']}", pos=pos))
        else:
            links.append(FieldLink(f.name, f.name, pos=pos))
    return links


@dataclass(frozen=True)
class Step:
    """One resolved link, ready for an emitter. Paths are relative to the ROS / UAVCAN message."""

    kind: str  # number | array | time | table | value | string | expr
    ros_path: tuple[PathSeg, ...]
    ros_type: RosType
    uavcan_path: tuple[PathSeg, ...] = ()
    uavcan_type: DsdlType | None = None
    scale: float | None = None
    offset: float | None = None
    table: tuple[tuple[int, int], ...] = ()
    table_default: int | None = None  # UAVCAN -> ROS: the ROS value of every key the table does not list
    value: Scalar | None = None
    limits: tuple[float, float] | None = None
    exact: bool = True  # UAVCAN -> ROS -> UAVCAN gives the value back
    pos: Pos = NOWHERE
    # kind `expr`: the typed expression (model.expr) computing the target from source fields. To ROS: ros_path is
    # the target, uavcan_path empty; to UAVCAN (uavcan_exprs): uavcan_path the target, ros_path empty.
    expr: ENode | None = None
    elements: ResolvedMapping | None = None  # kind "elements": the element mapping (validate.element_mappings)
    wrap: bool = False  # `on_out_of_range: wrap` on the line: an integer beyond the target stored modulo 2**bits

    @property
    def ros(self) -> str:
        return format_path(list(self.ros_path))

    @property
    def uavcan(self) -> str:
        return format_path(list(self.uavcan_path))


@dataclass(frozen=True)
class ResolvedMapping:
    """A mapping checked against both types: built whole by validation, never changed after."""

    mapping: Mapping
    ros_message: RosMessage
    dsdl_struct: DsdlStruct
    steps: list[Step] = field(default_factory=list)
    uavcan_values: list[tuple[tuple[PathSeg, ...], DsdlType, Scalar]] = field(default_factory=list)
    has_header: bool = False
    rate_hz: float = 0.0
    # DroneCAN: the fields a message must have to be this mapping's (UAVCAN->ROS), or that it sets (ROS->UAVCAN)
    select: list[tuple[tuple[PathSeg, ...], DsdlType, Scalar]] = field(default_factory=list)
    # DroneCAN arrays of which the mapping names elements: array path -> positions (int) or items (Key), in order
    elements: dict[tuple[PathSeg, ...], list] = field(default_factory=dict)

    @property
    def stamp_from_source(self) -> bool:
        return any(s.kind == "time" and s.ros == "header.stamp" for s in self.steps)


def _int_holds(ros_base: str, lo: int, hi: int) -> bool:
    ros_lo, ros_hi = ROS_INT_RANGES[ros_base]
    return ros_lo <= lo and hi <= ros_hi


def check_scalar(ros: RosType, uav: DsdlType, link: FieldLink) -> tuple[str, bool]:
    """Check one scalar pair; returns (step kind, exact round trip). Raises RuleError."""
    ros_base = ros.base
    transformed = link.scale is not None or link.offset is not None
    if link.round and (uav.kind != "float" or ros_base not in ROS_INT_RANGES or link.table is not None):
        raise RuleError(f"`round` takes a UAVCAN float into a ROS integer, not {uav.base_name} into {ros_base}")
    if link.table is not None:
        if uav.kind not in ("int", "uint") or ros_base not in ROS_INT_RANGES:
            raise RuleError(f"a table maps integers to integers, not {uav} to {ros_base}")
        lo, hi = uav.range
        ros_lo, ros_hi = ROS_INT_RANGES[ros_base]
        for key, value in link.table.items():
            if not lo <= key <= hi:
                raise RuleError(f"table key {key} is outside the range of {uav} [{lo}, {hi}]")
            if not ros_lo <= value <= ros_hi:
                raise RuleError(f"table value {value} is outside the range of {ros_base}")
        if link.table_default is not None and not ros_lo <= link.table_default <= ros_hi:
            raise RuleError(f"table default {link.table_default} is outside the range of {ros_base}")
        injective = len(set(link.table.values())) == len(link.table)
        return "table", injective and len(link.table) == hi - lo + 1
    if uav.kind == "bool":
        if ros_base != "bool" or transformed:
            raise RuleError(f"a UAVCAN bool maps to a ROS bool, not {ros_base}")
        return "number", True
    if ros_base == "bool":
        raise RuleError(f"a ROS bool receives a UAVCAN bool, not {uav}")
    if uav.kind in ("int", "uint", "byte"):
        lo, hi = uav.range
        if ros_base in ROS_INT_RANGES:
            if transformed:
                raise RuleError(f"scale/offset give fractions: {uav} with a scale needs a float ROS field, "
                                f"not {ros_base}")
            if not _int_holds(ros_base, lo, hi):
                raise RuleError(
                    f"ROS {ros_base} is narrower than the UAVCAN {uav.base_name} it receives (range [{lo}, {hi}]); "
                    f"expected {widen_int(uav.kind if uav.kind != 'byte' else 'uint', uav.bits)} or wider"
                )
            return "number", True
        if ros_base in ROS_FLOAT_BITS:
            mantissa = 24 if ros_base == "float32" else 53
            exact = max(abs(lo), abs(hi)) <= 2**mantissa
            if not exact and not transformed:
                raise RuleError(f"ROS {ros_base} cannot hold every {uav.base_name} exactly; expected a wider type")
            if transformed:
                # v * scale + offset is off by up to 2^-(mantissa-1) of its size; back in UAVCAN units the error
                # must stay below the half step that round() absorbs.
                reach = max(abs(lo), abs(hi)) + abs((link.offset or 0.0) / (link.scale or 1.0))
                exact = reach < 2 ** (mantissa - 2)
            return "number", exact
        raise RuleError(f"a UAVCAN {uav.base_name} cannot map to ROS {ros_base}")
    if uav.kind == "float" and link.round:
        # rounded half to even; NaN is rejected and values beyond the integer saturate (counted)
        return "number", False
    if uav.kind == "float":
        if ros_base not in ROS_FLOAT_BITS:
            raise RuleError(f"a UAVCAN {uav.base_name} maps to a ROS float, not {ros_base}"
                            + (" (or to an integer with `round: true`)" if ros_base in ROS_INT_RANGES else ""))
        if ROS_FLOAT_BITS[ros_base] < uav.bits:
            expected = "float32" if uav.bits <= 32 else "float64"
            raise RuleError(f"ROS {ros_base} is narrower than the UAVCAN {uav.base_name} it receives; "
                            f"expected {expected} or wider")
        # An offset moves small values onto a coarser grid (0.001 K - 273.15 loses the 0.001); a scale costs one
        # rounding, harmless only when the ROS float has at least two more mantissa bits than the UAVCAN one.
        mantissas = {16: 11, 32: 24, 64: 53}
        exact = link.offset is None and (
            link.scale is None or mantissas[ROS_FLOAT_BITS[ros_base]] >= mantissas.get(uav.bits, 53) + 2)
        return "number", exact
    raise RuleError(f"UAVCAN {uav} cannot be linked to a ROS field")


def missing_table_keys(uav: DsdlType, keys: set[int], shown: int = 5) -> tuple[int, list[int]]:
    """How many values of the integer type `uav` are not among `keys`, and the first `shown` of them.

    >>> missing_table_keys(DsdlType("uint", 2), {0, 1})
    (2, [2, 3])
    >>> missing_table_keys(DsdlType("int", 16), {0}, 3)
    (65535, [-32768, -32767, -32766])
    """
    lo, hi = uav.range
    count = hi - lo + 1 - sum(1 for k in keys if lo <= k <= hi)
    first: list[int] = []
    value = lo
    while len(first) < min(shown, count):
        if value not in keys:
            first.append(value)
        value += 1
    return count, first


def check_string(ros: RosType, uav: DsdlType, link: FieldLink, v0: bool = False) -> bool:
    """Check a UAVCAN utf8[<=N] / ROS string pair (step kind `string`); returns whether the round trip is exact.
    `v0`: a DroneCAN mapping, whose text is uint8[<=N] (v0 DSDL has no utf8), e.g. Panic's reason_text."""
    text = v0 and uav.kind == "uint" and uav.bits == 8  # the same bytes as utf8: what v0 firmware sends as text
    if not (uav.kind == "utf8" or text) or uav.array != "bounded" or ros.base != "string" or ros.array:
        what = "a DroneCAN uint8[<=N]" if v0 else "a UAVCAN utf8[<=N]"
        raise RuleError(f"{what} maps to a ROS string, not {uav} to {ros}")
    if link.scale is not None or link.offset is not None or link.table is not None or link.limits is not None:
        raise RuleError("scale, offset, table and limits do not apply to strings")
    if ros.string_bound is not None and ros.string_bound < (uav.capacity or 0):
        raise RuleError(f"ROS {ros} is shorter than UAVCAN {uav}; expected string<={uav.capacity} or unbounded")
    return True  # for valid UTF-8 without NUL (which ends a ROS string); invalid bytes are replaced


def check_arrays(ros: RosType, uav: DsdlType, link: FieldLink) -> bool:
    """Check an array pair; returns whether the round trip is exact (it is not when padding hides a length)."""
    if link.table is not None:
        raise RuleError("a table applies to scalars, not arrays")
    if link.round:
        raise RuleError("`round` applies to scalars, not arrays")
    if not ros.array:
        raise RuleError(f"ROS field {ros} is not an array but UAVCAN {uav} is")
    if not uav.array:
        raise RuleError(f"UAVCAN field {uav} is not an array but ROS {ros} is")
    check_scalar(ros.element, uav.element, link)
    if ros.array == "fixed":
        if uav.array == "fixed" and uav.capacity != ros.capacity:
            raise RuleError(f"fixed arrays differ in size: ROS {ros.capacity}, UAVCAN {uav.capacity}")
        if uav.array == "bounded" and (uav.capacity or 0) > (ros.capacity or 0):
            raise RuleError(f"UAVCAN {uav} holds more elements than ROS {ros}")
        return uav.array == "fixed"
    if ros.array == "bounded" and (ros.capacity or 0) < (uav.capacity or 0):
        raise RuleError(f"ROS {ros} is shorter than UAVCAN {uav}; a bounded array keeps its bound")
    return True


def wrap_problem(step: Step, to_ros: bool) -> str | None:
    """Why a line's `on_out_of_range: wrap` cannot apply to `step` (its target written `to_ros` or to UAVCAN),
    None when it can (or the line does not wrap). Wrap stores an integer modulo 2**bits of an integer target, as C
    does; it needs an integer value (an integer field as it is, or an `expr` of integer result) that can pass the
    target's range."""
    if not step.wrap:
        return None
    target = step.ros_type if to_ros else step.uavcan_type
    if isinstance(target, RosType):
        target_range = None if target.array else ROS_INT_RANGES.get(target.base)
        if target.base in ("byte", "char"):
            target_range = None
    else:
        target_range = (None if target is None or target.array or target.kind not in ("int", "uint")
                        else (int(target.range[0]), int(target.range[1])))
    if target_range is None:
        return f"on_out_of_range: wrap stores an integer modulo 2**bits; {target} is no integer scalar"
    if step.kind == "expr" and step.expr is not None:
        if step.expr.kind != "int":
            return (f"on_out_of_range: wrap takes an integer value; the expression gives a {step.expr.kind} "
                    "(write trunc() or round())")
        value_range = step.expr.range or (-(2**63), 2**63 - 1)
    elif step.kind == "number" and step.scale is None and step.offset is None:
        source = step.uavcan_type if to_ros else step.ros_type
        if isinstance(source, RosType):
            value_range = ROS_INT_RANGES.get(source.base)  # type: ignore[assignment]
        else:
            value_range = (None if source is None or source.kind not in ("int", "uint")  # type: ignore[assignment]
                           else (int(source.range[0]), int(source.range[1])))
        if value_range is None:
            return f"on_out_of_range: wrap takes an integer value; {source} is not an integer (a float needs an expr " \
                   "with trunc() or round())"
    else:
        return (f"on_out_of_range: wrap applies to an integer field as it is or an `expr`, not to a line with "
                f"{'scale or offset' if step.kind == 'number' else step.kind}")
    lo, hi = int(value_range[0]), int(value_range[1])
    if target_range[0] <= lo and hi <= target_range[1]:
        return f"on_out_of_range: wrap has nothing to wrap: the value ({lo}..{hi}) always fits {target}"
    return None
