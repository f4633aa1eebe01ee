"""The simulated devices on DroneCAN (UAVCAN v0): under a layout that puts a device on DroneCAN, the simulator runs it
as a dronecan node on the same simulated vehicle (runtime/sim/dronecan.py, runtime/sim/devices_dronecan.py).

Everything is checked against plain dronecan nodes (the library itself, on this repository's loopback driver) on a
private ``mcast-lo:`` bus of this test session, in this process; the Cyphal side of the mixed layout runs over
python-can ``virtual`` CAN FD. Rates have wide tolerances and every wait is a deadline (2 loaded cores).
"""

from __future__ import annotations

import asyncio
import json
import math
import os
import subprocess
import sys
import time
from collections import defaultdict
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

dronecan = pytest.importorskip("dronecan")
pytest.importorskip("pycyphal")

from helpers.dronecan_support import private_iface, until  # noqa: E402
from helpers.runtime_support import generated_or_skip  # noqa: E402

from sam_runtime.dronecan_io import NodeLoop, make_node  # noqa: E402
from sam_runtime.sim.simulator import SimConfig, Simulator, layout_protocols  # noqa: E402

pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning:pydsdl")

NODE_STATUS = "uavcan.protocol.NodeStatus"
RPM_COMMAND = "uavcan.equipment.esc.RPMCommand"
ARRAY_COMMAND = "uavcan.equipment.actuator.ArrayCommand"
ESC_STATUS = "uavcan.equipment.esc.Status"
POSITION_FEEDBACK = "sam.actuator.PositionFeedback"


def _run(coro: Any, timeout: float = 60.0) -> Any:
    async def bounded() -> Any:
        async with asyncio.timeout(timeout):
            return await coro

    return asyncio.run(bounded())


def _t(name: str) -> Any:
    """A dronecan type by name, looked up now (load_dsdl replaces the type objects)."""
    return dronecan.TYPENAMES[name]


class Peer:
    """A plain dronecan node on the bus that keeps every broadcast it hears: (receive time, message) by (source node,
    type name)."""

    def __init__(self, iface: str, node_id: int) -> None:
        self.node = make_node(iface, node_id)
        self.loop = NodeLoop(self.node)
        self.heard: dict[tuple[int, str], list[tuple[float, Any]]] = defaultdict(list)
        self.node.add_handler(None, self._on_transfer)  # every type, whatever load_dsdl did meanwhile
        self.loop.start()

    def _on_transfer(self, event: Any) -> None:
        if not event.transfer.service_not_message:
            key = (event.transfer.source_node_id, str(event.message._type.full_name))
            self.heard[key].append((time.monotonic(), event.message))

    def last(self, source: int, type_name: str) -> Any:
        got = self.heard.get((source, type_name))
        return got[-1][1] if got else None

    def count(self, source: int, type_name: str, since: float = 0.0, until_t: float = math.inf) -> int:
        return sum(1 for t, _ in self.heard.get((source, type_name), ()) if since <= t < until_t)

    def broadcast(self, msg: Any) -> None:
        self.node.broadcast(msg)

    async def request(self, request: Any, dest: int, timeout: float = 5.0) -> Any:
        done: asyncio.Future[Any] = asyncio.get_running_loop().create_future()
        self.node.request(request, dest, lambda e: done.done() or done.set_result(e), timeout=timeout)
        self.loop.wake()
        event = await asyncio.wait_for(done, timeout + 1.0)
        return None if event is None else event.response

    def close(self) -> None:
        self.loop.stop()
        self.node.close()


@pytest.fixture(scope="module")
def gen() -> Any:
    g = generated_or_skip()
    if g.tables().VEHICLE != "sam" or not getattr(g.tables(), "DRONECAN_DEVICES", ()):
        pytest.skip("SAM's DroneCAN devices")
    return g


def _commands(sim: Simulator, device: str, type_name: str) -> dict[str, Any]:
    return sim.report()["devices"][device]["commands"][f"dronecan:{type_name}"]


async def _until(pred: Callable[[], Any], timeout: float, what: str) -> Any:
    return await until(pred, timeout, what)


# ============================================================================================ broadcasts
async def _broadcast_scenario(gen: Any) -> dict[str, Any]:
    tables = gen.tables()
    iface = private_iface()
    sim = Simulator(gen, SimConfig(layout="dronecan", dronecan_iface=iface))
    await sim.start(publish_now=True)
    peer = Peer(iface, 99)
    try:
        ids = {d.node_id for d in tables.DRONECAN_DEVICES}
        await _until(lambda: all(peer.count(n, NODE_STATUS) for n in ids), 10, "NodeStatus from every device")
        t0 = time.monotonic()
        await asyncio.sleep(3.0)  # a measurement window, not a wait for discovery
        t1 = time.monotonic()
        rates = {(d.node_id, p.data_type.name): peer.count(d.node_id, p.data_type.name, t0, t1) / (t1 - t0)
                 for d in tables.DRONECAN_DEVICES for p in d.publishes}
        last = {key: got[-1][1] for key, got in peer.heard.items()}
        schedule = sim.report()
        info = await peer.request(_t("uavcan.protocol.GetNodeInfo").Request(), 11)
        # RestartNode: a wrong magic number is refused; the right one reboots the device (uptime from 0).
        await _until(lambda: peer.last(15, NODE_STATUS).uptime_sec >= 4, 20, "the battery's uptime >= 4 s")
        restart = _t("uavcan.protocol.RestartNode").Request
        refused = await peer.request(restart(magic_number=0x1234), 15)
        t_restart, uptime_before = time.monotonic(), peer.last(15, NODE_STATUS).uptime_sec
        accepted = await peer.request(restart(magic_number=restart().MAGIC_NUMBER), 15)
        await _until(lambda: sim.device("battery").power_cycles == 1 and sim.device("battery").powered, 20,
                     "the battery's reboot")
        # The old node's uptime only grows; a new node's starts at 0. Judged against the uptime before the restart
        # (>= 4 s) rather than a bound on the new node's first status, which a loaded machine may send late.
        rebooted = await _until(lambda: next((m for t, m in peer.heard[(15, NODE_STATUS)]
                                              if t > t_restart and m.uptime_sec < uptime_before), None), 20,
                                "a NodeStatus of the rebooted battery (uptime from 0)")
        return {"rates": rates, "last": last, "schedule": schedule, "info": info, "refused": refused,
                "accepted": accepted, "rebooted": rebooted, "uptime_before": uptime_before, "report": sim.report()}
    finally:
        peer.close()
        await sim.close()


def test_every_sam_device_broadcasts_its_v0_types_at_nominal_rates_with_the_vehicles_values(gen: Any) -> None:
    res = _run(_broadcast_scenario(gen))
    tables = gen.tables()
    rates = res["rates"]
    print("v0 rates [Hz]:", {f"{n}:{t.rsplit('.', 1)[1]}": round(r, 1) for (n, t), r in sorted(rates.items())})
    schedule = res["schedule"]
    for d in tables.DRONECAN_DEVICES:
        for p in d.publishes:
            # What arrived (a loaded machine skips the ticks it is too late for) and what was due on the schedule
            # (sent, or skipped and counted as late): about the nominal rate.
            rate = rates[(d.node_id, p.data_type.name)]
            key = f"dronecan:{p.data_type.name}"
            dev = schedule["devices"][d.name]
            # Against the rate the device achieved (a loaded machine makes it skip ticks, counted as late below),
            # not the nominal one alone: what arrived is what was sent.
            achieved = dev["published"][key] / schedule["publishing_s"]
            assert 0.5 * achieved - 1.0 <= rate <= 1.25 * p.rate_hz + 1.0, (d.name, p.data_type.name, rate, achieved)
            due = p.rate_hz * schedule["publishing_s"]
            assert abs(dev["published"][key] + dev["late"].get(key, 0) - due) <= 0.15 * due + 2, (d.name, dev, due)
        status = res["last"][(d.node_id, NODE_STATUS)]
        assert (status.health, status.mode) == (status.HEALTH_OK, status.MODE_OPERATIONAL), d.name
        rep = res["report"]["devices"][d.name]
        assert rep["protocol"] == "dronecan" and rep["node_id"] == d.node_id
        for p in d.publishes:
            assert rep["published"][f"dronecan:{p.data_type.name}"] > 0, (d.name, rep)
    last = res["last"]
    imu = last[(11, "uavcan.equipment.ahrs.RawIMU")]
    assert imu.accelerometer_latest[2] == pytest.approx(9.81, abs=0.3) and abs(imu.accelerometer_latest[0]) < 0.3
    assert len(imu.covariance) == 6  # the diagonal
    # no time-sync master on this bus: the device never synchronised its clock, so its stamps are unknown (0)
    assert imu.timestamp.usec == 0 and res["report"]["devices"]["imu"]["time_sync"]["synchronised"] is False
    mag = last[(12, "uavcan.equipment.ahrs.MagneticFieldStrength")]
    assert 0.45 < math.dist((0, 0, 0), list(mag.magnetic_field_ga)) < 0.6  # Gauss, Stockholm
    fix = last[(13, "uavcan.equipment.gnss.Fix2")]
    assert fix.status == 3 and abs(fix.latitude_deg_1e8 * 1e-8 - 59.35) < 0.01
    assert abs(fix.longitude_deg_1e8 * 1e-8 - 18.07) < 0.01 and len(fix.covariance) == 36
    assert last[(14, "uavcan.equipment.air_data.StaticPressure")].static_pressure == pytest.approx(101325, abs=50)
    battery = last[(15, "uavcan.equipment.power.BatteryInfo")]
    assert battery.state_of_charge_pct == 95 and 20 < battery.voltage < 30 and battery.model_name.decode() == \
        "SAM 6S Li-ion"
    assert last[(16, "sam.sensor.Altitude")].altitude == pytest.approx(25.0, abs=0.5)  # the default sea floor
    esc_1, esc_2 = last[(21, ESC_STATUS)], last[(22, ESC_STATUS)]
    assert (esc_1.esc_index, esc_2.esc_index) == (0, 1) and esc_1.rpm == esc_2.rpm == 0
    assert esc_1.temperature == pytest.approx(298.15, abs=0.2)  # kelvin
    tv = last[(23, "sam.actuator.ThrustVectorFeedback")]
    assert (tv.vertical_mrad, tv.horizontal_mrad) == (0, 0)
    assert last[(25, POSITION_FEEDBACK)].percent == last[(26, POSITION_FEEDBACK)].percent == 50.0
    assert res["info"] is not None and res["info"].name.decode() == "org.sam.sim.imu"
    assert res["refused"].ok is False and res["accepted"].ok is True
    assert res["rebooted"].uptime_sec < res["uptime_before"]
    assert res["report"]["devices"]["battery"]["power_cycles"] == 1


# ============================================================================================ commands
async def _command_scenario(gen: Any, record: Path) -> dict[str, Any]:
    iface = private_iface()
    actuators = ["thruster_1", "thruster_2", "thrust_vector", "ballast", "longitudinal_weight", "buoyancy_piston"]
    sim = Simulator(gen, SimConfig(layout="dronecan", dronecan_iface=iface, devices=actuators, record=record))
    await sim.start(publish_now=True)
    bridge = Peer(iface, gen.tables().BRIDGE_NODE_ID)
    rogue = Peer(iface, 42)
    veh = sim.vehicle.vehicle
    out: dict[str, Any] = {}
    try:
        await _until(lambda: bridge.last(21, ESC_STATUS) and bridge.last(22, ESC_STATUS), 10, "both ESCs' status")
        rpm = _t(RPM_COMMAND)
        rogue.broadcast(rpm(rpm=[1500, 1500]))
        await _until(lambda: all(_commands(sim, d, RPM_COMMAND)["rejected"] == 1 for d in actuators[:2]), 5,
                     "the rogue's RPMCommand rejected by both thrusters")
        out["rogue"] = {d: _commands(sim, d, RPM_COMMAND) for d in actuators[:2]}
        out["after_rogue"] = (veh.commands.rpm_1, veh.commands.rpm_2)

        bridge.broadcast(rpm(rpm=[1000, 1000]))
        await _until(lambda: all(_commands(sim, d, RPM_COMMAND)["accepted"] == 1 for d in actuators[:2]), 5,
                     "the bridge's RPMCommand accepted by both thrusters")
        out["accepted"] = {d: _commands(sim, d, RPM_COMMAND) for d in actuators[:2]}
        out["commanded"] = (veh.commands.rpm_1, veh.commands.rpm_2)
        await _until(lambda: sim.truth()["speed"] > 0.05 and bridge.last(21, ESC_STATUS).rpm > 500
                     and bridge.last(22, ESC_STATUS).rpm > 500, 10, "the thrusters spinning and the vehicle moving")
        out["esc"] = (bridge.last(21, ESC_STATUS), bridge.last(22, ESC_STATUS))
        out["speed"] = sim.truth()["speed"]

        bridge.broadcast(rpm(rpm=[1200]))  # no element for thruster 2: not a command for it
        await _until(lambda: _commands(sim, "thruster_1", RPM_COMMAND)["accepted"] == 2
                     and _commands(sim, "thruster_2", RPM_COMMAND)["not_addressed"] == 1, 5, "the one-ESC command")
        out["one_esc"] = {d: _commands(sim, d, RPM_COMMAND) for d in actuators[:2]}
        out["one_esc_rpm"] = (veh.commands.rpm_1, veh.commands.rpm_2)

        array, item = _t(ARRAY_COMMAND), _t("uavcan.equipment.actuator.Command")
        bridge.broadcast(array(commands=[item(actuator_id=5, command_type=0, command_value=0.0)]))  # sink
        await _until(lambda: _commands(sim, "buoyancy_piston", ARRAY_COMMAND)["accepted"] == 1
                     and all(_commands(sim, d, ARRAY_COMMAND)["not_addressed"] == 1 for d in actuators[2:5]), 5,
                     "the buoyancy command")
        out["array"] = {d: _commands(sim, d, ARRAY_COMMAND) for d in actuators[2:]}
        out["pct"] = (veh.commands.buoyancy_pct, veh.commands.longitudinal_weight_pct)
        t_cmd = time.monotonic()
        await _until(lambda: bridge.last(26, POSITION_FEEDBACK).percent < 45.0, 5, "the piston moving in")
        out["lw_feedback"] = [float(m.percent) for t, m in bridge.heard[(25, POSITION_FEEDBACK)] if t > t_cmd]

        bridge.broadcast(array(commands=[item(actuator_id=0, command_type=1, command_value=0.05),
                                         item(actuator_id=1, command_type=1, command_value=-0.1)]))
        await _until(lambda: _commands(sim, "thrust_vector", ARRAY_COMMAND)["accepted"] == 1, 5, "the nozzle")
        out["angles"] = (veh.commands.vertical_rad, veh.commands.horizontal_rad)
        out["report"] = sim.report()
    finally:
        bridge.close()
        rogue.close()
        await sim.close()
    return out


def test_actuators_take_their_element_of_the_bridges_broadcasts_and_drive_the_vehicle(gen: Any, tmp_path: Path
                                                                                       ) -> None:
    record = tmp_path / "record.jsonl"
    res = _run(_command_scenario(gen, record))
    for device in ("thruster_1", "thruster_2"):
        rogue = res["rogue"][device]
        assert (rogue["accepted"], rogue["rejected"], rogue["rejected_sources"]) == (0, 1, {"42": 1})
    assert res["after_rogue"] == (0.0, 0.0)
    assert res["accepted"]["thruster_1"]["last"] == {"rpm[0]": 1000}
    assert res["accepted"]["thruster_2"]["last"] == {"rpm[1]": 1000}
    assert res["commanded"] == (1000.0, 1000.0)
    esc_1, esc_2 = res["esc"]
    assert (esc_1.esc_index, esc_2.esc_index) == (0, 1) and esc_1.rpm <= 1000 and esc_1.temperature > 298.15
    assert res["speed"] > 0.05
    assert res["one_esc"]["thruster_1"]["last"] == {"rpm[0]": 1200}
    assert res["one_esc"]["thruster_2"]["accepted"] == 1 and res["one_esc_rpm"] == (1200.0, 1000.0)
    array = res["array"]
    assert array["buoyancy_piston"]["accepted"] == 1 and array["buoyancy_piston"]["not_addressed"] == 0
    assert array["buoyancy_piston"]["last"] == {
        "commands[actuator_id=5]": {"actuator_id": 5, "command_type": 0, "command_value": 0.0}}
    for device in ("thrust_vector", "ballast", "longitudinal_weight"):
        assert (array[device]["accepted"], array[device]["not_addressed"]) == (0, 1), device
    assert res["pct"] == (0.0, 50.0)  # only the buoyancy piston moves
    assert res["lw_feedback"] and all(p == 50.0 for p in res["lw_feedback"])
    vertical, horizontal = res["angles"]
    assert vertical == pytest.approx(0.05, abs=1e-3) and horizontal == pytest.approx(-0.1, abs=1e-3)
    # The record: the commands as received (with their source and verdict) and the broadcasts as sent.
    lines = [json.loads(x) for x in record.read_text().splitlines()]
    rx = [r for r in lines if r["dir"] == "rx" and r["device"] == "thruster_1" and r["data_type"] == RPM_COMMAND]
    assert [(r["source"], r["accepted"]) for r in rx[:2]] == [(42, False), (100, True)]
    assert rx[1]["value"] == {"rpm": [1000, 1000]} and rx[1]["data_type_id"] == 1031
    tx = [r for r in lines if r["dir"] == "tx" and r["device"] == "thruster_2"]
    assert tx and tx[-1]["data_type"] == ESC_STATUS and tx[-1]["value"]["esc_index"] == 1


# ============================================================================================ layouts
async def _mixed_scenario(gen: Any) -> dict[str, Any]:
    iface = private_iface()
    sim = Simulator(gen, SimConfig("can", f"virtual:simdcmixed{os.getpid()}", 64, layout="mixed",
                                   dronecan_iface=iface))
    await sim.start(publish_now=True)
    import uavcan.node

    from sam_runtime.cyphal_io.transport import aclose
    from sam_runtime.cyphal_io.transport import make_node as make_cyphal_node

    tables = gen.tables()
    peer = Peer(iface, 99)
    cyphal = make_cyphal_node("org.test.listener", 99, "can", iface=f"virtual:simdcmixed{os.getpid()}", mtu=64)
    imu = next(d for d in tables.DEVICES if d.name == "imu").publishes[0]
    cyphal_imu: list[Any] = []
    heartbeats: dict[int, Any] = {}
    sub = cyphal.make_subscriber(gen.dsdl_class(imu), imu.subject_id)
    sub.receive_in_background(lambda msg, tr: cyphal_imu.append(msg))
    hb = cyphal.make_subscriber(uavcan.node.Heartbeat_1_0)
    hb.receive_in_background(lambda msg, tr: heartbeats.__setitem__(tr.source_node_id, msg))
    try:
        await _until(lambda: cyphal_imu and peer.last(15, "uavcan.equipment.power.BatteryInfo")
                     and peer.last(21, ESC_STATUS) and 11 in heartbeats and peer.last(21, NODE_STATUS), 10,
                     "Cyphal IMU samples and heartbeats, DroneCAN battery and ESC status")
        return {"protocols": {d.info.name: d.protocol for d in sim.devices}, "cyphal_imu": cyphal_imu[-1],
                "v0_imu": peer.last(11, "uavcan.equipment.ahrs.RawIMU"), "v0_status_11": peer.last(11, NODE_STATUS),
                "heartbeats": dict(heartbeats), "report": sim.report()}
    finally:
        peer.close()
        await aclose(sub, hb)
        await sim.close()
        await aclose(cyphal)


def test_mixed_layout_runs_nav_sensors_on_cyphal_and_the_rest_on_dronecan(gen: Any) -> None:
    pytest.importorskip("can")
    res = _run(_mixed_scenario(gen))
    expected = dict(next(lay for lay in gen.tables().LAYOUTS if lay.name == "mixed").protocols)
    assert res["protocols"] == expected
    assert {n for n, p in expected.items() if p == "cyphal"} == {"imu", "magnetometer", "gps", "pressure", "altimeter"}
    assert res["cyphal_imu"].accelerometer_latest[2] == pytest.approx(9.81, abs=0.3)
    assert res["v0_imu"] is None and res["v0_status_11"] is None  # the IMU is not on DroneCAN
    assert 21 not in res["heartbeats"]  # nor the thruster on Cyphal
    devices = res["report"]["devices"]
    assert devices["imu"]["protocol"] == "cyphal" and "1100" in devices["imu"]["published"]
    assert devices["battery"]["protocol"] == "dronecan"
    assert devices["battery"]["published"]["dronecan:uavcan.equipment.power.BatteryInfo"] >= 1
    assert res["report"]["layout"] == "mixed"


def test_the_specs_v0_types_are_added_without_reloading_dronecans_own(gen: Any) -> None:
    """dronecan.load_dsdl() would replace every type object of the process (handlers registered on the old ones
    never fire again): the simulator adds the spec's own types beside them instead."""
    from sam_runtime.sim.dronecan import ensure_types, type_problems

    raw_imu, status = _t("uavcan.equipment.ahrs.RawIMU"), _t(NODE_STATUS)
    ensure_types(gen)
    assert type_problems(gen.tables()) == []
    assert _t("uavcan.equipment.ahrs.RawIMU") is raw_imu and _t(NODE_STATUS) is status
    feedback = _t(POSITION_FEEDBACK)
    assert feedback.default_dtid == 20102 and dronecan.DATATYPES[(20102, feedback.kind)] is feedback
    msg = feedback(percent=12.5, encoder_count=1250)
    msg.timestamp.usec = 42
    frames = dronecan.transport.Transfer(payload=msg, source_node_id=26, transfer_id=3).to_frames()
    received = dronecan.transport.Transfer()
    received.from_frames(frames)  # a multi-frame transfer: its CRC is seeded with the signature (base_crc)
    assert (received.payload.percent, received.payload.encoder_count, received.payload.timestamp.usec) == (
        12.5, 1250, 42)
    ensure_types(gen)  # again: nothing to do
    assert _t(POSITION_FEEDBACK) is feedback


def test_generic_values_for_every_v0_type() -> None:
    """Every message type dronecan knows gets in-range values (they encode and decode) that change over time."""
    from sam_runtime.sim.devices_dronecan import generic_fill_v0, to_builtin_v0

    checked = changed = 0
    for name, t in sorted(dronecan.TYPENAMES.items()):
        if t.kind != t.KIND_MESSAGE:
            continue
        a, b = generic_fill_v0(t(), 0.0, 1_000_000), generic_fill_v0(t(), 5.0, 6_000_000)
        wire = t()
        wire._unpack(a._pack())
        assert to_builtin_v0(wire).keys() == to_builtin_v0(a).keys(), name
        if any(f.type.full_name == "uavcan.Timestamp" for f in t.fields if f.name == "timestamp"):
            assert wire.timestamp.usec == 1_000_000, name
        checked += 1
        changed += to_builtin_v0(a) != to_builtin_v0(b)
    assert checked > 100 and changed > 0.8 * checked, (checked, changed)


def test_layouts_are_the_specs_and_an_unknown_one_is_refused(gen: Any) -> None:
    tables = gen.tables()
    assert set(layout_protocols(tables, "default").values()) == {"cyphal"}
    assert set(layout_protocols(tables, "dronecan").values()) == {"dronecan"}
    assert list(layout_protocols(tables, "mixed")) == [d.name for d in tables.DEVICES]  # spec order
    with pytest.raises(ValueError, match=r"no layout 'nope'; its layouts: default, dronecan, mixed"):
        Simulator(gen, SimConfig(layout="nope"))
    with pytest.raises(ValueError, match="mcast-lo:7"):  # dronecan's own mcast: driver is refused
        Simulator(gen, SimConfig(layout="dronecan", dronecan_iface="mcast:7"))
    with pytest.raises(ValueError, match="unknown device"):
        Simulator(gen, SimConfig(layout="dronecan", devices=["imu", "sonar"]))
    # No DroneCAN machinery for a Cyphal-only layout.
    assert {d.protocol for d in Simulator(gen, SimConfig()).devices} == {"cyphal"}


@pytest.mark.slow
def test_sim_command_line_layout_and_dronecan_iface(gen: Any, tmp_path: Path) -> None:
    report = tmp_path / "report.json"
    env = {k: v for k, v in os.environ.items() if not k.startswith("UAVCAN__")}
    env["SAM_GENERATED_DIR"] = str(gen.root)
    base = [sys.executable, "-m", "sam_runtime.cli", "sim", "--dronecan-iface", private_iface()]
    proc = subprocess.run([*base, "--layout", "dronecan", "--devices", "imu,thruster_1", "--duration", "1.5",
                           "--report", str(report)], env=env, capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr[-3000:]
    data = json.loads(report.read_text())
    assert data["layout"] == "dronecan" and set(data["devices"]) == {"imu", "thruster_1"}
    published = data["devices"]["imu"]["published"]["dronecan:uavcan.equipment.ahrs.RawIMU"]
    late = data["devices"]["imu"]["late"].get("dronecan:uavcan.equipment.ahrs.RawIMU", 0)
    assert 75 <= published <= 152 and published + late >= 140, data["devices"]["imu"]
    assert data["devices"]["thruster_1"]["published"]["dronecan:uavcan.equipment.esc.Status"] == pytest.approx(15,
                                                                                                           abs=2)
    proc = subprocess.run([*base, "--layout", "nope", "--duration", "0.1"], env=env, capture_output=True, text=True,
                          timeout=60)
    assert proc.returncode == 1 and "Traceback" not in proc.stderr and "its layouts: default, dronecan, mixed" in \
        proc.stderr, proc.stderr


# ============================================================================================ another spec
async def _ferry_scenario(ferry: Any) -> dict[str, Any]:
    iface = private_iface()
    sim = Simulator(ferry, SimConfig(layout="all_dronecan", dronecan_iface=iface))
    await sim.start(publish_now=True)
    bridge = Peer(iface, ferry.tables().BRIDGE_NODE_ID)
    try:
        publishers = {d.node_id: [p.data_type.name for p in d.publishes] for d in ferry.tables().DRONECAN_DEVICES}
        await _until(lambda: all(bridge.last(n, t) for n, types in publishers.items() for t in types), 10,
                     "a broadcast of every ferry device")
        last = {(n, t): bridge.last(n, t) for n, types in publishers.items() for t in types}
        bridge.broadcast(_t("uavcan.equipment.esc.RawCommand")(cmd=[100, 200, 4000]))
        bridge.broadcast(_t("ferry.drive.SetMode")(device_id=1, mode=5, enable=True))
        item = _t("uavcan.equipment.actuator.Command")
        bridge.broadcast(_t(ARRAY_COMMAND)(commands=[item(actuator_id=9, command_type=0, command_value=0.5)]))

        def commands(device: str, type_name: str) -> dict[str, Any]:
            return sim.report()["devices"][device]["commands"][f"dronecan:{type_name}"]

        await _until(lambda: commands("ramp", ARRAY_COMMAND)["accepted"] == 1
                     and commands("drive_3", "uavcan.equipment.esc.RawCommand")["accepted"] == 1
                     and commands("drive_2", "ferry.drive.SetMode")["not_addressed"] == 1, 5, "the ferry's commands")
        await _until(lambda: bridge.last(33, ESC_STATUS).rpm > 100, 5, "drive 3 spinning up")
        return {"last": last, "report": sim.report(), "protocols": layout_protocols(ferry.tables(), "default")}
    finally:
        bridge.close()
        await sim.close()


@pytest.mark.slow
def test_a_non_sam_spec_gets_generic_v0_values_with_its_selections_and_its_own_actuator_model() -> None:
    """tests/specs/ferry.yaml: DroneCAN-only devices, custom v0 types (nested, padded, keyed items), three ESCs in
    one RawCommand: generic values that encode, the values the bridge's mappings select on, commands by element."""
    from helpers.spec_build import generated_spec

    from sam_runtime.genpkg import GeneratedPackage

    ferry = GeneratedPackage(generated_spec("ferry"))
    res = _run(_ferry_scenario(ferry))  # its types are added beside SAM's: nothing of this process is reloaded
    assert res["protocols"] == {"depth": "cyphal", "drive_1": "dronecan", "drive_2": "dronecan",
                                "drive_3": "dronecan", "hull": "dronecan", "steering": "dronecan", "ramp": "dronecan"}
    last = res["last"]
    assert last[(31, "ferry.drive.Telemetry")].device_id == 1 and last[(32, "ferry.drive.Telemetry")].device_id == 2
    assert last[(33, ESC_STATUS)].esc_index == 2  # drive_3's mappings select esc_index 2
    leak = last[(40, "ferry.hull.LeakReport")]
    assert leak.device_id == 4 and {1, 5} <= {c.compartment for c in leak.compartments}
    assert last[(31, "ferry.drive.Telemetry")].timestamp.usec == 0  # no time-sync master: unknown
    devices = res["report"]["devices"]
    raw = "dronecan:uavcan.equipment.esc.RawCommand"
    assert [devices[d]["commands"][raw]["last"] for d in ("drive_1", "drive_2", "drive_3")] == [
        {"cmd[0]": 100}, {"cmd[1]": 200}, {"cmd[2]": 4000}]
    set_mode = "dronecan:ferry.drive.SetMode"
    assert devices["drive_1"]["commands"][set_mode]["last"] == {"device_id": 1, "mode": 5, "enable": True}
    assert devices["drive_2"]["commands"][set_mode]["accepted"] == 0
    array = f"dronecan:{ARRAY_COMMAND}"
    assert devices["ramp"]["commands"][array]["last"] == {
        "commands[actuator_id=9]": {"actuator_id": 9, "command_type": 0, "command_value": 0.5}}
    assert (devices["steering"]["commands"][array]["accepted"], devices["steering"]["commands"][array][
        "not_addressed"]) == (0, 1)
    assert res["report"]["vehicle"]["speed"] == 0.0  # nothing of SAM's drives the vehicle
