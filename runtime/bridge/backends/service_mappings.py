"""The ROS side of the bridge's service mappings, whatever the protocol (issue 19): each ROS service of
``services.py`` (generated from the spec's ``bridge.service_mappings``) answered by a request to its device, which a
protocol's subclass sends (``dronecan_services``, ``cyphal_services``).

Threads: the ROS services live on a ROS node of their own, served by the bridge's executor of waiting calls
(backends.spin_thread.WaitingCalls: one thread and a pool of up to 16, shared with the boards' store services) with a
reentrant callback group, so one slow device holds one pool thread for at most its mapping's timeout and never another
call, the bridge's topics (another executor) or its UAVCAN loop. A call converts the ROS request (in that thread),
hands it to the asyncio loop's thread, which owns the UAVCAN node (``call_soon_threadsafe`` of the subclass's
``send``), and waits for the response or the timeout; the subclass ends the :class:`Call` in the loop's thread (values
or a failure).

A device duty (a mapping with ``duty``, of the spec's ``bridge.node_services``) whose srv type is not installed (a
spec whose ROS package was not built, its other interfaces all standard) is not served: logged once, counted as the
bridge's ``service_type_missing``, ``served: false`` in its stats; a mapping the spec declares needs its type.

The caller learns of a failure (no answer within ``timeout_s``, the link down, a request that could not be sent)
by the response: the srv's default values, with its bool ``success`` False and its string ``message`` the reason
when the srv has those fields (std_srvs' convention; the ROS client never waits forever). Every call is counted per
mapping: ``calls``, ``answered``, ``timeouts``, ``failed.<reason>``, ``saturated.<field>``, and the responses that
reach no waiting call (``late_responses``, ``duplicate_responses``, ``malformed_responses``, counted by the
subclass). The counters are published once a second (in the loop's housekeeping round), and at once after a
failure, on /diagnostics as ``<bridge>/service/<name>`` (WARN for 10 s after a failure or a bad response), and are
in the bridge's ``stats()["services"]``.
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

from sam_codegen.model.text import cut_utf8, encode_text
from sam_runtime.bridge.counters import log
from sam_runtime.bridge.diagnostics import Status, statuses_cdr
from sam_runtime.bridge.lifetime import Lifetime

__all__ = ["Call", "MappingStats", "ServiceMappingsRos", "from_uavcan", "set_field", "to_uavcan"]

WARN_AFTER_PROBLEM_S = 10.0


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
        if link.kind == "bytes":  # a uint8 array as it is (a unique id)
            out[link.target] = [int(b) for b in raw]
        elif link.kind == "ok_if_zero":  # a status code: 0 is success
            out[link.target] = int(raw) == 0
        elif link.kind == "int" and link.scale is None and link.offset is None and not isinstance(raw, float) \
                and float(raw).is_integer():  # exact, also beyond 2**53 (a uint64 revision id)
            value = int(raw)
            if not link.lo <= value <= link.hi:
                saturated.append(link.target)
                value = int(min(max(value, link.lo), link.hi))
            out[link.target] = value
        elif link.kind == "text":
            if towards_uavcan:
                data = encode_text(str(raw))
                if len(data) > link.hi:  # cut at a character boundary, as the topic mappings' converters do
                    saturated.append(link.target)
                    data = cut_utf8(data, int(link.hi))
                out[link.target] = data
            else:
                text = bytes(int(b) for b in raw).decode(errors="replace") if not isinstance(raw, str) else raw
                if math.isfinite(link.hi) and len(text) > link.hi:
                    saturated.append(link.target)
                    text = text[: int(link.hi)]
                out[link.target] = text
        else:
            out[link.target] = _number(link, float(raw), towards_uavcan, saturated)
    return out


def set_field(message: Any, path: str, value: Any) -> None:
    """Set a response field by its path: `status.uptime_sec` is a field of the response's message field `status`
    (issue 27: a nested response field is written, never left at zero)."""
    *parents, name = path.split(".")
    for parent in parents:
        message = getattr(message, parent)
    setattr(message, name, value)


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


class Call:
    """One call in flight: filled in the loop's thread, read by the waiting service thread."""

    def __init__(self) -> None:
        self.done = threading.Event()
        self.values: dict[str, Any] | None = None
        self.failure: str | None = None  # the reason, for the caller and the counters
        self.reason: str = ""  # the counter key of a failure
        self.key: tuple[int, int, int] | None = None  # (data type id, device, transfer id) once sent


class MappingStats:
    def __init__(self, mapping: Any) -> None:
        self.mapping = mapping
        self.counts: collections.Counter[str] = collections.Counter()
        self.last_problem: float | None = None
        self.latency_ms_last: float | None = None
        self.latency_ms_max: float = 0.0

    def problem(self, key: str, n: int = 1) -> None:
        self.counts[key] += n
        self.last_problem = time.monotonic()


class ServiceMappingsRos:
    """The protocol-independent part. Subclasses set ``protocol``, ``node_ids`` (the valid destination node ids)
    and implement ``send`` (the loop's thread: the request out, ``call`` ended by its response or its timeout).

    :param backend: the bridge's backend.
    :param ros: the bridge's RosSide (its context and name).
    :param mappings: the generated ``services.SERVICE_MAPPINGS`` this protocol serves."""

    protocol = "UAVCAN"
    node_ids = range(1, 128)

    def __init__(self, lifetime: Lifetime, backend: Any, ros: Any, mappings: Sequence[Any], *,
                 diagnostics_period: float = 1.0) -> None:
        self.lifetime, self.backend, self.ros = lifetime, backend, ros
        self.mappings = list(mappings)
        self.diagnostics_period = float(diagnostics_period)
        self._lock = threading.Lock()
        self.stats = {m.name: MappingStats(m) for m in self.mappings}
        self._loop: asyncio.AbstractEventLoop | None = None
        self._node: Any = None  # the services' node, on the bridge's executor of waiting calls
        self._diag_pub: Any = None
        # The device duties (mappings with a ``duty``) answer for these nodes only (node id -> device name: the
        # devices the layout puts on this bridge's protocol); ``duty_suffix`` ("_dronecan" in a mixed layout, where
        # two bridges share one namespace) goes after their service names; ``health`` (the bridge's DeviceHealth)
        # has each node's last heartbeat. Set by the composition root.
        self.devices: dict[int, str] = {}
        self.duty_suffix = ""
        self.health: Any = None
        self.unserved: set[str] = set()  # duties whose srv type is not installed
        self.status_prefix = ros.name  # /diagnostics names: the bridge's, with its namespace (composition sets it)
        # False while a managed bridge is not active (sam_runtime.bridge.managed): no request goes to the bus, each
        # call fails at once as ``failed.inactive``
        self.active = True

    def send(self, m: Any, nid: int, values: dict[str, Any], call: Call) -> None:
        raise NotImplementedError

    def attach(self) -> None:
        self.lifetime.add_hooks(f"{self.protocol} service mappings", start=self._start, close=self._close)
        if self.diagnostics_period > 0:
            # On the loop, in the bridge's housekeeping round (its period is the bridge's /diagnostics period): an
            # rclpy timer woke the services' executor thread and one of its workers every period for it.
            self.lifetime.every(self.diagnostics_period, "service diagnostics", self.publish_diagnostics)

    def count(self, m: Any, key: str, n: int = 1, problem: bool = True) -> None:
        """Add to a mapping's counter (any thread)."""
        with self._lock:
            if problem:
                self.stats[m.name].problem(key, n)
            else:
                self.stats[m.name].counts[key] += n

    # ------------------------------------------------------------------------------------------------ ROS side
    def _start(self) -> None:
        from rclpy.callback_groups import ReentrantCallbackGroup
        from rclpy.node import Node

        self._loop = asyncio.get_running_loop()
        base = self.ros.name
        # in the bridge's namespace: relative service names (the duties' defaults) resolve where its topics do
        node = Node(f"{base}_services", namespace=self.ros.node.get_namespace(), context=self.ros.context)
        group = ReentrantCallbackGroup()
        for m in self.mappings:
            try:
                srv_type = getattr(importlib.import_module(m.ros_module), m.ros_class)
            except (ImportError, AttributeError) as ex:
                if getattr(m, "duty", None) is None:
                    raise  # a mapping the spec declares: its package must be there
                # a built-in duty of a spec whose ROS package is not built (its other interfaces are standard):
                # the bridge runs without it, and says so
                self.unserved.add(m.name)
                self.lifetime.errors["service_type_missing"] += 1
                log.warning("the device duty %s (%s) is not served: %s is not installed (%s; build the spec's ROS "
                            "package: sam-codegen ros-install)", m.duty, self.service_name(m), m.ros_type, ex)
                continue
            node.create_service(srv_type, self.service_name(m), self._callback(m), callback_group=group)
        if self.diagnostics_period > 0:
            from diagnostic_msgs.msg import DiagnosticArray

            self._diag_pub = node.create_publisher(DiagnosticArray, "/diagnostics", 10)
        self._node = node
        self.ros.waiting_calls.add(self.ros.context, node)

    def service_name(self, m: Any) -> str:
        """The ROS name a mapping is served under (a duty's with the layout's protocol suffix)."""
        return m.service + self.duty_suffix if getattr(m, "duty", None) is not None else m.service

    def _close(self) -> None:
        node, self._node = self._node, None
        if node is not None:
            self.ros.waiting_calls.remove(node)

    def _callback(self, m: Any) -> Any:
        return lambda request, response: self.serve(m, request, response)

    def serve(self, m: Any, request: Any, response: Any) -> Any:
        """A ROS call of mapping ``m`` (an executor thread): the device's answer in ``response``, or the failure."""
        st = self.stats[m.name]
        with self._lock:
            st.counts["calls"] += 1
        if not self.active:
            return self._fail(m, response, "inactive", "the bridge is not active (its lifecycle manager has not "
                              "activated it)")
        saturated: list[str] = []
        try:
            values = to_uavcan(m, request, saturated)
        except Exception as ex:  # a value the conversion cannot take (a bug: the spec's types are checked)
            return self._fail(m, response, "convert_error", f"the request cannot be converted: {ex}")
        nid = m.destination_node_id
        if m.destination_field is not None:
            nid = int(getattr(request, m.destination_field))
            if nid not in self.node_ids:
                return self._fail(m, response, "bad_node_id", f"{nid} is not a {self.protocol} node id "
                                  f"({self.node_ids.start}..{self.node_ids.stop - 1})")
            if getattr(m, "duty", None) is not None and nid not in self.devices:
                known = ", ".join(f"{n} ({name})" for n, name in sorted(self.devices.items())) or "none"
                return self._fail(m, response, "bad_node_id", f"node {nid} is no {self.protocol} device of this "
                                  f"bridge (its devices: {known})", nid)
        call = Call()
        loop = self._loop
        if loop is None or loop.is_closed() or self.lifetime.closed:
            return self._fail(m, response, "not_running", "the bridge is not running")
        started = time.monotonic()
        loop.call_soon_threadsafe(self.send, m, nid, values, call)
        # the protocol's own timeout ends the call; the margin only guards against a stalled loop.
        if not call.done.wait(m.timeout_s + 2.0):
            call.failure, call.reason = f"the bridge's loop did not answer within {m.timeout_s + 2.0:.1f} s", "stalled"
        with self._lock:
            for name in saturated:
                st.counts[f"saturated.{name}"] += 1
        if call.failure is not None or call.values is None:
            return self._fail(m, response, call.reason or "failed", call.failure or "no answer", nid)
        for name, value in call.values.items():
            set_field(response, name, value)
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

    # ------------------------------------------------------------------------------------------------ reports
    def snapshot(self) -> dict[str, Any]:
        now = time.monotonic()
        out: dict[str, Any] = {}
        with self._lock:
            for name, st in self.stats.items():
                m = st.mapping
                out[name] = {
                    "service": self.service_name(m), "ros_type": m.ros_type, "data_type": m.data_type,
                    "data_type_id": m.data_type_id, "destination_node_id": m.destination_node_id,
                    "device": m.device, "destination_field": m.destination_field, "timeout_s": m.timeout_s,
                    **{k: st.counts.get(k, 0) for k in ("calls", "answered", "timeouts", "late_responses",
                                                         "duplicate_responses", "malformed_responses")},
                    **{k: v for k, v in sorted(st.counts.items()) if "." in k},
                    "latency_ms_last": st.latency_ms_last, "latency_ms_max": st.latency_ms_max,
                    "served": name not in self.unserved,
                    "warn": st.last_problem is not None and now - st.last_problem < WARN_AFTER_PROBLEM_S,
                }
        return out

    def diagnostics_statuses(self) -> list[Status]:
        """One status per mapping: (level, name, message, hardware_id, values) as sam_runtime.bridge.diagnostics'."""
        out: list[Status] = []
        for name, entry in self.snapshot().items():
            hardware_id = (f"node {entry['destination_node_id']} ({entry['device']})" if entry["device"]
                           else f"the node of the request's {entry['destination_field']}")
            message = (f"{entry['answered']}/{entry['calls']} answered, {entry['timeouts']} timed out"
                       + (" (a recent failure or bad response)" if entry["warn"] else ""))
            values = {k: str(v) for k, v in entry.items() if k != "warn"}
            out.append((1 if entry["warn"] else 0, f"{self.status_prefix}/service/{name}", message, hardware_id,
                        values))
        return out

    def diagnostics_message(self, stamp_ns: int | None = None) -> Any:
        """The statuses as a diagnostic_msgs/DiagnosticArray (what :meth:`publish_diagnostics` publishes as CDR)."""
        from builtin_interfaces.msg import Time
        from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue

        array = DiagnosticArray()
        ns = self.ros.clock.now().nanoseconds if stamp_ns is None else int(stamp_ns)
        array.header.stamp = Time(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)
        array.status = [DiagnosticStatus(level=bytes([level]), name=name, message=msg, hardware_id=hw,
                                         values=[KeyValue(key=k, value=v) for k, v in values.items()])
                        for level, name, msg, hw, values in self.diagnostics_statuses()]
        return array

    def publish_diagnostics(self) -> None:
        """Never raises (the housekeeping round, and a call thread after a failure; rclpy's publish is thread-safe)."""
        if self._diag_pub is None or self.lifetime.closed:
            return
        try:
            # Serialized here and published raw: building a KeyValue object per value (rclpy checks each field)
            # cost as much as the bridge's whole /diagnostics, once a second (sam_runtime.bridge.diagnostics).
            self._diag_pub.publish(statuses_cdr(self.diagnostics_statuses(), self.ros.clock.now().nanoseconds))
        except Exception as ex:
            self.lifetime.errors["service_diagnostics_error"] += 1
            self.lifetime.rlog.note(("service", "diagnostics"), logging.ERROR, "service diagnostics: %s: %s",
                                    type(ex).__name__, ex)
