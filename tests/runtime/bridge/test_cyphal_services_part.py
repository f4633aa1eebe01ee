"""The Cyphal side of the service mappings (runtime/bridge/backends/cyphal_services.py) without a bus: a fake
pycyphal node and client. A call ends with the converted response, a timeout (the client's None) or link_down; the
clients' counts of unexpected and undecodable responses become late_responses and malformed_responses; the clients
are made again on a new node (a reopened link)."""

from __future__ import annotations

import asyncio
import logging
from types import SimpleNamespace as NS
from typing import Any

import pytest

from sam_runtime.bridge.backends import cyphal_services
from sam_runtime.bridge.backends.service_mappings import Call
from sam_runtime.bridge.lifetime import Lifetime
from sam_runtime.common.rate_log import RateLimitedLog


class _Type:
    class Request:
        low_percent = 0

    Response = NS


MAPPING = NS(
    name="limits", service="/charger/set_limits", ros_type="p/srv/Limits", data_type="ran.power.Limits.1.0",
    data_type_id=200, destination_node_id=31, device="charger", destination_field=None, timeout_s=0.5,
    request=(NS(target="low_percent", source="low", kind="int", value=None, scale=None, offset=None, lo=0, hi=255),),
    response=(NS(target="reason", source="reason", kind="text", value=None, scale=None, offset=None,
                 lo=float("-inf"), hi=float("inf")),),
    success_field="success", message_field="message",
)


class _Client:
    def __init__(self, answers: list[Any]) -> None:
        self.answers, self.requests, self.response_timeout = answers, [], 0.0
        self.stats = NS(unexpected_responses=0, deserialization_failures=0)

    async def call(self, request: Any) -> Any:
        self.requests.append(request)
        return self.answers.pop(0)

    def sample_statistics(self) -> Any:
        return self.stats


class _Node:
    def __init__(self, answers: list[Any]) -> None:
        self.clients: list[tuple[int, int, _Client]] = []
        self.answers = answers
        self.presentation = NS(make_client=self.make_client)

    def make_client(self, dtype: Any, service_id: int, server_node_id: int) -> _Client:
        client = _Client(self.answers)
        self.clients.append((service_id, server_node_id, client))
        return client


@pytest.fixture
def part(monkeypatch: pytest.MonkeyPatch) -> cyphal_services.CyphalServices:
    monkeypatch.setattr(cyphal_services, "dsdl_class", lambda name: _Type)
    lifetime = Lifetime("bridge", RateLimitedLog(logging.getLogger("test"), 10.0))
    return cyphal_services.CyphalServices(lifetime, NS(node=None), NS(name="bridge"), [MAPPING],
                                          diagnostics_period=0)


def _run(part: cyphal_services.CyphalServices, values: dict[str, Any]) -> Call:
    async def go() -> Call:
        call = Call()
        part.send(MAPPING, 31, values, call)
        while not call.done.is_set():
            await asyncio.sleep(0)
        return call

    return asyncio.run(go())


def test_answer_timeout_and_link_down(part: cyphal_services.CyphalServices) -> None:
    call = _run(part, {"low_percent": 20})
    assert call.reason == "link_down" and call.failure == "the Cyphal link is down"
    node = _Node([(NS(reason=b"ok"), None), None])
    part.backend.node = node
    call = _run(part, {"low_percent": 20})
    assert call.failure is None and call.values == {"reason": "ok"}
    service_id, nid, client = node.clients[0]
    assert (service_id, nid, client.response_timeout) == (200, 31, 0.5)  # by keyword: service id, then node
    assert client.requests[0].low_percent == 20
    call = _run(part, {"low_percent": 0})
    assert call.reason == "timeout" and call.failure == "node 31 (charger) did not answer within 0.5 s"
    assert len(node.clients) == 1  # one client per (mapping, node)


def test_unexpected_and_undecodable_responses_are_counted(part: cyphal_services.CyphalServices) -> None:
    node = _Node([(NS(reason=b""), None), (NS(reason=b""), None)])
    part.backend.node = node
    _run(part, {"low_percent": 1})
    client = node.clients[0][2]
    client.stats = NS(unexpected_responses=2, deserialization_failures=1)
    part.poll_statistics()
    part.poll_statistics()  # counted once
    counts = part.snapshot()["limits"]
    assert counts["late_responses"] == 2 and counts["malformed_responses"] == 1 and counts["warn"] is True
    part.backend.node = _Node([(NS(reason=b""), None)])  # the link reopened: a new node, new clients
    _run(part, {"low_percent": 1})
    assert len(part.backend.node.clients) == 1


def _link(target: str, source: str | None, kind: str, value: Any = None, hi: float = float("inf")) -> NS:
    return NS(target=target, source=source, kind=kind, value=value, scale=None, offset=None, lo=0, hi=hi)


INFO_DUTY = NS(
    name="node_services.get_node_info", service="uavcan_get_node_info", ros_type="p/srv/UavcanGetNodeInfo",
    data_type="uavcan.node.GetInfo.1.0", data_type_id=430, destination_node_id=0, device="",
    destination_field="node_id", timeout_s=0.5, request=(),
    response=(_link("success", None, "bool", True), _link("name", "name", "text"),
              _link("uptime_sec", "heartbeat.uptime_s", "int", hi=2**32 - 1),
              _link("health", "heartbeat.health", "int", hi=255), _link("mode", "heartbeat.mode", "int", hi=255),
              _link("software_vcs_revision_id", "software_vcs_revision_id", "int", hi=float(2**64)),
              _link("unique_id", "unique_id", "bytes")),
    success_field="success", message_field="message", duty="get_node_info",
)


def test_the_get_node_info_duty_takes_what_get_info_lacks_from_the_heartbeat(monkeypatch: pytest.MonkeyPatch) -> None:
    """GetInfo has no uptime, health or mode: the node's last heartbeat gives them (0 before any); a uint64 stays
    exact; the unique id is copied as bytes."""
    from sam_runtime.bridge.backend import DeviceStatus

    monkeypatch.setattr(cyphal_services, "dsdl_class", lambda name: _Type)
    lifetime = Lifetime("bridge", RateLimitedLog(logging.getLogger("test"), 10.0))
    answer = NS(name=b"org.ran.charger", software_vcs_revision_id=2**64 - 3, unique_id=bytes(range(16)))
    part = cyphal_services.CyphalServices(lifetime, NS(node=_Node([(answer, None), (answer, None)])),
                                          NS(name="bridge"), [INFO_DUTY], diagnostics_period=0)
    part.health = NS(records={31: NS(status=DeviceStatus(31, "CAUTION", 1, "MAINTENANCE", 1234, 7))})

    def run(nid: int) -> Call:
        async def go() -> Call:
            call = Call()
            part.send(INFO_DUTY, nid, {}, call)
            while not call.done.is_set():
                await asyncio.sleep(0)
            return call

        return asyncio.run(go())

    values = run(31).values
    assert values == {"success": True, "name": "org.ran.charger", "uptime_sec": 1234, "health": 2, "mode": 2,
                      "software_vcs_revision_id": 2**64 - 3, "unique_id": list(range(16))}
    unheard = run(32).values  # no heartbeat of node 32 heard: zeros
    assert unheard is not None and (unheard["uptime_sec"], unheard["health"], unheard["mode"]) == (0, 0, 0)


@pytest.fixture
def duty_part(monkeypatch: pytest.MonkeyPatch) -> cyphal_services.CyphalServices:
    monkeypatch.setattr(cyphal_services, "dsdl_class", lambda name: _Type)
    lifetime = Lifetime("bridge", RateLimitedLog(logging.getLogger("test"), 10.0))
    return cyphal_services.CyphalServices(lifetime, NS(node=None), NS(name="bridge"), [INFO_DUTY],
                                          diagnostics_period=0)


def test_a_duty_refuses_a_node_that_is_no_device(duty_part: cyphal_services.CyphalServices) -> None:
    """A node id of no device of the bridge's protocol: success false and the reason at once, bad_node_id."""
    part = duty_part
    part.devices = {31: "charger"}
    response = part.serve(INFO_DUTY, NS(node_id=99), NS(success=True, message=""))
    assert response.success is False
    assert response.message == "node 99 is no Cyphal device of this bridge (its devices: 31 (charger))"
    assert part.stats[INFO_DUTY.name].counts == {"calls": 1, "failed.bad_node_id": 1}


def test_an_inactive_bridge_sends_no_request(duty_part: cyphal_services.CyphalServices) -> None:
    """A managed bridge its lifecycle manager has not activated (issue 30): every call fails at once as inactive,
    before anything is converted or handed to the bus."""
    part = duty_part
    part.devices = {31: "charger"}
    part.active = False
    response = part.serve(INFO_DUTY, NS(node_id=31), NS(success=True, message=""))
    assert response.success is False and "not active" in response.message
    assert part.stats[INFO_DUTY.name].counts == {"calls": 1, "failed.inactive": 1}


def test_restart_status_zero_is_success() -> None:
    from sam_runtime.bridge.backends.service_mappings import from_uavcan

    mapping = NS(response=(_link("success", "status", "ok_if_zero"),))
    assert from_uavcan(mapping, NS(status=0), []) == {"success": True}
    assert from_uavcan(mapping, NS(status=3), []) == {"success": False}


def test_the_published_diagnostics_cdr_is_the_message(part: cyphal_services.CyphalServices) -> None:
    """The service mappings publish their /diagnostics as CDR (statuses_cdr): rclpy deserializes the very message
    diagnostics_message() builds, after calls that answered, timed out and failed (WARN)."""
    pytest.importorskip("diagnostic_msgs")
    from diagnostic_msgs.msg import DiagnosticArray
    from rclpy.serialization import deserialize_message

    from sam_runtime.bridge.diagnostics import statuses_cdr

    m = part.mappings[0]
    part.count(m, "calls", 3, problem=False)
    part.count(m, "answered", 1, problem=False)
    part.count(m, "timeouts")
    part.count(m, "failed.link_down")
    stamp_ns = 1_700_000_000_123_456_789
    got = deserialize_message(statuses_cdr(part.diagnostics_statuses(), stamp_ns), DiagnosticArray)
    want = part.diagnostics_message(stamp_ns)
    assert got == want
    (status,) = got.status
    assert status.level == b"\x01" and status.name == "bridge/service/limits"
    values = {kv.key: kv.value for kv in status.values}
    assert values["calls"] == "3" and values["timeouts"] == "1" and values["failed.link_down"] == "1"
