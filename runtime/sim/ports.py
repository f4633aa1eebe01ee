"""What the simulator and its protocol adapters share: a simulated device (:class:`SimDevice`) with its ports
(:class:`PubPort`, :class:`SubPort`), what an adapter does for its protocol (:class:`DeviceAdapter`:
sam_runtime.sim.cyphal, sam_runtime.sim.dronecan) and what it may use of the simulator (:class:`DeviceHost`:
sam_runtime.sim.simulator)."""

from __future__ import annotations

import asyncio
from collections import Counter
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Protocol

from sam_runtime.genpkg import GeneratedPackage
from sam_runtime.sim.config import SimConfig
from sam_runtime.sim.devices import DeviceState, PhysicsFn
from sam_runtime.sim.time_sync import DeviceClock, SyncSlave

if TYPE_CHECKING:
    from sam_codegen.contracts.tables_api import TablesModule

__all__ = ["DeviceAdapter", "DeviceHost", "PubPort", "SimDevice", "SubPort"]


@dataclass
class PubPort:
    """A port the device publishes on its schedule."""


    port: Any  # PortInfo (Cyphal) or DroneCanPortInfo
    dtype: Any  # the pycyphal class, or the v0 type's full name
    physics: PhysicsFn | None
    key: str = ""  # in report(): the subject id (Cyphal), "dronecan:<data type name>"
    ident: int = 0  # the subject id or data type id: the schedule's offset, the generic values' seed
    publisher: Any = None
    task: asyncio.Task[None] | None = None
    sent: int = 0
    late: int = 0
    failed: int = 0
    busy: bool = False  # a publish in flight
    last_stamp_us: int = 0  # the last synchronised stamp of the port: its stamps only increase
    extra: Any = None  # the protocol adapter's

    def __post_init__(self) -> None:
        if not self.key:
            self.key, self.ident = str(self.port.subject_id), int(self.port.subject_id)


@dataclass
class SubPort:
    """A command port the device subscribes to, with what it accepted and rejected."""


    port: Any
    dtype: Any
    subscriber: Any = None
    accepted: int = 0
    rejected: int = 0
    rejected_sources: Counter[int] = field(default_factory=Counter)
    last: dict[str, Any] | None = None
    key: str = ""
    ident: int = 0
    not_addressed: int = 0  # DroneCAN: broadcasts without this device's element
    extra: Any = None

    def __post_init__(self) -> None:
        if not self.key:
            self.key, self.ident = str(self.port.subject_id), int(self.port.subject_id)


@dataclass
class SimDevice:
    """One simulated device: its firmware's info, state, node and ports."""


    info: Any  # DeviceInfo (Cyphal) or DroneCanDeviceInfo
    state: DeviceState
    node: Any = None
    pubs: list[PubPort] = field(default_factory=list)
    subs: list[SubPort] = field(default_factory=list)
    powered: bool = False
    power_cycles: int = 0
    protocol: str = "cyphal"
    extra: Any = None  # the protocol adapter's (DroneCAN: the NodeLoop)
    # Its own clock and time-sync slave (sam_runtime.sim.time_sync); None: it stamps with the shared stamp clock
    clock: DeviceClock | None = None
    sync: SyncSlave | None = None  # a new one at each power-on (unsynchronised after a reboot)
    stamps_synchronised: int = 0  # messages it stamped in the master's time
    stamps_unknown: int = 0  # messages it stamped 0 ("unknown") because it had not synchronised yet


class DeviceHost(Protocol):
    """What a protocol adapter uses of the simulator."""

    gen: GeneratedPackage
    tables: TablesModule
    config: SimConfig
    devices: list[SimDevice]
    bridge_node_id: int | None

    def on_command(self, dev: SimDevice, sp: SubPort, msg: Any, transfer: Any) -> None:
        """A command arrived on ``sp`` (``transfer.source_node_id`` sent it)."""

    async def restart(self, name: str) -> None:
        """Power the device off, then on again."""

    def on_time_sync(self, dev: SimDevice, master: int, transfer_id: int, prev_tx_us: int, rx_mono_ns: int) -> None:
        """A time-sync message from node ``master`` reached ``dev`` at monotonic time ``rx_mono_ns``."""


class DeviceAdapter(Protocol):
    """One protocol's part of the simulated devices: the node, its ports, the messages' values, closing."""

    protocol: str

    def prepare(self) -> None:
        """Once, in the running loop, before the first device opens."""

    def ports(self, dev: SimDevice) -> None:
        """Add the device's ports (``dev.pubs``, ``dev.subs``)."""

    def open(self, dev: SimDevice) -> None:
        """The device's node (heartbeats start at once) and its ports' publishers and subscribers."""

    async def close(self, devices: list[SimDevice]) -> None:
        """Close the devices' ports and nodes (never raises)."""

    def blank(self, pp: PubPort, t: float, now_us: int) -> Any:
        """A message of ``pp``'s type with generic in-range values."""

    def finish(self, dev: SimDevice, pp: PubPort, obj: Any, t: float, now_us: int) -> None:
        """Last touches to a message after physics filled it."""

    def command_values(self, dev: SimDevice, sp: SubPort, msg: Any) -> dict[str, Any] | None:
        """The command's values for this device (None: not meant for it)."""

    def apply(self, dev: SimDevice, values: dict[str, Any]) -> dict[str, float]:
        """Apply a command's values; the vehicle model's inputs they set."""

    def record(self, port: Any, obj: Any, transmitted: bool) -> dict[str, Any]:
        """A JSON-able record of a message (as transmitted)."""

    def command_report(self, sp: SubPort) -> dict[str, Any]:
        """The protocol's own counts of a command port in the run report (beside accepted and rejected)."""

    def sync_params(self, dev: SimDevice) -> tuple[float, int]:
        """The protocol's time sync: the longest interval between two messages of a master (s), the transfer id
        modulo of the device's transport."""
