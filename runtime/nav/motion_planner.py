"""The motion planner's logic (document IV.F): goals, the z convention, the safety clamps and the path geometry.

The z convention of the document (for /nav_goal position.z and /nav_heading z): z < 0 is a target depth -z;
z > 0 a target altitude z above the sea floor; z == 0 the surface. Plans are in world with z = -target depth:
altitude targets become depths through the sea-floor estimate (current depth + current altitude), so they need a
valid altitude; they are re-evaluated at every replan.

Safety: no pose of a plan is deeper than ``safe_depth`` nor closer to the sea floor than ``safe_altitude`` (when
the altitude is known; otherwise only the depth limit applies). A goal beyond is planned at the limit and the plan
says why (``Plan.clamped``). Goals in a frame other than world, or with a non-finite number, are refused with a
reason and counted; they never replace the current goal.

Geometry: a straight line from the current position to the goal with a pose about every ``spacing`` metres,
oriented along the line, the depth ramping from the current depth toward the target at ``max_dive_slope``
(metres of depth per metre of path) and the last pose exactly at the goal and the target depth; for a heading
goal, a line of ``heading_length`` metres ahead along the heading. A plan always has at least one pose.
"""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass

from sam_runtime.physics.geo import quaternion_from_euler

__all__ = ["GOAL_FRAME", "Goal", "GoalDecision", "Plan", "PlanResult", "Planner", "PlannerConfig", "clamp_depth",
           "target_depth_from_z"]

GOAL_FRAME = "world"

PathPose = tuple[float, float, float, float, float, float, float]  # x, y, z, qx, qy, qz, qw (world)


@dataclass(frozen=True)
class Goal:
    kind: str  # "pose" or "heading"
    z: float  # the document's convention
    x: float = math.nan  # pose goals [m, world]
    y: float = math.nan
    heading: float = math.nan  # heading goals [rad, ENU yaw]
    stamp: float = 0.0


@dataclass(frozen=True)
class GoalDecision:
    accepted: bool
    reason: str  # why refused, or "" when accepted
    goal: Goal | None = None


@dataclass(frozen=True)
class Plan:
    stamp: float
    goal: Goal
    poses: tuple[PathPose, ...]  # never empty
    requested_depth: float  # the goal's depth before the clamps [m]
    target_depth: float  # the depth planned [m]
    clamped: tuple[str, ...]  # why the target was limited, one line per limit (empty: not clamped)

    @property
    def frame_id(self) -> str:
        return GOAL_FRAME


@dataclass(frozen=True)
class PlanResult:
    plan: Plan | None
    reason: str  # why there is no plan ("" with a plan)


@dataclass(frozen=True)
class PlannerConfig:
    spacing: float = 1.0  # [m] between poses
    heading_length: float = 50.0  # [m] of line ahead for a heading goal
    max_dive_slope: float = 0.3  # [m depth per m path] of the depth ramp

    def __post_init__(self) -> None:
        for name in ("spacing", "heading_length", "max_dive_slope"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v > 0.0):
                raise ValueError(f"{name} must be finite and > 0, got {v}")


def _altitude_valid(altitude: float | None) -> bool:
    return altitude is not None and math.isfinite(altitude) and altitude >= 0.0


def target_depth_from_z(z: float, depth: float, altitude: float | None) -> tuple[float | None, str]:
    """The depth [m] a goal's z asks for (the document's convention), before the safety clamps; (None, reason)
    when it cannot be known (an altitude target without a valid altitude).

    >>> target_depth_from_z(-8.0, 2.0, None), target_depth_from_z(0.0, 2.0, None)
    ((8.0, ''), (0.0, ''))
    >>> target_depth_from_z(5.0, 2.0, 18.0)  # 5 m above a floor at 20 m
    (15.0, '')
    >>> target_depth_from_z(5.0, 2.0, float('nan'))[0] is None
    True
    """
    if z < 0.0:
        return -z, ""
    if z == 0.0:
        return 0.0, ""
    if not _altitude_valid(altitude):
        return None, f"altitude goal z={z:g} m needs a valid altitude (no bottom lock)"
    assert altitude is not None
    return max(0.0, depth + altitude - z), ""


def clamp_depth(target: float, *, depth: float, altitude: float | None, safe_depth: float,
                safe_altitude: float) -> tuple[float, list[str]]:
    """The target depth within the limits, and one reason per limit that applied.

    >>> clamp_depth(70.0, depth=0.0, altitude=None, safe_depth=50.0, safe_altitude=5.0)
    (50.0, ['goal depth 70.00 m clamped to safe_depth 50.00 m'])
    >>> clamp_depth(18.0, depth=10.0, altitude=10.0, safe_depth=50.0, safe_altitude=5.0)
    (15.0, ['goal depth 18.00 m clamped to 15.00 m: safe_altitude 5.00 m above the sea floor at 20.00 m'])
    """
    reasons = []
    limit = target
    if limit > safe_depth:
        limit = safe_depth
        reasons.append(f"goal depth {target:.2f} m clamped to safe_depth {safe_depth:.2f} m")
    if _altitude_valid(altitude):
        assert altitude is not None
        floor = depth + altitude
        deepest = max(0.0, floor - safe_altitude)
        if limit > deepest:
            reasons.append(f"goal depth {target:.2f} m clamped to {deepest:.2f} m: safe_altitude "
                           f"{safe_altitude:.2f} m above the sea floor at {floor:.2f} m")
            limit = deepest
    return max(0.0, limit), reasons


def _finite(*values: float) -> bool:
    return all(isinstance(v, int | float) and math.isfinite(v) for v in values)


class Planner:
    """Holds the current goal and plans a path for it from the vehicle's current state.

    ``set_pose_goal``/``set_heading_goal`` validate and replace the goal (or refuse it); ``plan(...)`` is called on
    every replan with the vehicle's position in world, its depth and altitude (NaN/None: unknown) and the current
    ``safe_depth``/``safe_altitude``."""

    def __init__(self, config: PlannerConfig | None = None, *, safe_depth: float = 50.0,
                 safe_altitude: float = 5.0, goal_frame: str = GOAL_FRAME) -> None:
        self.config = config or PlannerConfig()
        self.goal_frame = goal_frame  # world as the vehicle names it (with its frame prefix: sam1/world)
        self.safe_depth = safe_depth
        self.safe_altitude = safe_altitude
        self.goal: Goal | None = None
        self.refused: Counter[str] = Counter()  # per reason kind: frame, not_finite

    def _refuse(self, kind: str, reason: str) -> GoalDecision:
        self.refused[kind] += 1
        return GoalDecision(False, reason)

    def _check_frame(self, frame_id: str) -> str:
        return "" if frame_id == self.goal_frame else f"goal frame {frame_id!r} is not {self.goal_frame!r}"

    def set_pose_goal(self, t: float, frame_id: str, x: float, y: float, z: float,
                      orientation: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 1.0)) -> GoalDecision:
        """A /nav_goal: a position in world; z per the document's convention. The orientation is not a target
        (SAM cannot turn on the spot; the path's poses point along the path) but must be finite."""
        why = self._check_frame(frame_id)
        if why:
            return self._refuse("frame", why)
        if not _finite(x, y, z, *orientation):
            return self._refuse("not_finite", f"goal has a non-finite value: position ({x}, {y}, {z}), "
                                              f"orientation {tuple(orientation)}")
        self.goal = Goal("pose", float(z), x=float(x), y=float(y), stamp=t)
        return GoalDecision(True, "", self.goal)

    def set_heading_goal(self, t: float, frame_id: str, heading: float, z: float) -> GoalDecision:
        """A /nav_heading: follow ``heading`` (ENU yaw [rad], in world) at z (the document's convention)."""
        why = self._check_frame(frame_id)
        if why:
            return self._refuse("frame", why)
        if not _finite(heading, z):
            return self._refuse("not_finite", f"heading goal has a non-finite value: heading {heading}, z {z}")
        self.goal = Goal("heading", float(z), heading=float(heading), stamp=t)
        return GoalDecision(True, "", self.goal)

    def clear_goal(self) -> None:
        self.goal = None

    def plan(self, t: float, x: float, y: float, depth: float, altitude: float | None = None,
             yaw: float = 0.0) -> PlanResult:
        """A plan from (x, y) [world] at ``depth`` toward the goal; ``yaw`` orients a path of a single pose."""
        goal = self.goal
        if goal is None:
            return PlanResult(None, "no goal")
        if not _finite(x, y, depth, yaw):
            return PlanResult(None, f"vehicle state not finite: ({x}, {y}, depth {depth}, yaw {yaw})")
        if not (_finite(self.safe_depth, self.safe_altitude) and self.safe_depth >= 0.0 and self.safe_altitude >= 0.0):
            return PlanResult(None, f"invalid limits safe_depth={self.safe_depth} safe_altitude={self.safe_altitude}")
        alt = altitude if _altitude_valid(altitude) else None
        requested, why = target_depth_from_z(goal.z, depth, alt)
        if requested is None:
            return PlanResult(None, why)
        target, clamped = clamp_depth(requested, depth=depth, altitude=alt, safe_depth=self.safe_depth,
                                      safe_altitude=self.safe_altitude)
        deepest = clamp_depth(math.inf, depth=depth, altitude=alt, safe_depth=self.safe_depth,
                              safe_altitude=self.safe_altitude)[0]
        if goal.kind == "pose":
            gx, gy = goal.x, goal.y
        else:
            gx = x + self.config.heading_length * math.cos(goal.heading)
            gy = y + self.config.heading_length * math.sin(goal.heading)
        poses = self._line(x, y, depth, gx, gy, target, deepest, yaw)
        if not poses:  # unreachable by construction; never hand out an empty plan
            return PlanResult(None, "empty path")
        return PlanResult(Plan(t, goal, tuple(poses), requested, target, tuple(clamped)), "")

    def _line(self, x: float, y: float, depth: float, gx: float, gy: float, target: float, deepest: float,
              yaw: float) -> list[PathPose]:
        length = math.hypot(gx - x, gy - y)
        heading = math.atan2(gy - y, gx - x) if length > 1e-6 else yaw
        q = quaternion_from_euler(0.0, 0.0, heading)
        n = math.ceil(length / self.config.spacing) if length > 1e-6 else 0
        poses = []
        for i in range(n + 1):
            f = i / n if n else 1.0
            s = f * length
            if i == n:
                d = target
            else:
                ramp = self.config.max_dive_slope * s
                d = depth + max(-ramp, min(ramp, target - depth))
            d = max(0.0, min(d, deepest))
            poses.append((x + f * (gx - x), y + f * (gy - y), -d, *q))
        return poses
