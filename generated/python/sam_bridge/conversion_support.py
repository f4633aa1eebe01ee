# Generated from interfaces.yaml by sam-codegen; do not edit.
"""What the sam bridge's converters (convert.py, convert_v0.py) and wire codecs (codec.py, codec_v0.py)
share: the counts of saturated values and rejected messages, the error of malformed wire data, and the element
checks of arrays. One class of each, whichever module a bridge takes them from.

Standard library only.
"""

from __future__ import annotations

__all__ = ["ConversionStats", "WireError", "clamp_finite_floats", "clamp_floats", "clamp_ints", "divide",
           "maximum", "minimum", "reject_nan_floats", "round_ints"]

_INF = float("inf")


class ConversionStats:
    """Counts, per "<mapping>.<field>", the values that were saturated and the messages that were rejected."""

    __slots__ = ("rejected", "saturated")

    def __init__(self) -> None:
        self.saturated: dict[str, int] = {}
        self.rejected: dict[str, int] = {}

    def saturate(self, key: str) -> None:
        self.saturated[key] = self.saturated.get(key, 0) + 1

    def reject(self, key: str) -> None:
        self.rejected[key] = self.rejected.get(key, 0) + 1

    def reject_nan(self, key: str) -> None:
        """A message rejected because a value was NaN (the bridge counts its drop as `not_a_number`)."""
        self.reject(key)


class WireError(ValueError):
    """A malformed UAVCAN payload (one pycyphal or dronecan would not decode) or CDR that does not hold the
    message (truncated, a string without its NUL, a bound exceeded, not little-endian plain CDR)."""


def clamp_floats(
    values: list[float], bound: float, stats: ConversionStats, key: str, reject: bool
) -> list[float] | None:
    """Saturate the elements beyond +-bound (infinities too) into it, or reject; NaN passes."""
    for x in values:
        if x > bound or x < -bound:
            break
    else:
        return values
    if reject:
        stats.reject(key)
        return None
    stats.saturate(key)
    return [bound if x > bound else -bound if x < -bound else x for x in values]


def clamp_finite_floats(
    values: list[float], bound: float, stats: ConversionStats, key: str, reject: bool
) -> list[float] | None:
    """Saturate the finite elements beyond +-bound into it, or reject; infinities and NaN pass."""
    for x in values:
        if bound < x < _INF or -_INF < x < -bound:
            break
    else:
        return values
    if reject:
        stats.reject(key)
        return None
    stats.saturate(key)
    return [bound if bound < x < _INF else -bound if -_INF < x < -bound else x for x in values]


def clamp_ints(
    values: list[int], lo: int, hi: int, stats: ConversionStats, key: str, reject: bool
) -> list[int] | None:
    """Saturate integer elements into [lo, hi], or reject."""
    if values and (max(values) > hi or min(values) < lo):
        if reject:
            stats.reject(key)
            return None
        stats.saturate(key)
        return [hi if x > hi else lo if x < lo else x for x in values]
    return values


def round_ints(
    values: list[float], lo: int, hi: int, stats: ConversionStats, key: str, reject: bool
) -> list[int] | None:
    """Round float elements half to even into [lo, hi], saturating (or rejecting) beyond; NaN rejects."""
    out = []
    saturated = False
    for x in values:
        if x != x:
            stats.reject_nan(key)
            return None
        if x >= hi + 0.5:
            out.append(hi)
            saturated = True
        elif x <= lo - 0.5:
            out.append(lo)
            saturated = True
        else:
            out.append(round(x))
    if saturated:
        if reject:
            stats.reject(key)
            return None
        stats.saturate(key)
    return out


def reject_nan_floats(values: list[float], stats: ConversionStats, key: str) -> list[float] | None:
    """The elements of a command, or None (counted) when one is NaN: NaN is no setpoint."""
    for x in values:
        if x != x:
            stats.reject_nan(key)
            return None
    return values


def maximum(a: float, b: float) -> float:
    """max() of a mapping expression as IEEE 754-2019 `maximum`: NaN when either argument is NaN (Python's
    max() keeps its first argument against a NaN, so max(1, NaN) was 1 and max(NaN, 1) NaN), +0 above -0."""
    if a != a or b != b:
        return _INF - _INF
    if a == b:  # equal: for two zeros, +0 above -0
        return b if _negative_zero(a) else a
    return a if a > b else b


def minimum(a: float, b: float) -> float:
    """min() of a mapping expression as IEEE 754-2019 `minimum`: NaN when either argument is NaN, -0 below
    +0."""
    if a != a or b != b:
        return _INF - _INF
    if a == b:  # equal: for two zeros, -0 below +0
        return b if _negative_zero(b) else a
    return a if a < b else b


def _negative_zero(x: float) -> bool:
    return x == 0 and repr(float(x))[0] == "-"  # (math.copysign without importing math)


def divide(a: float, b: float) -> float:
    """a / b of a mapping expression as IEEE 754 has it where Python raises: x / 0 is +-inf by the sign of x
    (the divisor's zero taken as +0), 0 / 0 and NaN / 0 are NaN."""
    if b:
        return a / b
    if a != a or a == 0:
        return _INF - _INF
    return _INF if a > 0 else -_INF
