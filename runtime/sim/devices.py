"""What the simulated devices measure: the state the devices of one vehicle share, generic values for any DSDL type,
and the SAM devices' physics.

- Generic values: :func:`generic_fill` fills every field of any DSDL type from its pydsdl model (slow sines within
  the field's range, timestamps in microseconds, composites recursively), so any spec gets plausible, changing
  data.
- Physics (:data:`PHYSICS`, keyed by the type name without its root namespace and version, e.g. ``sensor.RawIMU``):
  measurements of the shared simulated vehicle (:mod:`sam_runtime.physics.vehicle`) - IMU, magnetometer, pressure,
  altimeter, GNSS (a fix only at the surface), battery - and the actuators' feedback. The SAM actuator devices
  (:data:`SAM_ACTUATORS`, by device name) drive the vehicle's inputs; feedback of other devices comes from their
  own simple model (:meth:`DeviceState.approach`: toward the last command at a finite rate).
- Each physics function first integrates the vehicle up to the time of the reading (fixed 10 ms steps).
"""

from __future__ import annotations

import logging
import math
import random
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from sam_runtime.physics.vehicle import SimulatedVehicle, Vehicle

__all__ = ["PHYSICS", "SAM_ACTUATORS", "DeviceState", "PhysicsFn", "VehicleState", "device_stamp_us", "fill_altitude",
           "fill_battery", "fill_gnss", "fill_imu", "fill_magnetometer", "fill_position_feedback", "fill_pressure",
           "fill_thrust_vector_feedback", "generic_fill", "physics_key", "set_field", "vehicle_actuator"]

_log = logging.getLogger("sam_runtime.sim.simulator")

SYNC_TIMESTAMP = "uavcan.time.SynchronizedTimestamp"
GEOID_HEIGHT_M = 23.0  # the geoid above the WGS 84 ellipsoid near Stockholm

# SAM's actuator devices (by the spec's device name): command field -> the vehicle model's input.
SAM_ACTUATORS: dict[str, dict[str, str]] = {
    "thruster_1": {"rpm": "rpm_1"},
    "thruster_2": {"rpm": "rpm_2"},
    "thrust_vector": {"vertical_radians": "vertical_rad", "horizontal_radians": "horizontal_rad"},
    "ballast": {"weight_1_offset_radians": "ballast_1_rad", "weight_2_offset_radians": "ballast_2_rad"},
    "longitudinal_weight": {"percent": "longitudinal_weight_pct"},
    "buoyancy_piston": {"percent": "buoyancy_pct"},
}


# ============================================================================================ state
@dataclass
class VehicleState:
    """What the devices of one vehicle share: the clock and the simulated vehicle (model and sensors)."""

    epoch_us: int = field(default_factory=lambda: time.time_ns() // 1000)
    mono0_ns: int = field(default_factory=time.monotonic_ns)
    rng: random.Random = field(default_factory=lambda: random.Random(0x5A3))
    time_scale: float = 1.0  # vehicle seconds per wall second
    model: SimulatedVehicle = field(default_factory=SimulatedVehicle)

    def t(self) -> float:
        """Vehicle seconds since start."""
        return (time.monotonic_ns() - self.mono0_ns) * 1e-9 * self.time_scale

    def now_us(self) -> int:
        """Monotonic microseconds since the Unix epoch of the start time (in vehicle time)."""
        return self.epoch_us + int((time.monotonic_ns() - self.mono0_ns) * self.time_scale) // 1000

    @property
    def vehicle(self) -> Vehicle:
        return self.model.vehicle

    def sync(self, t: float) -> Vehicle:
        """The vehicle integrated up to ``t`` (never backwards)."""
        self.model.vehicle.advance_to(t)
        return self.model.vehicle


@dataclass
class DeviceState:
    """One simulated device's own state: its last accepted command and its actuator positions."""

    name: str
    node_id: int
    command: dict[str, Any] = field(default_factory=dict)  # field name -> value of the last accepted command
    position: dict[str, float] = field(default_factory=dict)  # model state, e.g. percent, rpm
    last_update: float | None = None  # VehicleState.t() of the last model step
    extra: dict[str, Any] = field(default_factory=dict)
    # The stamp of the message being made, in the device's synchronised time (0: not synchronised yet, "unknown");
    # None: the shared stamp clock (no device clocks, e.g. under a time scale)
    stamp_us: int | None = None

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
            elif isinstance(t, pydsdl.VariableLengthArrayType) and isinstance(t.element_type, pydsdl.CompositeType):
                # a few elements, each filled as a nested composite (arrays of composites mapped element by element)
                element = pycyphal.dsdl.get_class(t.element_type)
                setattr(obj, f.name, [generic_fill(element(), tt, now_us, seed + i + 1 + k)
                                      for k in range(min(t.capacity, 3))])
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


def set_field(obj: Any, name: str, value: Any) -> None:
    """Set a field if the type has it (a spec may differ from SAM's); out-of-range values are clipped by the
    caller or left at the generic value."""
    if hasattr(obj, name):
        try:
            setattr(obj, name, value)
        except (ValueError, TypeError) as ex:
            _log.debug("%s.%s = %r refused: %s", type(obj).__name__, name, value, ex)


def device_stamp_us(dev: DeviceState, veh: VehicleState) -> int:
    """The stamp of the device's message now: its synchronised time (0 before it synchronised), or the shared stamp
    clock when the devices have no clocks of their own."""
    return veh.now_us() if dev.stamp_us is None else dev.stamp_us


def _stamp(obj: Any, name: str, us: int) -> None:
    """A timestamp field: Cyphal's SynchronizedTimestamp (``microsecond``) or UAVCAN v0's Timestamp (``usec``)."""
    sub = getattr(obj, name, None)
    if sub is None:
        return
    if hasattr(sub, "microsecond"):
        sub.microsecond = us
    elif hasattr(sub, "usec"):
        sub.usec = us


# ============================================================================================ SAM physics
PhysicsFn = Callable[[Any, DeviceState, VehicleState, float, float, random.Random], None]


def fill_imu(obj: Any, dev: DeviceState, veh: VehicleState, t: float, dt: float, rng: random.Random, *,
         full_covariance: bool = True) -> None:
    veh.sync(t)
    m = veh.model.sensors.imu()
    _stamp(obj, "timestamp", device_stamp_us(dev, veh))
    set_field(obj, "integration_interval", dt)
    set_field(obj, "rate_gyro_latest", list(m.gyro))
    set_field(obj, "rate_gyro_integral", [g * dt for g in m.gyro])
    set_field(obj, "accelerometer_latest", list(m.accel))
    set_field(obj, "accelerometer_integral", [a * dt for a in m.accel])
    # Full 6x6 covariance of [gyro, accel], row major: makes the transfer multi-frame on CAN FD too; or its diagonal
    # (UAVCAN v0: on classic CAN, 36 float16 would more than double the frames of every sample).
    n = veh.model.sensors.noise
    if full_covariance:
        set_field(obj, "covariance", [(n.gyro ** 2 if i < 3 else n.accel ** 2) if i == j else 0.0
                                 for i in range(6) for j in range(6)])
    else:
        set_field(obj, "covariance", [n.gyro ** 2] * 3 + [n.accel ** 2] * 3)


def fill_magnetometer(obj: Any, dev: DeviceState, veh: VehicleState, t: float, dt: float, rng: random.Random) -> None:
    veh.sync(t)
    set_field(obj, "magnetic_field_ga", list(veh.model.sensors.magnetometer()))
    var = veh.model.sensors.noise.mag ** 2
    set_field(obj, "magnetic_field_covariance", [var if i == j else 0.0 for i in range(3) for j in range(3)])


def fill_gnss(obj: Any, dev: DeviceState, veh: VehicleState, t: float, dt: float, rng: random.Random) -> None:
    veh.sync(t)
    fix = veh.model.sensors.gps()
    _stamp(obj, "timestamp", device_stamp_us(dev, veh))
    set_field(obj, "latitude_deg_1e8", round(fix.lat * 1e8))
    set_field(obj, "longitude_deg_1e8", round(fix.lon * 1e8))
    set_field(obj, "status", fix.status)
    set_field(obj, "sats_used", fix.sats)
    if fix.status == veh.model.sensors.GPS_STATUS_NO_FIX:
        set_field(obj, "height_ellipsoid_mm", 0)
        set_field(obj, "height_msl_mm", 0)
        set_field(obj, "ned_velocity", [0.0, 0.0, 0.0])
        set_field(obj, "pdop", 99.0)
        set_field(obj, "position_covariance", [])  # unknown
        return
    set_field(obj, "height_ellipsoid_mm", round((GEOID_HEIGHT_M + fix.height_msl) * 1000))
    set_field(obj, "height_msl_mm", round(fix.height_msl * 1000))
    set_field(obj, "ned_velocity", list(fix.ned_velocity))
    set_field(obj, "pdop", 1.2)
    var = fix.std_m ** 2
    set_field(obj, "position_covariance", [var if i == j else 0.0 for i in range(3) for j in range(3)])


def fill_pressure(obj: Any, dev: DeviceState, veh: VehicleState, t: float, dt: float, rng: random.Random) -> None:
    veh.sync(t)
    set_field(obj, "static_pressure", veh.model.sensors.pressure())
    set_field(obj, "static_pressure_variance", veh.model.sensors.noise.pressure ** 2)


def fill_altitude(obj: Any, dev: DeviceState, veh: VehicleState, t: float, dt: float, rng: random.Random) -> None:
    veh.sync(t)
    _stamp(obj, "timestamp", device_stamp_us(dev, veh))
    set_field(obj, "altitude", veh.model.sensors.altitude())
    set_field(obj, "altitude_variance", veh.model.sensors.noise.altitude ** 2)


def fill_battery(obj: Any, dev: DeviceState, veh: VehicleState, t: float, dt: float, rng: random.Random) -> None:
    veh.sync(t)
    b = veh.model.sensors.battery()
    set_field(obj, "temperature", b.temperature_k)
    set_field(obj, "voltage", b.voltage)
    set_field(obj, "current", b.current)
    set_field(obj, "average_power_10sec", b.power_w)
    set_field(obj, "remaining_capacity_wh", b.remaining_wh)
    set_field(obj, "full_charge_capacity_wh", b.full_wh)
    set_field(obj, "hours_to_full_charge", 0.0)
    set_field(obj, "status_flags", b.status_flags)
    set_field(obj, "state_of_health_pct", b.health_pct)
    set_field(obj, "state_of_charge_pct", round(b.soc * 100))
    set_field(obj, "state_of_charge_pct_stdev", 2)
    set_field(obj, "battery_id", 0)
    set_field(obj, "model_instance_id", 0x5A3_0001)
    set_field(obj, "model_name", b"SAM 6S Li-ion")


def vehicle_actuator(dev: DeviceState, veh: VehicleState, t: float, command_field: str) -> float | None:
    """The vehicle model's actuator position for a SAM device's command field, or None for other devices."""
    name = SAM_ACTUATORS.get(dev.name, {}).get(command_field)
    if name is None:
        return None
    return float(getattr(veh.sync(t).actuators, name))


def _thruster_feedback(obj: Any, dev: DeviceState, veh: VehicleState, t: float, dt: float,
                       rng: random.Random) -> None:
    rpm = vehicle_actuator(dev, veh, t, "rpm")
    if rpm is None:
        rpm = dev.approach("rpm", float(dev.command.get("rpm", 0)), 2000.0, t)  # spins up at 2000 rpm/s
    _stamp(obj, "timestamp", device_stamp_us(dev, veh))
    set_field(obj, "rpm", round(max(-131072, min(131071, rpm))))
    set_field(obj, "current", 0.3 + 2.0 * abs(rpm) / 1000.0)
    set_field(obj, "temperature_c", int(min(127, 25 + abs(rpm) / 200.0)))


def fill_thrust_vector_feedback(obj: Any, dev: DeviceState, veh: VehicleState, t: float, dt: float,
                            rng: random.Random) -> None:
    v = vehicle_actuator(dev, veh, t, "vertical_radians")
    h = vehicle_actuator(dev, veh, t, "horizontal_radians")
    if v is None or h is None:  # 0.5 rad/s servos
        v = dev.approach("vertical", float(dev.command.get("vertical_radians", 0.0)), 0.5, t)
        h = dev.approach("horizontal", float(dev.command.get("horizontal_radians", 0.0)), 0.5, t)
    _stamp(obj, "timestamp", device_stamp_us(dev, veh))
    set_field(obj, "vertical_mrad", int(max(-4096, min(4095, round(v * 1000)))))
    set_field(obj, "horizontal_mrad", int(max(-4096, min(4095, round(h * 1000)))))


def fill_position_feedback(obj: Any, dev: DeviceState, veh: VehicleState, t: float, dt: float,
                       rng: random.Random) -> None:
    pct = vehicle_actuator(dev, veh, t, "percent")
    if pct is None:
        target = float(dev.command.get("percent", 50.0))
        pct = dev.approach("percent", max(0.0, min(100.0, target)), 10.0, t, initial=50.0)  # 10 %/s
    _stamp(obj, "timestamp", device_stamp_us(dev, veh))
    set_field(obj, "percent", pct)
    set_field(obj, "encoder_count", round(pct * 100))  # 10 000 counts over the full travel


# Keyed by the DSDL type's full name without the root namespace and version.
PHYSICS: dict[str, PhysicsFn] = {
    "sensor.RawIMU": fill_imu,
    "sensor.MagneticFieldStrength": fill_magnetometer,
    "sensor.GNSSFix": fill_gnss,
    "sensor.StaticPressure": fill_pressure,
    "sensor.Altitude": fill_altitude,
    "power.BatteryInfo": fill_battery,
    "actuator.ThrusterFeedback": _thruster_feedback,
    "actuator.ThrustVectorFeedback": fill_thrust_vector_feedback,
    "actuator.PositionFeedback": fill_position_feedback,
}


def physics_key(dsdl_type: str) -> str:
    """``sam.sensor.RawIMU.0.1`` -> ``sensor.RawIMU``."""
    parts = dsdl_type.split(".")
    if len(parts) >= 3 and parts[-1].isdigit() and parts[-2].isdigit():
        parts = parts[:-2]
    return ".".join(parts[1:])
