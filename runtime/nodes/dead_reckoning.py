"""Dead reckoning (IV.E.1): odom -> base_link on /tf at PUBLISH_HZ from a timer, whatever the sensors' rates.

The inputs feed :class:`sam_runtime.nav.dead_reckoning.DeadReckoning` with the time they arrive on this node's
clock (one clock for inputs and output: the estimate is integrated up to the publication time). /gps_fix is only
watched (the correction from fixes is SLAM's job); its count is on /diagnostics.
"""

from __future__ import annotations

import math
from typing import Any

from sam_nodes.dead_reckoning import DeadReckoningBase

from sam_runtime.nav.dead_reckoning import DeadReckoning as Estimator
from sam_runtime.nav.dead_reckoning import DeadReckoningConfig
from sam_runtime.nodes.common import Level, StatusReporter, guarded_timer, now_s

__all__ = ["PUBLISH_HZ", "DeadReckoning"]

PUBLISH_HZ = 25.0  # >= 20 Hz (IV.E.1), with margin for a loaded machine
INPUT_TIMEOUT_S = 1.0  # an input silent for longer makes the estimate WARN (IMU, magnetometer, pressure)


class DeadReckoning(DeadReckoningBase):
    def __init__(self, *, config: DeadReckoningConfig | None = None, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.estimator = Estimator(config)
        self.published = 0
        self.gps_fixes = 0
        self.status = StatusReporter(self)
        self.timer = guarded_timer(self, 1.0 / PUBLISH_HZ, "publish", self.publish)
        self.status(Level.WARN, "waiting for the IMU, the magnetometer and the pressure")

    def on_imu(self, msg: Any) -> None:
        g, a = msg.angular_velocity, msg.linear_acceleration
        self.estimator.on_imu(now_s(self), (g.x, g.y, g.z), (a.x, a.y, a.z))

    def on_magnetic_field(self, msg: Any) -> None:
        m = msg.magnetic_field
        self.estimator.on_magnetometer(now_s(self), (m.x, m.y, m.z))

    def on_pressure(self, msg: Any) -> None:
        self.estimator.on_pressure(now_s(self), msg.fluid_pressure)

    def on_thruster_1_feedback(self, msg: Any) -> None:
        self.estimator.on_thruster_rpm(now_s(self), 0, msg.rpm)

    def on_thruster_2_feedback(self, msg: Any) -> None:
        self.estimator.on_thruster_rpm(now_s(self), 1, msg.rpm)

    def on_gps_fix(self, msg: Any) -> None:
        self.gps_fixes += 1

    def publish(self) -> None:
        t = now_s(self)
        pose = self.estimator.pose(t)
        ages = self.estimator.input_ages(t)
        silent = [k for k in ("imu", "mag", "pressure") if (age := ages[k]) is None or age > INPUT_TIMEOUT_S]
        refused = {k: v for k, v in self.estimator.counts.items() if k.startswith("refused.")}
        if pose is None:
            self.status(Level.WARN, "waiting for " + ", ".join(silent or ["the first pose"]), **refused)
            return
        self.publish_odom_to_base_link(round(t * 1e9), pose.translation, pose.rotation)
        self.published += 1
        values = dict(x=pose.x, y=pose.y, depth=-pose.z, yaw_deg=math.degrees(pose.yaw),
                      pitch_deg=math.degrees(pose.pitch), speed=pose.speed, published=self.published,
                      gps_fixes_seen=self.gps_fixes, **refused)
        if silent:
            self.status(Level.WARN, "no recent " + ", ".join(silent) + ": the estimate drifts", **values)
        else:
            self.status(Level.OK, f"publishing odom->base_link at {PUBLISH_HZ:g} Hz", **values)
