"""The DroneCAN node duties of the bridge (those of SAM's current v0 bridge), a part attached to the bridge's
lifetime beside the DroneCAN backend:

- every device's ``uavcan.protocol.GetNodeInfo`` and ``uavcan.protocol.RestartNode`` as ROS services
  (std_srvs/Trigger) ``/<bridge>/<device>/get_node_info`` (the answer as JSON in ``message``) and
  ``/<bridge>/<device>/restart``;
- ``uavcan.protocol.Panic`` both ways (std_msgs/String): a Panic on the bus is published on ``/<bridge>/panic_received``
  as ``node <id>: <reason>``; a message on ``/<bridge>/panic`` is broadcast as Panic (reason: its first 7 bytes)
  MIN_MESSAGES (3) times 0.1 s apart, as receivers wait for 3 within MAX_INTERVAL_MS (500) before they act.
  ``panic=False`` (the spec's ``panic_duty: mappings``: its own mappings of Panic instead) leaves Panic alone; beside
  a mapping of Panic on the wire path (``panic_duty: both``) the tapped Panic transfers are shared with the node, so
  both see every Panic;
- optional: a dynamic node id allocation server (dronecan's CentralizedServer with its NodeMonitor, in memory).
  (The bus's GlobalTimeSync master is sam_runtime.bridge.time_sync's, on both protocols.)

The services live on a ROS node of their own with its own executor thread: a service call waits (at most
``timeout`` s) for the device's answer, and must never hold up the bridge's command path, which the bridge's
executor serves. The dronecan node belongs to the asyncio loop's thread: requests are handed to it with
``call_soon_threadsafe``. Handlers are registered on every node the backend opens (it reopens after a failure).
"""

from __future__ import annotations

import asyncio
import json
import logging
import threading
from collections.abc import Callable, Mapping
from typing import Any

from sam_runtime.bridge.backends.spin_thread import SpinThread
from sam_runtime.bridge.counters import log
from sam_runtime.bridge.lifetime import Lifetime

__all__ = ["DroneCanDuties", "node_info_json"]

PANIC_MIN_MESSAGES = 3
PANIC_INTERVAL_S = 0.1


def node_info_json(node_id: int, response: Any) -> str:
    """A GetNodeInfo response as JSON (name, versions, unique id, status).

    >>> from types import SimpleNamespace as S
    >>> r = S(name=b"org.sam.imu", status=S(uptime_sec=5, health=0, mode=0, vendor_specific_status_code=0),
    ...       software_version=S(major=1, minor=2, vcs_commit=0xABC), hardware_version=S(major=3, minor=0,
    ...       unique_id=[1, 2] + [0] * 14))
    >>> json.loads(node_info_json(21, r))["hardware_version"]["unique_id"]
    '01020000000000000000000000000000'
    """
    def text(v: Any) -> str:
        return bytes(v).decode(errors="replace") if not isinstance(v, str) else v

    st, sw, hw = response.status, response.software_version, response.hardware_version
    return json.dumps({
        "node_id": node_id, "name": text(response.name),
        "status": {"uptime_sec": int(st.uptime_sec), "health": int(st.health), "mode": int(st.mode),
                   "vendor_specific_status_code": int(st.vendor_specific_status_code)},
        "software_version": {"major": int(sw.major), "minor": int(sw.minor), "vcs_commit": int(sw.vcs_commit)},
        "hardware_version": {"major": int(hw.major), "minor": int(hw.minor),
                             "unique_id": bytes(int(b) for b in hw.unique_id).hex()},
    })


class DroneCanDuties:
    """:param backend: the bridge's DroneCanBackend (``on_open`` hook, ``node``).
    :param ros: the bridge's RosSide (its context, its name).
    :param devices: node id -> device name."""

    def __init__(self, lifetime: Lifetime, backend: Any, ros: Any, devices: Mapping[int, str], *,
                 dna_server: bool = False, timeout: float = 1.0, panic: bool = True) -> None:
        self.lifetime, self.backend, self.ros = lifetime, backend, ros
        self.devices = dict(devices)
        self.panic = bool(panic)  # the built-in Panic duty (off: the spec's mappings of Panic handle it)
        self.dna_server, self.timeout = bool(dna_server), float(timeout)
        self.counts: dict[str, int] = {"panic_in": 0, "panic_out": 0, "requests": 0, "request_timeouts": 0}
        self._loop: asyncio.AbstractEventLoop | None = None
        self._spinner: SpinThread | None = None  # the services' node on its executor thread
        self._panic_pub: Any = None
        self._dna: Any = None

    def attach(self) -> None:
        """Before the link opens (the backend calls our hook at each open), after the bridge's ROS node."""
        self.backend.on_open(self._on_open)
        self.lifetime.add_hooks("DroneCAN duties", start=self._start, close=self._close)

    # ------------------------------------------------------------------------------------------------ ROS side
    def _start(self) -> None:
        from rclpy.executors import SingleThreadedExecutor
        from rclpy.node import Node
        from std_msgs.msg import String
        from std_srvs.srv import Trigger

        self._loop = asyncio.get_running_loop()
        base = self.ros.name
        node = Node(f"{base}_dronecan_duties", namespace=self.ros.node.get_namespace(),
                    context=self.ros.context)
        for nid, name in sorted(self.devices.items()):
            node.create_service(Trigger, f"{base}/{name}/get_node_info", _service(self._get_node_info, nid))
            node.create_service(Trigger, f"{base}/{name}/restart", _service(self._restart, nid))
        if self.panic:
            self._panic_pub = node.create_publisher(String, f"{base}/panic_received", 10)
            node.create_subscription(String, f"{base}/panic", self._on_ros_panic, 10)
        executor = SingleThreadedExecutor(context=self.ros.context)
        self._spinner = SpinThread(self.lifetime, self.ros.context, executor, node, f"{base}-dronecan-duties",
                                   "dronecan_duties_error", "DroneCAN duties")
        self._spinner.start()

    def _close(self) -> None:
        if self._spinner is not None:
            self._spinner.close()

    # ------------------------------------------------------------------------------------------------ requests
    def _request(self, request: Any, nid: int) -> Any:
        """Send ``request`` to node ``nid`` from the asyncio thread; the response, None on timeout, or raises
        RuntimeError when the link is down (called from the duties' executor thread)."""
        done = threading.Event()
        box: list[Any] = [None]

        def on_response(event: Any) -> None:
            box[0] = None if event is None else event.response
            done.set()

        def send() -> None:
            node = self.backend.node
            if node is None:
                box[0] = RuntimeError("the DroneCAN link is down")
                done.set()
                return
            try:
                node.request(request, nid, on_response, timeout=self.timeout)
            except Exception as ex:
                box[0] = RuntimeError(f"{type(ex).__name__}: {ex}")
                done.set()

        loop = self._loop
        if loop is None or loop.is_closed():
            raise RuntimeError("the bridge is not running")
        self.counts["requests"] += 1
        loop.call_soon_threadsafe(send)
        if not done.wait(self.timeout + 1.0):
            box[0] = None
        if isinstance(box[0], Exception):
            raise box[0]
        if box[0] is None:
            self.counts["request_timeouts"] += 1
        return box[0]

    def _serve(self, request: Any, nid: int, resp: Any, answer: Callable[[Any], tuple[bool, str]]) -> Any:
        """A Trigger response from the device's answer to ``request``: ``answer(response)`` -> (success, message);
        a link down or no answer within the timeout is a refusal that says so."""
        try:
            r = self._request(request, nid)
        except RuntimeError as ex:
            resp.success, resp.message = False, str(ex)
            return resp
        if r is None:
            resp.success, resp.message = False, f"node {nid} did not answer within {self.timeout:.1f} s"
        else:
            resp.success, resp.message = answer(r)
        return resp

    def _get_node_info(self, nid: int, resp: Any) -> Any:
        import dronecan

        return self._serve(dronecan.uavcan.protocol.GetNodeInfo.Request(), nid, resp,
                           lambda r: (True, node_info_json(nid, r)))

    def _restart(self, nid: int, resp: Any) -> Any:
        import dronecan

        req = dronecan.uavcan.protocol.RestartNode.Request()
        req.magic_number = req.MAGIC_NUMBER

        def answer(r: Any) -> tuple[bool, str]:
            message = f"node {nid} " + ("restarts" if r.ok else "refused to restart")
            log.warning("restart of node %d (%s) requested over ROS: %s", nid, self.devices.get(nid, "?"), message)
            return bool(r.ok), message

        return self._serve(req, nid, resp, answer)

    # ------------------------------------------------------------------------------------------------ panic
    def _on_ros_panic(self, msg: Any) -> None:
        reason = msg.data.encode()[:7]
        loop = self._loop
        if loop is None or loop.is_closed():
            return
        for k in range(PANIC_MIN_MESSAGES):
            loop.call_soon_threadsafe(loop.call_later, k * PANIC_INTERVAL_S, self._broadcast_panic, reason)

    def _broadcast_panic(self, reason: bytes) -> None:
        import dronecan

        node = self.backend.node
        if node is None or self.lifetime.closed:
            self.lifetime.errors["panic_not_sent"] += 1
            return
        try:
            node.broadcast(dronecan.uavcan.protocol.Panic(reason_text=reason))
            self.counts["panic_out"] += 1
        except Exception as ex:
            self.lifetime.errors["panic_not_sent"] += 1
            log.warning("Panic broadcast failed: %s: %s", type(ex).__name__, ex)

    def _on_bus_panic(self, event: Any) -> None:
        from std_msgs.msg import String

        src = event.transfer.source_node_id
        reason = bytes(event.message.reason_text).decode(errors="replace")
        self.counts["panic_in"] += 1
        self.lifetime.rlog.note(("dronecan", "panic"), logging.ERROR, "Panic from node %s (%s): %r", src,
                                self.devices.get(src, "no device"), reason)
        if self._panic_pub is not None:
            self._panic_pub.publish(String(data=f"node {src}: {reason}"))

    # ------------------------------------------------------------------------------------------------ per node
    def _on_open(self, node: Any, node_loop: Any) -> None:
        import dronecan

        if self.panic:
            panic = dronecan.uavcan.protocol.Panic
            node_loop.add_handler(panic, self._on_bus_panic)
            taps = getattr(getattr(node_loop, "gate", None), "taps", None)
            if taps is not None:  # a mapping of Panic on the wire path takes its transfers: share them with us
                taps.share(panic.default_dtid)
        if self.dna_server:
            from dronecan.app.dynamic_node_id import CentralizedServer
            from dronecan.app.node_monitor import NodeMonitor

            self._dna = CentralizedServer(node, NodeMonitor(node))


def _service(answer: Callable[[int, Any], Any], nid: int) -> Callable[[Any, Any], Any]:
    """A std_srvs/Trigger service callback ``(request, response)`` answering for device ``nid``."""
    return lambda _request, response: answer(nid, response)
