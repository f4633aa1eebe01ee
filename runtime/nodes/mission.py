"""Mission (an addition to the document: where the planner's goals come from): publishes a sequence of goals
(:mod:`sam_runtime.nav.mission`) on /nav_goal or /nav_heading and advances on arrival, judged from
world -> base_link.

It starts once the planner subscribes and world -> base_link exists (a goal sent into nothing would be lost:
the goal topics are volatile), and sends the current goal again every REPUBLISH_S (a planner that restarted gets
it back; an unchanged goal does not disturb one that did not).
"""

from __future__ import annotations

import math
from typing import Any

from sam_nodes.mission import MissionBase

from sam_runtime.nav.mission import DEMO_MISSION, MissionGoal, arrived
from sam_runtime.nodes.common import Level, StatusReporter, guarded_timer, now_s
from sam_runtime.tf_buffer import TfError

__all__ = ["REPUBLISH_S", "Mission"]

TICK_S = 0.2
REPUBLISH_S = 5.0
POSE_MAX_AGE_S = 3.0


class Mission(MissionBase):
    def __init__(self, *, goals: tuple[MissionGoal, ...] | None = None, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.goals = tuple(goals) if goals is not None else DEMO_MISSION
        if not self.goals:
            raise ValueError("a mission needs at least one goal")
        self.index = 0
        self.started_at: float | None = None  # when the current goal was first sent
        self.sent_at = -math.inf
        self.complete = False
        self.distance: float | None = None
        self.depth: float | None = None
        self.status = StatusReporter(self)
        self.timer = guarded_timer(self, TICK_S, "mission", self.tick)
        self.get_logger().info(f"mission of {len(self.goals)} goal(s): "
                               + "; ".join(g.describe() for g in self.goals))
        self.status(Level.OK, "waiting for the motion planner and world -> base_link")

    def _own_topic(self, leaf: str) -> str:
        """The resolved name of this node's publisher whose last segment is ``leaf`` (/nav_goal, or /sam1/nav_goal
        in a namespace when the spec names it relative)."""
        return next((p.topic_name for p in self.publishers if p.topic_name.rsplit("/", 1)[-1] == leaf), "/" + leaf)

    @property
    def goal(self) -> MissionGoal:
        return self.goals[self.index]

    def tick(self) -> None:
        t = now_s(self)
        try:
            tr = self.lookup_world_to_base_link(max_age_s=POSE_MAX_AGE_S)
        except TfError as ex:
            self.status(Level.WARN if self.started_at is not None else Level.OK,
                        "waiting for world -> base_link", problem=str(ex), **self._values(t))
            return
        x, y, z = tr.translation
        self.depth = -z
        goal = self.goal
        if goal.kind == "pose":
            self.distance = math.hypot(goal.x - x, goal.y - y)
        planners = self.count_subscribers(self._own_topic("nav_goal" if goal.kind == "pose" else "nav_heading"))
        if self.started_at is None:
            if planners == 0:
                self.status(Level.OK, "waiting for the motion planner", **self._values(t))
                return
            self._send(t)
        if not self.complete and arrived(goal, x, y, self.depth, t - (self.started_at or t)):
            self.get_logger().info(f"goal {self.index + 1}/{len(self.goals)} reached: {goal.describe()}")
            if self.index + 1 < len(self.goals):
                self.index += 1
                self._send(t)
            else:
                self.complete = True
        elif t - self.sent_at >= REPUBLISH_S:
            self._send(t, again=True)
        if self.complete:
            self.status(Level.OK, f"mission complete ({len(self.goals)} goal(s)); holding the last",
                        **self._values(t))
        else:
            self.status(Level.OK, f"goal {self.index + 1}/{len(self.goals)}: {self.goal.describe()}",
                        **self._values(t))

    def _send(self, t: float, again: bool = False) -> None:
        from geometry_msgs.msg import PoseStamped
        from sam_msgs.msg import HeadingStamped

        g = self.goal
        stamp = self.get_clock().now().to_msg()
        if g.kind == "pose":
            msg = PoseStamped()
            msg.header.stamp, msg.header.frame_id = stamp, self.frame("world")
            msg.pose.position.x, msg.pose.position.y, msg.pose.position.z = g.x, g.y, g.z
            msg.pose.orientation.w = 1.0
            self.publish_nav_goal(msg)
        else:
            heading = HeadingStamped(heading=g.heading, z=g.z)
            heading.header.stamp, heading.header.frame_id = stamp, self.frame("world")
            self.publish_nav_heading(heading)
        if not again:
            self.started_at = t
            self.distance = None
            self.get_logger().info(f"goal {self.index + 1}/{len(self.goals)}: {g.describe()}")
        self.sent_at = t

    def _values(self, t: float) -> dict[str, Any]:
        g = self.goal
        return dict(goal_index=self.index + 1, goals=len(self.goals), goal=g.describe(), goal_kind=g.kind,
                    goal_x=g.x if g.kind == "pose" else None, goal_y=g.y if g.kind == "pose" else None,
                    goal_z=g.z, goal_heading_deg=math.degrees(g.heading) if g.kind == "heading" else None,
                    distance=self.distance, depth=self.depth, complete=self.complete,
                    goal_elapsed_s=None if self.started_at is None else t - self.started_at)
