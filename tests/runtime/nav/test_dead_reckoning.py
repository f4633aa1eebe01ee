"""Dead reckoning (runtime/nav/dead_reckoning.py) on the simulated vehicle: its noisy sensors at their nominal
rates (IMU and magnetometer values rounded to float16 as on the bus), the vehicle driven open loop through dives
and turns, the estimate against the true state."""

from __future__ import annotations

import math
import struct
from dataclasses import dataclass

import pytest

from sam_runtime.nav.dead_reckoning import DeadReckoning
from sam_runtime.physics.geo import euler_from_quaternion, pressure_at_depth, wrap_angle
from sam_runtime.physics.vehicle import SeaFloor, SimulatedVehicle, VehicleParams


def _f16(v: float) -> float:
    return struct.unpack("<e", struct.pack("<e", v))[0]


@dataclass
class Errors:
    final: float  # horizontal position [m]
    worst: float
    distance: float  # travelled [m]
    depth: float  # worst
    yaw: float  # worst after the start [rad]
    tilt: float  # worst roll/pitch [rad]


# Open loop: dive while driving, turn both ways, speed changes, a trim change.
SEQUENCE = {
    2.0: {"rpm_1": 1500, "rpm_2": 1500, "buoyancy_pct": 35.0},
    10.0: {"horizontal_rad": 0.08, "vertical_rad": -0.05},
    25.0: {"horizontal_rad": -0.1, "vertical_rad": 0.03, "buoyancy_pct": 50.0},
    40.0: {"horizontal_rad": 0.0, "rpm_1": 2000, "rpm_2": 2000, "longitudinal_weight_pct": 60.0},
    50.0: {"rpm_1": 800, "rpm_2": 800, "horizontal_rad": 0.12},
}


def _drive(params: VehicleParams | None = None, seed: int = 0, seconds: float = 60.0) -> Errors:
    sim = SimulatedVehicle(seed=seed, sea_floor=SeaFloor(40.0), start=(3.0, -2.0, 0.0, 0.7),
                           params=params or VehicleParams())
    v, s, dr = sim.vehicle, sim.sensors, DeadReckoning()  # DR: the nominal parameters
    x0, y0 = v.state.x, v.state.y
    worst = depth_err = yaw_err = tilt_err = distance = 0.0
    px, py = x0, y0
    for k in range(round(seconds * 100) + 1):
        t = k / 100
        if round(t, 2) in SEQUENCE:
            v.command(**SEQUENCE[round(t, 2)])
        v.advance_to(t)
        m = s.imu()
        dr.on_imu(t, tuple(map(_f16, m.gyro)), tuple(map(_f16, m.accel)))  # 100 Hz
        if k % 2 == 0:  # 50 Hz
            dr.on_magnetometer(t, tuple(map(_f16, s.magnetometer())))
        if k % 5 == 0:  # 20 Hz
            dr.on_pressure(t, s.pressure())
        if k % 10 == 0:  # 10 Hz, integer rpm
            dr.on_thruster_rpm(t, 0, round(v.actuators.rpm_1))
            dr.on_thruster_rpm(t, 1, round(v.actuators.rpm_2))
        distance += math.hypot(v.state.x - px, v.state.y - py)
        px, py = v.state.x, v.state.y
        if k % 5 == 0:  # published at 20 Hz
            p = dr.pose(t)
            assert p is not None
            st = v.state
            worst = max(worst, math.hypot(p.x - (st.x - x0), p.y - (st.y - y0)))
            depth_err = max(depth_err, abs(-p.z - st.depth))
            if t > 1.0:
                yaw_err = max(yaw_err, abs(wrap_angle(p.yaw - st.yaw)))
            tilt_err = max(tilt_err, abs(p.roll - st.roll), abs(p.pitch - st.pitch))
    p = dr.pose(seconds)
    assert p is not None
    final = math.hypot(p.x - (v.state.x - x0), p.y - (v.state.y - y0))
    return Errors(final, worst, distance, depth_err, yaw_err, tilt_err)


@pytest.mark.parametrize("seed", [0, 5])
def test_dead_reckoning_on_the_vehicle_model_stays_within_a_metre_over_a_minute(seed: int) -> None:
    e = _drive(seed=seed)
    print(f"\nDR seed {seed}: {e}")
    assert e.distance > 60.0
    assert e.worst < 1.0  # about 1.5 % of the distance travelled
    assert e.depth < 0.01 and e.yaw < math.radians(2.0) and e.tilt < math.radians(1.5)


def test_a_model_mismatch_shows_as_a_proportional_drift() -> None:
    """The true vehicle has 10 % more drag than the nominal model the estimator uses: a drift of a few percent of
    the distance, not more."""
    e = _drive(VehicleParams(drag_linear=2.2, drag_quadratic=3.3))
    print(f"\nDR with 10 % more drag: {e}")
    assert 0.01 * e.distance < e.final < 0.08 * e.distance


def test_ready_only_once_attitude_heading_and_depth_are_measured() -> None:
    dr = DeadReckoning()
    assert dr.pose(0.0) is None
    dr.on_imu(0.0, (0.0, 0.0, 0.0), (0.0, 0.0, 9.81))
    dr.on_magnetometer(0.01, (0.0, 0.15, -0.49))  # facing east
    assert dr.pose(0.02) is None and not dr.ready
    dr.on_pressure(0.03, pressure_at_depth(4.0))
    p = dr.pose(0.04)
    assert p is not None and p.translation == pytest.approx((0.0, 0.0, -4.0)) and p.yaw == pytest.approx(0.0)
    assert euler_from_quaternion(p.rotation) == pytest.approx((0.0, 0.0, 0.0), abs=1e-9)


def test_heading_and_tilt_conventions() -> None:
    dr = DeadReckoning()
    # Facing north (ENU yaw +90 deg), nose 10 deg down: gravity's reaction leans back, the field levels to north.
    pitch = math.radians(10)
    dr.on_imu(0.0, (0.0, 0.0, 0.0), (-9.80665 * math.sin(pitch), 0.0, 9.80665 * math.cos(pitch)))
    field = (0.15 * math.cos(pitch) + 0.49 * math.sin(pitch), 0.0, 0.15 * math.sin(pitch) - 0.49 * math.cos(pitch))
    dr.on_magnetometer(0.0, field)
    dr.on_pressure(0.0, pressure_at_depth(1.0))
    p = dr.pose(0.0)
    assert p is not None
    assert p.pitch == pytest.approx(pitch, abs=1e-9) and p.yaw == pytest.approx(math.pi / 2, abs=1e-9)


def test_non_finite_readings_are_refused_and_counted() -> None:
    dr = DeadReckoning()
    assert not dr.on_imu(0.0, (math.nan, 0.0, 0.0), (0.0, 0.0, 9.8))
    assert not dr.on_magnetometer(0.0, (0.0, math.inf, 0.0))
    assert not dr.on_pressure(0.0, math.nan)
    assert not dr.on_pressure(0.0, -1.0)
    assert not dr.on_thruster_rpm(0.0, 0, math.nan)
    assert not dr.on_magnetometer(0.0, (0.0, 0.0, -0.5))  # straight down: no heading
    assert sum(v for k, v in dr.counts.items() if k.startswith("refused.")) == 6 and not dr.ready
    with pytest.raises(ValueError, match="thruster index must be 0 or 1"):
        dr.on_thruster_rpm(0.0, 2, 100.0)


def test_speed_from_the_feedback_rpm_and_stale_feedback_counts_as_stopped() -> None:
    dr = DeadReckoning()
    dr.on_imu(0.0, (0.0, 0.0, 0.0), (0.0, 0.0, 9.80665))
    dr.on_magnetometer(0.0, (0.0, 0.15, -0.49))
    dr.on_pressure(0.0, pressure_at_depth(0.0))
    for k in range(301):  # 30 s of 2000 rpm at 10 Hz
        dr.on_thruster_rpm(k * 0.1, 0, 2000)
        dr.on_thruster_rpm(k * 0.1, 1, 2000)
    p = dr.pose(30.0)
    assert p is not None and p.speed == pytest.approx(1.76, abs=0.01) and p.x > 45.0 and abs(p.y) < 1e-9
    for k in range(1, 601):  # no feedback for 30 s (poses at 20 Hz): the thrusters count as stopped
        p = dr.pose(30.0 + k * 0.05)
    assert p is not None and p.speed < 0.05  # coasted to rest
    x = p.x
    p = dr.pose(1000.0)  # a jump of the clock: at most max_gap (1 s) is integrated
    assert p is not None and p.t == 1000.0 and p.x - x < 0.05


def test_a_lost_imu_does_not_spin_the_estimate_and_input_ages_show_it() -> None:
    dr = DeadReckoning()
    dr.on_imu(0.0, (0.0, 0.0, 0.5), (0.0, 0.0, 9.80665))  # turning at 0.5 rad/s when the IMU goes silent
    dr.on_magnetometer(0.0, (0.0, 0.15, -0.49))
    dr.on_pressure(0.0, pressure_at_depth(2.0))
    for k in range(1, 41):
        p = dr.pose(k * 0.05)
    assert p is not None and 0.2 < p.yaw < 0.3  # integrated for imu_timeout (0.5 s), then held
    ages = dr.input_ages(2.0)
    assert ages["imu"] == ages["mag"] == ages["pressure"] == 2.0
    assert ages["thruster_1"] is None and ages["thruster_2"] is None
