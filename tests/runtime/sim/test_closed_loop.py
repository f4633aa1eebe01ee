"""The five nodes' logic closed around the simulated vehicle in one process, in simulated time
(runtime/sim/closed_loop.py): the issue's scenarios as measured outcomes against the vehicle's true state.

Positions in world are converted to the simulator's frame through SLAM's world origin (the first GPS fix), so the
true errors include the navigation error. Each scenario takes a second or two of wall time; ``-s`` prints the
figures."""

from __future__ import annotations

import math
import time
from typing import Any

import pytest

from sam_runtime.nav.performance_monitor import MonitorLimits
from sam_runtime.physics.geo import wrap_angle
from sam_runtime.physics.vehicle import SeaFloor
from sam_runtime.sim.closed_loop import ClosedLoop, LoopOptions


def _horizontal_error(loop: ClosedLoop, gx: float, gy: float) -> float:
    tx, ty = loop.world_to_truth(gx, gy)
    return math.hypot(loop.vehicle.state.x - tx, loop.vehicle.state.y - ty)


def _start(**options: Any) -> ClosedLoop:
    loop = ClosedLoop(LoopOptions(**options))
    loop.run(3.0)  # at the surface: GPS fixes define world and the first correction
    assert loop.slam.origin is not None and loop.world_pose() is not None
    return loop


def _first(loop: ClosedLoop, predicate: Any, seconds: float) -> float | None:
    """Run until ``predicate(loop)``; the simulated time it became true, or None."""
    return loop.t if loop.run(seconds, predicate) else None


def test_a_pose_goal_at_depth_is_reached_within_tolerance_and_time() -> None:
    wall = time.monotonic()
    loop = _start(seed=1)
    t0 = loop.t
    goal = (40.0, 25.0, -6.0)
    assert loop.goal_pose(*goal).accepted
    arrived = _first(loop, lambda lp: lp.commands is not None and lp.commands.mode == "arrived", 120.0)
    assert arrived is not None, loop.events
    loop.run(20.0)  # coast and settle at depth
    err = _horizontal_error(loop, goal[0], goal[1])
    depth = loop.vehicle.state.depth
    print(f"\npose goal {goal}: arrived after {arrived - t0:.1f} s (straight line {math.hypot(*goal[:2]):.0f} m), "
          f"final horizontal error {err:.2f} m, depth {depth:.2f} m, max depth {loop.vehicle.state.max_depth:.2f} m, "
          f"navigation error {loop.dr_error():.2f} m, wall {time.monotonic() - wall:.2f} s")
    assert arrived - t0 < 75.0  # 47 m at ~1.25 m/s, plus the dive and the slow-down
    assert err < 3.0  # the goal tolerance (1.5 m) + coasting + navigation error
    assert depth == pytest.approx(6.0, abs=0.3) and loop.vehicle.state.max_depth < 6.5
    assert loop.vehicle.state.floor_contacts == 0


def test_a_heading_goal_is_held_at_its_depth() -> None:
    loop = _start(seed=3)
    heading = math.radians(120.0)
    assert loop.goal_heading(heading, -4.0).accepted
    loop.run(40.0)  # turn and dive
    yaw_errors, depths = [], []

    def sample(lp: ClosedLoop) -> bool:
        yaw_errors.append(abs(wrap_angle(lp.vehicle.state.yaw - heading)))
        depths.append(lp.vehicle.state.depth)
        return False

    loop.run(60.0, sample)
    print(f"\nheading goal 120 deg at 4 m: over 60 s, max heading error {math.degrees(max(yaw_errors)):.2f} deg, "
          f"depth {min(depths):.2f}..{max(depths):.2f} m")
    assert max(yaw_errors) < math.radians(3.0)
    assert 3.7 < min(depths) and max(depths) < 4.3
    assert loop.commands is not None and loop.commands.rpm_1 > 0  # a heading goal never "arrives"


def test_a_goal_deeper_than_safe_depth_is_planned_at_safe_depth_and_never_exceeded() -> None:
    loop = _start(seed=2, safe_depth=8.0)
    assert loop.goal_pose(50.0, -10.0, -20.0).accepted
    loop.run(90.0)
    assert loop.plan is not None
    assert loop.plan.target_depth == 8.0 and loop.plan.clamped == ("goal depth 20.00 m clamped to safe_depth 8.00 m",)
    assert all(-pose[2] <= 8.0 for pose in loop.plan.poses)
    max_depth = loop.vehicle.state.max_depth
    print(f"\ngoal at 20 m, safe_depth 8 m: max depth {max_depth:.2f} m, final {loop.vehicle.state.depth:.2f} m")
    assert max_depth < 8.0 + 0.2  # the depth controller's overshoot only
    assert loop.vehicle.state.depth == pytest.approx(8.0, abs=0.2)


def test_an_altitude_goal_keeps_its_height_above_the_sea_floor() -> None:
    loop = _start(seed=4, sea_floor=SeaFloor(15.0))
    assert loop.goal_pose(40.0, 0.0, 6.0).accepted  # 6 m above the floor at 15 m: 9 m deep
    loop.run(70.0)
    assert loop.vehicle.altitude() == pytest.approx(6.0, abs=0.3)


@pytest.mark.parametrize("offset", [(0.0, 3.0), (-2.0, 0.0), (0.0, -6.0)])
def test_a_goal_inside_the_turning_circles_is_reached(offset: tuple[float, float]) -> None:
    loop = _start(seed=11)
    here = loop.world_pose()
    assert here is not None
    goal = (here.x + offset[0], here.y + offset[1], -2.0)
    loop.goal_pose(*goal)
    arrived = _first(loop, lambda lp: lp.commands is not None and lp.commands.mode == "arrived", 120.0)
    assert arrived is not None and _horizontal_error(loop, goal[0], goal[1]) < 3.0


def _emergency_figures(loop: ClosedLoop, crossing: float) -> tuple[float, float]:
    abort = _first(loop, lambda lp: lp.monitor.state == "emergency", 60.0)
    assert abort is not None, loop.events
    surface = _first(loop, lambda lp: lp.vehicle.state.depth == 0.0, 120.0)
    assert surface is not None, f"did not surface: depth {loop.vehicle.state.depth:.2f} m"
    c = loop.commands
    assert c is not None and c.mode == "abort" and c.rpm_1 == 0 and c.buoyancy_pct == 100.0
    assert loop.vehicle.commands.buoyancy_pct == 100.0 and loop.vehicle.commands.rpm_1 == 0.0
    return abort - crossing, surface - crossing


def test_lowering_critical_depth_below_the_current_depth_makes_the_vehicle_surface() -> None:
    loop = _start(seed=4)
    loop.goal_pose(80.0, 0.0, -10.0)
    loop.run(50.0)
    depth = loop.vehicle.state.depth
    assert depth > 8.0
    loop.monitor.limits.critical_depth = depth - 2.0  # the parameter lowered at run time
    to_abort, to_surface = _emergency_figures(loop, loop.t)
    print(f"\ncritical_depth lowered to {depth - 2:.1f} m at {depth:.1f} m: abort after {to_abort:.2f} s, "
          f"surface after {to_surface:.1f} s")
    assert to_abort <= 0.2  # the monitor runs at 10 Hz
    assert to_surface < 60.0
    assert "critical_depth" in loop.monitor.reasons[0]


def test_critical_altitude_over_a_rising_sea_floor_makes_the_vehicle_surface() -> None:
    loop = _start(seed=6, sea_floor=SeaFloor.parse("0:20,30:20,60:3"))
    loop.goal_pose(80.0, 0.0, -8.0)
    crossing = _first(loop, lambda lp: lp.vehicle.altitude() < 2.0, 120.0)
    assert crossing is not None
    to_abort, to_surface = _emergency_figures(loop, crossing)
    print(f"\nsea floor rising from 20 to 3 m under a vehicle at 8 m: altitude below 2 m at {crossing:.1f} s, abort "
          f"after {to_abort:.2f} s, surface after {to_surface:.1f} s, floor contacts "
          f"{loop.vehicle.state.floor_contacts}")
    assert to_abort <= 0.5  # the altimeter at 10 Hz and its noise, the monitor at 10 Hz
    assert "critical_altitude" in loop.monitor.reasons[0]
    assert loop.vehicle.state.floor_contacts == 0


def test_a_low_battery_makes_the_vehicle_surface() -> None:
    loop = _start(seed=5, battery_percent=24.0, battery_drain_factor=30.0)
    loop.goal_pose(80.0, 0.0, -6.0)
    crossing = _first(loop, lambda lp: lp.vehicle.state.battery_soc * 100.0 < 19.5, 120.0)  # reported as 19 %
    depth = loop.vehicle.state.depth
    assert crossing is not None and depth > 1.0
    to_abort, to_surface = _emergency_figures(loop, crossing)
    print(f"\nbattery below min_battery_percent at {depth:.1f} m: abort after {to_abort:.2f} s, "
          f"surface after {to_surface:.1f} s")
    assert to_abort <= 1.1  # the battery reports at 1 Hz
    assert loop.monitor.reasons == ("battery 19.0 % below min_battery_percent 20.0 %",)


def test_the_controller_stops_when_the_planner_dies() -> None:
    loop = _start(seed=7)
    loop.goal_pose(100.0, 0.0, -3.0)
    loop.run(20.0)
    assert loop.commands is not None and loop.commands.mode == "follow"
    loop.replanning = False
    died = loop.t
    stopped = _first(loop, lambda lp: lp.commands.mode == "idle", 20.0)
    assert stopped is not None and loop.commands.reason.startswith("stale plan")
    assert stopped - died <= loop.options.controller.plan_timeout + 0.2
    assert loop.vehicle.commands.rpm_1 == 0.0 and loop.vehicle.commands.horizontal_rad == 0.0
    loop.run(30.0)
    assert loop.vehicle.state.u < 0.2  # coasting to rest


def test_refused_goals_leave_the_vehicle_alone() -> None:
    loop = _start(seed=8)
    assert not loop.goal_pose(10.0, 0.0, math.nan).accepted
    assert not loop.goal_pose(10.0, 0.0, -3.0, frame_id="odom").accepted
    loop.run(10.0)
    assert loop.planner.refused == {"not_finite": 1, "frame": 1} and loop.plan is None
    assert loop.vehicle.state.u == 0.0 and loop.vehicle.state.depth == 0.0


def test_a_seed_gives_one_run() -> None:
    def run() -> list:
        loop = _start(seed=9)
        loop.goal_pose(20.0, 5.0, -3.0)
        loop.run(20.0)
        return loop.history

    assert run() == run()


@pytest.mark.parametrize("limits", [MonitorLimits(critical_depth=60.0, critical_altitude=2.0)])
def test_no_false_emergency_on_a_normal_mission(limits: MonitorLimits) -> None:
    loop = _start(seed=10, limits=limits)
    loop.goal_pose(30.0, -20.0, -8.0)
    loop.run(60.0)
    loop.goal_pose(0.0, 0.0, 0.0)  # back to the surface at the start
    loop.run(80.0)
    assert loop.monitor.triggers == 0 and loop.vehicle.state.depth < 0.3
    assert _horizontal_error(loop, 0.0, 0.0) < 3.0
