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

import collections
import logging
from collections.abc import Sequence
from typing import Any

from sam_runtime.bridge.backends.service_mappings import Call, ServiceMappingsRos, from_uavcan, to_uavcan
from sam_runtime.bridge.lifetime import Lifetime

__all__ = ["DroneCanServices", "from_uavcan", "to_uavcan"]

_FINISHED_KEPT = 1024  # requests remembered after their end, to tell late and duplicate responses apart


class DroneCanServices(ServiceMappingsRos):
    """:param backend: the bridge's DroneCanBackend (``on_open``, ``node``).
    :param ros: the bridge's RosSide (its context and name).
    :param mappings: the generated ``services.SERVICE_MAPPINGS``."""

    protocol = "DroneCAN"

    def __init__(self, lifetime: Lifetime, backend: Any, ros: Any, mappings: Sequence[Any], *,
                 diagnostics_period: float = 1.0) -> None:
        super().__init__(lifetime, backend, ros, mappings, diagnostics_period=diagnostics_period)
        # who gets a response from (data type id, node): a mapping with a fixed device, else one of that data type
        # whose request names the node
        self._by_key = {(m.data_type_id, m.destination_node_id): m for m in self.mappings
                        if m.destination_field is None}
        self._by_type = {m.data_type_id: m for m in self.mappings if m.destination_field is not None}
        self._pending: dict[tuple[int, int, int], Call] = {}  # in the loop's thread only
        self._finished: collections.OrderedDict[tuple[int, int, int], str] = collections.OrderedDict()
        self._sending: Call | None = None  # the call node.request is sending (its transfer id comes by the hook)

    def attach(self) -> None:
        self.backend.on_open(self._on_open)
        super().attach()

    # ------------------------------------------------------------------------------------------------ UAVCAN side
    def send(self, m: Any, nid: int, values: dict[str, Any], call: Call) -> None:
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
        node_loop = getattr(self.backend, "node_loop", None)
        if node_loop is not None:  # the request's timeout is on dronecan's scheduler: the NodeLoop re-arms its timer
            node_loop.wake()

    def _on_response(self, m: Any, nid: int, call: Call, event: Any) -> None:
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
