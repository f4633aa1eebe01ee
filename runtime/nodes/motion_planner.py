"""Motion planner (IV.F): /nav_goal or /nav_heading -> nav_msgs/Path on /global_plan.

The geometry, the z convention and the safety clamps are :class:`sam_runtime.nav.motion_planner.Planner`'s. This node
replans every REPLAN_PERIOD_S from world -> base_link, at once on a new goal and on a change of safe_depth or
safe_altitude. A goal in another frame than world or with a non-finite number is refused: logged with its reason,
counted (``refused.<kind>`` on /diagnostics) and the current goal is kept. A plan whose target was limited by
safe_depth or safe_altitude says so on /diagnostics (WARN, ``clamped``). An empty path is never published.
"""

from __future__ import annotations

import math
import time
from dataclasses import replace
from typing import Any

from sam_nodes.motion_planner import MotionPlannerBase

from sam_runtime.nav.controller import ControllerPose
from sam_runtime.nav.motion_planner import GOAL_FRAME, Goal, Plan, Planner, PlannerConfig
from sam_runtime.nodes.common import Level, StatusReporter, guarded_timer, now_s
from sam_runtime.tf_buffer import TfError, TfStale

__all__ = ["REPLAN_PERIOD_S", "MotionPlanner"]

REPLAN_PERIOD_S = 2.0  # "the planner is expected to run every few seconds" (IV.F)
TICK_S = 0.25
POSE_MAX_AGE_S = 3.0  # world -> base_link: SLAM publishes world -> odom at 2 Hz
ALTITUDE_MAX_AGE_S = 2.0  # an older altimeter reading counts as no bottom lock
REFUSAL_WARN_S = 10.0  # a refused goal keeps the status at WARN this long


def _goal_text(plan: Plan) -> str:
    g = plan.goal
    where = (f"pose goal ({g.x:.1f}, {g.y:.1f})" if g.kind == "pose"
             else f"heading goal {math.degrees(g.heading):.0f} deg")
    return f"{where} at depth {plan.target_depth:.2f} m"


class MotionPlanner(MotionPlannerBase):
    def __init__(self, *, config: PlannerConfig | None = None, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.planner = Planner(config, safe_depth=self.safe_depth, safe_altitude=self.safe_altitude,
                               goal_frame=self.frame(GOAL_FRAME))
        self.altitude = (math.nan, -math.inf)  # (range, time received)
        self.plan: Plan | None = None
        self.published = 0
        self.next_replan = math.inf
        self.last_refusal: tuple[float, str] | None = None  # (monotonic time, reason)
        self.last_problem = ""
        self.tf_problem = ""
        self.status = StatusReporter(self)
        self.add_post_set_parameters_callback(self._on_parameters)
        self.timer = guarded_timer(self, TICK_S, "replan", self.tick)
        self.status(Level.OK, "no goal")

    # ---------------------------------------------------------------------------------- inputs
    def on_nav_goal(self, msg: Any) -> None:
        p, q = msg.pose.position, msg.pose.orientation
        before = self.planner.goal
        self._decided(self.planner.set_pose_goal(now_s(self), msg.header.frame_id, p.x, p.y, p.z,
                                                 (q.x, q.y, q.z, q.w)), "/nav_goal", before)

    def on_nav_heading(self, msg: Any) -> None:
        before = self.planner.goal
        self._decided(self.planner.set_heading_goal(now_s(self), msg.header.frame_id, msg.heading, msg.z),
                      "/nav_heading", before)

    def on_altitude(self, msg: Any) -> None:
        self.altitude = (float(msg.range), now_s(self))

    def _on_parameters(self, _params: list[Any]) -> None:
        if self.planner.goal is not None:
            self.next_replan = 0.0  # the new limits at the next tick

    def _decided(self, decision: Any, topic: str, before: Goal | None) -> None:
        if decision.accepted:
            if before is not None and replace(before, stamp=0.0) == replace(decision.goal, stamp=0.0):
                return  # the same goal sent again (a mission repeats its goal): the plan goes on
            self.get_logger().info(f"new goal from {topic}: {decision.goal}")
            self.next_replan = 0.0
            self.tick()
            return
        self.last_refusal = (time.monotonic(), decision.reason)
        self.get_logger().warning(f"goal on {topic} refused: {decision.reason} "
                                  f"({sum(self.planner.refused.values())} refused so far)")
        self.tick(report_only=True)

    # ---------------------------------------------------------------------------------- planning
    def tick(self, report_only: bool = False) -> None:
        t = now_s(self)
        if not report_only and self.planner.goal is not None and t >= self.next_replan:
            self.next_replan = t + REPLAN_PERIOD_S
            self.replan(t)
        self.report()

    def replan(self, t: float) -> None:
        try:
            pose = ControllerPose.from_transform(*self._world_pose())
        except TfError as ex:  # the message stays stable (it is the status message); the details are a value
            self.last_problem = f"no plan: world -> base_link {'stale' if isinstance(ex, TfStale) else 'unavailable'}"
            self.tf_problem = str(ex)
            return
        self.tf_problem = ""
        altitude, at = self.altitude
        if t - at > ALTITUDE_MAX_AGE_S:
            altitude = math.nan
        self.planner.safe_depth, self.planner.safe_altitude = self.safe_depth, self.safe_altitude
        result = self.planner.plan(t, pose.x, pose.y, -pose.z, altitude, pose.yaw)
        if result.plan is None or not result.plan.poses:
            self.last_problem = f"no plan: {result.reason or 'empty path'}"
            return
        self.last_problem = ""
        if result.plan.clamped and (self.plan is None or self.plan.clamped != result.plan.clamped):
            self.get_logger().warning("; ".join(result.plan.clamped))
        self.plan = result.plan
        self.publish_global_plan(self._path_message(result.plan))
        self.published += 1

    def _world_pose(self) -> tuple[tuple[float, float, float], tuple[float, float, float, float]]:
        tr = self.lookup_world_to_base_link(max_age_s=POSE_MAX_AGE_S)
        return tr.translation, tr.rotation

    def _path_message(self, plan: Plan) -> Any:
        from geometry_msgs.msg import PoseStamped
        from nav_msgs.msg import Path

        path = Path()
        path.header.stamp = self.get_clock().now().to_msg()
        path.header.frame_id = self.frame(plan.frame_id)
        for x, y, z, qx, qy, qz, qw in plan.poses:
            ps = PoseStamped()
            ps.header = path.header
            ps.pose.position.x, ps.pose.position.y, ps.pose.position.z = x, y, z
            o = ps.pose.orientation
            o.x, o.y, o.z, o.w = qx, qy, qz, qw
            path.poses.append(ps)
        return path

    # ---------------------------------------------------------------------------------- health
    def report(self) -> None:
        refused = {f"refused.{k}": v for k, v in sorted(self.planner.refused.items())}
        recent = self.last_refusal is not None and time.monotonic() - self.last_refusal[0] < REFUSAL_WARN_S
        values: dict[str, Any] = dict(refused=sum(self.planner.refused.values()), **refused,
                                      last_refused=None if self.last_refusal is None else self.last_refusal[1],
                                      safe_depth=self.safe_depth, safe_altitude=self.safe_altitude,
                                      tf_problem=self.tf_problem or None,
                                      plans_published=self.published)
        plan = self.plan
        if plan is not None:
            end = plan.poses[-1]
            values.update(poses=len(plan.poses), length_m=math.dist(plan.poses[0][:2], end[:2]),
                          requested_depth=plan.requested_depth, target_depth=plan.target_depth,
                          clamped="; ".join(plan.clamped) or "no", goal_kind=plan.goal.kind)
        if self.planner.goal is None:
            level, message = Level.OK, "no goal"
        elif plan is None:
            level, message = Level.WARN, self.last_problem or "no plan yet"
        else:
            level, message = Level.OK, "planning to " + _goal_text(plan)
            if plan.clamped:
                level, message = Level.WARN, message + ": " + "; ".join(plan.clamped)
            if self.last_problem:
                level, message = Level.WARN, f"{message}; {self.last_problem}"
        if recent:
            assert self.last_refusal is not None
            level, message = max(level, Level.WARN), f"{message}; goal refused: {self.last_refusal[1]}"
        self.status(level, message, **values)
