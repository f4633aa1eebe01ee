"""The service-mapping part of the DroneCAN bridge alone (runtime/bridge/backends/dronecan_services.py): no bus,
no ROS node; dronecan's request callback and transfer hook are called as dronecan calls them.

- the conversions: scale/offset both ways, integers rounded half to even and saturated (counted), NaN into an
  integer, float32 saturation, text cut at its capacity, nested response paths;
- the responses that reach no waiting call: late (after the timeout) and duplicate, told apart by the request's
  transfer id; a response to a request of another part is not counted;
- a call's failure: the srv's success false and message the reason, counted; the link down.
"""

from __future__ import annotations

import logging
import math
from types import SimpleNamespace as NS
from typing import Any

from hypothesis import given, settings
from hypothesis import strategies as st

from sam_codegen.model.text import cut_utf8, cut_utf8_expr
from sam_runtime.bridge.backends.dronecan_services import DroneCanServices, from_uavcan, to_uavcan
from sam_runtime.bridge.lifetime import Lifetime
from sam_runtime.common.rate_log import RateLimitedLog

F32 = 3.4028234663852886e38


def _link(target: str, source: str | None, kind: str, value: Any = None, scale: float | None = None,
          offset: float | None = None, lo: float = -math.inf, hi: float = math.inf) -> NS:
    return NS(target=target, source=source, kind=kind, value=value, scale=scale, offset=offset, lo=lo, hi=hi)


MAPPING = NS(
    name="update", service="/bms/update", ros_type="p/srv/Update", data_type="v.Update", data_type_id=201,
    destination_node_id=30, device="bms", destination_field=None, timeout_s=0.5,
    request=(_link("command", "command", "int", lo=0, hi=255), _link("charge", "percent", "float", scale=0.5,
                                                                       offset=10.0, lo=-F32, hi=F32),
             _link("tag", "label", "text", hi=4)),
    response=(_link("success", "ok", "bool"), _link("uptime", "status.uptime_sec", "int", lo=0, hi=65535),
              _link("answered", None, "bool", value=True)),
    success_field="success", message_field="message",
)


def test_request_conversion_rounds_saturates_and_cuts() -> None:
    saturated: list[str] = []
    values = to_uavcan(MAPPING, NS(command=2.5, percent=110.0, label="abcdef"), saturated)
    assert values == {"command": 2, "charge": 200.0, "tag": b"abcd"}  # half to even; (110 - 10) / 0.5
    assert saturated == ["tag"]
    saturated.clear()
    assert to_uavcan(MAPPING, NS(command=300, percent=1e39, label=""), saturated) == {
        "command": 255, "charge": F32, "tag": b""}
    assert saturated == ["command", "charge"]
    saturated.clear()
    assert to_uavcan(MAPPING, NS(command=math.nan, percent=math.nan, label=""), saturated)["command"] == 0
    assert saturated == ["command"]  # NaN cannot be an integer; a float NaN passes


def test_response_conversion_reads_nested_fields() -> None:
    saturated: list[str] = []
    response = NS(ok=3, status=NS(uptime_sec=70000))
    assert from_uavcan(MAPPING, response, saturated) == {"success": True, "uptime": 65535, "answered": True}
    assert saturated == ["uptime"]


class _Backend:
    node_id = 100
    node: Any = None

    def on_open(self, hook: Any) -> None:
        pass


def _part() -> DroneCanServices:
    lifetime = Lifetime("bridge", RateLimitedLog(logging.getLogger("test"), 10.0))
    return DroneCanServices(lifetime, _Backend(), NS(name="bridge"), [MAPPING], diagnostics_period=0)


def _transfer(direction: str, request: bool, transfer_id: int, source: int, dest: int) -> NS:
    return NS(direction=direction, service_not_message=True, request_not_response=request, data_type_id=201,
              source_node_id=source, dest_node_id=dest, transfer_id=transfer_id)


class _Node:
    """dronecan's Node as the part uses it: request() calls the transfer hook with the outgoing request."""

    def __init__(self, part: DroneCanServices) -> None:
        self.part, self.next_id, self.callbacks = part, 0, {}

    def request(self, payload: Any, nid: int, callback: Any, timeout: float) -> None:
        self.part._hook(_transfer("tx", True, self.next_id, 100, nid))
        self.callbacks[self.next_id] = callback
        self.next_id += 1


def test_late_and_duplicate_responses_are_counted_and_dropped(monkeypatch: Any) -> None:
    import sys

    fake_type = NS(Request=lambda: NS())
    monkeypatch.setitem(sys.modules, "dronecan", NS(TYPENAMES={"v.Update": fake_type}))
    part = _part()
    node = _Node(part)
    part.backend.node = node
    from sam_runtime.bridge.backends import service_mappings as mod

    calls = [mod.Call(), mod.Call()]
    part.send(MAPPING, 30, {"command": 1}, calls[0])
    part.send(MAPPING, 30, {"command": 1}, calls[1])
    assert [c.key for c in calls] == [(201, 30, 0), (201, 30, 1)]
    node.callbacks[0](None)  # the first times out
    assert calls[0].reason == "timeout" and calls[0].done.is_set()
    part._hook(_transfer("rx", False, 1, 30, 100))  # the second's answer: awaited, not counted
    node.callbacks[1](NS(response=NS(ok=1, status=NS(uptime_sec=5))))
    assert calls[1].values == {"success": True, "uptime": 5, "answered": True}
    part._hook(_transfer("rx", False, 0, 30, 100))  # the first's answer, after its timeout
    part._hook(_transfer("rx", False, 1, 30, 100))  # the second's answer again
    part._hook(_transfer("rx", False, 7, 30, 100))  # a request of another part (the node duties)
    part._hook(_transfer("rx", False, 1, 30, 99))  # for another node
    counts = part.snapshot()["update"]
    assert counts["late_responses"] == 1 and counts["duplicate_responses"] == 1
    assert counts["warn"] is True


def test_a_failed_call_says_so_in_the_response() -> None:
    part = _part()
    part._loop = None  # not running
    response = NS(success=True, message="")
    assert part.serve(MAPPING, NS(command=1, percent=0.0, label=""), response) is response
    assert response.success is False and response.message == "the bridge is not running"
    part._fail(MAPPING, response, "timeout", "node 30 (bms) did not answer within 0.5 s")
    counts = part.snapshot()["update"]
    assert counts["calls"] == 1 and counts["failed.not_running"] == 1 and counts["timeouts"] == 1


def test_link_down_fails_the_call() -> None:
    from sam_runtime.bridge.backends import service_mappings as mod

    part = _part()
    call = mod.Call()
    part.send(MAPPING, 30, {}, call)  # backend.node is None
    assert call.done.is_set() and call.reason == "link_down" and call.failure == "the DroneCAN link is down"


def test_service_text_is_cut_at_a_character_boundary_as_topics_cut_it() -> None:
    """Issue 27 (class 6): 'éééé' into 7 bytes is 3 characters (6 bytes), never 'ééé' + a lone 0xC3; the rule is
    the one the generated topic converters inline (sam_codegen.model.text.cut_utf8_expr), checked on many texts."""
    mapping = NS(**{**vars(MAPPING), "request": (_link("tag", "label", "text", hi=7),)})
    saturated: list[str] = []
    assert to_uavcan(mapping, NS(label="éééé"), saturated) == {"tag": "ééé".encode()}
    assert saturated == ["tag"]

    @settings(max_examples=300, deadline=None)
    @given(st.text(), st.integers(0, 40))
    def agree(text: str, cap: int) -> None:
        data = text.encode(errors="replace")
        generated = eval(cut_utf8_expr("data", cap), {}, {"data": data})  # the topic converters' statement
        cut = to_uavcan(NS(**{**vars(MAPPING), "request": (_link("tag", "label", "text", hi=cap),)}),
                        NS(label=text), [])["tag"]
        assert cut == generated == cut_utf8(data, cap)
        assert len(cut) <= cap and data.startswith(cut)
        assert len(data) - len(cut) < 4 or len(cut) > cap - 4  # only the last, partial character goes
        cut.decode()  # valid UTF-8: no lone lead byte

    agree()
