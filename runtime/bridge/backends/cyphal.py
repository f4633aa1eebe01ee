"""The Cyphal v1 backend: a pycyphal.application node (heartbeat, GetInfo, registers) on a pycyphal transport, the
bridge's ports as named ports with the standard registers (sam_runtime.cyphal_io.ports), the devices' heartbeats as
device status events, pycyphal's per-subject counters, and the signs of a dead transport.

- Transports: :class:`TransportConfig` (UDP on 127.0.0.1 by default, CAN through pycyphal's media, loopback, the
  standard UAVCAN__* register variables, or a custom factory).
- Ports: ``uavcan.sub.<name>.id/.type`` and ``uavcan.pub.<name>.id/.type`` registers whose defaults are the spec's
  subject ids (overridable as usual, e.g. ``UAVCAN__SUB__IMU__ID``), and ``uavcan.node.id``.
- Cyphal v1 messages carry no destination: a command reaches its device because each actuator has its own subject.
- Below the bridge: pycyphal's counters of each subscription (``errors`` with their kinds per source node on UDP,
  ``deserialization_failures``, ``overruns`` of the bounded receive queue, ``drops``), accumulated across
  reopenings; increments are logged at a bounded rate.
- A dead transport: the CAN media close themselves for good on unrecoverable OS errors (the transport then only
  raises ResourceClosedError); a publish that finds its port closed says so too.
- Transmission times (a port that ``want_tx_times``, the time-sync master's): on Cyphal/UDP the kernel's software
  transmission timestamp of the session's socket (sam_runtime.common.tx_timestamps), read after every publish; on
  CAN through python-can the bounds of the media's transmit thread's send call (sam_runtime.cyphal_io.can_tx_times;
  pycyphal's own feedback there is the time its send coroutine resumed on the loop); else (SocketCAN media) none,
  and the master measures the send call.
"""

from __future__ import annotations

import collections
import logging
import math
import os
import socket
import threading
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from sam_runtime.bridge.backend import (
    Backend,
    BelowBridge,
    BridgeConfigError,
    DeviceStatus,
    Inlet,
    LinkDownError,
    Outlet,
)
from sam_runtime.bridge.backends.cyphal_wire import RawSender, Receiver, open_receiver
from sam_runtime.bridge.counters import log
from sam_runtime.common.rate_log import RateLimitedLog
from sam_runtime.common.tx_timestamps import KernelTxStamps, TxWindow
from sam_runtime.cyphal_io.can_tx_times import CanTxTimes
from sam_runtime.cyphal_io.ports import PortConfigError, register_environment, register_node_id, resolve_subject
from sam_runtime.cyphal_io.transport import aclose, make_node, make_transport, transport_from_env

__all__ = ["DEFAULT_RX_QUEUE_SIZE", "CyphalBackend", "TransportConfig"]

DEFAULT_RX_QUEUE_SIZE = 1000
SEND_TIMEOUT_S = 1.0
_HEALTH = {0: "NOMINAL", 1: "ADVISORY", 2: "CAUTION", 3: "WARNING"}
_HEALTH_LEVEL = {0: 0, 1: 0, 2: 1}  # /diagnostics: NOMINAL, ADVISORY OK; CAUTION WARN; WARNING (or unknown) ERROR
_MODE = {0: "OPERATIONAL", 1: "INITIALIZATION", 2: "MAINTENANCE", 3: "SOFTWARE_UPDATE"}
_PROBLEMS = ("errors", "deserialization_failures", "overruns", "drops")


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
            env = self.env()
            keys = sorted(k for k in env if k.startswith("UAVCAN__") and k != "UAVCAN__NODE__ID")
            return "env(" + ", ".join(f"{k}={env[k]}" for k in keys) + ")"
        if self.kind == "udp":
            return f"udp:{self.iface or '127.0.0.1'}"
        if self.kind == "can":
            return f"can:{self.iface} mtu={self.mtu or 64}"
        return self.kind

    def env(self) -> Mapping[str, str]:
        return os.environ if self.environ is None else self.environ

    def node_id(self, default: int) -> int:
        """``UAVCAN__NODE__ID`` for an ``env`` transport, else ``default``."""
        if self.kind == "env":
            raw = str(self.env().get("UAVCAN__NODE__ID", "")).strip()
            if raw:
                try:
                    return int(raw)
                except ValueError:
                    raise BridgeConfigError(f"UAVCAN__NODE__ID={raw!r} is not an integer") from None
        return int(default)


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


def _transport_dead(transport: Any) -> bool:
    """Best effort: pycyphal's CAN media close themselves for good on unrecoverable OS errors (the python-can
    media on any OSError of its receive thread, SocketCAN on ENETDOWN & co.); the transport then only raises
    ResourceClosedError. A redundant transport is dead when all its inferiors are."""
    inferiors = getattr(transport, "inferiors", None)
    if isinstance(inferiors, list | tuple) and inferiors:
        return all(_transport_dead(t) for t in inferiors)
    if not hasattr(transport, "_maybe_media"):
        return False
    media = transport._maybe_media
    return media is None or bool(getattr(media, "_closed", False))


def _monotonic(transfer: Any) -> float:
    try:
        return transfer.timestamp.monotonic_ns * 1e-9  # .monotonic builds a Decimal
    except Exception:
        return time.monotonic()


class _Subscription(Inlet):
    def __init__(self, name: str, spec_id: int, dtype: Any, handler: Callable[[Any, int | None, int, float], None],
                 raw: bool = False) -> None:
        self.name, self.spec_id, self.dtype, self.handler, self.raw = name, spec_id, dtype, handler, raw
        self.port_name = f"uavcan.sub.{name}"
        self.port_id: int | None = None
        self.below = BelowBridge()
        self.subscriber: Any = None  # a pycyphal Subscriber, or on the wire path a cyphal_wire.Receiver
        self.seen: dict[str, int] = {}  # pycyphal's counters of the current subscriber already accumulated
        self.refused = 0  # the wire path: payloads the codec refused since the port opened

    def malformed(self, src: int | None, detail: str) -> None:
        # Reported like pycyphal's deserialization_failures of a presentation-layer port (poll_statistics).
        self.refused += 1

    def statistics(self) -> tuple[dict[str, int], Any]:
        """pycyphal's counters of the current port (cumulative since it opened) and its transport session's
        statistics."""
        if self.raw:
            ts = self.subscriber.statistics()
            return {"transfers": ts.transfers, "frames": ts.frames, "errors": ts.errors, "drops": ts.drops,
                    "deserialization_failures": self.refused, "overruns": 0}, ts
        s = self.subscriber.sample_statistics()
        ts = s.transport_session
        return {"transfers": ts.transfers, "frames": ts.frames, "errors": ts.errors, "drops": ts.drops,
                "deserialization_failures": s.deserialization_failures, "overruns": s.overruns}, ts

    def on_transfer(self, msg: Any, transfer: Any) -> None:
        self.handler(msg, transfer.source_node_id, transfer.transfer_id, _monotonic(transfer))


class _Publication(Outlet):
    def __init__(self, backend: CyphalBackend, name: str, spec_id: int, dtype: Any, raw: bool = False) -> None:
        self._backend = backend
        self.name, self.spec_id, self.dtype = name, spec_id, dtype
        self.port_name = f"uavcan.pub.{name}"
        self.port_id: int | None = None
        self.send_timeout = SEND_TIMEOUT_S
        self.publisher: Any = None  # a pycyphal Publisher, or on the wire path a RawSender with its session open
        self.raw_sender = RawSender() if raw else None
        self.stamps: KernelTxStamps | None = None  # the kernel's transmission times (want_tx_times, UDP)
        self.can_times: CanTxTimes | None = None  # python-can's transmit thread's (want_tx_times, CAN)
        self._last_tx: Callable[[], TxWindow | None] | None = None  # how to read the last message's time

    @property
    def ready(self) -> bool:
        return self.publisher is not None

    async def publish(self, obj: Any) -> bool:
        import pycyphal.transport

        pub = self.publisher
        if pub is None:
            raise LinkDownError(self.port_name)
        try:
            sender = self.raw_sender
            if sender is not None and pub is sender:
                return await sender.send(obj, self.send_timeout)
            self._last_tx = None
            stamps, can_times = self.stamps, self.can_times
            if can_times is not None:
                count = can_times.count
                ok = bool(await pub.publish(obj))
                if ok:  # read when asked: by then the transmit thread has certainly noted it
                    self._last_tx = lambda: can_times.take(count)
                return ok
            if stamps is None:
                return bool(await pub.publish(obj))
            ok = False
            try:
                ok = bool(await pub.publish(obj))
            finally:
                if ok:  # read when asked: by then the kernel has certainly reported it (a NIC's queue)
                    self._last_tx = stamps.take
                else:
                    stamps.take()  # what a failed attempt left: the next take sees the next send's only
            return ok
        except pycyphal.transport.ResourceClosedError as ex:
            if self.publisher is pub:  # not replaced by a reopened one meanwhile: the transport is gone
                self._backend.suspect(f"publish on {self.port_id}: {type(ex).__name__}: {ex}")
            raise

    def take_tx_time(self) -> TxWindow | None:
        read, self._last_tx = self._last_tx, None
        return None if read is None else read()


class CyphalBackend(Backend):
    """:param name: the node's GetInfo name (``org.<vehicle>.<bridge>``).
    :param rx_queue_size: bound of each subject's pycyphal receive queue (beyond: ``overruns``); 0 = unbounded.
    :param rlog: the bridge's bounded-rate log (transport errors, what pycyphal discarded);
        ``errors``: the bridge's error counters (``cyphal.<kind>`` per transport error)."""

    protocol, label, stack = "cyphal", "Cyphal", "pycyphal"

    def __init__(self, name: str, node_id: int, transport: TransportConfig, *, rlog: RateLimitedLog,
                 errors: collections.Counter[str], rx_queue_size: int = DEFAULT_RX_QUEUE_SIZE) -> None:
        self.name = name[:50]
        self.node_id = node_id
        self.transport_config = transport
        self.rx_queue_size = int(rx_queue_size)
        self._rlog, self._errors = rlog, errors
        self._subs: list[_Subscription] = []
        self._pubs: list[_Publication] = []
        self._status_handlers: list[Callable[[DeviceStatus], None]] = []
        self._heartbeat_ids: dict[int, int] = {}  # node id -> transfer id of its last heartbeat
        self._node: Any = None
        self._hb_sub: Any = None  # a pycyphal Subscriber, or on Cyphal/UDP the heartbeat's port of the loop receiver
        self._loop_rx: Any = None  # on Cyphal/UDP: the transport's UDPLoopReceiver
        self._overflows_seen = 0
        self._not_subscribed_seen = 0
        self._suspect: str | None = None
        self._modulo = 2**64
        self._poll_lock = threading.Lock()

    def describe(self) -> str:
        return self.transport_config.describe()

    @property
    def node(self) -> Any:
        """The pycyphal node while the link is open (None before and between reopenings); the loop's thread only."""
        return self._node

    # -------------------------------------------------------------------------------------------- declarations
    def subscribe(self, name: str, port_id: int, dtype: Any, handler: Callable[[Any, int | None, int, float], None],
                  *, raw: bool = False) -> Inlet:
        sub = _Subscription(name, port_id, dtype, handler, raw)
        self._subs.append(sub)
        return sub

    def advertise(self, name: str, port_id: int, dtype: Any, *, raw: bool = False) -> Outlet:
        pub = _Publication(self, name, port_id, dtype, raw)
        self._pubs.append(pub)
        return pub

    def on_device_status(self, handler: Callable[[DeviceStatus], None]) -> None:
        self._status_handlers.append(handler)

    # -------------------------------------------------------------------------------------------- the link
    @property
    def transfer_id_modulo(self) -> int:
        return self._modulo

    @property
    def last_rx_overflow(self) -> float:
        rx = self._loop_rx
        return rx.last_overflow_ns * 1e-9 if rx is not None and rx.last_overflow_ns else -math.inf

    def suspect(self, reason: str) -> None:
        self._suspect = reason

    def link_problem(self) -> str | None:
        if self._node is None:
            return "no Cyphal node"
        if self._suspect:
            return self._suspect
        if self._loop_rx is not None and self._loop_rx.failure:
            return str(self._loop_rx.failure)
        try:
            transport = self._node.presentation.transport
            sessions = getattr(transport, "session_socket", None)  # a LoopSessionsUDPTransport's (services' input)
            if sessions is not None and sessions.failure:
                return str(sessions.failure)
            if _transport_dead(transport):
                return "the transport's media closed itself"
        except Exception as ex:
            return f"{type(ex).__name__}: {ex}"
        return None

    def _make_transport(self) -> Any:
        tc = self.transport_config
        if tc.kind == "env":
            env = dict(tc.env())
            env["UAVCAN__NODE__ID"] = str(self.node_id)
            return transport_from_env(env, loop_rx=True)
        if tc.kind == "custom":
            if tc.factory is None:
                raise BridgeConfigError("a custom transport needs a factory")
            return tc.factory(self.node_id)
        # Cyphal/UDP on one interface: the subscriptions are received on the event loop (no thread per session)
        return make_transport(tc.kind, node_id=self.node_id, iface=tc.iface, mtu=tc.mtu, loop_rx=True)

    async def open(self) -> None:
        """The Cyphal node and every port (at start and whenever the transport is reopened)."""
        try:
            self._open()  # (in the loop: the wire path's receive tasks start there)
        except PortConfigError as ex:
            raise BridgeConfigError(str(ex)) from None

    def _open(self) -> None:
        import pycyphal.dsdl
        import uavcan.node

        tc = self.transport_config
        env = tc.environ if tc.kind == "env" and tc.environ is not None else os.environ
        # The registers (uavcan.node.id, uavcan.pub/sub.<port>.id/.type) and their UAVCAN__* overrides.
        node = make_node(self.name, self.node_id, transport=self._make_transport(),
                         environ=register_environment(env))
        try:
            register_node_id(node.registry, self.node_id)
            node.heartbeat_publisher.mode = uavcan.node.Mode_1_0.OPERATIONAL
            transport = node.presentation.transport
            self._modulo = int(transport.protocol_parameters.transfer_id_modulo)
            if hasattr(transport, "add_error_hook"):  # CAN: media errors (bus off, error passive, ...) counted
                transport.add_error_hook(self._on_transport_error)
            rxq = self.rx_queue_size if self.rx_queue_size > 0 else None
            for pub in self._pubs:
                pub.port_id = pub.spec_id if pub.fixed_port else resolve_subject(node.registry, "pub", pub.name,
                                                                                  pub.dtype, pub.spec_id)
                if pub.raw_sender is not None:
                    pub.raw_sender.reopen(transport, pub.port_id, pub.dtype)
                    pub.publisher = pub.raw_sender
                    continue
                p = node.presentation.make_publisher(pub.dtype, pub.port_id)
                p.send_timeout = pub.send_timeout
                pub.publisher = p
                pub.stamps = pub.can_times = None
                if pub.tx_times:  # Cyphal/UDP: the kernel's transmission timestamps of the session's socket
                    sock = getattr(p.transport_session, "socket", None)
                    pub.stamps = KernelTxStamps.attach(sock) if isinstance(sock, socket.socket) else None
                    if pub.stamps is None:  # Cyphal/CAN through python-can: its transmit thread's
                        pub.can_times = CanTxTimes.attach(transport, pub.port_id, self.node_id)
            for sub in self._subs:
                sub.port_id = resolve_subject(node.registry, "sub", sub.name, sub.dtype, sub.spec_id)
                sub.seen, sub.refused = {}, 0
                if sub.raw:
                    sub.subscriber = open_receiver(transport, sub.port_id, sub.dtype, sub.handler)
                    continue
                sub.subscriber = node.presentation.make_subscriber(sub.dtype, sub.port_id, rxq)
                sub.subscriber.receive_in_background(sub.on_transfer)
            loop_rx = getattr(transport, "loop_receiver", None)  # a LoopUDPTransport's
            if loop_rx is not None:
                hb = uavcan.node.Heartbeat_1_0
                self._hb_sub = loop_rx.subscribe(pycyphal.dsdl.get_fixed_port_id(hb),
                                                 pycyphal.dsdl.get_extent_bytes(hb), self._on_heartbeat_payload)
            else:
                self._hb_sub = node.make_subscriber(uavcan.node.Heartbeat_1_0)
                self._hb_sub.receive_in_background(self._on_heartbeat)
        except BaseException:
            for sub in self._subs:
                if isinstance(sub.subscriber, Receiver):
                    sub.subscriber.abort()
                    sub.subscriber = None
            node.close()
            raise
        self._node = node
        self._loop_rx, self._overflows_seen, self._not_subscribed_seen = loop_rx, 0, 0
        self._suspect = None

    async def close(self) -> None:
        """Close every port and the node (what their subscribers counted is kept)."""
        self.poll_statistics()
        receivers = [s.subscriber for s in self._subs if isinstance(s.subscriber, Receiver)]
        ports: list[Any] = [s.subscriber for s in self._subs if not isinstance(s.subscriber, Receiver)]
        ports += [p.publisher for p in self._pubs if not isinstance(p.publisher, RawSender)] + [self._hb_sub]
        for s in self._subs:
            s.subscriber = None
        for p in self._pubs:
            if p.raw_sender is not None:
                p.raw_sender.close()
            p.publisher = None
        self._hb_sub = self._loop_rx = None
        node, self._node = self._node, None
        try:
            for receiver in receivers:
                await receiver.close()
            await aclose(*[p for p in ports if p is not None])
            if node is not None:
                await aclose(node)
        except Exception as ex:  # a dead transport may refuse to close cleanly
            log.warning("closing the Cyphal node: %s: %s", type(ex).__name__, ex)

    def _on_transport_error(self, timestamp: Any, error: Any) -> None:
        kind = getattr(error, "name", str(error))
        self._errors[f"cyphal.{kind}"] += 1
        self._rlog.note(("cyphal", kind), logging.WARNING, "transport error %s", kind)

    def _on_heartbeat_payload(self, payload: bytes, nid: int | None, tid: int, stamp: float) -> None:
        import pycyphal.dsdl
        import uavcan.node

        msg = pycyphal.dsdl.deserialize(uavcan.node.Heartbeat_1_0, [memoryview(payload)])
        if msg is None:  # what pycyphal's subscriber counts as a deserialization failure
            self._errors["cyphal.heartbeat_malformed"] += 1
            self._rlog.note(("cyphal", "heartbeat_malformed"), logging.WARNING,
                            "an undecodable heartbeat from node %s", nid)
            return
        self._heartbeat(msg, nid, tid)

    def _on_heartbeat(self, msg: Any, transfer: Any) -> None:
        self._heartbeat(msg, transfer.source_node_id, int(transfer.transfer_id))

    def _heartbeat(self, msg: Any, nid: int | None, tid: int) -> None:
        if nid is None:
            return
        health, mode = int(msg.health.value), int(msg.mode.value)
        last = self._heartbeat_ids.get(nid)
        self._heartbeat_ids[nid] = tid
        # 64-bit ids (UDP) never wrap: ids that went back mean the node started over; modulo 32 (CAN) says nothing
        ids_restarted = self._modulo >= 2**32 and last is not None and tid < last
        st = DeviceStatus(nid, _HEALTH.get(health, str(health)), _HEALTH_LEVEL.get(health, 2),
                          _MODE.get(mode, str(mode)), int(msg.uptime), int(msg.vendor_specific_status_code),
                          ids_restarted)
        for handler in self._status_handlers:
            handler(st)

    # -------------------------------------------------------------------------------------------- counters
    def poll_statistics(self) -> None:
        """Accumulate pycyphal's per-subject counters (they restart with each new subscriber) and log their
        increments at a bounded rate (thread-safe)."""
        with self._poll_lock:
            loop_rx = self._loop_rx
            if loop_rx is not None and loop_rx.overflows > self._overflows_seen:
                # Datagrams the kernel dropped for a full receive buffer (their transfers are also lost to the core)
                delta, self._overflows_seen = loop_rx.overflows - self._overflows_seen, loop_rx.overflows
                self._errors["cyphal.udp_rx_overflow"] += delta
                self._rlog.note(("cyphal", "udp_rx_overflow"), logging.WARNING,
                                "%d datagrams dropped by the kernel (receive buffer full)", delta, count=delta)
            if loop_rx is not None and loop_rx.not_subscribed > self._not_subscribed_seen:
                # Datagrams to the port for no subscribed subject (unicast, stray groups): counted (issue 29)
                delta = loop_rx.not_subscribed - self._not_subscribed_seen
                self._not_subscribed_seen = loop_rx.not_subscribed
                self._errors["cyphal.udp_not_subscribed"] += delta
            for sub in self._subs:
                subscriber = sub.subscriber
                if subscriber is None:
                    continue
                try:
                    now, ts = sub.statistics()
                except Exception:  # closed meanwhile
                    continue
                kinds = _error_kinds(ts)
                below = sub.below
                for key, value in now.items():
                    delta = int(value) - sub.seen.get(key, 0)
                    if delta <= 0:
                        continue
                    sub.seen[key] = int(value)
                    below.count(key, delta, key in _PROBLEMS)
                    if key in _PROBLEMS:
                        detail = ""
                        if key == "errors" and kinds:
                            detail = f" ({', '.join(f'{k} {v}' for k, v in sorted(kinds.items()))} in all)"
                        self._rlog.note((f"subject {sub.spec_id}", f"cyphal.{key}"), logging.WARNING,
                                        "%d discarded by pycyphal below the bridge%s", delta, detail, count=delta)
                for k, v in kinds.items():
                    base = sub.seen.get(f"kind.{k}", 0)
                    if v > base:
                        below.count_kind(k, v - base)
                        sub.seen[f"kind.{k}"] = v
