"""The performance monitor's state machine (runtime/nav/performance_monitor.py): each emergency condition, latching
until cleared, and the emergency outputs."""

from __future__ import annotations

import math

import pytest

from sam_runtime.nav.performance_monitor import MonitorLimits, PerformanceMonitor
from sam_runtime.physics.geo import pressure_at_depth


def _nominal() -> PerformanceMonitor:
    m = PerformanceMonitor(MonitorLimits(critical_depth=10.0, critical_altitude=2.0, min_battery_percent=20.0))
    m.on_depth(0.0, 5.0)
    m.on_altitude(0.0, 8.0)
    m.on_battery(0.0, 80.0, 1)
    out = m.evaluate(0.0)
    assert out.state == "nominal" and not out.abort_active and out.buoyancy_pct is None and out.rpm is None
    return m


@pytest.mark.parametrize(("feed", "reason"), [
    (lambda m: m.on_depth(1.0, 10.5), "depth 10.50 m beyond critical_depth 10.00 m"),
    (lambda m: m.on_pressure(1.0, pressure_at_depth(12.0)), "depth 12.00 m beyond critical_depth 10.00 m"),
    (lambda m: m.on_altitude(1.0, 1.5), "altitude 1.50 m below critical_altitude 2.00 m"),
    (lambda m: m.on_battery(1.0, 19.0, 1), "battery 19.0 % below min_battery_percent 20.0 %"),
    (lambda m: m.on_battery(1.0, 80.0, 3), "battery health dead"),
    (lambda m: m.on_battery(1.0, 80.0, 2), "battery health overheat"),
])
def test_each_condition_triggers_an_emergency_ascent(feed: object, reason: str) -> None:
    m = _nominal()
    feed(m)  # type: ignore[operator]
    out = m.evaluate(1.0)
    assert out.state == "emergency" and out.reasons == (reason,) and out.changed and out.since == 1.0
    assert out.abort_active and out.abort_reason == reason and out.buoyancy_pct == 100.0 and out.rpm == 0


@pytest.mark.parametrize("altitude", [math.nan, math.inf, -1.0])
def test_an_invalid_altitude_is_no_bottom_lock_not_an_emergency(altitude: float) -> None:
    m = _nominal()
    m.on_altitude(1.0, 1.0)
    m.on_altitude(2.0, altitude)  # the last valid reading is not kept either
    assert m.evaluate(2.0).state == "nominal"


def test_unknown_battery_values_do_not_trigger() -> None:
    m = _nominal()
    m.on_battery(1.0, math.nan, 0)  # percentage unknown, health unknown
    assert m.evaluate(1.0).state == "nominal"


def test_latched_until_cleared_and_triggers_again_if_the_condition_holds() -> None:
    m = _nominal()
    m.on_depth(1.0, 11.0)
    assert m.evaluate(1.0).changed
    m.on_depth(2.0, 3.0)  # back above: still an emergency
    out = m.evaluate(2.0)
    assert out.state == "emergency" and not out.changed and out.reasons == ("depth 11.00 m beyond critical_depth "
                                                                            "10.00 m",)
    m.on_battery(3.0, 10.0, 1)  # a second kind of condition joins the reasons
    out = m.evaluate(3.0)
    assert out.changed and len(out.reasons) == 2 and out.abort_reason.startswith("depth 11.00 m") \
        and "; battery 10.0 %" in out.abort_reason and out.since == 1.0
    out = m.clear(4.0)
    assert out.state == "nominal" and out.changed and not out.abort_active
    out = m.evaluate(4.1)  # the battery is still low
    assert out.state == "emergency" and out.changed and out.reasons == ("battery 10.0 % below min_battery_percent "
                                                                        "20.0 %",)
    m.on_battery(5.0, 90.0, 1)
    m.clear(5.0)
    out = m.evaluate(5.1)
    assert out.state == "nominal" and not out.changed and m.triggers == 2


def test_limits_follow_parameter_updates() -> None:
    m = _nominal()
    m.limits.critical_depth = 4.0  # lowered at run time below the current depth
    out = m.evaluate(1.0)
    assert out.state == "emergency" and out.reasons == ("depth 5.00 m beyond critical_depth 4.00 m",)


def test_non_finite_depth_inputs_are_refused_and_counted() -> None:
    m = _nominal()
    m.on_depth(1.0, math.nan)
    m.on_pressure(1.0, -5.0)
    assert m.refused == 2 and m.depth == 5.0
