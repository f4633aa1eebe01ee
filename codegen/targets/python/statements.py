"""Conversion-plan operations as Python: the typed statements templates/python/statements.j2 renders (for convert.py,
convert_v0.py and the wire codecs alike), and the expressions and literals inside them.

The plan (conversion_plan) has decided what happens to each value; this module only says it in Python: which
condition, which literal, which helper of conversion_support.py.j2.

Invariants: a statement is a frozen value (the emitters build lists of them and never change one); its fields are
pieces of Python code (expressions, names, literals), never spec text that is not a literal yet; each class has a
`kind`, the name of its branch in statements.j2's `statement` macro, and renders at function-body indentation.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from sam_codegen.conversion_plan import (
    FLOAT32_MAX,
    INT32_MAX,
    Clamp,
    Convert,
    Limits,
    LinkPlan,
    Offset,
    Op,
    RejectNaN,
    Round,
    Scale,
    TimestampFromRos,
    TimestampToRos,
    Wrap,
    dsdl_range,
    is_int_dsdl,
)
from sam_codegen.model.spec import Scalar
from sam_codegen.model.text import cut_utf8_expr
from sam_codegen.model.types import DsdlType
from sam_codegen.render.pysource import py_literal, typed_literal

__all__ = ["Assign", "Bound", "CutToMaxLength", "CutUtf8", "FindItem", "FixLength", "HelperCall", "NanReject",
           "PadArray", "Policy", "RequireMinLength", "Statement", "TableLookup", "TimeToRos", "array_check_helper",
           "array_nan_helper",
           "bound_statement", "check_statements", "dsdl_literal", "float32_helper", "timestamp_from_ros",
           "timestamp_to_ros", "to_ros_expr", "to_uavcan_expr"]


def dsdl_literal(value: Scalar, t: DsdlType) -> str:
    """A literal for a DSDL field of primitive type `t`."""
    return typed_literal(value, "float" if t.kind == "float" else t.kind)


_num = py_literal  # a numeric literal in generated code (ints stay ints)


# ---- statements ------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Statement:
    """One statement of a generated function body."""

    kind: ClassVar[str]


@dataclass(frozen=True)
class Assign(Statement):
    kind: ClassVar[str] = "assign"
    target: str
    expr: str


@dataclass(frozen=True)
class NanReject(Statement):
    """Drop the message when `var` is NaN (it cannot become an integer)."""

    kind: ClassVar[str] = "nan_reject"
    var: str
    key: str


@dataclass(frozen=True)
class Bound(Statement):
    """if/elif chain: each (condition, saturated value) saturates or rejects; `otherwise` runs when none hit."""

    kind: ClassVar[str] = "bound"
    var: str
    checks: tuple[tuple[str, str], ...]
    key: str
    reject: bool
    otherwise: str | None = None


@dataclass(frozen=True)
class TableLookup(Statement):
    """`var` = the table's value for `read`: `default` when missing, else the message is dropped."""

    kind: ClassVar[str] = "table"
    var: str
    table: str
    read: str
    key: str
    default: str | None


@dataclass(frozen=True)
class TimeToRos(Statement):
    """A UAVCAN microsecond timestamp `read` -> builtin_interfaces/Time locals `sec` and `nanosec` (0: the receive
    time); `checks` are (condition, saturated sec, saturated nanosec)."""

    kind: ClassVar[str] = "time_to_ros"
    us: str
    read: str
    sec: str
    nanosec: str
    checks: tuple[tuple[str, str, str], ...]
    key: str
    reject: bool


@dataclass(frozen=True)
class PadArray(Statement):
    kind: ClassVar[str] = "pad"
    var: str
    size: int
    zero: str


@dataclass(frozen=True)
class HelperCall(Statement):
    """`var` = a conversion_support helper's result; None drops the message."""

    kind: ClassVar[str] = "helper"
    var: str
    helper: str
    args: tuple[str, ...]


@dataclass(frozen=True)
class FixLength(Statement):
    """A list for a fixed-size array: padded with `zero` or cut to `cap` (counted)."""

    kind: ClassVar[str] = "fixed_length"
    var: str
    cap: int
    zero: str
    key: str
    reject: bool


@dataclass(frozen=True)
class CutToMaxLength(Statement):
    """A list for a bounded array cut to `cap` (counted); `padded`: only zero elements may go."""

    kind: ClassVar[str] = "max_length"
    var: str
    cap: int
    key: str
    reject: bool
    padded: bool


@dataclass(frozen=True)
class CutUtf8(Statement):
    """UTF-8 bytes cut to `cap` at a character boundary (counted)."""

    kind: ClassVar[str] = "utf8_length"
    var: str
    cap: int
    key: str
    reject: bool

    @property
    def cut(self) -> str:
        """The cut, as the bridge's service mappings make it too (one rule: sam_codegen.model.text)."""
        return cut_utf8_expr(self.var, self.cap)


@dataclass(frozen=True)
class RequireMinLength(Statement):
    """Drop the message when the list `var` has fewer than `size` elements."""

    kind: ClassVar[str] = "min_length"
    var: str
    size: int
    key: str


@dataclass(frozen=True)
class FindItem(Statement):
    """`var` = the first item of `array` whose `field` (attribute name or record position) is `value`, or drop."""

    kind: ClassVar[str] = "required_item"
    var: str
    array: str
    field: str
    value: str
    key: str


@dataclass(frozen=True)
class Policy:
    key: str  # the stats key literal
    reject: bool  # on_out_of_range == "reject"


def bound_statement(var: str, checks: list[tuple[str, str]], policy: Policy, otherwise: str | None = None) -> Bound:
    return Bound(var, tuple(checks), policy.key, policy.reject, otherwise)


def check_statements(var: str, ops: list[Op] | tuple[Op, ...], key: str) -> list[Statement]:
    """The statements of the check operations (RejectNaN, Limits, Clamp, Round) among `ops`, on local `var`.

    >>> [type(s).__name__ for s in check_statements("v", [RejectNaN(), Clamp("round", 0, 255, False)], "'k'")]
    ['NanReject', 'Bound']
    >>> check_statements("v", [Clamp("float32", -1.0, 1.0, True)], "'k'")[0].checks
    (('1.0 < v < _INF', '1.0'), ('-_INF < v < -1.0', '-1.0'))
    """
    out: list[Statement] = []
    for op in ops:
        if isinstance(op, RejectNaN):
            out.append(NanReject(var, key))
        elif isinstance(op, Round):
            out.append(Assign(var, f"round({var})"))
        elif isinstance(op, Limits):
            low, high = _num(op.low), _num(op.high)
            out.append(bound_statement(var, [(f"{var} < {low}", low), (f"{var} > {high}", high)],
                                       Policy(key, op.reject)))
        elif isinstance(op, Clamp):
            out.append(_clamp_statement(var, op, Policy(key, op.reject)))
        elif isinstance(op, Wrap):
            out.append(Assign(var, wrap_expr(var, op)))
    return out


def wrap_expr(var: str, op: Wrap) -> str:
    """`var` (an int) modulo 2**bits, two's complement for a signed target, as C stores it.

    >>> wrap_expr("v", Wrap(8, False)), wrap_expr("v", Wrap(18, True))
    ('v & 255', '((v + 131072) & 262143) - 131072')
    """
    mask = (1 << op.bits) - 1
    if not op.signed:
        return f"{var} & {mask}"
    half = 1 << (op.bits - 1)
    return f"(({var} + {half}) & {mask}) - {half}"


def _clamp_statement(var: str, op: Clamp, policy: Policy) -> Bound:
    lo, hi = op.low, op.high
    if op.mode == "round":
        assert lo is not None and hi is not None
        checks = [(f"{var} >= {_num(hi + 0.5)}", _num(hi)), (f"{var} <= {_num(lo - 0.5)}", _num(lo))]
        return bound_statement(var, checks, policy, otherwise=f"{var} = round({var})")
    if op.mode == "integer":
        checks = [] if hi is None else [(f"{var} > {_num(hi)}", _num(hi))]
        return bound_statement(var, checks + ([] if lo is None else [(f"{var} < {_num(lo)}", _num(lo))]), policy)
    if op.mode == "float16":
        return bound_statement(var, [(f"{var} > {_num(hi)}", _num(hi)), (f"{var} < {_num(lo)}", _num(lo))], policy)
    return bound_statement(var, [(f"{_num(hi)} < {var} < _INF", _num(hi)), (f"-_INF < {var} < {_num(lo)}", _num(lo))],
                           policy)


def array_check_helper(var: str, link: LinkPlan, elem: DsdlType) -> HelperCall | None:
    """The conversion_support.py.j2 call that does a ROS -> UAVCAN array link's element checks, if it has any."""
    checks = [op for op in link.ops if isinstance(op, (RejectNaN, Round, Limits, Clamp))]
    if elem.kind == "float":  # NaN is array_nan_helper's
        checks = [op for op in checks if not isinstance(op, RejectNaN)]
    if not checks:
        return None
    key, reject = repr(link.key), str(link.reject)
    if is_int_dsdl(elem):
        lo, hi = elem.range
        helper = "_support.round_ints" if any(isinstance(op, RejectNaN) for op in checks) else "_support.clamp_ints"
        args = [var, str(lo), str(hi), "stats", key, reject]
    else:  # float16 saturates infinities too, float32 keeps them (as for scalars)
        helper = "_support.clamp_floats" if elem.bits == 16 else "_support.clamp_finite_floats"
        args = [var, _num(dsdl_range(elem)[1]), "stats", key, reject]  # type: ignore[index]
    return HelperCall(var, helper, tuple(args))


def array_nan_helper(var: str, link: LinkPlan, elem: DsdlType) -> HelperCall | None:
    """The call that rejects a ROS -> UAVCAN float array holding a NaN, when the link rejects NaN (a command)."""
    if elem.kind != "float" or not any(isinstance(op, RejectNaN) for op in link.ops):
        return None
    return HelperCall(var, "_support.reject_nan_floats", (var, "stats", repr(link.key)))


def float32_helper(var: str, link: LinkPlan) -> HelperCall:
    """A UAVCAN -> ROS float32 array whose scaled values may pass FLOAT32_MAX."""
    return HelperCall(var, "_support.clamp_finite_floats",
                      (var, _num(FLOAT32_MAX), "stats", repr(link.key), str(link.reject)))


def timestamp_to_ros(op: TimestampToRos, us: str, read: str, sec: str, nanosec: str, key: str) -> TimeToRos:
    checks: list[tuple[str, str, str]] = []
    if op.high is not None:
        checks.append((f"{us} > {op.high}", str(INT32_MAX), "999_999_999"))
    if op.low is not None:
        checks.append((f"{us} < {op.low}", str(-(2**31)), "0"))
    return TimeToRos(us, read, sec, nanosec, tuple(checks), key, op.reject)


def timestamp_from_ros(op: TimestampFromRos, var: str, us: str, key: str) -> list[Statement]:
    """`var` = the microseconds expression `us`, then the target integer's bounds."""
    out: list[Statement] = [Assign(var, us)]
    checks: list[tuple[str, str]] = []
    if op.high is not None:
        checks.append((f"{var} > {op.high}", str(op.high)))
    if op.low is not None:
        checks.append((f"{var} < {op.low}", str(op.low)))
    if checks:
        out.append(bound_statement(var, checks, Policy(key, op.reject)))
    return out


# ---- expressions -----------------------------------------------------------------------------------------------


def to_ros_expr(x: str, ops: tuple[Op, ...], ros_base: str) -> str:
    """A UAVCAN-side element expression `x` through a UAVCAN -> ROS link's arithmetic.

    >>> to_ros_expr("v", (Scale(0.5), Offset(-273.15)), "float32")
    'v * 0.5 - 273.15'
    >>> to_ros_expr("v", (Convert("int16", "float64"),), "float64"), to_ros_expr("v", (), "byte")
    ('float(v)', 'bytes((v,))')
    """
    text = x
    transformed = False
    for op in ops:
        if isinstance(op, Scale):
            text, transformed = f"{text} * {_num(float(op.factor))}", True
        elif isinstance(op, Offset):
            off = float(op.amount)
            text = f"{text} + {_num(off)}" if off >= 0 else f"{text} - {_num(-off)}"
            transformed = True
    if not transformed:
        if any(isinstance(op, Convert) and op.change == "as float" for op in ops):
            text = f"float({x})"
        elif ros_base == "byte":  # rclpy keeps a byte as a bytes object of length 1
            text = f"bytes(({x},))"
    return text


def to_uavcan_expr(x: str, ops: tuple[Op, ...] | list[Op]) -> str:
    """A ROS-side element expression `x` through a ROS -> UAVCAN link's inverse arithmetic (x read as a number).

    >>> to_uavcan_expr("v", [Offset(-273.15, True), Scale(0.5, True)]), to_uavcan_expr("v", [Scale(2.0, True)])
    ('(v + 273.15) / 0.5', 'v / 2.0')
    """
    text, offset = x, False
    for op in ops:
        if isinstance(op, Offset):
            off = float(op.amount)
            text, offset = (f"{text} - {_num(off)}" if off >= 0 else f"{text} + {_num(-off)}"), True
        elif isinstance(op, Scale):
            scale = _num(float(op.factor))
            text = f"({text}) / {scale}" if offset else f"{text} / {scale}"
    return text
