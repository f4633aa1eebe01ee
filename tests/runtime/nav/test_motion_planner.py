"""The motion planner's logic (runtime/nav/motion_planner.py): the document's z convention, the safety clamps, refused
goals, and the path geometry."""

from __future__ import annotations

import itertools
import math

import pytest

from sam_runtime.nav.motion_planner import Planner, PlannerConfig, clamp_depth, target_depth_from_z
from sam_runtime.physics.geo import euler_from_quaternion


@pytest.mark.parametrize(("z", "depth", "altitude", "expected"), [
    (-8.0, 0.0, None, 8.0),  # z < 0: a depth
    (-8.0, 3.0, 10.0, 8.0),
    (0.0, 5.0, 10.0, 0.0),  # the surface
    (4.0, 6.0, 10.0, 12.0),  # z > 0: 4 m above a floor at 16 m
    (20.0, 6.0, 10.0, 0.0),  # more than the water column: the surface
])
def test_z_convention(z: float, depth: float, altitude: float | None, expected: float) -> None:
    assert target_depth_from_z(z, depth, altitude) == (expected, "")


@pytest.mark.parametrize("altitude", [None, math.nan, math.inf, -1.0])
def test_an_altitude_goal_needs_a_valid_altitude(altitude: float | None) -> None:
    depth, why = target_depth_from_z(3.0, 5.0, altitude)
    assert depth is None and why == "altitude goal z=3 m needs a valid altitude (no bottom lock)"
    p = Planner()
    assert p.set_pose_goal(0.0, "world", 10.0, 0.0, 3.0).accepted
    res = p.plan(1.0, 0.0, 0.0, 5.0, altitude)
    assert res.plan is None and res.reason == why


def test_clamps_at_safe_depth_and_safe_altitude() -> None:
    assert clamp_depth(10.0, depth=0.0, altitude=None, safe_depth=50.0, safe_altitude=5.0) == (10.0, [])
    d, why = clamp_depth(70.0, depth=2.0, altitude=None, safe_depth=50.0, safe_altitude=5.0)
    assert d == 50.0 and why == ["goal depth 70.00 m clamped to safe_depth 50.00 m"]
    d, why = clamp_depth(70.0, depth=2.0, altitude=28.0, safe_depth=50.0, safe_altitude=5.0)  # floor at 30 m
    assert d == 25.0 and why == ["goal depth 70.00 m clamped to safe_depth 50.00 m",
                                 "goal depth 70.00 m clamped to 25.00 m: safe_altitude 5.00 m above the sea floor at "
                                 "30.00 m"]
    d, why = clamp_depth(3.0, depth=1.0, altitude=2.0, safe_depth=50.0, safe_altitude=5.0)  # 3 m of water
    assert d == 0.0 and len(why) == 1  # shallower than safe_altitude: stay at the surface
    d, why = clamp_depth(40.0, depth=1.0, altitude=math.nan, safe_depth=50.0, safe_altitude=5.0)
    assert (d, why) == (40.0, [])  # unknown altitude: the depth limit only


def test_a_deeper_goal_is_planned_at_the_limit_and_says_so() -> None:
    p = Planner(safe_depth=8.0, safe_altitude=5.0)
    assert p.set_pose_goal(0.0, "world", 30.0, 0.0, -20.0).accepted
    plan = p.plan(1.0, 0.0, 0.0, 0.0, 24.0).plan
    assert plan is not None
    assert plan.requested_depth == 20.0 and plan.target_depth == 8.0
    assert plan.clamped == ("goal depth 20.00 m clamped to safe_depth 8.00 m",)
    assert all(-pose[2] <= 8.0 for pose in plan.poses) and plan.poses[-1][2] == -8.0
    # The sea floor rises: the next replan keeps safe_altitude above it, from the current depth and altitude.
    plan = p.plan(2.0, 20.0, 0.0, 7.0, 5.0).plan  # floor at 12 m
    assert plan is not None and plan.target_depth == 7.0
    assert all(-pose[2] <= 7.0 + 1e-12 for pose in plan.poses)
    assert "safe_altitude 5.00 m above the sea floor at 12.00 m" in plan.clamped[-1]
    # Already deeper than the limit (the limit was lowered): every pose of the new plan is within it.
    p.safe_depth = 4.0
    plan = p.plan(3.0, 20.0, 0.0, 7.0, 5.0).plan
    assert plan is not None and max(-pose[2] for pose in plan.poses) == 4.0


@pytest.mark.parametrize(("frame", "xyz", "orientation", "kind", "reason"), [
    ("map", (1.0, 2.0, -3.0), (0, 0, 0, 1), "frame", "goal frame 'map' is not 'world'"),
    ("", (1.0, 2.0, -3.0), (0, 0, 0, 1), "frame", "goal frame '' is not 'world'"),
    ("world", (math.nan, 2.0, -3.0), (0, 0, 0, 1), "not_finite",
     "goal has a non-finite value: position (nan, 2.0, -3.0)"),
    ("world", (1.0, 2.0, math.inf), (0, 0, 0, 1), "not_finite", "goal has a non-finite value"),
    ("world", (1.0, 2.0, -3.0), (0, 0, math.nan, 1), "not_finite", "orientation (0, 0, nan, 1)"),
])
def test_bad_goals_are_refused_with_a_reason_and_counted(frame: str, xyz: tuple, orientation: tuple, kind: str,
                                                         reason: str) -> None:
    p = Planner()
    assert p.set_pose_goal(0.0, "world", 5.0, 5.0, -2.0).accepted
    d = p.set_pose_goal(1.0, frame, *xyz, orientation=orientation)
    assert not d.accepted and reason in d.reason and d.goal is None
    assert p.refused == {kind: 1}
    assert p.goal is not None and (p.goal.x, p.goal.y) == (5.0, 5.0)  # the previous goal stays


def test_bad_heading_goals_are_refused() -> None:
    p = Planner()
    assert not p.set_heading_goal(0.0, "world", math.nan, -3.0).accepted
    assert not p.set_heading_goal(0.0, "odom", 1.0, -3.0).accepted
    assert not p.set_heading_goal(0.0, "world", 1.0, -math.inf).accepted
    assert p.refused == {"not_finite": 2, "frame": 1} and p.goal is None
    assert p.plan(0.0, 0.0, 0.0, 0.0).reason == "no goal"


def test_pose_goal_path_geometry() -> None:
    p = Planner(PlannerConfig(spacing=1.0, max_dive_slope=0.3))
    p.set_pose_goal(0.0, "world", 13.0, -7.0, -4.0)
    plan = p.plan(1.0, 1.0, 2.0, 0.5, 20.0).plan
    assert plan is not None and plan.frame_id == "world" and plan.stamp == 1.0 and plan.clamped == ()
    poses = plan.poses
    length = math.hypot(12.0, -9.0)  # 15 m
    assert len(poses) == 16  # a pose every metre, both ends included
    assert poses[0][:3] == pytest.approx((1.0, 2.0, -0.5)) and poses[-1][:3] == pytest.approx((13.0, -7.0, -4.0))
    steps = [math.dist(a[:2], b[:2]) for a, b in itertools.pairwise(poses)]
    assert all(s == pytest.approx(length / 15) for s in steps)
    heading = math.atan2(-9.0, 12.0)
    for pose in poses:
        roll, pitch, yaw = euler_from_quaternion(pose[3:])
        assert (roll, pitch, yaw) == pytest.approx((0.0, 0.0, heading), abs=1e-9)
    # The depth ramps down at no more than 0.3 m per metre (3.5 m over 11.7 m), then holds the target.
    depths = [-pose[2] for pose in poses]
    assert all(b >= a and b - a <= 0.3 * length / 15 + 1e-9 for a, b in itertools.pairwise(depths))
    assert depths[12:] == [4.0] * 4 and depths[11] < 4.0
    # A goal too steep for the ramp still ends at its depth.
    p.set_pose_goal(2.0, "world", 5.0, 2.0, -10.0)
    plan = p.plan(3.0, 1.0, 2.0, 0.5, 20.0).plan
    assert plan is not None and [-pose[2] for pose in plan.poses] == pytest.approx([0.5, 0.8, 1.1, 1.4, 10.0])


def test_heading_goal_is_a_line_ahead_from_the_current_position() -> None:
    p = Planner(PlannerConfig(heading_length=30.0))
    assert p.set_heading_goal(0.0, "world", math.radians(135), -4.0).accepted
    plan = p.plan(2.0, 10.0, 5.0, 4.0, None).plan
    assert plan is not None and len(plan.poses) == 31
    end = plan.poses[-1]
    h = math.radians(135)
    assert end[:2] == pytest.approx((10.0 + 30.0 * math.cos(h), 5.0 + 30.0 * math.sin(h)))
    assert all(pose[2] == -4.0 for pose in plan.poses)
    assert euler_from_quaternion(end[3:])[2] == pytest.approx(math.radians(135))
    # Replanned later from where the vehicle is.
    plan = p.plan(5.0, 0.0, 0.0, 4.0, None).plan
    assert plan is not None and plan.poses[0][:2] == (0.0, 0.0)


def test_a_goal_at_the_current_position_gives_one_pose_never_an_empty_path() -> None:
    p = Planner()
    p.set_pose_goal(0.0, "world", 3.0, 4.0, -2.0)
    plan = p.plan(1.0, 3.0, 4.0, 0.0, None, yaw=1.0).plan
    assert plan is not None and len(plan.poses) == 1
    assert plan.poses[0][:3] == (3.0, 4.0, -2.0) and euler_from_quaternion(plan.poses[0][3:])[2] == pytest.approx(1.0)


def test_no_plan_from_an_unknown_vehicle_state() -> None:
    p = Planner()
    p.set_pose_goal(0.0, "world", 3.0, 4.0, -2.0)
    res = p.plan(1.0, math.nan, 0.0, 0.0)
    assert res.plan is None and res.reason.startswith("vehicle state not finite")


@pytest.mark.parametrize("field", ["spacing", "heading_length", "max_dive_slope"])
def test_bad_planner_config_is_refused(field: str) -> None:
    with pytest.raises(ValueError, match=f"{field} must be finite and > 0"):
        PlannerConfig(**{field: 0.0})
