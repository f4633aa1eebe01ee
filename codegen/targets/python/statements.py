"""Conversion-plan operations as Python: literals, expressions and the statement dicts templates/python/statements.j2
renders (for convert.py, convert_v0.py and the wire codecs alike).

The plan (conversion_plan) has decided what happens to each value; this module only says it in Python: which
condition, which literal, which helper of conversion_support.py.j2.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

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
    dsdl_range,
    is_int_dsdl,
)
from sam_codegen.model.spec import Scalar
from sam_codegen.model.types import ROS_FLOAT_BITS, DsdlType


def py_literal(value: Scalar) -> str:
    """A Python literal; non-finite floats refer to the module constants _NAN and _INF of convert.py.

    >>> py_literal(1.0), py_literal(float("nan")), py_literal(-float("inf")), py_literal("a'b"), py_literal(2)
    ('1.0', '_NAN', '-_INF', '"a\\'b"', '2')
    """
    if isinstance(value, float):
        if math.isnan(value):
            return "_NAN"
        if math.isinf(value):
            return "_INF" if value > 0 else "-_INF"
    return repr(value)


def typed_literal(value: Scalar, base: str) -> str:
    """A literal of the Python type rclpy / pycyphal keep for a field of primitive type `base`.

    >>> typed_literal(0, "float32"), typed_literal(1, "bool"), typed_literal(7, "byte"), typed_literal(3.0, "int8")
    ('0.0', 'True', "b'\\\\x07'", '3')
    """
    if base in ROS_FLOAT_BITS or base.startswith("float"):
        return py_literal(float(value))
    if base == "bool":
        return py_literal(bool(value))
    if base == "byte":
        return repr(bytes((int(value),)))
    if base in ("string", "wstring"):
        return py_literal(str(value))
    return py_literal(int(value))


def dsdl_literal(value: Scalar, t: DsdlType) -> str:
    """A literal for a DSDL field of primitive type `t`."""
    return typed_literal(value, "float" if t.kind == "float" else t.kind)


_num = py_literal  # a numeric literal in generated code (ints stay ints)


# ---- statements ------------------------------------------------------------------------------------------------


def st(kind: str, **kw: Any) -> dict[str, Any]:
    """One statement for statements.j2's `statement` macro."""
    return {"kind": kind, **kw}


@dataclass
class Policy:
    key: str  # the stats key literal
    reject: bool  # on_out_of_range == "reject"


def bound_statement(var: str, checks: list[tuple[str, str]], policy: Policy, otherwise: str | None = None
                    ) -> dict[str, Any]:
    """if/elif chain: each (condition, saturated value) saturates or rejects; `otherwise` runs when none hit."""
    return st("bound", var=var, checks=checks, key=policy.key, reject=policy.reject, otherwise=otherwise)


def check_statements(var: str, ops: list[Op] | tuple[Op, ...], key: str) -> list[dict[str, Any]]:
    """The statements of the check operations (RejectNaN, Limits, Clamp, Round) among `ops`, on local `var`.

    >>> [s["kind"] for s in check_statements("v", [RejectNaN(), Clamp("round", 0, 255, False)], "'k'")]
    ['nan_reject', 'bound']
    >>> check_statements("v", [Clamp("float32", -1.0, 1.0, True)], "'k'")[0]["checks"]
    [('1.0 < v < _INF', '1.0'), ('-_INF < v < -1.0', '-1.0')]
    """
    out: list[dict[str, Any]] = []
    for op in ops:
        if isinstance(op, RejectNaN):
            out.append(st("nan_reject", var=var, key=key))
        elif isinstance(op, Round):
            out.append(st("assign", target=var, expr=f"round({var})"))
        elif isinstance(op, Limits):
            low, high = _num(op.low), _num(op.high)
            out.append(bound_statement(var, [(f"{var} < {low}", low), (f"{var} > {high}", high)],
                                       Policy(key, op.reject)))
        elif isinstance(op, Clamp):
            out.append(_clamp_statement(var, op, Policy(key, op.reject)))
    return out


def _clamp_statement(var: str, op: Clamp, policy: Policy) -> dict[str, Any]:
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


def array_check_helper(var: str, link: LinkPlan, elem: DsdlType) -> dict[str, Any] | None:
    """The conversion_support.py.j2 call that does a ROS -> UAVCAN array link's element checks, if it has any."""
    checks = [op for op in link.ops if isinstance(op, (RejectNaN, Round, Limits, Clamp))]
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
    return st("helper", var=var, helper=helper, args=args)


def float32_helper(var: str, link: LinkPlan) -> dict[str, Any]:
    """A UAVCAN -> ROS float32 array whose scaled values may pass FLOAT32_MAX."""
    return st("helper", var=var, helper="_support.clamp_finite_floats",
              args=[var, _num(FLOAT32_MAX), "stats", repr(link.key), str(link.reject)])


def timestamp_to_ros(op: TimestampToRos, us: str, read: str, sec: str, nanosec: str, key: str) -> dict[str, Any]:
    checks = []
    if op.high is not None:
        checks.append((f"{us} > {op.high}", str(INT32_MAX), "999_999_999"))
    if op.low is not None:
        checks.append((f"{us} < {op.low}", str(-(2**31)), "0"))
    return st("time_to_ros", us=us, read=read, sec=sec, nanosec=nanosec, checks=checks, key=key, reject=op.reject)


def timestamp_from_ros(op: TimestampFromRos, var: str, us: str, key: str) -> list[dict[str, Any]]:
    """`var` = the microseconds expression `us`, then the target integer's bounds."""
    out = [st("assign", target=var, expr=us)]
    checks = []
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
