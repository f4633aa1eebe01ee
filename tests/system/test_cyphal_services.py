"""Service mappings on Cyphal across processes (issue 19): a plain pycyphal charger serving the spec's
ran.power.SetChargeLimits.1.0 at service id 200 (tests/helpers/charger_server.py, Cyphal/UDP on 127.0.0.1, with
GetInfo as every pycyphal application node), the bridge of tests/specs/auv_cyphal_services.yaml, and an
independent rclpy client (tests/helpers/ros_service_client.py charger).

- an answered call carries the request's fields to the device (float percent -> uint8) and its answer back
  (bool, uint8[] -> string);
- a call the device answers only after the mapping's timeout (0.5 s) fails with success false and the reason, and
  its late answer is counted on /diagnostics (late_responses) and dropped;
- the standard uavcan.node.GetInfo.1.0 at its fixed port id of the node the request names, and a clear failure for a
  node that does not answer.
"""

from __future__ import annotations

from typing import Any

import pytest

pytest.importorskip("pycyphal")
pytest.importorskip("rclpy")

from helpers.runtime_support import cyphal_udp_lock, helper_cmd
from helpers.service_run import ServiceRun, requests_seen
from helpers.spec_build import spec_workdir

pytestmark = [pytest.mark.ros, pytest.mark.slow]

TIMEOUT_S = 0.5  # set_charge_limits', in auv_cyphal_services.yaml


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    built, d, env = spec_workdir(tmp_path_factory, "auv_cyphal_services", "cyphal_services", 63)
    with cyphal_udp_lock(), ServiceRun(env, d) as r:
        peer = r.start("peer", helper_cmd("charger_server.py", "--generated", str(built.generated), "--node-id",
                                          "31", "--late", str(3 * TIMEOUT_S)))
        bridge = r.bridge("--transport", "udp", "--iface", "127.0.0.1")
        peer.wait_line("READY", 60)
        bridge.wait_line("READY", 90)
        result = r.client("charger")
        r.assert_bridge_alive()
    return result | {"peer": requests_seen(peer)} | r.outcome()


def test_an_answered_call_carries_both_ways(run: dict[str, Any]) -> None:
    accepted, refused = run["limits"][0], run["limits"][1]
    assert accepted["success"] is True and accepted["accepted"] is True and accepted["reason"] == "ok"
    assert accepted["message"] == ""
    assert refused["success"] is True and refused["accepted"] is False and refused["reason"] == "low >= high"
    assert run["peer"][:2] == [{"low_percent": 20, "high_percent": 80}, {"low_percent": 90, "high_percent": 10}]


def test_an_unanswered_call_fails_after_the_timeout_and_its_late_answer_is_counted(run: dict[str, Any]) -> None:
    late = run["limits"][2]
    assert late["success"] is False and late["accepted"] is False and late["reason"] == ""
    assert late["message"] == "node 31 (charger) did not answer within 0.5 s"
    assert late["elapsed_s"] >= TIMEOUT_S
    status = run["status"]
    assert status["calls"] == "3" and status["answered"] == "2" and status["timeouts"] == "1"
    assert status["late_responses"] == "1" and status["malformed_responses"] == "0"
    assert status["level"] == "1"  # WARN: a recent failure
    assert len(run["peer"]) == 3  # every call reached the device once


def test_standard_get_info_of_the_node_the_request_names(run: dict[str, Any]) -> None:
    info, missing = run["info"]
    assert info["success"] is True and info["name"] == "org.ran.charger" and info["message"] == ""
    assert missing["success"] is False and missing["name"] == ""
    assert missing["message"] == "node 99 did not answer within 1 s"


def test_the_bridge_reports_the_services_in_its_stats(run: dict[str, Any]) -> None:
    stats = run["bridge_stats"]
    assert stats is not None and "services" in stats, stats
    entry = stats["services"]["set_charge_limits"]
    assert entry["service"] == "/charger/set_limits" and entry["data_type_id"] == 200 and entry["calls"] == 3
    info = stats["services"]["get_node_info"]
    assert info["data_type_id"] == 430 and info["calls"] == 2 and info["timeouts"] == 1
    assert "Traceback" not in run["bridge_stderr"]
