"""The bridge across processes over Cyphal/UDP on 127.0.0.1 (issue 3).

- sensors: sim devices -> Cyphal/UDP -> bridge process -> a separate rclpy subscriber process, for 10 s at the
  nominal rates: every message arrives (counts sent = received per topic), in order, with the values the
  devices sent after the documented conversions; the devices' heartbeats reach /diagnostics.
- commands: a separate rclpy process publishes the actuator topics -> bridge (configured by the standard
  UAVCAN__* register variables) -> the simulated actuators receive the matching commands, from the bridge's
  node id, with the right (saturated where out of range) values.
- static routing: a node id the spec does not allow is not bridged and its drops are counted; the actuators
  ignore commands from it.
- the main job (`run`): --duration for scripted runs and Ctrl-C, both exit 0 and leave no process behind.

Each scenario uses its own ROS_DOMAIN_ID; discovery and delivery are polled with deadlines.
"""

from __future__ import annotations

import itertools
import json
import math
import os
import re
import signal
import statistics
import sys
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("pycyphal")
pytest.importorskip("rclpy")

from helpers.ros_probe import listen_cmd, publish_cmd
from helpers.runtime_support import (
    Proc,
    child_env,
    command_plan,
    cyphal_udp_lock,
    domain_id,
    generated_or_skip,
    helper_cmd,
    load_records,
    poll_until,
    read_json,
    ros_prefix_for,
    runtime_cmd,
)

numpy = pytest.importorskip("numpy")

pytestmark = [pytest.mark.ros, pytest.mark.slow]

WINDOW_S = 10.0
SENSOR_TOPICS = ("/imu", "/magnetic_field", "/gps_fix", "/pressure", "/battery_state")
ROGUE_NODE_ID = 42
ROGUE_COUNT = 20
START_BOUND_S = 240.0  # the main job's prepare and its three children's start on a loaded 2-core machine


def f16(x: float) -> float:
    return float(numpy.float16(x))


def _sam_or_skip() -> Any:
    gen = generated_or_skip()
    if gen.tables().VEHICLE != "sam":
        pytest.skip("the value checks are written for the SAM spec")
    return gen


def _stop_all(*procs: Proc) -> None:
    for p in procs:
        p.stop()


# ============================================================================================ sensors
@pytest.fixture(scope="module")
def sensor_run(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    gen = _sam_or_skip()
    prefix = ros_prefix_for(gen)
    d = tmp_path_factory.mktemp("udp_sensors")
    env = child_env(prefix, domain_id(1), {"SAM_GENERATED_DIR": str(gen.root)})
    tables = gen.tables()
    in_maps = [m for m in tables.MAPPINGS if m.direction == "uavcan_to_ros"]
    topics = sorted({m.topic.name for m in in_maps})
    udp = ["--transport", "udp", "--iface", "127.0.0.1"]
    with cyphal_udp_lock():
        return _sensor_run(gen, d, env, in_maps, topics, udp)


def _sensor_run(gen: Any, d: Path, env: dict[str, str], in_maps: list[Any], topics: list[str], udp: list[str]
                ) -> dict[str, Any]:
    bridge = Proc("bridge", runtime_cmd("bridge", *udp, "--stats-file", str(d / "bridge.json")), env, d)
    sim = Proc("sim", runtime_cmd("sim", *udp, "--start-file", str(d / "go"), "--duration", str(WINDOW_S),
                                  "--record", str(d / "sim.jsonl"), "--report", str(d / "sim.json")), env, d)
    probe = Proc("probe", listen_cmd(gen.root, topics, d / "probe.json", d / "probe.jsonl", diagnostics=True), env, d)
    try:
        bridge.wait_line("READY", 60)
        sim.wait_line("READY", 60)
        probe.wait_line("READY", 30)

        def bridge_sees_probe_and_devices() -> dict[str, Any] | None:
            s = read_json(d / "bridge.json")
            if not s:
                return None
            subs_ok = all((s["mappings"][m.name].get("ros_subscribers") or 0) > 0 for m in in_maps)
            devs_ok = all(v.get("alive") for v in s["devices"].values())
            return s if subs_ok and devs_ok else None

        before = poll_until(bridge_sees_probe_and_devices, 20, "the bridge's publishers matching the probe")
        sim.wait_line("SYNCHRONISED", 30)  # the devices' clocks follow the bridge's: every stamp a device's own
        (d / "go").touch()
        sim.wait_line("DONE", WINDOW_S + 30)
        assert sim.wait(15) == 0
        report = read_json(d / "sim.json")
        sent = {int(sid): n for dev in report["devices"].values() for sid, n in dev["published"].items()}
        late = {int(sid): n for dev in report["devices"].values() for sid, n in dev["late"].items()}
        expected = {t: sum(sent.get(m.port.subject_id, 0) for m in in_maps if m.topic.name == t) for t in topics}

        def probe_has_all() -> bool:
            p = read_json(d / "probe.json")
            return bool(p) and all(p["counts"].get(t, 0) >= expected[t] for t in topics)

        try:
            poll_until(probe_has_all, 15, "every message at the probe")
        except AssertionError:
            pass  # the counts are compared (and reported) by the tests
        assert probe.stop(signal.SIGTERM) == 0, probe.stderr_tail()
        assert bridge.stop(signal.SIGTERM) == 0, bridge.stderr_tail()
    finally:
        _stop_all(probe, bridge, sim)
    return {
        "gen": gen, "dir": d, "in_maps": in_maps, "topics": topics, "sent": sent, "late": late, "expected": expected,
        "report": report, "before": before, "stats": read_json(d / "bridge.json"),
        "probe": read_json(d / "probe.json"), "tx": load_records(d / "sim.jsonl"),
        "rx": load_records(d / "probe.jsonl"),
    }


def _stamp_ns(msg: dict[str, Any]) -> int:
    return msg["header"]["stamp"]["sec"] * 10**9 + msg["header"]["stamp"]["nanosec"]


def _pairs(run: dict[str, Any], topic: str, subject: int) -> list[tuple[dict[str, Any], dict[str, Any]]]:
    tx = [r for r in run["tx"] if r["dir"] == "tx" and r["subject"] == subject]
    rx = [r for r in run["rx"] if r["topic"] == topic]
    assert len(tx) == len(rx) > 0, f"{topic}: {len(tx)} sent, {len(rx)} received"
    return list(zip(tx, rx, strict=True))


def _get(msg: Any, path: str) -> Any:
    for part in path.split("."):
        m = re.fullmatch(r"(\w+)(?:\[(\d+)\])?", part)
        assert m, path
        msg = msg[m[1]]
        if m[2] is not None:
            msg = msg[int(m[2])]
    return msg


def _num(v: Any) -> float:
    return float(v)  # the probe writes NaN as the string "nan"


def test_udp_sensor_values_after_documented_conversions(sensor_run: dict[str, Any]) -> None:
    run = sensor_run
    for tx, rx in _pairs(run, "/imu", 1100):
        v, m = tx["value"], rx["msg"]
        us = v["timestamp"]["microsecond"]
        assert _stamp_ns(m) == us * 1000 and m["header"]["frame_id"] == "imu_link"
        assert [m["angular_velocity"][k] for k in "xyz"] == v["rate_gyro_latest"]
        assert [m["linear_acceleration"][k] for k in "xyz"] == v["accelerometer_latest"]
        assert abs(m["linear_acceleration"]["z"] - 9.81) < 0.2  # gravity, the vehicle at rest
    for tx, rx in _pairs(run, "/magnetic_field", 1101):
        v, m = tx["value"], rx["msg"]
        assert [m["magnetic_field"][k] for k in "xyz"] == pytest.approx(
            [g * 1e-4 for g in v["magnetic_field_ga"]], rel=1e-12)  # Gauss -> Tesla
        cov = [c * 1e-8 for c in v["magnetic_field_covariance"]]
        assert m["magnetic_field_covariance"] == pytest.approx(cov + [0.0] * (9 - len(cov)), rel=1e-12)
        assert m["header"]["frame_id"] == "magnetometer_link"
        # No device timestamp: the bridge stamps the receive time (after the send, before the probe got it).
        assert tx["wall_ns"] - 2 * 10**9 <= _stamp_ns(m) <= rx["wall_ns"] + 10**6
        assert 0.4e-4 < math.dist((0, 0, 0), [m["magnetic_field"][k] for k in "xyz"]) < 0.6e-4  # ~0.5 G
    for tx, rx in _pairs(run, "/gps_fix", 1102):
        v, m = tx["value"], rx["msg"]
        assert _stamp_ns(m) == v["timestamp"]["microsecond"] * 1000 and m["header"]["frame_id"] == "gps_link"
        assert m["latitude"] == pytest.approx(v["latitude_deg_1e8"] * 1e-8, rel=1e-15)
        assert m["longitude"] == pytest.approx(v["longitude_deg_1e8"] * 1e-8, rel=1e-15)
        assert m["altitude"] == pytest.approx(v["height_ellipsoid_mm"] * 1e-3, rel=1e-15)
        assert m["status"]["status"] == {0: -1, 1: -1, 2: 0, 3: 0}[v["status"]]
        assert m["position_covariance"] == v["position_covariance"] + [0.0] * (9 - len(v["position_covariance"]))
        assert 59.34 < m["latitude"] < 59.36 and 18.06 < m["longitude"] < 18.08  # KTH, at the surface
    for tx, rx in _pairs(run, "/pressure", 1103):
        v, m = tx["value"], rx["msg"]
        assert m["fluid_pressure"] == v["static_pressure"] and m["variance"] == v["static_pressure_variance"]
        assert m["header"]["frame_id"] == "pressure_link"
        assert 101_325 - 100 < m["fluid_pressure"] < 101_325 + 1025 * 9.81 * 10 + 100  # 0..10 m of seawater
    for tx, rx in _pairs(run, "/battery_state", 1104):
        v, m = tx["value"], rx["msg"]
        assert m["voltage"] == v["voltage"] and m["current"] == v["current"]
        assert m["temperature"] == pytest.approx(v["temperature"] - 273.15, abs=1e-3)  # K -> degC
        assert m["percentage"] == pytest.approx(v["state_of_charge_pct"] * 0.01, rel=1e-6)
        assert m["present"] is True and m["header"]["frame_id"] == "base_link"
        assert math.isnan(_num(m["charge"]))
    _check_spec_constants(run)


def _check_spec_constants(run: dict[str, Any]) -> None:
    """Every `{value: ...}` line of the spec's UAVCAN->ROS mappings is in every received message."""
    from sam_codegen.frontend.loader import load_spec_file

    spec_file = Path(__file__).resolve().parents[2] / "spec" / "interfaces.yaml"
    spec = load_spec_file(spec_file)
    assert spec.bridge is not None
    by_topic: dict[str, list[Any]] = {}
    for r in run["rx"]:
        by_topic.setdefault(r["topic"], []).append(r["msg"])
    checked = 0
    for mapping in spec.bridge.mappings:
        if mapping.direction != "uavcan_to_ros" or mapping.topic not in SENSOR_TOPICS:
            continue
        for link in mapping.links:
            if link.value is None or link.uavcan_path:
                continue
            for msg in by_topic.get(mapping.topic, []):
                got = _get(msg, link.ros_path)
                if isinstance(link.value, float) and math.isnan(link.value):
                    assert math.isnan(_num(got)), (mapping.name, link.ros_path, got)
                else:
                    assert got == link.value, (mapping.name, link.ros_path, got, link.value)
                checked += 1
    assert checked > 0


def test_udp_nothing_lost_or_reordered_over_10s_at_nominal_rates(sensor_run: dict[str, Any]) -> None:
    run = sensor_run
    stats, probe = run["stats"]["mappings"], run["probe"]
    rows = []
    for m in run["in_maps"]:
        sent, late = run["sent"][m.port.subject_id], run["late"].get(m.port.subject_id, 0)
        st = stats[m.name]
        rows.append(f"{m.topic.name:30} subject {m.port.subject_id} nominal {m.rate_hz * WINDOW_S:6.0f} "
                    f"sent {sent:5d} skipped {late:4d} bridged {st['published']:5d} "
                    f"received {probe['counts'][m.topic.name]:5d}")
        # The device kept its schedule: each tick sent, or skipped (counted) when the machine held its loop up.
        assert sent + late >= 0.9 * m.rate_hz * WINDOW_S, f"{m.topic.name}: the device fell behind its schedule"
        assert sent > 0, m.topic.name
        assert st["received"] == st["published"] == sent and st["dropped"] == {}, (m.name, st)
    for t in run["topics"]:
        assert probe["counts"][t] == run["expected"][t], (t, probe["counts"][t], run["expected"][t])
    # In order: device timestamps strictly increase at the receiver.
    for topic in ("/imu", "/gps_fix"):
        stamps = [_stamp_ns(r["msg"]) for r in run["rx"] if r["topic"] == topic]
        assert all(a < b for a, b in itertools.pairwise(stamps)), f"{topic} reordered"
    # Latency device send -> ROS subscriber, for the report.
    lat = [(rx["wall_ns"] - tx["wall_ns"]) / 1e6 for tx, rx in _pairs(run, "/imu", 1100)]
    q = statistics.quantiles(lat, n=100)
    figures = "\n".join(rows) + (f"\n/imu latency device->ROS subscriber: median {statistics.median(lat):.2f} ms, "
                                 f"p99 {q[98]:.2f} ms, max {max(lat):.2f} ms")
    (run["dir"] / "figures.txt").write_text(figures + "\n")
    print("\n" + figures)


def test_udp_heartbeats_and_diagnostics(sensor_run: dict[str, Any]) -> None:
    run = sensor_run
    tables = run["gen"].tables()
    for name, dev in run["before"]["devices"].items():
        assert dev["alive"] and dev["health"] == "NOMINAL" and dev["mode"] == "OPERATIONAL", (name, dev)
    assert run["before"]["bridge"]["node_id"] == tables.BRIDGE_NODE_ID
    diag = run["probe"]["diagnostics"]
    for dev in tables.DEVICES:
        assert f"{tables.BRIDGE_NAME}/device/{dev.name}" in diag
    imu = diag[f"{tables.BRIDGE_NAME}/mapping/imu"]
    assert imu["values"]["topic"] == "/imu" and imu["values"]["dropped"] == "0"


# ============================================================================================ commands
@pytest.fixture(scope="module")
def command_run(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    gen = _sam_or_skip()
    prefix = ros_prefix_for(gen)
    d = tmp_path_factory.mktemp("udp_commands")
    tables = gen.tables()
    env = child_env(prefix, domain_id(2), {"SAM_GENERATED_DIR": str(gen.root)})
    # The bridge takes its transport and node id from the standard Cyphal register variables.
    bridge_env = {**env, "UAVCAN__UDP__IFACE": "127.0.0.1", "UAVCAN__NODE__ID": str(tables.BRIDGE_NODE_ID)}
    actuators = [dv.name for dv in tables.DEVICES if dv.subscribes]
    plan = command_plan(tables, 20)
    (d / "plan.json").write_text(json.dumps({"rate_hz": 20, "topics": plan}))
    with cyphal_udp_lock():
        return _command_run(gen, d, env, bridge_env, actuators, plan)


def _command_run(gen: Any, d: Path, env: dict[str, str], bridge_env: dict[str, str], actuators: list[str],
                 plan: dict[str, Any]) -> dict[str, Any]:
    tables = gen.tables()
    bridge = Proc("bridge", runtime_cmd("bridge", "--stats-file", str(d / "bridge.json")), bridge_env, d)
    sim = Proc("sim", runtime_cmd("sim", "--transport", "udp", "--iface", "127.0.0.1", "--devices",
                                  ",".join(actuators), "--record", str(d / "sim.jsonl"),
                                  "--report", str(d / "sim.json")), env, d)
    procs = [bridge, sim]
    try:
        bridge.wait_line("READY", 60)
        sim.wait_line("READY", 60)
        pub = Proc("publisher", publish_cmd(gen.root, d / "plan.json", d / "pub.json"), env, d)
        procs.append(pub)
        pub.wait_line("DONE", 60)
        want = {m.port.subject_id: len(plan[m.topic.name]) for m in tables.MAPPINGS
                if m.direction == "ros_to_uavcan"}

        def accepted() -> dict[int, int]:
            out: dict[int, int] = {}
            for r in load_records(d / "sim.jsonl"):
                if r["dir"] == "rx" and r["accepted"]:
                    out[r["subject"]] = out.get(r["subject"], 0) + 1
            return out

        poll_until(lambda: all(accepted().get(s, 0) >= n for s, n in want.items()), 20, "the commands at the sim")
        cmd_subject = next(m.port.subject_id for m in tables.MAPPINGS
                           if m.topic.name == "/longitudinal_weight_position")
        rogue = Proc("rogue", helper_cmd("rogue_node.py", "--generated", str(gen.root), "--node-id",
                                         str(ROGUE_NODE_ID), "--publish", f"1100:{ROGUE_COUNT}", "--publish",
                                         f"{cmd_subject}:{ROGUE_COUNT}"), env, d)
        procs.append(rogue)
        rogue.wait_line("DONE", 60)
        poll_until(lambda: ((read_json(d / "bridge.json") or {}).get("mappings", {}).get("imu", {})
                            .get("dropped", {}).get("unknown_source", 0) >= ROGUE_COUNT), 10, "the rogue's drops")
        poll_until(lambda: sum(1 for r in load_records(d / "sim.jsonl") if r["dir"] == "rx" and not r["accepted"])
                   >= ROGUE_COUNT, 10, "the rogue's commands at the sim")
        assert sim.stop(signal.SIGTERM) == 0, sim.stderr_tail()
        assert bridge.stop(signal.SIGTERM) == 0, bridge.stderr_tail()
    finally:
        _stop_all(*procs)
    return {"gen": gen, "plan": plan, "stats": read_json(d / "bridge.json"), "report": read_json(d / "sim.json"),
            "rx": [r for r in load_records(d / "sim.jsonl") if r["dir"] == "rx"], "cmd_subject": cmd_subject}


def _clip(v: float, lo: float, hi: float) -> float:
    return max(lo, min(hi, v))


def test_udp_commands_reach_the_actuators(command_run: dict[str, Any]) -> None:
    run = command_run
    plan, tables = run["plan"], run["gen"].tables()
    by_subject: dict[int, list[dict[str, Any]]] = {}
    for r in run["rx"]:
        if r["accepted"]:
            by_subject.setdefault(r["subject"], []).append(r)
    expect: dict[int, list[dict[str, Any]]] = {
        1200: [{"rpm": int(_clip(c["thruster_1_rpm"], -131072, 131071))} for c in plan["/thruster_rpms"]],
        1201: [{"rpm": int(_clip(c["thruster_2_rpm"], -131072, 131071))} for c in plan["/thruster_rpms"]],
        1202: [{"vertical_radians": f16(_clip(c["thruster_vertical_radians"], -0.12, 0.12)),  # the spec's limits
                "horizontal_radians": f16(_clip(c["thruster_horizontal_radians"], -0.12, 0.12))}
               for c in plan["/thruster_angles"]],
        1203: [{"weight_1_offset_radians": f16(_clip(c["weight_1_offset_radians"], -1.5708, 1.5708)),
                "weight_2_offset_radians": f16(_clip(c["weight_2_offset_radians"], -1.5708, 1.5708))}
               for c in plan["/ballast_angles"]],
        1204: [{"percent": f16(_clip(c["percent"], 0, 100))} for c in plan["/longitudinal_weight_position"]],
        1205: [{"percent": f16(_clip(c["percent"], 0, 100))} for c in plan["/buoyancy_piston_position"]],
    }
    for m in tables.MAPPINGS:
        if m.direction != "ros_to_uavcan":
            continue
        got = by_subject.get(m.port.subject_id, [])
        # Each command went to its configured destination's subject, from the bridge's node id, in order.
        assert [r["value"] for r in got] == expect[m.port.subject_id], m.name
        assert {r["source"] for r in got} == {tables.BRIDGE_NODE_ID}
        assert {r["node_id"] for r in got} == {m.destination_node_id}
        st = run["stats"]["mappings"][m.name]
        assert st["received"] == st["published"] == len(expect[m.port.subject_id]) and st["dropped"] == {}
    sat = run["stats"]["mappings"]
    assert sat["thruster_1_rpm"]["saturated"] == {"thruster_1_rpm.rpm": 1}
    assert sat["longitudinal_weight"]["saturated"] == {"longitudinal_weight.percent": 1}
    assert sat["buoyancy_piston"]["saturated"] == {"buoyancy_piston.percent": 1}
    assert sat["thrust_vector"]["saturated"] == {"thrust_vector.vertical_radians": 1,
                                                 "thrust_vector.horizontal_radians": 1}
    assert sat["ballast"]["saturated"] == {"ballast.weight_1_offset_radians": 1, "ballast.weight_2_offset_radians": 1}
    assert run["stats"]["bridge"]["transport"].startswith("env(")  # configured by UAVCAN__UDP__IFACE


def test_udp_unknown_sender_is_not_bridged_and_counted(command_run: dict[str, Any]) -> None:
    imu = command_run["stats"]["mappings"]["imu"]  # no IMU device in this run: only the rogue sent on 1100
    assert imu["received"] == ROGUE_COUNT and imu["published"] == 0
    assert imu["dropped"] == {"unknown_source": ROGUE_COUNT}


def test_udp_actuator_ignores_foreign_commands(command_run: dict[str, Any]) -> None:
    sid = str(command_run["cmd_subject"])
    cmds = next(d["commands"][sid] for d in command_run["report"]["devices"].values() if sid in d["commands"])
    assert cmds["rejected"] == ROGUE_COUNT and cmds["rejected_sources"] == {str(ROGUE_NODE_ID): ROGUE_COUNT}
    assert cmds["accepted"] == len(command_run["plan"]["/longitudinal_weight_position"])


# ============================================================================================ the main job
def _run_cmd(gen: Any, prefix: Path, *extra: str) -> list[str]:
    cmd = runtime_cmd("run", "--no-build", "--plain", "--generated", str(gen.root), *extra)
    if prefix != Path(sys.prefix).absolute():
        cmd += ["--ros-prefix", str(prefix)]
    return cmd


def _table_rows(lines: list[str]) -> dict[str, list[str]]:
    return {ln.split()[0]: ln.split() for ln in lines if ln.startswith("/")}


def test_run_job_with_duration(tmp_path: Path) -> None:
    gen = generated_or_skip()
    prefix = ros_prefix_for(gen)
    env = child_env(prefix, domain_id(3))
    with cyphal_udp_lock():
        p = Proc("run", _run_cmd(gen, prefix, "--duration", "7", "--log-dir", str(tmp_path)), env, tmp_path)
        try:  # the 7 s count from the vehicle's start: the bound has the start-up on a loaded machine on top
            assert p.wait(START_BOUND_S + 60) == 0, p.stderr_tail()
        finally:
            p.stop()
    out = p.lines
    final = out[next(i for i, ln in enumerate(out) if ln.startswith("final (duration)")):]
    rows = _table_rows(final)
    tables = gen.tables()
    for m in tables.MAPPINGS:
        if m.direction == "uavcan_to_ros":  # data flowed on every topic (its rate against the schedule: test_sim)
            assert int(rows[m.topic.name][4]) > 0, (m.topic.name, rows[m.topic.name])
    for dev in tables.DEVICES:
        line = next(ln for ln in final if ln.startswith(dev.name + " "))
        assert line.rstrip().endswith("ok"), line
    assert any(re.match(r"bridge: \d+ mappings, 0 dropped", ln) for ln in final), final


def test_run_job_stops_cleanly_on_ctrl_c(tmp_path: Path) -> None:
    gen = generated_or_skip()
    prefix = ros_prefix_for(gen)
    env = child_env(prefix, domain_id(4))
    with cyphal_udp_lock():
        p = Proc("run", _run_cmd(gen, prefix, "--log-dir", str(tmp_path)), env, tmp_path)
        try:
            header = p.wait_line(f"{gen.tables().VEHICLE} bridge run", START_BOUND_S)
            pids = [int(x) for x in re.findall(r"pid (\d+)", header)]
            assert len(pids) == 3  # sim, bridge, node host
            # Wait until data flows (a non-zero /imu rate in a table), then Ctrl-C.
            # the header comes while the children still start: their start-up is in this bound too
            poll_until(lambda: any(ln.startswith("/imu") and float(ln.split()[2]) > 0 for ln in p.lines),
                       START_BOUND_S, "data in the monitor")
            os.kill(p.proc.pid, signal.SIGINT)
            assert p.wait(30) == 0, p.stderr_tail()
        finally:
            p.stop()
    for pid in pids:
        assert not Path(f"/proc/{pid}").exists() or "zombie" in Path(f"/proc/{pid}/status").read_text().lower(), pid
    assert any(ln.startswith("final (SIGINT)") for ln in p.lines)
    assert (tmp_path / "bridge.log").read_text().count("READY") == 1
