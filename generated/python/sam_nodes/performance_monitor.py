# Generated from interfaces.yaml by sam-codegen; do not edit.
"""The ROS 2 interface of node performance_monitor: Watches depth, altitude and the battery; orders an
emergency ascent (IV.H).

Write the node as a subclass of ``PerformanceMonitorBase`` with logic only; topic names, types, QoS,
parameters and frames come from the spec::

    class PerformanceMonitor(PerformanceMonitorBase):
        def on_pressure(self, msg: FluidPressure) -> None:
            ...

``PerformanceMonitorBase(*, node_name=None, namespace=None, parameter_overrides=None, frame_prefix=None,
**node_kwargs)``: the node is named ``performance_monitor`` unless node_name says otherwise; in ``namespace``
(or an ``__ns`` remap) the spec's relative topic names resolve under it, absolute ones stay; node_kwargs go to
rclpy's Node (context, cli_args, ...); parameter_overrides ({name: value}, spec or ROS names) win over the
node's --params-file values, which win over the spec defaults. A value out of range or breaking a rule raises
sam_runtime.node_support.ParameterConfigError. ``frame_prefix`` (default: the node's namespace, ``sam1/`` in
``/sam1``; ``\"\"`` for none) goes before every frame id the base publishes or looks up; ``self.frame(name)``
gives a spec frame with it.

Subscriptions (override the method; the default counts and drops; a method that raises is counted, logged and
shown on /diagnostics, and the node goes on):
- ``on_pressure(msg: FluidPressure)``: /pressure (sensor_msgs/FluidPressure), QoS sensor_data (best_effort,
  volatile, keep last 5). Water pressure.
- ``on_altitude(msg: Range)``: /altitude (sensor_msgs/Range), QoS sensor_data (best_effort, volatile, keep
  last 5). Altitude above the sea floor from the altimeter; NaN range = no bottom lock.
- ``on_battery_state(msg: BatteryState)``: /battery_state (sensor_msgs/BatteryState), QoS sensor_data
  (best_effort, volatile, keep last 5). Battery health and charge.

Publications:
- ``publish_abort(msg: Abort)``: /abort (sam_msgs/Abort), QoS latched (reliable, transient_local, keep last
  1). Emergency ascent ordered (active) or cleared by the performance monitor.
- ``publish_thruster_rpms(msg: ThrusterRPMs)``: /thruster_rpms (sam_msgs/ThrusterRPMs), QoS reliable
  (reliable, volatile, keep last 10). Thruster speed commands.
- ``publish_buoyancy_piston_position(msg: PercentStamped)``: /buoyancy_piston_position
  (sam_msgs/PercentStamped), QoS reliable (reliable, volatile, keep last 10). Buoyancy piston position
  command.

Parameters (read-only properties with the current value; a change goes through set_parameters or the node's
~/set_parameters service, which refuses a value out of range or one that breaks a rule, naming it):
- ``critical_altitude -> float``: ROS parameter critical_altitude [m], 0 .. 100, default 2.0. The monitor
  triggers an emergency ascent when below this altitude.
- ``critical_depth -> float``: ROS parameter critical_depth [m], 0 .. 200, default 60.0. The monitor triggers
  an emergency ascent when below this water depth.
- ``min_battery_percent -> float``: ROS parameter min_battery_percent [%], 0 .. 100, default 20.0. The monitor
  triggers an emergency ascent when the charge falls below this.

Rules (the spec's parameter_rules about this node's parameters):
- ``critical_altitude < safe_altitude``: The critical altitude lies below the safe altitude (closer to the sea
  floor).
- ``critical_depth > safe_depth``: The critical depth lies below the safe depth (deeper).

Compared with parameters of other nodes (mirrored: this node's --params-file value or the spec default, then
every change the nodes that read them announce on /parameter_events):
- safe_altitude [m], default 5.0, read by motion_planner
- safe_depth [m], default 50.0, read by motion_planner

Transforms:
- ``self.tf`` is None: this node reads no transforms (give it `reads_transforms` in the spec).

Health: ``report_status(level, message, **values)`` publishes the node's DiagnosticStatus (name = the node's
name) on /diagnostics at once; it is repeated every second with the counters of dropped and failed messages.
level: sam_runtime.node_support.Level (OK, WARN, ERROR, STALE).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from rclpy.node import Node
from sam_msgs.msg import Abort, PercentStamped, ThrusterRPMs
from sam_runtime import node_support, tf_buffer
from sensor_msgs.msg import BatteryState, FluidPressure, Range

NODE_NAME = 'performance_monitor'

PARAMETERS: tuple[node_support.ParameterSpec, ...] = (
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
    node_support.ParameterSpec(
        name='/min_battery_percent',
        type='double',
        default=20.0,
        minimum=0.0,
        maximum=100.0,
        unit='%',
        description='The monitor triggers an emergency ascent when the charge falls below this.',
        readers=('performance_monitor',),
    ),
)

# Parameters only other nodes read, which a rule compares with one of this node's (mirrored, not declared).
PARTNERS: tuple[node_support.ParameterSpec, ...] = (
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


class PerformanceMonitorBase(Node):
    """Node performance_monitor: subclass it and override the on_* methods (see the module docstring)."""

    def __init__(self, *, node_name: str | None = None, namespace: str | None = None,
                 parameter_overrides: Mapping[str, Any] | None = None, frame_prefix: str | None = None,
                 **node_kwargs: Any) -> None:
        super().__init__(node_name or NODE_NAME, namespace=namespace, **node_kwargs)
        self.frame_prefix = node_support.frame_prefix_of(self, frame_prefix)
        self._gen_support = node_support.NodeSupport(self)
        self._gen_parameters = node_support.declare_parameters(
            self, PARAMETERS, RULES, overrides=parameter_overrides, partners=PARTNERS)
        self.tf: tf_buffer.TfBuffer | None = None
        self._gen_pub_abort = self.create_publisher(
            Abort, "/abort",
            node_support.qos_profile("reliable", "transient_local", 1))
        self._gen_pub_thruster_rpms = self.create_publisher(
            ThrusterRPMs, "/thruster_rpms",
            node_support.qos_profile("reliable", "volatile", 10))
        self._gen_pub_buoyancy_piston_position = self.create_publisher(
            PercentStamped, "/buoyancy_piston_position",
            node_support.qos_profile("reliable", "volatile", 10))
        self._gen_sub_pressure = self.create_subscription(
            FluidPressure, "/pressure",
            self._gen_support.callback("on_pressure", self.on_pressure),
            node_support.qos_profile("best_effort", "volatile", 5))
        self._gen_sub_altitude = self.create_subscription(
            Range, "/altitude",
            self._gen_support.callback("on_altitude", self.on_altitude),
            node_support.qos_profile("best_effort", "volatile", 5))
        self._gen_sub_battery_state = self.create_subscription(
            BatteryState, "/battery_state",
            self._gen_support.callback("on_battery_state", self.on_battery_state),
            node_support.qos_profile("best_effort", "volatile", 5))

    @property
    def critical_altitude(self) -> float:
        """ROS parameter critical_altitude: its current value."""
        return self.get_parameter("critical_altitude").value

    @property
    def critical_depth(self) -> float:
        """ROS parameter critical_depth: its current value."""
        return self.get_parameter("critical_depth").value

    @property
    def min_battery_percent(self) -> float:
        """ROS parameter min_battery_percent: its current value."""
        return self.get_parameter("min_battery_percent").value

    def on_pressure(self, msg: FluidPressure) -> None:
        """A message on /pressure: override; this default counts and drops it."""
        self._gen_support.unhandled("/pressure", "on_pressure")

    def on_altitude(self, msg: Range) -> None:
        """A message on /altitude: override; this default counts and drops it."""
        self._gen_support.unhandled("/altitude", "on_altitude")

    def on_battery_state(self, msg: BatteryState) -> None:
        """A message on /battery_state: override; this default counts and drops it."""
        self._gen_support.unhandled("/battery_state", "on_battery_state")

    def publish_abort(self, msg: Abort) -> None:
        """Publish on /abort (sam_msgs/Abort)."""
        self._gen_pub_abort.publish(msg)

    def publish_thruster_rpms(self, msg: ThrusterRPMs) -> None:
        """Publish on /thruster_rpms (sam_msgs/ThrusterRPMs)."""
        self._gen_pub_thruster_rpms.publish(msg)

    def publish_buoyancy_piston_position(self, msg: PercentStamped) -> None:
        """Publish on /buoyancy_piston_position (sam_msgs/PercentStamped)."""
        self._gen_pub_buoyancy_piston_position.publish(msg)

    def frame(self, name: str) -> str:
        """A spec frame id as this node writes and looks it up: with the frame prefix (empty stays empty)."""
        return f"{self.frame_prefix}{name}" if name else name

    def report_status(self, level: int, message: str, **values: Any) -> None:
        """Publish this node's DiagnosticStatus on /diagnostics now (repeated every second until the next)."""
        self._gen_support.report(level, message, values)
