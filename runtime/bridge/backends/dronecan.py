"""The DroneCAN (UAVCAN v0) backend, on sam_runtime.dronecan_io: a ``dronecan`` Node behind a FrameGate, driven in
the asyncio loop's thread by a NodeLoop (every exception out of dronecan's ``spin()`` counted, never raised), on any
interface URI of dronecan_io (``mcast-lo:`` between processes on this machine, ``slcan:``, ``socketcan:``).

Wired to the spec by the composition root (``Bridge(layout=..., protocol="dronecan")``); what it does for the core:

- subscriptions by data type id: every transfer of that type from any node goes to the core's handler with its
  source node id, transfer id (5 bits: modulo 32) and receive time; the core filters the sources per mapping
  (``unknown_source``) and counts the gaps, as for Cyphal. The data type is named by its full name
  (``uavcan.equipment.ahrs.RawIMU``) or given as the dronecan type, and looked up again at every open (dronecan's
  ``load_dsdl`` replaces every type object: a handler registered on an old one never fires); its data type id must
  be the port id the spec gives;
- publications: ``node.broadcast`` (v0 commands carry no destination either; the ESC index or actuator id is in
  the message), sent before publish returns; a port that ``want_tx_times`` (the time-sync master's) gets the
  driver's transmission window of its frame where the driver measures one (sam_runtime.dronecan_io's ``mcast-lo:``
  driver: the bounds of its send system call), else none (the master measures the broadcast call, which does not
  wait: no loop lag in it);
- device health: every ``uavcan.protocol.NodeStatus`` as a DeviceStatus (OK, WARNING, ERROR, CRITICAL; its
  OFFLINE_TIMEOUT_MS is 3000 like Cyphal's heartbeat timeout);
- the link: a closed driver (its socket failed) or a send that raised DriverError asks for a reopen;
- below the bridge: what the FrameGate and the NodeLoop dropped for the port's data type (CRC and toggle errors,
  incomplete transfers, payloads that do not decode, ...), by reason and source node.

The node answers GetNodeInfo (dronecan does) and broadcasts its own NodeStatus (OPERATIONAL, OK) once a second.
"""

from __future__ import annotations

import collections
import logging
import threading
from collections.abc import Callable
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
from sam_runtime.bridge.counters import log
from sam_runtime.common.rate_log import RateLimitedLog
from sam_runtime.common.tx_timestamps import TxWindow
from sam_runtime.dronecan_io import DropReason, IfaceError, NodeLoop, close_node
from sam_runtime.dronecan_io import make_node as default_make_node
from sam_runtime.dronecan_io.wire import TransferTaps, broadcast_payload

__all__ = ["DroneCanBackend", "node_status"]

TRANSFER_ID_MODULO = 32  # v0 tail byte: 5-bit transfer ids
IDLE_WAKEUP_S = 1.0  # the NodeLoop's longest sleep without a frame or a scheduler deadline
_HEALTH = {0: "OK", 1: "WARNING", 2: "ERROR", 3: "CRITICAL"}
_HEALTH_LEVEL = {0: 0, 1: 1}  # /diagnostics: OK OK, WARNING WARN, ERROR and CRITICAL ERROR
_MODE = {0: "OPERATIONAL", 1: "INITIALIZATION", 2: "MAINTENANCE", 3: "SOFTWARE_UPDATE", 7: "OFFLINE"}


def node_status(node_id: int, msg: Any) -> DeviceStatus:
    """A uavcan.protocol.NodeStatus as a DeviceStatus.

    >>> from types import SimpleNamespace as S
    >>> node_status(12, S(health=2, mode=0, uptime_sec=41, vendor_specific_status_code=7))
    DeviceStatus(node_id=12, health='ERROR', level=2, mode='OPERATIONAL', uptime_s=41, vssc=7, ids_restarted=False)
    """
    health, mode = int(msg.health), int(msg.mode)
    return DeviceStatus(node_id, _HEALTH.get(health, str(health)), _HEALTH_LEVEL.get(health, 2),
                        _MODE.get(mode, str(mode)), int(msg.uptime_sec), int(msg.vendor_specific_status_code))


def _type_name(dtype: Any) -> str:
    return dtype if isinstance(dtype, str) else str(dtype.full_name)


def _resolve(dtype: Any, port_id: int) -> Any:
    """The current dronecan type object of ``dtype``, checked against the spec's data type id ``port_id``."""
    import dronecan

    name = _type_name(dtype)
    t = dronecan.TYPENAMES.get(name)
    if t is None:
        raise BridgeConfigError(f"dronecan knows no data type {name!r} (custom types: dronecan.load_dsdl first)")
    if t.default_dtid != port_id:
        raise BridgeConfigError(f"{name} has data type id {t.default_dtid}, the spec says {port_id}")
    return t


class _Subscription(Inlet):
    def __init__(self, name: str, port_id: int, dtype: Any, handler: Callable[[Any, int | None, int, float], None],
                 raw: bool = False) -> None:
        self.name, self.dtype, self.handler, self.raw = name, dtype, handler, raw
        self.port_name = f"dronecan.sub.{name}"
        self.spec_id = port_id
        self.port_id: int | None = port_id
        self.below = BelowBridge()
        self.transfers = 0  # of the current node
        self.seen: dict[str, int] = {}  # what was accumulated into ``below`` of the current node
        self.drops: Any = None  # the current node's DropCounter

    def on_event(self, event: Any) -> None:
        self.transfers += 1
        t = event.transfer
        self.handler(event.message, t.source_node_id, int(t.transfer_id), float(t.ts_monotonic))

    def on_payload(self, payload: bytes, src: int, transfer_id: int, monotonic_s: float) -> None:
        self.transfers += 1
        self.handler(payload, src, transfer_id, monotonic_s)

    def malformed(self, src: int | None, detail: str) -> None:
        """Counted where dronecan's failures to unpack are (NodeLoop: ``malformed_payload``), so below the bridge
        both paths report the same reason."""

        if self.drops is None:
            super().malformed(src, detail)
            return
        self.drops.add(DropReason.MALFORMED_PAYLOAD, data_type_id=self.port_id, source_node_id=src, detail=detail)


class _Publication(Outlet):
    def __init__(self, backend: DroneCanBackend, name: str, port_id: int, dtype: Any) -> None:
        self._backend = backend
        self.name, self.dtype = name, dtype
        self.port_name = f"dronecan.pub.{name}"
        self.spec_id = port_id
        self.port_id: int | None = port_id
        self.send_timeout = 0.1  # the loopback driver's; a broadcast is sent (or raises) before it returns
        self.raw = False
        self.crc_base = 0  # the wire path: the data type's CRC seed, from dronecan's type at each open
        self._last_tx: TxWindow | None = None

    @property
    def ready(self) -> bool:
        return self._backend.node is not None

    async def publish(self, obj: Any) -> bool:
        from dronecan.driver.common import DriverError, TxQueueFullError

        node = self._backend.node
        if node is None:
            raise LinkDownError(self.port_name)
        self._last_tx = None
        driver: Any = _driver(node) if self.tx_times else None
        sent = getattr(driver, "frames_sent", None)
        try:
            if self.raw:
                broadcast_payload(node, self.spec_id, self.crc_base, obj)
            else:
                node.broadcast(obj)
            if sent is not None and driver.frames_sent == sent + 1 and driver.last_tx_ns is not None:
                # one frame, sent by this broadcast (the driver is used in this thread only): the driver's window
                earliest, latest = driver.last_tx_ns
                self._last_tx = TxWindow(earliest, latest, "driver")
        except TxQueueFullError:
            raise  # the bus is full: counted by the core, the next one goes
        except DriverError as ex:
            if self._backend.node is node:
                self._backend.suspect(f"broadcast on {self.port_id}: {type(ex).__name__}: {ex}")
            raise
        return True

    def take_tx_time(self) -> TxWindow | None:
        window, self._last_tx = self._last_tx, None
        return window


def _driver(node: Any) -> Any:
    """The CAN driver under the node's FrameGate."""
    return getattr(node.can_driver, "inner", node.can_driver)


class DroneCanBackend(Backend):
    """:param iface: a sam_runtime.dronecan_io interface URI (``mcast-lo:``, ``slcan:/dev/ttyACM0``,
        ``socketcan:can0``).
    :param node_id: the bridge's v0 node id (1..125).
    :param make_node: ``make_node(iface, node_id, **kwargs)`` (default sam_runtime.dronecan_io.make_node)."""

    protocol, label, stack = "dronecan", "DroneCAN", "dronecan"

    def __init__(self, iface: str, node_id: int, *, rlog: RateLimitedLog, errors: collections.Counter[str],
                 name: str = "org.sam.bridge", node_status_interval: float = 1.0,
                 make_node: Callable[..., Any] | None = None) -> None:
        if not 1 <= int(node_id) <= 125:
            raise BridgeConfigError(f"a DroneCAN node id is 1..125, not {node_id}")
        self.iface = iface
        self.node_id = int(node_id)
        self.name = name
        self._status_interval = node_status_interval
        self._make_node = make_node
        self._rlog, self._errors = rlog, errors
        self._subs: list[_Subscription] = []
        self._pubs: list[_Publication] = []
        self._status_handlers: list[Callable[[DeviceStatus], None]] = []
        self._open_hooks: list[Callable[[Any, Any], None]] = []
        self.node: Any = None
        self.node_loop: Any = None
        self._suspect: str | None = None
        self._poll_lock = threading.Lock()
        self._bus_seen: dict[str, int] = {}  # the drops of no subscribed data type already in errors (issue 29)

    def describe(self) -> str:
        return f"dronecan:{self.iface}"

    # -------------------------------------------------------------------------------------------- declarations
    def subscribe(self, name: str, port_id: int, dtype: Any, handler: Callable[[Any, int | None, int, float], None],
                  *, raw: bool = False) -> Inlet:
        sub = _Subscription(name, port_id, dtype, handler, raw)
        self._subs.append(sub)
        return sub

    def advertise(self, name: str, port_id: int, dtype: Any, *, raw: bool = False) -> Outlet:
        pub = _Publication(self, name, port_id, dtype)
        pub.raw = raw
        self._pubs.append(pub)
        return pub

    def on_device_status(self, handler: Callable[[DeviceStatus], None]) -> None:
        self._status_handlers.append(handler)

    def on_open(self, hook: Callable[[Any, Any], None]) -> None:
        """``hook(node, node_loop)`` whenever a node is opened (at start and at every reopening), before it runs:
        for the parts that register handlers of their own (sam_runtime.bridge.backends.dronecan_duties)."""
        self._open_hooks.append(hook)

    # -------------------------------------------------------------------------------------------- the link
    @property
    def transfer_id_modulo(self) -> int:
        return TRANSFER_ID_MODULO

    def suspect(self, reason: str) -> None:
        self._suspect = reason

    def link_problem(self) -> str | None:
        if self.node is None:
            return "no DroneCAN node"
        if self._suspect:
            return self._suspect
        driver = getattr(self.node.can_driver, "inner", self.node.can_driver)
        if getattr(driver, "_closed", False):
            return "the CAN driver closed"
        return None

    async def open(self) -> None:
        """The node, its NodeLoop and every declared port (at start and whenever the link is reopened)."""
        import dronecan

        types = [(sub, _resolve(sub.dtype, sub.spec_id)) for sub in self._subs]
        for pub in self._pubs:
            pub.crc_base = int(_resolve(pub.dtype, pub.spec_id).base_crc)
        info = dronecan.uavcan.protocol.GetNodeInfo.Response()
        info.name = self.name[:80]
        try:
            node = (self._make_node or default_make_node)(self.iface, self.node_id,
                                                          node_status_interval=self._status_interval,
                                                          node_info=info)
        except IfaceError as ex:
            raise BridgeConfigError(str(ex)) from None
        try:
            node.mode = dronecan.uavcan.protocol.NodeStatus().MODE_OPERATIONAL
            node.health = dronecan.uavcan.protocol.NodeStatus().HEALTH_OK
            # max_idle 1 s, not 0.1 s: the loop's timer wakes the bridge at dronecan's next deadline (NodeStatus at
            # 1 Hz) and for the gate's sweep, not ten times a second; whoever adds scheduled work outside dronecan's
            # handlers wakes the NodeLoop (the service mappings' requests)
            loop = NodeLoop(node, logger=log, max_idle=IDLE_WAKEUP_S)
            taps = TransferTaps(loop.drops)
            self._bus_seen = {}  # the new loop's counter starts at 0
            for sub, t in types:
                sub.transfers, sub.seen, sub.drops = 0, {}, loop.drops
                if sub.raw:
                    taps.add(sub.spec_id, int(t.base_crc), sub.on_payload)
                else:
                    loop.add_handler(t, sub.on_event)
            loop.gate.taps = taps
            loop.add_handler(dronecan.uavcan.protocol.NodeStatus, self._on_status)
            for hook in self._open_hooks:
                hook(node, loop)
            loop.start()
        except BaseException:
            node.close()
            raise
        self.node, self.node_loop, self._suspect = node, loop, None

    async def close(self) -> None:
        self.poll_statistics()
        loop, node = self.node_loop, self.node
        self.node_loop = self.node = None

        close_node(loop, node, log, "closing the DroneCAN node")

    def _on_status(self, event: Any) -> None:
        nid = event.transfer.source_node_id
        if nid is None:
            return
        st = node_status(nid, event.message)
        for handler in self._status_handlers:
            handler(st)

    # -------------------------------------------------------------------------------------------- counters
    def poll_statistics(self) -> None:
        """What the FrameGate and the NodeLoop dropped for each subscribed data type, accumulated across
        reopenings, and the transfers delivered (thread-safe)."""
        loop = self.node_loop
        detailed = loop.drops.detailed() if loop is not None else {}
        with self._poll_lock:
            # The bus's drops no mapping's counters show (junk packets, 11-bit or Cyphal frames, others' data
            # types): the bridge's errors, as dronecan.<reason> (issue 29: every frame read is counted somewhere).
            subscribed = {sub.port_id for sub in self._subs}
            bus: dict[str, int] = {}
            for key, n in detailed.items():
                if key.data_type_id is None or key.data_type_id not in subscribed:
                    bus[key.reason.value] = bus.get(key.reason.value, 0) + n
            for reason, n in bus.items():
                delta = n - self._bus_seen.get(reason, 0)
                if delta > 0:
                    self._bus_seen[reason] = n
                    self._errors[f"dronecan.{reason}"] += delta
            for sub in self._subs:
                now: dict[str, int] = {"transfers": sub.transfers}
                for key, n in detailed.items():
                    if key.data_type_id == sub.port_id:
                        now["errors"] = now.get("errors", 0) + n
                        kind = f"{key.reason.value}" + (f".node{key.source_node_id}"
                                                        if key.source_node_id is not None else "")
                        now[f"kind.{kind}"] = now.get(f"kind.{kind}", 0) + n
                for key, value in now.items():
                    delta = value - sub.seen.get(key, 0)
                    if delta <= 0:
                        continue
                    sub.seen[key] = value
                    if key.startswith("kind."):
                        sub.below.count_kind(key[5:], delta)
                        continue
                    sub.below.count(key, delta, key == "errors")
                    if key == "errors":
                        self._rlog.note((f"data type {sub.port_id}", "dronecan.errors"), logging.WARNING,
                                        "%d discarded by dronecan below the bridge", delta, count=delta)
