# Generated from interfaces.yaml by sam-codegen; do not edit.
"""The ROS 2 interface of node motion_planner: Plans a path to a heading or pose goal at a target depth or
altitude (IV.F).

Write the node as a subclass of ``MotionPlannerBase`` with logic only; topic names, types, QoS, parameters and
frames come from the spec::

    class MotionPlanner(MotionPlannerBase):
        def on_nav_goal(self, msg: PoseStamped) -> None:
            ...

``MotionPlannerBase(*, node_name=None, namespace=None, parameter_overrides=None, frame_prefix=None,
**node_kwargs)``: the node is named ``motion_planner`` unless node_name says otherwise; in ``namespace`` (or
an ``__ns`` remap) the spec's relative topic names resolve under it, absolute ones stay; node_kwargs go to
rclpy's Node (context, cli_args, ...); parameter_overrides ({name: value}, spec or ROS names) win over the
node's --params-file values, which win over the spec defaults. A value out of range or breaking a rule raises
sam_runtime.node_support.ParameterConfigError. ``frame_prefix`` (default: the node's namespace, ``sam1/`` in
``/sam1``; ``\"\"`` for none) goes before every frame id the base publishes or looks up; ``self.frame(name)``
gives a spec frame with it.

Subscriptions (override the method; the default counts and drops; a method that raises is counted, logged and
shown on /diagnostics, and the node goes on):
- ``on_nav_goal(msg: PoseStamped)``: /nav_goal (geometry_msgs/PoseStamped), QoS reliable (reliable, volatile,
  keep last 10). Pose goal in /world; position.z < 0 depth, > 0 altitude.
- ``on_nav_heading(msg: HeadingStamped)``: /nav_heading (sam_msgs/HeadingStamped), QoS reliable (reliable,
  volatile, keep last 10). Heading goal; z < 0 depth, z > 0 altitude.
- ``on_altitude(msg: Range)``: /altitude (sensor_msgs/Range), QoS sensor_data (best_effort, volatile, keep
  last 5). Altitude above the sea floor from the altimeter; NaN range = no bottom lock.

Publications:
- ``publish_global_plan(msg: Path)``: /global_plan (nav_msgs/Path), QoS reliable (reliable, volatile, keep
  last 10). The planned path the controller follows.

Parameters (read-only properties with the current value; a change goes through set_parameters or the node's
~/set_parameters service, which refuses a value out of range or one that breaks a rule, naming it):
- ``safe_altitude -> float``: ROS parameter safe_altitude [m], 0 .. 100, default 5.0. The motion planner
  always tries to stay above this height over the sea floor.
- ``safe_depth -> float``: ROS parameter safe_depth [m], 0 .. 200, default 50.0. The motion planner always
  tries to stay above this water depth.

Rules (the spec's parameter_rules about this node's parameters):
- ``critical_altitude < safe_altitude``: The critical altitude lies below the safe altitude (closer to the sea
  floor).
- ``critical_depth > safe_depth``: The critical depth lies below the safe depth (deeper).

Compared with parameters of other nodes (mirrored: this node's --params-file value or the spec default, then
every change the nodes that read them announce on /parameter_events):
- critical_altitude [m], default 2.0, read by performance_monitor
- critical_depth [m], default 60.0, read by performance_monitor

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
from nav_msgs.msg import Path
from rclpy.node import Node
from sam_msgs.msg import HeadingStamped
from sam_runtime import node_support, tf_buffer
from sensor_msgs.msg import Range

NODE_NAME = 'motion_planner'

PARAMETERS: tuple[node_support.ParameterSpec, ...] = (
    node_support.ParameterSpec(
        name='/safe_altitude',
        type='double',
        default=5.0,
        minimum=0.0,
        maximum=100.0,
        unit='m',
        description='The motion planner always tries to stay above this height over the sea floor.',
        readers=('motion_planner',),
    ),
    node_support.ParameterSpec(
        name='/safe_depth',
        type='double',
        default=50.0,
        minimum=0.0,
        maximum=200.0,
        unit='m',
        description='The motion planner always tries to stay above this water depth.',
        readers=('motion_planner',),
    ),
)

# Parameters only other nodes read, which a rule compares with one of this node's (mirrored, not declared).
PARTNERS: tuple[node_support.ParameterSpec, ...] = (
    node_support.ParameterSpec(
        name='/critical_altitude',
        type='double',
        default=2.0,
        minimum=0.0,
        maximum=100.0,
        unit='m',
        description='The monitor triggers an emergency ascent when below this altitude.',
        readers=('performance_monitor',),
    ),
    node_support.ParameterSpec(
        name='/critical_depth',
        type='double',
        default=60.0,
        minimum=0.0,
        maximum=200.0,
        unit='m',
        description='The monitor triggers an emergency ascent when below this water depth.',
        readers=('performance_monitor',),
    ),
)

RULES: tuple[node_support.RuleSpec, ...] = (
    node_support.RuleSpec(
        left='/critical_altitude',
        op='<',
        right='/safe_altitude',
        description='The critical altitude lies below the safe altitude (closer to the sea floor).',
    ),
    node_support.RuleSpec(
        left='/critical_depth',
        op='>',
        right='/safe_depth',
        description='The critical depth lies below the safe depth (deeper).',
    ),
)


class MotionPlannerBase(Node):
    """Node motion_planner: subclass it and override the on_* methods (see the module docstring)."""

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
        self._gen_pub_global_plan = self.create_publisher(
            Path, "/global_plan",
            node_support.qos_profile("reliable", "volatile", 10))
        self._gen_sub_nav_goal = self.create_subscription(
            PoseStamped, "/nav_goal",
            self._gen_support.callback("on_nav_goal", self.on_nav_goal),
            node_support.qos_profile("reliable", "volatile", 10))
        self._gen_sub_nav_heading = self.create_subscription(
            HeadingStamped, "/nav_heading",
            self._gen_support.callback("on_nav_heading", self.on_nav_heading),
            node_support.qos_profile("reliable", "volatile", 10))
        self._gen_sub_altitude = self.create_subscription(
            Range, "/altitude",
            self._gen_support.callback("on_altitude", self.on_altitude),
            node_support.qos_profile("best_effort", "volatile", 5))

    @property
    def safe_altitude(self) -> float:
        """ROS parameter safe_altitude: its current value."""
        return self.get_parameter("safe_altitude").value

    @property
    def safe_depth(self) -> float:
        """ROS parameter safe_depth: its current value."""
        return self.get_parameter("safe_depth").value

    def on_nav_goal(self, msg: PoseStamped) -> None:
        """A message on /nav_goal: override; this default counts and drops it."""
        self._gen_support.unhandled("/nav_goal", "on_nav_goal")

    def on_nav_heading(self, msg: HeadingStamped) -> None:
        """A message on /nav_heading: override; this default counts and drops it."""
        self._gen_support.unhandled("/nav_heading", "on_nav_heading")

    def on_altitude(self, msg: Range) -> None:
        """A message on /altitude: override; this default counts and drops it."""
        self._gen_support.unhandled("/altitude", "on_altitude")

    def publish_global_plan(self, msg: Path) -> None:
        """Publish on /global_plan (nav_msgs/Path)."""
        self._gen_pub_global_plan.publish(msg)

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
