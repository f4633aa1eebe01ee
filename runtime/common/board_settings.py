"""A board's settings (the generated tables' DEVICE_PARAMETERS) as values: the rules a value must keep, the form a
board stores (an enum's integer), and a simulated board's store (current values, saved values, factory defaults).

One place for the rules, so that the bridge refuses a ROS parameter set with the same reason a board would refuse
the write (the bridge checks before any bus traffic; the simulated boards check again, as real firmware does).
Protocol-independent: the Cyphal register and DroneCAN GetSet forms are the protocols' (sim.cyphal / sim.dronecan,
bridge.device_params).
"""

from __future__ import annotations

import math
import struct
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from sam_codegen.contracts.table_types import DeviceParameterInfo

__all__ = [
    "BoardSettings",
    "Stored",
    "default_stored",
    "f32_shortest",
    "from_stored",
    "ros_problem",
    "stored_problem",
    "to_stored",
]

Stored = bool | int | float | str  # what a board holds: an enum's integer, every other type as it is

_FLOAT32_MAX = 3.4028234663852886e38


def _f32(value: float) -> float:
    return float(struct.unpack("<f", struct.pack("<f", value))[0])


def _range_problem(p: DeviceParameterInfo, value: float) -> str | None:
    low = p.minimum if p.minimum is None or p.type != "real" else _f32(p.minimum)
    high = p.maximum if p.maximum is None or p.type != "real" else _f32(p.maximum)
    if (low is not None and value < low) or (high is not None and value > high):
        unit = f" {p.unit}" if p.unit else ""
        return f"{value!r} is outside {p.minimum}..{p.maximum}{unit}"
    return None


def stored_problem(p: DeviceParameterInfo, value: object) -> str | None:
    """Why a board refuses to store `value` for `p` (None: it stores it): the type, the range, an enum's integers,
    a string's length in UTF-8 bytes."""
    if p.type == "bool":
        return None if isinstance(value, bool) else f"{p.name} is a bool, not {type(value).__name__}"
    if p.type in ("integer", "enum"):
        if isinstance(value, bool) or not isinstance(value, int):
            return f"{p.name} is an integer, not {type(value).__name__}"
        if p.type == "enum":
            allowed = sorted(v for _, v in p.values)
            return None if value in allowed else f"{value} is none of {allowed}"
        return _range_problem(p, value)
    if p.type == "real":
        if isinstance(value, bool) or not isinstance(value, int | float):
            return f"{p.name} is a real, not {type(value).__name__}"
        if not math.isfinite(value) or abs(value) > _FLOAT32_MAX:
            return f"{value!r} is not a finite float32"
        # a real travels as float32 on both protocols: 0.1 arrives as 0.10000000149..., still within 0..0.1
        return None if _range_problem(p, _f32(value)) is None else _range_problem(p, float(value))
    if not isinstance(value, str):
        return f"{p.name} is a string, not {type(value).__name__}"
    if p.max_length is not None and len(value.encode()) > p.max_length:
        return f"{value!r} is longer than {p.max_length} bytes"
    return None


def to_stored(p: DeviceParameterInfo, value: object) -> Stored | None:
    """The board's form of a ROS-side value (an enum's name -> its integer; an integer given for a real -> float);
    None if there is none (ros_problem says why)."""
    if p.type == "enum":
        return dict(p.values).get(value) if isinstance(value, str) else None
    if p.type == "real" and isinstance(value, int) and not isinstance(value, bool):
        return float(value)
    if isinstance(value, bool | int | float | str):
        return value
    return None


def ros_problem(p: DeviceParameterInfo, value: object) -> str | None:
    """Why the bridge refuses `value` (a ROS parameter's) for `p` before it reaches the board (None: it is fine)."""
    if p.type == "enum":
        names = [n for n, _ in p.values]
        return None if value in names else f"{value!r} is none of {names}"
    stored = to_stored(p, value)
    return f"{p.name} takes a {p.type}, not {type(value).__name__}" if stored is None else stored_problem(p, stored)


def from_stored(p: DeviceParameterInfo, value: Stored) -> Stored:
    """A board's value as the ROS side shows it: an enum's name (its integer as text if it has no name)."""
    if p.type == "enum" and not isinstance(value, str):
        names = {v: n for n, v in p.values}
        return names.get(int(value), str(value))
    if p.type == "real" and isinstance(value, float) and math.isfinite(value):
        return f32_shortest(value)
    return value


def f32_shortest(value: float) -> float:
    """The shortest decimal that is the same float32 as `value`: a board's real32 0.0007999999797903 is 0.0008,
    the value that was set.

    >>> f32_shortest(0.0007999999797903001), f32_shortest(0.12)
    (0.0008, 0.12)
    """
    target = _f32(value)
    for digits in range(1, 10):
        candidate = float(f"{value:.{digits}g}")
        if _f32(candidate) == target:
            return candidate
    return value


def default_stored(p: DeviceParameterInfo) -> Stored:
    stored = to_stored(p, p.default)
    assert stored is not None, p  # the spec's defaults are checked by the frontend
    return stored


class BoardSettings:
    """A simulated board's settings by their name on its protocol: the values it runs with, the values saved in
    its non-volatile memory (what a reboot loads), and its factory defaults (the spec's)."""

    def __init__(self, params: tuple[DeviceParameterInfo, ...], protocol: str) -> None:
        self.params = {p.name_on(protocol): p for p in params}
        self.defaults = {name: default_stored(p) for name, p in self.params.items()}
        self.saved = dict(self.defaults)
        self.values = dict(self.saved)
        self.refused = 0  # writes refused (a bad type, out of range)

    def write(self, name: str, value: Stored) -> str | None:
        """Set `name` to `value` unless the board refuses it (the reason; the value stays as it was)."""
        problem = stored_problem(self.params[name], value)
        if problem is None:
            self.values[name] = value
        else:
            self.refused += 1
        return problem

    def save(self) -> None:
        """Store the current values (DroneCAN's ExecuteOpcode SAVE, Cyphal's STORE_PERSISTENT_STATES)."""
        self.saved = dict(self.values)

    def erase(self) -> None:
        """Forget the saved values: the next reboot loads the factory defaults (ExecuteOpcode ERASE)."""
        self.saved = dict(self.defaults)

    def reboot(self) -> None:
        """A restart runs with the saved values: what was set but not saved is lost."""
        self.values = dict(self.saved)
