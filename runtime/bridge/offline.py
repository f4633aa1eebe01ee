"""The bridge's UAVCAN -> ROS path without a bus or ROS: recorded transfers in, the CDR it would publish out
(``sam-codegen replay``).

The same parts as the live bridge on the wire path: :func:`~.wiring.in_groups` (the generated codecs, one group per
port, ``select`` / element matching), :class:`~.inbound.Inbound` (source node filter, stamps, out-of-order,
``unselected``, drops and saturation counted in :class:`~.counters.MappingStats`) and :class:`~.loss.TransferLoss`
(gaps in transfer ids; Cyphal/UDP ids never wrap, DroneCAN's wrap at 32). Only the two ends are stand-ins: the
backend records each port's handler instead of subscribing, and each mapping's publisher collects what it is given.

Invariants: :meth:`OfflineBridge.feed` returns, in publication order, exactly what the live bridge with the same
generated package would have published for that transfer had it received it at ``receive_ns``; with each output
the same conversion at a receive time one second and a bit later, so a caller can tell the fields that depend on
the receive time (a device stamp of 0 becomes the receive time) from the others. Never raises for any payload
(a payload the codec refuses is counted as ``deserialization_failures`` below the bridge, as live).
Traffic control (issue 19): a mapping the spec starts disabled drops and counts (``disabled``) as live. A mapping's
``max_rate_hz`` runs on the recorded receive times (``monotonic_s``) instead of the loop's clock: a message held for
its slot comes out of the first :meth:`OfflineBridge.feed` at or after that slot (before that transfer's own
publications, as live), and the ones still held at the end out of :meth:`OfflineBridge.finish`. Its ``cdr_later`` is
the conversion of the transfer it came from.
Commands (issue 30): :meth:`OfflineBridge.command` converts a recorded ROS command (its CDR, as the bridge's raw
subscription received it) by each of its topic's ROS -> UAVCAN mappings with the same generated codecs into the
payloads the live bridge sends (before its queue, rate limit and deadline, which depend on the live loop), so the
replay can compare them with the transfers the recording holds from the bridge's node id.
Namespaced runs (issue 30): given the run's :class:`~sam_runtime.common.ros_namespace.RosNamespace`, the topics are
named as that run resolved them and every frame id carries its prefix, as the live bridge in that namespace wrote.
"""

from __future__ import annotations

import asyncio
import functools
import heapq
import itertools
import logging
import math
import threading
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from sam_codegen.model.protocols.registry import protocol as protocol_of
from sam_runtime.bridge.backend import Backend, BelowBridge, BridgeConfigError, DeviceStatus, Inlet, Outlet
from sam_runtime.bridge.counters import MappingStats
from sam_runtime.bridge.inbound import Inbound, InMapping
from sam_runtime.bridge.layout import port_id_of, select
from sam_runtime.bridge.lifetime import Lifetime
from sam_runtime.bridge.loss import TransferLoss
from sam_runtime.bridge.switches import switches_of
from sam_runtime.bridge.wiring import codec_gaps, in_groups, missing_codecs, nominal_rates, out_mappings
from sam_runtime.common.rate_log import RateLimitedLog
from sam_runtime.common.ros_namespace import RosNamespace
from sam_runtime.genpkg import GeneratedPackage
from sam_runtime.protocols import runtime_protocol

__all__ = ["RECEIVE_TIME_PROBE_NS", "Command", "OfflineBridge", "Published"]

log = logging.getLogger("sam_runtime.bridge.offline")
RECEIVE_TIME_PROBE_NS = 1_000_000_007  # the second conversion's receive time is this much later


@dataclass(frozen=True)
class Published:
    """One publication of the offline bridge."""

    topic: str
    ros_type: str
    mapping: str
    cdr: bytes
    cdr_later: bytes  # the same conversion at receive_ns + RECEIVE_TIME_PROBE_NS


@dataclass(frozen=True)
class Command:
    """One transfer the bridge would send for a ROS command."""

    port_id: int  # Cyphal subject id or DroneCAN data type id
    mapping: str
    payload: bytes


class _Inlet(Inlet):
    def __init__(self, name: str, port_id: int) -> None:
        self.port_name, self.port_id, self.below = name, port_id, BelowBridge()


class _Backend(Backend):
    """Subscriptions remembered by port; nothing is ever sent or opened."""

    def __init__(self, protocol: str) -> None:
        self.protocol = protocol
        self.label = protocol
        self.node_id = 0
        self.handlers: dict[int, Callable[[Any, int | None, int, float], None]] = {}
        self.inlets: dict[int, _Inlet] = {}

    def describe(self) -> str:
        return "a recording"

    def subscribe(self, name: str, port_id: int, dtype: Any, handler: Any, *, raw: bool = False) -> Inlet:
        self.handlers[port_id] = handler
        self.inlets[port_id] = inlet = _Inlet(name, port_id)
        return inlet

    def advertise(self, name: str, port_id: int, dtype: Any, *, raw: bool = False) -> Outlet:
        raise BridgeConfigError("the offline bridge publishes nothing on the bus")

    def on_device_status(self, handler: Callable[[DeviceStatus], None]) -> None:
        pass

    async def open(self) -> None:
        pass

    async def close(self) -> None:
        pass

    def link_problem(self) -> str | None:
        return None

    @property
    def transfer_id_modulo(self) -> int:
        return protocol_of(self.protocol).transfer_id_modulo


class _Timer:
    def __init__(self) -> None:
        self.cancelled = False

    def cancel(self) -> None:
        self.cancelled = True


class _RecordedClock:
    """The pacers' event loop offline: the recorded receive times are the clock, timers run when feed() passes
    them (in time order, the clock at each one's time)."""

    def __init__(self) -> None:
        self.now = -math.inf
        self._timers: list[tuple[float, int, Callable[[], Any], _Timer]] = []
        self._seq = itertools.count()

    def time(self) -> float:
        return self.now

    def call_at(self, when: float, callback: Callable[[], Any]) -> _Timer:
        timer = _Timer()
        heapq.heappush(self._timers, (when, next(self._seq), callback, timer))
        return timer

    def advance(self, to: float) -> None:
        while self._timers and self._timers[0][0] <= to:
            when, _, callback, timer = heapq.heappop(self._timers)
            self.now = max(self.now, when)
            if not timer.cancelled:
                callback()
        self.now = max(self.now, to)


class _Collector:
    """A mapping's publisher: keeps what the inbound path publishes."""

    def __init__(self, bridge: OfflineBridge, im: InMapping) -> None:
        self._bridge, self._im = bridge, im

    def publish(self, out: Any) -> None:
        self._bridge.collect(self._im, bytes(out))


class _Scratch:
    """The stats of the probe conversion: counted nowhere."""

    def saturate(self, key: str) -> None:
        pass

    def reject(self, key: str) -> None:
        pass

    def reject_nan(self, key: str) -> None:
        pass


class _Ros:
    """What Inbound asks of the ROS side: publishers and the receive clock."""

    def __init__(self) -> None:
        self.now_ns = 0

    def receive_ns(self) -> int:
        return self.now_ns

    def publisher(self, topic: Any, cls: Any) -> Any:
        return None  # replaced per mapping by a _Collector once started


class OfflineBridge:
    """:param gen: the generated package (its tables and wire codecs; its ROS classes must be importable).
    :param layout: the spec's layout; :param protocol: the half of a mixed layout (as :class:`~.composition.Bridge`);
    :param namespace: the recorded run's namespace and frame prefix (default: the root, no prefix).
    """

    def __init__(self, gen: GeneratedPackage, *, layout: str | None = None, protocol: str | None = None,
                 namespace: RosNamespace | None = None) -> None:
        tables = gen.tables()
        self.names = names = namespace or RosNamespace()
        self.selection = sel = select(tables, layout, protocol)
        self.protocol = sel.protocol
        codec = gen.codec(sel.protocol, names.frame_prefix)
        missing = missing_codecs(codec, sel.mappings)
        if missing:
            raise BridgeConfigError(f"the generated package {gen.root} has no wire codecs for "
                                    f"{codec_gaps(codec, missing)}")
        runtime_protocol(sel.protocol).bridge().prepare_replay(gen)  # (Cyphal: the DSDL, compiled)
        self.rlog = RateLimitedLog(log)
        lock = threading.Lock()
        self.counters = {m.name: MappingStats(lock, m.name, self.rlog) for m in sel.mappings}
        self.lifetime = Lifetime(f"{tables.BRIDGE_NAME}_offline", self.rlog)
        self._backend = _Backend(sel.protocol)
        self._ros = _Ros()
        rates = nominal_rates(tables, sel.device_infos)
        backend = self._backend

        def loss(port_id: int) -> TransferLoss:
            return TransferLoss(port_id, rates, lambda: backend.transfer_id_modulo, lambda nid: None, lambda: (),
                                lambda nid: self.inbound.forget_stamps(nid))

        groups = in_groups(gen, None, self.counters, loss, sel.mappings, codec)
        self.inbound = Inbound(self.lifetime, groups, self._ros, backend)
        self.inbound.frame_prefix = names.frame_prefix  # (the object path's; the codecs took it above)
        self._clock = _RecordedClock()
        self._convert: dict[str, Callable[..., Any]] = {}  # each mapping's own conversion
        self._inputs: dict[str, tuple[bytes, int]] = {}  # each mapping's last converted (payload, receive_ns)
        self.inbound.attach()
        asyncio.run(self.lifetime.start())  # the start hooks: publishers and subscriptions, nothing periodic
        self._ros_type = {m.name: m.topic.ros_type for m in sel.mappings}
        for group in self.inbound.groups.values():
            for im in group.mappings:
                im.ros_publisher = _Collector(self, im)
                # traffic control offline: the initial switch as live, the rate limit on the recorded times
                im.switch = switches_of([im.info])[im.info.name]
                if im.pacer is not None:
                    im.pacer.loop = self._clock
                self._convert[im.info.name] = convert = im.to_ros
                im.to_ros = functools.partial(self._remembering, im.info.name, convert)
        self._out: list[tuple[InMapping, bytes, tuple[bytes, int]]] = []
        # the ROS -> UAVCAN side: each command topic's mappings, on the same codecs (stats of their own)
        self.node_id = tables.BRIDGE_NODE_ID  # the recorded transfers the commands are compared with come from it
        self._commands: dict[str, list[Any]] = {}
        for om in out_mappings(gen, None, self.counters, sel.mappings, codec):
            om.switch = switches_of([om.info])[om.info.name]  # a mapping the spec starts disabled sends nothing
            self._commands.setdefault(names.resolve(om.info.topic.name), []).append(om)

    @property
    def topics(self) -> dict[str, str]:
        """topic -> ROS type of every UAVCAN -> ROS mapping."""
        return {self.names.resolve(im.info.topic.name): im.info.topic.ros_type
                for g in self.inbound.groups.values() for im in g.mappings}

    @property
    def command_topics(self) -> dict[str, str]:
        """topic (as the run resolved it) -> ROS type of every ROS -> UAVCAN mapping."""
        return {t: oms[0].info.topic.ros_type for t, oms in self._commands.items()}

    @property
    def command_ports(self) -> dict[int, str]:
        """port id -> a label (the mappings that send on it) of the ROS -> UAVCAN mappings."""
        out: dict[int, list[str]] = {}
        for oms in self._commands.values():
            for om in oms:
                out.setdefault(port_id_of(om.info), []).append(om.info.name)
        return {p: "+".join(sorted(set(names))) for p, names in out.items()}

    def command(self, topic: str, cdr: bytes) -> list[Command]:
        """The payloads the bridge sends for one ROS command on ``topic`` (nothing for another topic, a disabled
        mapping, or a message a mapping rejects: those are counted as live). Never raises."""
        out = []
        for om in self._commands.get(topic, ()):
            om.stats.receive()
            if not om.switch.enabled:
                om.stats.drop("disabled")
                continue
            try:
                payload = om.to_uavcan(cdr, om.stats)
            except Exception:  # counted as the live bridge counts it
                om.stats.drop("convert_error")
                continue
            if payload is None:
                om.stats.drop("rejected")
                continue
            om.stats.publish()
            out.append(Command(port_id_of(om.info), om.info.name, bytes(payload)))
        return out

    @property
    def ports(self) -> set[int]:
        return set(self._backend.handlers)

    def collect(self, im: InMapping, cdr: bytes) -> None:
        self._out.append((im, cdr, self._inputs[im.info.name]))

    def _remembering(self, mapping: str, convert: Callable[..., Any], payload: bytes, receive_ns: int, stats: Any
                     ) -> Any:
        """The mapping's conversion, remembering its last converted input: what a publication came from (the
        transfer itself, or for a message held for its rate slot the latest conversion: the held one)."""
        out = convert(payload, receive_ns, stats)
        if out is not None:
            self._inputs[mapping] = (payload, receive_ns)
        return out

    def feed(self, port_id: int, payload: bytes, source_node_id: int | None, transfer_id: int, monotonic_s: float,
             receive_ns: int) -> list[Published]:
        """One transfer of a subscribed port (others: nothing), as the live bridge handles it."""
        self._out = []
        self._clock.advance(monotonic_s)  # messages held for a rate slot that came before this transfer
        handler = self._backend.handlers.get(port_id)
        if handler is not None:
            self._ros.now_ns = receive_ns
            handler(payload, source_node_id, transfer_id, monotonic_s)
        return self._published()

    def finish(self) -> list[Published]:
        """The end of the recording: the messages still held for their rate slot, as the live bridge publishes
        them when the slot comes."""
        self._out = []
        self._clock.advance(math.inf)
        return self._published()

    def _published(self) -> list[Published]:
        out = []
        for im, cdr, (payload, receive_ns) in self._out:
            try:
                later = self._convert[im.info.name](payload, receive_ns + RECEIVE_TIME_PROBE_NS, _Scratch())
            except Exception:  # it converted once: the probe cannot fail differently, but never raise
                later = None
            out.append(Published(self.names.resolve(im.info.topic.name), im.info.topic.ros_type, im.info.name, cdr,
                                 bytes(later[0]) if later else cdr))
        return out

    def stats(self) -> dict[str, Any]:
        """Per mapping the live bridge's counters; per port what was refused below the bridge."""
        below = {str(pid): inlet.below.snapshot()[0] for pid, inlet in self._backend.inlets.items()
                 if inlet.below.snapshot()[0]}
        self.rlog.flush(force=True)
        return {"mappings": {name: st.snapshot() for name, st in self.counters.items()}, "below_bridge": below}
