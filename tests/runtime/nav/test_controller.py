"""The controller's law (runtime/nav/controller.py): the contract's signs, slowing and stopping at the goal, and the
safe stop with no pose, no plan, an empty or stale plan, or an abort."""

from __future__ import annotations

import math
import random

import pytest

from sam_runtime.nav.controller import Commands, Controller, ControllerConfig, ControllerPose

LEVEL = ControllerPose(0.0, 0.0, -5.0, 0.0, 0.0, 0.0)  # at 5 m, facing east


def _line(x0: float, y0: float, x1: float, y1: float, z: float, n: int = 20) -> list[tuple[float, float, float]]:
    return [(x0 + (x1 - x0) * i / n, y0 + (y1 - y0) * i / n, z) for i in range(n + 1)]


def _follow(poses: list, pose: ControllerPose = LEVEL, cfg: ControllerConfig | None = None) -> Commands:
    c = Controller(cfg)
    c.set_plan(0.0, poses)
    return c.step(0.1, pose)


def _is_stop(c: Commands, buoyancy: float = 50.0) -> bool:
    return (c.rpm_1, c.rpm_2, c.vertical_rad, c.horizontal_rad, c.ballast_1_rad, c.ballast_2_rad,
            c.longitudinal_weight_pct, c.buoyancy_pct) == (0, 0, 0.0, 0.0, 0.0, 0.0, 50.0, buoyancy)


def test_a_target_to_port_gives_a_positive_horizontal_angle() -> None:
    left = _follow(_line(0, 0, 20, 20, -5.0))  # north-east: to port of an east-facing vehicle
    right = _follow(_line(0, 0, 20, -20, -5.0))
    assert left.mode == "follow" and left.horizontal_rad > 0.0 and right.horizontal_rad < 0.0
    behind = _follow(_line(0, 0, -20, 1, -5.0))
    assert behind.horizontal_rad == pytest.approx(0.12)  # saturated at the mechanical limit
    ahead = _follow(_line(0, 0, 30, 0, -5.0))
    assert ahead.horizontal_rad == pytest.approx(0.0, abs=1e-12) and ahead.rpm_1 == ahead.rpm_2 == 1500


def test_a_deeper_target_sinks_and_pitches_down_a_shallower_one_rises() -> None:
    deeper = _follow(_line(0, 0, 30, 0, -9.0))
    assert deeper.buoyancy_pct < 50.0 and deeper.longitudinal_weight_pct > 50.0  # weight forward: nose down
    assert deeper.vertical_rad < 0.0  # the nozzle pitches the nose down (> 0 is nose up)
    shallower = _follow(_line(0, 0, 30, 0, -1.0))
    assert shallower.buoyancy_pct > 50.0 and shallower.longitudinal_weight_pct < 50.0 and shallower.vertical_rad > 0
    level = _follow(_line(0, 0, 30, 0, -5.0))
    assert level.buoyancy_pct == pytest.approx(50.0) and level.vertical_rad == pytest.approx(0.0)
    # Already nose down (REP-103 pitch > 0) at the right depth: the nozzle lifts the nose.
    nose_down = _follow(_line(0, 0, 30, 0, -5.0), ControllerPose(0.0, 0.0, -5.0, 0.0, 0.3, 0.0))
    assert nose_down.vertical_rad > 0.0


def test_slows_near_the_end_and_stops_at_the_goal() -> None:
    cfg = ControllerConfig(cruise_rpm=1500, min_rpm=500, slow_radius=8.0, goal_tolerance=1.5)
    far = _follow(_line(0, 0, 40, 0, -5.0), cfg=cfg)
    near = _follow(_line(0, 0, 5, 0, -5.0), cfg=cfg)
    close = _follow(_line(0, 0, 2, 0, -5.0), cfg=cfg)
    assert far.rpm_1 == 1500 and 500 < near.rpm_1 < 1500 and close.rpm_1 == 500
    arrived = _follow(_line(-10, 0, 1.0, 0.5, -7.0), cfg=cfg)
    assert arrived.mode == "arrived" and arrived.rpm_1 == arrived.rpm_2 == 0 and arrived.horizontal_rad == 0.0
    assert arrived.buoyancy_pct < 50.0  # still holding the goal's depth (7 m, at 5 m now)
    assert arrived.distance_to_goal == pytest.approx(math.hypot(1.0, 0.5))


def test_arrival_holds_over_replans_of_the_same_goal_until_it_drifts_far() -> None:
    c = Controller(ControllerConfig(goal_tolerance=1.5, rearm_distance=5.0))
    c.set_plan(0.0, _line(-10, 0, 1.0, 0.0, -5.0))
    assert c.step(0.1, LEVEL).mode == "arrived"
    c.set_plan(2.0, _line(3.0, 0, 1.0, 0.0, -5.0))  # replanned from where it coasted to
    assert c.step(2.1, ControllerPose(3.0, 0.0, -5.0, 0.0, 0.0, 0.0)).mode == "arrived"
    assert c.step(2.2, ControllerPose(7.0, 0.0, -5.0, 0.0, 0.0, 0.0)).mode == "follow"
    c.set_plan(3.0, _line(0, 0, 1.0, 20.0, -5.0))  # another goal
    assert c.step(3.1, LEVEL).mode == "follow"


def test_no_pose_no_plan_empty_or_stale_plan_stop_the_vehicle() -> None:
    c = Controller(ControllerConfig(plan_timeout=5.0))
    out = c.step(0.0, LEVEL)
    assert _is_stop(out) and out.mode == "idle" and out.reason == "no plan"
    c.set_plan(1.0, [])
    out = c.step(1.1, LEVEL)
    assert _is_stop(out) and out.reason == "empty plan"
    c.set_plan(2.0, _line(0, 0, 30, 0, -5.0))
    assert c.step(6.9, LEVEL).mode == "follow"
    out = c.step(7.1, LEVEL)
    assert _is_stop(out) and out.reason == "stale plan: 5.1 s old (timeout 5 s)"
    c.set_plan(7.5, _line(0, 0, 30, 0, -5.0))
    assert c.step(7.6, LEVEL).mode == "follow"
    out = c.step(7.7, None)
    assert _is_stop(out) and out.reason == "no pose (world -> base_link unavailable)"
    out = c.step(7.8, ControllerPose(math.nan, 0.0, -5.0, 0.0, 0.0, 0.0))
    assert _is_stop(out)


def test_an_abort_means_full_buoyancy_and_zero_rpm_until_cleared() -> None:
    c = Controller()
    c.set_plan(0.0, _line(0, 0, 30, 0, -8.0))
    c.set_abort(True, "depth 61 m beyond critical_depth 60 m")
    for t in (0.1, 0.2, 30.0):
        out = c.step(t, LEVEL)
        assert _is_stop(out, buoyancy=100.0) and out.mode == "abort"
        assert out.reason == "abort: depth 61 m beyond critical_depth 60 m"
    c.set_plan(31.0, _line(0, 0, 30, 0, -8.0))  # a new plan does not end the abort
    assert c.step(31.1, LEVEL).mode == "abort"
    c.set_abort(False)
    assert c.step(31.2, LEVEL).mode == "follow"
    assert _is_stop(c.step(31.3, None))  # and no pose still stops, with neutral buoyancy


def test_outputs_stay_within_the_contracts_limits() -> None:
    rng = random.Random(9)
    c = Controller()
    for k in range(500):
        if k % 25 == 0:
            c.set_plan(k * 0.1, _line(rng.uniform(-50, 50), rng.uniform(-50, 50), rng.uniform(-50, 50),
                                      rng.uniform(-50, 50), rng.uniform(-60, 0), n=rng.randrange(1, 30)))
        pose = ControllerPose(rng.uniform(-60, 60), rng.uniform(-60, 60), rng.uniform(-60, 0), rng.uniform(-1, 1),
                              rng.uniform(-1.2, 1.2), rng.uniform(-4, 4))
        out = c.step(k * 0.1, pose)
        assert -2000 <= out.rpm_1 <= 2000 and out.rpm_1 == out.rpm_2 and isinstance(out.rpm_1, int)
        assert abs(out.vertical_rad) <= 0.12 and abs(out.horizontal_rad) <= 0.12
        assert 0.0 <= out.buoyancy_pct <= 100.0 and 0.0 <= out.longitudinal_weight_pct <= 100.0
        assert all(math.isfinite(v) for v in (out.vertical_rad, out.horizontal_rad, out.buoyancy_pct))


def test_bad_controller_config_is_refused() -> None:
    with pytest.raises(ValueError, match="lookahead, goal_tolerance and plan_timeout must be > 0"):
        ControllerConfig(plan_timeout=0.0)
    with pytest.raises(ValueError, match="cruise_rpm must be finite"):
        ControllerConfig(cruise_rpm=math.nan)


def test_a_goal_close_behind_is_first_left_behind() -> None:
    """Inside the turning circles a torpedo never reaches it by turning: run straight, then come back."""
    cfg = ControllerConfig(turn_radius=6.0)
    c = Controller(cfg)
    c.set_plan(0.0, _line(0, 0, -4.0, 3.0, -5.0))  # 5 m behind, to port
    out = c.step(0.1, LEVEL)
    assert out.mode == "follow" and out.horizontal_rad == 0.0 and out.rpm_1 == cfg.cruise_rpm
    assert out.reason == "running straight to open the distance to a goal 5.0 m behind"
    out = c.step(0.2, ControllerPose(7.0, 0.0, -5.0, 0.0, 0.0, 0.0))  # 11.4 m away: still opening
    assert out.horizontal_rad == 0.0
    c.set_plan(1.0, _line(8.5, 0, -4.0, 3.0, -5.0))  # replanned from 12.9 m away: turn back now
    out = c.step(1.1, ControllerPose(8.5, 0.0, -5.0, 0.0, 0.0, 0.0))
    assert out.horizontal_rad == pytest.approx(0.12) and out.reason.startswith("following")
    ahead = Controller(cfg)
    ahead.set_plan(0.0, _line(0, 0, 4.0, 3.0, -5.0))  # close but ahead: just steer
    assert ahead.step(0.1, LEVEL).horizontal_rad > 0.0
