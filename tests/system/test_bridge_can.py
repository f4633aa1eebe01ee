"""The bridge over Cyphal/CAN (python-can), everything in one process: simulated devices, the bridge, an rclpy
probe node and a rogue node share one python-can ``virtual`` bus (Classic CAN and CAN FD; multi-frame
transfers). SocketCAN is supported for real hardware but needs a kernel with CAN: skipped where there is none.

The scenario runs in a helper process (tests/helpers/can_scenario.py) so that rclpy and the python-can
channel never outlive the test.
"""

from __future__ import annotations

import json
import os
import socket
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("pycyphal")
pytest.importorskip("can")
pytest.importorskip("rclpy")

from helpers.runtime_support import HELPERS, child_env, domain_id, generated_or_skip, load_records, ros_prefix_for

numpy = pytest.importorskip("numpy")

pytestmark = [pytest.mark.ros, pytest.mark.slow]


def f16(x: float) -> float:
    return float(numpy.float16(x))


def _run_scenario(tmp_path: Path, iface: str, mtu: int, rate_scale: float, duration: float, offset: int,
                  bridge_env: bool = False, wire: str = "codec") -> dict[str, Any]:
    gen = generated_or_skip()
    if gen.tables().VEHICLE != "sam":
        pytest.skip("the value checks are written for the SAM spec")
    prefix = ros_prefix_for(gen)
    out = tmp_path / "result.json"
    cmd = [sys.executable, str(HELPERS / "can_scenario.py"), "--iface", iface, "--mtu", str(mtu),
           "--rate-scale", str(rate_scale), "--duration", str(duration), "--out", str(out)]
    if bridge_env:
        cmd.append("--bridge-env")
    cmd += ["--wire", wire]
    env = child_env(prefix, domain_id(offset), {"SAM_GENERATED_DIR": str(gen.root)})
    proc = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0 and out.exists(), f"scenario failed:\n{proc.stdout[-3000:]}\n{proc.stderr[-5000:]}"
    assert "Traceback" not in proc.stderr, proc.stderr[-5000:]
    result = json.loads(out.read_text())
    assert result["wire"] == wire, "the bridge did not take the path asked for"
    return result


def _check(res: dict[str, Any], record: Path) -> None:
    # Every sensor and feedback message the devices sent reached ROS: counts equal per topic, no drops.
    assert res["received_counts"] == res["expected"], (res["received_counts"], res["expected"])
    assert all(v > 0 for v in res["expected"].values())
    rogue = res["rogue"]
    for name, m in res["bridge"]["mappings"].items():
        drops = dict(m["dropped"])
        if name == rogue["imu_mapping"]:
            # The node the spec does not allow is not bridged, and each of its transfers is a counted drop.
            assert drops.pop("unknown_source") == rogue["count"]
        assert drops == {}, (name, m)
        assert m["published"] + m["dropped_total"] == m["received"], (name, m)
    imu = res["bridge"]["mappings"]["imu"]
    # RawIMU with its full 6x6 covariance is 120 bytes: multi-frame on Classic CAN and on CAN FD.
    assert imu["cyphal"]["frames"] > imu["cyphal"]["transfers"] > 0, imu["cyphal"]
    assert imu["cyphal"]["errors"] == 0 and imu["cyphal"]["deserialization_failures"] == 0

    # Values: the i-th ROS message is the i-th transfer the device sent, after the documented conversions.
    tx = [r["value"] for r in load_records(record) if r["dir"] == "tx" and r["subject"] == 1100]
    recv = res["received"]["/imu"]
    assert len(tx) == len(recv) > 0
    for sent, got in zip(tx, recv, strict=True):
        us = sent["timestamp"]["microsecond"]
        assert (got["header"]["stamp"]["sec"], got["header"]["stamp"]["nanosec"]) == (us // 10**6, us % 10**6 * 1000)
        assert got["header"]["frame_id"] == "imu_link"
        assert [got["linear_acceleration"][k] for k in "xyz"] == sent["accelerometer_latest"]
        assert [got["angular_velocity"][k] for k in "xyz"] == sent["rate_gyro_latest"]
        assert got["orientation_covariance"][0] == -1.0

    # Commands: every one reached its actuator, from the bridge's node id, with the right (saturated) value.
    devs = res["sim"]["devices"]
    plan = res["plan"]
    n_rpm = len(plan["/thruster_rpms"])
    assert devs["thruster_1"]["commands"]["1200"]["accepted"] == n_rpm
    assert devs["thruster_1"]["commands"]["1200"]["last"] == {"rpm": 131071}  # 1e6 saturates to int18
    assert devs["thruster_2"]["commands"]["1201"]["last"] == {"rpm": -131072}
    assert devs["longitudinal_weight"]["commands"]["1204"]["last"] == {"percent": 100.0}  # 150 % -> 100
    assert devs["buoyancy_piston"]["commands"]["1205"]["last"] == {"percent": 0.0}  # -20 % -> 0
    last_tv = plan["/thruster_angles"][-1]
    assert devs["thrust_vector"]["commands"]["1202"]["last"] == {
        "vertical_radians": f16(0.12), "horizontal_radians": f16(-0.12)}  # the last: 0.5 and -1e6, the spec's limits
    assert last_tv == {"thruster_vertical_radians": 0.5, "thruster_horizontal_radians": -1e6}
    total_rejected = sum(c["rejected"] for d in devs.values() for c in d["commands"].values())
    assert total_rejected == rogue["count"]
    assert devs["thruster_1"]["commands"][str(rogue["command_subject"])]["rejected_sources"] == {
        str(rogue["node_id"]): rogue["count"]}
    sat = res["bridge"]["mappings"]
    assert sat["thruster_1_rpm"]["saturated"] == {"thruster_1_rpm.rpm": 1}
    assert sat["longitudinal_weight"]["saturated"] == {"longitudinal_weight.percent": 1}

    # Every device's heartbeat was seen.
    assert all(d["seen"] and d["health"] == "NOMINAL" for d in res["devices"].values()), res["devices"]

    # The devices stamped in the bridge's time (their clocks synchronised before they published): the master's
    # transmission times came from python-can's transmit thread, not from its send calls on this loaded loop.
    assert res["time_sync_master"]["tx_time"].get("can_thread", 0) >= 1, res["time_sync_master"]


def test_virtual_can_fd_one_process(tmp_path: Path) -> None:
    res = _run_scenario(tmp_path, f"virtual:samfd{os.getpid()}", 64, rate_scale=1.0, duration=3.0, offset=11)
    _check(res, tmp_path / "result.sim.jsonl")
    # At nominal rates (IMU 100 Hz) for 3 s: the device's schedule had 300 ticks (less the edges); the ones its
    # event loop was too late for are skipped and counted, never sent in a burst. The device shares this process
    # with the bridge and the probe, so how many it skips depends on the CPU it gets (up to ~25 % with other
    # test processes beside it); everything it sent is checked above.
    imu_dev = res["sim"]["devices"]["imu"]
    sent, late = imu_dev["published"]["1100"], imu_dev["late"].get("1100", 0)
    assert sent == res["expected"]["/imu"] and sent + late >= 0.95 * 300, imu_dev
    # How many of the ticks it made is the CPU's business (146 of 300 with another process burning a core, 13 in a
    # CI-like run on a machine twice as slow with 4 workers: a floor in ticks failed there): the floor only says a
    # real multi-frame stream flowed, several transfers (each transfer id in turn) reassembled and checked above.
    assert sent >= 5, imu_dev


def test_virtual_classic_can_one_process_from_env_registers(tmp_path: Path) -> None:
    """Classic CAN (MTU 8: 18 frames per IMU message); the bridge configured by UAVCAN__CAN__IFACE/MTU, on its object
    path (the object converters: still selectable, so still tested end to end).
    python-can's virtual bus in Python carries about 60 such IMU transfers/s on this machine, so the rates
    are scaled by 1/4 here (a real 1 Mbit/s bus carries them at the nominal rates)."""
    res = _run_scenario(tmp_path, f"virtual:samcc{os.getpid()}", 8, rate_scale=0.25, duration=4.0, offset=12,
                        bridge_env=True, wire="object")
    _check(res, tmp_path / "result.sim.jsonl")
    imu = res["bridge"]["mappings"]["imu"]["cyphal"]
    assert imu["frames"] >= 10 * imu["transfers"], imu  # really Classic CAN frames


def _socketcan_iface() -> str | None:
    try:
        socket.socket(socket.AF_CAN, socket.SOCK_RAW, socket.CAN_RAW).close()
    except (OSError, AttributeError):
        return None
    for dev in sorted(Path("/sys/class/net").glob("*")):
        try:
            if (dev / "type").read_text().strip() == "280":  # ARPHRD_CAN
                return dev.name
        except OSError:
            continue
    return ""


def test_socketcan_one_process(tmp_path: Path) -> None:
    iface = _socketcan_iface()
    if iface is None:
        pytest.skip("SocketCAN: this kernel has no CAN support (AF_CAN is refused), so it cannot be exercised "
                    "here; the bridge still supports socketcan:IFACE for real hardware")
    if not iface:
        pytest.skip("SocketCAN: the kernel has CAN but no CAN/vcan interface is up (e.g. `ip link add vcan0 "
                    "type vcan && ip link set vcan0 up`)")
    res = _run_scenario(tmp_path, f"socketcan:{iface}", 64, rate_scale=0.5,
                        duration=3.0, offset=13)
    _check(res, tmp_path / "result.sim.jsonl")
