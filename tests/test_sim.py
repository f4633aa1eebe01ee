"""The simulated devices (runtime/sim.py): one Cyphal node per device of the spec, plausible changing values at
the nominal rates, actuators that accept only the bridge's commands and move at a finite rate.

The network tests run over python-can ``virtual`` CAN FD in this process (a channel name per test), so they
cannot see, or be seen by, any other run on the machine.
"""

from __future__ import annotations

import asyncio
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

from sam_runtime.sim import DeviceState, SimConfig, Simulator, VehicleState, generic_fill, physics_key

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


def test_vehicle_depth_oscillates_between_surface_and_10_m() -> None:
    veh = VehicleState()
    depths = [veh.depth(t) for t in range(0, 121)]
    assert min(depths) == pytest.approx(0.0, abs=1e-9) and max(depths) == pytest.approx(10.0, abs=1e-3)
    a, b = veh.now_us(), veh.now_us()
    assert b >= a and abs(a / 1e6 - time.time()) < 5  # microseconds, epoch = the wall clock at start


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
    from sam_runtime.sim import PHYSICS

    obj = sim.gen.dsdl_class(port)()
    generic_fill(obj, t, sim.vehicle.now_us())
    PHYSICS[physics_key(port.dsdl_type)](obj, dev.state, sim.vehicle, t, 1.0 / port.rate_hz, sim.vehicle.rng)
    dev.state.last_update = t
    return obj


def test_sam_physics_values_are_plausible(gen: Any) -> None:
    if gen.tables().VEHICLE != "sam":
        pytest.skip("SAM's devices")
    sim = Simulator(gen)
    imu = _sample(sim, "imu", 1.0)
    assert imu.accelerometer_latest[2] == pytest.approx(9.81, abs=0.2) and abs(imu.accelerometer_latest[0]) < 0.2
    assert len(imu.covariance) == 36 and imu.timestamp.microsecond > 0
    mag = _sample(sim, "magnetometer", 1.0)
    assert 0.45 < math.dist((0, 0, 0), [float(x) for x in mag.magnetic_field_ga]) < 0.6  # Gauss, Stockholm
    h0 = [float(x) for x in _sample(sim, "magnetometer", 0.0).magnetic_field_ga]
    h1 = [float(x) for x in _sample(sim, "magnetometer", 20.0).magnetic_field_ga]
    assert math.dist(h0[:2], h1[:2]) > 0.05  # the field rotates with the heading
    gps = _sample(sim, "gps", 1.0)
    assert abs(gps.latitude_deg_1e8 * 1e-8 - 59.35) < 0.01 and abs(gps.longitude_deg_1e8 * 1e-8 - 18.07) < 0.01
    assert gps.status == 3 and abs(gps.height_msl_mm) < 1000  # a 3D fix at the surface
    for t, depth in ((0.0, 0.0), (30.0, 5.0), (60.0, 10.0)):
        p = _sample(sim, "pressure", t).static_pressure
        assert p == pytest.approx(101325 + 1025 * 9.80665 * depth, abs=30), t
    b0, b1 = _sample(sim, "battery", 0.0), _sample(sim, "battery", 200.0)
    assert b1.state_of_charge_pct < b0.state_of_charge_pct and b1.voltage < b0.voltage and b0.current < 0


async def _network_scenario(gen: Any, channel: str) -> dict[str, Any]:
    import uavcan.node

    from sam_runtime.transport import aclose, make_node

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
        t0 = time.monotonic()
        await asyncio.sleep(2.0)  # measure the rates over a known window
        window = time.monotonic() - t0
        rates = {sid: n / window for sid, n in counts.items()}
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
        report = sim.report()
        await aclose(pub_ok, pub_bad, hb, *subs)
    finally:
        await sim.close()
        await aclose(bridge_like, other)
    return {"rates": rates, "heartbeats": heartbeats, "after": after, "report": report}


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
            assert res["rates"].get(p.subject_id, 0) == pytest.approx(p.rate_hz, rel=0.2, abs=1.0), (d.name, p)
    cmd = res["report"]["devices"]["longitudinal_weight"]["commands"]["1204"]
    assert cmd["accepted"] == 1 and cmd["last"] == {"percent": 80.0}
    assert cmd["rejected"] == 1 and cmd["rejected_sources"] == {"42": 1}
    # From 50 % toward 80 % at 10 %/s: about 60 % a second after the command, never a jump.
    assert res["after"], "no feedback after the command"
    for dt, pct in res["after"]:
        assert 50.0 <= pct <= 50.0 + 10.0 * dt + 1.5, (dt, pct)
    assert any(dt > 0.9 and pct > 57.0 for dt, pct in res["after"]), res["after"]


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
            assert data["devices"][d.name]["published"][str(p.subject_id)] == pytest.approx(1.5 * p.rate_hz, abs=2)


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

    with caplog.at_level(logging.WARNING, logger="sam_runtime.sim"):
        failed, elapsed = _run(scenario())
    lines = [r.getMessage() for r in caplog.records if r.name == "sam_runtime.sim"]
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
