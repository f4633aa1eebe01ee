"""The performance monitor's state machine (document IV.H).

NOMINAL until one of: depth deeper than ``critical_depth``; a valid altitude below ``critical_altitude`` (NaN or
negative altitude = no bottom lock: not checked); the battery's charge below ``min_battery_percent`` or its health
reported as not good. Then EMERGENCY with the reasons, latched until :meth:`PerformanceMonitor.clear` (if a
condition still holds then, the next evaluation triggers again). In emergency the monitor's outputs are an active
abort with the reason, buoyancy 100 % and zero RPM (the emergency ascent).

Inputs are plain values with their times (seconds, any clock): depth [m] (or pressure through
:func:`sam_runtime.physics.geo.depth_from_pressure`), altitude [m], battery percent 0..100 (sensor_msgs/BatteryState
percentage x 100; NaN = unknown: not checked) and health (BatteryState.POWER_SUPPLY_HEALTH_*).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from sam_runtime.physics.geo import P_ATM, RHO_SEAWATER, depth_from_pressure

__all__ = ["BATTERY_HEALTH_BAD", "MonitorLimits", "MonitorOutput", "PerformanceMonitor"]

# sensor_msgs/BatteryState POWER_SUPPLY_HEALTH_*: UNKNOWN 0 and GOOD 1 are fine; these are not.
BATTERY_HEALTH_NAMES = {0: "unknown", 1: "good", 2: "overheat", 3: "dead", 4: "overvoltage",
                        5: "unspecified failure", 6: "cold", 7: "watchdog timer expired", 8: "safety timer expired"}
BATTERY_HEALTH_BAD = frozenset({2, 3, 4, 5, 6, 7, 8})

NOMINAL, EMERGENCY = "nominal", "emergency"


@dataclass
class MonitorLimits:
    critical_depth: float = 60.0  # [m]
    critical_altitude: float = 2.0  # [m]
    min_battery_percent: float = 20.0  # [%]


@dataclass(frozen=True)
class MonitorOutput:
    state: str  # "nominal" or "emergency"
    reasons: tuple[str, ...]  # why (emergency), empty when nominal
    abort_active: bool
    abort_reason: str
    buoyancy_pct: float | None  # the emergency ascent's commands, None when nominal (the controller commands)
    rpm: int | None
    changed: bool  # the state or the reasons changed at this evaluation (publish the abort now)
    since: float | None  # time of the transition into the current emergency


@dataclass
class PerformanceMonitor:
    limits: MonitorLimits = field(default_factory=MonitorLimits)
    p_atm: float = P_ATM
    rho: float = RHO_SEAWATER

    def __post_init__(self) -> None:
        self.depth: float | None = None
        self.altitude: float | None = None
        self.battery_percent: float | None = None
        self.battery_health: int | None = None
        self.state = NOMINAL
        self.reasons: tuple[str, ...] = ()
        self.since: float | None = None
        self.triggers = 0  # transitions into emergency
        self._latched: dict[str, str] = {}  # condition kind -> why, at its first occurrence
        self.refused = 0  # non-finite inputs (NaN altitude is not one: it means no bottom lock)

    # ---------------------------------------------------------------------------------- inputs
    def on_depth(self, t: float, depth: float) -> None:
        if math.isfinite(depth):
            self.depth = depth
        else:
            self.refused += 1

    def on_pressure(self, t: float, pressure_pa: float) -> None:
        if math.isfinite(pressure_pa) and pressure_pa > 0.0:
            self.depth = depth_from_pressure(pressure_pa, self.p_atm, self.rho)
        else:
            self.refused += 1

    def on_altitude(self, t: float, altitude: float) -> None:
        """Altitude [m]; NaN/inf or negative = no bottom lock (not checked until valid again)."""
        self.altitude = altitude if math.isfinite(altitude) and altitude >= 0.0 else None

    def on_battery(self, t: float, percent: float, health: int = 0) -> None:
        """``percent`` 0..100 (NaN: unknown), ``health`` as BatteryState.power_supply_health."""
        self.battery_percent = percent if math.isfinite(percent) else None
        self.battery_health = int(health)

    # ---------------------------------------------------------------------------------- state machine
    def conditions(self) -> dict[str, str]:
        """The emergency conditions that hold now: kind (depth, altitude, battery_low, battery_health) -> why."""
        lim, out = self.limits, {}
        if self.depth is not None and self.depth > lim.critical_depth:
            out["depth"] = f"depth {self.depth:.2f} m beyond critical_depth {lim.critical_depth:.2f} m"
        if self.altitude is not None and self.altitude < lim.critical_altitude:
            out["altitude"] = f"altitude {self.altitude:.2f} m below critical_altitude {lim.critical_altitude:.2f} m"
        if self.battery_percent is not None and self.battery_percent < lim.min_battery_percent:
            out["battery_low"] = (f"battery {self.battery_percent:.1f} % below min_battery_percent "
                                  f"{lim.min_battery_percent:.1f} %")
        if self.battery_health in BATTERY_HEALTH_BAD:
            out["battery_health"] = f"battery health {BATTERY_HEALTH_NAMES[self.battery_health]}"
        return out

    def evaluate(self, t: float) -> MonitorOutput:
        """Check the conditions, latching each new kind with the values of its first occurrence."""
        changed = False
        for kind, why in self.conditions().items():
            if kind not in self._latched:
                self._latched[kind] = why
                changed = True
        if self._latched and self.state == NOMINAL:
            self.state, self.since = EMERGENCY, t
            self.triggers += 1
        self.reasons = tuple(self._latched.values())
        return self.output(changed)

    def output(self, changed: bool = False) -> MonitorOutput:
        if self.state == EMERGENCY:
            reason = "; ".join(self.reasons)
            return MonitorOutput(EMERGENCY, self.reasons, True, reason, 100.0, 0, changed, self.since)
        return MonitorOutput(NOMINAL, (), False, "", None, None, changed, None)

    def clear(self, t: float) -> MonitorOutput:
        """Leave the emergency (an operator's decision); a condition that still holds triggers again at the next
        :meth:`evaluate`."""
        was = self.state
        self.state, self.reasons, self.since = NOMINAL, (), None
        self._latched.clear()
        return self.output(changed=was != NOMINAL)
