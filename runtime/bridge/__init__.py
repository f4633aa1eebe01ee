"""The uavcan_ros_bridge of design document section IV.B, driven by the generated tables and converters: one
protocol-agnostic core made of small parts, and a protocol backend behind a small interface (:mod:`.backend`).

Two halves, so that neither direction waits on the other:

- UAVCAN -> ROS runs on the asyncio event loop of the backend: one subscription per port; its handler checks the
  sender against the mapping's configured source node ids, converts with the generated ``<mapping>_to_ros``
  (receive time from the node's ROS clock: the system clock, read directly, unless use_sim_time is set) and
  publishes to ROS at once (rclpy's publish is thread-safe).
- ROS -> UAVCAN runs on the rclpy event loop, an executor spinning in its own thread: one ROS subscription per
  topic (fanning out to every mapping of that topic), converted there with ``<mapping>_to_uavcan`` and handed to
  the asyncio loop (neither pycyphal nor dronecan is thread-safe) through a deque drained by one
  ``call_soon_threadsafe`` per batch, where one bounded queue + worker task per mapping publishes on the
  mapping's port, in order.

The parts (each attached to the bridge's lifetime, :mod:`.lifetime`, reporting through handlers):

=====================  ==============================================================================================
module                 job
=====================  ==============================================================================================
``composition``        :class:`Bridge`: creates the parts, wires their handlers, attaches them in start order
``lifetime``           start/close hooks in order, periodic jobs, the bridge's error counters
``backend``            the interface a protocol backend implements, its device status events
``backends``           the only protocol-specific part, imported by ``composition`` alone: ``backends.cyphal``
                       (Cyphal v1 through pycyphal: transports, node, registers/ports, heartbeats, pycyphal's
                       counters; its wire path ``backends.cyphal_wire``), ``backends.dronecan`` (DroneCAN through
                       sam_runtime.dronecan_io; its node duties ``backends.dronecan_duties``)
``ros_side``           the ROS node: parameters, each topic's QoS, the receive clock, the executor thread (which
                       spins the DroneCAN duties' node too; it sleeps until a callback is due)
``inbound``            the UAVCAN -> ROS path (source filter, conversion, stamps, publish)
``outbound``           the ROS -> UAVCAN path (conversion, bounded queues, workers)
``handoff``            the rclpy thread -> asyncio loop hand-off, one wake-up per batch
``loss``               transfer-loss accounting from the gaps in transfer ids
``health``             device health from heartbeats: offline timers, restarts
``silence``            mappings silent while their device is alive (rules: ``liveness``)
``link``               the backend's link opened, watched, reopened with back-off
``counters``           per-mapping counters and drop reasons; the bounded-rate log is sam_runtime.common.rate_log
``reporting``          the stats snapshot and /diagnostics publishing; ``diagnostics`` builds the message
``wiring``             the generated tables and converters -> run-time mappings
``layout``             which mappings and devices a bridge serves under a layout (one protocol of a mixed one)
``liveness``           the silence rules (grace per mapping, silent while the device is alive), used by ``silence``
``rate_limit``         ``max_rate_hz`` and ``deadline`` as pure logic on an injected clock (issue 19), driven by the
                       asyncio loop's timers from ``inbound`` and ``outbound``
``managed``            the bridge as a ROS 2 managed (lifecycle) node: configure/activate/deactivate/cleanup/shutdown
                       through the lifecycle_msgs services (``sam-codegen bridge --managed``)
``switches``           enable/disable per mapping: its state and its std_srvs/SetBool service (issue 19)
``time_sync``          the bus's time-sync master (both protocols; its message per protocol in
                       ``backends.time_sync_messages``) and the watch on the devices' stamps (unknown, off, error)
=====================  ==============================================================================================

Cyphal v1 messages carry no destination: a command reaches its configured destination node because the
spec gives each actuator its own subject (the destination node id is checked against the devices table at
start-up and reported). Every problem with a value or a frame is a counted drop (per mapping, per reason),
never an exception out of a loop. The bridge is also a proper Cyphal node (heartbeat, GetInfo, registers)
and a proper ROS node (its parameters declared from the spec with their ranges, the spec's parameter rules
enforced on every set); it tracks every device's heartbeat and publishes its counters and the devices'
state as diagnostic_msgs/DiagnosticArray on /diagnostics once a second.

Faults, and what the bridge does about them (issue 4). Nothing raises out of either loop; every message that
does not become a publication is counted per mapping under ``dropped.<reason>``:

=====================  ====================================================================================
reason                 when
=====================  ====================================================================================
``unknown_source``     a transfer from a node id the mapping does not accept (spoofing, a stray node)
``rejected``           the converter refused a value under the mapping's ``reject`` policy (NaN into an
                       integer or a limited field, a value missing from a table, ...)
``convert_error``      the converter raised (a bug: logged, counted, the loop goes on)
``handler_error``      the receive handler itself failed (a bug: likewise)
``publish_error``      the ROS publish or the Cyphal publish raised (e.g. a CAN bus error, ENOBUFS)
``not_sent``           the Cyphal transport did not send every frame before the 1 s deadline (pycyphal's
                       python-can media also reports a ``can.CanError`` this way)
``queue_full``         ROS -> UAVCAN: the mapping's bounded Cyphal publish queue was full (overload)
``link_down``          ROS -> UAVCAN: the Cyphal transport was being reopened after it failed
``shutdown``           the bridge was closing
``lost``               transfers of an accepted source that never reached the bridge: gaps in that source's
                       transfer ids. Whatever the cause below the bridge - a datagram the kernel dropped in a
                       burst, a frame that failed its CRC, a transfer that did not deserialize, the subject's
                       bounded receive queue (``rx_queue_size``) overflowing - each such transfer is counted
                       exactly once, when the next transfer of that source arrives. Exact on Cyphal/UDP
                       (64-bit transfer ids); on Cyphal/CAN (modulo 32) exact while fewer than 16 transfers
                       of the source were due in the gap (by its measured or nominal rate), not counted
                       beyond (unless the bridge's link was down: next reason). A source that restarted
                       meanwhile (heartbeat uptime shorter than the gap) is not counted.
``rate_limited``       UAVCAN -> ROS: a message held for its ``max_rate_hz`` slot that a newer one replaced
``coalesced``          ROS -> UAVCAN: likewise for a command
``expired``            ROS -> UAVCAN: a command older than the mapping's ``deadline`` when it would have been sent
``disabled``           the mapping was disabled (``enabled: false`` in the spec, or its SetBool service)
``inactive``           ROS -> UAVCAN: a managed bridge (``--managed``, :mod:`.managed`) not in its active lifecycle
                       state (configured, or deactivated by its manager); telemetry goes on meanwhile
``transfer_id_jump``   a transfer whose id is further ahead of its source's previous one than the time between
                       them allows (issue 29; 64-bit ids): a restart with another counter or a spoof. Not
                       published, not counted as ``lost``, the source's sequence kept (see :mod:`.loss`)
``bad_cdr``            ROS -> UAVCAN, wire path: a command whose bytes the generated codec refuses as CDR
``lost_link_down``     Cyphal/CAN only, an estimate: transfers of an accepted source missed while the bridge's
                       own Cyphal link was down (see :mod:`.loss`: the transfer-id gap modulo 32 plus the
                       multiple of 32 closest to the source's rate x the time without data)
=====================  ====================================================================================

So per UAVCAN -> ROS mapping, once nothing is in flight and the sources sent again after a loss: the transfers
its accepted sources sent == ``published + dropped_total - dropped.unknown_source``, and ``received`` (what
reached the bridge) == ``published`` + the drops other than ``lost``. The causes below the bridge are pycyphal's
counters of the subject, polled once a second (when /diagnostics is built) and on every :meth:`Bridge.stats`,
reported per mapping as ``cyphal.*``: ``errors`` (datagrams/frames that do not parse, transfers failing their CRC,
multi-frame transfers with missing frames, duplicate or stale transfer ids - ``error.<kind>`` names them, per source
node on UDP), ``deserialization_failures``, ``overruns`` (receive queue full), ``drops`` (the transport's own
queue). They count frames from any sender, also ones that never were a valid transfer of an accepted source, so they
are not added to ``dropped``; any of them, like any drop, makes the mapping WARN in
/diagnostics for 10 s. Saturated values are counted per field under ``saturated.<mapping>.<field>`` (the
message is still published), rejected ones under ``rejected.<...>``.

- Out-of-order data: pycyphal itself discards a transfer whose transfer id is not newer than the last one of
  that source within the 2 s transfer-id timeout (a duplicate or a reordered frame: ``cyphal.errors``). A
  device timestamp (``header.stamp``) older than the previous message of the same source on the same mapping
  is published anyway, in arrival order, and counted under ``out_of_order``: the bridge never reorders or
  holds data back, and the stamp tells ROS consumers (tf2, message_filters, estimators) what to do with it.
  A device that restarted (its heartbeat's uptime went down; on Cyphal/UDP also its transfer ids starting over)
  may have restarted its clock: its next stamp is compared with nothing.
- Unknown timestamps (0): the ROS receive time, counted per device (``time_sync``: a device not synchronised
  yet). float16 NaN/+-inf from a device are passed to ROS unchanged
  (float32/float64 hold them); the devices' ranges are the consumers' business.
- Logging is bounded: the first occurrence of a (mapping, reason) is a WARNING at once, later ones are
  summed and logged at most once per ``log_interval`` seconds (default 10) with the count since the previous
  line; saturations and rejections likewise. Nothing stays unlogged: pending counts are flushed at close.
- Heartbeats: a device is alive while its last uavcan.node.Heartbeat is younger than the Cyphal offline
  timeout (3 s). The moment it is not, /diagnostics shows it at ERROR (published at once, not at the next
  period), and it is logged; when heartbeats come back it is OK again (a restart - uptime going backwards - is
  counted and logged). A device never heard of is STALE. Nodes that are no device of the spec (tools such as
  yakut) are tracked in the stats; their first appearance is logged at INFO, their comings and goings at DEBUG.
- Silence: a UAVCAN -> ROS mapping that gets nothing from its device while the device's heartbeat is alive -
  never, or no more - for longer than max(3 s, 5 nominal periods) is WARN in /diagnostics ("no message for N s
  while device X is alive; nominal R Hz"), logged once when it starts and when it ends (sam_runtime.bridge.liveness).
- Cyphal ports and registers: the bridge's ports are named after its mappings, with the standard registers
  ``uavcan.sub.<mapping>.id``/``.type`` and ``uavcan.pub.<mapping>.id``/``.type`` (a subject of several mappings:
  the first one's name) whose defaults are the spec's subject ids, overridable as usual (e.g.
  ``UAVCAN__SUB__IMU__ID``), and ``uavcan.node.id`` (sam_runtime.cyphal_io.ports).
- A Cyphal transport that dies (pycyphal's CAN media close themselves for good on unrecoverable OS errors, e.g.
  ENETDOWN when a SocketCAN interface goes down) is detected within 1 s (the housekeeping round) and reopened with
  back-off (0.5 s doubling to 2 s) until it works again; meanwhile commands are dropped as ``link_down`` and
  /diagnostics shows the bridge at ERROR. Transient bus errors (a send raising) are counted and the next message
  goes through.
- ROS QoS: each topic's two sides from the spec (``qos`` for the publishers, ``subscriber_qos`` for the command
  subscriptions; REP 2003: sensor data published reliable for best-effort subscribers, commands reliable, ...).
  A slow or stuck ROS subscriber never blocks UAVCAN -> ROS: the ROS publishers are keep-last, so DDS drops that
  subscriber's oldest samples (reliable topics) or never waits for it (best effort) instead of blocking the bridge.
- Security: a mapping accepts transfers only from its spec's source node ids (``unknown_source`` otherwise), or
  from every node when the spec says ``source_node_ids: any`` for it (``any_node``: routed by its ``select`` alone);
  actuators (the simulated ones too) accept commands only from the bridge's node id. Cyphal/UDP binds
  127.0.0.1 and ROS discovery stays on localhost (ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST) unless the user
  configures an interface (``--iface``, UAVCAN__UDP__IFACE, or that variable) explicitly.
"""

from __future__ import annotations

import os

# Must precede any rclpy import in the process (loopback-only discovery on these machines).
os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")

from sam_runtime.bridge.backend import BridgeConfigError
from sam_runtime.bridge.backends.cyphal import DEFAULT_RX_QUEUE_SIZE, TransportConfig
from sam_runtime.bridge.composition import Bridge
from sam_runtime.bridge.counters import DEFAULT_LOG_INTERVAL_S, DROP_REASONS, MappingStats
from sam_runtime.bridge.outbound import DEFAULT_QUEUE_SIZE

__all__ = [
    "DEFAULT_LOG_INTERVAL_S",
    "DEFAULT_QUEUE_SIZE",
    "DEFAULT_RX_QUEUE_SIZE",
    "DROP_REASONS",
    "Bridge",
    "BridgeConfigError",
    "MappingStats",
    "TransportConfig",
]
