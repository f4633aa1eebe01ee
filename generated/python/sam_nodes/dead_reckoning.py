# Generated from interfaces.yaml by sam-codegen; do not edit.
"""The ROS 2 interface of node dead_reckoning: Dead reckoning; high-rate pose of base_link in odom from the
IMU, compass, depth and thrusters (IV.E.1).

Write the node as a subclass of ``DeadReckoningBase`` with logic only; topic names, types, QoS, parameters and
frames come from the spec::

    class DeadReckoning(DeadReckoningBase):
        def on_imu(self, msg: Imu) -> None:
            ...

``DeadReckoningBase(*, node_name=None, namespace=None, parameter_overrides=None, frame_prefix=None,
**node_kwargs)``: the node is named ``dead_reckoning`` unless node_name says otherwise; in ``namespace`` (or
an ``__ns`` remap) the spec's relative topic names resolve under it, absolute ones stay; node_kwargs go to
rclpy's Node (context, cli_args, ...); parameter_overrides ({name: value}, spec or ROS names) win over the
node's --params-file values, which win over the spec defaults. A value out of range or breaking a rule raises
sam_runtime.node_support.ParameterConfigError. ``frame_prefix`` (default: the node's namespace, ``sam1/`` in
``/sam1``; ``\"\"`` for none) goes before every frame id the base publishes or looks up; ``self.frame(name)``
gives a spec frame with it.

Subscriptions (override the method; the default counts and drops; a method that raises is counted, logged and
shown on /diagnostics, and the node goes on):
- ``on_imu(msg: Imu)``: /imu (sensor_msgs/Imu), QoS sensor_data (best_effort, volatile, keep last 5). IMU
  samples.
- ``on_magnetic_field(msg: MagneticField)``: /magnetic_field (sensor_msgs/MagneticField), QoS sensor_data
  (best_effort, volatile, keep last 5). Magnetometer samples.
- ``on_pressure(msg: FluidPressure)``: /pressure (sensor_msgs/FluidPressure), QoS sensor_data (best_effort,
  volatile, keep last 5). Water pressure.
- ``on_gps_fix(msg: NavSatFix)``: /gps_fix (sensor_msgs/NavSatFix), QoS sensor_data (best_effort, volatile,
  keep last 5). GPS fixes, at the surface.
- ``on_thruster_1_feedback(msg: ThrusterFeedback)``: /thruster_1/feedback (sam_msgs/ThrusterFeedback), QoS
  sensor_data (best_effort, volatile, keep last 5). Thruster 1 feedback.
- ``on_thruster_2_feedback(msg: ThrusterFeedback)``: /thruster_2/feedback (sam_msgs/ThrusterFeedback), QoS
  sensor_data (best_effort, volatile, keep last 5). Thruster 2 feedback.

Publications:
- none

Parameters (read-only properties with the current value; a change goes through set_parameters or the node's
~/set_parameters service, which refuses a value out of range or one that breaks a rule, naming it):
- none

Transforms:
- ``self.tf`` is None: this node reads no transforms (give it `reads_transforms` in the spec).
- ``publish_odom_to_base_link(stamp, translation, rotation)``: the pose of base_link in odom on /tf (High-rate
  dead reckoning pose (IV.E.1).); stamp in ns, an rclpy Time or a builtin_interfaces/Time; translation (x, y,
  z) [m]; rotation (x, y, z, w), a unit quaternion.

Health: ``report_status(level, message, **values)`` publishes the node's DiagnosticStatus (name = the node's
name) on /diagnostics at once; it is repeated every second with the counters of dropped and failed messages.
level: sam_runtime.node_support.Level (OK, WARN, ERROR, STALE).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from rclpy.node import Node
from sam_msgs.msg import ThrusterFeedback
from sam_runtime import node_support, tf_buffer
from sensor_msgs.msg import FluidPressure, Imu, MagneticField, NavSatFix
from tf2_msgs.msg import TFMessage

NODE_NAME = 'dead_reckoning'

PARAMETERS: tuple[node_support.ParameterSpec, ...] = (
)

# Parameters only other nodes read, which a rule compares with one of this node's (mirrored, not declared).
PARTNERS: tuple[node_support.ParameterSpec, ...] = (
)

RULES: tuple[node_support.RuleSpec, ...] = (
)


class DeadReckoningBase(Node):
    """Node dead_reckoning: subclass it and override the on_* methods (see the module docstring)."""

    def __init__(self, *, node_name: str | None = None, namespace: str | None = None,
                 parameter_overrides: Mapping[str, Any] | None = None, frame_prefix: str | None = None,
                 **node_kwargs: Any) -> None:
        super().__init__(node_name or NODE_NAME, namespace=namespace, **node_kwargs)
        self.frame_prefix = node_support.frame_prefix_of(self, frame_prefix)
        self._gen_support = node_support.NodeSupport(self)
        self._gen_parameters = node_support.declare_parameters(
            self, PARAMETERS, RULES, overrides=parameter_overrides, partners=PARTNERS)
        self.tf: tf_buffer.TfBuffer | None = None
        self._gen_pub_tf = self.create_publisher(
            TFMessage, "/tf", node_support.qos_profile("reliable", "volatile", 100))
        self._gen_sub_imu = self.create_subscription(
            Imu, "/imu",
            self._gen_support.callback("on_imu", self.on_imu),
            node_support.qos_profile("best_effort", "volatile", 5))
        self._gen_sub_magnetic_field = self.create_subscription(
            MagneticField, "/magnetic_field",
            self._gen_support.callback("on_magnetic_field", self.on_magnetic_field),
            node_support.qos_profile("best_effort", "volatile", 5))
        self._gen_sub_pressure = self.create_subscription(
            FluidPressure, "/pressure",
            self._gen_support.callback("on_pressure", self.on_pressure),
            node_support.qos_profile("best_effort", "volatile", 5))
        self._gen_sub_gps_fix = self.create_subscription(
            NavSatFix, "/gps_fix",
            self._gen_support.callback("on_gps_fix", self.on_gps_fix),
            node_support.qos_profile("best_effort", "volatile", 5))
        self._gen_sub_thruster_1_feedback = self.create_subscription(
            ThrusterFeedback, "/thruster_1/feedback",
            self._gen_support.callback("on_thruster_1_feedback", self.on_thruster_1_feedback),
            node_support.qos_profile("best_effort", "volatile", 5))
        self._gen_sub_thruster_2_feedback = self.create_subscription(
            ThrusterFeedback, "/thruster_2/feedback",
            self._gen_support.callback("on_thruster_2_feedback", self.on_thruster_2_feedback),
            node_support.qos_profile("best_effort", "volatile", 5))

    def on_imu(self, msg: Imu) -> None:
        """A message on /imu: override; this default counts and drops it."""
        self._gen_support.unhandled("/imu", "on_imu")

    def on_magnetic_field(self, msg: MagneticField) -> None:
        """A message on /magnetic_field: override; this default counts and drops it."""
        self._gen_support.unhandled("/magnetic_field", "on_magnetic_field")

    def on_pressure(self, msg: FluidPressure) -> None:
        """A message on /pressure: override; this default counts and drops it."""
        self._gen_support.unhandled("/pressure", "on_pressure")

    def on_gps_fix(self, msg: NavSatFix) -> None:
        """A message on /gps_fix: override; this default counts and drops it."""
        self._gen_support.unhandled("/gps_fix", "on_gps_fix")

    def on_thruster_1_feedback(self, msg: ThrusterFeedback) -> None:
        """A message on /thruster_1/feedback: override; this default counts and drops it."""
        self._gen_support.unhandled("/thruster_1/feedback", "on_thruster_1_feedback")

    def on_thruster_2_feedback(self, msg: ThrusterFeedback) -> None:
        """A message on /thruster_2/feedback: override; this default counts and drops it."""
        self._gen_support.unhandled("/thruster_2/feedback", "on_thruster_2_feedback")

    def publish_odom_to_base_link(
        self, stamp: Any, translation: tuple[float, float, float], rotation: tuple[float, float, float, float]
    ) -> None:
        """Publish the pose of base_link in odom on /tf (ValueError for a bad value)."""
        node_support.publish_transform(
            self._gen_pub_tf, self.frame("odom"), self.frame("base_link"), stamp, translation,
            rotation)

    def frame(self, name: str) -> str:
        """A spec frame id as this node writes and looks it up: with the frame prefix (empty stays empty)."""
        return f"{self.frame_prefix}{name}" if name else name

    def report_status(self, level: int, message: str, **values: Any) -> None:
        """Publish this node's DiagnosticStatus on /diagnostics now (repeated every second until the next)."""
        self._gen_support.report(level, message, values)
