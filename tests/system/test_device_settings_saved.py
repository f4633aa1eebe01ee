"""The boards' settings saved from ROS and given at the bridge's start (issue 28), across processes: the simulated
boards (``sam-codegen sim``: a reboot runs with the saved values only), their bridge, and an independent rclpy client
(tests/helpers/param_client.py) of the parameter services, the bridge's ``<device>/store_settings`` (std_srvs/Trigger)
and its device duty ``uavcan_restart_node`` (the board's reboot: Cyphal ExecuteCommand RESTART, DroneCAN RestartNode):

- a value set through ROS and stored (store_settings) is kept across the board's reboot; one set after the store is
  lost (the bridge reads the board again after its restart and shows the saved value); on Cyphal/UDP (glider) and
  DroneCAN (lolo_v0);
- store_settings of a board that does not answer fails with the reason; both are counted;
- ``--ros-args --params-file F`` at the bridge's start (Cyphal/UDP): an override that differs from the board's value
  is written to the board after its first read (logged ``name: board -> override``), one the spec refuses is logged
  with the reason; both counted, no traceback; the bridge's ``--param <device>.<setting>=V`` likewise (DroneCAN).
"""

from __future__ import annotations

from typing import Any

import pytest
import yaml

pytest.importorskip("pycyphal")
pytest.importorskip("dronecan")
pytest.importorskip("rclpy")

from helpers.dronecan_support import private_iface
from helpers.runtime_support import cyphal_udp_lock, poll_until, runtime_cmd
from helpers.service_run import ServiceRun
from helpers.spec_build import spec_workdir

pytestmark = [pytest.mark.ros, pytest.mark.slow]

UDP = ["--transport", "udp", "--iface", "127.0.0.1"]




def _counts(r: ServiceRun) -> dict[str, Any]:
    counts: dict[str, Any] = (r.bridge_stats() or {}).get("device_parameters", {})
    return counts


def _up_for(r: ServiceRun, device: str, seconds: int) -> None:
    """Until the board's heartbeat says it has been up that long: the bridge counts a restart when the uptime goes
    down, which a board restarted within its first second or two would not show."""
    poll_until(lambda: (r.bridge_stats() or {}).get("devices", {}).get(device, {}).get("uptime_s", 0) >= seconds,
               30, f"{device} up for {seconds} s")


def _restarted_and_read(r: ServiceRun, device: str, reads: int) -> None:
    """Until the bridge counted the board's restart and read all its settings again (its stats file)."""
    try:
        poll_until(lambda: ((r.bridge_stats() or {}).get("devices", {}).get(device, {}).get("restarts", 0) >= 1
                            and _counts(r).get("reads", 0) >= reads), 30,
                   f"the bridge counting {device}'s restart and reading its settings again")
    except AssertionError as ex:
        stats = r.bridge_stats() or {}
        raise AssertionError(f"{ex}: {stats.get('devices', {}).get(device)} {_counts(r)}\n"
                             f"{r.bridge_stderr()[-3000:]}") from None


@pytest.fixture(scope="module")
def cyphal(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    _, d, env = spec_workdir(tmp_path_factory, "glider", "settings_saved_cyphal", 88)
    overrides = d / "overrides.yaml"
    overrides.write_text(yaml.safe_dump({"/**": {"ros__parameters": {
        "pump": {"pump": {"rate_limit": 4.0e-5, "direction": "sideways"}}}}}))
    with cyphal_udp_lock(), ServiceRun(env, d) as r:
        sim = r.start("sim", runtime_cmd("sim", *UDP, "--devices", "pump"))  # the ctd board is off
        # (--ros-args takes the rest of the line: the stats file first)
        r.bridge_proc = bridge = r.start("bridge", runtime_cmd("bridge", *UDP, "--stats-file", str(r.stats_file),
                                                               "--ros-args", "--params-file", str(overrides)))
        sim.wait_line("READY", 90)
        bridge.wait_line("READY", 90)
        poll_until(lambda: _counts(r).get("reads", 0) >= 3 and _counts(r).get("overrides_applied", 0) >= 1, 30,
                   "the bridge reading the pump's settings and writing the override")
        _up_for(r, "pump", 3)
        first = r.param_client("--node", "/glider_bridge", "--prefix", "pump", "--set", "ctd.ctd.sample_rate=4",
                               "--set", "pump.pump.volume_limit=0.0008", "--trigger", "/pump/store_settings",
                               "--trigger", "/ctd/store_settings", "--set", "pump.pump.direction=\"inverted\"",
                               "--restart", "glider_msgs/srv/UavcanRestartNode=21@/uavcan_restart_node")
        _restarted_and_read(r, "pump", 6)
        again = r.param_client("--node", "/glider_bridge", "--prefix", "pump")
        poll_until(lambda: _counts(r).get("stores", 0) >= 2, 20, "the bridge's stats file counting the stores")
        return {"first": first, "again": again} | r.outcome()


@pytest.fixture(scope="module")
def dronecan(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    _, d, env = spec_workdir(tmp_path_factory, "lolo_v0", "settings_saved_dronecan", 89)
    iface = private_iface()
    with ServiceRun(env, d) as r:
        sim = r.start("sim", runtime_cmd("sim", "--devices", "esc_port", "--dronecan-iface", iface))
        # an override by the bridge's own --param (its parameter_overrides), as a params file's
        bridge = r.bridge("--protocol", "dronecan", "--dronecan-iface", iface, "--param", "esc_port.esc.index=3")
        sim.wait_line("READY", 90)
        bridge.wait_line("READY", 90)
        poll_until(lambda: _counts(r).get("reads", 0) >= 4 and _counts(r).get("overrides_applied", 0) >= 1, 30,
                   "the bridge reading esc_port's settings and writing the override")
        _up_for(r, "esc_port", 3)
        first = r.param_client("--node", "/sabre_bridge", "--prefix", "esc_port",
                               "--set", "esc_port.esc.poles=28", "--trigger", "/esc_port/store_settings",
                               "--set", "esc_port.esc.rpm_limit=2500",
                               "--restart", "sabre_msgs/srv/UavcanRestartNode=50@/uavcan_restart_node")
        _restarted_and_read(r, "esc_port", 8)
        again = r.param_client("--node", "/sabre_bridge", "--prefix", "esc_port")
        poll_until(lambda: _counts(r).get("stores", 0) >= 1, 20, "the bridge's stats file counting the store")
        return {"first": first, "again": again} | r.outcome()


def test_cyphal_a_stored_value_survives_the_reboot_an_unsaved_one_does_not(cyphal: dict[str, Any]) -> None:
    first, again = cyphal["first"], cyphal["again"]
    assert [s["successful"] for s in first["sets"]] == [False, True, True], first["sets"]
    assert [x["success"] for x in first["restarts"]] == [True], first["restarts"]
    assert again["get"]["pump.pump.volume_limit"] == pytest.approx(0.0008, rel=1e-6), again  # stored: kept
    assert again["get"]["pump.pump.direction"] == "normal", again  # set after the store: lost at the reboot


def test_cyphal_store_settings_answers_the_boards_ok_or_the_reason(cyphal: dict[str, Any]) -> None:
    pump, ctd = cyphal["first"]["triggers"]
    assert pump["service"] == "/pump/store_settings" and pump["success"], pump
    assert pump["message"] == "pump stored its settings"
    assert not ctd["success"] and ctd["message"] == "ctd: node 23 did not answer within 3 s", ctd
    counts = cyphal["bridge_stats"]["device_parameters"]
    assert counts["stores"] == 2 and counts["store_failures"] == 1, counts
    assert "Traceback" not in cyphal["bridge_stderr"]


def test_cyphal_params_file_overrides_are_written_to_the_board(cyphal: dict[str, Any]) -> None:
    stderr = cyphal["bridge_stderr"]
    assert "pump.pump.rate_limit: 2e-05 -> 4e-05 (the override written to the board)" in stderr, stderr[-3000:]
    assert ("pump.pump.direction: the override 'sideways' is refused by the spec: 'sideways' is none of "
            "['normal', 'inverted']") in stderr, stderr[-3000:]
    counts = cyphal["bridge_stats"]["device_parameters"]
    assert counts["overrides_applied"] == 1 and counts["overrides_refused"] == 1, counts
    # the first client saw the board's value (written, then stored with the others: kept across the reboot too)
    assert cyphal["first"]["get"]["pump.pump.rate_limit"] == pytest.approx(4e-5, rel=1e-6)
    assert cyphal["again"]["get"]["pump.pump.rate_limit"] == pytest.approx(4e-5, rel=1e-6)
    assert "Traceback" not in stderr


def test_dronecan_a_stored_value_survives_the_reboot_an_unsaved_one_does_not(dronecan: dict[str, Any]) -> None:
    first, again = dronecan["first"], dronecan["again"]
    assert [s["successful"] for s in first["sets"]] == [True, True], first["sets"]
    (store,) = first["triggers"]
    assert store["success"] and store["message"] == "esc_port stored its settings", store
    assert first["restarts"][0]["success"], first["restarts"]
    assert again["get"]["esc_port.esc.poles"] == 28, again  # stored: kept
    assert again["get"]["esc_port.esc.rpm_limit"] == 3000, again  # set after the store: lost (the spec default)
    counts = dronecan["bridge_stats"]["device_parameters"]
    assert counts["stores"] == 1 and counts.get("store_failures", 0) == 0, counts
    assert "Traceback" not in dronecan["bridge_stderr"]


def test_dronecan_a_param_override_is_written_to_the_board(dronecan: dict[str, Any]) -> None:
    assert "esc_port.esc.index: 0 -> 3 (the override written to the board)" in dronecan["bridge_stderr"]
    assert dronecan["first"]["get"]["esc_port.esc.index"] == 3
    assert dronecan["again"]["get"]["esc_port.esc.index"] == 3  # stored with the others: kept across the reboot
    assert dronecan["bridge_stats"]["device_parameters"]["overrides_applied"] == 1


def test_cyphal_a_set_to_a_silent_board_holds_the_executor_for_the_timeout(cyphal: dict[str, Any]) -> None:
    # rclpy answers a set synchronously on the bridge's one executor thread: the worst case of one setting is the
    # timeout (the client's round trip around it)
    off = cyphal["first"]["sets"][0]
    assert off["name"] == "ctd.ctd.sample_rate" and "did not answer within 1 s" in off["reason"], off
    assert 1.0 <= off["seconds"] < 10.0, off
    print(f"a set to a board that does not answer: {off['seconds']:.3f} s")
