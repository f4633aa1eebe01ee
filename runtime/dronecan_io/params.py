"""A board setting's value in uavcan.protocol.param (DroneCAN): GetSet's Value union (integer_value int64,
real_value float32, boolean_value, string_value) and NumericValue (min/max), both ways. Used by the simulated
boards (their GetSet server) and the bridge (its GetSet requests). An enum travels as its integer."""

from __future__ import annotations

from typing import Any

__all__ = ["OPCODE_ERASE", "OPCODE_SAVE", "fill_value", "read_value"]

OPCODE_SAVE = 0  # uavcan.protocol.param.ExecuteOpcode.Request.OPCODE_SAVE
OPCODE_ERASE = 1  # OPCODE_ERASE


def fill_value(union: Any, kind: str, value: bool | int | float | str | None) -> None:
    """Set GetSet's Value (or a NumericValue: integer/real only) `union` to `value` of a setting of type `kind`;
    None: empty."""
    import dronecan

    if value is None:
        dronecan.switch_union_field(union, "empty")
    elif kind == "bool":
        union.boolean_value = int(bool(value))
    elif kind in ("integer", "enum"):
        union.integer_value = int(value)
    elif kind == "real":
        union.real_value = float(value)
    else:
        union.string_value = str(value)


def read_value(union: Any, kind: str) -> bool | int | float | str | None:
    """A Value union read as a setting of type `kind` (None: empty or another type)."""
    import dronecan

    field = dronecan.get_active_union_field(union)
    if kind == "bool" and field == "boolean_value":
        return bool(union.boolean_value)
    if kind in ("integer", "enum") and field == "integer_value":
        return int(union.integer_value)
    if kind == "real" and field == "real_value":
        return float(union.real_value)
    if kind == "real" and field == "integer_value":  # firmware may hold a whole real as an integer
        return float(union.integer_value)
    if kind == "string" and field == "string_value":
        return bytes(union.string_value).decode("utf-8", "replace")
    return None
