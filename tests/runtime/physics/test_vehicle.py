"""The simulated vehicle (runtime/physics/vehicle.py): magnitudes plausible for SAM, the contract's signs, hard limits
at the surface and the sea floor, finite actuator rates, determinism for a seed, and the sensor models."""

from __future__ import annotations

import math

import pytest

from sam_runtime.physics.geo import local_from_latlon
from sam_runtime.physics.vehicle import (
    SeaFloor,
    Sensors,
    SimulatedVehicle,
    Vehicle,
    VehicleParams,
    steady_surge_speed,
)


def _run(v: Vehicle, seconds: float, **commands: float) -> Vehicle:
    v.command(**commands)
    v.advance_to(v.t + seconds)
    return v


def test_top_speed_at_max_rpm_is_plausible_and_matches_the_nominal_relation() -> None:
    v = _run(Vehicle(), 30.0, rpm_1=2000, rpm_2=2000)
    assert 1.5 <= v.state.u <= 2.0
    assert v.state.u == pytest.approx(steady_surge_speed(2000, 2000), rel=1e-3)
    assert v.state.depth == 0.0 and abs(v.state.y) < 1e-9 and v.state.x > 30.0  # straight east at the surface
    assert steady_surge_speed(1000, 1000) == pytest.approx(_run(Vehicle(), 40.0, rpm_1=1000, rpm_2=1000).state.u,
                                                           rel=1e-3)
    slow = _run(Vehicle(), 10.0, rpm_1=-1000, rpm_2=-1000)
    assert slow.state.u < 0.0 and slow.state.x < 0.0  # reverse thrust backs up


def test_buoyancy_sinks_and_rises_at_a_few_tenths_of_a_metre_per_second() -> None:
    v = Vehicle(sea_floor=SeaFloor(100.0))
    _run(v, 30.0, buoyancy_pct=0.0)
    sink_rate = -v.state.velocity[2]
    assert 0.1 <= sink_rate <= 0.5 and v.state.depth > 4.0
    depth = v.state.depth
    _run(v, 30.0, buoyancy_pct=100.0)
    assert 0.1 <= v.state.velocity[2] <= 0.5 and v.state.depth < depth
    _run(v, 60.0)
    assert v.state.depth == 0.0 and v.state.max_depth >= depth  # floats, never above (the piston takes 10 s)
    neutral = _run(Vehicle(depth=5.0), 60.0)
    assert neutral.state.depth == pytest.approx(5.0, abs=1e-9)  # 50 %: neutral


def test_signs_of_the_contract() -> None:
    port = _run(Vehicle(), 10.0, rpm_1=1500, rpm_2=1500, horizontal_rad=0.1)
    assert port.state.r > 0.05 and port.state.yaw > 0.2 and port.state.y > 0.0  # to port: counter-clockwise
    up = _run(Vehicle(depth=10.0, sea_floor=SeaFloor(100.0)), 5.0, rpm_1=1500, rpm_2=1500, vertical_rad=0.1)
    assert up.state.pitch < -0.1 and up.state.depth < 10.0  # nose up (REP-103 pitch < 0) and climbs
    down = _run(Vehicle(depth=10.0, sea_floor=SeaFloor(100.0)), 5.0, rpm_1=1500, rpm_2=1500, vertical_rad=-0.1)
    assert down.state.pitch > 0.1 and down.state.depth > 10.0
    trim = _run(Vehicle(depth=10.0), 30.0, longitudinal_weight_pct=100.0)
    assert 0.2 < trim.state.pitch < 0.6  # weight forward: nose down, held by the righting moment
    trim_aft = _run(Vehicle(depth=10.0), 30.0, longitudinal_weight_pct=0.0)
    assert trim_aft.state.pitch == pytest.approx(-trim.state.pitch, abs=1e-6)
    roll = _run(Vehicle(depth=10.0), 30.0, ballast_1_rad=1.0, ballast_2_rad=1.0)
    assert 0.05 < roll.state.roll < 0.4  # strong righting: a few degrees to starboard


def test_a_turn_has_a_plausible_radius_and_steers_a_little_at_low_speed() -> None:
    v = _run(Vehicle(), 60.0, rpm_1=2000, rpm_2=2000, horizontal_rad=0.12)
    radius = v.state.u / v.state.r
    assert 4.0 < radius < 20.0
    slow = _run(Vehicle(), 60.0, rpm_1=300, rpm_2=300, horizontal_rad=0.12)
    assert 0.005 < slow.state.r < v.state.r


def test_actuators_move_at_finite_rates_and_are_clamped() -> None:
    v = Vehicle()
    v.command(rpm_1=5000, rpm_2=-1000, vertical_rad=-1.0, horizontal_rad=0.3, longitudinal_weight_pct=150.0,
              buoyancy_pct=-10.0, ballast_1_rad=3.0)
    assert (v.commands.rpm_1, v.commands.vertical_rad, v.commands.horizontal_rad) == (2000.0, -0.12, 0.12)
    assert (v.commands.longitudinal_weight_pct, v.commands.buoyancy_pct) == (100.0, 0.0)
    v.advance_to(0.5)
    a = v.actuators
    assert a.rpm_1 == pytest.approx(1000.0) and a.rpm_2 == pytest.approx(-1000.0)  # 2000 rpm/s
    assert a.vertical_rad == pytest.approx(-0.12) and a.horizontal_rad == pytest.approx(0.12)  # 0.5 rad/s
    assert a.longitudinal_weight_pct == pytest.approx(55.0) and a.buoyancy_pct == pytest.approx(45.0)  # 10 %/s
    v.command(rpm_1=math.nan, buoyancy_pct=math.inf, rpm_2=0.0)
    assert v.rejected_commands == 2 and v.commands.rpm_1 == 2000.0 and v.commands.rpm_2 == 0.0
    with pytest.raises(KeyError, match="unknown actuator 'rudder'"):
        v.command(rudder=1.0)


def test_never_below_the_sea_floor_flat_or_a_shoal() -> None:
    v = _run(Vehicle(sea_floor=SeaFloor(8.0)), 120.0, buoyancy_pct=0.0)
    assert v.state.depth == 8.0 and v.state.at_floor and v.state.floor_contacts > 0 and v.altitude() == 0.0
    shoal = SeaFloor.parse("0:20,30:20,60:4")
    v = Vehicle(sea_floor=shoal, depth=12.0)
    v.command(rpm_1=1500, rpm_2=1500)
    lowest_altitude = math.inf
    for _ in range(800):  # 80 s east over the shoal
        v.advance_to(v.t + 0.1)
        lowest_altitude = min(lowest_altitude, v.altitude())
        assert v.state.depth <= shoal.depth_at(v.state.x, v.state.y) + 1e-9
    assert lowest_altitude == 0.0 and v.state.x > 60.0 and v.state.depth <= 4.0


def test_fixed_steps_make_the_trajectory_independent_of_the_callers_timing() -> None:
    def drive(chunks: list[float]) -> dict:
        v = Vehicle(sea_floor=SeaFloor(50.0))
        v.command(rpm_1=1800, rpm_2=1700, horizontal_rad=0.05, buoyancy_pct=30.0)
        t = 0.0
        for c in chunks:
            t += c
            v.advance_to(t)
        return v.truth()

    a = drive([20.0])
    b = drive([0.013] * 1538 + [0.006])  # 20.0 s in uneven pieces
    assert a == b and a["t"] == 20.0


def test_same_seed_same_run_other_seed_other_noise_same_trajectory() -> None:
    def run(seed: int) -> tuple[list, list]:
        sim = SimulatedVehicle(seed=seed, sea_floor=SeaFloor(30.0))
        readings, truths = [], []
        for k in range(300):
            if k == 50:
                sim.vehicle.command(rpm_1=1500, rpm_2=1500, buoyancy_pct=20.0, horizontal_rad=0.05)
            sim.vehicle.advance_to(k * 0.1)
            s = sim.sensors
            readings.append((s.imu(), s.magnetometer(), s.pressure(), s.altitude(), s.gps(), s.battery()))
            truths.append(sim.vehicle.truth())
        return readings, truths

    r1, t1 = run(11)
    r2, t2 = run(11)
    r3, t3 = run(12)
    assert r1 == r2 and t1 == t2
    assert t3 == t1 and r3 != r1  # noise does not move the vehicle


def test_sensors_measure_the_true_state() -> None:
    sim = SimulatedVehicle(seed=1, sea_floor=SeaFloor(20.0), start=(0.0, 0.0, 0.0, math.pi / 2))  # facing north
    s: Sensors = sim.sensors
    imu = s.imu()
    assert imu.accel[2] == pytest.approx(9.80665, abs=0.1) and max(map(abs, imu.accel[:2])) < 0.1
    assert max(map(abs, imu.gyro)) < 0.01
    mag = s.magnetometer()
    assert mag[0] == pytest.approx(0.15, abs=0.01) and abs(mag[1]) < 0.01 and mag[2] == pytest.approx(-0.49, abs=0.01)
    assert s.pressure() == pytest.approx(101325.0, abs=25)
    assert s.altitude() == pytest.approx(20.0, abs=0.3)
    fix = s.gps()
    assert fix.status == 3 and math.hypot(*local_from_latlon(fix.lat, fix.lon, 59.35, 18.07)) < 5.0
    # Nose down on the trim weight: the specific force leans back (-g sin(pitch) on x).
    sim.vehicle.command(longitudinal_weight_pct=100.0, buoyancy_pct=0.0)
    sim.vehicle.advance_to(30.0)
    st = sim.vehicle.state
    imu = s.imu()
    assert imu.accel[0] == pytest.approx(-9.80665 * math.sin(st.pitch), abs=0.1)
    assert s.pressure() == pytest.approx(101325.0 + 1025 * 9.80665 * st.depth, abs=25)
    assert s.gps().status == 0  # no fix under water
    deep = SimulatedVehicle(sea_floor=SeaFloor(60.0))
    assert math.isnan(deep.sensors.altitude())  # beyond the altimeter's 30 m


def test_battery_drains_with_thruster_power_and_reports_health() -> None:
    idle = _run(Vehicle(battery_percent=50.0, battery_drain_factor=10.0), 60.0)
    busy = _run(Vehicle(battery_percent=50.0, battery_drain_factor=10.0), 60.0, rpm_1=2000, rpm_2=2000)
    assert 0.0 < 50.0 - 100 * idle.state.battery_soc < 50.0 - 100 * busy.state.battery_soc
    # 10 x 230 W (hotel and both thrusters at full power) for a minute, from 800 Wh: 4.8 %.
    assert 100 * busy.state.battery_soc == pytest.approx(50.0 - 10 * 230 * 60 / 3600 / 800 * 100, abs=0.2)
    assert 100 * idle.state.battery_soc == pytest.approx(50.0 - 10 * 30 * 60 / 3600 / 800 * 100, abs=0.01)
    sick = SimulatedVehicle(battery_health_pct=25)
    b = sick.sensors.battery()
    assert b.health_pct == 25 and b.status_flags & 64 and b.status_flags & 128 and b.current <= 0.0
    assert SimulatedVehicle().sensors.battery().status_flags == 1  # in use, healthy


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"depth": 30.0}, "start depth 30.0 m must be within 0..25.0 m"),
    ({"depth": -1.0}, "start depth -1.0 m"),
    ({"x": math.nan}, "x must be finite"),
    ({"battery_percent": 120.0}, "battery_percent must be within 0..100"),
    ({"battery_drain_factor": -1.0}, "battery_drain_factor must be >= 0"),
])
def test_bad_vehicle_options_are_refused_with_a_reason(kwargs: dict, message: str) -> None:
    with pytest.raises(ValueError, match=message.replace(".", r"\.").replace("(", r"\(")):
        Vehicle(**kwargs)


@pytest.mark.parametrize(("text", "message"), [
    ("deep", "expected a depth or 'distance:depth,...'"),
    ("0:20,x:5", "expected a depth"),
    ("-3", "must be finite and > 0"),
    ("0:20,10:0", "must be finite and > 0"),
    ("0:20,0:5", "strictly increasing"),
])
def test_bad_sea_floors_are_refused_with_a_reason(text: str, message: str) -> None:
    with pytest.raises(ValueError, match=message.replace(".", r"\.")):
        SeaFloor.parse(text)


def test_parameters_are_a_plain_frozen_record() -> None:
    p = VehicleParams()
    with pytest.raises(AttributeError):
        p.mass = 1.0  # type: ignore[misc]
    assert steady_surge_speed(2000, 2000, VehicleParams(drag_quadratic=6.0)) < steady_surge_speed(2000, 2000, p)
