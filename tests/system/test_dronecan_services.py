"""A service mapping across processes (issue 19): a plain dronecan battery management system serving the vendor v0
service UpdateBattery (tests/helpers/battery_peer.py, on a private loopback bus), the bridge of
tests/specs/auv_services.yaml, and an independent rclpy client (tests/helpers/ros_service_client.py battery) calling
/bms/update_battery (lolo_msgs/srv/UpdateBattery).

- an answered call carries the request's fields to the device and its answer back (success, status);
- a call the device never answers ends after the mapping's timeout (0.5 s) with success false, and a slow call does
  not hold up another: issued first, it comes back after a second call issued after it;
- a duplicate answer, a late answer (after its call timed out) and a malformed answer are counted on /diagnostics
  and dropped: the bridge goes on and answers the next call;
- the node duties (GetNodeInfo, GetTransportStats, RestartNode) as the spec's typed services, the node named in
  the request.
"""

from __future__ import annotations

from typing import Any

import pytest

pytest.importorskip("dronecan")
pytest.importorskip("rclpy")

from helpers.dronecan_support import private_iface
from helpers.runtime_support import helper_cmd
from helpers.service_run import ServiceRun, requests_seen
from helpers.spec_build import spec_workdir

pytestmark = [pytest.mark.ros, pytest.mark.slow]

TIMEOUT_S = 0.5  # the mapping's, in auv_services.yaml


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    built, d, env = spec_workdir(tmp_path_factory, "auv_services", "dronecan_services", 61)
    iface = private_iface()
    with ServiceRun(env, d) as r:
        peer = r.start("peer", helper_cmd("battery_peer.py", "--iface", iface, "--node-id", "30", "--generated",
                                          str(built.generated), "--late", str(3 * TIMEOUT_S)))
        bridge = r.bridge("--dronecan-iface", iface)
        peer.wait_line("READY", 60)
        bridge.wait_line("READY", 90)
        result = r.client("battery", "--service", "/bms/update_battery", "--status", "bridge/service/update_battery",
                          "--duties")
        r.assert_bridge_alive()
    result["peer"] = requests_seen(peer)
    result["bridge_stats"] = r.bridge_stats()
    return result


def test_an_answered_call_carries_both_ways(run: dict[str, Any]) -> None:
    first = run["calls"][0]
    assert first["command"] == 1 and first["success"] is True and first["status"] == 1
    assert run["peer"][0]["command"] == 1 and run["peer"][0]["charge"] == 42.5  # charge_percent -> charge


def test_an_unanswered_call_fails_after_the_timeout(run: dict[str, Any]) -> None:
    unanswered = run["calls"][1]
    assert unanswered["command"] == 2 and unanswered["success"] is False and unanswered["status"] == 0
    assert unanswered["elapsed_s"] >= TIMEOUT_S  # not before the mapping's timeout


def test_a_slow_call_does_not_hold_up_another(run: dict[str, Any]) -> None:
    # issued first (command 2: never answered), it ends after the second call (answered)
    assert run["concurrent"] == [{"command": 1, "success": True}, {"command": 2, "success": False}]


def test_bad_answers_are_counted_and_dropped(run: dict[str, Any]) -> None:
    calls = run["calls"]
    assert [c["command"] for c in calls] == [1, 2, 3, 4, 5]
    assert calls[2]["success"] is True  # the first of the two answers
    assert calls[3]["success"] is False and calls[4]["success"] is False  # late, malformed: the timeout
    status = run["status"]
    assert status["calls"] == "7" and status["answered"] == "3"
    assert status["timeouts"] == "4"  # 2, 4 (late), 5 (malformed), 2 again
    assert status["duplicate_responses"] == "1" and status["late_responses"] == "1"
    assert int(status["malformed_responses"]) >= 1
    assert status["level"] == "1"  # WARN: a recent failure
    assert [r["command"] for r in run["peer"]] == [1, 2, 3, 4, 5, 2, 1]  # every call reached the device once


def test_the_bridge_reports_the_service_in_its_stats(run: dict[str, Any]) -> None:
    stats = run["bridge_stats"]
    assert stats is not None and "services" in stats, stats
    entry = stats["services"]["update_battery"]
    assert entry["service"] == "/bms/update_battery" and entry["data_type_id"] == 201
    assert entry["calls"] == 7


def test_typed_node_duties(run: dict[str, Any]) -> None:
    """GetNodeInfo, GetTransportStats and RestartNode as the spec's typed services, the node named in the
    request: the device's answers, and a clear failure for a node that does not answer."""
    duties = run["duties"]
    info = duties["info"]
    assert info["success"] is True and info["name"] == "org.lolo.bms" and info["message"] == ""
    assert info["mode"] == 0 and info["health"] == 0 and info["uptime_sec"] >= 0
    missing = duties["info_missing"]
    assert missing["success"] is False and missing["name"] == ""
    assert missing["message"] == "node 99 did not answer within 1 s"
    assert duties["stats"] == {"success": True, "message": "", "transfers_tx": 11, "transfers_rx": 22,
                               "transfer_errors": 3}
    assert duties["restart"] == {"success": True, "message": ""}
    stats = run["bridge_stats"]["services"]
    assert stats["get_node_info"]["calls"] == 2 and stats["get_node_info"]["timeouts"] == 1
    assert stats["restart_node"]["answered"] == 1
