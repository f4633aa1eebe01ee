"""Dead reckoning (document IV.E.1): the pose odom -> base_link from the IMU, the magnetometer, the pressure sensor
and the thrusters' feedback.

- Attitude: the gyro rates integrated (Euler-angle kinematics), pulled toward the accelerometer's gravity for roll
  and pitch (a complementary filter). The vehicle's own acceleration is removed from the specific force first,
  from the estimated surge and the measured rates, so turns and speed changes do not tilt the estimate; readings
  whose norm is far from g are not trusted at all.
- Heading: the magnetometer levelled with the estimated roll and pitch gives the world ENU yaw (the Earth field's
  horizontal part points north, :data:`~sam_runtime.physics.vehicle.EARTH_FIELD_ENU_GA`); the gyro-integrated
  yaw is pulled toward it.
- Depth: from the pressure, d = (p - p_atm) / (rho g) with sea water; odom z = -d.
- Speed: the surge ODE of the vehicle's nominal parameters driven by the feedback RPMs (at steady state the same
  rpm -> speed relation as :func:`sam_runtime.physics.vehicle.steady_surge_speed`).
- Position: the surge along the estimated attitude, integrated in odom (ENU, origin where the estimator started).

Times are seconds from any clock, passed in; readings older than the last processed time are used with a zero
step (never integrated backwards). Non-finite readings are refused and counted.
"""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass, field

from sam_runtime.physics.geo import (
    P_ATM,
    RHO_SEAWATER,
    G,
    Vec3,
    depth_from_pressure,
    quaternion_from_euler,
    rotate_body_to_world,
    wrap_angle,
)
from sam_runtime.physics.vehicle import VehicleParams, surge_acceleration

__all__ = ["DeadReckoning", "DeadReckoningConfig", "DrPose"]


@dataclass(frozen=True)
class DeadReckoningConfig:
    """Gains are correction rates [1/s] of the complementary filters (the inverse of their time constants)."""

    attitude_gain: float = 0.5  # roll/pitch toward the accelerometer
    heading_gain: float = 0.5  # yaw toward the magnetometer
    accel_trust_band: float = 1.0  # ignore specific forces whose norm differs from g by more [m/s^2]
    max_step: float = 0.05  # integration sub-step [s]
    max_gap: float = 1.0  # a longer gap between two updates is integrated as this long (a stalled clock)
    feedback_timeout: float = 1.0  # thruster feedback older than this counts as 0 rpm [s]
    imu_timeout: float = 0.5  # gyro rates older than this count as 0 (a lost IMU does not spin the estimate) [s]
    p_atm: float = P_ATM
    rho: float = RHO_SEAWATER
    vehicle: VehicleParams = field(default_factory=VehicleParams)  # nominal: the speed model


@dataclass(frozen=True)
class DrPose:
    """The pose of base_link in odom at time ``t``: translation (x, y, z = -depth) and rotation (x, y, z, w)."""

    t: float
    x: float
    y: float
    z: float
    roll: float
    pitch: float
    yaw: float
    speed: float  # estimated surge [m/s]

    @property
    def translation(self) -> Vec3:
        return self.x, self.y, self.z

    @property
    def rotation(self) -> tuple[float, float, float, float]:
        return quaternion_from_euler(self.roll, self.pitch, self.yaw)


def _finite(*values: float) -> bool:
    return all(math.isfinite(v) for v in values)


class DeadReckoning:
    """Feed it with ``on_imu``, ``on_magnetometer``, ``on_pressure`` and ``on_thruster_rpm``; ``pose(t)`` gives the
    pose once the attitude, heading and depth have each been measured at least once (``ready``)."""

    def __init__(self, config: DeadReckoningConfig | None = None) -> None:
        self.config = config or DeadReckoningConfig()
        self.t: float | None = None  # time up to which the state is integrated
        self.x = self.y = 0.0
        self.depth: float | None = None
        self.roll = self.pitch = self.yaw = 0.0
        self.u = 0.0
        self.rates: Vec3 = (0.0, 0.0, 0.0)
        self._have_tilt = self._have_heading = False
        self._rpm: list[tuple[float, float]] = [(0.0, -math.inf), (0.0, -math.inf)]  # (rpm, time) per thruster
        self.counts: Counter[str] = Counter()  # processed readings per input and refusals per reason
        self._prev: dict[str, float] = {}  # time of the previous reading per filter input

    @property
    def ready(self) -> bool:
        return self._have_tilt and self._have_heading and self.depth is not None

    # ---------------------------------------------------------------------------------- propagation
    def _rpm_at(self, index: int, t: float) -> float:
        rpm, stamp = self._rpm[index]
        return rpm if t - stamp <= self.config.feedback_timeout else 0.0

    def advance(self, t: float) -> None:
        """Integrate speed, attitude (gyro) and position up to ``t``."""
        if self.t is None:
            self.t = t
            return
        gap = t - self.t
        if gap <= 0.0:
            return
        span = min(gap, self.config.max_gap)
        n = max(1, math.ceil(span / self.config.max_step))
        h = span / n
        imu_t = self._prev.get("imu", -math.inf)
        for i in range(n):
            tk = self.t + i * h
            p, q, r = self.rates if tk - imu_t <= self.config.imu_timeout else (0.0, 0.0, 0.0)
            rpm_1, rpm_2 = self._rpm_at(0, tk), self._rpm_at(1, tk)
            self.u += surge_acceleration(self.u, rpm_1, rpm_2, self.config.vehicle) * h
            sr, cr = math.sin(self.roll), math.cos(self.roll)
            cp = max(math.cos(self.pitch), 0.05)
            self.roll += (p + (sr * q + cr * r) * math.sin(self.pitch) / cp) * h
            self.pitch += (cr * q - sr * r) * h
            self.yaw = wrap_angle(self.yaw + (sr * q + cr * r) / cp * h)
            fwd = rotate_body_to_world((self.u, 0.0, 0.0), self.roll, self.pitch, self.yaw)
            self.x += fwd[0] * h
            self.y += fwd[1] * h
        self.t = t

    # ---------------------------------------------------------------------------------- inputs
    def _refuse(self, what: str) -> None:
        self.counts[f"refused.{what}"] += 1

    def on_imu(self, t: float, gyro: Vec3, accel: Vec3) -> bool:
        """Body rates [rad/s] and specific force [m/s^2], FLU (REP-145: +g on z at rest)."""
        if not _finite(t, *gyro, *accel):
            self._refuse("imu_not_finite")
            return False
        self.advance(t)
        dt = self._last_dt("imu", t)
        self.rates = (float(gyro[0]), float(gyro[1]), float(gyro[2]))
        # Gravity = specific force minus the vehicle's own acceleration (surge change, and the centripetal terms
        # of moving forward at u while rotating: w x (u, 0, 0) = (0, r u, -q u)).
        u_dot = surge_acceleration(self.u, self._rpm_at(0, t), self._rpm_at(1, t), self.config.vehicle)
        gx = accel[0] - u_dot
        gy = accel[1] - self.rates[2] * self.u
        gz = accel[2] + self.rates[1] * self.u
        norm = math.sqrt(gx * gx + gy * gy + gz * gz)
        if abs(norm - G) <= self.config.accel_trust_band:
            roll_m = math.atan2(gy, gz)
            pitch_m = math.atan2(-gx, math.sqrt(gy * gy + gz * gz))
            if not self._have_tilt:
                self.roll, self.pitch, self._have_tilt = roll_m, pitch_m, True
            else:
                k = min(1.0, self.config.attitude_gain * dt)
                self.roll += k * wrap_angle(roll_m - self.roll)
                self.pitch += k * wrap_angle(pitch_m - self.pitch)
        else:
            self.counts["accel_untrusted"] += 1
        self.counts["imu"] += 1
        return True

    def on_magnetometer(self, t: float, field_body: Vec3) -> bool:
        """The magnetic field in body axes (any unit: only its direction is used)."""
        if not _finite(t, *field_body):
            self._refuse("magnetometer_not_finite")
            return False
        self.advance(t)
        # Level the measurement: Ry(pitch) Rx(roll) m_body = Rz(yaw)^T m_world = (B_n sin yaw, B_n cos yaw, ...).
        mx, my, mz = field_body
        cr, sr = math.cos(self.roll), math.sin(self.roll)
        cp, sp = math.cos(self.pitch), math.sin(self.pitch)
        y1 = cr * my - sr * mz
        z1 = sr * my + cr * mz
        lx = cp * mx + sp * z1
        ly = y1
        if math.hypot(lx, ly) < 1e-9:
            self._refuse("magnetometer_vertical")
            return False
        yaw_m = math.atan2(lx, ly)
        dt = self._last_dt("mag", t)
        if not self._have_heading:
            self.yaw, self._have_heading = yaw_m, True
        else:
            k = min(1.0, self.config.heading_gain * dt)
            self.yaw = wrap_angle(self.yaw + k * wrap_angle(yaw_m - self.yaw))
        self.counts["magnetometer"] += 1
        return True

    def on_pressure(self, t: float, pressure_pa: float) -> bool:
        """Absolute pressure [Pa]."""
        if not _finite(t, pressure_pa) or pressure_pa <= 0.0:
            self._refuse("pressure_invalid")
            return False
        self.advance(t)
        self.depth = max(0.0, depth_from_pressure(pressure_pa, self.config.p_atm, self.config.rho))
        self._prev["pressure"] = t
        self.counts["pressure"] += 1
        return True

    def on_thruster_rpm(self, t: float, index: int, rpm: float) -> bool:
        """Measured speed [rpm] of thruster ``index`` (0 or 1; positive = forward thrust)."""
        if index not in (0, 1):
            raise ValueError(f"thruster index must be 0 or 1, got {index}")
        if not _finite(t, rpm):
            self._refuse("rpm_not_finite")
            return False
        self.advance(t)
        self._rpm[index] = (float(rpm), t)
        self.counts["thruster_rpm"] += 1
        return True

    def _last_dt(self, key: str, t: float) -> float:
        """Seconds since the previous reading of ``key`` (its filter's own step), bounded."""
        prev = self._prev.get(key)
        self._prev[key] = t
        return 0.0 if prev is None else min(max(t - prev, 0.0), self.config.max_gap)

    def input_ages(self, t: float) -> dict[str, float | None]:
        """Seconds since the last accepted reading of each input at ``t`` (None: never), for diagnostics."""
        ages: dict[str, float | None] = {k: None if k not in self._prev else t - self._prev[k]
                                         for k in ("imu", "mag", "pressure")}
        for i, (_, stamp) in enumerate(self._rpm):
            ages[f"thruster_{i + 1}"] = None if stamp == -math.inf else t - stamp
        return ages

    # ---------------------------------------------------------------------------------- output
    def pose(self, t: float | None = None) -> DrPose | None:
        """The pose at ``t`` (integrated up to it; default: the last update's time), or None until ready."""
        if t is not None:
            self.advance(t)
        if not self.ready or self.t is None or self.depth is None:
            return None
        return DrPose(self.t, self.x, self.y, -self.depth, self.roll, self.pitch, self.yaw, self.u)
