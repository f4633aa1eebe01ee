"""The bridge's service mappings on DroneCAN (issue 19): each ROS service of ``services.py`` (generated from the
spec's ``bridge.service_mappings``) answered by a v0 request to its device.

Threads: the ROS services live on a ROS node of their own, served by a MultiThreadedExecutor with a reentrant
callback group (max(4, 2 per mapping) threads: more calls at once wait for a free one), so one slow device holds
one executor thread for at most its mapping's timeout and never another call, the bridge's topics (another
executor) or its UAVCAN loop. A call converts the ROS request (in that thread), hands it to the asyncio loop's
thread, which owns the dronecan node (``call_soon_threadsafe``), and waits for the response or the timeout;
dronecan's request callback (in the loop's thread) converts the response and wakes it.

The caller learns of a failure (no answer within ``timeout_s``, the link down, a request that could not be sent)
by the response: the srv's default values, with its bool ``success`` False and its string ``message`` the reason
when the srv has those fields (std_srvs' convention; the ROS client never waits forever). Every call is counted per
mapping: ``calls``, ``answered``, ``timeouts``, ``failed.<reason>``, ``saturated.<field>``, and responses that reach
no waiting call are counted and dropped, never raised: ``late_responses`` (after its call timed out),
``duplicate_responses`` (a second answer), ``malformed_responses`` (a payload dronecan could not decode: the call
then times out); a response to no request of the mappings is left to dronecan, which drops it (another part of the
bridge, the node duties, may be its asker). The counters are published once a second, and at
once after a failure, on /diagnostics as ``<bridge>/service/<name>`` (WARN for 10 s after a failure or a bad
response), and are in the bridge's ``stats()["services"]``.
"""

from __future__ import annotations

import asyncio
import collections
import importlib
import logging
import math
import threading
import time
from collections.abc import Sequence
from typing import Any

from sam_runtime.bridge.backends.spin_thread import SpinThread
from sam_runtime.bridge.lifetime import Lifetime

__all__ = ["DroneCanServices", "from_uavcan", "to_uavcan"]

WARN_AFTER_PROBLEM_S = 10.0
_FINISHED_KEPT = 1024  # requests remembered after their end, to tell late and duplicate responses apart
_EXECUTOR_THREADS = 4


def _number(link: Any, value: float, towards_uavcan: bool, saturated: list[str]) -> Any:
    """One number by a link's rule (scale/offset, rounding, saturation); ``saturated`` gets the target's name when
    the value had to be limited."""
    if link.scale is not None or link.offset is not None:
        scale = 1.0 if link.scale is None else link.scale
        offset = 0.0 if link.offset is None else link.offset
        value = (value - offset) / scale if towards_uavcan else value * scale + offset
    if link.kind == "bool":
        return bool(value)
    if link.kind == "int":
        if math.isnan(value):
            saturated.append(link.target)
            return 0
        if value < link.lo or value > link.hi:
            saturated.append(link.target)
            value = min(max(value, link.lo), link.hi)
        return round(value)
    value = float(value)
    if math.isfinite(value) and not link.lo <= value <= link.hi:
        saturated.append(link.target)
        value = min(max(value, link.lo), link.hi)
    return value


def _convert(links: Sequence[Any], source: Any, towards_uavcan: bool, saturated: list[str]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for link in links:
        raw = link.value
        if link.source is not None:  # a response's source may be nested: "status.uptime_sec"
            raw = source
            for name in link.source.split("."):
                raw = getattr(raw, name)
        if link.kind == "text":
            if towards_uavcan:
                data = str(raw).encode()
                if len(data) > link.hi:
                    saturated.append(link.target)
                out[link.target] = data[: int(link.hi)]
            else:
                text = bytes(int(b) for b in raw).decode(errors="replace") if not isinstance(raw, str) else raw
                if math.isfinite(link.hi) and len(text) > link.hi:
                    saturated.append(link.target)
                    text = text[: int(link.hi)]
                out[link.target] = text
        else:
            out[link.target] = _number(link, float(raw), towards_uavcan, saturated)
    return out


def to_uavcan(mapping: Any, request: Any, saturated: list[str]) -> dict[str, Any]:
    """The UAVCAN request's fields from a ROS request (every field of the request).

    >>> from types import SimpleNamespace as S
    >>> link = S(target="level", source="percent", kind="int", value=None, scale=0.5, offset=None, lo=0, hi=255)
    >>> sat: list[str] = []
    >>> to_uavcan(S(request=(link,)), S(percent=200.0), sat), sat
    ({'level': 255}, ['level'])
    """
    return _convert(mapping.request, request, True, saturated)


def from_uavcan(mapping: Any, response: Any, saturated: list[str]) -> dict[str, Any]:
    """The ROS response's fields from a UAVCAN response (the linked ones).

    >>> from types import SimpleNamespace as S
    >>> link = S(target="ok", source="success", kind="bool", value=None, scale=None, offset=None, lo=0, hi=1)
    >>> from_uavcan(S(response=(link,)), S(success=1), [])
    {'ok': True}
    """
    return _convert(mapping.response, response, False, saturated)


class _Call:
    """One call in flight: filled in the loop's thread, read by the waiting service thread."""

    def __init__(self) -> None:
        self.done = threading.Event()
        self.values: dict[str, Any] | None = None
        self.failure: str | None = None  # the reason, for the caller and the counters
        self.reason: str = ""  # the counter key of a failure
        self.key: tuple[int, int, int] | None = None  # (data type id, device, transfer id) once sent


class _Stats:
    def __init__(self, mapping: Any) -> None:
        self.mapping = mapping
        self.counts: collections.Counter[str] = collections.Counter()
        self.last_problem: float | None = None
        self.latency_ms_last: float | None = None
        self.latency_ms_max: float = 0.0

    def problem(self, key: str, n: int = 1) -> None:
        self.counts[key] += n
        self.last_problem = time.monotonic()


class DroneCanServices:
    """:param backend: the bridge's DroneCanBackend (``on_open``, ``node``).
    :param ros: the bridge's RosSide (its context and name).
    :param mappings: the generated ``services.SERVICE_MAPPINGS``."""

    def __init__(self, lifetime: Lifetime, backend: Any, ros: Any, mappings: Sequence[Any], *,
                 diagnostics_period: float = 1.0) -> None:
        self.lifetime, self.backend, self.ros = lifetime, backend, ros
        self.mappings = list(mappings)
        self.diagnostics_period = float(diagnostics_period)
        self._lock = threading.Lock()
        self.stats = {m.name: _Stats(m) for m in self.mappings}
        # who gets a response from (data type id, node): a mapping with a fixed device, else one of that data type
        # whose request names the node
        self._by_key = {(m.data_type_id, m.destination_node_id): m for m in self.mappings
                        if m.destination_field is None}
        self._by_type = {m.data_type_id: m for m in self.mappings if m.destination_field is not None}
        self._pending: dict[tuple[int, int, int], _Call] = {}  # in the loop's thread only
        self._finished: collections.OrderedDict[tuple[int, int, int], str] = collections.OrderedDict()
        self._sending: _Call | None = None  # the call node.request is sending (its transfer id comes by the hook)
        self._loop: asyncio.AbstractEventLoop | None = None
        self._spinner: SpinThread | None = None  # the services' node on its executor thread
        self._diag_pub: Any = None

    def attach(self) -> None:
        self.backend.on_open(self._on_open)
        self.lifetime.add_hooks("DroneCAN service mappings", start=self._start, close=self._close)

    # ------------------------------------------------------------------------------------------------ ROS side
    def _start(self) -> None:
        from rclpy.callback_groups import ReentrantCallbackGroup
        from rclpy.executors import MultiThreadedExecutor
        from rclpy.node import Node

        self._loop = asyncio.get_running_loop()
        base = self.ros.name
        node = Node(f"{base}_services", context=self.ros.context)
        group = ReentrantCallbackGroup()
        for m in self.mappings:
            srv_type = getattr(importlib.import_module(m.ros_module), m.ros_class)
            node.create_service(srv_type, m.service, self._callback(m), callback_group=group)
        if self.diagnostics_period > 0:
            from diagnostic_msgs.msg import DiagnosticArray

            self._diag_pub = node.create_publisher(DiagnosticArray, "/diagnostics", 10)
            node.create_timer(self.diagnostics_period, self.publish_diagnostics, callback_group=group)
        threads = max(_EXECUTOR_THREADS, 2 * len(self.mappings))  # two calls in flight per mapping at least
        executor = MultiThreadedExecutor(num_threads=threads, context=self.ros.context)
        self._spinner = SpinThread(self.lifetime, self.ros.context, executor, node, f"{base}-services",
                                   "service_executor_error", "service mappings")
        self._spinner.start()

    def _close(self) -> None:
        if self._spinner is not None:
            self._spinner.close()

    def _callback(self, m: Any) -> Any:
        return lambda request, response: self.serve(m, request, response)

    def serve(self, m: Any, request: Any, response: Any) -> Any:
        """A ROS call of mapping ``m`` (an executor thread): the device's answer in ``response``, or the failure."""
        st = self.stats[m.name]
        with self._lock:
            st.counts["calls"] += 1
        saturated: list[str] = []
        try:
            values = to_uavcan(m, request, saturated)
        except Exception as ex:  # a value the conversion cannot take (a bug: the spec's types are checked)
            return self._fail(m, response, "convert_error", f"the request cannot be converted: {ex}")
        nid = m.destination_node_id
        if m.destination_field is not None:
            nid = int(getattr(request, m.destination_field))
            if not 1 <= nid <= 127:
                return self._fail(m, response, "bad_node_id", f"{nid} is not a DroneCAN node id (1..127)")
        call = _Call()
        loop = self._loop
        if loop is None or loop.is_closed() or self.lifetime.closed:
            return self._fail(m, response, "not_running", "the bridge is not running")
        started = time.monotonic()
        loop.call_soon_threadsafe(self._send, m, nid, values, call)
        # dronecan's own timeout ends the call; the margin only guards against a stalled loop.
        if not call.done.wait(m.timeout_s + 2.0):
            call.failure, call.reason = f"the bridge's loop did not answer within {m.timeout_s + 2.0:.1f} s", "stalled"
        with self._lock:
            for name in saturated:
                st.counts[f"saturated.{name}"] += 1
        if call.failure is not None or call.values is None:
            return self._fail(m, response, call.reason or "failed", call.failure or "no answer", nid)
        for name, value in call.values.items():
            setattr(response, name, value)
        with self._lock:
            st.counts["answered"] += 1
            st.latency_ms_last = round((time.monotonic() - started) * 1000.0, 3)
            st.latency_ms_max = max(st.latency_ms_max, st.latency_ms_last)
        return response

    def _fail(self, m: Any, response: Any, reason: str, text: str, nid: int | None = None) -> Any:
        st = self.stats[m.name]
        with self._lock:
            st.problem("timeouts" if reason == "timeout" else f"failed.{reason}")
        self.lifetime.rlog.note((f"service {m.name}", reason), logging.WARNING, "service %s (%s, node %d): %s",
                                m.service, m.data_type, m.destination_node_id if nid is None else nid, text)
        if m.success_field is not None:
            setattr(response, m.success_field, False)
        if m.message_field is not None:
            setattr(response, m.message_field, text)
        self.publish_diagnostics()
        return response

    # ------------------------------------------------------------------------------------------------ UAVCAN side
    def _send(self, m: Any, nid: int, values: dict[str, Any], call: _Call) -> None:
        """In the loop's thread: the request to the device; its response or timeout ends ``call``."""
        import dronecan

        node = self.backend.node
        if node is None:
            call.failure, call.reason = "the DroneCAN link is down", "link_down"
            call.done.set()
            return
        try:
            request = dronecan.TYPENAMES[m.data_type].Request()
            for name, value in values.items():
                setattr(request, name, value)
            self._sending = call
            try:
                node.request(request, nid, lambda event: self._on_response(m, nid, call, event), timeout=m.timeout_s)
            finally:
                self._sending = None
        except Exception as ex:
            call.failure, call.reason = f"the request was not sent: {type(ex).__name__}: {ex}", "send_error"
            call.done.set()
            return
        if call.key is not None:
            self._pending[call.key] = call

    def _on_response(self, m: Any, nid: int, call: _Call, event: Any) -> None:
        """dronecan's request callback (the loop's thread): the response, or None at the timeout."""
        key = call.key
        if key is not None:
            self._pending.pop(key, None)
            self._finished[key] = "timed_out" if event is None else "answered"
            while len(self._finished) > _FINISHED_KEPT:
                self._finished.popitem(last=False)
        if event is None:
            who = f"node {nid}" + (f" ({m.device})" if m.device else "")
            call.failure, call.reason = f"{who} did not answer within {m.timeout_s:g} s", "timeout"
        else:
            saturated: list[str] = []
            try:
                call.values = from_uavcan(m, event.response, saturated)
            except Exception as ex:
                call.failure, call.reason = f"the response cannot be converted: {ex}", "convert_error"
            if saturated:
                with self._lock:
                    for name in saturated:
                        self.stats[m.name].counts[f"saturated.{name}"] += 1
        call.done.set()

    def _on_open(self, node: Any, node_loop: Any) -> None:
        node.add_transfer_hook(self._hook)
        node_loop.drops.add_listener(self._on_drop)
        self._pending.clear()

    def _hook(self, transfer: Any) -> None:
        """Every transfer in or out (the loop's thread), before dronecan matches a response to its request."""
        if not transfer.service_not_message:
            return
        if getattr(transfer, "direction", "") == "tx":
            if transfer.request_not_response and self._sending is not None:
                self._sending.key = (transfer.data_type_id, transfer.dest_node_id, transfer.transfer_id)
            return
        if transfer.request_not_response or transfer.dest_node_id != self.backend.node_id:
            return
        key = (transfer.data_type_id, transfer.source_node_id, transfer.transfer_id)
        if key in self._pending:
            return  # the answer its call waits for: dronecan hands it over next
        state = self._finished.get(key)
        if state is None:
            return  # a response to no request of ours (another part of the bridge asked): dronecan's business
        m = self._by_key.get(key[:2]) or self._by_type.get(key[0])
        if m is None:
            return
        reason = "late_responses" if state == "timed_out" else "duplicate_responses"
        with self._lock:
            self.stats[m.name].problem(reason)
        self.lifetime.rlog.note((f"service {m.name}", reason), logging.WARNING,
                                "service %s: %s from node %d dropped (transfer id %d)", m.service,
                                reason.replace("_", " ")[:-1], transfer.source_node_id, transfer.transfer_id)

    def _on_drop(self, key: Any, detail: str) -> None:
        """A transfer dronecan could not decode (the NodeLoop counted it): a malformed response of a mapping."""
        m = self._by_key.get((key.data_type_id, key.source_node_id)) or self._by_type.get(key.data_type_id)
        if m is None or "malformed" not in str(getattr(key.reason, "value", key.reason)):
            return
        with self._lock:
            self.stats[m.name].problem("malformed_responses")

    # ------------------------------------------------------------------------------------------------ reports
    def snapshot(self) -> dict[str, Any]:
        now = time.monotonic()
        out: dict[str, Any] = {}
        with self._lock:
            for name, st in self.stats.items():
                m = st.mapping
                out[name] = {
                    "service": m.service, "ros_type": m.ros_type, "data_type": m.data_type,
                    "data_type_id": m.data_type_id, "destination_node_id": m.destination_node_id,
                    "device": m.device, "destination_field": m.destination_field, "timeout_s": m.timeout_s,
                    **{k: st.counts.get(k, 0) for k in ("calls", "answered", "timeouts", "late_responses",
                                                         "duplicate_responses", "malformed_responses")},
                    **{k: v for k, v in sorted(st.counts.items()) if "." in k},
                    "latency_ms_last": st.latency_ms_last, "latency_ms_max": st.latency_ms_max,
                    "warn": st.last_problem is not None and now - st.last_problem < WARN_AFTER_PROBLEM_S,
                }
        return out

    def diagnostics_message(self) -> Any:
        from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue

        array = DiagnosticArray()
        array.header.stamp = self.ros.clock.now().to_msg()
        for name, entry in self.snapshot().items():
            status = DiagnosticStatus()
            status.name = f"{self.ros.name}/service/{name}"
            status.hardware_id = (f"node {entry['destination_node_id']} ({entry['device']})" if entry["device"]
                                  else f"the node of the request's {entry['destination_field']}")
            status.level = DiagnosticStatus.WARN if entry["warn"] else DiagnosticStatus.OK
            status.message = (f"{entry['answered']}/{entry['calls']} answered, {entry['timeouts']} timed out"
                              + (" (a recent failure or bad response)" if entry["warn"] else ""))
            status.values = [KeyValue(key=k, value=str(v)) for k, v in entry.items() if k != "warn"]
            array.status.append(status)
        return array

    def publish_diagnostics(self) -> None:
        """Never raises (the timer and after a failure; rclpy's publish is thread-safe)."""
        if self._diag_pub is None or self.lifetime.closed:
            return
        try:
            self._diag_pub.publish(self.diagnostics_message())
        except Exception as ex:
            self.lifetime.errors["service_diagnostics_error"] += 1
            self.lifetime.rlog.note(("service", "diagnostics"), logging.ERROR, "service diagnostics: %s: %s",
                                    type(ex).__name__, ex)
