"""Faults at run time (issue 4): bad input, faults and overload never crash the bridge or lose data silently.

Two scenarios, each in a helper process (tests/helpers/fault_scenario.py) so that rclpy, pycyphal and python-can
never outlive the test; the tests check the figures they write:

- Cyphal/UDP on 127.0.0.1 (under the machine-wide UDP lock): the bridge and an rclpy probe; a separate injector
  process (tests/helpers/fault_injector.py) plays the IMU (node 11) and a spoofer (node 42) with raw datagrams:
  spoofed transfers, malformed/truncated/CRC-broken datagrams, multi-frame transfers missing a frame,
  undecodable transfers, reordered and duplicated transfer ids, out-of-order/unknown device stamps, float16
  limits, and two bursts of 5000 IMU messages (as fast as possible, ~80,000/s; and at 3,000/s).
- Cyphal/CAN FD on a python-can virtual bus, all in one process: the bridge (its CAN media wrapped by a
  fault-injecting python-can bus), every simulated device and an rclpy probe; a slow ROS subscriber in its own
  process. Phases: out-of-range commands, the slow subscriber, transient bus errors, the interface going down
  and back, the GPS's heartbeat stopping and resuming, /diagnostics content.

Each test prints its figures on lines starting with ``FIGURES:`` (run with -s to see them).
"""

from __future__ import annotations

import asyncio
import itertools
import json
import logging
import math
import os
import re
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("pycyphal")
pytest.importorskip("can")
pytest.importorskip("rclpy")

from helpers.runtime_support import HELPERS, child_env, cyphal_udp_lock, domain_id, generated_or_skip, ros_prefix_for

from sam_runtime.bridge.link import CHECK_PERIOD_S, REOPEN_BACKOFF_S

pytestmark = [pytest.mark.ros, pytest.mark.slow]

BRIDGE = "uavcan_ros_bridge"
F16_MAX = 65504.0
# The spec's limits of the thrust vector (+-0.12 rad) and the ballast (+-1.5708 rad), as float16 on the bus
NOZZLE_F16, BALLAST_F16 = 0.1199951171875, 1.5703125


def _figures(title: str, data: Any) -> None:
    print(f"\nFIGURES: {title}: {json.dumps(data, sort_keys=True, default=str)}")


def _run(tmp: Path, mode: str, *extra: str, offset: int) -> dict[str, Any]:
    gen = generated_or_skip()
    if gen.tables().VEHICLE != "sam":
        pytest.skip("the fault scenarios are written for the SAM spec")
    prefix = ros_prefix_for(gen)
    out = tmp / f"{mode}.json"
    cmd = [sys.executable, str(HELPERS / "fault_scenario.py"), mode, *extra, "--out", str(out)]
    env = child_env(prefix, domain_id(offset), {"SAM_GENERATED_DIR": str(gen.root)})
    proc = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=240)
    (tmp / f"{mode}.stderr").write_text(proc.stderr)
    assert proc.returncode == 0 and out.exists(), f"scenario failed:\n{proc.stdout[-3000:]}\n{proc.stderr[-6000:]}"
    res = json.loads(out.read_text())
    res["stdout"] = proc.stdout
    res["stderr"] = proc.stderr
    return res


@pytest.fixture(scope="module")
def udp_run(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    tmp = tmp_path_factory.mktemp("faults_udp")
    with cyphal_udp_lock():
        return _run(tmp, "udp", offset=21)


@pytest.fixture(scope="module")
def can_run(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    tmp = tmp_path_factory.mktemp("faults_can")
    return _run(tmp, "can", "--iface", f"virtual:faults{os.getpid()}", offset=22)


def _accounted(ph: dict[str, Any]) -> None:
    """Every transfer the injector sent was published or counted as dropped: nothing is silent."""
    assert ph["settled"], ph
    assert ph["published"] + ph["dropped_total"] == ph["sent_total"], ph


def _closed_fault_media(exc: str) -> bool:
    """A ResourceClosedError of a python-can media on the fault scenario's own virtual bus.

    >>> _closed_fault_media("pycyphal.transport._error.ResourceClosedError: PythonCANMedia('virtual:faults37', mtu=64)")
    True
    >>> _closed_fault_media("ValueError: boom")
    False
    """
    return "ResourceClosedError: PythonCANMedia('virtual:faults" in exc


def _silence_explained(age_s: float, received_t: float, sends: list[float], stalls: list[list[float]],
                       period: float = 1.0, slack: float = 0.05) -> bool:
    """Whether "heartbeat lost: none for ``age_s`` s", received by the probe at ``received_t`` (monotonic, the
    scenario's process), is what a working bridge reports: the device's own heartbeats (``sends``, the times its
    heartbeat publisher sent them) left a silence that long, or the event loop the device and the bridge share
    stalled (``stalls``: (when the late timer ran, how late it was), measured) long enough to hold the device's
    heartbeat or the bridge's handling of it. Generous where the timing is unknown (the report may have waited for
    the probe up to ``age_s``), never explained without a silence or a stall to show for it.

    >>> _silence_explained(3.2, 100.0, [95.0, 96.0, 97.0, 98.0, 99.0, 99.9], [])  # heartbeats every second
    False
    >>> _silence_explained(3.2, 100.0, [95.0, 96.0, 96.8], [])  # the device itself silent since 96.8
    True
    >>> _silence_explained(3.9, 100.0, [95.0, 96.0, 97.0, 99.9], [[99.9, 2.8]])  # a stall of 2.8 s held it
    True
    >>> _silence_explained(3.9, 100.0, [95.0, 96.0, 97.0, 99.9], [[99.9, 0.5]])  # too short a stall
    False
    """
    lo, hi = received_t - 2 * age_s - period, received_t
    sent = sorted(t for t in sends if t <= hi)
    gaps = [b - a for a, b in itertools.pairwise(sent) if b >= lo] + [hi - sent[-1] if sent else math.inf]
    stalled = sum(lag for t, lag in stalls if t >= lo and t - lag <= hi + age_s)
    return max(gaps) + stalled >= age_s - slack


def _device_ok_or_silence_explained(res: dict[str, Any], dev: str, st: dict[str, Any]) -> None:
    """A device's report: OK with its heartbeat alive, or ERROR "heartbeat lost" that the device's own heartbeats
    and the measured loop stalls explain (the simulated devices share the bridge's process and loop: on a loaded
    machine they may go unheard for 3 s, and the bridge must say so)."""
    if st["level"] == 0 and st["values"]["alive"] == "True":
        return
    age = float(st["values"].get("age_s", "nan"))
    assert st["level"] == 2 and st["message"].startswith("heartbeat lost") and age >= 3.0, (dev, st)
    sends, stalls = res["heartbeat_sends"].get(dev, []), res["loop_stalls"]
    assert _silence_explained(age, st["t"], sends, stalls), (
        dev, st, "sent around it:", [round(t - st["t"], 3) for t in sends if abs(t - st["t"]) < 3 * age],
        "stalls around it:", [(round(t - st["t"], 3), lag) for t, lag in stalls if abs(t - st["t"]) < 3 * age])


def _no_tracebacks(res: dict[str, Any]) -> None:
    """No exception escaped the bridge's loops (pycyphal logs what it catches itself with a traceback: only the
    injected faults may appear there)."""
    for block in res["stderr"].split("Traceback (most recent call last):")[1:]:
        exc = next((ln for ln in block.splitlines()[1:] if ln.strip() and not ln.startswith(" ")), "")
        # pycyphal logs (with a traceback) what its own background publishers meet: the injected fault itself, or,
        # when the injected ENETDOWN has made a media close itself, that closed media of the test's bus.
        assert "(injected CAN fault)" in exc or _closed_fault_media(exc), block[:3000]
    assert "Task exception was never retrieved" not in res["stderr"]
    assert "Task was destroyed but it is pending" not in res["stderr"]


# ============================================================================================ UDP
def test_spoofed_source_is_dropped_and_counted(udp_run: dict[str, Any]) -> None:
    ph = udp_run["phases"]["spoof"]
    _figures("spoofed source (node 42 on the IMU subject, UDP)", {
        k: ph[k] for k in ("sent", "received", "published", "dropped", "ros_received")})
    _accounted(ph)
    assert ph["published"] == 0 and ph["ros_received"] == 0
    assert ph["dropped"] == {"unknown_source": 50}


def test_malformed_and_truncated_frames_are_counted(udp_run: dict[str, Any]) -> None:
    ph = udp_run["phases"]["malformed"]
    inj = ph["injector"]
    _figures("malformed/truncated datagrams (UDP)", {
        "datagrams": inj["datagrams"], "kinds": inj["kinds"], "published": ph["published"],
        "dropped": ph["dropped"], "cyphal": ph["cyphal"]})
    # 60 datagrams that are no Cyphal frame at all, 20 transfers failing their CRC, 10 missing their last frame.
    assert ph["cyphal"]["errors"] == 90
    # The 60 by kind too (issue 29), none blamed on a node: garbage fails the header CRC as a broken header does.
    assert ph["cyphal"]["error_kinds"] == {"INTEGRITY_ERROR.node11": 20, "MULTIFRAME_MISSING_FRAMES.node11": 10,
                                           "HEADER_CRC": 40, "TRUNCATED_HEADER": 20}
    # The 30 broken transfers of the accepted source are lost, each counted once; the valid one is published.
    _accounted(ph)
    assert ph["dropped"] == {"lost": 30} and ph["published"] == 1 == ph["ros_received"]


def test_undecodable_transfers_are_counted(udp_run: dict[str, Any]) -> None:
    ph = udp_run["phases"]["undecodable"]
    _figures("undecodable transfers (covariance length 200 > 36, UDP)", {
        k: ph[k] for k in ("sent", "received", "published", "dropped", "cyphal")})
    assert ph["cyphal"]["deserialization_failures"] == 20
    _accounted(ph)
    assert ph["dropped"] == {"lost": 20} and ph["published"] == 1


def test_reordered_and_duplicated_transfers(udp_run: dict[str, Any]) -> None:
    """Transfer ids t, t+2, t+1, t+1, t+3: pycyphal discards the late and the duplicate one (counted as errors);
    the bridge counts t+1 as lost once, never twice, and publishes t, t+2, t+3 in arrival order."""
    ph = udp_run["phases"]["reorder"]
    _figures("reordered/duplicate transfer ids (UDP)", {
        k: ph[k] for k in ("injector", "published", "dropped", "cyphal")})
    assert ph["cyphal"]["errors"] == 2 and ph["cyphal"]["error_kinds"] == {"UNEXPECTED_TRANSFER_ID.node11": 2}
    _accounted(ph)
    assert ph["published"] == 3 and ph["dropped"] == {"lost": 1}


def test_device_stamps_unknown_stamps_and_float16_specials(udp_run: dict[str, Any]) -> None:
    ph = udp_run["phases"]["stamps"]
    recs = ph["records"]
    _figures("device stamps and float16 limits (UDP)", {
        "sent": ph["sent"], "published": ph["published"], "out_of_order": ph["out_of_order"],
        "stamps_ns": [r["stamp_ns"] for r in recs]})
    _accounted(ph)
    assert ph["published"] == 6 == len(recs)
    sent_us = ph["injector"]["stamps_us"]
    # An older stamp is published anyway, in arrival order, and counted.
    assert [r["stamp_ns"] for r in recs[:4]] == [us * 1000 for us in sent_us[:4]]
    assert ph["out_of_order"] == 1
    # Stamp 0 (unknown): the receive time of the bridge.
    lo, hi = ph["wall_window_ns"]
    assert lo <= recs[4]["stamp_ns"] <= hi and recs[4]["stamp_ns"] <= recs[4]["recv_wall_ns"]
    # float16 NaN/+-inf pass to ROS unchanged; the float16 limits stay what they are.
    gyro = [float(x) for x in recs[5]["gyro"]]
    assert math.isnan(gyro[0]) and gyro[1] == math.inf and gyro[2] == -math.inf
    assert recs[5]["acc"] == [F16_MAX, -F16_MAX, 0.0]
    assert all(r["frame_id"] == "imu_link" for r in recs)


@pytest.mark.parametrize("phase", ["burst_max", "burst_paced"])
def test_burst_above_capacity_every_message_published_or_counted(udp_run: dict[str, Any], phase: str) -> None:
    ph = udp_run["phases"][phase]
    inj = ph["injector"]
    _figures(f"burst {phase} (UDP, 5000 IMU + 10 trailing)", {
        "sent": ph["sent_total"], "sender_rate_hz": inj["burst_rate_hz"], "burst_s": inj["burst_s"],
        "received_by_bridge": ph["received"], "published": ph["published"], "dropped": ph["dropped"],
        "pycyphal": ph["cyphal"], "ros_subscriber_received": ph["ros_received"], "settle_s": ph["seconds"]})
    # received by the transport + counted losses == sent; published + every drop == sent.
    assert ph["cyphal"]["transfers"] + ph["dropped"].get("lost", 0) == ph["sent_total"]
    _accounted(ph)
    assert set(ph["dropped"]) <= {"lost"}
    assert ph["published"] >= 10  # the trailing messages after the burst at least
    assert ph["ros_received"] <= ph["published"]


def test_udp_drops_are_logged_at_a_bounded_rate(udp_run: dict[str, Any]) -> None:
    """Many drops, a handful of log lines: one per (mapping, reason) per log_interval at most."""
    lines = udp_run["log_lines"]
    imu = udp_run["bridge"]["mappings"]["imu"]
    uptime, interval = udp_run["bridge"]["bridge"]["uptime_s"], udp_run["log_interval"]
    _figures("bounded-rate logging (UDP)", {"log_lines": lines, "drops": imu["dropped"],
                                            "uptime_s": uptime, "log_interval_s": interval})
    limit = 1 + math.ceil(uptime / interval)
    # Every lost transfer is an occurrence: the 50 broken on purpose, and what the bursts lose (how many depends on
    # how fast the injector gets the CPU and on the receive buffer: 3,878 of the bursts' 10,000 with a CPU burner
    # beside the test when pycyphal's threads received them; none to a few thousand since the bridge receives on
    # its loop through one socket), yet a handful of lines.
    assert imu["dropped"]["lost"] >= 50 and 1 <= lines["imu|lost"] <= limit
    assert 1 <= lines["imu|unknown_source"] <= limit
    assert all(n <= limit for n in lines.values()), lines
    # In the log (stderr): the same lines, plus at most one flushed at close; together they count every loss.
    lost_lines = [ln for ln in udp_run["stderr"].splitlines() if ln.startswith("imu: lost:")]
    assert lines["imu|lost"] <= len(lost_lines) <= lines["imu|lost"] + 1
    counted = 0
    for ln in lost_lines:
        m = re.match(r"imu: lost: (\d+) in the last ", ln) or re.search(r"\((\d+); more are summed", ln)
        assert m, ln
        counted += int(m.group(1))
    assert counted == imu["dropped"]["lost"]


def test_udp_diagnostics_carry_the_counters(udp_run: dict[str, Any]) -> None:
    diag = udp_run["diagnostics"][f"{BRIDGE}/mapping/imu"]
    v = diag["values"]
    _figures("/diagnostics of mapping imu after the UDP faults", {"level": diag["level"], "message": diag["message"],
                                                                 "values": v})
    imu = udp_run["bridge"]["mappings"]["imu"]
    assert diag["level"] == 1  # WARN: drops within the last 10 s
    assert int(v["received"]) == imu["received"] and int(v["published"]) == imu["published"]
    assert int(v["dropped"]) == imu["dropped_total"]
    assert int(v["dropped.lost"]) == imu["dropped"]["lost"] and int(v["dropped.unknown_source"]) == 50
    assert int(v["cyphal.errors"]) == 92 and int(v["cyphal.deserialization_failures"]) == 20
    assert int(v["out_of_order"]) == imu["out_of_order"] == 1
    assert "saturated" in v
    _no_tracebacks(udp_run)


# ============================================================================================ CAN
def test_out_of_range_commands_through_the_running_bridge(can_run: dict[str, Any]) -> None:
    ph = can_run["phases"]["commands"]
    last, b = ph["last_at_actuator"], ph["bridge"]
    _figures("ROS->UAVCAN out-of-range commands (CAN FD)", {
        "sent": ph["sent"], "at_actuators": ph["at_actuators"], "values_at_actuators": last,
        "bridge": {m: {k: x.get(k) for k in ("received", "published", "dropped", "saturated", "rejected_fields")}
                   for m, x in b.items()}})
    assert last["thruster_1_rpm"] == {"rpm": 131071} and last["thruster_2_rpm"] == {"rpm": -131072}  # int18
    assert b["thruster_1_rpm"]["saturated"] == {"thruster_1_rpm.rpm": 1}
    assert last["thrust_vector"] == {"vertical_radians": NOZZLE_F16, "horizontal_radians": -NOZZLE_F16}  # +-inf
    assert b["thrust_vector"]["saturated"] == {"thrust_vector.vertical_radians": 1,
                                               "thrust_vector.horizontal_radians": 1}
    assert last["buoyancy_piston"] == {"percent": 100.0} and b["buoyancy_piston"]["saturated"] == {
        "buoyancy_piston.percent": 1}
    # A NaN command is no setpoint: dropped and counted as not_a_number (a limited field or not); the actuator
    # never saw it, the next valid value goes.
    assert last["longitudinal_weight"] is None and ph["last_longitudinal_weight"] == {"percent": 42.0}
    assert b["longitudinal_weight"]["dropped"] == {"not_a_number": 1}
    assert b["longitudinal_weight"]["rejected_fields"] == {"longitudinal_weight.percent": 1}
    assert b["ballast"]["dropped"] == {"not_a_number": 1}
    # 1e6 saturates to the spec's limit (issue 29: no longer float16's 65504).
    assert last["ballast"] == {"weight_1_offset_radians": 0.5, "weight_2_offset_radians": BALLAST_F16}
    assert b["ballast"]["saturated"] == {"ballast.weight_2_offset_radians": 1}
    lw = ph["diagnostics"]["longitudinal_weight"]["values"]
    assert lw["dropped.not_a_number"] == "1" and lw["rejected.longitudinal_weight.percent"] == "1"
    t1 = ph["diagnostics"]["thruster_1_rpm"]["values"]
    assert t1["saturated"] == "1" and t1["saturated.thruster_1_rpm.rpm"] == "1"


def test_slow_ros_subscriber_does_not_block_the_bridge(can_run: dict[str, Any]) -> None:
    ph = can_run["phases"]["slow_subscriber"]
    imu = ph["mappings"]["imu"]
    _figures("slow ROS subscriber (0.1 s per /imu callback, keep-last 10; CAN FD, nominal rates)", {
        "window_s": ph["window_s"], "imu_sent": imu["sent"], "imu_published": imu["published"],
        "imu_dropped": imu["dropped"], "fast_probe_received": ph["ros_received"]["/imu"],
        "slow_subscriber_received": ph["slow_received"], "fast_probe_latency_ms": ph["fast_probe_latency_ms"],
        "all_mappings_sent_published": {m: [x["sent"], x["published"]] for m, x in ph["mappings"].items()}})
    for m, x in ph["mappings"].items():
        assert x["published"] == x["sent"] and x["dropped"] == {}, (m, x)
    # The simulated IMU really ran at its 100 Hz: what it sent plus the ticks it skipped while the shared loop was
    # late (187..275 of 300 sent with a CPU burner beside the test; the rest skipped, counted).
    assert imu["sent"] + imu["sim_late_ticks"] >= 0.8 * 100 * ph["window_s"], imu
    assert ph["ros_received"]["/imu"] == imu["published"]  # the other subscriber gets everything
    # The slow one gets what it can take (at most 10 a second; 32 of 72 with two CPU burners beside the test, when
    # the shared loop let the IMU send only 72 of its 300 ticks). How much less than everything depends on how much
    # the loaded machine let the IMU send, so only "some, and never more" is judged.
    assert 0 < ph["slow_received"] <= imu["published"]


def test_can_bus_errors_are_counted_and_the_bridge_recovers(can_run: dict[str, Any]) -> None:
    ph = can_run["phases"]["bus_errors_transient"]
    cmd = ph["commands"]
    _figures("transient CAN bus errors for 1 s (send ENOBUFS, receive CanOperationError)", {
        "injected": ph["injected"], "commands": cmd, "link": ph["link"],
        "sensors": {m: x for m, x in ph["mappings"].items() if x["dropped"] or m == "imu"}})
    assert ph["injected"].get("send_ENOBUFS", 0) >= 5 and ph["injected"].get("recv_CanOperationError", 0) >= 1
    # The 5 commands during the fault: counted as publish errors; the 5 after it reach the actuator.
    assert cmd["bridge"]["dropped"] == {"publish_error": 5} and cmd["bridge"]["published"] == 5
    assert cmd["at_actuator"] == 5 and cmd["last_at_actuator"] == {"rpm": 2004}
    # Sensor data: delayed while the receive thread backs off, never silently lost (pycyphal drops the frames it
    # was holding when the receive call raised: those transfers show as `lost`).
    for m, x in ph["mappings"].items():
        assert x["unaccounted"] == 0 and set(x["dropped"]) <= {"lost"}, (m, x)
        assert x["published"] > 0, m
    assert ph["link"]["outages"] == 0  # transient errors: the media survived, nothing to reopen


def test_can_interface_down_and_back_the_bridge_reopens(can_run: dict[str, Any]) -> None:
    ph = can_run["phases"]["interface_down"]
    cmd = ph["commands"]
    _figures("CAN interface down for 2 s (ENETDOWN: pycyphal's media dies), then back", {
        "injected": ph["injected"], "detected_after_s": ph["detected_after_s"],
        "detected_after_media_died_s": ph["detected_after_media_died_s"], "loop_lag_max_ms": ph["loop_lag_max_ms"],
        "first_open_attempt_after_interface_up_s": ph["first_attempt_after_up_s"],
        "open_attempts_after_up": ph["open_attempts_after_up"],
        "reopened_after_interface_up_s": ph["reopened_after_up_s"], "data_again_after_up_s":
        ph["data_again_after_up_s"], "link": ph["link"], "bridge_errors": ph["bridge_errors"],
        "diag_bridge_while_down": [ph["diag_bridge_level_while_down"], ph["diag_bridge_message_while_down"]],
        "commands": cmd, "sensors": {m: {k: x[k] for k in ("sent", "published", "dropped", "unaccounted",
                                                           "sim_late_ticks")} for m, x in ph["mappings"].items()}})
    # Wall-clock bounds are judged against the measured stalls of the event loop the bridge runs on, so they hold
    # on a loaded machine: the link is checked every CHECK_PERIOD_S once pycyphal's media met the fault; the
    # reopen is retried every REOPEN_BACKOFF_S[1] at most, and the first attempt after the interface came up works.
    lag_s = ph["loop_lag_max_ms"] / 1000
    assert ph["detected_after_media_died_s"] is not None
    # (+0.3 s: the injector's recv sleeps 0.05 s before it raises, and pycyphal's media thread closes the media.)
    assert ph["detected_after_media_died_s"] <= CHECK_PERIOD_S + lag_s + 0.3, (ph["detected_after_media_died_s"], lag_s)
    assert ph["diag_bridge_level_while_down"] == 2  # ERROR while down
    assert ph["diag_bridge_level_after"] == 0 and ph["link"]["up"] and ph["link"]["outages"] == 1
    assert ph["open_attempts_after_up"] == 1 and ph["bridge_errors"]["transport_reopened"] == 1
    assert ph["first_attempt_after_up_s"] <= REOPEN_BACKOFF_S[1] + lag_s + 0.2, (ph["first_attempt_after_up_s"], lag_s)
    assert ph["injected"].get("open_ENETDOWN", 0) >= 1  # it tried while the interface was still down
    assert cmd["bridge"]["dropped"] == {"link_down": 5} and cmd["at_actuator"] == 5
    assert cmd["last_at_actuator"] == {"rpm": 4004}
    for m, x in ph["mappings"].items():
        assert x["published"] > 0, m  # data flows again
        # What the bridge could not hear is estimated from the transfer ids (exact modulo 32) and the source's
        # rate (an estimate: off by multiples of 32). Here the simulated devices share the bridge's process and
        # event loop, which stalls while the bridge reopens its CAN media (python-can's set_filters) and under
        # CPU load: they then skip ticks (counted: sim_late_ticks), send fewer messages than their rate says, and
        # the estimate exceeds the truth by up to what they skipped (rounded to the next multiple of 32).
        assert set(x["dropped"]) <= {"lost_link_down", "lost"}, (m, x)
        assert x["unaccounted"] % 32 == 0, (m, x)
        skipped = -(-x["sim_late_ticks"] // 32) * 32
        assert abs(x["unaccounted"]) <= max(64, 0.3 * (x["sent"] - x["published"])) + skipped, (m, x)


def test_heartbeat_timeout_and_recovery_on_diagnostics(can_run: dict[str, Any]) -> None:
    ph = can_run["phases"]["heartbeat"]
    _figures("GPS heartbeat stops (power off) and resumes (power on)", {
        k: ph[k] for k in ("heartbeat_age_at_power_off_s", "error_after_power_off_s", "heartbeat_age_when_reported_s",
                           "heartbeats_when_lost", "message_when_lost", "ok_after_power_on_s", "when_ok",
                           "loop_lag_max_ms", "gps_fix")} | {
        "device": {k: ph["device"][k] for k in ("alive", "lost_events", "restarts", "uptime_s")}})
    # ERROR on /diagnostics once the last heartbeat is 3 s old (the Cyphal offline timeout), published at once: the
    # report's own age is 3 s, late by no more than the bridge's event loop was (its stalls are measured, so this
    # holds on a loaded machine too; the probe's wall-clock figures above are shown, not judged).
    lag_s = ph["loop_lag_max_ms"] / 1000
    assert 3.0 <= ph["heartbeat_age_when_reported_s"] <= 3.0 + lag_s + 0.1, (ph["heartbeat_age_when_reported_s"], lag_s)
    # Not before the timeout: the last heartbeat was at most `heartbeat_age_at_power_off_s` old at power-off.
    assert ph["error_after_power_off_s"] >= 3.0 - ph["heartbeat_age_at_power_off_s"] - 0.002
    assert "heartbeat lost" in ph["message_when_lost"]
    # OK again on the first heartbeat of the rebooted GPS, at once (not at the next /diagnostics period): the OK
    # report carries exactly one heartbeat more than the ERROR one, and the restart it revealed.
    assert ph["when_ok"]["heartbeats"] == ph["heartbeats_when_lost"] + 1, ph["when_ok"]
    assert ph["when_ok"]["restarts"] == 1, ph["when_ok"]
    assert ph["device"]["alive"] and ph["device"]["restarts"] == 1 and ph["device"]["lost_events"] >= 1
    assert ph["gps_fix"]["published"] >= 1  # its data flows again
    levels = [e["level"] for e in ph["events"]]
    assert levels[-2:] == [2, 0]


def test_diagnostics_content(can_run: dict[str, Any]) -> None:
    """/diagnostics (subscribed by the probe): one status for the bridge, one per mapping with received,
    published, dropped (+ by reason), saturated (+ by field), one per device with its heartbeat state."""
    diag, bridge = can_run["diagnostics"], can_run["bridge"]
    mappings = bridge["mappings"]
    names = {n for n in diag if n.startswith(f"{BRIDGE}/mapping/")}
    _figures("/diagnostics at the end of the CAN run", {
        "statuses": len(diag), "bridge": diag[BRIDGE]["message"],
        "mappings": {n.split("/")[-1]: diag[n]["message"] for n in sorted(names)},
        "devices": {n.split("/")[-1]: [d["level"], d["message"]] for n, d in diag.items() if "/device/" in n}})
    assert names == {f"{BRIDGE}/mapping/{m}" for m in mappings}
    for name in mappings:
        v = diag[f"{BRIDGE}/mapping/{name}"]["values"]
        for key in ("received", "published", "dropped", "saturated", "out_of_order", "direction", "topic"):
            assert key in v, (name, key)
        assert sum(int(x) for k, x in v.items() if k.startswith("dropped.")) == int(v["dropped"])
        assert sum(int(x) for k, x in v.items() if k.startswith("saturated.")) == int(v["saturated"])
    assert diag[f"{BRIDGE}/mapping/thruster_1_rpm"]["values"]["dropped.publish_error"] == "5"
    assert int(diag[f"{BRIDGE}/mapping/imu"]["values"]["dropped.lost_link_down"]) > 0
    # Every device at the end, in a report that carries a heartbeat the bridge handled after the phases (the
    # scenario waited for one in which all are OK, for as long as each device sent 5 heartbeats): OK, or - when
    # the shared loop let no such report come - a loss that the device's own heartbeats and the stalls explain.
    final = can_run["final"]
    _figures("the final /diagnostics report", final | {"loop_stalls_over_1s": [
        s for s in can_run["loop_stalls"] if s[1] > 1.0]})
    for dev in bridge["devices"]:
        d = diag[f"{BRIDGE}/device/{dev}"]
        assert int(d["values"]["heartbeats"]) > 0, (dev, d)
        _device_ok_or_silence_explained(can_run, dev, d)
    b = diag[BRIDGE]["values"]
    assert b["link_up"] == "True" and b["link_outages"] == "1" and diag[BRIDGE]["level"] == 0
    # Heartbeat: ERROR when lost, OK again, for every device during the link outage too (it heard nothing).
    # From the baseline on (the scenario waited, with a deadline, until every device was OK on /diagnostics):
    # OK, then ERROR at least once (the link outage or the power-off), and OK again.
    base = can_run["diag_events_baseline"]
    gps_events = [e for e in can_run["diag_events"][base:] if e["name"] == f"{BRIDGE}/device/gps"]
    gps = [e["level"] for e in gps_events]
    assert gps and gps[0] == 2 and 0 in gps[1:], gps
    # Before it: STALE only while the bridge had not heard the device yet (the probe's first /diagnostics may come
    # before the first heartbeat), then OK; a loss in between only as the device's heartbeats and the stalls of
    # the start-up explain it.
    before_events = [e for e in can_run["diag_events"][:base] if e["name"] == f"{BRIDGE}/device/gps"]
    for e in before_events:
        if e["level"] == 2:
            _device_ok_or_silence_explained(can_run, "gps", e)
    before = [lvl for lvl, _ in itertools.groupby(e["level"] for e in before_events if e["level"] != 2)]
    assert before in ([0], [3, 0]), [e["level"] for e in before_events]
    _no_tracebacks(can_run)


# ============================================================================================ units
def test_rate_limited_log_sums_occurrences() -> None:
    from sam_runtime.common.rate_log import RateLimitedLog

    records: list[str] = []

    class Keep(logging.Handler):
        def emit(self, record: logging.LogRecord) -> None:
            records.append(record.getMessage())

    logger = logging.getLogger("test_faults.ratelimit")
    logger.propagate = False
    logger.addHandler(Keep())
    logger.setLevel(logging.INFO)
    log = RateLimitedLog(logger, interval=0.2)
    t_end = time.monotonic() + 0.5
    n = 0
    while time.monotonic() < t_end:
        log.note(("imu", "lost"), logging.WARNING, "gap before %d", n)
        n += 1
    log.note(("imu", "unknown_source"), logging.WARNING, "from node %d", 42)
    log.flush(force=True)
    lost = [r for r in records if r.startswith("imu: lost:")]
    _figures("bounded-rate log (unit)", {"occurrences": n, "lines": len(lost)})
    assert n > 1000 and 2 <= len(lost) <= 1 + 0.5 / 0.2 + 1  # the first at once, then one per interval, + flush
    assert sum(int(r.split(": ")[2].split()[0]) for r in lost[1:]) + 1 == n  # every occurrence counted once
    assert log.lines[("imu", "lost")] == len(lost)
    assert [r for r in records if r.startswith("imu: unknown_source:")] == [
        "imu: unknown_source: from node 42 (1; more are summed at most every 0 s)"]


def test_aclose_leaves_the_other_nodes_of_the_loop_alone() -> None:
    """Closing one node (the bridge reopening its transport, a simulated device powering off) must not cancel
    the pycyphal tasks of the other nodes in the same event loop."""
    from sam_runtime.cyphal_io.transport import aclose, make_node

    async def run() -> tuple[int, int]:
        iface = f"virtual:aclose{os.getpid()}"
        gen = generated_or_skip()
        gen.compile_dsdl()
        import uavcan.primitive.scalar

        nat8 = uavcan.primitive.scalar.Natural8_1_0
        a = make_node("org.test.a", 1, "can", iface=iface)
        b = make_node("org.test.b", 2, "can", iface=iface)
        c = make_node("org.test.c", 3, "can", iface=iface)
        got: list[int] = []
        try:
            sub_c = c.make_subscriber(nat8, 1000)
            sub_c.receive_in_background(lambda msg, tr: got.append(int(msg.value)))
            sub_b = b.make_subscriber(nat8, 1000)
            pub = a.make_publisher(nat8, 1000)
            await pub.publish(nat8(1))
            deadline = time.monotonic() + 5
            while not got and time.monotonic() < deadline:
                await asyncio.sleep(0.01)
            await aclose(sub_b, b)  # b goes away
            await pub.publish(nat8(2))
            deadline = time.monotonic() + 5
            while len(got) < 2 and time.monotonic() < deadline:
                await asyncio.sleep(0.01)
        finally:
            await aclose(a, b, c)
        return len(got), got[-1] if got else -1

    count, last = asyncio.run(run())
    assert (count, last) == (2, 2)
