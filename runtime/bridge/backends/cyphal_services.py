"""The bridge's service mappings on Cyphal (issue 19): each ROS service of ``services.py`` whose mapping says
``protocol: cyphal`` answered by a pycyphal client request to its device (the ROS side, the threads and the
counters: ``service_mappings``).

The loop's thread owns the pycyphal node: ``send`` (called there) starts a task that sends the request with a
client of (service type, server node id, service id) and awaits its response for the mapping's timeout; the client
is made once per (mapping, node) on the node of the current link and made again after the link reopens. pycyphal
matches a response to its request by transfer id and drops the others, counting them: a response that reaches no
waiting request (after its call timed out, or a second one) is ``unexpected_responses`` in pycyphal's client
statistics, counted here as ``late_responses`` (pycyphal does not tell late from duplicate), and a response it could
not deserialize is ``deserialization_failures``, counted as ``malformed_responses`` (the call then times out). The
clients' statistics are read in the loop's thread after each call and once a second. The device duty get_node_info
(GetInfo, which has no uptime, health, mode or vendor code) takes those from the node's last heartbeat the bridge
heard (0 when none).
"""

from __future__ import annotations

import asyncio
import importlib
import logging
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from sam_runtime.bridge.backends.service_mappings import Call, ServiceMappingsRos, from_uavcan
from sam_runtime.bridge.lifetime import Lifetime

__all__ = ["CyphalServices", "dsdl_class"]

_POLL_PERIOD_S = 1.0
# uavcan.node.Health.1.0 and Mode.1.0 by the names the backend's DeviceStatus gives them
_HEALTH = {"NOMINAL": 0, "ADVISORY": 1, "CAUTION": 2, "WARNING": 3}
_MODE = {"OPERATIONAL": 0, "INITIALIZATION": 1, "MAINTENANCE": 2, "SOFTWARE_UPDATE": 3}


@dataclass(frozen=True)
class _Heartbeat:
    uptime_s: int
    health: int
    mode: int
    vssc: int


def _code(names: dict[str, int], name: str) -> int:
    """A health or mode name back to its value (the backend keeps an unknown value as its digits)."""
    return names.get(name, int(name) if name.isdigit() else 0)


class _WithHeartbeat:
    """A GetInfo response whose links may also read ``heartbeat.<x>`` (the duty get_node_info on Cyphal)."""

    def __init__(self, response: Any, heartbeat: _Heartbeat) -> None:
        self._response, self.heartbeat = response, heartbeat

    def __getattr__(self, name: str) -> Any:
        return getattr(self._response, name)


def dsdl_class(full_name: str) -> Any:
    """The compiled pycyphal class of ``ns.Name.MAJOR.MINOR`` (its package compiled and on the path)."""
    parts = full_name.split(".")
    module = importlib.import_module(".".join(parts[:-3]))
    return getattr(module, f"{parts[-3]}_{parts[-2]}_{parts[-1]}")


class CyphalServices(ServiceMappingsRos):
    """:param backend: the bridge's CyphalBackend (``node``: the pycyphal node of the open link, or None)."""

    protocol = "Cyphal"
    node_ids = range(0, 65535)  # Cyphal/UDP's; a CAN transport takes 0..127 and pycyphal refuses the rest

    def __init__(self, lifetime: Lifetime, backend: Any, ros: Any, mappings: Sequence[Any], *,
                 diagnostics_period: float = 1.0) -> None:
        super().__init__(lifetime, backend, ros, mappings, diagnostics_period=diagnostics_period)
        self._types = {m.name: dsdl_class(m.data_type) for m in self.mappings}
        self._clients: dict[tuple[str, int], Any] = {}  # (mapping, node) -> client of the node below
        self._client_node: Any = None  # the pycyphal node the clients were made on
        self._seen: dict[tuple[str, int], tuple[int, int]] = {}  # a client's statistics already counted
        self._tasks: set[asyncio.Task[None]] = set()

    def attach(self) -> None:
        super().attach()
        self.lifetime.every(_POLL_PERIOD_S, "Cyphal service statistics", self.poll_statistics)

    def _client(self, m: Any, nid: int) -> Any:
        node = self.backend.node
        if node is not self._client_node:  # a new link: the old clients closed with their node
            self.poll_statistics()
            self._clients.clear()
            self._seen.clear()
            self._client_node = node
        key = (m.name, nid)
        client = self._clients.get(key)
        if client is None:
            client = node.presentation.make_client(self._types[m.name], service_id=m.data_type_id, server_node_id=nid)
            client.response_timeout = m.timeout_s
            self._clients[key] = client
        return client

    def send(self, m: Any, nid: int, values: dict[str, Any], call: Call) -> None:
        """In the loop's thread: the request to the device; its response or timeout ends ``call``."""
        if self.backend.node is None:
            call.failure, call.reason = "the Cyphal link is down", "link_down"
            call.done.set()
            return
        try:
            request = self._types[m.name].Request()
            for name, value in values.items():
                setattr(request, name, value)
            client = self._client(m, nid)
        except Exception as ex:
            call.failure, call.reason = f"the request was not sent: {type(ex).__name__}: {ex}", "send_error"
            call.done.set()
            return
        task = asyncio.get_running_loop().create_task(self._call(m, nid, client, request, call))
        self._tasks.add(task)
        task.add_done_callback(self._tasks.discard)

    async def _call(self, m: Any, nid: int, client: Any, request: Any, call: Call) -> None:
        try:
            result = await client.call(request)
        except Exception as ex:  # the transport closed under it, or it refused the request
            call.failure, call.reason = f"the request was not sent: {type(ex).__name__}: {ex}", "send_error"
            call.done.set()
            return
        if result is None:
            who = f"node {nid}" + (f" ({m.device})" if m.device else "")
            call.failure, call.reason = f"{who} did not answer within {m.timeout_s:g} s", "timeout"
        else:
            saturated: list[str] = []
            try:
                answer = result[0] if getattr(m, "duty", None) != "get_node_info" else _WithHeartbeat(
                    result[0], self.heartbeat(nid))
                call.values = from_uavcan(m, answer, saturated)
            except Exception as ex:
                call.failure, call.reason = f"the response cannot be converted: {ex}", "convert_error"
            for name in saturated:
                self.count(m, f"saturated.{name}", problem=False)
        call.done.set()
        self.poll_statistics()

    def heartbeat(self, nid: int) -> Any:
        """The node's last heartbeat as numbers (uptime_s, health, mode, vssc; 0 when none was heard): GetInfo
        has none of them, the duty's srv has them (DroneCAN's GetNodeInfo carries its NodeStatus)."""
        rec = self.health.records.get(nid) if self.health is not None else None
        if rec is None:
            return _Heartbeat(0, 0, 0, 0)
        st = rec.status
        return _Heartbeat(int(st.uptime_s), _code(_HEALTH, st.health), _code(_MODE, st.mode), int(st.vssc))

    def poll_statistics(self) -> None:
        """The clients' counts of responses that reached no request and of undecodable ones (the loop's thread)."""
        by_name = {m.name: m for m in self.mappings}
        for key, client in list(self._clients.items()):
            try:
                st = client.sample_statistics()
            except Exception:
                continue  # closed with its node
            now = (int(st.unexpected_responses), int(st.deserialization_failures))
            before = self._seen.get(key, (0, 0))
            self._seen[key] = now
            m = by_name[key[0]]
            for reason, n in (("late_responses", now[0] - before[0]), ("malformed_responses", now[1] - before[1])):
                if n > 0:
                    self.count(m, reason, n)
                    self.lifetime.rlog.note((f"service {m.name}", reason), logging.WARNING,
                                            "service %s: %d %s from node %d dropped", m.service, n,
                                            reason.replace("_", " "), key[1])

