"""The simulated devices (runtime/sim/simulator.py): one Cyphal node per device of the spec, plausible changing values
at the nominal rates, actuators that accept only the bridge's commands and move at a finite rate; the SAM devices
measure one shared vehicle that their actuators drive.

The network tests run over python-can ``virtual`` CAN FD in this process (a channel name per test), so they
cannot see, or be seen by, any other run on the machine.
"""

from __future__ import annotations

import asyncio
import itertools
import json
import math
import os
import subprocess
import sys
import time
from collections import Counter, defaultdict
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("pycyphal")
pytest.importorskip("can")

from helpers.runtime_support import generated_or_skip
from helpers.settling import until_stable

from sam_runtime.physics.vehicle import SeaFloor, SimulatedVehicle
from sam_runtime.sim.simulator import (
    PHYSICS,
    DeviceState,
    SimConfig,
    Simulator,
    VehicleState,
    generic_fill,
    physics_key,
)

# pycyphal.dsdl.to_builtin/serialize call a pydsdl API that pydsdl 1.25 deprecates: noise only.
pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning:pydsdl")


def _run(coro: Any, timeout: float = 30.0) -> Any:
    async def bounded() -> Any:
        async with asyncio.timeout(timeout):
            return await coro

    return asyncio.run(bounded())


def test_physics_key() -> None:
    assert physics_key("sam.sensor.RawIMU.0.1") == "sensor.RawIMU"
    assert physics_key("rover.power.BatteryInfo.1.0") == "power.BatteryInfo"
    assert physics_key("x.Y") == "Y"


def test_actuator_moves_toward_its_command_at_a_finite_rate() -> None:
    dev = DeviceState("w", 25)
    assert dev.approach("percent", 80.0, 10.0, t=0.0, initial=50.0) == 50.0  # first step: no time has passed
    dev.last_update = 0.0
    assert dev.approach("percent", 80.0, 10.0, t=1.0) == pytest.approx(60.0)
    dev.last_update = 1.0
    assert dev.approach("percent", 80.0, 10.0, t=10.0) == 80.0  # reaches and stays at the target
    dev.last_update = 10.0
    assert dev.approach("percent", 0.0, 10.0, t=12.0) == pytest.approx(60.0)  # and back down


def test_vehicle_clock_and_model_time() -> None:
    veh = VehicleState()
    a, b = veh.now_us(), veh.now_us()
    assert b >= a and abs(a / 1e6 - time.time()) < 5  # microseconds, epoch = the wall clock at start
    # The model follows the device reads in whole 10 ms steps, never backwards.
    assert veh.sync(1.234).t == pytest.approx(1.23)
    assert veh.sync(0.5).t == pytest.approx(1.23)
    fast = VehicleState(time_scale=4.0)
    t0 = time.monotonic()
    while time.monotonic() - t0 < 0.05:
        pass
    assert fast.t() >= 4 * 0.05 - 1e-6  # vehicle seconds run 4x the wall clock


@pytest.fixture(scope="module")
def gen() -> Any:
    g = generated_or_skip()
    g.compile_dsdl()
    return g


def test_generic_values_for_any_type(gen: Any) -> None:
    """Types without a physics model get in-range values that change over time (here: standard types)."""
    import pycyphal.dsdl
    import uavcan.node
    import uavcan.si.sample.velocity

    for cls in (uavcan.node.GetInfo_1_0.Response, uavcan.si.sample.velocity.Vector3_1_0, uavcan.node.Heartbeat_1_0):
        a = generic_fill(cls(), 0.0, 1_000_000)
        b = generic_fill(cls(), 5.0, 6_000_000)
        # Serializable (every value in range) and changing.
        for obj in (a, b):
            assert pycyphal.dsdl.deserialize(cls, list(pycyphal.dsdl.serialize(obj))) is not None
        assert pycyphal.dsdl.to_builtin(a) != pycyphal.dsdl.to_builtin(b), cls
    v = generic_fill(uavcan.si.sample.velocity.Vector3_1_0(), 1.0, 123_456)
    assert v.timestamp.microsecond == 123_456


def _sample(sim: Simulator, device: str, t: float) -> Any:
    dev = next(d for d in sim.devices if d.info.name == device)
    port = dev.info.publishes[0]
    obj = sim.gen.dsdl_class(port)()
    generic_fill(obj, t, sim.vehicle.now_us())
    PHYSICS[physics_key(port.dsdl_type)](obj, dev.state, sim.vehicle, t, 1.0 / port.rate_hz, sim.vehicle.rng)
    dev.state.last_update = t
    return obj


class _Transfer:
    def __init__(self, source_node_id: int | None) -> None:
        self.source_node_id = source_node_id


def _command(sim: Simulator, device: str, source: int, **values: Any) -> None:
    """A command as the device receives it (no network): through the simulator's command handler."""
    dev = next(d for d in sim.devices if d.info.name == device)
    if not dev.subs:
        port = dev.info.subscribes[0]
        from sam_runtime.sim.ports import SubPort

        dev.subs.append(SubPort(port, sim.gen.dsdl_class(port)))
    sp = dev.subs[0]
    sim.on_command(dev, sp, sp.dtype(**values), _Transfer(source))


def test_sam_physics_values_are_plausible(gen: Any) -> None:
    if gen.tables().VEHICLE != "sam":
        pytest.skip("SAM's devices")
    sim = Simulator(gen, SimConfig(battery_drain_factor=20.0))
    imu = _sample(sim, "imu", 1.0)
    assert imu.accelerometer_latest[2] == pytest.approx(9.81, abs=0.2) and abs(imu.accelerometer_latest[0]) < 0.2
    assert len(imu.covariance) == 36 and imu.timestamp.microsecond > 0
    mag = _sample(sim, "magnetometer", 1.0)
    assert 0.45 < math.dist((0, 0, 0), [float(x) for x in mag.magnetic_field_ga]) < 0.6  # Gauss, Stockholm
    gps = _sample(sim, "gps", 1.0)
    assert abs(gps.latitude_deg_1e8 * 1e-8 - 59.35) < 0.01 and abs(gps.longitude_deg_1e8 * 1e-8 - 18.07) < 0.01
    assert gps.status == 3 and abs(gps.height_msl_mm) < 1000  # a 3D fix at the surface
    p = _sample(sim, "pressure", 2.0).static_pressure
    assert p == pytest.approx(101325, abs=30)  # at the surface
    # The field rotates with the heading: the bridge's commands turn the vehicle.
    bridge = sim.bridge_node_id
    h0 = [float(x) for x in _sample(sim, "magnetometer", 2.0).magnetic_field_ga]
    _command(sim, "thruster_1", bridge, rpm=1500)
    _command(sim, "thruster_2", bridge, rpm=1500)
    _command(sim, "thrust_vector", bridge, vertical_radians=0.0, horizontal_radians=0.12)
    h1 = [float(x) for x in _sample(sim, "magnetometer", 22.0).magnetic_field_ga]
    assert math.dist(h0[:2], h1[:2]) > 0.05
    assert sim.vehicle.vehicle.state.r > 0.1  # to port: a counter-clockwise yaw rate
    b0, b1 = _sample(sim, "battery", 22.0), _sample(sim, "battery", 222.0)
    assert b1.state_of_charge_pct < b0.state_of_charge_pct and b1.voltage < b0.voltage and b0.current < 0


def test_actuators_drive_the_shared_vehicle_and_its_sensors_measure_it(gen: Any) -> None:
    if gen.tables().VEHICLE != "sam":
        pytest.skip("SAM's devices")
    sim = Simulator(gen, SimConfig(seed=3, sea_floor=SeaFloor(20.0)))
    veh = sim.vehicle.vehicle
    _command(sim, "buoyancy_piston", 42, percent=0.0)  # not the bridge: ignored
    assert _sample(sim, "buoyancy_piston", 5.0).percent == 50.0 and veh.state.depth == 0.0
    _command(sim, "buoyancy_piston", sim.bridge_node_id, percent=0.0)  # sink
    fb = [float(_sample(sim, "buoyancy_piston", 5.0 + k).percent) for k in (1, 2, 5, 6)]
    assert fb == pytest.approx([40.0, 30.0, 0.0, 0.0], abs=0.6)  # 10 %/s
    p = float(_sample(sim, "pressure", 40.0).static_pressure)
    assert veh.state.depth > 3.0 and p == pytest.approx(101325 + 1025 * 9.80665 * veh.state.depth, abs=30)
    gps = _sample(sim, "gps", 40.0)
    assert gps.status == 0 and list(gps.position_covariance) == []  # no fix under water
    gps_thruster = _sample(sim, "thruster_1", 40.0)
    assert gps_thruster.rpm == 0
    _command(sim, "buoyancy_piston", sim.bridge_node_id, percent=100.0)  # back up
    _sample(sim, "pressure", 120.0)
    assert veh.state.depth == 0.0 and veh.state.max_depth > 3.0
    assert _sample(sim, "gps", 121.0).status == 3
    # Out-of-range commands are clamped by the mechanism; NaN is refused and counted.
    _command(sim, "thrust_vector", sim.bridge_node_id, vertical_radians=1.0, horizontal_radians=float("nan"))
    fb = _sample(sim, "thrust_vector", 125.0)
    assert fb.vertical_mrad == 120 and fb.horizontal_mrad == 0
    assert veh.rejected_commands == 1
    truth = sim.truth()
    assert truth["max_depth"] == veh.state.max_depth and truth["gps_origin"] == [59.35, 18.07]


def test_altimeter_physics_measures_the_range_to_the_sea_floor() -> None:
    """The altimeter's DSDL type (sam.sensor.Altitude.0.1: timestamp, altitude, altitude_variance) on any object
    with those fields: the range to the floor, NaN beyond the altimeter's range."""
    from types import SimpleNamespace

    def sample(veh: VehicleState, t: float) -> Any:
        obj = SimpleNamespace(timestamp=SimpleNamespace(microsecond=0), altitude=0.0, altitude_variance=0.0)
        PHYSICS["sensor.Altitude"](obj, DeviceState("altimeter", 16), veh, t, 0.1, veh.rng)
        return obj

    shallow = VehicleState(model=SimulatedVehicle(sea_floor=SeaFloor(12.0), start=(0.0, 0.0, 2.0, 0.0)))
    obj = sample(shallow, 1.0)
    assert obj.altitude == pytest.approx(10.0, abs=0.3) and obj.altitude_variance > 0
    assert obj.timestamp.microsecond > 0
    deep = VehicleState(model=SimulatedVehicle(sea_floor=SeaFloor(80.0)))
    assert math.isnan(sample(deep, 1.0).altitude)  # no bottom lock beyond 30 m


async def _quiet_point(sim: Simulator, counts: Counter[int], stable_s: float = 0.3,
                       timeout: float = 10.0) -> dict[int, dict[str, int]]:
    """Pause the devices, wait (deadline) until what they sent has all arrived, and return per subject what they
    sent, the ticks they skipped and what was received."""
    await sim.pause()
    await until_stable(lambda: dict(counts), stable_s, timeout)
    out: dict[int, dict[str, int]] = {}
    for d in sim.devices:
        for pp in d.pubs:
            sid = pp.port.subject_id
            one = out.setdefault(sid, {"sent": 0, "late": 0, "received": counts[sid]})
            one["sent"] += pp.sent
            one["late"] += pp.late
    return out


async def _network_scenario(gen: Any, channel: str) -> dict[str, Any]:
    import uavcan.node

    from sam_runtime.cyphal_io.transport import aclose, make_node

    tables = gen.tables()
    iface = f"virtual:{channel}"
    sim = Simulator(gen, SimConfig("can", iface, 64))
    await sim.start(publish_now=True)
    bridge_like = make_node("org.test.commander", tables.BRIDGE_NODE_ID, "can", iface=iface, mtu=64)
    other = make_node("org.test.other", 42, "can", iface=iface, mtu=64)
    counts: Counter[int] = Counter()
    heartbeats: dict[int, Any] = {}
    feedback: dict[int, list[tuple[float, Any]]] = defaultdict(list)
    subs = []
    for d in tables.DEVICES:
        for p in d.publishes:
            sub = bridge_like.make_subscriber(gen.dsdl_class(p), p.subject_id)
            sub.receive_in_background(lambda msg, tr, sid=p.subject_id: (
                counts.update([sid]), feedback[sid].append((time.monotonic(), msg))))
            subs.append(sub)
    hb = bridge_like.make_subscriber(uavcan.node.Heartbeat_1_0)
    hb.receive_in_background(lambda msg, tr: heartbeats.__setitem__(tr.source_node_id, msg))
    try:
        # The rates over a known window between two quiet points (publishing paused, nothing in flight). Under CPU
        # load the shared event loop runs late and the devices skip ticks (counted as late, never burst): what
        # they sent plus what they skipped is their schedule, and everything they sent must arrive.
        start = await _quiet_point(sim, counts)
        sim.resume()
        t0 = time.monotonic()
        await asyncio.sleep(2.0)
        window = time.monotonic() - t0
        end = await _quiet_point(sim, counts)
        sim.resume()
        rates = {sid: {k: end[sid][k] - start[sid][k] for k in ("sent", "late", "received")} | {"window": window}
                 for sid in end}
        # A command from the bridge's node id and one from an unknown node, to the longitudinal weight.
        target = next(d for d in tables.DEVICES if d.name == "longitudinal_weight")
        cmd_port = target.subscribes[0]
        cls = gen.dsdl_class(cmd_port)
        pub_ok = bridge_like.make_publisher(cls, cmd_port.subject_id)
        pub_bad = other.make_publisher(cls, cmd_port.subject_id)
        assert await pub_bad.publish(cls(percent=5.0))
        assert await pub_ok.publish(cls(percent=80.0))
        t_cmd = time.monotonic()
        fb_sid = target.publishes[0].subject_id
        deadline = time.monotonic() + 5
        while time.monotonic() < deadline and not any(
                t > t_cmd + 1.0 for t, _ in feedback[fb_sid]):
            await asyncio.sleep(0.05)
        after = [(t - t_cmd, float(m.percent)) for t, m in feedback[fb_sid] if t > t_cmd]
        # The thruster spins up the shared vehicle; without power it stops (its command is gone).
        thruster = next(d for d in tables.DEVICES if d.name == "thruster_1")
        rpm_cls = gen.dsdl_class(thruster.subscribes[0])
        pub_rpm = bridge_like.make_publisher(rpm_cls, thruster.subscribes[0].subject_id)
        assert await pub_rpm.publish(rpm_cls(rpm=1000))
        deadline = time.monotonic() + 5
        while time.monotonic() < deadline and sim.vehicle.vehicle.commands.rpm_1 != 1000.0:
            await asyncio.sleep(0.02)
        spun_up = sim.vehicle.vehicle.commands.rpm_1
        await sim.power_off("thruster_1")
        stopped = sim.vehicle.vehicle.commands.rpm_1
        report = sim.report()
        await aclose(pub_ok, pub_bad, pub_rpm, hb, *subs)
    finally:
        await sim.close()
        await aclose(bridge_like, other)
    return {"rates": rates, "heartbeats": heartbeats, "after": after, "report": report, "spun_up": spun_up,
            "stopped": stopped}


@pytest.mark.slow
def test_devices_publish_at_nominal_rates_with_heartbeats_and_obey_only_the_bridge(gen: Any) -> None:
    if gen.tables().VEHICLE != "sam":
        pytest.skip("SAM's devices")
    res = _run(_network_scenario(gen, f"simtest{os.getpid()}"))
    tables = gen.tables()
    for d in tables.DEVICES:
        hb = res["heartbeats"].get(d.node_id)
        assert hb is not None, f"no heartbeat from {d.name} (node {d.node_id})"
        assert hb.health.value == hb.health.NOMINAL and hb.mode.value == hb.mode.OPERATIONAL
        for p in d.publishes:
            got = res["rates"][p.subject_id]
            assert got["received"] == got["sent"] > 0, (d.name, p, got)
            scheduled = (got["sent"] + got["late"]) / got["window"]
            assert scheduled == pytest.approx(p.rate_hz, rel=0.2, abs=1.0), (d.name, p, got)
    cmd = res["report"]["devices"]["longitudinal_weight"]["commands"]["1204"]
    assert cmd["accepted"] == 1 and cmd["last"] == {"percent": 80.0}
    assert cmd["rejected"] == 1 and cmd["rejected_sources"] == {"42": 1}
    # From 50 % toward 80 % at 10 %/s: about 60 % a second after the command, never a jump.
    assert res["after"], "no feedback after the command"
    for dt, pct in res["after"]:
        assert 50.0 <= pct <= 50.0 + 10.0 * dt + 1.5, (dt, pct)
    assert any(dt > 0.9 and pct > 57.0 for dt, pct in res["after"]), res["after"]
    assert res["spun_up"] == 1000.0 and res["stopped"] == 0.0
    assert res["report"]["devices"]["thruster_1"]["powered"] is False


@pytest.mark.slow
def test_sim_command_line_runs_for_a_duration_and_reports(gen: Any, tmp_path: Path) -> None:
    report = tmp_path / "report.json"
    env = {k: v for k, v in os.environ.items() if not k.startswith("UAVCAN__")}
    env["SAM_GENERATED_DIR"] = str(gen.root)
    devs = [d for d in gen.tables().DEVICES if d.publishes][:2]
    proc = subprocess.run(
        [sys.executable, "-m", "sam_runtime.cli", "sim", "--transport", "can", "--iface",
         f"virtual:simcli{os.getpid()}", "--mtu", "64", "--duration", "1.5", "--report", str(report),
         "--devices", ",".join(d.name for d in devs)],
        env=env, capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert "Traceback" not in proc.stderr
    data = json.loads(report.read_text())
    assert set(data["devices"]) == {d.name for d in devs}
    for d in devs:
        for p in d.publishes:
            dev = data["devices"][d.name]
            key = str(p.subject_id)  # what it sent plus the ticks it skipped while the machine was busy
            assert dev["published"][key] + dev["late"].get(key, 0) == pytest.approx(1.5 * p.rate_hz, abs=2)


@pytest.mark.slow
def test_sim_command_line_vehicle_options_and_truth_file(gen: Any, tmp_path: Path) -> None:
    truth = tmp_path / "truth.jsonl"
    env = {k: v for k, v in os.environ.items() if not k.startswith("UAVCAN__")}
    env["SAM_GENERATED_DIR"] = str(gen.root)
    base = [sys.executable, "-m", "sam_runtime.cli", "sim", "--transport", "can", "--iface",
            f"virtual:simtruth{os.getpid()}", "--mtu", "64", "--devices", "pressure"]
    proc = subprocess.run(
        [*base, "--duration", "1.5", "--truth-file", str(truth), "--truth-rate", "10", "--seed", "7",
         "--start", "5,-3,2,1.0", "--sea-floor", "0:20,50:8", "--battery-start", "40", "--gps-origin", "10.5,20.25"],
        env=env, capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr[-3000:]
    lines = [json.loads(x) for x in truth.read_text().splitlines()]
    assert len(lines) >= 10, lines  # 10 Hz over 1.5 s, and a last one at exit
    first, last = lines[0], lines[-1]
    assert (first["x"], first["y"], first["depth"], first["yaw"]) == pytest.approx((5.0, -3.0, 2.0, 1.0), abs=1e-3)
    assert first["sea_floor_depth"] == pytest.approx(20 - 12 * 5 / 50) and first["altitude"] == pytest.approx(16.8)
    assert first["battery_percent"] == pytest.approx(40.0, abs=0.01) and first["gps_origin"] == [10.5, 20.25]
    assert last["t"] >= 1.4 and all(b["t"] >= a["t"] for a, b in itertools.pairwise(lines))
    assert last["depth"] == pytest.approx(2.0, abs=0.01)  # neutral buoyancy, no thrust: it stays
    # Four times faster than the wall clock: the vehicle's time, the rates and the stamps.
    fast = tmp_path / "fast.json"
    report = tmp_path / "report.json"
    proc = subprocess.run([*base, "--duration", "1.0", "--time-scale", "4", "--truth-file", str(fast), "--report",
                           str(report)], env=env, capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert json.loads(fast.read_text())["t"] >= 3.6  # at exit: 4 x (start-up + 1 s of publishing)
    pressure = json.loads(report.read_text())["devices"]["pressure"]
    # 20 Hz of vehicle time = 80 per wall second; ticks the loaded process was too late for are skipped and counted
    # (a stall near the end may count a few beyond the window).
    published, late = pressure["published"]["1103"], pressure["late"].get("1103", 0)
    assert 40 <= published <= 83 and published + late >= 77, pressure
    for bad, message in ((["--start", "0,0,30,0"], "the sea floor there"), (["--sea-floor", "deep"], "sea floor"),
                         (["--gps-origin", "95,0"], "GPS origin")):
        proc = subprocess.run([*base, "--duration", "0.1", *bad], env=env, capture_output=True, text=True, timeout=60)
        assert proc.returncode == 1 and "Traceback" not in proc.stderr and message in proc.stderr, proc.stderr


@pytest.mark.slow
def test_a_non_sam_spec_gets_generic_values_and_its_own_actuator_model(tmp_path: Path) -> None:
    """tests/specs/rover.yaml has none of SAM's devices: every port publishes generic in-range values, the vehicle
    model is there but drives nothing, commands are accepted from the bridge only."""
    import pycyphal.dsdl
    from helpers.spec_build import generated_spec

    from sam_runtime.genpkg import GeneratedPackage

    # The shared build of the rover spec: one process imports one rover_bridge (genpkg refuses a second copy).
    rover = GeneratedPackage(generated_spec("rover"))

    async def scenario() -> dict[str, Any]:
        sim = Simulator(rover, SimConfig("can", f"virtual:rover{os.getpid()}", 64, truth_file=tmp_path / "t.json"))
        await sim.start(publish_now=True)
        try:
            await asyncio.sleep(1.0)
            samples = {}
            for dev in sim.devices:
                for pp in dev.pubs:
                    a, b = sim.make_sample(dev, pp, 0.1), sim.make_sample(dev, pp, 0.1)
                    wire = pycyphal.dsdl.deserialize(pp.dtype, list(pycyphal.dsdl.serialize(a)))
                    samples[pp.port.subject_id] = (pycyphal.dsdl.to_builtin(wire), pycyphal.dsdl.to_builtin(b))
            drive = sim.device("drive")
            sp = drive.subs[0]
            sim.on_command(drive, sp, sp.dtype(), _Transfer(sim.bridge_node_id))
            sim.on_command(drive, sp, sp.dtype(), _Transfer(3))
            return {"report": sim.report(), "samples": samples}
        finally:
            await sim.close()

    res = _run(scenario())
    report = res["report"]
    assert set(report["devices"]) == {"drive", "thermo", "air", "nav", "lights"}
    assert report["devices"]["nav"]["published"]["520"] >= 20  # 50 Hz for a second, on a loaded machine too
    assert report["devices"]["drive"]["commands"]["501"]["accepted"] == 1
    assert report["devices"]["drive"]["commands"]["501"]["rejected"] == 1
    assert report["vehicle"]["depth"] == 0.0 and report["vehicle"]["speed"] == 0.0  # nothing drives it
    assert set(res["samples"]) == {500, 510, 511, 520}
    assert json.loads((tmp_path / "t.json").read_text())["t"] >= 0.9  # the atomic truth file, rewritten


def test_failed_publications_are_logged_at_a_bounded_rate(caplog: pytest.LogCaptureFixture) -> None:
    """Issue 11, defect 14: a device whose every publication fails (here the glider spec's altimeter at 10x its
    rate, its publish raising) logs the first failure at once, then one line per log interval with the count,
    and the lines add up to every failure; it used to log one line per failure."""
    import logging
    import re

    from helpers.spec_build import generated_spec

    from sam_runtime.genpkg import GeneratedPackage

    glider = GeneratedPackage(generated_spec("glider"))
    glider.compile_dsdl()
    interval = 1.0

    async def scenario() -> tuple[int, float]:
        sim = Simulator(glider, SimConfig("can", f"virtual:simlog{os.getpid()}", 64, devices=["altimeter"],
                                          rate_scale=10.0, log_interval=interval))
        await sim.start()
        pp = sim.device("altimeter").pubs[0]

        async def failing(obj: Any) -> bool:
            raise OSError("injected send failure")

        pp.publisher.publish = failing  # type: ignore[method-assign]
        t0 = time.monotonic()
        sim.start_publishing()
        while pp.failed < 100 or time.monotonic() - t0 < 2.5 * interval:
            await asyncio.sleep(0.05)
        await sim.close()
        return pp.failed, time.monotonic() - t0

    with caplog.at_level(logging.WARNING, logger="sam_runtime.sim.simulator"):
        failed, elapsed = _run(scenario())
    lines = [r.getMessage() for r in caplog.records if r.name == "sam_runtime.sim.simulator"]
    assert lines and lines[0] == ("altimeter: publish on 620: failed: OSError: injected send failure (1; more are "
                                  "summed at most every 1 s)")
    # At most one line per interval (+ the first, + the one flushed at close); together they count every failure.
    assert len(lines) <= 2 + math.ceil(elapsed / interval) and len(lines) < failed / 10, (len(lines), failed)
    counted = 0
    for line in lines:
        m = re.search(r"\((\d+); more are summed", line) or re.search(r": (\d+) in the last ", line)
        assert m, line
        counted += int(m.group(1))
    assert counted == failed
