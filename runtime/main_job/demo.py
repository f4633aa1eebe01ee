"""Demo values for any ROS message, built from the message's own field types (issue 11, defect 4).

The demo publisher of main_job.live_view.LiveView sweeps the command topics of a spec that has no nodes of its
own. Its values come from each field's rosidl type (``SLOT_TYPES``), never from a guess on the type's name: a
fixed-size array gets a sequence of exactly its size, a bounded sequence at most its bound, an integer a value inside
its width, a bool a bool, a byte a one-byte ``bytes``, a string a ``str``, a nested message (or a sequence of them) its
own class, filled the same way. Every message is also constructed with ``check_fields=True``, so rclpy's own setters
check each value as it is set: a mistake here raises (and the caller counts and logs it) instead of reaching rclpy's
C conversion, where a scalar in an array field is a segmentation fault.

Values sweep slowly (a sine of period 30 s) and stay small and non-negative (floats in 0.1..0.9, integers
0..2) so that they fit the usual limits and tables of a mapping; a few names of SAM's commands get their own
ranges (percent 10..90, rpm +-1000, radians +-0.3).
"""

from __future__ import annotations

import importlib
import math
from typing import Any

__all__ = ["demo_message", "field_problems"]

SWEEP_PERIOD_S = 30.0
SEQUENCE_LENGTH = 2  # elements put into an unbounded (or larger bounded) sequence

_INT_RANGES: dict[str, tuple[int, int]] = {
    **{f"int{b}": (-(2 ** (b - 1)), 2 ** (b - 1) - 1) for b in (8, 16, 32, 64)},
    **{f"uint{b}": (0, 2**b - 1) for b in (8, 16, 32, 64)},
    "char": (0, 255),
    "short": (-(2**15), 2**15 - 1), "unsigned short": (0, 2**16 - 1),
    "long": (-(2**31), 2**31 - 1), "unsigned long": (0, 2**32 - 1),
    "long long": (-(2**63), 2**63 - 1), "unsigned long long": (0, 2**64 - 1),
}
_FLOAT32_MAX = 3.402823466e38


def _named_value(name: str, s: float) -> float | None:
    """SAM's command fields: the ranges their actuators expect."""
    if "percent" in name:
        return 50.0 + 40.0 * s
    if "rpm" in name:
        return 1000.0 * s
    if "radian" in name:
        return 0.3 * s
    return None


def _basic(typename: str, name: str, s: float) -> Any:
    """One value of a rosidl BasicType: the Python type its setter requires, inside its range.

    >>> _basic("int8", "trim", 1.0), _basic("uint8", "rpm", -1.0), _basic("boolean", "on", 0.2)
    (2, 0, True)
    >>> _basic("float", "x", 0.0), _basic("octet", "b", 1.0)
    (0.5, b'\\x02')
    """
    if typename == "boolean":
        return s > 0
    named = _named_value(name, s)
    if typename in ("float", "double", "long double"):
        value = 0.5 + 0.4 * s if named is None else named
        return float(max(-_FLOAT32_MAX, min(_FLOAT32_MAX, value)) if typename == "float" else value)
    if typename == "octet":
        return bytes([round(1 + s)])
    if typename == "wchar":
        return "a"
    lo, hi = _INT_RANGES[typename]
    return max(lo, min(hi, round(1 + s if named is None else named)))


def _message_class(namespaced: Any) -> type:
    """The Python class of a rosidl NamespacedType (``['std_msgs', 'msg'], 'Header'``)."""
    return getattr(importlib.import_module(".".join(namespaced.namespaces)), namespaced.name)


def _value(slot: Any, name: str, t: float, phase: float, stamp: Any) -> Any:
    from rosidl_parser import definition as d

    s = math.sin(2.0 * math.pi * t / SWEEP_PERIOD_S + phase)
    if isinstance(slot, d.BasicType):
        return _basic(slot.typename, name, s)
    if isinstance(slot, d.AbstractGenericString):
        limit = getattr(slot, "maximum_size", None)
        return "demo"[:limit] if limit is not None else "demo"
    if isinstance(slot, d.NamespacedType):
        return demo_message(_message_class(slot), t, stamp, phase)
    if isinstance(slot, d.AbstractNestedType):
        if isinstance(slot, d.Array):
            n = slot.size
        elif isinstance(slot, d.BoundedSequence):
            n = min(slot.maximum_size, SEQUENCE_LENGTH)
        else:
            n = SEQUENCE_LENGTH
        return [_value(slot.value_type, name, t, phase + 0.5 * k, stamp) for k in range(n)]
    raise TypeError(f"field {name!r}: unsupported rosidl type {slot!r}")


def demo_message(cls: Any, t: float, stamp: Any = None, phase: float = 0.0) -> Any:
    """A message of ``cls`` with every field set to a demo value for time ``t`` [s].

    ``stamp`` (a builtin_interfaces/Time) goes into every Time field (header stamps); without it they stay 0.
    Built with ``check_fields=True``: rclpy refuses any value that does not fit its field (AssertionError),
    so the message can never hold a wrongly shaped value.
    """
    if stamp is not None and cls.__name__ == "Time" and cls.__module__.startswith("builtin_interfaces."):
        return cls(sec=int(stamp.sec), nanosec=int(stamp.nanosec), check_fields=True)
    msg = cls(check_fields=True)
    for k, ((name, _), slot) in enumerate(zip(cls.get_fields_and_field_types().items(), cls.SLOT_TYPES,
                                            strict=True)):
        if name == "frame_id":  # a header's frame: the bridge or the receiver decides it
            continue
        setattr(msg, name, _value(slot, name, t, phase + 1.0 + k, stamp))
    return msg


def field_problems(msg: Any, path: str = "") -> list[str]:
    """Every field of ``msg`` whose value rclpy's own checks refuse (wrong type, shape or range), as
    ``"path: reason"``; [] for a message that is safe to publish. For tests and checks, not for a hot path."""
    from rosidl_parser import definition as d

    problems: list[str] = []
    cls = type(msg)
    checker = cls(check_fields=True)
    for (name, _), slot in zip(cls.get_fields_and_field_types().items(), cls.SLOT_TYPES, strict=True):
        value = getattr(msg, name)
        where = f"{path}{name}"
        try:
            setattr(checker, name, value)
        except AssertionError as ex:
            problems.append(f"{where}: {ex}")
            continue
        if isinstance(slot, d.Array) and getattr(value, "ndim", 1) != 1:  # a 0-d numpy array passes size == 1
            problems.append(f"{where}: a numpy array of shape {value.shape}, expected ({slot.size},)")
        if isinstance(slot, d.NamespacedType):
            problems += field_problems(value, where + ".")
        elif isinstance(slot, d.AbstractNestedType) and isinstance(slot.value_type, d.NamespacedType):
            for i, item in enumerate(value):
                problems += field_problems(item, f"{where}[{i}].")
    return problems
