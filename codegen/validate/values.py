"""Checks shared by the validators: id ranges, names the converters can use, and literal values against a type."""

from __future__ import annotations

import keyword
import math

from sam_codegen.model.diagnostics import Diagnostics, Pos
from sam_codegen.model.spec import Scalar
from sam_codegen.model.types import ROS_FLOAT_BITS, ROS_INT_RANGES, DsdlType, RosType

CAN_NODE_IDS = range(0, 128)
SUBJECT_IDS = range(0, 8192)


def python_safe(name: str) -> bool:
    """Whether a name can be a Python attribute as it is.

    >>> python_safe("rpm"), python_safe("class"), python_safe("match")
    (True, False, False)
    """
    # Generated converters use names as Python attributes; keywords would be mangled differently per generator.
    return not keyword.iskeyword(name) and not keyword.issoftkeyword(name)


def check_ros_value(diag: Diagnostics, t: RosType, value: Scalar, pos: Pos, what: str) -> None:
    """Report `value` unless it is a literal of the primitive ROS type `t`."""
    base = t.base
    if base in ROS_INT_RANGES:
        lo, hi = ROS_INT_RANGES[base]
        if isinstance(value, bool) or not isinstance(value, int) or not lo <= value <= hi:
            diag.error(pos, f"{what} = {value!r} does not fit {base}", f"an integer in [{lo}, {hi}]")
    elif base in ROS_FLOAT_BITS:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            diag.error(pos, f"{what} = {value!r} is not a number", f"a {base}")
    elif base == "bool":
        if not isinstance(value, bool):
            diag.error(pos, f"{what} = {value!r} is not a bool", "true or false")
    elif base in ("string", "wstring"):
        if not isinstance(value, str):
            diag.error(pos, f"{what} = {value!r} is not a string")
        elif t.string_bound is not None and len(value) > t.string_bound:
            diag.error(pos, f"{what} is longer than its bound {t.string_bound}")


def check_dsdl_value(diag: Diagnostics, t: DsdlType, value: Scalar, pos: Pos, what: str, v0: bool = False) -> None:
    """Report `value` unless it is a literal of the primitive scalar DSDL type `t` (`v0`: a DSDL v0 type, whose
    bool constants may also be written 0 or 1; the frontend has already turned those into bools)."""
    if t.array or t.kind in ("composite", "void", "utf8"):
        diag.error(pos, f"{what} must have a primitive scalar type, not {t}")
    elif t.kind in ("int", "uint", "byte"):
        lo, hi = t.range
        if isinstance(value, bool) or not isinstance(value, int) or not lo <= value <= hi:
            diag.error(pos, f"{what} = {value!r} does not fit {t}", f"an integer in [{lo}, {hi}]")
    elif t.kind == "float":
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            diag.error(pos, f"{what} = {value!r} is not a finite number", f"a {t}")
    elif t.kind == "bool" and not isinstance(value, bool):
        diag.error(pos, f"{what} = {value!r} is not a bool", "true, false, 0 or 1" if v0 else "true or false")
