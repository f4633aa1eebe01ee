"""The simulator's options (:class:`SimConfig`)."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path

from sam_runtime.common.cli_fields import Flag, cli_field
from sam_runtime.physics.vehicle import SimulatedVehicle, VehicleOptions

__all__ = ["SimConfig"]


@dataclass(frozen=True)
class SimConfig(VehicleOptions):
    """``kind``/``iface``/``mtu`` as in :func:`~sam_runtime.cyphal_io.transport.make_transport`
    (``env``: UAVCAN__UDP__IFACE
    / UAVCAN__CAN__IFACE / UAVCAN__CAN__MTU from ``environ``; node ids always come from the spec). The simulated
    vehicle's options are VehicleOptions' (keyword only); the fields with a flag are `sam-sim`'s options."""

    kind: str = "udp"
    iface: str | None = None
    mtu: int | None = None
    environ: Mapping[str, str] | None = None
    layout: str = "default"  # one of the spec's layouts: which devices run Cyphal, which DroneCAN
    dronecan_iface: str = "mcast-lo:"  # the DroneCAN devices' bus (a sam_runtime.dronecan_io interface URI)
    bridge_node_id: int | None = None  # commands accepted only from it; default: the spec's bridge
    devices: Iterable[str] | None = None  # subset of device names; default all
    rate_scale: float = 1.0
    record: Path | None = None  # JSON lines of every transmitted/received message
    # The vehicle's time (the main job runs its nodes on the wall clock: no --time-scale there) and its true state.
    time_scale: float = field(default=1.0, metadata=cli_field(
        Flag("--time-scale", "vehicle seconds per wall second; rates and stamps follow (default 1)", type=float,
             main_job=False), value=lambda a: a.time_scale))
    truth_file: Path | None = field(default=None, metadata=cli_field(  # the main job names its own
        Flag("--truth-file", "the vehicle's true state: JSON lines if it ends in .jsonl, else one JSON object "
             "replaced atomically", type=Path, forwarded=False), value=lambda a: a.truth_file))
    truth_rate_hz: float = field(default=5.0, metadata=cli_field(  # of vehicle time
        Flag("--truth-rate", "truth samples per vehicle second (default 5)", type=float), value=lambda a: a.truth_rate))
    log_interval: float = 10.0  # failed publications: the first logged at once, then a count per interval
    # Each device its own clock (an offset of 5..120 s from the computers', sam_runtime.sim.time_sync), following the
    # bus's time-sync master and stamping 0 ("unknown") until it synchronised; off: the shared stamp clock, as
    # under a time scale other than 1 (the vehicle's time is then not the computers')
    device_clocks: bool = True
    # A reboot (ExecuteCommand RESTART, RestartNode): the device is silent this long (its reset, bootloader and
    # firmware start) before its new node (uptime and transfer ids from 0) comes up
    reboot_s: float = 1.0
    # Boards whose firmware was built from another spec (issue 28 part 4): each reports another interface hash than
    # its spec's (every bit of it inverted: nonzero, never the spec's), as a board flashed from an older spec would.
    stale_firmware: tuple[str, ...] = field(default=(), metadata=cli_field(
        Flag("--stale-firmware", "comma-separated devices whose firmware is from another (older) spec: they report "
             "another interface hash than the spec's (default: none)", metavar="DEVICES", default=",".join),
        value=lambda a: tuple(d.strip() for d in (a.stale_firmware or "").split(",") if d.strip())))

    def firmware_hash(self, device: str, spec_hash: int) -> int:
        """The interface hash `device`'s simulated firmware reports (Cyphal GetInfo software_vcs_revision_id,
        DroneCAN GetNodeInfo software_version.image_crc): its spec's, or another for a stale board.

        >>> SimConfig(stale_firmware=("imu",)).firmware_hash("imu", 0x0123456789abcdef) == 0xfedcba9876543210
        True
        >>> SimConfig().firmware_hash("imu", 5)
        5
        """
        return spec_hash ^ 0xFFFF_FFFF_FFFF_FFFF if device in self.stale_firmware else spec_hash

    def make_vehicle(self) -> SimulatedVehicle:
        """The vehicle of these options (raises ValueError on an impossible start, e.g. below the sea floor)."""
        return SimulatedVehicle(self)
