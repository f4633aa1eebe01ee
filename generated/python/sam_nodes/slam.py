# Generated from interfaces.yaml by sam-codegen; do not edit.
"""The ROS 2 interface of node slam: SLAM; low-rate correction of odom in world from GPS fixes at the
surface (IV.E.2).

Write the node as a subclass of ``SlamBase`` with logic only; topic names, types, QoS, parameters and frames
come from the spec::

    class Slam(SlamBase):
        def on_gps_fix(self, msg: NavSatFix) -> None:
            ...

``SlamBase(*, node_name=None, namespace=None, parameter_overrides=None, frame_prefix=None, **node_kwargs)``:
the node is named ``slam`` unless node_name says otherwise; in ``namespace`` (or an ``__ns`` remap) the spec's
relative topic names resolve under it, absolute ones stay; node_kwargs go to rclpy's Node (context, cli_args,
...); parameter_overrides ({name: value}, spec or ROS names) win over the node's --params-file values, which
win over the spec defaults. A value out of range or breaking a rule raises
sam_runtime.node_support.ParameterConfigError. ``frame_prefix`` (default: the node's namespace, ``sam1/`` in
``/sam1``; ``\"\"`` for none) goes before every frame id the base publishes or looks up; ``self.frame(name)``
gives a spec frame with it.

Subscriptions (override the method; the default counts and drops; a method that raises is counted, logged and
shown on /diagnostics, and the node goes on):
- ``on_gps_fix(msg: NavSatFix)``: /gps_fix (sensor_msgs/NavSatFix), QoS sensor_data (best_effort, volatile,
  keep last 5). GPS fixes, at the surface.

Publications:
- none

Parameters (read-only properties with the current value; a change goes through set_parameters or the node's
~/set_parameters service, which refuses a value out of range or one that breaks a rule, naming it):
- none

Transforms:
- ``self.tf``: a sam_runtime.tf_buffer.TfBuffer fed from /tf and /tf_static.
- ``lookup_odom_to_base_link(max_age_s=None, *, time_ns=None) -> Transform``: the pose of base_link in
  odom, chained through the tree (TfMissingEdge; TfStale when an edge is older than max_age_s on this
  node's clock; time_ns: at that time, interpolated).
- ``publish_world_to_odom(stamp, translation, rotation)``: the pose of odom in world on /tf (Low-rate SLAM
  correction (IV.E.2).); stamp in ns, an rclpy Time or a builtin_interfaces/Time; translation (x, y, z) [m];
  rotation (x, y, z, w), a unit quaternion.

Health: ``report_status(level, message, **values)`` publishes the node's DiagnosticStatus (name = the node's
name) on /diagnostics at once; it is repeated every second with the counters of dropped and failed messages.
level: sam_runtime.node_support.Level (OK, WARN, ERROR, STALE).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from rclpy.node import Node
from sam_runtime import node_support, tf_buffer
from sensor_msgs.msg import NavSatFix
from tf2_msgs.msg import TFMessage

NODE_NAME = 'slam'

PARAMETERS: tuple[node_support.ParameterSpec, ...] = (
)

# Parameters only other nodes read, which a rule compares with one of this node's (mirrored, not declared).
PARTNERS: tuple[node_support.ParameterSpec, ...] = (
)

RULES: tuple[node_support.RuleSpec, ...] = (
)


class SlamBase(Node):
    """Node slam: subclass it and override the on_* methods (see the module docstring)."""

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
        self._gen_pub_tf = self.create_publisher(
            TFMessage, "/tf", node_support.qos_profile("reliable", "volatile", 100))
        self._gen_sub_gps_fix = self.create_subscription(
            NavSatFix, "/gps_fix",
            self._gen_support.callback("on_gps_fix", self.on_gps_fix),
            node_support.qos_profile("best_effort", "volatile", 5))

    def on_gps_fix(self, msg: NavSatFix) -> None:
        """A message on /gps_fix: override; this default counts and drops it."""
        self._gen_support.unhandled("/gps_fix", "on_gps_fix")

    def lookup_odom_to_base_link(
        self, max_age_s: float | None = None, *, time_ns: int | None = None
    ) -> tf_buffer.Transform:
        """The pose of base_link in odom (raises tf_buffer.TfError subclasses)."""
        assert self.tf is not None
        return self.tf.lookup(self.frame("odom"), self.frame("base_link"),
                              now_ns=self.get_clock().now().nanoseconds, max_age_s=max_age_s, time_ns=time_ns)

    def publish_world_to_odom(
        self, stamp: Any, translation: tuple[float, float, float], rotation: tuple[float, float, float, float]
    ) -> None:
        """Publish the pose of odom in world on /tf (ValueError for a bad value)."""
        node_support.publish_transform(
            self._gen_pub_tf, self.frame("world"), self.frame("odom"), stamp, translation,
            rotation)

    def frame(self, name: str) -> str:
        """A spec frame id as this node writes and looks it up: with the frame prefix (empty stays empty)."""
        return f"{self.frame_prefix}{name}" if name else name

    def report_status(self, level: int, message: str, **values: Any) -> None:
        """Publish this node's DiagnosticStatus on /diagnostics now (repeated every second until the next)."""
        self._gen_support.report(level, message, values)
