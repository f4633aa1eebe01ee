"""A board setting's value as a Cyphal register (uavcan.register.Value.1.0) and back: a bool is bit[1], an integer
(and an enum's integer) integer64[1], a real real32[1], a string string. Used by the simulated boards (their
registers) and the bridge (its uavcan.register.Access requests)."""

from __future__ import annotations

from typing import Any

__all__ = ["register_stored", "register_value"]


def register_value(kind: str, value: bool | int | float | str) -> Any:
    """The uavcan.register.Value.1.0 of a setting of type `kind` holding `value` (its stored form)."""
    from pycyphal.application.register import Bit, Integer64, Real32, String, Value

    if kind == "bool":
        return Value(bit=Bit([bool(value)]))
    if kind in ("integer", "enum"):
        return Value(integer64=Integer64([int(value)]))
    if kind == "real":
        return Value(real32=Real32([float(value)]))
    return Value(string=String(str(value)))


def register_stored(kind: str, value: Any) -> bool | int | float | str | None:
    """A register value read as a setting of type `kind` (None: empty, or not convertible: a missing register,
    another type)."""
    from pycyphal.application.register import ValueProxy

    if value is None or value.empty is not None:
        return None
    proxy = ValueProxy(value)
    try:
        if kind == "string":
            return str(proxy) if value.string is not None else None
        if value.string is not None or value.unstructured is not None:
            return None
        if kind == "bool":
            return bool(proxy.bools[0])
        if kind in ("integer", "enum"):
            return int(proxy.ints[0])
        return float(proxy.floats[0])
    except (IndexError, ValueError, TypeError):  # an empty array, a conversion that does not exist
        return None
