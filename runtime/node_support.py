"""What the generated node bases (generated/python/<vehicle>_nodes) share, and the bridge uses too.

- Parameters: ``declare_parameters(node, parameters, rules, overrides=..., partners=...)`` declares each with a
  ParameterDescriptor (type, range, unit and description, its rules as additional constraints) and refuses a
  ``set_parameters`` that breaks a spec rule (``parameter_rules``), naming the rule in the result's reason.
  ROS 2 has no global parameters: a node declares the ones it reads. A rule can compare a parameter this node
  reads with one only another node reads (``critical_depth > safe_depth``); that other one is a *partner*: not
  declared here, but mirrored, starting from this node's overrides (``--params-file`` ``/**``, or
  ``overrides``) or the spec default, then following every change the nodes that read it announce on
  /parameter_events. So lowering critical_depth on the monitor below the planner's current safe_depth is
  refused too.
- QoS: ``qos_profile(reliability, durability, depth)`` from the spec's names (tables' QosInfo, the generated
  bases' literals).
- TF: ``feed_tf`` keeps a TfBuffer fed from /tf and /tf_static; ``publish_transform`` and
  ``publish_static_transforms`` build the TFMessages.
- Health: ``NodeSupport`` publishes the node's DiagnosticStatus on /diagnostics (at once on ``report`` and at
  1 Hz of wall time), counts and logs what would otherwise be lost (a subscriber callback that raised, a message
  nobody handles, a rejected transform) without ending the node. A node in a namespace names its status with
  it (``sam1/controller``: /diagnostics is global, two vehicles must stay apart there).
- Namespaces: ``frame_prefix_of`` the prefix a node puts before its frame ids (sam_runtime.common.ros_namespace).

rclpy and the message packages are imported when a function needs them, so the module imports anywhere.
"""

from __future__ import annotations

import enum
import math
import sys
import time
import traceback
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

from sam_codegen.model.names import ros_parameter_name
from sam_runtime.common.ros_namespace import ros_namespace
from sam_runtime.tf_buffer import TfBuffer, TfError

__all__ = [
    "DIAGNOSTICS_TOPIC",
    "Level",
    "NodeSupport",
    "ParameterConfigError",
    "ParameterGuard",
    "ParameterSpec",
    "RuleSpec",
    "declare_parameters",
    "feed_tf",
    "frame_prefix_of",
    "publish_static_transforms",
    "publish_transform",
    "qos_profile",
    "ros_parameter_name",
    "stamp_to_ns",
    "status_name",
]

DIAGNOSTICS_TOPIC = "/diagnostics"
STATUS_PERIOD_S = 1.0
LOG_INTERVAL_S = 10.0  # one log line per (node, what) per interval after the first


class Level(enum.IntEnum):
    """diagnostic_msgs/DiagnosticStatus levels."""

    OK = 0
    WARN = 1
    ERROR = 2
    STALE = 3


# ---- parameters --------------------------------------------------------------------------------------------------


class ParameterInfoLike(Protocol):
    """The fields of a spec parameter (tables.ParameterInfo and ParameterSpec both have them)."""

    name: str
    type: str
    default: Any
    minimum: float | None
    maximum: float | None
    unit: str
    description: str


class RuleInfoLike(Protocol):
    left: str
    op: str
    right: str
    description: str


@dataclass(frozen=True)
class ParameterSpec:
    """A parameter as the spec declares it (`name` as in the spec: /safe_depth)."""

    name: str
    type: str  # "double" | "integer" | "bool" | "string"
    default: float | int | bool | str
    minimum: float | None = None
    maximum: float | None = None
    unit: str = ""
    description: str = ""
    readers: tuple[str, ...] = ()  # the spec's nodes that declare it (whose changes a partner mirror follows)


@dataclass(frozen=True)
class RuleSpec:
    """A spec parameter rule: `left op right`."""

    left: str
    op: str
    right: str
    description: str = ""


class ParameterConfigError(Exception):
    """Parameters cannot be declared as asked (an unknown override, a value out of range, a broken rule)."""


_RULE_OPS: dict[str, Callable[[Any, Any], bool]] = {
    "<": lambda a, b: a < b, "<=": lambda a, b: a <= b, ">": lambda a, b: a > b, ">=": lambda a, b: a >= b,
}


def _coerce(p: ParameterInfoLike, value: Any) -> Any:
    """A value of the parameter's type; a whole number for a double is fine, anything else is an error."""
    kind = str(p.type).lower()
    if kind in ("double", "float", "float64", "float32"):
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ParameterConfigError(f"parameter {ros_parameter_name(p.name)}: {value!r} is not a number")
        return float(value)
    if kind in ("integer", "int", "int64", "int32"):
        if isinstance(value, bool) or not isinstance(value, int):
            if isinstance(value, float) and value.is_integer():
                return int(value)
            raise ParameterConfigError(f"parameter {ros_parameter_name(p.name)}: {value!r} is not an integer")
        return value
    if kind in ("bool", "boolean"):
        if isinstance(value, bool):
            return value
        if isinstance(value, str) and value.lower() in ("true", "false"):
            return value.lower() == "true"
        raise ParameterConfigError(f"parameter {ros_parameter_name(p.name)}: {value!r} is not a bool")
    if not isinstance(value, str):
        raise ParameterConfigError(f"parameter {ros_parameter_name(p.name)}: {value!r} is not a string")
    return value


def _descriptor(p: ParameterInfoLike, constraints: list[str]) -> Any:
    from rcl_interfaces.msg import FloatingPointRange, IntegerRange, ParameterDescriptor, ParameterType

    name = ros_parameter_name(p.name)
    desc = ParameterDescriptor(name=name, description=p.description + (f" [{p.unit}]" if p.unit else ""),
                               additional_constraints="; ".join(constraints))
    kind = str(p.type).lower()
    if kind in ("double", "float", "float64", "float32"):
        desc.type = ParameterType.PARAMETER_DOUBLE
        if p.minimum is not None or p.maximum is not None:
            lo = -sys.float_info.max if p.minimum is None else float(p.minimum)
            hi = sys.float_info.max if p.maximum is None else float(p.maximum)
            desc.floating_point_range = [FloatingPointRange(from_value=lo, to_value=hi, step=0.0)]
    elif kind in ("integer", "int", "int64", "int32"):
        desc.type = ParameterType.PARAMETER_INTEGER
        if p.minimum is not None or p.maximum is not None:
            lo = -(2**63) if p.minimum is None else math.ceil(p.minimum)
            hi = 2**63 - 1 if p.maximum is None else math.floor(p.maximum)
            desc.integer_range = [IntegerRange(from_value=int(lo), to_value=int(hi), step=1)]
    elif kind in ("bool", "boolean"):
        desc.type = ParameterType.PARAMETER_BOOL
    else:
        desc.type = ParameterType.PARAMETER_STRING
    return desc


def rule_text(rule: RuleInfoLike) -> str:
    """
    >>> rule_text(RuleSpec("/critical_depth", ">", "/safe_depth"))
    'critical_depth > safe_depth'
    """
    return f"{ros_parameter_name(rule.left)} {rule.op} {ros_parameter_name(rule.right)}"


def rule_violation(rules: Iterable[RuleInfoLike], values: Mapping[str, Any], changed: Iterable[str] | None = None,
                   sources: Mapping[str, str] | None = None) -> str | None:
    """The first rule the values (by ROS name) break, as a reason naming it; rules with a side not in `values` and,
    given `changed`, rules about none of those names are not judged.

    >>> rules = [RuleSpec("/critical_depth", ">", "/safe_depth", "Deeper.")]
    >>> rule_violation(rules, {"critical_depth": 40.0, "safe_depth": 50.0})
    "breaks parameter rule 'critical_depth > safe_depth' (Deeper.): critical_depth = 40.0, safe_depth = 50.0"
    >>> rule_violation(rules, {"critical_depth": 40.0, "safe_depth": 50.0}, changed=["use_sim_time"]) is None
    True
    """
    watch = None if changed is None else set(changed)
    for rule in rules:
        left, right = ros_parameter_name(rule.left), ros_parameter_name(rule.right)
        op = _RULE_OPS.get(rule.op)
        if op is None or left not in values or right not in values:
            continue
        if watch is not None and not {left, right} & watch:
            continue
        lv, rv = values[left], values[right]
        try:
            ok = op(lv, rv)
        except TypeError:
            ok = False
        if not ok:
            where = {n: f" ({sources[n]})" for n in (left, right) if sources and n in sources}
            return (f"breaks parameter rule '{rule_text(rule)}'" + (f" ({rule.description})" if rule.description
                                                                   else "")
                    + f": {left} = {lv}{where.get(left, '')}, {right} = {rv}{where.get(right, '')}")
    return None


class ParameterGuard:
    """The rule check of one node's parameters; made by declare_parameters."""

    def __init__(self, node: Any, own: Sequence[ParameterInfoLike], rules: Sequence[RuleInfoLike],
                 partners: Sequence[ParameterInfoLike]) -> None:
        self.node = node
        self.own = {ros_parameter_name(p.name): p for p in own}
        self.rules = list(rules)
        self.partners = {ros_parameter_name(p.name): p for p in partners}
        self.partner_values: dict[str, Any] = {}
        self.partner_sources: dict[str, str] = {}  # ROS name -> where its value came from
        self._readers = {ros_parameter_name(p.name): set(getattr(p, "readers", ()) or ()) for p in partners}

    def values(self) -> dict[str, Any]:
        values = dict(self.partner_values)
        values.update({n: self.node.get_parameter(n).value for n in self.own})
        return values

    def violation(self, changed: Mapping[str, Any] | None = None) -> str | None:
        values = self.values()
        values.update(changed or {})
        return rule_violation(self.rules, values, None if changed is None else list(changed), self.partner_sources)

    def on_set(self, params: list[Any]) -> Any:
        from rcl_interfaces.msg import SetParametersResult

        reason = self.violation({p.name: p.value for p in params})
        return SetParametersResult(successful=reason is None, reason=reason or "")

    def on_parameter_event(self, event: Any) -> None:
        """Follow a partner's value as the nodes that read it change it (ParameterEvent from /parameter_events)."""
        from rclpy.parameter import parameter_value_to_python

        node_ns, _, node_name = str(event.node).rpartition("/")
        if str(event.node) == self.node.get_fully_qualified_name() or (node_ns or "/") != self.node.get_namespace():
            return
        for param in [*event.new_parameters, *event.changed_parameters]:
            readers = self._readers.get(param.name)
            if readers is None or (readers and node_name not in readers):
                continue
            try:
                value = _coerce(self.partners[param.name], parameter_value_to_python(param.value))
            except (ParameterConfigError, RuntimeError, ValueError):  # another type: not the spec's parameter
                continue
            self.partner_values[param.name] = value
            self.partner_sources[param.name] = f"as set on {event.node}"


def declare_parameters(node: Any, parameters: Sequence[ParameterInfoLike],
                       rules: Sequence[RuleInfoLike] = (), *,
                       overrides: Mapping[str, Any] | Sequence[Any] | None = None,
                       partners: Sequence[ParameterInfoLike] = ()) -> ParameterGuard:
    """Declare `parameters` on an rclpy node (descriptor with type, range, unit, description and its rules) and
    install the rule check. Values: `overrides` ({spec or ROS name: value}, or rclpy Parameters; here also for
    partners), else the node's own overrides (--params-file), else the spec default. Raises ParameterConfigError
    for an unknown override, a value outside the range or of the wrong type, or initial values that break a rule.
    """
    guard = ParameterGuard(node, parameters, rules, partners)
    pairs = overrides.items() if isinstance(overrides, Mapping) else ((p.name, p.value) for p in overrides or ())
    given = {ros_parameter_name(k): v for k, v in pairs}
    unknown = set(given) - set(guard.own) - set(guard.partners)
    if unknown:
        raise ParameterConfigError(f"unknown parameter(s) {sorted(unknown)}; this node has "
                                   f"{sorted(guard.own) + sorted(guard.partners)}")
    node_overrides = getattr(node, "_parameter_overrides", {}) or {}  # rclpy's: params files and constructor
    for name, p in guard.own.items():
        constraints = [f"{rule_text(r)}: {r.description}".rstrip(": ") for r in guard.rules
                       if name in (ros_parameter_name(r.left), ros_parameter_name(r.right))]
        desc = _descriptor(p, constraints)
        value = _coerce(p, given[name] if name in given else p.default)
        try:
            node.declare_parameter(name, value, desc, ignore_override=name in given)
        except Exception as ex:  # rclpy: InvalidParameterValueException (range), InvalidParameterTypeException
            raise ParameterConfigError(f"parameter {name}: {type(ex).__name__}: {ex}") from None
    for name, p in guard.partners.items():
        if name in given:
            guard.partner_values[name], guard.partner_sources[name] = _coerce(p, given[name]), "override"
        elif name in node_overrides:
            guard.partner_values[name] = _coerce(p, node_overrides[name].value)
            guard.partner_sources[name] = "parameter override"
        else:
            guard.partner_values[name], guard.partner_sources[name] = _coerce(p, p.default), "spec default"
    problem = guard.violation()
    if problem:
        raise ParameterConfigError(f"the initial parameters of {node.get_name()} {problem}")
    node.add_on_set_parameters_callback(guard.on_set)
    if guard.partners:
        from rcl_interfaces.msg import ParameterEvent
        from rclpy.qos import qos_profile_parameter_events

        node.create_subscription(ParameterEvent, "/parameter_events", guard.on_parameter_event,
                                 qos_profile_parameter_events)
    return guard


# ---- QoS ---------------------------------------------------------------------------------------------------------


def qos_profile(reliability: str, durability: str, depth: int) -> Any:
    """An rclpy QoSProfile (keep last `depth`) from the spec's names (reliable | best_effort,
    volatile | transient_local)."""
    from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

    reliabilities = {"reliable": ReliabilityPolicy.RELIABLE, "best_effort": ReliabilityPolicy.BEST_EFFORT}
    durabilities = {"volatile": DurabilityPolicy.VOLATILE, "transient_local": DurabilityPolicy.TRANSIENT_LOCAL}
    if reliability not in reliabilities or durability not in durabilities or int(depth) < 1:
        raise ValueError(f"no such QoS: reliability {reliability!r}, durability {durability!r}, depth {depth!r}")
    return QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=int(depth), reliability=reliabilities[reliability],
                      durability=durabilities[durability])


# ---- time and TF -------------------------------------------------------------------------------------------------


def stamp_to_ns(stamp: Any) -> int:
    """Nanoseconds from an int (ns), an rclpy Time or a builtin_interfaces/Time."""
    if isinstance(stamp, bool):
        raise TypeError(f"not a time stamp: {stamp!r}")
    if isinstance(stamp, int):
        return stamp
    if hasattr(stamp, "nanoseconds"):
        return int(stamp.nanoseconds)
    if hasattr(stamp, "sec") and hasattr(stamp, "nanosec"):
        return int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)
    raise TypeError(f"not a time stamp: {stamp!r} (an int of nanoseconds, rclpy Time or builtin_interfaces/Time)")


def _time_msg(ns: int) -> Any:
    from builtin_interfaces.msg import Time

    sec, nanosec = divmod(int(ns), 1_000_000_000)
    return Time(sec=sec, nanosec=nanosec)


def _transform_stamped(parent: str, child: str, ns: int, translation: Sequence[float],
                       rotation: Sequence[float]) -> Any:
    from geometry_msgs.msg import TransformStamped

    values = [float(v) for v in (*translation, *rotation)]
    if len(translation) != 3 or len(rotation) != 4 or not all(math.isfinite(v) for v in values):
        raise ValueError(f"transform {parent}->{child}: translation (x, y, z) and rotation (x, y, z, w) must be "
                         f"finite, got {tuple(translation)}, {tuple(rotation)}")
    norm2 = sum(v * v for v in values[3:])
    if abs(norm2 - 1.0) > 1e-3:
        raise ValueError(f"transform {parent}->{child}: rotation {tuple(rotation)} is not a unit quaternion")
    msg = TransformStamped()
    msg.header.stamp = _time_msg(ns)
    msg.header.frame_id = parent
    msg.child_frame_id = child
    t, r = msg.transform.translation, msg.transform.rotation
    t.x, t.y, t.z = values[:3]
    r.x, r.y, r.z, r.w = values[3:]
    return msg


def publish_transform(publisher: Any, parent: str, child: str, stamp: Any, translation: Sequence[float],
                      rotation: Sequence[float]) -> None:
    """Publish one transform parent->child (pose of child in parent) as a TFMessage; ValueError for a
    non-finite value or a rotation that is not a unit quaternion (x, y, z, w)."""
    from tf2_msgs.msg import TFMessage

    publisher.publish(TFMessage(transforms=[_transform_stamped(parent, child, stamp_to_ns(stamp), translation,
                                                               rotation)]))


def publish_static_transforms(node: Any, transforms: Sequence[tuple[str, str, Sequence[float], Sequence[float]]],
                              topic: str, qos: Any, frame_prefix: str = "") -> Any:
    """Publish (parent, child, translation, rotation xyzw) static transforms once, in one TFMessage (a latched
    topic keeps one message per publisher), stamped now, every frame id after ``frame_prefix``; returns the
    publisher (keep it: it serves late subscribers)."""
    from tf2_msgs.msg import TFMessage

    now = node.get_clock().now().nanoseconds
    publisher = node.create_publisher(TFMessage, topic, qos)
    publisher.publish(TFMessage(transforms=[_transform_stamped(frame_prefix + p, frame_prefix + c, now, t, r)
                                            for p, c, t, r in transforms]))
    return publisher


class TfFeed:
    """Feeds a TfBuffer from /tf and /tf_static; a rejected transform is counted and logged, never raised."""

    def __init__(self, node: Any, buffer: TfBuffer, support: NodeSupport, tf_topic: str, tf_qos: Any,
                 static_topic: str | None, static_qos: Any) -> None:
        from tf2_msgs.msg import TFMessage

        self.buffer, self.support = buffer, support
        self.subscriptions = [node.create_subscription(TFMessage, tf_topic, self.on_tf, tf_qos)]
        if static_topic is not None:
            self.subscriptions.append(node.create_subscription(TFMessage, static_topic, self.on_tf_static,
                                                               static_qos))

    def on_tf(self, msg: Any) -> None:
        self._store(msg, False)

    def on_tf_static(self, msg: Any) -> None:
        self._store(msg, True)

    def _store(self, msg: Any, static: bool) -> None:
        for ts in msg.transforms:
            t, r = ts.transform.translation, ts.transform.rotation
            try:
                stored = self.buffer.set_transform(ts.header.frame_id, ts.child_frame_id, stamp_to_ns(ts.header.stamp),
                                                   (t.x, t.y, t.z), (r.x, r.y, r.z, r.w), static=static)
            except TfError as ex:
                self.support.count("tf.rejected", f"rejected transform {ts.header.frame_id}->{ts.child_frame_id}: "
                                   f"{ex}")
                continue
            if not stored:
                self.support.count("tf.too_old", f"ignored transform {ts.header.frame_id}->{ts.child_frame_id}: "
                                   "older than the buffer's cache")


def feed_tf(node: Any, buffer: TfBuffer, support: NodeSupport, tf_topic: str, tf_qos: Any,
            static_topic: str | None = None, static_qos: Any = None) -> TfFeed:
    """Subscribe `buffer` to the TF topics (static_topic None: only dynamic transforms)."""
    return TfFeed(node, buffer, support, tf_topic, tf_qos, static_topic, static_qos)


# ---- namespaces ---------------------------------------------------------------------------------------------------


def frame_prefix_of(node: Any, frame_prefix: str | None = None) -> str:
    """The frame prefix of a node: ``frame_prefix`` checked (``a/b`` -> ``a/b/``), or by default its namespace's
    (``/sam1`` -> ``sam1/``, ``/`` -> ``""``); ValueError for an invalid one."""
    return ros_namespace(node.get_namespace(), (), frame_prefix).frame_prefix


def status_name(node: Any) -> str:
    """A node's diagnostic status name: its name, after its namespace when it has one (``sam1/controller``)."""
    return ros_namespace(node.get_namespace()).status_name(node.get_name())


# ---- health ------------------------------------------------------------------------------------------------------


class NodeSupport:
    """A node's health: its DiagnosticStatus on /diagnostics (at once on `report`, and every STATUS_PERIOD_S of
    wall time), counters of what went wrong, rate-limited logs, and guarded subscriber callbacks."""

    def __init__(self, node: Any, diagnostics_topic: str = DIAGNOSTICS_TOPIC,
                 period_s: float = STATUS_PERIOD_S) -> None:
        from diagnostic_msgs.msg import DiagnosticArray
        from rclpy.clock import Clock, ClockType

        self.node = node
        self.level, self.message = Level.OK, "running"
        self.values: dict[str, Any] = {}
        self.counters: dict[str, int] = {}
        self._errors_since_report: list[str] = []
        self._logged: dict[str, float] = {}
        self._unhandled: set[str] = set()
        self.publisher = node.create_publisher(DiagnosticArray, diagnostics_topic, 10)
        # Wall time: health reports keep their pace whether or not use_sim_time runs the node's clock.
        self.timer = node.create_timer(period_s, self.publish, clock=Clock(clock_type=ClockType.STEADY_TIME))

    def report(self, level: int, message: str, values: Mapping[str, Any]) -> None:
        if isinstance(level, bytes):
            level = level[0]
        if int(level) not in tuple(Level):
            raise ValueError(f"diagnostic level {level!r} is not one of {[int(v) for v in Level]} (OK .. STALE)")
        self.level, self.message, self.values = Level(int(level)), str(message), dict(values)
        self._errors_since_report.clear()
        self.publish()

    def count(self, key: str, log: str | None = None) -> None:
        """Count an event (shown in the status values); log it, at most once per LOG_INTERVAL_S per key."""
        self.counters[key] = self.counters.get(key, 0) + 1
        if log is not None:
            now = time.monotonic()
            if now - self._logged.get(key, -math.inf) >= LOG_INTERVAL_S:
                self._logged[key] = now
                total = self.counters[key]
                self.node.get_logger().warning(f"{log}" + (f" ({total} so far)" if total > 1 else ""))

    def callback(self, name: str, method: Callable[[Any], None]) -> Callable[[Any], None]:
        """`method` for a subscription: an exception is counted (errors.<name>), logged with its traceback
        (rate-limited) and shown as ERROR in the status, instead of ending the executor."""
        def call(msg: Any) -> None:
            try:
                method(msg)
            except Exception as ex:  # the node's own bug: visible on /diagnostics and in the log, not fatal
                key = f"errors.{name}"
                self.counters[key] = self.counters.get(key, 0) + 1
                self._errors_since_report.append(f"{name} raised {type(ex).__name__}: {ex}")
                now = time.monotonic()
                if now - self._logged.get(key, -math.inf) >= LOG_INTERVAL_S:
                    self._logged[key] = now
                    self.node.get_logger().error(f"{name} raised (message dropped, {self.counters[key]} so far):\n"
                                                 + traceback.format_exc().rstrip())
        return call

    def unhandled(self, topic: str, method: str) -> None:
        """A message of a topic whose on_<topic> the subclass did not override: counted, logged once."""
        key = f"unhandled.{topic}"
        self.counters[key] = self.counters.get(key, 0) + 1
        if topic not in self._unhandled:
            self._unhandled.add(topic)
            self.node.get_logger().warning(f"{self.node.get_name()}: no {method} override; messages on {topic} are "
                                           "counted and dropped")

    def status(self) -> Any:
        from diagnostic_msgs.msg import DiagnosticStatus, KeyValue

        level, message = self.level, self.message
        if self._errors_since_report:
            level = max(level, Level.ERROR)
            message = f"{message}; {len(self._errors_since_report)} callback error(s), the last: " \
                      f"{self._errors_since_report[-1]}"
        values = [KeyValue(key=str(k), value=str(v)) for k, v in self.values.items()]
        values += [KeyValue(key=k, value=str(v)) for k, v in sorted(self.counters.items())]
        return DiagnosticStatus(level=bytes([int(level)]), name=status_name(self.node), message=message,
                                hardware_id=self.node.get_fully_qualified_name(), values=values)

    def publish(self) -> None:
        from diagnostic_msgs.msg import DiagnosticArray

        try:
            array = DiagnosticArray(status=[self.status()])
            array.header.stamp = self.node.get_clock().now().to_msg()
            self.publisher.publish(array)
        except Exception as ex:  # e.g. the context is shutting down; never raise into the executor
            self.count("errors.diagnostics", f"cannot publish diagnostics: {type(ex).__name__}: {ex}")

