"""The uavcan_ros_bridge of design document section IV.B, driven by the generated tables and converters.

Two halves, so that neither direction waits on the other:

- UAVCAN -> ROS runs on the pycyphal (asyncio) event loop: one pycyphal subscriber per subject; its handler
  checks the sender against the mapping's configured source node ids, converts with the generated
  ``<mapping>_to_ros`` (receive time from the node's ROS clock: the system clock, read directly, unless
  use_sim_time is set) and publishes to ROS at once (rclpy's publish is thread-safe).
- ROS -> UAVCAN runs on the rclpy event loop, an executor spinning in its own thread: one ROS subscription
  per topic (fanning out to every mapping of that topic), converted there with ``<mapping>_to_uavcan`` and
  handed to the asyncio loop (pycyphal is not thread-safe) through a deque drained by one
  ``call_soon_threadsafe`` per batch, where one bounded queue + worker task per mapping publishes on the
  mapping's subject, in order.

Cyphal v1 messages carry no destination: a command reaches its configured destination node because the
spec gives each actuator its own subject (the destination node id is checked against the devices table at
start-up and reported). Every problem with a value or a frame is a counted drop (per mapping, per reason),
never an exception out of a loop. The bridge is also a proper Cyphal node (heartbeat, GetInfo, registers)
and a proper ROS node (its parameters declared from the spec with their ranges, the spec's parameter rules
enforced on every set); it tracks every device's heartbeat and publishes its counters and the devices'
state as diagnostic_msgs/DiagnosticArray on /diagnostics once a second.

Faults, and what the bridge does about them (issue 4). Nothing raises out of either loop; every message that
does not become a publication is counted per mapping under ``dropped.<reason>``:

=====================  ====================================================================================
reason                 when
=====================  ====================================================================================
``unknown_source``     a transfer from a node id the mapping does not accept (spoofing, a stray node)
``rejected``           the converter refused a value under the mapping's ``reject`` policy (NaN into an
                       integer or a limited field, a value missing from a table, ...)
``convert_error``      the converter raised (a bug: logged, counted, the loop goes on)
``handler_error``      the receive handler itself failed (a bug: likewise)
``publish_error``      the ROS publish or the Cyphal publish raised (e.g. a CAN bus error, ENOBUFS)
``not_sent``           the Cyphal transport did not send every frame before the 1 s deadline (pycyphal's
                       python-can media also reports a ``can.CanError`` this way)
``queue_full``         ROS -> UAVCAN: the mapping's bounded Cyphal publish queue was full (overload)
``link_down``          ROS -> UAVCAN: the Cyphal transport was being reopened after it failed
``shutdown``           the bridge was closing
``lost``               transfers of an accepted source that never reached the bridge: gaps in that source's
                       transfer ids. Whatever the cause below the bridge - a datagram the kernel dropped in a
                       burst, a frame that failed its CRC, a transfer that did not deserialize, the subject's
                       bounded receive queue (``rx_queue_size``) overflowing - each such transfer is counted
                       exactly once, when the next transfer of that source arrives. Exact on Cyphal/UDP
                       (64-bit transfer ids); on Cyphal/CAN (modulo 32) exact while fewer than 16 transfers
                       of the source were due in the gap (by its measured or nominal rate), not counted
                       beyond (unless the bridge's link was down: next reason). A source that restarted
                       meanwhile (heartbeat uptime shorter than the gap) is not counted.
``lost_link_down``     Cyphal/CAN only, an estimate: transfers of an accepted source missed while the bridge's
                       own Cyphal link was down (see ``_can_gap``: the transfer-id gap modulo 32 plus the
                       multiple of 32 closest to the source's rate x the time without data)
=====================  ====================================================================================

So per UAVCAN -> ROS mapping, once nothing is in flight and the sources sent again after a loss: the transfers
its accepted sources sent == ``published + dropped_total - dropped.unknown_source``, and ``received`` (what
reached the bridge) == ``published`` + the drops other than ``lost``. The causes below the bridge are
pycyphal's counters of the subject, polled every 0.2 s and on every :meth:`Bridge.stats`, reported per
mapping as ``cyphal.*``: ``errors`` (datagrams/frames that do not parse, transfers failing their CRC,
multi-frame transfers with missing frames, duplicate or stale transfer ids - ``error.<kind>`` names them, per
source node on UDP), ``deserialization_failures``, ``overruns`` (receive queue full), ``drops`` (the transport's
own queue). They count frames from any sender, also ones that never were a valid transfer of an accepted
source, so they are not added to ``dropped``; any of them, like any drop, makes the mapping WARN in
/diagnostics for 10 s. Saturated values are counted per field under ``saturated.<mapping>.<field>`` (the
message is still published), rejected ones under ``rejected.<...>``.

- Out-of-order data: pycyphal itself discards a transfer whose transfer id is not newer than the last one of
  that source within the 2 s transfer-id timeout (a duplicate or a reordered frame: ``cyphal.errors``). A
  device timestamp (``header.stamp``) older than the previous message of the same source on the same mapping
  is published anyway, in arrival order, and counted under ``out_of_order``: the bridge never reorders or
  holds data back, and the stamp tells ROS consumers (tf2, message_filters, estimators) what to do with it.
  A device that restarted (its heartbeat's uptime went down; on Cyphal/UDP also its transfer ids starting over)
  may have restarted its clock: its next stamp is compared with nothing.
- Unknown timestamps (0): the ROS receive time. float16 NaN/+-inf from a device are passed to ROS unchanged
  (float32/float64 hold them); the devices' ranges are the consumers' business.
- Logging is bounded: the first occurrence of a (mapping, reason) is a WARNING at once, later ones are
  summed and logged at most once per ``log_interval`` seconds (default 10) with the count since the previous
  line; saturations and rejections likewise. Nothing stays unlogged: pending counts are flushed at close.
- Heartbeats: a device is alive while its last uavcan.node.Heartbeat is younger than the Cyphal offline
  timeout (3 s). The moment it is not, /diagnostics shows it at ERROR (published at once, not at the next
  period), and it is logged; when heartbeats come back it is OK again (a restart - uptime going backwards - is
  counted and logged). A device never heard of is STALE. Nodes that are no device of the spec (tools such as
  yakut) are tracked in the stats; their first appearance is logged at INFO, their comings and goings at DEBUG.
- Silence: a UAVCAN -> ROS mapping that gets nothing from its device while the device's heartbeat is alive -
  never, or no more - for longer than max(3 s, 5 nominal periods) is WARN in /diagnostics ("no message for N s
  while device X is alive; nominal R Hz"), logged once when it starts and when it ends (sam_runtime.liveness).
- Cyphal ports and registers: the bridge's ports are named after its mappings, with the standard registers
  ``uavcan.sub.<mapping>.id``/``.type`` and ``uavcan.pub.<mapping>.id``/``.type`` (a subject of several mappings:
  the first one's name) whose defaults are the spec's subject ids, overridable as usual (e.g.
  ``UAVCAN__SUB__IMU__ID``), and ``uavcan.node.id`` (sam_runtime.cyphal_ports).
- A Cyphal transport that dies (pycyphal's CAN media close themselves for good on unrecoverable OS errors,
  e.g. ENETDOWN when a SocketCAN interface goes down) is detected within 0.2 s and reopened with back-off
  (0.5 s doubling to 2 s) until it works again; meanwhile commands are dropped as ``link_down`` and
  /diagnostics shows the bridge at ERROR. Transient bus errors (a send raising) are counted and the next
  message goes through.
- ROS QoS: each topic's from the spec (``qos``: sensor data best effort, commands and states reliable, ...).
  A slow or stuck ROS subscriber never blocks UAVCAN -> ROS: the ROS publishers are keep-last, so DDS drops that
  subscriber's oldest samples (reliable topics) or never waits for it (best effort) instead of blocking the bridge.
- Security: a mapping accepts transfers only from its spec's source node ids (``unknown_source`` otherwise);
  actuators (the simulated ones too) accept commands only from the bridge's node id. Cyphal/UDP binds
  127.0.0.1 and ROS discovery stays on localhost (ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST) unless the user
  configures an interface (``--iface``, UAVCAN__UDP__IFACE, or that variable) explicitly.
"""

from __future__ import annotations

import os

# Must precede any rclpy import in the process (loopback-only discovery on these machines).
os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")

import asyncio
import collections
import logging
import threading
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from sam_runtime.cyphal_ports import (
    PortConfigError,
    register_environment,
    register_node_id,
    resolve_subject,
    subscription_names,
)
from sam_runtime.genpkg import GeneratedPackage
from sam_runtime.liveness import LivenessMonitor
from sam_runtime.node_support import ros_parameter_name

__all__ = [
    "Bridge",
    "BridgeConfigError",
    "MappingStats",
    "RateLimitedLog",
    "TransportConfig",
    "cancel_and_wait",
    "quiet_late_media_completions",
    "ros_parameter_name",
]

_log = logging.getLogger("sam_runtime.bridge")

HEARTBEAT_STALE_S = 3.0  # uavcan.node.Heartbeat.OFFLINE_TIMEOUT
DEFAULT_QUEUE_SIZE = 256
DEFAULT_RX_QUEUE_SIZE = 1000
DEFAULT_LOG_INTERVAL_S = 10.0
HOUSEKEEPING_PERIOD_S = 0.2
RECENT_DROP_WINDOW_S = 10.0  # a mapping's diagnostics level is WARN while it dropped within this window
TRANSFER_ID_TIMEOUT_S = 2.0  # Cyphal's default transfer-id timeout
REOPEN_BACKOFF_S = (0.5, 2.0)
DROP_REASONS = ("unknown_source", "rejected", "convert_error", "handler_error", "publish_error", "not_sent",
                "queue_full", "link_down", "shutdown", "lost", "lost_link_down")
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
    ``environ`` (default ``os.environ``), or ``custom``: ``factory(node_id)`` returns a new pycyphal transport
    (called again whenever the bridge reopens a failed transport; e.g. special CAN media, fault injection).
    """

    kind: str = "udp"
    iface: str | None = None
    mtu: int | None = None
    environ: Mapping[str, str] | None = None
    factory: Callable[[int], Any] | None = None

    def describe(self) -> str:
        if self.kind == "custom":
            return f"custom({getattr(self.factory, '__name__', self.factory)!s})"
        if self.kind == "env":
            env = os.environ if self.environ is None else self.environ
            keys = sorted(k for k in env if k.startswith("UAVCAN__") and k != "UAVCAN__NODE__ID")
            return "env(" + ", ".join(f"{k}={env[k]}" for k in keys) + ")"
        if self.kind == "udp":
            return f"udp:{self.iface or '127.0.0.1'}"
        if self.kind == "can":
            return f"can:{self.iface} mtu={self.mtu or 64}"
        return self.kind


class RateLimitedLog:
    """At most one log line per key (e.g. (mapping, reason)) per ``interval`` seconds, with the count since the
    previous line. The first occurrence of a key is logged at once. Thread-safe; formatting is lazy."""

    def __init__(self, logger: logging.Logger, interval: float = DEFAULT_LOG_INTERVAL_S) -> None:
        self.logger = logger
        self.interval = float(interval)
        self._lock = threading.Lock()
        # key -> [last_emit_monotonic, pending, total, level, msg, args]
        self._state: dict[tuple[str, str], list[Any]] = {}
        self.lines: collections.Counter[tuple[str, str]] = collections.Counter()  # lines written per key

    def note(self, key: tuple[str, str], level: int, msg: str, *args: Any, count: int = 1) -> None:
        now = time.monotonic()
        emit: tuple[int, float, int] | None = None
        with self._lock:
            st = self._state.get(key)
            if st is None:
                self._state[key] = [now, 0, count, level, msg, args]
                emit = (count, 0.0, count)
            else:
                st[1] += count
                st[2] += count
                st[3], st[4], st[5] = level, msg, args
                if now - st[0] >= self.interval:
                    emit = (st[1], now - st[0], st[2])
                    st[0], st[1] = now, 0
            if emit is not None:
                self.lines[key] += 1
        if emit is not None:
            self._emit(key, level, msg, args, *emit)

    def flush(self, force: bool = False) -> None:
        """Write the pending counts whose interval has passed (all of them with ``force``)."""
        now = time.monotonic()
        out = []
        with self._lock:
            for key, st in self._state.items():
                if st[1] and (force or now - st[0] >= self.interval):
                    out.append((key, st[3], st[4], st[5], st[1], now - st[0], st[2]))
                    st[0], st[1] = now, 0
                    self.lines[key] += 1
        for key, level, msg, args, n, dt, total in out:
            self._emit(key, level, msg, args, n, dt, total)

    def _emit(self, key: tuple[str, str], level: int, msg: str, args: tuple[Any, ...], n: int, dt: float,
              total: int) -> None:
        if not self.logger.isEnabledFor(level):
            return
        try:
            detail = msg % args if args else msg
        except Exception:  # a bad format must not break the caller
            detail = f"{msg} {args!r}"
        if dt == 0.0 and n == total:
            self.logger.log(level, "%s: %s: %s (%d; more are summed at most every %.0f s)", key[0], key[1],
                            detail, n, self.interval)
        else:
            self.logger.log(level, "%s: %s: %d in the last %.1f s (%d in all); the last: %s", key[0], key[1], n,
                            dt, total, detail)


class MappingStats:
    """Counters of one mapping. Also the ``stats`` object handed to the generated converters
    (``saturate(key)``, ``reject(key)``). Thread-safe: both event loops may touch it.

    ``name`` and ``log`` (optional) make saturations and rejections logged at a bounded rate."""

    def __init__(self, lock: threading.Lock, name: str = "", log: RateLimitedLog | None = None) -> None:
        self._lock = lock
        self.name = name
        self._log = log
        self.received = 0
        self.published = 0
        self.out_of_order = 0
        self.dropped: collections.Counter[str] = collections.Counter()
        self.saturated: collections.Counter[str] = collections.Counter()
        self.rejected: collections.Counter[str] = collections.Counter()
        self.last_published_monotonic: float | None = None
        self.last_drop_monotonic: float | None = None

    # converter interface
    def saturate(self, key: str) -> None:
        with self._lock:
            self.saturated[str(key)] += 1
        if self._log is not None:
            self._log.note((self.name, "saturated"), logging.WARNING, "saturated %s", key)

    def reject(self, key: str) -> None:
        with self._lock:
            self.rejected[str(key)] += 1
        if self._log is not None:
            self._log.note((self.name, "rejected"), logging.WARNING, "rejected a message for %s", key)

    # bridge interface
    def receive(self) -> None:
        with self._lock:
            self.received += 1

    def publish(self) -> None:
        with self._lock:
            self.published += 1
            self.last_published_monotonic = time.monotonic()

    def drop(self, reason: str, count: int = 1) -> None:
        if count <= 0:
            return
        with self._lock:
            self.dropped[reason] += count
            self.last_drop_monotonic = time.monotonic()

    def reorder(self) -> None:
        with self._lock:
            self.out_of_order += 1

    def snapshot(self) -> dict[str, Any]:
        with self._lock:
            return {
                "received": self.received,
                "published": self.published,
                "dropped": dict(self.dropped),
                "dropped_total": sum(self.dropped.values()),
                "saturated": dict(self.saturated),
                "saturated_total": sum(self.saturated.values()),
                "rejected_fields": dict(self.rejected),
                "out_of_order": self.out_of_order,
                "last_drop_age_s": None if self.last_drop_monotonic is None
                else round(time.monotonic() - self.last_drop_monotonic, 3),
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
    alive: bool = True  # as last reported (transitions are logged and published at once)
    lost_events: int = 0  # times the heartbeat timed out
    restarts: int = 0  # times the uptime went backwards
    alive_since: float = 0.0  # time.monotonic() when the heartbeat (re)appeared


@dataclass
class _OutMapping:
    """A ROS -> UAVCAN mapping at run time."""

    info: Any
    to_uavcan: Callable[..., Any]
    stats: MappingStats
    publisher: Any = None  # pycyphal Publisher
    port_id: int | None = None  # the subject it publishes on (register uavcan.pub.<mapping>.id)
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
    last_stamp_ns: dict[int, int] = field(default_factory=dict)  # per source: stamp of the last published message


@dataclass
class _SubjectGroup:
    subject_id: int  # the spec's
    dtype: type
    mappings: list[_InMapping] = field(default_factory=list)
    subscriber: Any = None
    port_name: str = ""  # register uavcan.sub.<port_name>.id
    port_id: int | None = None  # the subject it listens on (the register's value, default the spec's)
    accepted_sources: frozenset[int] = frozenset()
    last_tid: dict[int, tuple[int, float]] = field(default_factory=dict)  # source -> (transfer id, monotonic s)
    rate: dict[int, tuple[float, int, float]] = field(default_factory=dict)  # source -> (since, count, rate)
    # pycyphal's counters of the current subscriber already turned into drops (reset with a new subscriber)
    seen: dict[str, int] = field(default_factory=dict)
    # cumulative pycyphal counters over every subscriber this group had (transport reopened)
    cyphal_total: dict[str, int] = field(default_factory=dict)
    error_kinds: collections.Counter[str] = field(default_factory=collections.Counter)
    last_problem_monotonic: float | None = None


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


def _error_kinds(session_stats: Any) -> dict[str, int]:
    """pycyphal's breakdown of a session's errors, where the transport gives one (UDP: reassembly errors per
    source node; CAN: reception error counters)."""
    out: collections.Counter[str] = collections.Counter()
    per_src = getattr(session_stats, "reassembly_errors_per_source_node_id", None)
    if isinstance(per_src, dict):
        for src, errs in per_src.items():
            for err, n in errs.items():
                if n:
                    out[f"{getattr(err, 'name', err)}.node{src}"] += int(n)
    for attr in ("reassembly_errors", "reception_error_counters"):
        errs = getattr(session_stats, attr, None)
        if isinstance(errs, dict):
            for err, n in errs.items():
                if n:
                    out[str(getattr(err, "name", err))] += int(n)
    return dict(out)


class Bridge:
    """The bridge. Create it, then inside a running asyncio loop ``await start()``; ``await close()`` to stop.

    :param gen: the generated package (tables + converters).
    :param node_id: Cyphal node id; default ``UAVCAN__NODE__ID`` for an ``env`` transport, else the spec's
        bridge node id.
    :param transport: see :class:`TransportConfig`.
    :param ros_args: extra ROS arguments (``--ros-args ...``) for rclpy.init, e.g. remappings.
    :param parameter_overrides: initial values of the spec's parameters, by spec or ROS name.
    :param qos_depth: history depth of the ROS publishers and subscriptions (keep-last); default: each topic's
        from the spec (its ``qos``, like reliability and durability).
    :param command_reliability: ``reliable`` or ``best_effort`` for the ROS command subscriptions; default: the
        topic's from the spec.
    :param diagnostics_period: seconds between /diagnostics messages (0 disables them).
    :param queue_size: bound of each ROS -> UAVCAN mapping's Cyphal publish queue (beyond: ``queue_full``).
    :param rx_queue_size: bound of each subject's pycyphal receive queue (beyond: ``overrun``); 0 = unbounded.
    :param log_interval: seconds between two log lines of one (mapping, reason); the first is immediate.
    """

    def __init__(
        self,
        gen: GeneratedPackage,
        *,
        node_id: int | None = None,
        transport: TransportConfig | None = None,
        ros_args: Sequence[str] = (),
        parameter_overrides: Mapping[str, Any] | None = None,
        qos_depth: int | None = None,
        queue_size: int = DEFAULT_QUEUE_SIZE,
        command_reliability: str | None = None,
        diagnostics_period: float = 1.0,
        rx_queue_size: int = DEFAULT_RX_QUEUE_SIZE,
        log_interval: float = DEFAULT_LOG_INTERVAL_S,
    ) -> None:
        self.gen = gen
        self.tables = gen.tables()
        self.transport_config = transport or TransportConfig()
        self.node_id = self._resolve_node_id(node_id)
        self._ros_args = list(ros_args)
        self._overrides = dict(parameter_overrides or {})
        self._qos_depth = None if qos_depth is None else int(qos_depth)
        self._queue_size = int(queue_size)
        if command_reliability not in (None, "reliable", "best_effort"):
            raise BridgeConfigError(f"command_reliability must be reliable or best_effort, not {command_reliability!r}")
        self._command_reliability = command_reliability
        self._diag_period = float(diagnostics_period)

        self._rx_queue_size = int(rx_queue_size)
        self._lock = threading.Lock()
        self._poll_lock = threading.Lock()
        self.log = RateLimitedLog(_log, log_interval)
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
        self._spin_future: Any = None  # see _start_ros
        self._spin_thread: threading.Thread | None = None
        self._stop_spin = threading.Event()
        self._started_monotonic: float | None = None
        self._closed = False
        self._diag_pub: Any = None
        self._ros_pubs: dict[str, Any] = {}
        self._ros_subs: dict[str, Any] = {}
        self._ros_time_active = False  # see _start_ros
        # ROS -> UAVCAN hand-off (see _on_ros): converted objects in arrival order, and whether a drain is
        # already scheduled on the asyncio loop.
        self._handoff: collections.deque[tuple[_OutMapping, Any]] = collections.deque()
        self._handoff_scheduled = False
        self._housekeeping_task: asyncio.Task[None] | None = None
        self._reopen_task: asyncio.Task[None] | None = None
        # The Cyphal link: reopened when the transport dies (see _check_link).
        self._link_up = False
        self._link_state = "not started"
        self._link_suspect: str | None = None
        self._link_down_since: float | None = None
        self._link_outages = 0
        self._link_down_s = 0.0
        self._tid_modulo = 2**64
        self._outage_windows: collections.deque[tuple[float, float]] = collections.deque(maxlen=16)
        self._nominal_rates = {(d.node_id, p.subject_id): float(p.rate_hz) for d in self.tables.DEVICES
                               for p in d.publishes if getattr(p, "rate_hz", None)}
        self._link_up_since = 0.0  # time.monotonic() of the last (re)open of the Cyphal node
        # UAVCAN -> ROS mappings silent while their device is alive (sam_runtime.liveness)
        self._liveness = LivenessMonitor(
            [(m.name, m.rate_hz, m.source_node_ids) for m in self.tables.MAPPINGS if m.direction == "uavcan_to_ros"],
            {d.node_id: d.name for d in self.tables.DEVICES})
        self._subject_of = {m.name: m.port.subject_id for m in self.tables.MAPPINGS}
        self._sub_names = subscription_names(self.tables.MAPPINGS)  # subject -> port name (cyphal_ports)

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
        self._housekeeping_task = asyncio.create_task(self._housekeeping(), name=f"{self.name}-housekeeping")
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
        from rclpy.signals import SignalHandlerOptions

        self._ros_ctx = rclpy.Context()
        rclpy.init(args=[], context=self._ros_ctx, signal_handler_options=SignalHandlerOptions.NO)
        cli_args = None
        if self._ros_args:
            cli_args = self._ros_args if self._ros_args[0] == "--ros-args" else ["--ros-args", *self._ros_args]
        self._ros_node = Node(self.name, context=self._ros_ctx, cli_args=cli_args)
        self._clock = self._ros_node.get_clock()
        # Receive stamps: the node's ROS clock reads the system clock (CLOCK_REALTIME, as time.time_ns) unless
        # use_sim_time made ROS time active; time.time_ns costs ~0.06 us against ~2.4 us for Clock.now(), so the
        # clock is asked only while ROS time is active (tracked after every parameter set: use_sim_time may
        # change at run time).
        self._ros_time_active = bool(self._clock.ros_time_is_active)
        self._ros_node.add_post_set_parameters_callback(self._after_set_parameters)
        self._declare_parameters()

        for m in self.tables.MAPPINGS:
            stats = self._mstats.setdefault(m.name, MappingStats(self._lock, m.name, self.log))
            ros_cls = self.gen.ros_class(m.topic)
            if m.direction == "uavcan_to_ros":
                pub = self._ros_pubs.get(m.topic.name)
                if pub is None:
                    pub = self._ros_node.create_publisher(ros_cls, m.topic.name, self._topic_qos(m.topic))
                    self._ros_pubs[m.topic.name] = pub
                group = self._in_groups.get(m.port.subject_id)
                if group is None:
                    group = _SubjectGroup(m.port.subject_id, self.gen.dsdl_class(m.port),
                                          port_name=self._sub_names[m.port.subject_id])
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
                ros_cls, topic, lambda msg, oms=oms: self._on_ros(oms, msg),
                self._topic_qos(oms[0].info.topic, self._command_reliability))
        if self._diag_period > 0:
            self._diag_pub = self._ros_node.create_publisher(DiagnosticArray, "/diagnostics", 10)
            self._ros_node.create_timer(self._diag_period, self._publish_diagnostics)
        try:
            # The events executor does not rebuild a wait set per wake-up: ~3x the command throughput
            # of SingleThreadedExecutor here (bench/profile_bridge.py).
            from rclpy.experimental import EventsExecutor

            self._executor = EventsExecutor(context=self._ros_ctx)
            # _spin runs it in 0.1 s slices (spin_until_future_complete on a future that never completes)
            # instead of returning to Python after every callback as spin_once does: ~15 % less CPU per command
            # in the rclpy thread (`python -m bench.profile_bridge ab`). Not for the Python executors: they add
            # a done callback to the future on every call.
            from rclpy.task import Future

            self._spin_future = Future()
        except ImportError:
            self._executor = SingleThreadedExecutor(context=self._ros_ctx)
        self._executor.add_node(self._ros_node)

    def _topic_qos(self, topic: Any, reliability: str | None = None) -> Any:
        """The topic's QoS from the spec (sensor data best effort, commands reliable, ...); ``qos_depth`` and
        ``command_reliability`` override the depth and the commands' reliability when given."""
        from sam_runtime.node_support import qos_profile

        q = topic.qos
        return qos_profile(reliability or q.reliability, q.durability,
                           q.depth if self._qos_depth is None else self._qos_depth)

    def _after_set_parameters(self, params: list[Any]) -> None:
        self._ros_time_active = bool(self._clock.ros_time_is_active)

    def _receive_ns(self) -> int:
        """The ROS receive time in nanoseconds (the node's clock: system time, or ROS time under use_sim_time)."""
        return self._clock.now().nanoseconds if self._ros_time_active else time.time_ns()

    def _declare_parameters(self) -> None:
        """The spec's parameters with their ranges and rules (sam_runtime.node_support, as the generated nodes)."""
        from sam_runtime.node_support import ParameterConfigError, declare_parameters

        try:
            declare_parameters(self._ros_node, self.tables.PARAMETERS, getattr(self.tables, "PARAMETER_RULES", ()),
                               overrides=self._overrides)
        except ParameterConfigError as ex:
            raise BridgeConfigError(str(ex)) from None

    # Cyphal side --------------------------------------------------------------------------------
    async def _start_cyphal(self, converters: Mapping[str, Any]) -> None:
        for om in self._out.values():
            om.queue = asyncio.Queue(maxsize=self._queue_size)
        for group in self._in_groups.values():
            group.accepted_sources = frozenset(n for im in group.mappings for n in im.info.source_node_ids)
        try:
            self._open_cyphal()
        except PortConfigError as ex:
            raise BridgeConfigError(str(ex)) from None
        for om in self._out.values():
            om.worker = asyncio.create_task(self._out_worker(om), name=f"bridge-out-{om.info.name}")

    def _make_transport(self) -> Any:
        from sam_runtime.transport import make_transport, transport_from_env

        tc = self.transport_config
        if tc.kind == "env":
            env = dict(os.environ if tc.environ is None else tc.environ)
            env["UAVCAN__NODE__ID"] = str(self.node_id)
            return transport_from_env(env)
        if tc.kind == "custom":
            if tc.factory is None:
                raise BridgeConfigError("a custom transport needs a factory")
            return tc.factory(self.node_id)
        return make_transport(tc.kind, node_id=self.node_id, iface=tc.iface, mtu=tc.mtu)

    def _open_cyphal(self) -> None:
        """The Cyphal node and every port (at start and whenever the transport is reopened)."""
        import uavcan.node

        from sam_runtime.transport import make_node

        name = f"org.{self.tables.VEHICLE}.{self.name}"[:50]
        tc = self.transport_config
        env = tc.environ if tc.kind == "env" and tc.environ is not None else os.environ
        # The registers (uavcan.node.id, uavcan.pub/sub.<port>.id/.type) and their UAVCAN__* overrides.
        node = make_node(name, self.node_id, transport=self._make_transport(), environ=register_environment(env))
        try:
            register_node_id(node.registry, self.node_id)
            node.heartbeat_publisher.mode = uavcan.node.Mode_1_0.OPERATIONAL
            transport = node.presentation.transport
            self._tid_modulo = int(transport.protocol_parameters.transfer_id_modulo)
            if hasattr(transport, "add_error_hook"):  # CAN: media errors (bus off, error passive, ...) counted
                transport.add_error_hook(self._on_transport_error)
            rxq = self._rx_queue_size if self._rx_queue_size > 0 else None
            for om in self._out.values():
                dtype = self.gen.dsdl_class(om.info.port)
                om.port_id = resolve_subject(node.registry, "pub", om.info.name, dtype, om.info.port.subject_id)
                pub = node.presentation.make_publisher(dtype, om.port_id)
                pub.send_timeout = 1.0
                om.publisher = pub
            for group in self._in_groups.values():
                group.port_id = resolve_subject(node.registry, "sub", group.port_name, group.dtype, group.subject_id)
                group.subscriber = node.presentation.make_subscriber(group.dtype, group.port_id, rxq)
                group.seen = {}
                group.subscriber.receive_in_background(
                    lambda msg, transfer, group=group: self._on_uavcan(group, msg, transfer))
            self._hb_sub = node.make_subscriber(uavcan.node.Heartbeat_1_0)
            self._hb_sub.receive_in_background(self._on_heartbeat)
        except BaseException:
            node.close()
            raise
        self._cy_node = node
        self._link_up, self._link_state, self._link_suspect = True, "up", None
        self._link_up_since = time.monotonic()

    async def _close_cyphal(self) -> None:
        """Close every Cyphal port and the node (the workers and their queues stay)."""
        from sam_runtime.transport import aclose

        self._poll_cyphal_stats()  # what the old subscribers counted is not lost
        ports: list[Any] = [g.subscriber for g in self._in_groups.values()] + [
            om.publisher for om in self._out.values()]
        ports.append(self._hb_sub)
        for g in self._in_groups.values():
            g.subscriber = None
        for om in self._out.values():
            om.publisher = None
        self._hb_sub = None
        node, self._cy_node = self._cy_node, None
        try:
            await aclose(*[p for p in ports if p is not None])
            if node is not None:
                await aclose(node)
        except Exception as ex:  # a dead transport may refuse to close cleanly
            _log.warning("closing the Cyphal node: %s: %s", type(ex).__name__, ex)

    def _on_transport_error(self, timestamp: Any, error: Any) -> None:
        kind = getattr(error, "name", str(error))
        self._errors[f"cyphal.{kind}"] += 1
        self.log.note(("cyphal", kind), logging.WARNING, "transport error %s", kind)

    @staticmethod
    def _transport_dead(transport: Any) -> bool:
        """Best effort: pycyphal's CAN media close themselves for good on unrecoverable OS errors (the python-can
        media on any OSError of its receive thread, SocketCAN on ENETDOWN & co.); the transport then only raises
        ResourceClosedError. A redundant transport is dead when all its inferiors are."""
        inferiors = getattr(transport, "inferiors", None)
        if isinstance(inferiors, list | tuple) and inferiors:
            return all(Bridge._transport_dead(t) for t in inferiors)
        if not hasattr(transport, "_maybe_media"):
            return False
        media = transport._maybe_media
        return media is None or bool(getattr(media, "_closed", False))

    def _check_link(self) -> str | None:
        """Why the Cyphal link needs reopening, or None."""
        if self._cy_node is None:
            return "no Cyphal node"
        if self._link_suspect:
            return self._link_suspect
        try:
            if self._transport_dead(self._cy_node.presentation.transport):
                return "the transport's media closed itself"
        except Exception as ex:
            return f"{type(ex).__name__}: {ex}"
        return None

    async def _reopen_cyphal(self, reason: str) -> None:
        """Close the failed node and open a new one, with back-off, until it works or the bridge closes."""
        self._link_up, self._link_state = False, f"down: {reason}"
        self._link_outages += 1
        self._link_down_since = time.monotonic()
        self._errors["transport_down"] += 1
        _log.error("Cyphal transport %s failed (%s): reopening", self.transport_config.describe(), reason)
        self._publish_diagnostics()
        await self._close_cyphal()
        delay = REOPEN_BACKOFF_S[0]
        attempts = 0
        while not self._closed:
            attempts += 1
            try:
                self._open_cyphal()
                break
            except Exception as ex:
                self._errors["transport_reopen_failed"] += 1
                self._link_state = f"down: {reason}; reopen attempt {attempts}: {type(ex).__name__}: {ex}"
                self.log.note(("cyphal", "reopen_failed"), logging.WARNING, "reopening the transport: %s: %s",
                              type(ex).__name__, ex)
                await asyncio.sleep(delay)
                delay = min(delay * 2.0, REOPEN_BACKOFF_S[1])
        if self._link_down_since is not None:
            down = time.monotonic() - self._link_down_since
            self._outage_windows.append((self._link_down_since, time.monotonic()))
            self._link_down_s += down
            self._link_down_since = None
            if self._link_up:
                self._errors["transport_reopened"] += 1
                _log.warning("Cyphal transport reopened after %.1f s (%d attempts)", down, attempts)
                self._publish_diagnostics()

    # ------------------------------------------------------------------------------------------ housekeeping
    async def _housekeeping(self) -> None:
        """Every 0.2 s on the asyncio loop: pycyphal's counters into drops, heartbeat timeouts, the link, the
        bounded-rate log. Never raises (a failure is counted and the next round runs)."""
        while not self._closed:
            await asyncio.sleep(HOUSEKEEPING_PERIOD_S)
            try:
                self._poll_cyphal_stats()
                self._check_heartbeats()
                self._check_liveness()
                self.log.flush()
                if self._reopen_task is None or self._reopen_task.done():
                    why = self._check_link()
                    if why is not None and not self._closed:
                        self._reopen_task = asyncio.create_task(self._reopen_cyphal(why),
                                                                name=f"{self.name}-reopen")
            except asyncio.CancelledError:
                raise
            except Exception as ex:
                self._errors["housekeeping_error"] += 1
                self.log.note(("bridge", "housekeeping_error"), logging.ERROR, "housekeeping: %s: %s",
                              type(ex).__name__, ex)

    _CYPHAL_PROBLEMS = ("errors", "deserialization_failures", "overruns", "drops")

    def _poll_cyphal_stats(self) -> None:
        """Accumulate pycyphal's per-subject counters (they restart with each new subscriber) and log their
        increments at a bounded rate (thread-safe)."""
        with self._poll_lock:
            for group in self._in_groups.values():
                sub = group.subscriber
                if sub is None:
                    continue
                try:
                    s = sub.sample_statistics()
                except Exception:  # closed meanwhile
                    continue
                ts = s.transport_session
                now = {"transfers": ts.transfers, "frames": ts.frames, "errors": ts.errors, "drops": ts.drops,
                       "deserialization_failures": s.deserialization_failures, "overruns": s.overruns}
                kinds = _error_kinds(ts)
                for key, value in now.items():
                    delta = int(value) - group.seen.get(key, 0)
                    if delta <= 0:
                        continue
                    group.seen[key] = int(value)
                    group.cyphal_total[key] = group.cyphal_total.get(key, 0) + delta
                    if key in self._CYPHAL_PROBLEMS:
                        group.last_problem_monotonic = time.monotonic()
                        detail = ""
                        if key == "errors" and kinds:
                            detail = f" ({', '.join(f'{k} {v}' for k, v in sorted(kinds.items()))} in all)"
                        self.log.note((f"subject {group.subject_id}", f"cyphal.{key}"), logging.WARNING,
                                      "%d discarded by pycyphal below the bridge%s", delta, detail, count=delta)
                for k, v in kinds.items():
                    base = group.seen.get(f"kind.{k}", 0)
                    if v > base:
                        group.error_kinds[k] += v - base
                        group.seen[f"kind.{k}"] = v

    # ------------------------------------------------------------------------------------------ UAVCAN -> ROS
    def _on_uavcan(self, group: _SubjectGroup, msg: Any, transfer: Any) -> None:
        """Runs on the asyncio loop for every received transfer of the group's subject. Never raises."""
        try:
            self._bridge_transfer(group, msg, transfer)
        except Exception as ex:  # a bug: counted and logged, the receive loop goes on
            self._handler_failed([im.stats for im in group.mappings], f"subject {group.subject_id}", ex)

    def _handler_failed(self, stats: list[Any], where: str, ex: Exception) -> None:
        """A receive handler raised (a bug): one handler_error per mapping it serves, and a rate-bounded log line."""
        for st in stats:
            st.drop("handler_error")
        self._errors["handler_error"] += 1
        self.log.note((where, "handler_error"), logging.ERROR, "%s: %s", type(ex).__name__, ex)

    def _track_transfer_id(self, group: _SubjectGroup, src: int, transfer: Any) -> tuple[int, int]:
        """(lost, estimated): transfers lost before this one from ``src`` (a gap in its transfer ids), and, on
        CAN only, an estimate of those missed while the bridge's own link was down (see _can_gap)."""
        tid = int(transfer.transfer_id)
        try:
            now = transfer.timestamp.monotonic_ns * 1e-9  # .monotonic builds a Decimal
        except Exception:
            now = time.monotonic()
        prev = group.last_tid.get(src)
        group.last_tid[src] = (tid, now)
        if prev is None:
            return 0, 0
        modulo = self._tid_modulo
        d = (tid - prev[0]) % modulo
        if modulo < 2**32 and now - prev[1] > TRANSFER_ID_TIMEOUT_S:  # CAN: the ids may have wrapped meanwhile
            res = self._can_gap(group, src, prev[1], now, d, modulo)
            group.rate.pop(src, None)
            return res
        if d == 1:  # the source's actual rate over a long window (for _can_gap)
            t0, n, rate = group.rate.get(src, (prev[1], 0, 0.0))
            n += 1
            if now - t0 >= 2.0:
                rate = n / (now - t0)
            if now - t0 > 60.0:  # a new window, the old rate kept meanwhile
                t0, n = now, 0
            group.rate[src] = (t0, n, rate)
        elif d != 0:
            group.rate.pop(src, None)
        if d <= 1 or d >= modulo // 2:  # next in sequence, duplicate, or backwards (the source restarted)
            if d >= modulo // 2 and modulo >= 2**32:  # UDP: ids start over only when the node restarts
                self._forget_stamps(src)  # (whether its heartbeat said so before this message or not)
            return 0, 0
        return d - 1, 0

    def _can_gap(self, group: _SubjectGroup, src: int, t_prev: float, t_now: float, d: int,
                 modulo: int) -> tuple[int, int]:
        """A gap longer than the transfer-id timeout on Cyphal/CAN, where transfer ids wrap every 32: the gap is
        known only modulo 32, so the source's rate (measured before, else the spec's nominal rate) decides.
        A source whose heartbeat uptime is shorter than the gap restarted meanwhile: nothing is counted.
        If the bridge's own link was down in between (it knows it was deaf), (0, estimate): the gap modulo 32
        plus the multiple of 32 closest to rate x elapsed time, counted as ``lost_link_down``. Otherwise, if
        fewer than 16 transfers were due (no wrap possible) and the gap fits, (gap, 0): exact, as ``lost``."""
        rate = group.rate.get(src, (0.0, 0, 0.0))[2] or self._nominal_rates.get((src, group.subject_id))
        if not rate:
            return 0, 0
        elapsed = t_now - t_prev
        hb = self._heartbeats.get(src)
        if hb is not None and hb.uptime + 1 < elapsed:
            return 0, 0
        base = (d - 1) % modulo
        expected = rate * elapsed - 1.0
        if any(start < t_now and end > t_prev for start, end in self._outage_windows):
            k = max(0, round((expected - base) / modulo))
            return 0, base + k * modulo
        if expected < modulo / 2 and base <= expected + 2:
            return base, 0
        return 0, 0

    def _bridge_transfer(self, group: _SubjectGroup, msg: Any, transfer: Any) -> None:
        src = transfer.source_node_id
        receive_ns: int | None = None
        lost, lost_est = self._track_transfer_id(group, src, transfer) if src in group.accepted_sources else (0, 0)
        for im in group.mappings:
            st = im.stats
            st.receive()
            name = im.info.name
            if src is None or src not in im.info.source_node_ids:
                st.drop("unknown_source")
                self.log.note((name, "unknown_source"), logging.WARNING,
                              "dropped a transfer from node %s (accepted: %s)", src, sorted(im.info.source_node_ids))
                continue
            if lost:
                st.drop("lost", lost)
                self.log.note((name, "lost"), logging.WARNING, "%d transfers from node %s never arrived "
                              "(transfer id gap before %d)", lost, src, transfer.transfer_id, count=lost)
            if lost_est:
                st.drop("lost_link_down", lost_est)
                self.log.note((name, "lost_link_down"), logging.WARNING, "about %d transfers from node %s missed "
                              "while the Cyphal link was down (estimated from the nominal rate)", lost_est, src,
                              count=lost_est)
            if receive_ns is None:
                receive_ns = self._receive_ns()
            try:
                ros_msg = im.to_ros(msg, receive_ns, st)
            except Exception as ex:
                st.drop("convert_error")
                self.log.note((name, "convert_error"), logging.ERROR, "conversion failed: %s: %s",
                              type(ex).__name__, ex)
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
                stamp = hdr.stamp.sec * 1_000_000_000 + hdr.stamp.nanosec
                last = im.last_stamp_ns.get(src)
                im.last_stamp_ns[src] = stamp
                if last is not None and stamp < last:  # published anyway, in arrival order (see the docstring)
                    st.reorder()
                    self.log.note((name, "out_of_order"), logging.WARNING,
                                  "node %s: stamp %.6f s is older than the previous one (%.6f s); published",
                                  src, stamp * 1e-9, last * 1e-9)
            try:
                im.ros_publisher.publish(ros_msg)
            except Exception as ex:
                st.drop("publish_error")
                self.log.note((name, "publish_error"), logging.ERROR, "ROS publish failed: %s: %s",
                              type(ex).__name__, ex)
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
                int(msg.vendor_specific_status_code), alive_since=now)
            if nid not in self._devices_by_id and nid != self.node_id:  # a tool (yakut, ...): noted once
                _log.info("node %d (no device of the spec) appeared on the bus", nid)
            return
        uptime = int(msg.uptime)
        if not rec.alive or now - rec.last_seen >= HEARTBEAT_STALE_S:
            rec.alive_since = now  # back (possibly before housekeeping noticed it was gone)
        if uptime < rec.uptime:
            rec.restarts += 1
            rec.alive_since = now  # a device that just booted gets its grace before it must publish
            self._device_restarted(nid, rec.uptime, uptime)
        rec.last_seen, rec.health, rec.mode = now, int(msg.health.value), int(msg.mode.value)
        rec.uptime, rec.vssc, rec.count = uptime, int(msg.vendor_specific_status_code), rec.count + 1
        if not rec.alive:
            self._check_heartbeats()  # back: report at once

    def _device_restarted(self, nid: int, old_uptime: int, uptime: int) -> None:
        """A node restarted (its uptime went down): its device clock may have restarted too, so the next stamp of
        each of its mappings is compared with nothing (it is no ``out_of_order``)."""
        self._forget_stamps(nid)
        if nid in self._devices_by_id:
            _log.warning("%s restarted (uptime %d s, before %d s)", self._device_name(nid), uptime, old_uptime)
        else:
            _log.debug("node %d restarted (uptime %d s, before %d s)", nid, uptime, old_uptime)

    def _device_name(self, nid: int) -> str:
        dev = self._devices_by_id.get(nid)
        return f"device {dev.name} (node {nid})" if dev is not None else f"node {nid}"

    def _forget_stamps(self, nid: int) -> None:
        for group in self._in_groups.values():
            for im in group.mappings:
                im.last_stamp_ns.pop(nid, None)

    def _check_heartbeats(self) -> None:
        """Log and publish (at once) every change between alive and lost of a device's heartbeat. Other nodes
        (tools such as yakut come and go) are tracked and shown in stats, their comings and goings logged at
        DEBUG only."""
        now = time.monotonic()
        changed = False
        for nid, rec in list(self._heartbeats.items()):
            alive = now - rec.last_seen < HEARTBEAT_STALE_S
            if alive == rec.alive:
                continue
            rec.alive = alive
            if not alive:
                rec.lost_events += 1
            if nid not in self._devices_by_id:
                _log.debug("node %d: heartbeat %s", nid, "back" if alive else "gone")
                continue
            changed = True
            if alive:
                _log.info("%s: heartbeat back (uptime %d s, %d restarts seen)", self._device_name(nid),
                          rec.uptime, rec.restarts)
            else:
                _log.warning("%s: heartbeat lost (none for %.1f s)", self._device_name(nid), now - rec.last_seen)
        if changed:
            self._publish_diagnostics()

    def _alive_since(self, nid: int) -> float | None:
        rec = self._heartbeats.get(nid)
        if rec is None or time.monotonic() - rec.last_seen >= HEARTBEAT_STALE_S:
            return None
        return rec.alive_since

    def _last_message(self, mapping: str, nid: int) -> float | None:
        group = self._in_groups.get(self._subject_of[mapping])
        last = group.last_tid.get(nid) if group is not None else None
        return None if last is None else last[1]

    def _check_liveness(self) -> None:
        """Log and publish (at once) a UAVCAN -> ROS mapping going silent while its device is alive, and the end
        of it (sam_runtime.liveness)."""
        changes = self._liveness.update(time.monotonic(), alive_since=self._alive_since,
                                        last_message=self._last_message, listening_since=self._link_up_since)
        for name, before, found in changes:
            if found is not None:
                _log.warning("%s: %s", name, found.message())
            elif before is not None:
                why = ("messages again from" if self._alive_since(before.node_id) is not None
                       else "no longer watched: no heartbeat from")
                _log.info("%s: %s device %s (node %d)", name, why, before.device, before.node_id)
        if changes:
            self._publish_diagnostics()

    # ------------------------------------------------------------------------------------------ ROS -> UAVCAN
    def _on_ros(self, oms: list[_OutMapping], msg: Any) -> None:
        """Runs in the rclpy executor thread for every message of a command topic. Never raises: an exception
        out of a callback would also leave the EventsExecutor's queued messages waiting for the next one."""
        try:
            self._hand_off_ros(oms, msg)
        except Exception as ex:  # a bug: counted and logged, the executor goes on
            self._handler_failed([om.stats for om in oms], f"topic {oms[0].info.topic.name if oms else '?'}", ex)

    def _hand_off_ros(self, oms: list[_OutMapping], msg: Any) -> None:
        loop = self._loop
        for om in oms:
            st = om.stats
            st.receive()
            name = om.info.name
            try:
                obj = om.to_uavcan(msg, st)
            except Exception as ex:
                st.drop("convert_error")
                self.log.note((name, "convert_error"), logging.ERROR, "conversion failed: %s: %s",
                              type(ex).__name__, ex)
                continue
            if obj is None:
                st.drop("rejected")
                continue
            # One wake-up of the asyncio loop per batch, not per message: call_soon_threadsafe writes to the
            # loop's self-pipe (a syscall, and a GIL hand-over) every time. The drain (on the loop) clears the
            # flag before it empties the deque, so an object appended after its last look finds the flag clear
            # and schedules the next drain: nothing stays behind. Each object then meets the bounded queue in
            # _enqueue exactly as one call_soon_threadsafe per object did (same order, same drops).
            assert loop is not None  # (before the append: what fails here is counted, never also delivered)
            self._handoff.append((om, obj))
            if not self._handoff_scheduled or loop.is_closed():
                self._handoff_scheduled = True
                try:
                    loop.call_soon_threadsafe(self._drain_handoff)
                except RuntimeError:  # loop closed: shutting down (a drain scheduled before will never run)
                    self._handoff_scheduled = False
                    self._drop_handoff()

    def _drain_handoff(self) -> None:
        """On the asyncio loop: every object handed off since the last drain into its mapping's queue."""
        self._handoff_scheduled = False
        handoff = self._handoff
        while handoff:
            om, obj = handoff.popleft()
            self._enqueue(om, obj)

    def _drop_handoff(self) -> None:
        """Objects handed off that no drain will take any more (the loop closed): counted as ``shutdown``."""
        handoff = self._handoff
        while True:
            try:
                om, _ = handoff.popleft()
            except IndexError:
                return
            om.stats.drop("shutdown")

    def _enqueue(self, om: _OutMapping, obj: Any) -> None:
        """On the asyncio loop: queue for the mapping's worker (keeps the order, bounds the backlog)."""
        if om.queue is None or self._closed:
            om.stats.drop("shutdown")
            return
        try:
            om.queue.put_nowait(obj)
        except asyncio.QueueFull:
            om.stats.drop("queue_full")
            self.log.note((om.info.name, "queue_full"), logging.WARNING, "Cyphal publish queue full (%d): dropping",
                          self._queue_size)

    async def _out_worker(self, om: _OutMapping) -> None:
        import pycyphal.transport

        assert om.queue is not None
        name = om.info.name
        while not self._closed:
            obj = await om.queue.get()
            pub = om.publisher
            if pub is None or not self._link_up:
                om.stats.drop("link_down")
                self.log.note((name, "link_down"), logging.WARNING, "the Cyphal transport is being reopened")
                continue
            try:
                ok = await pub.publish(obj)
            except asyncio.CancelledError:
                om.stats.drop("shutdown")
                raise
            except Exception as ex:
                if self._closed:
                    om.stats.drop("shutdown")
                    continue
                if isinstance(ex, pycyphal.transport.ResourceClosedError) and om.publisher is pub:
                    self._link_suspect = f"publish on {om.info.port.subject_id}: {type(ex).__name__}: {ex}"
                om.stats.drop("publish_error")
                self.log.note((name, "publish_error"), logging.WARNING, "Cyphal publish failed: %s: %s",
                              type(ex).__name__, ex)
                continue
            if ok:
                om.stats.publish()
            else:
                om.stats.drop("not_sent")
                self.log.note((name, "not_sent"), logging.WARNING,
                              "Cyphal publish: not every frame sent within %.1f s", pub.send_timeout)

    # ------------------------------------------------------------------------------------------ rclpy thread
    def _spin(self) -> None:
        executor, future = self._executor, self._spin_future
        while not self._stop_spin.is_set():
            try:
                if future is not None:
                    executor.spin_until_future_complete(future, timeout_sec=0.1)
                else:
                    executor.spin_once(timeout_sec=0.1)
            except Exception as ex:  # a callback bug or a context going down: keep spinning until told
                if self._stop_spin.is_set() or not self._ros_ctx.ok():
                    break
                self._errors["spin_error"] += 1
                self.log.note(("executor", "spin_error"), logging.ERROR, "rclpy executor: %s: %s",
                              type(ex).__name__, ex)

    # ------------------------------------------------------------------------------------------ reporting
    def stats(self) -> dict[str, Any]:
        """A JSON-serialisable snapshot of every counter, the devices' heartbeats and the bridge itself.
        Polls pycyphal's counters first, so the below-bridge drops are current."""
        self._poll_cyphal_stats()
        now = time.monotonic()
        mappings: dict[str, Any] = {}
        empty = MappingStats(threading.Lock()).snapshot()
        for m in self.tables.MAPPINGS:
            st = self._mstats.get(m.name)
            entry = {
                "direction": m.direction,
                "topic": m.topic.name,
                "subject_id": m.port.subject_id,
                **(st.snapshot() if st else empty),
            }
            if m.direction == "uavcan_to_ros":
                entry["source_node_ids"] = sorted(m.source_node_ids)
                group = self._in_groups.get(m.port.subject_id)
                entry["port"] = f"uavcan.sub.{self._sub_names[m.port.subject_id]}"
                if group is not None and group.port_id is not None:
                    entry["subject_id"] = group.port_id  # the register's value (the spec's by default)
                silence = self._liveness.findings.get(m.name)
                entry["liveness"] = {"state": "ok"} if silence is None else {
                    "state": silence.state, "message": silence.message(), "node_id": silence.node_id,
                    "silent_s": round(silence.silent_s, 3), "grace_s": silence.grace_s,
                    "nominal_rate_hz": silence.rate_hz}
                if group is not None:
                    with self._poll_lock:
                        tot = dict(group.cyphal_total)
                        kinds = dict(group.error_kinds)
                    entry["cyphal"] = {
                        "transfers": tot.get("transfers", 0), "frames": tot.get("frames", 0),
                        "errors": tot.get("errors", 0), "drops": tot.get("drops", 0),
                        "deserialization_failures": tot.get("deserialization_failures", 0),
                        "overruns": tot.get("overruns", 0),
                    }
                    if kinds:
                        entry["cyphal"]["error_kinds"] = kinds
                    if group.last_problem_monotonic is not None:
                        entry["cyphal"]["last_problem_age_s"] = round(now - group.last_problem_monotonic, 3)
                pub = self._ros_pubs.get(m.topic.name)
                entry["ros_subscribers"] = self._safe_count(pub, "get_subscription_count")
            else:
                entry["destination_node_id"] = m.destination_node_id
                om = self._out.get(m.name)
                entry["port"] = f"uavcan.pub.{m.name}"
                if om is not None and om.port_id is not None:
                    entry["subject_id"] = om.port_id
                entry["queued"] = om.queue.qsize() if om is not None and om.queue is not None else 0
                entry["ros_publishers"] = self._safe_count(self._ros_subs.get(m.topic.name), "get_publisher_count")
            mappings[m.name] = entry
        devices: dict[str, Any] = {}
        heartbeats = self._heartbeats.copy()  # atomic: the asyncio thread may add a node meanwhile
        for d in self.tables.DEVICES:
            rec = heartbeats.get(d.node_id)
            devices[d.name] = self._hb_entry(d.node_id, rec, now)
        known = {d.node_id for d in self.tables.DEVICES} | {self.node_id}
        others = {str(nid): self._hb_entry(nid, rec, now) for nid, rec in sorted(heartbeats.items())
                  if nid not in known}
        down_s = self._link_down_s + (now - self._link_down_since if self._link_down_since is not None else 0.0)
        return {
            "bridge": {
                "name": self.name,
                "node_id": self.node_id,
                "transport": self.transport_config.describe(),
                "uptime_s": round(now - self._started_monotonic, 3) if self._started_monotonic else 0.0,
                "errors": dict(self._errors),
                "link": {"up": self._link_up, "state": self._link_state, "outages": self._link_outages,
                         "down_s": round(down_s, 3)},
                "log_lines": sum(self.log.lines.values()),
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
            return {"node_id": nid, "seen": False, "alive": False, "state": "never seen"}
        age = now - rec.last_seen
        alive = age < HEARTBEAT_STALE_S
        return {
            "node_id": nid, "seen": True, "age_s": round(age, 3), "alive": alive,
            "state": "alive" if alive else "stale",
            "health": _HEALTH.get(rec.health, str(rec.health)), "mode": _MODE.get(rec.mode, str(rec.mode)),
            "uptime_s": rec.uptime, "vssc": rec.vssc, "heartbeats": rec.count, "lost_events": rec.lost_events,
            "restarts": rec.restarts,
        }

    def _publish_diagnostics(self) -> None:
        """The counters and device states as a DiagnosticArray (rclpy timer, and at once on a device or link
        change; rclpy's publish is thread-safe). Never raises."""
        if self._diag_pub is None or self._closed:
            return
        try:
            self._diag_pub.publish(self.diagnostics_message())
        except Exception as ex:
            self._errors["diagnostics_error"] += 1
            self.log.note(("diagnostics", "error"), logging.ERROR, "diagnostics: %s: %s", type(ex).__name__, ex)

    def diagnostics_message(self) -> Any:
        """diagnostic_msgs/DiagnosticArray: one status for the bridge (ERROR while its Cyphal link is down), one
        per mapping (received, published, dropped and dropped.<reason>, saturated and saturated.<field>,
        rejected.<field>, out_of_order, pycyphal's counters; WARN while it dropped within the last 10 s, or while it
        gets nothing from a device whose heartbeat is alive for longer than its grace: sam_runtime.liveness), one per
        device (OK while its heartbeat is alive and its health NOMINAL/ADVISORY, WARN on CAUTION, ERROR on
        WARNING health or when the heartbeat is lost, STALE when never seen)."""
        from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue

        snap = self.stats()
        arr = DiagnosticArray()
        arr.header.stamp = self._clock.now().to_msg()
        ok, warn, err, stale = (bytes([v]) for v in (0, 1, 2, 3))

        def kv(values: Mapping[str, Any]) -> list[Any]:
            return [KeyValue(key=str(k), value=str(v)) for k, v in values.items()]

        b = snap["bridge"]
        link = b["link"]
        total_drop = sum(m["dropped_total"] for m in snap["mappings"].values())
        bmsg = f"{len(snap['mappings'])} mappings, {total_drop} dropped"
        if not link["up"]:
            bmsg = f"Cyphal link {link['state']}; " + bmsg
        arr.status.append(DiagnosticStatus(
            level=ok if link["up"] else err, name=f"{self.name}", hardware_id=f"cyphal node {b['node_id']}",
            message=bmsg,
            values=kv({"node_id": b["node_id"], "transport": b["transport"], "uptime_s": b["uptime_s"],
                       "dropped_total": total_drop, "link_up": link["up"], "link_state": link["state"],
                       "link_outages": link["outages"], "link_down_s": link["down_s"],
                       **{f"error.{k}": v for k, v in sorted(b["errors"].items())}}),
        ))
        for name, m in snap["mappings"].items():
            values: dict[str, Any] = {
                "direction": m["direction"], "topic": m["topic"], "subject_id": m["subject_id"], "port": m["port"],
                "received": m["received"], "published": m["published"], "dropped": m["dropped_total"],
            }
            values.update({f"dropped.{k}": v for k, v in sorted(m["dropped"].items())})
            values["saturated"] = m["saturated_total"]
            values.update({f"saturated.{k}": v for k, v in sorted(m["saturated"].items())})
            values.update({f"rejected.{k}": v for k, v in sorted(m["rejected_fields"].items())})
            values["out_of_order"] = m["out_of_order"]
            cy = dict(m.get("cyphal") or {})
            kinds = cy.pop("error_kinds", {})
            problem_age = cy.pop("last_problem_age_s", None)
            values.update({f"cyphal.{k}": v for k, v in cy.items()})
            values.update({f"cyphal.error.{k}": v for k, v in sorted(kinds.items())})
            recent = any(age is not None and age < RECENT_DROP_WINDOW_S
                         for age in (m["last_drop_age_s"], problem_age))
            level = warn if recent else ok
            if m["dropped_total"]:
                parts = ", ".join(f"{k} {v}" for k, v in sorted(m["dropped"].items()))
                msg = f"{m['dropped_total']} dropped ({parts})" + (
                    f", the last {m['last_drop_age_s']:.0f} s ago" if m["last_drop_age_s"] is not None else "")
            else:
                msg = "ok"
            if m["saturated_total"]:
                msg += f", {m['saturated_total']} values saturated"
            bad = sum(int(cy.get(k, 0)) for k in self._CYPHAL_PROBLEMS)
            if bad:
                msg += f", {bad} frames/transfers discarded by pycyphal"
            live = m.get("liveness")
            if live is not None:
                values["liveness"] = live["state"]
                if live["state"] != "ok":  # silent while its device is alive (sam_runtime.liveness)
                    level = warn
                    msg = live["message"] + ("" if msg == "ok" else f"; {msg}")
                    values.update(silent_s=live["silent_s"], grace_s=live["grace_s"],
                                  nominal_rate_hz=live["nominal_rate_hz"])
            arr.status.append(DiagnosticStatus(
                level=level, name=f"{self.name}/mapping/{name}", hardware_id=f"subject {m['subject_id']}",
                message=msg, values=kv(values)))
        for name, d in snap["devices"].items():
            if not d["seen"]:
                level, msg = stale, "no heartbeat yet"
            elif not d["alive"]:
                level, msg = err, f"heartbeat lost: none for {d['age_s']:.1f} s"
                if not link["up"]:
                    msg += " (the bridge's Cyphal link is down)"
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
        self._drain_handoff()  # what the rclpy thread handed off last: counted as shutdown (see _enqueue)
        tasks = [om.worker for om in self._out.values() if om.worker is not None]
        tasks += [t for t in (self._housekeeping_task, self._reopen_task) if t is not None]
        stuck = await cancel_and_wait(tasks)
        if stuck:
            _log.warning("%d bridge tasks did not stop", len(stuck))
        try:
            await self._close_cyphal()
        except Exception as ex:  # never let a close problem hide the ROS shutdown
            _log.warning("closing the Cyphal node: %s: %s", type(ex).__name__, ex)
        self._link_up, self._link_state = False, "closed"
        self.log.flush(force=True)  # no count stays unlogged
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
