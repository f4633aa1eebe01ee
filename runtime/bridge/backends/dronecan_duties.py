"""The DroneCAN node duties of the bridge that are no ROS services, a part attached to the bridge's lifetime beside
the DroneCAN backend (the devices' GetNodeInfo, RestartNode and GetTransportStats are typed ROS services of the
spec's ``bridge.node_services``, served with the service mappings: backends.service_mappings):

- ``uavcan.protocol.Panic`` both ways (std_msgs/String): a Panic on the bus is published on ``/<bridge>/panic_received``
  as ``node <id>: <reason>``; a message on ``/<bridge>/panic`` is broadcast as Panic (reason: its first 7 bytes)
  MIN_MESSAGES (3) times 0.1 s apart, as receivers wait for 3 within MAX_INTERVAL_MS (500) before they act.
  ``panic=False`` (the spec's ``panic_duty: mappings``: its own mappings of Panic instead) leaves Panic alone; beside
  a mapping of Panic on the wire path (``panic_duty: both``) the tapped Panic transfers are shared with the node, so
  both see every Panic;
- optional: a dynamic node id allocation server (dronecan's CentralizedServer with its NodeMonitor, in memory).
  (The bus's GlobalTimeSync master is sam_runtime.bridge.time_sync's, on both protocols.)

The Panic topics live on a ROS node of their own, spun by the bridge's executor (RosSide.add_node: no thread of
their own; their callback only hands the broadcasts over, and an exception out of it is counted as
``dronecan_duties_error``). The dronecan node belongs to the asyncio loop's thread: broadcasts are handed to it with
``call_soon_threadsafe``. Handlers are registered on every node the backend opens (it reopens after a failure).
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import Mapping
from typing import Any

from sam_runtime.bridge.counters import log
from sam_runtime.bridge.lifetime import Lifetime

__all__ = ["DroneCanDuties"]

PANIC_MIN_MESSAGES = 3
PANIC_INTERVAL_S = 0.1


class DroneCanDuties:
    """:param backend: the bridge's DroneCanBackend (``on_open`` hook, ``node``).
    :param ros: the bridge's RosSide (its context, its name).
    :param devices: node id -> device name."""

    def __init__(self, lifetime: Lifetime, backend: Any, ros: Any, devices: Mapping[int, str], *,
                 dna_server: bool = False, panic: bool = True) -> None:
        self.lifetime, self.backend, self.ros = lifetime, backend, ros
        self.devices = dict(devices)
        self.panic = bool(panic)  # the built-in Panic duty (off: the spec's mappings of Panic handle it)
        self.dna_server = bool(dna_server)
        self.counts: dict[str, int] = {"panic_in": 0, "panic_out": 0}
        self._loop: asyncio.AbstractEventLoop | None = None
        self.ros_node: Any = None  # the Panic topics' node, on the bridge's executor
        self._panic_pub: Any = None
        self._dna: Any = None

    def attach(self) -> None:
        """Before the link opens (the backend calls our hook at each open), after the bridge's ROS node."""
        self.backend.on_open(self._on_open)
        self.lifetime.add_hooks("DroneCAN duties", start=self._start, close=self._close)

    # ------------------------------------------------------------------------------------------------ ROS side
    def _start(self) -> None:
        from rclpy.node import Node
        from std_msgs.msg import String

        self._loop = asyncio.get_running_loop()
        base = self.ros.name
        node = Node(f"{base}_dronecan_duties", namespace=self.ros.node.get_namespace(),
                    context=self.ros.context)
        if self.panic:
            self._panic_pub = node.create_publisher(String, f"{base}/panic_received", 10)
            node.create_subscription(String, f"{base}/panic", self._on_ros_panic, 10)
        self.ros_node = node
        self.ros.add_node(node)  # the bridge's executor spins it from its start on (the spinner starts last)

    def _close(self) -> None:
        """Nothing to stop: the bridge's executor stopped first and destroys the node at its close."""

    # ------------------------------------------------------------------------------------------------ panic
    def _on_ros_panic(self, msg: Any) -> None:
        try:
            self._hand_over_panic(msg)
        except Exception as ex:  # a bug: counted here, not as the bridge executor's spin_error
            self.lifetime.errors["dronecan_duties_error"] += 1
            log.warning("DroneCAN duties: %s: %s", type(ex).__name__, ex)

    def _hand_over_panic(self, msg: Any) -> None:
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
