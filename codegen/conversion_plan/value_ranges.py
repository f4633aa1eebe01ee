"""Value ranges of the plan's types: the finite range of a DSDL or ROS scalar, the limits of float16, float32 and
builtin_interfaces/Time, and how a scalar's width changes between two types (the `change` of a Convert)."""

from __future__ import annotations

import math
import re

from sam_codegen.model.types import ROS_INT_RANGES, DsdlType

FLOAT16_MAX = 65504.0
FLOAT32_MAX = 3.4028234663852886e38
INT32_MAX = 2**31 - 1
# builtin_interfaces/Time holds sec as int32 and nanosec as uint32.
TIME_US_MIN = -(2**31) * 1_000_000
TIME_US_MAX_TO_ROS = INT32_MAX * 1_000_000 + 999_999  # the last microsecond a Time can hold
TIME_US_MAX_FROM_ROS = INT32_MAX * 1_000_000 + (2**32 - 1) // 1000  # nanosec may exceed 1e9 in a bad message

ValueRange = tuple[float, float]


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
