"""The SLAM corrector (document IV.E.2): world -> odom from GPS fixes at the surface.

world is a local metric ENU frame around a datum: by default the first usable fix (or the mean of the first
``origin_fixes``), or a datum given in the configuration. Each usable fix, converted to world (equirectangular), is
compared with the dead-reckoning position in odom at that time; their difference is the translation world -> odom,
low-pass filtered over fixes (the first one taken as is). The dead reckoning's heading is absolute (magnetometer)
and its z is the measured depth, so the correction is a horizontal translation with an identity rotation.
Submerged there are no fixes: the last correction is kept and the system runs on dead reckoning alone.

A fix is usable when its status says fix (sensor_msgs/NavSatFix: status >= STATUS_FIX = 0), its latitude and
longitude are finite and in range, and (when the caller knows it) the vehicle is at the surface. Anything else is
ignored and counted per reason.
"""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass

from sam_runtime.physics.geo import Vec3, local_from_latlon

__all__ = ["SlamConfig", "SlamCorrector"]

NAVSAT_STATUS_FIX = 0  # sensor_msgs/NavSatStatus: -1 no fix, 0 fix, 1 SBAS, 2 GBAS


@dataclass(frozen=True)
class SlamConfig:
    gain: float = 0.2  # low-pass weight of a new fix's correction (0 < gain <= 1)
    origin_fixes: int = 1  # fixes averaged into the world origin (the contract: the first fix)
    datum: tuple[float, float] | None = None  # (lat, lon) of the world origin; None: from the fixes
    max_depth: float = 0.5  # fixes while the vehicle is deeper than this are ignored [m]

    def __post_init__(self) -> None:
        if not 0.0 < self.gain <= 1.0:
            raise ValueError(f"gain must be within (0, 1], got {self.gain}")
        if self.origin_fixes < 1:
            raise ValueError(f"origin_fixes must be >= 1, got {self.origin_fixes}")


def _valid_latlon(lat: float, lon: float) -> bool:
    return math.isfinite(lat) and math.isfinite(lon) and -90.0 <= lat <= 90.0 and -180.0 <= lon <= 180.0


class SlamCorrector:
    """``on_fix(...)`` per GPS fix; ``correction`` is the world -> odom translation once known."""

    def __init__(self, config: SlamConfig | None = None) -> None:
        self.config = config or SlamConfig()
        self.origin: tuple[float, float] | None = self.config.datum
        if self.origin is not None and not _valid_latlon(*self.origin):
            raise ValueError(f"datum must be a valid (lat, lon), got {self.origin}")
        self._origin_samples: list[tuple[float, float]] = []
        self.correction: tuple[float, float] | None = None
        self.last_fix_t: float | None = None
        self.counts: Counter[str] = Counter()

    def on_fix(self, t: float, status: int, lat: float, lon: float, dr_x: float, dr_y: float,
               depth: float | None = None) -> bool:
        """A NavSatFix (``status`` as NavSatStatus.status) and the dead-reckoning position (odom) at its time.
        Returns whether the fix was used."""
        if status < NAVSAT_STATUS_FIX:
            self.counts["ignored.no_fix"] += 1
            return False
        if not _valid_latlon(lat, lon):
            self.counts["ignored.invalid_position"] += 1
            return False
        if not (math.isfinite(dr_x) and math.isfinite(dr_y)):
            self.counts["ignored.invalid_odometry"] += 1
            return False
        if depth is not None and (not math.isfinite(depth) or depth > self.config.max_depth):
            self.counts["ignored.submerged"] += 1
            return False
        if self.origin is None:
            self._origin_samples.append((lat, lon))
            if len(self._origin_samples) < self.config.origin_fixes:
                self.counts["origin_samples"] += 1
                return True
            n = len(self._origin_samples)
            self.origin = (sum(a for a, _ in self._origin_samples) / n, sum(b for _, b in self._origin_samples) / n)
        e, nth = local_from_latlon(lat, lon, *self.origin)
        meas = (e - dr_x, nth - dr_y)
        if self.correction is None:
            self.correction = meas
        else:
            k = self.config.gain
            cx, cy = self.correction
            self.correction = (cx + k * (meas[0] - cx), cy + k * (meas[1] - cy))
        self.last_fix_t = t
        self.counts["used"] += 1
        return True

    def world_position(self, lat: float, lon: float) -> Vec3:
        """A (lat, lon) in world (z = 0), once the origin is known."""
        if self.origin is None:
            raise RuntimeError("no world origin yet (no GPS fix)")
        e, n = local_from_latlon(lat, lon, *self.origin)
        return e, n, 0.0

    def transform(self) -> tuple[Vec3, tuple[float, float, float, float]] | None:
        """world -> odom as (translation, rotation (x, y, z, w)), or None before the first usable fix."""
        if self.correction is None:
            return None
        return (self.correction[0], self.correction[1], 0.0), (0.0, 0.0, 0.0, 1.0)
