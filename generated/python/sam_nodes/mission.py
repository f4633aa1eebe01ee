# Generated from interfaces.yaml by sam-codegen; do not edit.
"""The ROS 2 interface of node mission: Gives the motion planner its goals, a pose or a heading at a depth
or altitude (an addition).

Write the node as a subclass of ``MissionBase`` with logic only; topic names, types, QoS, parameters and
frames come from the spec::

    class Mission(MissionBase):
        ...

``MissionBase(*, node_name=None, namespace=None, parameter_overrides=None, frame_prefix=None,
**node_kwargs)``: the node is named ``mission`` unless node_name says otherwise; in ``namespace`` (or an
``__ns`` remap) the spec's relative topic names resolve under it, absolute ones stay; node_kwargs go to
rclpy's Node (context, cli_args, ...); parameter_overrides ({name: value}, spec or ROS names) win over the
node's --params-file values, which win over the spec defaults. A value out of range or breaking a rule raises
sam_runtime.node_support.ParameterConfigError. ``frame_prefix`` (default: the node's namespace, ``sam1/`` in
``/sam1``; ``\"\"`` for none) goes before every frame id the base publishes or looks up; ``self.frame(name)``
gives a spec frame with it.

Subscriptions (override the method; the default counts and drops; a method that raises is counted, logged and
shown on /diagnostics, and the node goes on):
- none

Publications:
- ``publish_nav_goal(msg: PoseStamped)``: /nav_goal (geometry_msgs/PoseStamped), QoS reliable (reliable,
  volatile, keep last 10). Pose goal in /world; position.z < 0 depth, > 0 altitude.
- ``publish_nav_heading(msg: HeadingStamped)``: /nav_heading (sam_msgs/HeadingStamped), QoS reliable
  (reliable, volatile, keep last 10). Heading goal; z < 0 depth, z > 0 altitude.

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

from geometry_msgs.msg import PoseStamped
from rclpy.node import Node
from sam_msgs.msg import HeadingStamped
from sam_runtime import node_support, tf_buffer

NODE_NAME = 'mission'

PARAMETERS: tuple[node_support.ParameterSpec, ...] = (
)

# Parameters only other nodes read, which a rule compares with one of this node's (mirrored, not declared).
PARTNERS: tuple[node_support.ParameterSpec, ...] = (
)

RULES: tuple[node_support.RuleSpec, ...] = (
)


class MissionBase(Node):
    """Node mission: subclass it and override the on_* methods (see the module docstring)."""

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
        self._gen_pub_nav_goal = self.create_publisher(
            PoseStamped, "/nav_goal",
            node_support.qos_profile("reliable", "volatile", 10))
        self._gen_pub_nav_heading = self.create_publisher(
            HeadingStamped, "/nav_heading",
            node_support.qos_profile("reliable", "volatile", 10))

    def publish_nav_goal(self, msg: PoseStamped) -> None:
        """Publish on /nav_goal (geometry_msgs/PoseStamped)."""
        self._gen_pub_nav_goal.publish(msg)

    def publish_nav_heading(self, msg: HeadingStamped) -> None:
        """Publish on /nav_heading (sam_msgs/HeadingStamped)."""
        self._gen_pub_nav_heading.publish(msg)

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
