"""The simulator's options (:class:`SimConfig`)."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path

from sam_runtime.physics.vehicle import SeaFloor, SensorNoise, SimulatedVehicle, VehicleParams

__all__ = ["SimConfig"]


@dataclass
class SimConfig:
    """``kind``/``iface``/``mtu`` as in :func:`~sam_runtime.cyphal_io.transport.make_transport`
    (``env``: UAVCAN__UDP__IFACE
    / UAVCAN__CAN__IFACE / UAVCAN__CAN__MTU from ``environ``; node ids always come from the spec)."""

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
    # The simulated vehicle (physics.vehicle): noise seed, sea floor, start pose in the sim's world frame
    # (ENU metres around gps_origin; yaw counter-clockwise from east), battery, time.
    seed: int = 0
    sea_floor: SeaFloor = field(default_factory=SeaFloor)
    start: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)  # x, y, depth, yaw
    battery_percent: float = 95.0
    battery_drain_factor: float = 1.0  # multiplies the power drawn (a scenario can drain the battery quickly)
    battery_health_pct: int = 98
    gps_origin: tuple[float, float] = (59.35, 18.07)  # lat, lon of the sim's world origin (KTH, Stockholm)
    vehicle_params: VehicleParams = field(default_factory=VehicleParams)
    noise: SensorNoise = field(default_factory=SensorNoise)
    time_scale: float = 1.0  # vehicle seconds per wall second (rates and stamps follow)
    truth_file: Path | None = None  # the true state: JSON lines if it ends in .jsonl, else an atomic JSON file
    truth_rate_hz: float = 5.0  # of vehicle time

    def make_vehicle(self) -> SimulatedVehicle:
        """The vehicle of these options (raises ValueError on an impossible start, e.g. below the sea floor)."""
        return SimulatedVehicle(seed=self.seed, sea_floor=self.sea_floor, start=self.start,
                                battery_percent=self.battery_percent, battery_drain_factor=self.battery_drain_factor,
                                battery_health_pct=self.battery_health_pct, gps_origin=self.gps_origin,
                                params=self.vehicle_params, noise=self.noise)
    log_interval: float = 10.0  # failed publications: the first logged at once, then a count per interval
    # Each device its own clock (an offset of 5..120 s from the computers', sam_runtime.sim.time_sync), following the
    # bus's time-sync master and stamping 0 ("unknown") until it synchronised; off: the shared stamp clock, as
    # under a time scale other than 1 (the vehicle's time is then not the computers')
    device_clocks: bool = True
    # A reboot (ExecuteCommand RESTART, RestartNode): the device is silent this long (its reset, bootloader and
    # firmware start) before its new node (uptime and transfer ids from 0) comes up
    reboot_s: float = 1.0
