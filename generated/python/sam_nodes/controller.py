# Generated from interfaces.yaml by sam-codegen; do not edit.
"""The ROS 2 interface of node controller: Follows the planned path by commanding the actuators; obeys an
abort (IV.G).

Write the node as a subclass of ``ControllerBase`` with logic only; topic names, types, QoS, parameters and
frames come from the spec::

    class Controller(ControllerBase):
        def on_global_plan(self, msg: Path) -> None:
            ...

``ControllerBase(*, node_name=None, namespace=None, parameter_overrides=None, frame_prefix=None,
**node_kwargs)``: the node is named ``controller`` unless node_name says otherwise; in ``namespace`` (or an
``__ns`` remap) the spec's relative topic names resolve under it, absolute ones stay; node_kwargs go to
rclpy's Node (context, cli_args, ...); parameter_overrides ({name: value}, spec or ROS names) win over the
node's --params-file values, which win over the spec defaults. A value out of range or breaking a rule raises
sam_runtime.node_support.ParameterConfigError. ``frame_prefix`` (default: the node's namespace, ``sam1/`` in
``/sam1``; ``\"\"`` for none) goes before every frame id the base publishes or looks up; ``self.frame(name)``
gives a spec frame with it.

Subscriptions (override the method; the default counts and drops; a method that raises is counted, logged and
shown on /diagnostics, and the node goes on):
- ``on_global_plan(msg: Path)``: /global_plan (nav_msgs/Path), QoS reliable (reliable, volatile, keep last
  10). The planned path the controller follows.
- ``on_abort(msg: Abort)``: /abort (sam_msgs/Abort), QoS latched (reliable, transient_local, keep last 1).
  Emergency ascent ordered (active) or cleared by the performance monitor.

Publications:
- ``publish_thruster_rpms(msg: ThrusterRPMs)``: /thruster_rpms (sam_msgs/ThrusterRPMs), QoS reliable
  (reliable, volatile, keep last 10). Thruster speed commands.
- ``publish_thruster_angles(msg: ThrusterAngles)``: /thruster_angles (sam_msgs/ThrusterAngles), QoS reliable
  (reliable, volatile, keep last 10). Thrust vector commands.
- ``publish_ballast_angles(msg: BallastAngles)``: /ballast_angles (sam_msgs/BallastAngles), QoS reliable
  (reliable, volatile, keep last 10). Ballast weight commands.
- ``publish_longitudinal_weight_position(msg: PercentStamped)``: /longitudinal_weight_position
  (sam_msgs/PercentStamped), QoS reliable (reliable, volatile, keep last 10). Longitudinal weight position
  command.
- ``publish_buoyancy_piston_position(msg: PercentStamped)``: /buoyancy_piston_position
  (sam_msgs/PercentStamped), QoS reliable (reliable, volatile, keep last 10). Buoyancy piston position
  command.

Parameters (read-only properties with the current value; a change goes through set_parameters or the node's
~/set_parameters service, which refuses a value out of range or one that breaks a rule, naming it):
- none

Transforms:
- ``self.tf``: a sam_runtime.tf_buffer.TfBuffer fed from /tf and /tf_static.
- ``lookup_world_to_base_link(max_age_s=None, *, time_ns=None) -> Transform``: the pose of base_link in
  world, chained through the tree (TfMissingEdge; TfStale when an edge is older than max_age_s on this
  node's clock; time_ns: at that time, interpolated).

Health: ``report_status(level, message, **values)`` publishes the node's DiagnosticStatus (name = the node's
name) on /diagnostics at once; it is repeated every second with the counters of dropped and failed messages.
level: sam_runtime.node_support.Level (OK, WARN, ERROR, STALE).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from nav_msgs.msg import Path
from rclpy.node import Node
from sam_msgs.msg import Abort, BallastAngles, PercentStamped, ThrusterAngles, ThrusterRPMs
from sam_runtime import node_support, tf_buffer

NODE_NAME = 'controller'

PARAMETERS: tuple[node_support.ParameterSpec, ...] = (
)

# Parameters only other nodes read, which a rule compares with one of this node's (mirrored, not declared).
PARTNERS: tuple[node_support.ParameterSpec, ...] = (
)

RULES: tuple[node_support.RuleSpec, ...] = (
)


class ControllerBase(Node):
    """Node controller: subclass it and override the on_* methods (see the module docstring)."""

    def __init__(self, *, node_name: str | None = None, namespace: str | None = None,
                 parameter_overrides: Mapping[str, Any] | None = None, frame_prefix: str | None = None,
                 **node_kwargs: Any) -> None:
        super().__init__(node_name or NODE_NAME, namespace=namespace, **node_kwargs)
        self.frame_prefix = node_support.frame_prefix_of(self, frame_prefix)
        self._gen_support = node_support.NodeSupport(self)
        self._gen_parameters = node_support.declare_parameters(
            self, PARAMETERS, RULES, overrides=parameter_overrides, partners=PARTNERS)
        self.tf: tf_buffer.TfBuffer | None = tf_buffer.TfBuffer()
        self._gen_tf_feed = node_support.feed_tf(
            self, self.tf, self._gen_support, "/tf", node_support.qos_profile("reliable", "volatile", 100),
            "/tf_static", node_support.qos_profile("reliable", "transient_local", 1))
        self._gen_pub_thruster_rpms = self.create_publisher(
            ThrusterRPMs, "/thruster_rpms",
            node_support.qos_profile("reliable", "volatile", 10))
        self._gen_pub_thruster_angles = self.create_publisher(
            ThrusterAngles, "/thruster_angles",
            node_support.qos_profile("reliable", "volatile", 10))
        self._gen_pub_ballast_angles = self.create_publisher(
            BallastAngles, "/ballast_angles",
            node_support.qos_profile("reliable", "volatile", 10))
        self._gen_pub_longitudinal_weight_position = self.create_publisher(
            PercentStamped, "/longitudinal_weight_position",
            node_support.qos_profile("reliable", "volatile", 10))
        self._gen_pub_buoyancy_piston_position = self.create_publisher(
            PercentStamped, "/buoyancy_piston_position",
            node_support.qos_profile("reliable", "volatile", 10))
        self._gen_sub_global_plan = self.create_subscription(
            Path, "/global_plan",
            self._gen_support.callback("on_global_plan", self.on_global_plan),
            node_support.qos_profile("reliable", "volatile", 10))
        self._gen_sub_abort = self.create_subscription(
            Abort, "/abort",
            self._gen_support.callback("on_abort", self.on_abort),
            node_support.qos_profile("reliable", "transient_local", 1))

    def on_global_plan(self, msg: Path) -> None:
        """A message on /global_plan: override; this default counts and drops it."""
        self._gen_support.unhandled("/global_plan", "on_global_plan")

    def on_abort(self, msg: Abort) -> None:
        """A message on /abort: override; this default counts and drops it."""
        self._gen_support.unhandled("/abort", "on_abort")

    def publish_thruster_rpms(self, msg: ThrusterRPMs) -> None:
        """Publish on /thruster_rpms (sam_msgs/ThrusterRPMs)."""
        self._gen_pub_thruster_rpms.publish(msg)

    def publish_thruster_angles(self, msg: ThrusterAngles) -> None:
        """Publish on /thruster_angles (sam_msgs/ThrusterAngles)."""
        self._gen_pub_thruster_angles.publish(msg)

    def publish_ballast_angles(self, msg: BallastAngles) -> None:
        """Publish on /ballast_angles (sam_msgs/BallastAngles)."""
        self._gen_pub_ballast_angles.publish(msg)

    def publish_longitudinal_weight_position(self, msg: PercentStamped) -> None:
        """Publish on /longitudinal_weight_position (sam_msgs/PercentStamped)."""
        self._gen_pub_longitudinal_weight_position.publish(msg)

    def publish_buoyancy_piston_position(self, msg: PercentStamped) -> None:
        """Publish on /buoyancy_piston_position (sam_msgs/PercentStamped)."""
        self._gen_pub_buoyancy_piston_position.publish(msg)

    def lookup_world_to_base_link(
        self, max_age_s: float | None = None, *, time_ns: int | None = None
    ) -> tf_buffer.Transform:
        """The pose of base_link in world (raises tf_buffer.TfError subclasses)."""
        assert self.tf is not None
        return self.tf.lookup(self.frame("world"), self.frame("base_link"),
                              now_ns=self.get_clock().now().nanoseconds, max_age_s=max_age_s, time_ns=time_ns)

    def frame(self, name: str) -> str:
        """A spec frame id as this node writes and looks it up: with the frame prefix (empty stays empty)."""
        return f"{self.frame_prefix}{name}" if name else name

    def report_status(self, level: int, message: str, **values: Any) -> None:
        """Publish this node's DiagnosticStatus on /diagnostics now (repeated every second until the next)."""
        self._gen_support.report(level, message, values)
