"""The controller's law (document IV.G): follow a path given the pose world -> base_link.

- Heading: pure pursuit. The target is the point ``lookahead`` metres further along the path than the point
  closest to the vehicle; the horizontal thrust-vector angle turns toward it (> 0 yaws to port) with yaw-rate
  damping.
- Depth: the buoyancy piston (works at any speed): toward a desired depth rate proportional to the depth error of
  the lookahead point (bounded by ``max_depth_rate``), plus a proportional and a small integral term. While
  moving, also the pitch: a desired pitch toward the target depth, reached with the vertical thrust-vector angle
  (> 0 pitches the nose up) and held with the longitudinal weight (a feed-forward of the trim moment the desired
  pitch needs).
- A goal behind the vehicle and closer than two turning radii lies inside its turning circles (SAM cannot turn on
  the spot): the vehicle first runs straight until it is that far, then turns back toward it.
- Speed: both thrusters at ``cruise_rpm``, slowing within ``slow_radius`` of the path's end, zero within
  ``goal_tolerance`` (arrived; the depth is still held).
- No pose, no plan, an empty plan, a plan older than ``plan_timeout``: zero RPM, neutral angles and weights,
  neutral buoyancy. An abort: the same with buoyancy 100 % (emergency ascent), until the abort is cleared.

Pitch and rates follow REP-103 (pitch > 0: nose down). Times are seconds passed in; rates are estimated from
successive poses.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import cast

from sam_runtime.physics.geo import euler_from_quaternion, wrap_angle

__all__ = ["Commands", "Controller", "ControllerConfig", "ControllerPose"]

PathPose = tuple[float, ...]  # x, y, z (world, z = -depth) [, qx, qy, qz, qw]
_Point = tuple[float, float, float]


@dataclass(frozen=True)
class ControllerConfig:
    cruise_rpm: float = 1500.0
    min_rpm: float = 500.0  # the slowest approach before arriving
    max_rpm: float = 2000.0
    lookahead: float = 4.0  # [m]
    slow_radius: float = 8.0  # [m] from the end of the path
    goal_tolerance: float = 1.5  # [m], horizontal
    rearm_distance: float = 5.0  # [m] once arrived, drifting this far from the same goal resumes following
    turn_radius: float = 6.0  # [m] about SAM's at cruise; a goal behind closer than twice this is approached
    #                           after running straight to open the distance (it is inside the turning circles)
    plan_timeout: float = 10.0  # [s] a plan older than this is stale
    max_vector_angle: float = 0.12  # [rad]
    heading_gain: float = 0.4  # [rad of nozzle per rad of heading error]
    yaw_rate_gain: float = 0.4  # [rad of nozzle per rad/s]
    depth_gain: float = 4.0  # buoyancy [% per m of depth error]
    depth_rate_gain: float = 120.0  # [% per m/s of depth-rate error]
    depth_rate_per_error: float = 0.2  # desired depth rate [m/s per m of depth error]
    max_depth_rate: float = 0.3  # [m/s]
    depth_integral_gain: float = 0.2  # [% per m s], integrating only within depth_integral_band
    depth_integral_band: float = 1.0  # [m]
    depth_integral_limit: float = 5.0  # [%]
    pitch_per_depth_error: float = 0.15  # desired pitch [rad per m of depth error], while moving
    max_pitch: float = 0.35  # [rad]
    pitch_gain: float = 0.5  # vertical nozzle [rad per rad of pitch error]
    pitch_rate_gain: float = 0.3  # [rad per rad/s]
    trim_feedforward: float = 110.0  # longitudinal weight [% per unit sin(desired pitch)] (righting / trim)
    rate_filter: float = 0.3  # time constant of the rate estimates [s]

    def __post_init__(self) -> None:
        for name, v in self.__dict__.items():
            if not math.isfinite(v):
                raise ValueError(f"{name} must be finite, got {v}")
        if self.lookahead <= 0.0 or self.goal_tolerance <= 0.0 or self.plan_timeout <= 0.0:
            raise ValueError("lookahead, goal_tolerance and plan_timeout must be > 0")


@dataclass(frozen=True)
class ControllerPose:
    """world -> base_link: position (z = -depth) and REP-103 attitude."""

    x: float
    y: float
    z: float
    roll: float
    pitch: float
    yaw: float

    @classmethod
    def from_transform(cls, translation: tuple[float, float, float],
                       rotation: tuple[float, float, float, float]) -> ControllerPose:
        """From a TF lookup of world -> base_link (translation, quaternion (x, y, z, w)).

        >>> ControllerPose.from_transform((1.0, 2.0, -3.0), (0.0, 0.0, 0.0, 1.0))
        ControllerPose(x=1.0, y=2.0, z=-3.0, roll=0.0, pitch=0.0, yaw=0.0)
        """
        roll, pitch, yaw = euler_from_quaternion(rotation)
        return cls(float(translation[0]), float(translation[1]), float(translation[2]), roll, pitch, yaw)


@dataclass(frozen=True)
class Commands:
    """The five command topics' values, within the contract's limits."""

    rpm_1: int
    rpm_2: int
    vertical_rad: float  # /thruster_angles thruster_vertical_radians (> 0 nose up)
    horizontal_rad: float  # thruster_horizontal_radians (> 0 yaw to port)
    ballast_1_rad: float  # /ballast_angles
    ballast_2_rad: float
    longitudinal_weight_pct: float  # /longitudinal_weight_position
    buoyancy_pct: float  # /buoyancy_piston_position
    mode: str  # follow, arrived, idle, abort
    reason: str
    target: tuple[float, float, float] | None = None  # the lookahead point (world) while following
    distance_to_goal: float | None = None  # [m], horizontal, to the path's last pose


def _stop(mode: str, reason: str, buoyancy: float = 50.0) -> Commands:
    return Commands(0, 0, 0.0, 0.0, 0.0, 0.0, 50.0, buoyancy, mode, reason)


def _clamp(v: float, lim: float) -> float:
    return max(-lim, min(lim, v))


class Controller:
    """``set_plan``/``set_abort`` from the topics; ``step(t, pose)`` at the control rate gives the commands."""

    def __init__(self, config: ControllerConfig | None = None) -> None:
        self.config = config or ControllerConfig()
        self.path: tuple[PathPose, ...] = ()
        self.plan_stamp: float | None = None
        self.abort_active = False
        self.abort_reason = ""
        self._index = 0  # the closest path segment so far (the search only moves forward)
        self._prev: tuple[float, ControllerPose] | None = None
        self._rates = (0.0, 0.0, 0.0)  # depth rate [m/s, + down], pitch rate, yaw rate [rad/s]
        self._integral = 0.0
        self._last_integral_t: float | None = None
        self._arrived_at: tuple[float, float] | None = None  # the goal reached (kept over replans of it)
        self._opening = False  # running straight away from a goal inside the turning circles

    # ---------------------------------------------------------------------------------- inputs
    def set_plan(self, stamp: float, poses: Sequence[PathPose]) -> None:
        """A new path (world, z = -depth), received (or stamped) at ``stamp``. An empty path stops the vehicle."""
        self.path = tuple(tuple(float(c) for c in p[:3]) for p in poses)
        self.plan_stamp = stamp
        self._index = 0

    def set_abort(self, active: bool, reason: str = "") -> None:
        self.abort_active = bool(active)
        self.abort_reason = reason if active else ""

    # ---------------------------------------------------------------------------------- law
    def _update_rates(self, t: float, pose: ControllerPose) -> None:
        if self._prev is not None:
            t0, p0 = self._prev
            dt = t - t0
            if 0.0 < dt <= 1.0:
                a = min(1.0, dt / self.config.rate_filter)
                raw = ((p0.z - pose.z) / dt, (pose.pitch - p0.pitch) / dt, wrap_angle(pose.yaw - p0.yaw) / dt)
                self._rates = cast(_Point, tuple(r + a * (m - r) for r, m in zip(self._rates, raw, strict=True)))
            elif dt > 1.0:
                self._rates = (0.0, 0.0, 0.0)
        self._prev = (t, pose)

    def _lookahead(self, x: float, y: float) -> tuple[tuple[float, float, float], float]:
        """The lookahead point and the along-path distance from the closest point to the end."""
        path, la = self.path, self.config.lookahead
        if len(path) == 1:
            return cast(_Point, path[0]), math.hypot(path[0][0] - x, path[0][1] - y)
        best, best_d, best_f = self._index, math.inf, 0.0
        for i in range(self._index, len(path) - 1):
            (ax, ay, _), (bx, by, _) = path[i], path[i + 1]
            sx, sy = bx - ax, by - ay
            ll = sx * sx + sy * sy
            f = 0.0 if ll == 0.0 else max(0.0, min(1.0, ((x - ax) * sx + (y - ay) * sy) / ll))
            d = math.hypot(ax + f * sx - x, ay + f * sy - y)
            if d < best_d:
                best, best_d, best_f = i, d, f
        self._index = best
        seg_len = [math.hypot(path[i + 1][0] - path[i][0], path[i + 1][1] - path[i][1]) for i in range(len(path) - 1)]
        remaining = seg_len[best] * (1.0 - best_f) + sum(seg_len[best + 1:])
        # Walk `la` forward from the closest point.
        i, f, left = best, best_f, la
        while i < len(path) - 1:
            step = seg_len[i] * (1.0 - f)
            if step >= left and seg_len[i] > 0.0:
                f += left / seg_len[i]
                a, b = path[i], path[i + 1]
                return (a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1]), a[2] + f * (b[2] - a[2])), remaining
            left -= step
            i, f = i + 1, 0.0
        return cast(_Point, path[-1]), remaining

    def step(self, t: float, pose: ControllerPose | None) -> Commands:
        cfg = self.config
        if self.abort_active:
            self._integral = 0.0
            return _stop("abort", f"abort: {self.abort_reason}" if self.abort_reason else "abort", 100.0)
        if pose is None or not all(math.isfinite(v) for v in (pose.x, pose.y, pose.z, pose.roll, pose.pitch,
                                                                 pose.yaw)):
            self._prev = None
            return _stop("idle", "no pose (world -> base_link unavailable)")
        self._update_rates(t, pose)
        if self.plan_stamp is None:
            return _stop("idle", "no plan")
        if not self.path:
            return _stop("idle", "empty plan")
        age = t - self.plan_stamp
        if age > cfg.plan_timeout:
            return _stop("idle", f"stale plan: {age:.1f} s old (timeout {cfg.plan_timeout:g} s)")

        target, remaining = self._lookahead(pose.x, pose.y)
        end = self.path[-1]
        to_goal = math.hypot(end[0] - pose.x, end[1] - pose.y)
        depth, target_depth = -pose.z, -target[2]
        depth_rate, pitch_rate, yaw_rate = self._rates
        if self._arrived_at is not None and math.hypot(self._arrived_at[0] - end[0],
                                                       self._arrived_at[1] - end[1]) > cfg.goal_tolerance:
            self._arrived_at = None  # another goal
        arrived = to_goal <= (cfg.goal_tolerance if self._arrived_at is None else cfg.rearm_distance)
        self._arrived_at = (end[0], end[1]) if arrived else None
        if arrived:
            target_depth = -end[2]

        # Depth through the buoyancy piston: deeper target -> below 50 %.
        err = target_depth - depth
        dt = self._dt(t)
        if abs(err) < cfg.depth_integral_band:  # no wind-up during long dives
            self._integral = _clamp(self._integral + cfg.depth_integral_gain * err * dt, cfg.depth_integral_limit)
        desired_rate = _clamp(cfg.depth_rate_per_error * err, cfg.max_depth_rate)
        buoyancy = (50.0 - cfg.depth_gain * err - cfg.depth_rate_gain * (desired_rate - depth_rate)
                    - self._integral)
        buoyancy = max(0.0, min(100.0, buoyancy))

        if arrived:
            return Commands(0, 0, 0.0, 0.0, 0.0, 0.0, 50.0, buoyancy, "arrived",
                            f"within {cfg.goal_tolerance:g} m of the goal", (end[0], end[1], end[2]), to_goal)

        # Heading: pure pursuit of the lookahead point; a goal close behind is first left behind.
        desired_yaw = math.atan2(target[1] - pose.y, target[0] - pose.x)
        goal_bearing = wrap_angle(math.atan2(end[1] - pose.y, end[0] - pose.x) - pose.yaw)
        opening = self._opening if to_goal < 2.0 * cfg.turn_radius else False
        if not opening and to_goal < 2.0 * cfg.turn_radius and abs(goal_bearing) > math.pi / 2:
            opening = True
        self._opening = opening
        yaw_err = 0.0 if opening else wrap_angle(desired_yaw - pose.yaw)
        horizontal = _clamp(cfg.heading_gain * yaw_err - cfg.yaw_rate_gain * yaw_rate, cfg.max_vector_angle)

        # Speed: cruise, slowing toward the end of the path (not while opening the distance).
        frac = 1.0 if opening or cfg.slow_radius <= 0 else min(1.0, remaining / cfg.slow_radius)
        rpm = max(cfg.min_rpm, cfg.cruise_rpm * frac)
        rpm = round(max(-cfg.max_rpm, min(cfg.max_rpm, rpm)))

        # Pitch toward the target depth (REP-103: > 0 nose down), held by the trim weight, steered by the nozzle.
        desired_pitch = _clamp(cfg.pitch_per_depth_error * err, cfg.max_pitch)
        vertical = _clamp(-cfg.pitch_gain * (desired_pitch - pose.pitch) + cfg.pitch_rate_gain * pitch_rate,
                          cfg.max_vector_angle)
        weight = max(0.0, min(100.0, 50.0 + cfg.trim_feedforward * math.sin(desired_pitch)))
        why = (f"running straight to open the distance to a goal {to_goal:.1f} m behind" if opening
               else f"following a path of {len(self.path)} poses")
        return Commands(rpm, rpm, vertical, horizontal, 0.0, 0.0, weight, buoyancy, "follow", why, target, to_goal)

    def _dt(self, t: float) -> float:
        last, self._last_integral_t = self._last_integral_t, t
        return 0.0 if last is None else max(0.0, min(t - last, 1.0))
