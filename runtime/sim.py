"""Simulated devices: one Cyphal node per device of the spec, with the spec's node id, in one asyncio loop.

- Every published port runs at its nominal rate (``rate_hz`` of the spec, optionally scaled), on an
  absolute schedule (no drift; a late tick is published late, never twice).
- Values: a generic generator fills every field of any DSDL type from its pydsdl model (slow sines within
  the field's range, timestamps in microseconds, composites recursively), so any spec gets plausible,
  changing data. Where the type is known, a small physics table (:data:`PHYSICS`, keyed by the type name
  without its root namespace, e.g. ``sensor.RawIMU``) overrides the fields with the SAM models: IMU at rest
  with gravity and noise, a slowly rotating ~0.5 G magnetic field, a GNSS fix at the surface near KTH, the
  pressure at a depth that oscillates 0..10 m, a discharging battery, actuators moving toward their
  commanded values at a finite rate.
- Actuators accept commands only from the bridge's node id; commands from any other node are counted and
  ignored. The last accepted command drives the device's feedback model.
- Timestamps: microseconds on a monotonic clock whose epoch is the wall-clock time at start (realistic
  ROS stamps, never jumping).

``Simulator.report()`` gives counts per device and subject (published, commands accepted/rejected, the
last command); ``record`` writes every transmitted and received message (as transmitted) as JSON lines.
For fault tests: ``power_off(name)``/``power_on(name)`` (a device that stops - its heartbeat too - and
reboots) and ``pause()``/``resume()`` (hold every publication, heartbeats go on, nothing left in flight).
"""

from __future__ import annotations

import asyncio
import json
import logging
import math
import random
import time
from collections import Counter
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TextIO

from sam_runtime.genpkg import GeneratedPackage

__all__ = ["PHYSICS", "DeviceState", "SimConfig", "Simulator", "VehicleState"]

_log = logging.getLogger("sam_runtime.sim")

SYNC_TIMESTAMP = "uavcan.time.SynchronizedTimestamp"
G = 9.80665
RHO_SEAWATER = 1025.0
P_ATM = 101325.0


# ============================================================================================ state
@dataclass
class VehicleState:
    """What the devices of one vehicle share: time and the vehicle's motion."""

    epoch_us: int = field(default_factory=lambda: time.time_ns() // 1000)
    mono0_ns: int = field(default_factory=time.monotonic_ns)
    rng: random.Random = field(default_factory=lambda: random.Random(0x5A3))
    depth_period_s: float = 120.0
    max_depth_m: float = 10.0

    def t(self) -> float:
        """Seconds since start."""
        return (time.monotonic_ns() - self.mono0_ns) * 1e-9

    def now_us(self) -> int:
        """Monotonic microseconds since the Unix epoch of the start time."""
        return self.epoch_us + (time.monotonic_ns() - self.mono0_ns) // 1000

    def depth(self, t: float) -> float:
        """Depth [m], a slow oscillation between the surface and max_depth_m."""
        return self.max_depth_m * 0.5 * (1.0 - math.cos(2.0 * math.pi * t / self.depth_period_s))

    def heading(self, t: float) -> float:
        return (0.05 * t) % (2.0 * math.pi)


@dataclass
class DeviceState:
    """One simulated device's own state: its last accepted command and its actuator positions."""

    name: str
    node_id: int
    command: dict[str, Any] = field(default_factory=dict)  # field name -> value of the last accepted command
    position: dict[str, float] = field(default_factory=dict)  # model state, e.g. percent, rpm
    last_update: float | None = None  # VehicleState.t() of the last model step
    extra: dict[str, Any] = field(default_factory=dict)

    def approach(self, key: str, target: float, rate_per_s: float, t: float, initial: float = 0.0) -> float:
        """Move position[key] toward target at rate_per_s since the last call; returns the new value."""
        cur = self.position.get(key, initial)
        dt = 0.0 if self.last_update is None else max(0.0, t - self.last_update)
        step = rate_per_s * dt
        cur = min(cur + step, target) if target >= cur else max(cur - step, target)
        self.position[key] = cur
        return cur


# ============================================================================================ generic values
def _clip_float(bits: int, v: float) -> float:
    lim = {16: 65504.0, 32: 3.4028234e38}.get(bits, 1.7976931348623157e308)
    return max(-lim, min(lim, v))


def _int_range(t: Any) -> tuple[int, int]:
    import pydsdl

    if isinstance(t, pydsdl.BooleanType):
        return 0, 1
    r = t.inclusive_value_range
    return int(r.min), int(r.max)


def _generic_scalar(t: Any, phase: float, tt: float, now_us: int) -> Any:
    import pydsdl

    s = math.sin(2.0 * math.pi * tt / 20.0 + phase)
    if isinstance(t, pydsdl.BooleanType):
        return s > 0
    if isinstance(t, pydsdl.FloatType):
        return _clip_float(t.bit_length, round(10.0 * s, 3))
    if isinstance(t, pydsdl.IntegerType):
        lo, hi = _int_range(t)
        mid = (lo + hi) // 2 if lo < 0 else min(hi, 100)
        amp = min(1000, (hi - lo) // 4)
        return max(lo, min(hi, round(mid + amp * s)))
    return None


def generic_fill(obj: Any, tt: float, now_us: int, seed: int = 0) -> Any:
    """Fill every field of a pycyphal object with a slowly changing in-range value (any DSDL type)."""
    import pycyphal.dsdl
    import pydsdl

    model = pycyphal.dsdl.get_model(obj)
    if isinstance(model, pydsdl.DelimitedType):
        model = model.inner_type
    if isinstance(model, pydsdl.UnionType):
        return obj  # unions keep their default (first) variant
    for i, f in enumerate(model.fields_except_padding):
        t, phase = f.data_type, 0.7 * (i + seed)
        try:
            if isinstance(t, pydsdl.PrimitiveType):
                setattr(obj, f.name, _generic_scalar(t, phase, tt, now_us))
            elif isinstance(t, pydsdl.CompositeType):
                sub = getattr(obj, f.name)
                if str(t.full_name) == SYNC_TIMESTAMP or t.full_name.endswith(".SynchronizedTimestamp"):
                    sub.microsecond = now_us
                else:
                    generic_fill(sub, tt, now_us, seed + i + 1)
            elif isinstance(t, pydsdl.ArrayType) and isinstance(t.element_type, pydsdl.PrimitiveType):
                n = t.capacity if isinstance(t, pydsdl.FixedLengthArrayType) else min(t.capacity, 3)
                if isinstance(t.element_type, pydsdl.UnsignedIntegerType) and t.element_type.bit_length == 8 \
                        and "name" in f.name:
                    setattr(obj, f.name, b"sim"[: t.capacity])
                else:
                    setattr(obj, f.name, [_generic_scalar(t.element_type, phase + 0.3 * k, tt, now_us)
                                          for k in range(n)])
        except (ValueError, TypeError) as ex:  # a value the type refuses: keep the default
            _log.debug("generic value for %s.%s refused: %s", type(obj).__name__, f.name, ex)
    return obj


def _set(obj: Any, name: str, value: Any) -> None:
    """Set a field if the type has it (a spec may differ from SAM's); out-of-range values are clipped by the
    caller or left at the generic value."""
    if hasattr(obj, name):
        try:
            setattr(obj, name, value)
        except (ValueError, TypeError) as ex:
            _log.debug("%s.%s = %r refused: %s", type(obj).__name__, name, value, ex)


def _stamp(obj: Any, name: str, us: int) -> None:
    sub = getattr(obj, name, None)
    if sub is not None and hasattr(sub, "microsecond"):
        sub.microsecond = us


# ============================================================================================ SAM physics
PhysicsFn = Callable[[Any, DeviceState, VehicleState, float, float, random.Random], None]


def _imu(obj: Any, dev: DeviceState, veh: VehicleState, t: float, dt: float, rng: random.Random) -> None:
    n = rng.gauss
    gyro = [0.05 * math.sin(0.5 * t), 0.04 * math.sin(0.3 * t + 1.0), 0.05]  # yaw rate = d(heading)/dt
    acc = [0.02 * n(0, 1), 0.02 * n(0, 1), G + 0.02 * n(0, 1)]
    _stamp(obj, "timestamp", veh.now_us())
    _set(obj, "integration_interval", dt)
    _set(obj, "rate_gyro_latest", gyro)
    _set(obj, "rate_gyro_integral", [g * dt for g in gyro])
    _set(obj, "accelerometer_latest", acc)
    _set(obj, "accelerometer_integral", [a * dt for a in acc])
    # Full 6x6 covariance of [gyro, accel], row major: makes the transfer multi-frame on CAN FD too.
    _set(obj, "covariance", [(1e-4 if i < 3 else 4e-4) if i == j else 0.0 for i in range(6) for j in range(6)])


def _magnetometer(obj: Any, dev: DeviceState, veh: VehicleState, t: float, dt: float, rng: random.Random) -> None:
    # Stockholm: ~0.52 G total, inclination ~73 deg: 0.15 G horizontal, 0.49 G down; body frame rotates.
    h = veh.heading(t)
    field_ga = [0.15 * math.cos(h) + 0.002 * rng.gauss(0, 1), -0.15 * math.sin(h) + 0.002 * rng.gauss(0, 1),
                0.49 + 0.002 * rng.gauss(0, 1)]
    _set(obj, "magnetic_field_ga", field_ga)
    _set(obj, "magnetic_field_covariance", [4e-6 if i == j else 0.0 for i in range(3) for j in range(3)])


def _gnss(obj: Any, dev: DeviceState, veh: VehicleState, t: float, dt: float, rng: random.Random) -> None:
    # At the surface near KTH, Stockholm (59.35 N, 18.07 E), drifting slowly east-north-east at ~0.5 m/s.
    lat = 59.3500 + 0.5 * math.sin(0.3) * t / 111_320.0
    lon = 18.0700 + 0.5 * math.cos(0.3) * t / (111_320.0 * math.cos(math.radians(59.35)))
    _stamp(obj, "timestamp", veh.now_us())
    _set(obj, "latitude_deg_1e8", round(lat * 1e8))
    _set(obj, "longitude_deg_1e8", round(lon * 1e8))
    wave = 0.2 * math.sin(2 * math.pi * t / 8.0)
    _set(obj, "height_ellipsoid_mm", round((23.0 + wave) * 1000))  # geoid ~23 m above the ellipsoid
    _set(obj, "height_msl_mm", round(wave * 1000))
    _set(obj, "ned_velocity", [0.5 * math.sin(0.3), 0.5 * math.cos(0.3), 0.0])
    _set(obj, "sats_used", 9 + int(2 * (1 + math.sin(t / 30.0))))
    _set(obj, "status", 3)
    _set(obj, "pdop", 1.2 + 0.1 * math.sin(t / 10.0))
    _set(obj, "position_covariance", [2.25 if i == j else 0.0 for i in range(3) for j in range(3)])


def _pressure(obj: Any, dev: DeviceState, veh: VehicleState, t: float, dt: float, rng: random.Random) -> None:
    depth = veh.depth(t)
    _set(obj, "static_pressure", P_ATM + RHO_SEAWATER * G * depth + 5.0 * rng.gauss(0, 1))
    _set(obj, "static_pressure_variance", 25.0)


def _battery(obj: Any, dev: DeviceState, veh: VehicleState, t: float, dt: float, rng: random.Random) -> None:
    full_wh = 800.0
    soc = max(0.0, 0.95 - 0.0005 * t)  # 0.05 %/s: visible in a demo
    current = -(12.0 + 0.5 * math.sin(t / 5.0))
    voltage = 6 * (3.4 + 0.8 * soc)  # a 6S pack
    _set(obj, "temperature", 298.15 + 2.0 * math.sin(t / 60.0))
    _set(obj, "voltage", voltage)
    _set(obj, "current", current)
    _set(obj, "average_power_10sec", -voltage * current)
    _set(obj, "remaining_capacity_wh", full_wh * soc)
    _set(obj, "full_charge_capacity_wh", full_wh)
    _set(obj, "hours_to_full_charge", 0.0)
    _set(obj, "status_flags", 1)  # IN_USE
    _set(obj, "state_of_health_pct", 98)
    _set(obj, "state_of_charge_pct", round(soc * 100))
    _set(obj, "state_of_charge_pct_stdev", 2)
    _set(obj, "battery_id", 0)
    _set(obj, "model_instance_id", 0x5A3_0001)
    _set(obj, "model_name", b"SAM 6S Li-ion")


def _thruster_feedback(obj: Any, dev: DeviceState, veh: VehicleState, t: float, dt: float,
                       rng: random.Random) -> None:
    target = float(dev.command.get("rpm", 0))
    rpm = dev.approach("rpm", target, 2000.0, t)  # spins up at 2000 rpm/s
    _stamp(obj, "timestamp", veh.now_us())
    _set(obj, "rpm", round(max(-131072, min(131071, rpm))))
    _set(obj, "current", 0.3 + 2.0 * abs(rpm) / 1000.0)
    _set(obj, "temperature_c", int(min(127, 25 + abs(rpm) / 200.0)))


def _thrust_vector_feedback(obj: Any, dev: DeviceState, veh: VehicleState, t: float, dt: float,
                            rng: random.Random) -> None:
    v = dev.approach("vertical", float(dev.command.get("vertical_radians", 0.0)), 0.5, t)  # 0.5 rad/s servos
    h = dev.approach("horizontal", float(dev.command.get("horizontal_radians", 0.0)), 0.5, t)
    _stamp(obj, "timestamp", veh.now_us())
    _set(obj, "vertical_mrad", int(max(-4096, min(4095, round(v * 1000)))))
    _set(obj, "horizontal_mrad", int(max(-4096, min(4095, round(h * 1000)))))


def _position_feedback(obj: Any, dev: DeviceState, veh: VehicleState, t: float, dt: float,
                       rng: random.Random) -> None:
    target = float(dev.command.get("percent", 50.0))
    pct = dev.approach("percent", max(0.0, min(100.0, target)), 10.0, t, initial=50.0)  # 10 %/s
    _stamp(obj, "timestamp", veh.now_us())
    _set(obj, "percent", pct)
    _set(obj, "encoder_count", round(pct * 100))  # 10 000 counts over the full travel


# Keyed by the DSDL type's full name without the root namespace and version.
PHYSICS: dict[str, PhysicsFn] = {
    "sensor.RawIMU": _imu,
    "sensor.MagneticFieldStrength": _magnetometer,
    "sensor.GNSSFix": _gnss,
    "sensor.StaticPressure": _pressure,
    "power.BatteryInfo": _battery,
    "actuator.ThrusterFeedback": _thruster_feedback,
    "actuator.ThrustVectorFeedback": _thrust_vector_feedback,
    "actuator.PositionFeedback": _position_feedback,
}


def physics_key(dsdl_type: str) -> str:
    """``sam.sensor.RawIMU.0.1`` -> ``sensor.RawIMU``."""
    parts = dsdl_type.split(".")
    if len(parts) >= 3 and parts[-1].isdigit() and parts[-2].isdigit():
        parts = parts[:-2]
    return ".".join(parts[1:])


# ============================================================================================ simulator
@dataclass
class SimConfig:
    """``kind``/``iface``/``mtu`` as in :func:`sam_runtime.transport.make_transport` (``env``: UAVCAN__UDP__IFACE
    / UAVCAN__CAN__IFACE / UAVCAN__CAN__MTU from ``environ``; node ids always come from the spec)."""

    kind: str = "udp"
    iface: str | None = None
    mtu: int | None = None
    environ: Mapping[str, str] | None = None
    bridge_node_id: int | None = None  # commands accepted only from it; default: the spec's bridge
    devices: Iterable[str] | None = None  # subset of device names; default all
    rate_scale: float = 1.0
    record: Path | None = None  # JSON lines of every transmitted/received message
    log_interval: float = 10.0  # failed publications: the first logged at once, then a count per interval


@dataclass
class _PubPort:
    port: Any
    dtype: type
    physics: PhysicsFn | None
    publisher: Any = None
    task: asyncio.Task[None] | None = None
    sent: int = 0
    late: int = 0
    failed: int = 0
    busy: bool = False  # a publish in flight


@dataclass
class _SubPort:
    port: Any
    dtype: type
    subscriber: Any = None
    accepted: int = 0
    rejected: int = 0
    rejected_sources: Counter[int] = field(default_factory=Counter)
    last: dict[str, Any] | None = None


@dataclass
class _SimDevice:
    info: Any
    state: DeviceState
    node: Any = None
    pubs: list[_PubPort] = field(default_factory=list)
    subs: list[_SubPort] = field(default_factory=list)
    powered: bool = False
    power_cycles: int = 0


class Simulator:
    """All simulated devices of a spec. In a running loop: ``await start()``, ``start_publishing()`` (or pass
    ``publish_now=True``), ..., ``await close()``."""

    def __init__(self, gen: GeneratedPackage, config: SimConfig | None = None) -> None:
        self.gen = gen
        self.tables = gen.tables()
        self.config = config or SimConfig()
        self.vehicle = VehicleState()
        self.bridge_node_id = int(self.config.bridge_node_id if self.config.bridge_node_id is not None
                                  else self.tables.BRIDGE_NODE_ID)
        wanted = None if self.config.devices is None else set(self.config.devices)
        names = {d.name for d in self.tables.DEVICES}
        if wanted is not None and wanted - names:
            raise ValueError(f"unknown device(s) {sorted(wanted - names)}; the spec has {sorted(names)}")
        self.devices = [
            _SimDevice(d, DeviceState(d.name, d.node_id)) for d in self.tables.DEVICES
            if wanted is None or d.name in wanted
        ]
        self._go: asyncio.Event | None = None  # created in start() (inside the loop)
        self._running: asyncio.Event | None = None  # cleared by pause()
        self._record: TextIO | None = None
        self._publishing_since: float | None = None
        self._publishing_until: float | None = None
        self._closed = False
        from sam_runtime.bridge import RateLimitedLog

        self.log = RateLimitedLog(_log, self.config.log_interval)  # bounded, like the bridge's

    # ---------------------------------------------------------------------------------- lifecycle
    async def start(self, *, publish_now: bool = False) -> None:
        """Create every device's node (heartbeats start at once) and its ports; sensors wait for
        :meth:`start_publishing` unless ``publish_now``."""
        self.gen.compile_dsdl()

        from sam_runtime.bridge import quiet_late_media_completions

        quiet_late_media_completions(asyncio.get_running_loop())
        self._go = asyncio.Event()
        self._running = asyncio.Event()
        self._running.set()
        if self.config.record is not None:
            self._record = open(self.config.record, "w", buffering=1)
        try:
            for dev in self.devices:
                for port in dev.info.subscribes:
                    dev.subs.append(_SubPort(port, self.gen.dsdl_class(port)))
                for port in dev.info.publishes:
                    dev.pubs.append(_PubPort(port, self.gen.dsdl_class(port), PHYSICS.get(physics_key(port.dsdl_type))))
                self._open_device(dev)
            for dev in self.devices:
                self._start_device_tasks(dev)
        except BaseException:
            await self.close()
            raise
        if publish_now:
            self.start_publishing()

    def _open_device(self, dev: _SimDevice) -> None:
        """The device's node (heartbeats start at once) and its ports."""
        import uavcan.node

        from sam_runtime.transport import make_node, transport_from_env

        name = f"org.{self.tables.VEHICLE}.sim.{dev.info.name}"[:50]
        if self.config.kind == "env":
            env = dict(self.config.environ or {})
            env["UAVCAN__NODE__ID"] = str(dev.info.node_id)
            dev.node = make_node(name, dev.info.node_id, transport=transport_from_env(env))
        else:
            dev.node = make_node(name, dev.info.node_id, self.config.kind, iface=self.config.iface,
                                 mtu=self.config.mtu)
        dev.node.heartbeat_publisher.mode = uavcan.node.Mode_1_0.OPERATIONAL
        for sp in dev.subs:
            sp.subscriber = dev.node.make_subscriber(sp.dtype, sp.port.subject_id)
            sp.subscriber.receive_in_background(lambda msg, tr, dev=dev, sp=sp: self._on_command(dev, sp, msg, tr))
        for pp in dev.pubs:
            pp.publisher = dev.node.make_publisher(pp.dtype, pp.port.subject_id)
            pp.publisher.send_timeout = 1.0
        dev.powered = True

    def _start_device_tasks(self, dev: _SimDevice, restart: bool = False) -> None:
        for pp in dev.pubs:
            pp.task = asyncio.create_task(self._publish_loop(dev, pp, restart),
                                          name=f"sim-{dev.info.name}-{pp.port.subject_id}")

    def device(self, name: str) -> _SimDevice:
        for dev in self.devices:
            if dev.info.name == name:
                return dev
        raise KeyError(f"no simulated device {name!r}")

    async def power_off(self, name: str) -> None:
        """Cut the device's power: its node closes, so its heartbeats and publications stop (a device that stops
        sending, for heartbeat-timeout tests). Its counters are kept."""
        from sam_runtime.bridge import cancel_and_wait
        from sam_runtime.transport import aclose

        dev = self.device(name)
        if not dev.powered:
            return
        dev.powered = False
        await cancel_and_wait([pp.task for pp in dev.pubs if pp.task is not None])
        ports = [pp.publisher for pp in dev.pubs] + [sp.subscriber for sp in dev.subs]
        for pp in dev.pubs:
            pp.task, pp.publisher = None, None
        for sp in dev.subs:
            sp.subscriber = None
        node, dev.node = dev.node, None
        await aclose(*[p for p in ports if p is not None])
        if node is not None:
            await aclose(node)
        dev.power_cycles += 1

    async def power_on(self, name: str) -> None:
        """Power a device back on: a new node (uptime and transfer ids from 0, like a reboot) that publishes on
        its schedule again (if publishing was started)."""
        dev = self.device(name)
        if dev.powered or self._closed:
            return
        self._open_device(dev)
        self._start_device_tasks(dev, restart=True)

    def start_publishing(self, duration: float | None = None) -> None:
        """Open the gate: every publisher starts its schedule now; with ``duration``, stops after it."""
        assert self._go is not None, "start() first"
        now = time.monotonic()
        self._publishing_since = now
        self._publishing_until = None if duration is None else now + duration
        self._go.set()

    async def pause(self, timeout: float = 2.0) -> None:
        """Hold every publication (heartbeats go on) and wait until none is in flight: afterwards the counts of
        sent messages do not move (for exact before/after accounting in tests)."""
        assert self._running is not None, "start() first"
        self._running.clear()
        deadline = time.monotonic() + timeout
        while any(pp.busy for d in self.devices for pp in d.pubs) and time.monotonic() < deadline:
            await asyncio.sleep(0.005)

    def resume(self) -> None:
        """Publish again, each port on a new schedule from now (no burst to catch up, no late ticks)."""
        assert self._running is not None, "start() first"
        self._running.set()

    @property
    def publishing_done(self) -> bool:
        return self._publishing_until is not None and time.monotonic() >= self._publishing_until and all(
            pp.task is None or pp.task.done() for d in self.devices for pp in d.pubs)

    async def wait_publishing_done(self) -> None:
        tasks = [pp.task for d in self.devices for pp in d.pubs if pp.task is not None]
        if tasks:
            await asyncio.gather(*tasks, return_exceptions=True)

    async def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        from sam_runtime.bridge import cancel_and_wait
        from sam_runtime.transport import aclose

        stuck = await cancel_and_wait([pp.task for d in self.devices for pp in d.pubs if pp.task is not None])
        if stuck:
            _log.warning("%d publish tasks did not stop", len(stuck))
        ports = [p.publisher for d in self.devices for p in d.pubs] + [s.subscriber for d in self.devices
                                                                       for s in d.subs]
        try:
            await aclose(*[p for p in ports if p is not None])
            await aclose(*[d.node for d in self.devices if d.node is not None])
        except Exception as ex:
            _log.warning("closing the simulated nodes: %s: %s", type(ex).__name__, ex)
        if self._record is not None:
            self._record.close()
            self._record = None
        self.log.flush(force=True)  # no count stays unlogged

    # ---------------------------------------------------------------------------------- publishing
    def make_sample(self, dev: _SimDevice, pp: _PubPort, dt: float) -> Any:
        """One message of the port: generic values, then the device's physics (if known)."""
        t = self.vehicle.t()
        obj = pp.dtype()
        generic_fill(obj, t, self.vehicle.now_us(), seed=pp.port.subject_id)
        if pp.physics is not None:
            pp.physics(obj, dev.state, self.vehicle, t, dt, self.vehicle.rng)
        dev.state.last_update = t
        return obj

    async def _publish_loop(self, dev: _SimDevice, pp: _PubPort, restart: bool = False) -> None:
        assert self._go is not None
        await self._go.wait()
        rate = float(pp.port.rate_hz) * float(self.config.rate_scale)
        if rate <= 0:
            return
        period = 1.0 / rate
        # Align every port to the gate, offset a little per subject so that not all fire at once.
        offset = (pp.port.subject_id % 17) * period / 17.0
        started = self._publishing_since if self._publishing_since is not None else time.monotonic()
        if restart:  # powered on again: a new schedule from now
            started = time.monotonic() - offset
        k = 0
        while not self._closed:
            if self._running is not None and not self._running.is_set():
                await self._running.wait()
                started, k = time.monotonic() - offset, 0
                continue
            due = started + offset + k * period
            until = self._publishing_until
            if until is not None and due >= until:
                return
            delay = due - time.monotonic()
            if delay > 0:
                await asyncio.sleep(delay)
            elif delay < -period:
                # Too late for this tick: skip the missed ones (counted), never burst.
                missed = int(-delay // period)
                pp.late += missed
                k += missed
                continue
            if self._running is not None and not self._running.is_set():
                continue  # paused while sleeping
            obj = self.make_sample(dev, pp, period)
            if pp.publisher is None:  # powered off meanwhile
                return
            pp.busy = True
            pub = pp.publisher
            try:
                ok = await pub.publish(obj)
            except asyncio.CancelledError:
                raise
            except Exception as ex:
                pp.failed += 1
                self.log.note((dev.info.name, f"publish on {pp.port.subject_id}"), logging.WARNING, "failed: %s: %s",
                              type(ex).__name__, ex)
                ok = None
            finally:
                pp.busy = False
            if ok:
                pp.sent += 1
                if self._record is not None:
                    self._write_record("tx", dev, pp.port.subject_id, obj, seq=pp.sent)
            elif ok is False:
                pp.failed += 1
                self.log.note((dev.info.name, f"publish on {pp.port.subject_id}"), logging.WARNING,
                              "not every frame sent within %.1f s", pub.send_timeout)
            if pp.failed:
                self.log.flush()  # a count whose interval has passed, also when the failures have stopped
            k += 1

    # ---------------------------------------------------------------------------------- commands
    def _on_command(self, dev: _SimDevice, sp: _SubPort, msg: Any, transfer: Any) -> None:
        import pycyphal.dsdl

        src = transfer.source_node_id
        accepted = src == self.bridge_node_id
        if accepted:
            sp.accepted += 1
            values = pycyphal.dsdl.to_builtin(msg)
            sp.last = values
            dev.state.command.update(values)
        else:
            sp.rejected += 1
            sp.rejected_sources[-1 if src is None else int(src)] += 1
        if self._record is not None:
            self._write_record("rx", dev, sp.port.subject_id, msg, source=src, accepted=accepted,
                               seq=sp.accepted if accepted else sp.rejected)

    # ---------------------------------------------------------------------------------- reporting
    def _write_record(self, direction: str, dev: _SimDevice, subject: int, obj: Any, **extra: Any) -> None:
        import pycyphal.dsdl

        if direction == "tx":  # the values as transmitted (float16 rounding etc.)
            obj = pycyphal.dsdl.deserialize(type(obj), list(pycyphal.dsdl.serialize(obj)))
        assert self._record is not None
        line = {"dir": direction, "device": dev.info.name, "node_id": dev.info.node_id, "subject": subject,
                "wall_ns": time.time_ns(), **extra, "value": pycyphal.dsdl.to_builtin(obj)}
        self._record.write(json.dumps(line, default=_json_default) + "\n")

    def report(self) -> dict[str, Any]:
        devices: dict[str, Any] = {}
        for d in self.devices:
            devices[d.info.name] = {
                "node_id": d.info.node_id,
                "powered": d.powered,
                "power_cycles": d.power_cycles,
                "published": {str(p.port.subject_id): p.sent for p in d.pubs},
                "late": {str(p.port.subject_id): p.late for p in d.pubs if p.late},
                "failed": {str(p.port.subject_id): p.failed for p in d.pubs if p.failed},
                "commands": {
                    str(s.port.subject_id): {
                        "accepted": s.accepted, "rejected": s.rejected,
                        "rejected_sources": {str(k): v for k, v in s.rejected_sources.items()},
                        "last": s.last,
                    } for s in d.subs
                },
                "position": dict(d.state.position),
            }
        since = self._publishing_since
        return {
            "bridge_node_id": self.bridge_node_id,
            "publishing_s": None if since is None else round(
                (min(time.monotonic(), self._publishing_until or math.inf)) - since, 3),
            "devices": devices,
        }


def _json_default(o: Any) -> Any:
    try:
        import numpy

        if isinstance(o, numpy.ndarray):
            return o.tolist()
        if isinstance(o, numpy.generic):
            return o.item()
    except ImportError:  # pragma: no cover
        pass
    if isinstance(o, bytes | bytearray):
        return o.decode(errors="replace")
    return str(o)
