"""One simulated SAM: a simple rigid-body model driven by its actuators, and the sensors that measure it.

Pure and deterministic: no wall clock, no threads. :meth:`Vehicle.advance_to` moves the model to a time in fixed
steps (100 Hz), so a given seed and command sequence always give the same trajectory however the caller's clock
jitters; :class:`Sensors` measures the true state with noise from per-sensor generators seeded from one seed.

Frames and signs follow REP-103/105 and the issue's contract (see :mod:`sam_runtime.physics.geo`): world ENU, body
FLU, depth positive down, yaw counter-clockwise from east, pitch positive nose DOWN. Actuator signs: thrust
positive forward; horizontal thrust-vector angle > 0 yaws to port (positive yaw rate); vertical angle > 0 pitches
the nose up; buoyancy 100 % rises, 0 % sinks, 50 % neutral; longitudinal weight 100 % forward (nose down),
50 % neutral.

The model (magnitudes for a 1.5 m, 15 kg torpedo with two coaxial counter-rotating propellers behind a vectored
nozzle):

- surge: thrust k rpm|rpm| per propeller against linear + quadratic drag (about 1.8 m/s at 2000 rpm);
- yaw and pitch: the nozzle's lateral/vertical thrust components acting at the stern, with speed-dependent
  damping (the hull's lift grows with speed), a metacentric righting moment in pitch and the trim weight;
- roll: the two ballast weights against a strong righting moment;
- heave (world vertical): net buoyancy of the piston against a broadside hull drag, plus the vertical component of
  the surge along the pitch;
- hard limits at the surface (depth 0) and at the sea floor (:class:`SeaFloor`, flat or a profile);
- actuators slew toward their commands at finite rates; the battery drains with the thrusters' power.
"""

from __future__ import annotations

import itertools
import math
import random
from dataclasses import asdict, dataclass, field, fields, replace
from typing import Any, cast

from sam_runtime.common.cli_fields import Flag, cli_field, float_list
from sam_runtime.physics.geo import (
    P_ATM,
    RHO_SEAWATER,
    G,
    Vec3,
    latlon_from_local,
    pressure_at_depth,
    rotate_body_to_world,
    rotate_world_to_body,
)

__all__ = [
    "EARTH_FIELD_ENU_GA",
    "Actuators",
    "BatteryReading",
    "GpsReading",
    "ImuReading",
    "SeaFloor",
    "SensorNoise",
    "Sensors",
    "SimulatedVehicle",
    "TrueState",
    "Vehicle",
    "VehicleOptions",
    "VehicleParams",
    "steady_surge_speed",
    "surge_acceleration",
]

# The Earth's field near Stockholm in world ENU [Gauss]: 0.15 G toward north, 0.49 G down (inclination ~73 deg);
# declination ignored (the dead reckoning uses the same convention: magnetic north = world north).
EARTH_FIELD_ENU_GA: Vec3 = (0.0, 0.15, -0.49)

# BatteryInfo (UAVCAN v0 1092) status flags used here.
STATUS_FLAG_IN_USE = 1
STATUS_FLAG_BAD_BATTERY = 64
STATUS_FLAG_NEED_SERVICE = 128


# ============================================================================================ parameters
@dataclass(frozen=True)
class VehicleParams:
    """Physical parameters (SI units). The defaults are plausible for SAM; the navigation logic uses the same
    nominal values (e.g. :func:`steady_surge_speed`)."""

    dt: float = 0.01  # integration step [s]
    mass: float = 15.0  # [kg]
    surge_added_mass: float = 1.5  # [kg]
    heave_added_mass: float = 15.0  # [kg] (broadside: about the displaced water)
    thrust_coeff: float = 1.6e-6  # thrust per propeller = k rpm |rpm| [N/rpm^2]
    drag_linear: float = 2.0  # surge drag c1 u + c2 u|u| [N s/m]
    drag_quadratic: float = 3.0  # [N s^2/m^2]
    heave_drag_linear: float = 5.0  # [N s/m]
    heave_drag_quadratic: float = 50.0  # [N s^2/m^2]
    nozzle_arm: float = 0.7  # the nozzle's distance behind the centre of rotation [m]
    yaw_inertia: float = 5.0  # incl. added inertia [kg m^2]
    pitch_inertia: float = 5.0
    roll_inertia: float = 0.1
    rot_damping: float = 0.3  # yaw/pitch damping d0 + du |u| (+ d2 |w| w) [N m s/rad]
    rot_damping_per_speed: float = 2.5  # [N m s^2/(rad m)]
    rot_damping_quadratic: float = 1.0  # [N m s^2/rad^2]
    roll_damping: float = 0.5
    pitch_righting: float = 2.2  # weight x metacentric height [N m] (moment = -this * sin(pitch))
    roll_righting: float = 2.2
    trim_moment: float = 1.0  # the longitudinal weight at full travel [N m]
    ballast_moment: float = 0.5  # both ballast weights at 90 deg [N m]
    buoyancy_max: float = 6.0  # net buoyancy at 100 % (and -this at 0 %) [N]
    buoyancy_offset: float = 0.0  # a trim error [N] (> 0: light at 50 %)
    max_rpm: float = 2000.0
    rpm_rate: float = 2000.0  # [rpm/s]
    max_vector_angle: float = 0.12  # [rad], both axes
    vector_rate: float = 0.5  # [rad/s]
    percent_rate: float = 10.0  # linear actuators [%/s]
    max_ballast_angle: float = math.pi / 2
    ballast_rate: float = 1.0  # [rad/s]
    battery_capacity_wh: float = 800.0
    hotel_power_w: float = 30.0
    thruster_power_at_max_w: float = 100.0  # per thruster at max_rpm (power ~ rpm^3)


def _thrust(rpm: float, p: VehicleParams) -> float:
    return p.thrust_coeff * rpm * abs(rpm)


def surge_acceleration(u: float, rpm_1: float, rpm_2: float, p: VehicleParams, vertical_rad: float = 0.0,
                       horizontal_rad: float = 0.0) -> float:
    """du/dt [m/s^2] of the surge speed u under the two propellers' thrust (through the nozzle angles).

    >>> surge_acceleration(0.0, 0.0, 0.0, VehicleParams())
    0.0
    """
    thrust = (_thrust(rpm_1, p) + _thrust(rpm_2, p)) * math.cos(vertical_rad) * math.cos(horizontal_rad)
    drag = p.drag_linear * u + p.drag_quadratic * u * abs(u)
    return (thrust - drag) / (p.mass + p.surge_added_mass)


def steady_surge_speed(rpm_1: float, rpm_2: float, p: VehicleParams | None = None) -> float:
    """The surge speed [m/s] at which the drag balances the thrust of the two propellers (the nominal rpm -> speed
    relation; negative for reverse thrust).

    >>> round(steady_surge_speed(2000, 2000), 2), steady_surge_speed(0, 0), round(steady_surge_speed(-500, -500), 3)
    (1.76, 0.0, -0.281)
    """
    p = p or VehicleParams()
    thrust = _thrust(rpm_1, p) + _thrust(rpm_2, p)
    c1, c2 = p.drag_linear, p.drag_quadratic
    u = (-c1 + math.sqrt(c1 * c1 + 4.0 * c2 * abs(thrust))) / (2.0 * c2)
    return math.copysign(u, thrust) if thrust else 0.0


# ============================================================================================ sea floor
@dataclass(frozen=True)
class SeaFloor:
    """The sea floor's depth [m]: flat at ``depth``, or piecewise linear along a horizontal axis through the world
    origin (``profile``: (distance along the axis [m], depth [m]) points, constant beyond the ends; ``axis_yaw``:
    the axis' direction, counter-clockwise from east) - e.g. a shoal that rises under a vehicle heading east.

    >>> SeaFloor.parse("0:20,10:5").depth_at(5.0, 100.0)
    12.5
    >>> SeaFloor(25.0).depth_at(1e3, -1e3)
    25.0
    """

    depth: float = 25.0
    profile: tuple[tuple[float, float], ...] = ()
    axis_yaw: float = 0.0

    def __post_init__(self) -> None:
        depths = [self.depth] + [d for _, d in self.profile]
        if not all(math.isfinite(v) and v > 0.0 for v in depths):
            raise ValueError(f"sea floor depths must be finite and > 0 m, got {depths}")
        s = [s for s, _ in self.profile]
        if not all(math.isfinite(v) for v in s) or s != sorted(s) or len(set(s)) != len(s):
            raise ValueError(f"sea floor profile distances must be finite and strictly increasing, got {s}")

    @classmethod
    def parse(cls, text: str, *, axis_yaw: float = 0.0) -> SeaFloor:
        """``"25"`` (flat) or ``"S:D,S:D,..."`` (a profile of distance:depth points, sorted by distance)."""
        text = text.strip()
        try:
            if ":" not in text:
                return cls(float(text))
            points = tuple(sorted((float(s), float(d)) for s, d in (p.split(":") for p in text.split(","))))
        except ValueError as ex:
            raise ValueError(f"sea floor {text!r}: expected a depth or 'distance:depth,...' ({ex})") from None
        return cls(points[0][1], points, axis_yaw)

    def depth_at(self, x: float, y: float) -> float:
        if not self.profile:
            return self.depth
        s = x * math.cos(self.axis_yaw) + y * math.sin(self.axis_yaw)
        pts = self.profile
        if s <= pts[0][0]:
            return pts[0][1]
        for (s0, d0), (s1, d1) in itertools.pairwise(pts):
            if s <= s1:
                return d0 + (d1 - d0) * (s - s0) / (s1 - s0)
        return pts[-1][1]


# ============================================================================================ state
@dataclass
class Actuators:
    """Actuator positions (or commands): rpm, rad, %, with the contract's signs."""

    rpm_1: float = 0.0
    rpm_2: float = 0.0
    vertical_rad: float = 0.0
    horizontal_rad: float = 0.0
    ballast_1_rad: float = 0.0
    ballast_2_rad: float = 0.0
    longitudinal_weight_pct: float = 50.0
    buoyancy_pct: float = 50.0


ACTUATOR_NAMES = tuple(f.name for f in fields(Actuators))


@dataclass
class TrueState:
    """The true state: position in the sim's world frame (ENU around the GPS origin), depth, attitude, body rates,
    surge u (body x) and heave w (world up, from buoyancy)."""

    x: float = 0.0
    y: float = 0.0
    depth: float = 0.0
    roll: float = 0.0
    pitch: float = 0.0
    yaw: float = 0.0
    u: float = 0.0
    w: float = 0.0
    p: float = 0.0
    q: float = 0.0
    r: float = 0.0
    velocity: Vec3 = (0.0, 0.0, 0.0)  # world ENU [m/s], as moved (after the surface/floor limits)
    accel: Vec3 = (0.0, 0.0, 0.0)  # world ENU [m/s^2]
    battery_soc: float = 0.95  # 0..1
    power_w: float = 0.0
    max_depth: float = 0.0
    at_floor: bool = False
    floor_contacts: int = 0  # steps that ended on the sea floor


def _approach(cur: float, target: float, step: float) -> float:
    return min(cur + step, target) if target >= cur else max(cur - step, target)


class Vehicle:
    """The vehicle model. ``command(rpm_1=..., buoyancy_pct=...)`` sets actuator targets (clamped to the
    mechanical limits; non-finite values are refused and counted); ``advance_to(t)`` integrates in fixed steps."""

    def __init__(self, params: VehicleParams | None = None, *, sea_floor: SeaFloor | None = None, x: float = 0.0,
                 y: float = 0.0, depth: float = 0.0, yaw: float = 0.0, battery_percent: float = 95.0,
                 battery_drain_factor: float = 1.0, battery_health_pct: int = 98,
                 water_current: tuple[float, float] = (0.0, 0.0)) -> None:
        self.params = params or VehicleParams()
        self.sea_floor = sea_floor or SeaFloor()
        for name, v in (("x", x), ("y", y), ("depth", depth), ("yaw", yaw), ("battery_percent", battery_percent),
                        ("battery_drain_factor", battery_drain_factor)):
            if not math.isfinite(v):
                raise ValueError(f"{name} must be finite, got {v}")
        if not 0.0 <= battery_percent <= 100.0:
            raise ValueError(f"battery_percent must be within 0..100, got {battery_percent}")
        if battery_drain_factor < 0.0:
            raise ValueError(f"battery_drain_factor must be >= 0, got {battery_drain_factor}")
        if not 0 <= battery_health_pct <= 100:
            raise ValueError(f"battery_health_pct must be within 0..100, got {battery_health_pct}")
        floor = self.sea_floor.depth_at(x, y)
        if not 0.0 <= depth <= floor:
            raise ValueError(f"start depth {depth} m must be within 0..{floor} m (the sea floor there)")
        self.battery_drain_factor = battery_drain_factor
        self.battery_health_pct = int(battery_health_pct)
        self.water_current = water_current
        self.state = TrueState(x=x, y=y, depth=depth, yaw=yaw, battery_soc=battery_percent / 100.0, max_depth=depth)
        self.actuators = Actuators()
        self.commands = Actuators()
        self.rejected_commands = 0
        self.steps = 0

    @property
    def t(self) -> float:
        """Model time [s] since the start (a whole number of steps)."""
        return self.steps * self.params.dt

    # ---------------------------------------------------------------------------------- inputs
    def command(self, **values: float) -> None:
        """Set actuator targets by :class:`Actuators` field name. Out-of-range values are clamped to the
        mechanical limits; a non-finite value is refused (counted in ``rejected_commands``), the others apply."""
        p = self.params
        limits = {"rpm_1": p.max_rpm, "rpm_2": p.max_rpm, "vertical_rad": p.max_vector_angle,
                  "horizontal_rad": p.max_vector_angle, "ballast_1_rad": p.max_ballast_angle,
                  "ballast_2_rad": p.max_ballast_angle}
        for name, raw in values.items():
            if name not in ACTUATOR_NAMES:
                raise KeyError(f"unknown actuator {name!r}; known: {', '.join(ACTUATOR_NAMES)}")
            v = float(raw)
            if not math.isfinite(v):
                self.rejected_commands += 1
                continue
            lim = limits.get(name)
            v = max(0.0, min(100.0, v)) if lim is None else max(-lim, min(lim, v))
            setattr(self.commands, name, v)

    # ---------------------------------------------------------------------------------- integration
    def advance_to(self, t: float) -> int:
        """Integrate up to the last whole step at or before ``t`` (never backwards); returns the steps taken."""
        target = math.floor(t / self.params.dt + 1e-9)
        n = 0
        while self.steps < target:
            self.step()
            n += 1
        return n

    def step(self) -> None:
        """One fixed step (semi-implicit Euler)."""
        p, s, a, c = self.params, self.state, self.actuators, self.commands
        dt = p.dt
        a.rpm_1 = _approach(a.rpm_1, c.rpm_1, p.rpm_rate * dt)
        a.rpm_2 = _approach(a.rpm_2, c.rpm_2, p.rpm_rate * dt)
        a.vertical_rad = _approach(a.vertical_rad, c.vertical_rad, p.vector_rate * dt)
        a.horizontal_rad = _approach(a.horizontal_rad, c.horizontal_rad, p.vector_rate * dt)
        a.ballast_1_rad = _approach(a.ballast_1_rad, c.ballast_1_rad, p.ballast_rate * dt)
        a.ballast_2_rad = _approach(a.ballast_2_rad, c.ballast_2_rad, p.ballast_rate * dt)
        a.longitudinal_weight_pct = _approach(a.longitudinal_weight_pct, c.longitudinal_weight_pct,
                                              p.percent_rate * dt)
        a.buoyancy_pct = _approach(a.buoyancy_pct, c.buoyancy_pct, p.percent_rate * dt)

        thrust = _thrust(a.rpm_1, p) + _thrust(a.rpm_2, p)
        f_y = -thrust * math.sin(a.horizontal_rad)  # at the stern: pushes the stern to starboard -> nose to port
        f_z = -thrust * math.sin(a.vertical_rad)  # pushes the stern down -> nose up
        speed = abs(s.u)
        damp = p.rot_damping + p.rot_damping_per_speed * speed

        u_dot = surge_acceleration(s.u, a.rpm_1, a.rpm_2, p, a.vertical_rad, a.horizontal_rad)
        yaw_moment = -p.nozzle_arm * f_y - damp * s.r - p.rot_damping_quadratic * s.r * abs(s.r)
        pitch_moment = (p.nozzle_arm * f_z
                        + p.trim_moment * (a.longitudinal_weight_pct - 50.0) / 50.0 * math.cos(s.pitch)
                        - p.pitch_righting * math.sin(s.pitch) * math.cos(s.roll)
                        - damp * s.q - p.rot_damping_quadratic * s.q * abs(s.q))
        roll_moment = (p.ballast_moment * 0.5 * (math.sin(a.ballast_1_rad) + math.sin(a.ballast_2_rad))
                       - p.roll_righting * math.sin(s.roll) * math.cos(s.pitch) - p.roll_damping * s.p)
        buoyancy = p.buoyancy_max * (a.buoyancy_pct - 50.0) / 50.0 + p.buoyancy_offset
        heave_force = (buoyancy + f_z * math.cos(s.pitch) * math.cos(s.roll)
                       - p.heave_drag_linear * s.w - p.heave_drag_quadratic * s.w * abs(s.w))

        s.u += u_dot * dt
        s.r += yaw_moment / p.yaw_inertia * dt
        s.q += pitch_moment / p.pitch_inertia * dt
        s.p += roll_moment / p.roll_inertia * dt
        s.w += heave_force / (p.mass + p.heave_added_mass) * dt

        # Euler-angle kinematics of R = Rz Ry Rx with body rates (p, q, r); the righting moments keep the pitch
        # far from +-90 deg, the clamp only guards the tangent.
        sr, cr = math.sin(s.roll), math.cos(s.roll)
        cp = max(math.cos(s.pitch), 0.05)
        tp = math.sin(s.pitch) / cp
        s.roll += (s.p + (sr * s.q + cr * s.r) * tp) * dt
        s.pitch += (cr * s.q - sr * s.r) * dt
        s.yaw = (s.yaw + (sr * s.q + cr * s.r) / cp * dt + math.pi) % (2.0 * math.pi) - math.pi

        fwd = rotate_body_to_world((s.u, 0.0, 0.0), s.roll, s.pitch, s.yaw)
        vx, vy = fwd[0] + self.water_current[0], fwd[1] + self.water_current[1]
        vz = fwd[2] + s.w
        x0, y0, d0 = s.x, s.y, s.depth
        s.x += vx * dt
        s.y += vy * dt
        s.depth -= vz * dt
        if s.depth <= 0.0:  # the surface: floats there, never above
            s.depth = 0.0
            s.w = min(s.w, 0.0)
        floor = self.sea_floor.depth_at(s.x, s.y)
        s.at_floor = s.depth >= floor
        if s.at_floor:  # the sea floor: resting on it, never below
            s.depth = floor
            s.w = max(s.w, 0.0)
            s.floor_contacts += 1
        v_new = ((s.x - x0) / dt, (s.y - y0) / dt, (d0 - s.depth) / dt)
        s.accel = cast(Vec3, tuple((n - o) / dt for n, o in zip(v_new, s.velocity, strict=True)))
        s.velocity = v_new
        s.max_depth = max(s.max_depth, s.depth)

        rel = (abs(a.rpm_1) / p.max_rpm) ** 3 + (abs(a.rpm_2) / p.max_rpm) ** 3
        s.power_w = p.hotel_power_w + p.thruster_power_at_max_w * rel
        s.battery_soc = max(0.0, s.battery_soc - s.power_w * self.battery_drain_factor * dt
                            / (p.battery_capacity_wh * 3600.0))
        self.steps += 1

    # ---------------------------------------------------------------------------------- truth
    def altitude(self) -> float:
        """True height [m] of the vehicle above the sea floor."""
        return self.sea_floor.depth_at(self.state.x, self.state.y) - self.state.depth

    def truth(self) -> dict[str, Any]:
        """The true state for tests and the truth file (JSON-ready; angles in radians, REP-103)."""
        s = self.state
        return {
            "t": round(self.t, 6), "x": s.x, "y": s.y, "depth": s.depth, "altitude": self.altitude(),
            "sea_floor_depth": self.sea_floor.depth_at(s.x, s.y), "roll": s.roll, "pitch": s.pitch, "yaw": s.yaw,
            "speed": s.u, "vertical_speed": s.velocity[2], "max_depth": s.max_depth,
            "battery_percent": 100.0 * s.battery_soc, "power_w": s.power_w, "at_floor": s.at_floor,
            "floor_contacts": s.floor_contacts, "actuators": asdict(self.actuators), "commands": asdict(self.commands),
        }


# ============================================================================================ sensors
@dataclass(frozen=True)
class SensorNoise:
    """Standard deviations of the sensor noise (SI units; magnetometer in Gauss)."""

    gyro: float = 0.002  # [rad/s]
    gyro_bias: float = 0.0005  # a constant bias per axis, drawn once per seed [rad/s]
    accel: float = 0.02  # [m/s^2]
    mag: float = 0.002  # [G]
    pressure: float = 5.0  # [Pa] (0.5 mm of water)
    altitude: float = 0.05  # [m]
    gps: float = 1.0  # horizontal, per axis [m]


@dataclass(frozen=True)
class ImuReading:
    gyro: Vec3  # body rates [rad/s], FLU
    accel: Vec3  # specific force [m/s^2], FLU: +g on z at rest


@dataclass(frozen=True)
class GpsReading:
    status: int  # 3 = 3D fix, 0 = no fix (GNSSFix STATUS_*)
    lat: float  # [deg] (the last fix's when no fix)
    lon: float
    height_msl: float  # [m]
    ned_velocity: Vec3  # [m/s]
    sats: int
    std_m: float  # horizontal standard deviation [m]


@dataclass(frozen=True)
class BatteryReading:
    soc: float  # state of charge 0..1
    voltage: float  # [V]
    current: float  # [A], negative when discharging
    power_w: float
    temperature_k: float
    remaining_wh: float
    full_wh: float
    health_pct: int
    status_flags: int


class Sensors:
    """The vehicle's sensors: each reads the model's current (true) state and adds noise from its own generator, so
    a sensor's sequence of readings does not depend on how often the others are read."""

    GPS_STATUS_NO_FIX = 0
    GPS_STATUS_3D_FIX = 3

    def __init__(self, vehicle: Vehicle, *, seed: int = 0, noise: SensorNoise | None = None,
                 gps_origin: tuple[float, float] = (59.35, 18.07), gps_fix_max_depth: float = 0.3,
                 altimeter_max_range: float = 30.0, earth_field: Vec3 = EARTH_FIELD_ENU_GA,
                 cells: int = 6) -> None:
        lat0, lon0 = gps_origin
        if not (math.isfinite(lat0) and math.isfinite(lon0) and -85.0 <= lat0 <= 85.0 and -180.0 <= lon0 <= 180.0):
            raise ValueError(f"GPS origin must be a latitude within +-85 and a longitude within +-180, "
                             f"got {gps_origin}")
        self.vehicle = vehicle
        self.seed = seed
        self.noise = noise or SensorNoise()
        self.gps_origin = gps_origin
        self.gps_fix_max_depth = gps_fix_max_depth
        self.altimeter_max_range = altimeter_max_range
        self.earth_field = earth_field
        self.cells = cells
        self._rng = {name: random.Random(f"sam-sim/{seed}/{name}")
                     for name in ("imu", "mag", "pressure", "altitude", "gps", "bias")}
        b = self._rng["bias"]
        self.gyro_bias: Vec3 = (b.gauss(0, self.noise.gyro_bias), b.gauss(0, self.noise.gyro_bias),
                                b.gauss(0, self.noise.gyro_bias))
        self._last_fix = (lat0, lon0)

    def _gauss3(self, rng: random.Random, std: float) -> Vec3:
        return rng.gauss(0.0, std), rng.gauss(0.0, std), rng.gauss(0.0, std)

    def imu(self) -> ImuReading:
        s = self.vehicle.state
        n = self._gauss3(self._rng["imu"], self.noise.gyro)
        gyro = (s.p + self.gyro_bias[0] + n[0], s.q + self.gyro_bias[1] + n[1], s.r + self.gyro_bias[2] + n[2])
        f = rotate_world_to_body((s.accel[0], s.accel[1], s.accel[2] + G), s.roll, s.pitch, s.yaw)
        m = self._gauss3(self._rng["imu"], self.noise.accel)
        return ImuReading(gyro, (f[0] + m[0], f[1] + m[1], f[2] + m[2]))

    def magnetometer(self) -> Vec3:
        """The Earth's field in body axes [Gauss]."""
        s = self.vehicle.state
        b = rotate_world_to_body(self.earth_field, s.roll, s.pitch, s.yaw)
        n = self._gauss3(self._rng["mag"], self.noise.mag)
        return b[0] + n[0], b[1] + n[1], b[2] + n[2]

    def pressure(self) -> float:
        """Absolute pressure [Pa] at the vehicle's depth (sea water)."""
        return pressure_at_depth(self.vehicle.state.depth, P_ATM, RHO_SEAWATER, G) + self._rng["pressure"].gauss(
            0.0, self.noise.pressure)

    def altitude(self) -> float:
        """Range to the sea floor [m]; NaN beyond the altimeter's range (no bottom lock)."""
        true = self.vehicle.altitude()
        noisy = max(0.0, true + self._rng["altitude"].gauss(0.0, self.noise.altitude))
        return noisy if true <= self.altimeter_max_range else math.nan

    def gps(self) -> GpsReading:
        """A fix while the antenna is out of the water (depth below ``gps_fix_max_depth``), else NO_FIX with the last
        fix's position."""
        s, rng = self.vehicle.state, self._rng["gps"]
        if s.depth > self.gps_fix_max_depth:
            lat, lon = self._last_fix
            return GpsReading(self.GPS_STATUS_NO_FIX, lat, lon, 0.0, (0.0, 0.0, 0.0), 0, math.inf)
        e = s.x + rng.gauss(0.0, self.noise.gps)
        n = s.y + rng.gauss(0.0, self.noise.gps)
        lat, lon = latlon_from_local(e, n, *self.gps_origin)
        self._last_fix = (lat, lon)
        vel = (s.velocity[1] + rng.gauss(0, 0.05), s.velocity[0] + rng.gauss(0, 0.05), -s.velocity[2])
        height = max(-0.6, min(0.6, rng.gauss(0.0, 0.2)))  # the antenna floats at sea level
        return GpsReading(self.GPS_STATUS_3D_FIX, lat, lon, height, vel, 9 + rng.randrange(3), self.noise.gps)

    def battery(self) -> BatteryReading:
        v, p = self.vehicle, self.vehicle.params
        soc, power = v.state.battery_soc, v.state.power_w
        voltage = self.cells * (3.4 + 0.8 * soc) - 0.05 * power / (self.cells * 3.7)  # open circuit - I R
        health = v.battery_health_pct
        flags = STATUS_FLAG_IN_USE
        if health < 60:
            flags |= STATUS_FLAG_NEED_SERVICE
        if health < 30:
            flags |= STATUS_FLAG_BAD_BATTERY
        return BatteryReading(soc=soc, voltage=voltage, current=-power / voltage, power_w=power,
                              temperature_k=298.15 + 10.0 * power / (p.hotel_power_w + 2 * p.thruster_power_at_max_w),
                              remaining_wh=soc * p.battery_capacity_wh, full_wh=p.battery_capacity_wh,
                              health_pct=health, status_flags=flags)


def _numbers(values: tuple[float, ...]) -> str:
    return ",".join(f"{v:g}" for v in values)


@dataclass(frozen=True, kw_only=True)
class VehicleOptions:
    """The simulated vehicle's options, defined once: SimulatedVehicle takes them, the simulator's SimConfig and the
    closed loop's LoopOptions extend them, and the command line's options (sam_runtime.cli: `sam-sim`, and `run`,
    which passes them on to its sim) are their fields' flags (sam_runtime.common.cli_fields). Frames: the sim's
    world, ENU metres around gps_origin, yaw counter-clockwise from east, depth positive down."""

    seed: int = field(default=0, metadata=cli_field(
        Flag("--seed", "sensor noise seed (default 0)", type=int), value=lambda a: a.seed))
    sea_floor: SeaFloor = field(default_factory=SeaFloor, metadata=cli_field(
        Flag("--sea-floor", "sea floor depth [m], or a profile of distance:depth points along --sea-floor-axis "
             "(e.g. 0:25,40:25,60:6 rises to 6 m between 40 and 60 m east; default 25)", metavar="DEPTH|S:D,...",
             default=lambda floor: f"{floor.depth:g}"),
        Flag("--sea-floor-axis", "direction of the profile's axis, counter-clockwise from east (default 0: east)",
             metavar="RAD", type=float, default=lambda floor: floor.axis_yaw),
        value=lambda a: SeaFloor.parse(a.sea_floor, axis_yaw=a.sea_floor_axis)))
    start: tuple[float, float, float, float] = field(default=(0.0, 0.0, 0.0, 0.0), metadata=cli_field(
        Flag("--start", "start position [m], depth [m] and yaw [rad] (default 0,0,0,0: at the surface, facing east)",
             metavar="X,Y,DEPTH,YAW", default=_numbers),
        value=lambda a: float_list(a.start, 4, "--start")))  # x, y, depth, yaw
    battery_percent: float = field(default=95.0, metadata=cli_field(
        Flag("--battery-start", "state of charge (default 95)", metavar="PERCENT", type=float),
        value=lambda a: a.battery_start))
    battery_drain_factor: float = field(default=1.0, metadata=cli_field(
        Flag("--battery-drain-factor", "multiplies the power drawn from the battery (default 1; e.g. 300 to drain it "
             "in minutes)", type=float), value=lambda a: a.battery_drain_factor))
    battery_health_pct: int = field(default=98, metadata=cli_field(
        Flag("--battery-health", "state of health; below 60 the BMS flags NEED_SERVICE, below 30 BAD_BATTERY "
             "(default 98)", metavar="PERCENT", type=int), value=lambda a: a.battery_health))
    gps_origin: tuple[float, float] = field(default=(59.35, 18.07), metadata=cli_field(  # KTH, Stockholm
        Flag("--gps-origin", "latitude and longitude of the sim's origin (default 59.35,18.07: KTH, Stockholm)",
             metavar="LAT,LON", default=_numbers),
        value=lambda a: float_list(a.gps_origin, 2, "--gps-origin")))
    params: VehicleParams = field(default_factory=VehicleParams)
    noise: SensorNoise = field(default_factory=SensorNoise)


class SimulatedVehicle:
    """A vehicle and its sensors, built from its options (what the simulator and the in-process tests use):
    ``SimulatedVehicle(options)``, or the options' fields by keyword (``SimulatedVehicle(seed=3)``)."""

    def __init__(self, options: VehicleOptions | None = None, /, **fields: Any) -> None:
        self.options = o = replace(options, **fields) if options is not None else VehicleOptions(**fields)
        x, y, depth, yaw = o.start
        self.vehicle = Vehicle(o.params, sea_floor=o.sea_floor, x=x, y=y, depth=depth, yaw=yaw,
                               battery_percent=o.battery_percent, battery_drain_factor=o.battery_drain_factor,
                               battery_health_pct=o.battery_health_pct)
        self.sensors = Sensors(self.vehicle, seed=o.seed, noise=o.noise, gps_origin=o.gps_origin)
