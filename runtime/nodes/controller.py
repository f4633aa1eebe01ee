"""Controller (IV.G): follows /global_plan with world -> base_link, commanding the five actuator topics at
CONTROL_HZ through :class:`sam_runtime.nav.controller.Controller`.

Zero RPM, neutral angles and weights come out when there is no plan, the plan is empty or older than
``plan_timeout`` (from its stamp), the transforms are stale (world -> odom older than WORLD_MAX_AGE_S, the dead
reckoning's odom -> base_link older than ODOM_MAX_AGE_S) or an abort is active; an abort also commands the
buoyancy piston to 100 % (emergency ascent) until an /abort with active=false arrives. A plan in another frame than
world or with a non-finite pose is refused (counted, the vehicle stops as for an empty plan).
"""

from __future__ import annotations

import math
from typing import Any

from sam_nodes.controller import ControllerBase

from sam_runtime.nav.controller import Commands, ControllerConfig, ControllerPose
from sam_runtime.nav.controller import Controller as Law
from sam_runtime.nav.motion_planner import GOAL_FRAME
from sam_runtime.nodes.common import Level, StatusReporter, guarded_timer, now_s, stamp_s
from sam_runtime.tf_buffer import TfError

__all__ = ["CONTROL_HZ", "Controller"]

CONTROL_HZ = 10.0
ODOM_MAX_AGE_S = 0.5  # the dead reckoning publishes at 25 Hz
WORLD_MAX_AGE_S = 3.0  # SLAM publishes at 2 Hz


class Controller(ControllerBase):
    def __init__(self, *, config: ControllerConfig | None = None, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.law = Law(config)
        self.commands: Commands | None = None
        self.pose_problem = ""
        self.had_pose = False  # before the first pose, a missing one is the start-up, not a fault
        self.plans = 0
        self.plans_refused: dict[str, int] = {}
        self.status = StatusReporter(self)
        self.timer = guarded_timer(self, 1.0 / CONTROL_HZ, "control", self.step)
        self.status(Level.OK, "idle: no plan")

    # ---------------------------------------------------------------------------------- inputs
    def on_global_plan(self, msg: Any) -> None:
        t = now_s(self)
        poses = [(p.pose.position.x, p.pose.position.y, p.pose.position.z) for p in msg.poses]
        refused = ""
        if msg.header.frame_id != self.frame(GOAL_FRAME):
            refused = "frame"
            why = f"plan in frame {msg.header.frame_id!r}, not {self.frame(GOAL_FRAME)!r}"
        elif not all(math.isfinite(v) for pose in poses for v in pose):
            refused = "not_finite"
            why = "plan with a non-finite pose"
        if refused:
            self.plans_refused[refused] = self.plans_refused.get(refused, 0) + 1
            self._gen_support.count(f"plans_refused.{refused}", f"{why}: refused, stopping")
            poses = []  # follow nothing: the vehicle stops, as for an empty plan
        elif not poses:
            self._gen_support.count("plans_empty", "an empty plan: stopping")
        # The plan's age counts from its stamp (never from the future); an unset stamp from its arrival.
        stamp = stamp_s(msg.header.stamp)
        self.law.set_plan(min(stamp, t) if stamp > 0.0 else t, poses)
        self.plans += 1

    def on_abort(self, msg: Any) -> None:
        if bool(msg.active) != self.law.abort_active:
            log = self.get_logger().warning if msg.active else self.get_logger().info
            log(f"abort {'ordered' if msg.active else 'cleared'}: {msg.reason}")
        self.law.set_abort(bool(msg.active), msg.reason)
        self.step()  # at once: an emergency does not wait for the next tick

    # ---------------------------------------------------------------------------------- control
    def pose(self) -> ControllerPose | None:
        assert self.tf is not None
        try:
            now_ns = self.get_clock().now().nanoseconds
            self.tf.lookup(self.frame("odom"), self.frame("base_link"), now_ns=now_ns, max_age_s=ODOM_MAX_AGE_S)
            tr = self.lookup_world_to_base_link(max_age_s=WORLD_MAX_AGE_S)
        except TfError as ex:
            self.pose_problem = str(ex)
            return None
        self.pose_problem = ""
        self.had_pose = True
        return ControllerPose.from_transform(tr.translation, tr.rotation)

    def step(self) -> None:
        c = self.law.step(now_s(self), self.pose())
        self.commands = c
        self.publish_commands(c)
        self.report(c)

    def publish_commands(self, c: Commands) -> None:
        from sam_msgs.msg import BallastAngles, PercentStamped, ThrusterAngles, ThrusterRPMs

        stamp = self.get_clock().now().to_msg()
        rpms = ThrusterRPMs(thruster_1_rpm=int(c.rpm_1), thruster_2_rpm=int(c.rpm_2))
        angles = ThrusterAngles(thruster_vertical_radians=float(c.vertical_rad),
                                thruster_horizontal_radians=float(c.horizontal_rad))
        ballast = BallastAngles(weight_1_offset_radians=float(c.ballast_1_rad),
                                weight_2_offset_radians=float(c.ballast_2_rad))
        weight = PercentStamped(percent=float(c.longitudinal_weight_pct))
        buoyancy = PercentStamped(percent=float(c.buoyancy_pct))
        for msg in (rpms, angles, ballast, weight, buoyancy):
            msg.header.stamp = stamp
            msg.header.frame_id = self.frame("base_link")
        self.publish_thruster_rpms(rpms)
        self.publish_thruster_angles(angles)
        self.publish_ballast_angles(ballast)
        self.publish_longitudinal_weight_position(weight)
        self.publish_buoyancy_piston_position(buoyancy)

    def report(self, c: Commands) -> None:
        values: dict[str, Any] = dict(mode=c.mode, rpm=c.rpm_1, horizontal_rad=c.horizontal_rad,
                                      vertical_rad=c.vertical_rad, buoyancy_pct=c.buoyancy_pct,
                                      longitudinal_weight_pct=c.longitudinal_weight_pct,
                                      distance_to_goal=c.distance_to_goal, plans=self.plans,
                                      **{f"plans_refused.{k}": v for k, v in self.plans_refused.items()})
        if c.mode == "abort":
            level, message = Level.WARN, f"emergency ascent ({c.reason})"
        elif c.mode in ("follow", "arrived"):
            level, message = Level.OK, c.mode if c.mode == "arrived" else "following the plan"
        elif self.pose_problem:
            level = Level.ERROR if self.had_pose else Level.WARN
            message = "stopped: no pose (world -> base_link " + ("stale" if "stale" in self.pose_problem
                                                                  else "unavailable") + ")"
            values["tf_problem"] = self.pose_problem
        elif c.reason.startswith("stale plan") or c.reason == "empty plan":
            level, message = Level.WARN, "stopped: " + c.reason.split(":")[0]
            values["reason"] = c.reason
        else:
            level, message = Level.OK, f"idle: {c.reason}"
        self.status(level, message, **values)
