"""The uavcan_ros_bridge of design document section IV.B, driven by the generated tables and converters.

Two halves, so that neither direction waits on the other:

- UAVCAN -> ROS runs on the pycyphal (asyncio) event loop: one pycyphal subscriber per subject; its handler
  checks the sender against the mapping's configured source node ids, converts with the generated
  ``<mapping>_to_ros`` (receive time from the ROS clock) and publishes to ROS at once (rclpy's publish is
  thread-safe).
- ROS -> UAVCAN runs on the rclpy event loop, an executor spinning in its own thread: one ROS subscription
  per topic (fanning out to every mapping of that topic), converted there with ``<mapping>_to_uavcan`` and
  handed to the asyncio loop with ``call_soon_threadsafe`` (pycyphal is not thread-safe), where one bounded
  queue + worker task per mapping publishes on the mapping's subject, in order.

Cyphal v1 messages carry no destination: a command reaches its configured destination node because the
spec gives each actuator its own subject (the destination node id is checked against the devices table at
start-up and reported). Every problem with a value or a frame is a counted drop (per mapping, per reason),
never an exception out of a loop. The bridge is also a proper Cyphal node (heartbeat, GetInfo, registers)
and a proper ROS node (its parameters declared from the spec with their ranges, the spec's parameter rules
enforced on every set); it tracks every device's heartbeat and publishes its counters and the devices'
state as diagnostic_msgs/DiagnosticArray on /diagnostics once a second.
"""

from __future__ import annotations

import os

# Must precede any rclpy import in the process (loopback-only discovery on these machines).
os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")

import asyncio
import collections
import logging
import math
import operator
import sys
import threading
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from sam_runtime.genpkg import GeneratedPackage

__all__ = [
    "Bridge",
    "BridgeConfigError",
    "MappingStats",
    "TransportConfig",
    "cancel_and_wait",
    "quiet_late_media_completions",
    "ros_parameter_name",
]

_log = logging.getLogger("sam_runtime.bridge")

HEARTBEAT_STALE_S = 3.0
DEFAULT_QUEUE_SIZE = 256
DEFAULT_QOS_DEPTH = 100
_RULE_OPS: dict[str, Callable[[Any, Any], bool]] = {
    "<": operator.lt,
    "<=": operator.le,
    ">": operator.gt,
    ">=": operator.ge,
    "==": operator.eq,
    "!=": operator.ne,
}
_HEALTH = {0: "NOMINAL", 1: "ADVISORY", 2: "CAUTION", 3: "WARNING"}
_MODE = {0: "OPERATIONAL", 1: "INITIALIZATION", 2: "MAINTENANCE", 3: "SOFTWARE_UPDATE"}


class BridgeConfigError(Exception):
    """The generated tables, the transport or the parameters do not allow the bridge to start."""


@dataclass
class TransportConfig:
    """How the bridge reaches the Cyphal network.

    ``kind``: ``udp`` (default, ``iface`` default 127.0.0.1), ``can`` (``iface`` like ``virtual:bus0`` or
    ``socketcan:can0``, ``mtu`` 8 = Classic CAN, 64 = CAN FD), ``loopback``, or ``env``: the standard
    register environment variables (UAVCAN__UDP__IFACE, UAVCAN__CAN__IFACE, UAVCAN__CAN__MTU, ...) in
    ``environ`` (default ``os.environ``).
    """

    kind: str = "udp"
    iface: str | None = None
    mtu: int | None = None
    environ: Mapping[str, str] | None = None

    def describe(self) -> str:
        if self.kind == "env":
            env = os.environ if self.environ is None else self.environ
            keys = sorted(k for k in env if k.startswith("UAVCAN__") and k != "UAVCAN__NODE__ID")
            return "env(" + ", ".join(f"{k}={env[k]}" for k in keys) + ")"
        if self.kind == "udp":
            return f"udp:{self.iface or '127.0.0.1'}"
        if self.kind == "can":
            return f"can:{self.iface} mtu={self.mtu or 64}"
        return self.kind


class MappingStats:
    """Counters of one mapping. Also the ``stats`` object handed to the generated converters
    (``saturate(key)``, ``reject(key)``). Thread-safe: both event loops may touch it."""

    def __init__(self, lock: threading.Lock) -> None:
        self._lock = lock
        self.received = 0
        self.published = 0
        self.dropped: collections.Counter[str] = collections.Counter()
        self.saturated: collections.Counter[str] = collections.Counter()
        self.rejected: collections.Counter[str] = collections.Counter()
        self.last_published_monotonic: float | None = None

    # converter interface
    def saturate(self, key: str) -> None:
        with self._lock:
            self.saturated[str(key)] += 1

    def reject(self, key: str) -> None:
        with self._lock:
            self.rejected[str(key)] += 1

    # bridge interface
    def receive(self) -> None:
        with self._lock:
            self.received += 1

    def publish(self) -> None:
        with self._lock:
            self.published += 1
            self.last_published_monotonic = time.monotonic()

    def drop(self, reason: str) -> None:
        with self._lock:
            self.dropped[reason] += 1

    def snapshot(self) -> dict[str, Any]:
        with self._lock:
            return {
                "received": self.received,
                "published": self.published,
                "dropped": dict(self.dropped),
                "dropped_total": sum(self.dropped.values()),
                "saturated": dict(self.saturated),
                "rejected_fields": dict(self.rejected),
            }


@dataclass
class _HeartbeatRecord:
    node_id: int
    last_seen: float  # time.monotonic()
    health: int
    mode: int
    uptime: int
    vssc: int
    count: int = 1


@dataclass
class _OutMapping:
    """A ROS -> UAVCAN mapping at run time."""

    info: Any
    to_uavcan: Callable[..., Any]
    stats: MappingStats
    publisher: Any = None  # pycyphal Publisher
    queue: asyncio.Queue[Any] | None = None
    worker: asyncio.Task[None] | None = None


@dataclass
class _InMapping:
    """A UAVCAN -> ROS mapping at run time."""

    info: Any
    to_ros: Callable[..., Any]
    stats: MappingStats
    ros_publisher: Any = None
    has_header: bool = False


@dataclass
class _SubjectGroup:
    subject_id: int
    dtype: type
    mappings: list[_InMapping] = field(default_factory=list)
    subscriber: Any = None


def quiet_late_media_completions(loop: asyncio.AbstractEventLoop) -> None:
    """pycyphal's python-can media completes a frame's future from its TX thread with call_soon_threadsafe;
    when the awaiting task was cancelled meanwhile (a node closing, a send deadline), ``set_result`` on the
    cancelled future raises InvalidStateError inside the loop, which asyncio prints as a traceback. Those are
    harmless: log them at DEBUG level. Installed only when the loop has no exception handler of its own."""
    if loop.get_exception_handler() is not None:
        return

    def handler(lp: asyncio.AbstractEventLoop, context: dict[str, Any]) -> None:
        exc = context.get("exception")
        if isinstance(exc, asyncio.InvalidStateError) and "set_" in repr(context.get("handle", "")):
            _log.debug("late completion of a cancelled Cyphal media future: %s", context.get("handle"))
            return
        lp.default_exception_handler(context)

    loop.set_exception_handler(handler)


async def cancel_and_wait(tasks: Sequence[asyncio.Task[Any]], timeout: float = 2.0) -> list[asyncio.Task[Any]]:
    """Cancel tasks and wait for them, cancelling again while they run: on Python 3.11 a cancellation that
    lands inside pycyphal's ``wait_for`` can be lost, and a plain ``gather`` would then wait forever.
    Returns the tasks still running at the deadline."""
    loop = asyncio.get_running_loop()
    deadline = loop.time() + timeout
    pending = [t for t in tasks if not t.done()]
    while pending and loop.time() < deadline:
        for t in pending:
            t.cancel()
        await asyncio.wait(pending, timeout=min(0.05, max(0.0, deadline - loop.time())))
        pending = [t for t in pending if not t.done()]
    for t in tasks:
        if t.done() and not t.cancelled():
            t.exception()  # retrieved: no "exception was never retrieved" noise
    return pending


def ros_parameter_name(spec_name: str) -> str:
    """Spec parameter names are written like ROS 1 globals (``/safe_depth``); ROS 2 parameters are node-local
    names without the leading slash."""
    return spec_name.lstrip("/").replace("/", ".")


def _limited_log(counter: collections.Counter[tuple[str, str]], key: tuple[str, str], msg: str, *args: Any) -> None:
    """Warn on the first occurrence of a (mapping, reason), then only at DEBUG level (counters tell the rest)."""
    counter[key] += 1
    (_log.warning if counter[key] == 1 else _log.debug)(msg, *args)


class Bridge:
    """The bridge. Create it, then inside a running asyncio loop ``await start()``; ``await close()`` to stop.

    :param gen: the generated package (tables + converters).
    :param node_id: Cyphal node id; default ``UAVCAN__NODE__ID`` for an ``env`` transport, else the spec's
        bridge node id.
    :param transport: see :class:`TransportConfig`.
    :param ros_args: extra ROS arguments (``--ros-args ...``) for rclpy.init, e.g. remappings.
    :param parameter_overrides: initial values of the spec's parameters, by spec or ROS name.
    :param qos_depth: history depth of the ROS publishers and subscriptions (reliable, keep-last).
    :param command_reliability: ``reliable`` (default) or ``best_effort`` for the ROS command subscriptions.
    :param diagnostics_period: seconds between /diagnostics messages (0 disables them).
    """

    def __init__(
        self,
        gen: GeneratedPackage,
        *,
        node_id: int | None = None,
        transport: TransportConfig | None = None,
        ros_args: Sequence[str] = (),
        parameter_overrides: Mapping[str, Any] | None = None,
        qos_depth: int = DEFAULT_QOS_DEPTH,
        queue_size: int = DEFAULT_QUEUE_SIZE,
        command_reliability: str = "reliable",
        diagnostics_period: float = 1.0,
    ) -> None:
        self.gen = gen
        self.tables = gen.tables()
        self.transport_config = transport or TransportConfig()
        self.node_id = self._resolve_node_id(node_id)
        self._ros_args = list(ros_args)
        self._overrides = dict(parameter_overrides or {})
        self._qos_depth = int(qos_depth)
        self._queue_size = int(queue_size)
        if command_reliability not in ("reliable", "best_effort"):
            raise BridgeConfigError(f"command_reliability must be reliable or best_effort, not {command_reliability!r}")
        self._command_reliability = command_reliability
        self._diag_period = float(diagnostics_period)

        self._lock = threading.Lock()
        self._log_counts: collections.Counter[tuple[str, str]] = collections.Counter()
        self._mstats: dict[str, MappingStats] = {}
        self._in_groups: dict[int, _SubjectGroup] = {}
        self._out: dict[str, _OutMapping] = {}
        self._out_by_topic: dict[str, list[_OutMapping]] = {}
        self._heartbeats: dict[int, _HeartbeatRecord] = {}
        self._devices_by_id = {d.node_id: d for d in self.tables.DEVICES}
        self._errors: collections.Counter[str] = collections.Counter()

        self._loop: asyncio.AbstractEventLoop | None = None
        self._cy_node: Any = None
        self._hb_sub: Any = None
        self._ros_ctx: Any = None
        self._ros_node: Any = None
        self._executor: Any = None
        self._spin_thread: threading.Thread | None = None
        self._stop_spin = threading.Event()
        self._started_monotonic: float | None = None
        self._closed = False
        self._diag_pub: Any = None
        self._ros_pubs: dict[str, Any] = {}
        self._ros_subs: dict[str, Any] = {}

    # ------------------------------------------------------------------------------------------ set-up
    def _resolve_node_id(self, node_id: int | None) -> int:
        if node_id is not None:
            return int(node_id)
        if self.transport_config.kind == "env":
            env = os.environ if self.transport_config.environ is None else self.transport_config.environ
            raw = str(env.get("UAVCAN__NODE__ID", "")).strip()
            if raw:
                try:
                    return int(raw)
                except ValueError:
                    raise BridgeConfigError(f"UAVCAN__NODE__ID={raw!r} is not an integer") from None
        return int(self.tables.BRIDGE_NODE_ID)

    @property
    def name(self) -> str:
        return str(self.tables.BRIDGE_NAME)

    async def start(self) -> None:
        """Import the converters, bring up the ROS node and the Cyphal node, then start both halves."""
        if self._loop is not None:
            raise RuntimeError("Bridge.start() called twice")
        self._loop = asyncio.get_running_loop()
        quiet_late_media_completions(self._loop)
        convert = self.gen.convert()  # compiles the DSDL first (before uavcan/pycyphal.application)
        converters = getattr(convert, "CONVERTERS", {})
        try:
            self._check_tables()
            self._start_ros(convert, converters)
            await self._start_cyphal(converters)
        except BaseException:
            await self.close()
            raise
        self._started_monotonic = time.monotonic()
        self._stop_spin.clear()
        self._spin_thread = threading.Thread(target=self._spin, name=f"{self.name}-rclpy", daemon=True)
        self._spin_thread.start()
        _log.info(
            "%s started: Cyphal node %d on %s, %d UAVCAN->ROS and %d ROS->UAVCAN mappings",
            self.name, self.node_id, self.transport_config.describe(),
            sum(len(g.mappings) for g in self._in_groups.values()), len(self._out),
        )

    def _check_tables(self) -> None:
        for m in self.tables.MAPPINGS:
            if m.direction == "ros_to_uavcan" and m.destination_node_id is not None:
                dev = self._devices_by_id.get(m.destination_node_id)
                if dev is None:
                    _log.warning("mapping %s: destination node %s is no device of the spec", m.name,
                                 m.destination_node_id)
                elif all(p.subject_id != m.port.subject_id for p in dev.subscribes):
                    _log.warning("mapping %s: destination %s (node %d) does not subscribe to subject %d",
                                 m.name, dev.name, dev.node_id, m.port.subject_id)

    def _converter(self, convert: Any, converters: Mapping[str, Any], m: Any, which: int) -> Callable[..., Any]:
        fname = m.to_ros if which == 0 else m.to_uavcan
        fn = getattr(convert, fname, None) if fname else None
        if fn is None and m.name in converters:
            fn = converters[m.name][which]
        if fn is None:
            raise BridgeConfigError(f"the generated converters have no {fname or m.name!r} for mapping {m.name}")
        return fn

    # ROS side -----------------------------------------------------------------------------------
    def _start_ros(self, convert: Any, converters: Mapping[str, Any]) -> None:
        import rclpy
        from diagnostic_msgs.msg import DiagnosticArray
        from rclpy.executors import SingleThreadedExecutor
        from rclpy.node import Node
        from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy
        from rclpy.signals import SignalHandlerOptions

        self._ros_ctx = rclpy.Context()
        rclpy.init(args=[], context=self._ros_ctx, signal_handler_options=SignalHandlerOptions.NO)
        cli_args = None
        if self._ros_args:
            cli_args = self._ros_args if self._ros_args[0] == "--ros-args" else ["--ros-args", *self._ros_args]
        self._ros_node = Node(self.name, context=self._ros_ctx, cli_args=cli_args)
        self._clock = self._ros_node.get_clock()
        self._declare_parameters()

        reliable = QoSProfile(depth=self._qos_depth, history=HistoryPolicy.KEEP_LAST,
                              reliability=ReliabilityPolicy.RELIABLE)
        cmd_qos = QoSProfile(
            depth=self._qos_depth, history=HistoryPolicy.KEEP_LAST,
            reliability=ReliabilityPolicy.RELIABLE if self._command_reliability == "reliable"
            else ReliabilityPolicy.BEST_EFFORT,
        )
        for m in self.tables.MAPPINGS:
            stats = self._mstats.setdefault(m.name, MappingStats(self._lock))
            ros_cls = self.gen.ros_class(m.topic)
            if m.direction == "uavcan_to_ros":
                pub = self._ros_pubs.get(m.topic.name)
                if pub is None:
                    pub = self._ros_node.create_publisher(ros_cls, m.topic.name, reliable)
                    self._ros_pubs[m.topic.name] = pub
                group = self._in_groups.get(m.port.subject_id)
                if group is None:
                    group = _SubjectGroup(m.port.subject_id, self.gen.dsdl_class(m.port))
                    self._in_groups[m.port.subject_id] = group
                elif group.dtype is not self.gen.dsdl_class(m.port):
                    raise BridgeConfigError(
                        f"subject {m.port.subject_id} has two types: {group.dtype} and {m.port.dsdl_type}")
                group.mappings.append(_InMapping(
                    m, self._converter(convert, converters, m, 0), stats, pub,
                    has_header="header" in getattr(ros_cls, "get_fields_and_field_types", dict)(),
                ))
            elif m.direction == "ros_to_uavcan":
                om = _OutMapping(m, self._converter(convert, converters, m, 1), stats)
                self._out[m.name] = om
                self._out_by_topic.setdefault(m.topic.name, []).append(om)
            else:
                raise BridgeConfigError(f"mapping {m.name}: unknown direction {m.direction!r}")
        for topic, oms in self._out_by_topic.items():
            ros_cls = self.gen.ros_class(oms[0].info.topic)
            self._ros_subs[topic] = self._ros_node.create_subscription(
                ros_cls, topic, lambda msg, oms=oms: self._on_ros(oms, msg), cmd_qos)
        if self._diag_period > 0:
            self._diag_pub = self._ros_node.create_publisher(DiagnosticArray, "/diagnostics", 10)
            self._ros_node.create_timer(self._diag_period, self._publish_diagnostics)
        self._executor = SingleThreadedExecutor(context=self._ros_ctx)
        self._executor.add_node(self._ros_node)

    def _declare_parameters(self) -> None:
        from rcl_interfaces.msg import (
            FloatingPointRange,
            IntegerRange,
            ParameterDescriptor,
            ParameterType,
            SetParametersResult,
        )

        overrides = {ros_parameter_name(k): v for k, v in self._overrides.items()}
        known = set()
        for p in self.tables.PARAMETERS:
            name = ros_parameter_name(p.name)
            known.add(name)
            desc = ParameterDescriptor(name=name, description=p.description + (f" [{p.unit}]" if p.unit else ""))
            value: Any = overrides.get(name, p.default)
            ptype = str(p.type).lower()
            if ptype in ("double", "float", "float64", "float32"):
                desc.type = ParameterType.PARAMETER_DOUBLE
                value = float(value)
                if p.minimum is not None or p.maximum is not None:
                    lo = -sys.float_info.max if p.minimum is None else float(p.minimum)
                    hi = sys.float_info.max if p.maximum is None else float(p.maximum)
                    desc.floating_point_range = [FloatingPointRange(from_value=lo, to_value=hi, step=0.0)]
            elif ptype in ("int", "integer", "int64", "int32"):
                desc.type = ParameterType.PARAMETER_INTEGER
                value = int(value)
                if p.minimum is not None or p.maximum is not None:
                    lo = -(2**63) if p.minimum is None else math.ceil(p.minimum)
                    hi = 2**63 - 1 if p.maximum is None else math.floor(p.maximum)
                    desc.integer_range = [IntegerRange(from_value=int(lo), to_value=int(hi), step=1)]
            elif ptype in ("bool", "boolean"):
                desc.type = ParameterType.PARAMETER_BOOL
                value = value if isinstance(value, bool) else str(value).lower() in ("1", "true", "yes", "on")
            else:
                desc.type = ParameterType.PARAMETER_STRING
                value = str(value)
            try:
                self._ros_node.declare_parameter(name, value, desc)
            except Exception as ex:  # range violations of an override, invalid names
                raise BridgeConfigError(f"parameter {name}: {type(ex).__name__}: {ex}") from None
        unknown = set(overrides) - known
        if unknown:
            raise BridgeConfigError(f"unknown parameter(s) {sorted(unknown)}; the spec declares {sorted(known)}")
        current = {n: self._ros_node.get_parameter(n).value for n in known}
        problem = self._rule_violation(current)
        if problem:
            raise BridgeConfigError(f"initial parameters break a rule: {problem}")

        def on_set(params: list[Any]) -> Any:
            values = {n: self._ros_node.get_parameter(n).value for n in known}
            for prm in params:
                values[prm.name] = prm.value
            reason = self._rule_violation(values)
            return SetParametersResult(successful=reason is None, reason=reason or "")

        self._ros_node.add_on_set_parameters_callback(on_set)

    def _rule_violation(self, values: Mapping[str, Any]) -> str | None:
        for rule in getattr(self.tables, "PARAMETER_RULES", ()):
            left, right = ros_parameter_name(rule.left), ros_parameter_name(rule.right)
            op = _RULE_OPS.get(rule.op)
            if op is None or left not in values or right not in values:
                continue
            lv, rv = values[left], values[right]
            try:
                ok = op(lv, rv)
            except TypeError:
                ok = False
            if not ok:
                return f"{left}={lv} must be {rule.op} {right}={rv}: {rule.description}"
        return None

    # Cyphal side --------------------------------------------------------------------------------
    async def _start_cyphal(self, converters: Mapping[str, Any]) -> None:
        import uavcan.node

        from sam_runtime.transport import make_node, transport_from_env

        tc = self.transport_config
        name = f"org.{self.tables.VEHICLE}.{self.name}"[:50]
        if tc.kind == "env":
            env = dict(os.environ if tc.environ is None else tc.environ)
            env["UAVCAN__NODE__ID"] = str(self.node_id)
            transport = transport_from_env(env)
            self._cy_node = make_node(name, self.node_id, transport=transport)
        else:
            self._cy_node = make_node(name, self.node_id, tc.kind, iface=tc.iface, mtu=tc.mtu)
        self._cy_node.heartbeat_publisher.mode = uavcan.node.Mode_1_0.OPERATIONAL
        for om in self._out.values():
            om.publisher = self._cy_node.make_publisher(self.gen.dsdl_class(om.info.port), om.info.port.subject_id)
            om.publisher.send_timeout = 1.0
            om.queue = asyncio.Queue(maxsize=self._queue_size)
            om.worker = asyncio.create_task(self._out_worker(om), name=f"bridge-out-{om.info.name}")
        for group in self._in_groups.values():
            group.subscriber = self._cy_node.make_subscriber(group.dtype, group.subject_id)
            group.subscriber.receive_in_background(
                lambda msg, transfer, group=group: self._on_uavcan(group, msg, transfer))
        self._hb_sub = self._cy_node.make_subscriber(uavcan.node.Heartbeat_1_0)
        self._hb_sub.receive_in_background(self._on_heartbeat)

    # ------------------------------------------------------------------------------------------ UAVCAN -> ROS
    def _on_uavcan(self, group: _SubjectGroup, msg: Any, transfer: Any) -> None:
        """Runs on the asyncio loop for every received transfer of the group's subject."""
        src = transfer.source_node_id
        receive_ns: int | None = None
        for im in group.mappings:
            st = im.stats
            st.receive()
            name = im.info.name
            if src is None or src not in im.info.source_node_ids:
                st.drop("unknown_source")
                _limited_log(self._log_counts, (name, "unknown_source"),
                             "mapping %s: dropped a transfer from node %s (accepted: %s)",
                             name, src, sorted(im.info.source_node_ids))
                continue
            if receive_ns is None:
                receive_ns = self._clock.now().nanoseconds
            try:
                ros_msg = im.to_ros(msg, receive_ns, st)
            except Exception as ex:
                st.drop("convert_error")
                _limited_log(self._log_counts, (name, "convert_error"),
                             "mapping %s: conversion failed: %s: %s", name, type(ex).__name__, ex)
                continue
            if ros_msg is None:
                st.drop("rejected")
                continue
            if im.has_header:
                hdr = ros_msg.header
                if not hdr.frame_id and im.info.frame_id:
                    hdr.frame_id = im.info.frame_id
                if hdr.stamp.sec == 0 and hdr.stamp.nanosec == 0:
                    hdr.stamp.sec, hdr.stamp.nanosec = divmod(receive_ns, 1_000_000_000)
            try:
                im.ros_publisher.publish(ros_msg)
            except Exception as ex:
                st.drop("publish_error")
                _limited_log(self._log_counts, (name, "publish_error"),
                             "mapping %s: ROS publish failed: %s: %s", name, type(ex).__name__, ex)
                continue
            st.publish()

    def _on_heartbeat(self, msg: Any, transfer: Any) -> None:
        nid = transfer.source_node_id
        if nid is None:
            return
        rec = self._heartbeats.get(nid)
        now = time.monotonic()
        if rec is None:
            self._heartbeats[nid] = _HeartbeatRecord(
                nid, now, int(msg.health.value), int(msg.mode.value), int(msg.uptime),
                int(msg.vendor_specific_status_code))
        else:
            rec.last_seen, rec.health, rec.mode = now, int(msg.health.value), int(msg.mode.value)
            rec.uptime, rec.vssc, rec.count = int(msg.uptime), int(msg.vendor_specific_status_code), rec.count + 1

    # ------------------------------------------------------------------------------------------ ROS -> UAVCAN
    def _on_ros(self, oms: list[_OutMapping], msg: Any) -> None:
        """Runs in the rclpy executor thread for every message of a command topic."""
        loop = self._loop
        for om in oms:
            st = om.stats
            st.receive()
            name = om.info.name
            try:
                obj = om.to_uavcan(msg, st)
            except Exception as ex:
                st.drop("convert_error")
                _limited_log(self._log_counts, (name, "convert_error"),
                             "mapping %s: conversion failed: %s: %s", name, type(ex).__name__, ex)
                continue
            if obj is None:
                st.drop("rejected")
                continue
            try:
                assert loop is not None
                loop.call_soon_threadsafe(self._enqueue, om, obj)
            except RuntimeError:  # loop closed: shutting down
                st.drop("shutdown")

    def _enqueue(self, om: _OutMapping, obj: Any) -> None:
        """On the asyncio loop: queue for the mapping's worker (keeps the order, bounds the backlog)."""
        if om.queue is None or self._closed:
            om.stats.drop("shutdown")
            return
        try:
            om.queue.put_nowait(obj)
        except asyncio.QueueFull:
            om.stats.drop("queue_full")
            _limited_log(self._log_counts, (om.info.name, "queue_full"),
                         "mapping %s: Cyphal publish queue full (%d): dropping", om.info.name, self._queue_size)

    async def _out_worker(self, om: _OutMapping) -> None:
        assert om.queue is not None
        while not self._closed:
            obj = await om.queue.get()
            try:
                ok = await om.publisher.publish(obj)
            except asyncio.CancelledError:
                om.stats.drop("shutdown")
                raise
            except Exception as ex:
                om.stats.drop("publish_error")
                _limited_log(self._log_counts, (om.info.name, "publish_error"),
                             "mapping %s: Cyphal publish failed: %s: %s", om.info.name, type(ex).__name__, ex)
                continue
            if ok:
                om.stats.publish()
            else:
                om.stats.drop("publish_timeout")

    # ------------------------------------------------------------------------------------------ rclpy thread
    def _spin(self) -> None:
        while not self._stop_spin.is_set():
            try:
                self._executor.spin_once(timeout_sec=0.1)
            except Exception as ex:  # a callback bug or a context going down: keep spinning until told
                if self._stop_spin.is_set() or not self._ros_ctx.ok():
                    break
                self._errors["spin_error"] += 1
                _limited_log(self._log_counts, ("executor", "spin_error"),
                             "rclpy executor: %s: %s", type(ex).__name__, ex)

    # ------------------------------------------------------------------------------------------ reporting
    def stats(self) -> dict[str, Any]:
        """A JSON-serialisable snapshot of every counter, the devices' heartbeats and the bridge itself."""
        now = time.monotonic()
        mappings: dict[str, Any] = {}
        for m in self.tables.MAPPINGS:
            st = self._mstats.get(m.name)
            entry = {
                "direction": m.direction,
                "topic": m.topic.name,
                "subject_id": m.port.subject_id,
                **(st.snapshot() if st else {"received": 0, "published": 0, "dropped": {}, "dropped_total": 0,
                                             "saturated": {}, "rejected_fields": {}}),
            }
            if m.direction == "uavcan_to_ros":
                entry["source_node_ids"] = sorted(m.source_node_ids)
                group = self._in_groups.get(m.port.subject_id)
                if group is not None and group.subscriber is not None:
                    try:
                        s = group.subscriber.sample_statistics()
                        entry["cyphal"] = {
                            "transfers": s.transport_session.transfers, "frames": s.transport_session.frames,
                            "errors": s.transport_session.errors, "drops": s.transport_session.drops,
                            "deserialization_failures": s.deserialization_failures,
                        }
                    except Exception:  # closed
                        pass
                pub = self._ros_pubs.get(m.topic.name)
                entry["ros_subscribers"] = self._safe_count(pub, "get_subscription_count")
            else:
                entry["destination_node_id"] = m.destination_node_id
                om = self._out.get(m.name)
                entry["queued"] = om.queue.qsize() if om is not None and om.queue is not None else 0
                entry["ros_publishers"] = self._safe_count(self._ros_subs.get(m.topic.name), "get_publisher_count")
            mappings[m.name] = entry
        devices: dict[str, Any] = {}
        for d in self.tables.DEVICES:
            rec = self._heartbeats.get(d.node_id)
            devices[d.name] = self._hb_entry(d.node_id, rec, now)
        known = {d.node_id for d in self.tables.DEVICES} | {self.node_id}
        others = {str(nid): self._hb_entry(nid, rec, now) for nid, rec in sorted(self._heartbeats.items())
                  if nid not in known}
        return {
            "bridge": {
                "name": self.name,
                "node_id": self.node_id,
                "transport": self.transport_config.describe(),
                "uptime_s": round(now - self._started_monotonic, 3) if self._started_monotonic else 0.0,
                "errors": dict(self._errors),
            },
            "mappings": mappings,
            "devices": devices,
            "other_nodes": others,
        }

    @staticmethod
    def _safe_count(obj: Any, method: str) -> int | None:
        if obj is None:
            return None
        try:
            return int(getattr(obj, method)())
        except Exception:
            return None

    @staticmethod
    def _hb_entry(nid: int, rec: _HeartbeatRecord | None, now: float) -> dict[str, Any]:
        if rec is None:
            return {"node_id": nid, "seen": False}
        age = now - rec.last_seen
        return {
            "node_id": nid, "seen": True, "age_s": round(age, 3), "alive": age < HEARTBEAT_STALE_S,
            "health": _HEALTH.get(rec.health, str(rec.health)), "mode": _MODE.get(rec.mode, str(rec.mode)),
            "uptime_s": rec.uptime, "vssc": rec.vssc, "heartbeats": rec.count,
        }

    def _publish_diagnostics(self) -> None:
        """rclpy timer (executor thread): the counters and device states as a DiagnosticArray."""
        try:
            self._diag_pub.publish(self.diagnostics_message())
        except Exception as ex:
            self._errors["diagnostics_error"] += 1
            _limited_log(self._log_counts, ("diagnostics", "error"), "diagnostics: %s: %s", type(ex).__name__, ex)

    def diagnostics_message(self) -> Any:
        from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue

        snap = self.stats()
        arr = DiagnosticArray()
        arr.header.stamp = self._clock.now().to_msg()
        ok, warn, err, stale = (bytes([v]) for v in (0, 1, 2, 3))

        def kv(values: Mapping[str, Any]) -> list[Any]:
            return [KeyValue(key=str(k), value=str(v)) for k, v in values.items()]

        b = snap["bridge"]
        total_drop = sum(m["dropped_total"] for m in snap["mappings"].values())
        arr.status.append(DiagnosticStatus(
            level=ok, name=f"{self.name}", hardware_id=f"cyphal node {b['node_id']}",
            message=f"{len(snap['mappings'])} mappings, {total_drop} dropped",
            values=kv({"node_id": b["node_id"], "transport": b["transport"], "uptime_s": b["uptime_s"],
                       "dropped_total": total_drop, **{f"error.{k}": v for k, v in b["errors"].items()}}),
        ))
        for name, m in snap["mappings"].items():
            values: dict[str, Any] = {
                "direction": m["direction"], "topic": m["topic"], "subject_id": m["subject_id"],
                "received": m["received"], "published": m["published"], "dropped": m["dropped_total"],
            }
            values.update({f"dropped.{k}": v for k, v in sorted(m["dropped"].items())})
            values.update({f"saturated.{k}": v for k, v in sorted(m["saturated"].items())})
            values.update({f"rejected.{k}": v for k, v in sorted(m["rejected_fields"].items())})
            cy = m.get("cyphal") or {}
            values.update({f"cyphal.{k}": v for k, v in cy.items()})
            bad_frames = int(cy.get("errors", 0)) + int(cy.get("deserialization_failures", 0))
            level = warn if m["dropped_total"] or bad_frames else ok
            msg = f"{m['dropped_total']} dropped" if m["dropped_total"] else "ok"
            if bad_frames:
                msg += f", {bad_frames} bad Cyphal frames/transfers"
            arr.status.append(DiagnosticStatus(
                level=level, name=f"{self.name}/mapping/{name}", hardware_id=f"subject {m['subject_id']}",
                message=msg, values=kv(values)))
        for name, d in snap["devices"].items():
            if not d["seen"]:
                level, msg = stale, "no heartbeat"
            elif not d["alive"]:
                level, msg = stale, f"heartbeat {d['age_s']:.1f} s old"
            else:
                level = {"NOMINAL": ok, "ADVISORY": ok, "CAUTION": warn}.get(d["health"], err)
                msg = f"{d['health']} {d['mode']}"
            arr.status.append(DiagnosticStatus(
                level=level, name=f"{self.name}/device/{name}", hardware_id=f"cyphal node {d['node_id']}",
                message=msg, values=kv({k: v for k, v in d.items() if k != "seen"})))
        return arr

    # ------------------------------------------------------------------------------------------ shutdown
    async def close(self) -> None:
        """Stop the ROS half first (no more hand-offs), then close the Cyphal ports, then the nodes."""
        if self._closed:
            return
        self._closed = True
        self._stop_spin.set()
        if self._spin_thread is not None:
            await asyncio.get_running_loop().run_in_executor(None, self._spin_thread.join, 5.0)
        stuck = await cancel_and_wait([om.worker for om in self._out.values() if om.worker is not None])
        if stuck:
            _log.warning("%d publish workers did not stop", len(stuck))
        from sam_runtime.transport import aclose

        ports = [g.subscriber for g in self._in_groups.values()] + [om.publisher for om in self._out.values()]
        ports.append(self._hb_sub)
        try:
            await aclose(*[p for p in ports if p is not None])
            if self._cy_node is not None:
                await aclose(self._cy_node)
        except Exception as ex:  # never let a close problem hide the ROS shutdown
            _log.warning("closing the Cyphal node: %s: %s", type(ex).__name__, ex)
        if self._executor is not None:
            try:
                self._executor.shutdown(timeout_sec=1.0)
            except Exception:
                pass
        if self._ros_node is not None:
            try:
                self._ros_node.destroy_node()
            except Exception:
                pass
        if self._ros_ctx is not None:
            try:
                if self._ros_ctx.ok():
                    self._ros_ctx.shutdown()
            except Exception:
                pass

    async def __aenter__(self) -> Bridge:
        await self.start()
        return self

    async def __aexit__(self, *exc: object) -> None:
        await self.close()
