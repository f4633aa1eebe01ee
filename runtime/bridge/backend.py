"""What the protocol-agnostic core asks of a protocol backend (Cyphal v1 through pycyphal, DroneCAN through the
``dronecan`` package), and the events a backend reports.

Threads: the core calls a backend only on the asyncio loop, and a backend calls the core's handlers only there
(pycyphal's subscribers run in it; a dronecan Node is driven in it by ``sam_runtime.dronecan_io.NodeLoop``).

Ports are declared before :meth:`Backend.open` and live across reopenings: ``subscribe`` and ``advertise`` return
handles whose underlying protocol objects the backend (re)creates at every ``open`` and drops at ``close``; a
backend whose link failed is closed and opened again by the core (``sam_runtime.bridge.link``), with back-off,
without the core declaring anything again.

- UAVCAN -> ROS: ``handler(msg, source_node_id, transfer_id, monotonic_s)`` for every transfer of a subscribed
  port (``msg``: the deserialized message, or on a raw port its payload bytes), from any source (the core filters
  sources and counts the gaps in transfer ids: ``transfer_id_modulo``). Plain arguments, no object per transfer:
  this is the hot path.
- ROS -> UAVCAN: ``await outlet.publish(obj)`` (on a raw port: the payload bytes) -> True when sent, False when not
  every frame was sent in time; raises on a transport error (counted by the core), :class:`LinkDownError` when the
  port is not open.
- Device health: ``on_device_status(handler)``; the handler gets a :class:`DeviceStatus` for every heartbeat
  (Cyphal ``uavcan.node.Heartbeat``, DroneCAN ``uavcan.protocol.NodeStatus``) of any node. The core keeps the
  records, the offline timeouts and the restarts (``sam_runtime.bridge.health``).
- Transmission times (the time-sync master's port): ``outlet.want_tx_times()`` before open, then after each
  publish ``outlet.take_tx_time()`` -> a :class:`~sam_runtime.common.tx_timestamps.TxWindow` or None.
- Link: ``link_problem()`` says why the link must be reopened (a dead transport), polled by the core.
- Counters below the bridge (frames and transfers the protocol stack discarded): ``poll_statistics()``, then
  ``inlet.below`` per port.
"""

from __future__ import annotations

import abc
import math
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from sam_runtime.common.tx_timestamps import TxWindow

__all__ = ["Backend", "BelowBridge", "BridgeConfigError", "DeviceStatus", "Inlet", "LinkDownError", "Outlet",
           "TransferHandler"]

TransferHandler = Callable[[Any, "int | None", int, float], None]


class BridgeConfigError(Exception):
    """The generated tables, the transport or the parameters do not allow the bridge to start."""


class LinkDownError(Exception):
    """A port used while the backend's link is not open."""


@dataclass(frozen=True)
class DeviceStatus:
    """One heartbeat of a node, in the protocol's own words, with what it means for /diagnostics."""

    node_id: int
    health: str  # e.g. NOMINAL (Cyphal), OK (DroneCAN)
    level: int  # what the health means on /diagnostics: 0 OK, 1 WARN, 2 ERROR
    mode: str  # e.g. OPERATIONAL
    uptime_s: int
    vssc: int  # vendor-specific status code
    # the transport says the node started over (Cyphal/UDP: its 64-bit transfer ids went back, which they do only
    # when it restarts), whatever its uptime says: the first heartbeats of a quick reboot may have been dropped
    ids_restarted: bool = False


class BelowBridge:
    """A subscribed port's counters of the protocol stack, cumulative across reopenings: ``totals`` (transfers,
    frames, errors, drops, deserialization_failures, overruns: whatever the stack counts), ``error_kinds`` (the
    stack's breakdown of its errors), and when it last discarded something. Thread-safe."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._totals: dict[str, int] = {}
        self._kinds: dict[str, int] = {}
        self._last_problem: float | None = None

    def count(self, key: str, delta: int, problem: bool) -> None:
        with self._lock:
            self._totals[key] = self._totals.get(key, 0) + delta
            if problem:
                self._last_problem = time.monotonic()

    def count_kind(self, kind: str, delta: int) -> None:
        with self._lock:
            self._kinds[kind] = self._kinds.get(kind, 0) + delta

    def snapshot(self) -> tuple[dict[str, int], dict[str, int], float | None]:
        """(totals, error kinds, monotonic time of the last problem or None)."""
        with self._lock:
            return dict(self._totals), dict(self._kinds), self._last_problem


class Inlet(abc.ABC):
    """A subscribed port (handle): its name for registers and reports, the port id it listens on once open."""

    port_name: str  # e.g. uavcan.sub.imu
    port_id: int | None  # the subject (Cyphal) or data type id (DroneCAN) it listens on; None before open
    below: BelowBridge

    def malformed(self, src: int | None, detail: str) -> None:
        """A payload of the wire path that the generated codec refused (what the protocol library's deserializer
        refuses and counts on the object path): counted below the bridge like the library's own refusals."""
        self.below.count("deserialization_failures", 1, True)


class Outlet(abc.ABC):
    """An advertised port (handle)."""

    port_name: str  # e.g. uavcan.pub.thruster_1_rpm
    port_id: int | None
    send_timeout: float  # seconds a publish may take before it counts as not sent
    fixed_port: bool = False  # the type's fixed port id: no register configures it (the time-sync master's)

    @property
    @abc.abstractmethod
    def ready(self) -> bool:
        """Whether the port is open (the link is up)."""

    @abc.abstractmethod
    async def publish(self, obj: Any) -> bool:
        """Send ``obj``: True when every frame went out within ``send_timeout``."""

    # The time-sync master's port: when its messages left, measured below the bridge where the backend can.
    tx_times: bool = False

    def want_tx_times(self) -> None:
        """Measure when each message of this port leaves (from the next open on): :meth:`take_tx_time`."""
        self.tx_times = True

    def take_tx_time(self) -> TxWindow | None:
        """When the first frame of the message of the last successful :meth:`publish` left, as the transport or
        the driver measured it; None when it did not (not asked for, not supported, not measurable that time).
        Called once, before the next publish (a transport may report the time after publish returned)."""
        return None


class Backend(abc.ABC):
    """One protocol stack and its node on one bus."""

    protocol: str = ""  # key of its counters in the reports ("cyphal", "dronecan")
    label: str = ""  # for messages ("Cyphal", "DroneCAN")
    stack: str = ""  # what discards frames below the bridge ("pycyphal", "dronecan")
    node_id: int

    @abc.abstractmethod
    def describe(self) -> str:
        """The transport, for logs and reports (``udp:127.0.0.1``)."""

    @abc.abstractmethod
    def subscribe(self, name: str, port_id: int, dtype: Any, handler: TransferHandler, *, raw: bool = False
                  ) -> Inlet:
        """Declare a subscription (before open): ``name`` for registers/reports, the spec's port id. ``raw``: the
        handler gets each transfer's payload bytes instead of a deserialized message (the wire path)."""

    @abc.abstractmethod
    def advertise(self, name: str, port_id: int, dtype: Any, *, raw: bool = False) -> Outlet:
        """Declare a publication (before open). ``raw``: ``publish`` takes the payload bytes (the wire path)."""

    @abc.abstractmethod
    def on_device_status(self, handler: Callable[[DeviceStatus], None]) -> None:
        """Call ``handler`` for every heartbeat of any node (declare before open)."""

    @abc.abstractmethod
    async def open(self) -> None:
        """Open the node and every declared port; raise (BridgeConfigError for a configuration problem) when it
        cannot. Called again after :meth:`close` when the link failed."""

    @abc.abstractmethod
    async def close(self) -> None:
        """Close every port and the node; never raises."""

    @abc.abstractmethod
    def link_problem(self) -> str | None:
        """Why the open link must be reopened (its transport died), or None."""

    @property
    @abc.abstractmethod
    def transfer_id_modulo(self) -> int:
        """Transfer ids of a source wrap at this value (Cyphal/UDP 2**64, Cyphal/CAN and DroneCAN 32)."""

    @property
    def last_rx_overflow(self) -> float:
        """When (monotonic s) the kernel last dropped received frames for a full buffer, as far as the stack can
        tell (-inf: never, or it cannot tell). A transfer-id gap across such a drop is a loss however large
        (:mod:`.loss`)."""
        return -math.inf

    def poll_statistics(self) -> None:  # noqa: B027  (optional: a stack without counters has nothing to poll)
        """Bring every inlet's ``below`` up to date (thread-safe; logs what was discarded at a bounded rate)."""
