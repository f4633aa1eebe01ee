"""The recorder: every ROS topic of the spec (and /diagnostics) as CDR, and the raw UAVCAN bus, into one MCAP.

How the bus is captured: by a listener on the bus, not by the bridge. The bridge stays unchanged and cannot be
slowed or killed by the recording; the recording holds what was on the bus, also what the bridge dropped.

- Cyphal/UDP: an anonymous pycyphal UDP transport on the same interface with a promiscuous input session per subject
  of the spec (every device's publications and subscriptions) and uavcan.node.Heartbeat. Cyphal/UDP subjects are
  multicast groups, so this sees every transfer the bridge sees, reassembled by the same transport code; pycyphal's
  capture API (``begin_capture``) would see the services too, but needs libpcap and CAP_NET_RAW (root). Service
  transfers go to their destination node's multicast group: one more listener per node id that takes part (the
  bridge and every Cyphal device of the spec), a transport with that node id (it sends nothing) with promiscuous
  sessions (requests to a device; requests to and responses to the bridge) of the standard services the bridge
  and tools use (GetInfo, ExecuteCommand, GetTransportStatistics, register Access and List) and of the spec's Cyphal
  service mappings.
- DroneCAN on ``mcast-lo:``: a :class:`~sam_runtime.dronecan_io.LoopbackMulticastDriver` joined to the same loopback
  group behind a :class:`~sam_runtime.dronecan_io.FrameGate` whose taps take every completed transfer (messages and
  services, checked as dronecan checks them: toggle bits, and the CRC where the data type's signature is known).

Times (nanoseconds of the system clock): a ROS message's ``log_time`` is when rclpy received it (the middleware's
``received_timestamp``), its ``publish_time`` the publisher's source timestamp; a transfer's ``log_time`` and
``publish_time`` are both when the listener got it (UAVCAN transfers carry no send time), also in its envelope.

QoS of the ROS subscriptions (what rosbag2 chooses from the publishers it finds, chosen here from the spec's
publishers of the topic): best effort if any publisher is best effort, else reliable; transient local only when
every publisher is (latched topics: /tf_static, /abort); depth 1000.

Invariants: a message that arrives is written or counted (``RecordingWriter.not_recorded``); nothing raises out of
a callback or a listener; the listeners start before the ROS subscriptions and stop after them, so the bus side of
a recording spans its ROS side; :meth:`Recorder.close` writes the summary last.
"""

from __future__ import annotations

import asyncio
import json
import logging
import threading
import time
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from sam_codegen.catalogs.ros import ros_share_dirs
from sam_codegen.model.protocols.cyphal import CYPHAL
from sam_codegen.model.protocols.dronecan import DRONECAN
from sam_codegen.project.cyphal_path import dsdl_lookup_roots
from sam_runtime.common.ros_namespace import RosNamespace
from sam_runtime.common.run_names import RECORDING_METADATA, recorded_metadata
from sam_runtime.cyphal_io.transport import aclose, make_transport
from sam_runtime.dronecan_io.can_id import TAIL_TOGGLE
from sam_runtime.dronecan_io.drops import DropCounter
from sam_runtime.dronecan_io.frame_gate import FrameGate
from sam_runtime.dronecan_io.iface import make_driver
from sam_runtime.dronecan_io.types import ensure_types
from sam_runtime.dronecan_io.wire import TransferTaps, crc16
from sam_runtime.genpkg import GeneratedPackage
from sam_runtime.node_support import qos_profile
from sam_runtime.protocols import default_protocol, registered
from sam_runtime.recording.schemas import (
    CYPHAL_TOPIC,
    DRONECAN_TOPIC,
    HEARTBEAT_SUBJECT,
    HEARTBEAT_TYPE,
    KIND_MESSAGE,
    KIND_REQUEST,
    KIND_RESPONSE,
    ROS_LOST_METADATA,
    TRANSFER_MSG,
    TRANSFER_TYPE,
    Transfer,
    cyphal_definition_files,
    dronecan_definition_files,
    encode_transfer,
    qos_yaml,
    ros2msg_definition,
)
from sam_runtime.recording.writer import RecordingWriter

__all__ = ["DIAGNOSTICS_TOPIC", "METADATA_NAME", "DroneCanTaps", "Recorder", "RecorderConfig", "layout_protocols",
           "topic_qos"]

log = logging.getLogger("sam_runtime.recording")

DIAGNOSTICS_TOPIC = ("/diagnostics", "diagnostic_msgs/msg/DiagnosticArray")
METADATA_NAME = RECORDING_METADATA
FORMAT = "sam-recording/1"
_SUBSCRIPTION_DEPTH = 1000
# service id -> type of the standard Cyphal services recorded (the spec's service mappings are added)
CYPHAL_SERVICES = {430: "uavcan.node.GetInfo.1.0", 434: "uavcan.node.GetTransportStatistics.0.1",
                   435: "uavcan.node.ExecuteCommand.1.3", 384: "uavcan.register.Access.1.0",
                   385: "uavcan.register.List.1.0"}
_SERVICE_RECEIVE_TIMEOUT_S = 2.0
_SERVICE_EXTENT = 1 << 16  # bytes: a service payload is kept whole (register values, GetInfo's names)
_RECEIVE_TIMEOUT_S = 0.5


@dataclass
class RecorderConfig:
    path: Path
    layout: str | None = None
    iface: str = "127.0.0.1"  # Cyphal/UDP
    dronecan_iface: str = "mcast-lo:"
    ros: bool = True
    bus: bool = True
    # the vehicle's ROS namespace (None: /) and frame prefix: relative topics are subscribed under it, and each
    # channel is named as the run resolved it (/sam1/core/imu); both are kept in the metadata (common.run_names)
    namespace: str | None = None
    frame_prefix: str = ""


def layout_protocols(tables: Any, layout: str | None) -> tuple[str, list[str]]:
    """(layout name, the protocols its devices run), as the main job starts its bridges."""
    layouts = {lay.name: lay for lay in tables.LAYOUTS}
    name = str(layout or tables.DEFAULT_LAYOUT)
    lay = layouts.get(name)
    if lay is None:
        if layouts and name != "default":
            raise ValueError(f"the spec has no layout {name!r}; its layouts: {', '.join(sorted(layouts))}")
        return name, [default_protocol().name]
    return name, [p.name for p in registered() if p.layout_mappings(lay)]


def topic_qos(tables: Any) -> dict[str, tuple[str, str, str, int]]:
    """topic -> (ROS type, reliability, durability, depth) of the recorder's subscription (module docstring)."""
    offered: dict[str, list[Any]] = {}
    for m in (m for p in registered() for m in p.mappings(tables)):
        if m.direction == "uavcan_to_ros":
            offered.setdefault(m.topic.name, []).append(m.topic.qos)
    for n in tables.NODES:
        for ep in n.publishes:
            offered.setdefault(ep.topic, []).append(ep.qos)
    out = {}
    for t in tables.TOPICS:
        qs = offered.get(t.name) or [t.qos]
        rel = "best_effort" if any(q.reliability == "best_effort" for q in qs) else "reliable"
        dur = "transient_local" if all(q.durability == "transient_local" for q in qs) else "volatile"
        out[t.name] = (t.ros_type, rel, dur, _SUBSCRIPTION_DEPTH)
    out[DIAGNOSTICS_TOPIC[0]] = (DIAGNOSTICS_TOPIC[1], "reliable", "volatile", _SUBSCRIPTION_DEPTH)
    return out


class DroneCanTaps(TransferTaps):
    """Takes every completed v0 transfer (messages and services) and hands it to ``on_transfer``."""

    def __init__(self, drops: DropCounter, on_transfer: Callable[[Transfer], None]) -> None:
        super().__init__(drops)
        self._on_transfer = on_transfer
        self.crc_failures: Counter[str] = Counter()

    def take(self, frames: list[Any]) -> bool:
        import dronecan
        from dronecan.dsdl import CompoundType

        ident = frames[0].id
        service = bool(ident & 0x80)
        src = ident & 0x7F
        if service:
            dtid = (ident >> 16) & 0xFF
            kind = KIND_REQUEST if ident & 0x8000 else KIND_RESPONSE
            dst: int | None = (ident >> 8) & 0x7F
            dtype = dronecan.DATATYPES.get((dtid, CompoundType.KIND_SERVICE))
        else:
            dtid = (ident >> 8) & 0xFFFF if src else (ident >> 8) & 0x3
            kind, dst = KIND_MESSAGE, None
            dtype = dronecan.DATATYPES.get((dtid, CompoundType.KIND_MESSAGE)) if src else None
        signature = dtype.get_data_type_signature() if dtype is not None else 0
        if len(frames) == 1:
            payload = bytes(frames[0].data[:-1])
        else:
            toggle = 0
            for f in frames:
                if f.data[-1] & TAIL_TOGGLE != toggle:
                    self.crc_failures["toggle"] += 1
                    return True
                toggle ^= TAIL_TOGGLE
            data = b"".join(bytes(f.data[:-1]) for f in frames)
            payload = data[2:]
            if dtype is not None and crc16(payload, dtype.base_crc) != data[0] | data[1] << 8:
                self.crc_failures[dtype.full_name] += 1
                return True
        self._on_transfer(Transfer("dronecan", dtid, dtype.full_name if dtype is not None else "", src or None,
                                   frames[0].data[-1] & 0x1F, (ident >> 24) & 0x1F, _received_ns(frames[-1]), payload,
                                   kind, dst, signature))
        return True


@dataclass
class _Counts:
    ros: Counter[str] = field(default_factory=Counter)
    ros_lost: Counter[str] = field(default_factory=Counter)  # topic -> publisher sequence numbers never received
    transfers: Counter[str] = field(default_factory=Counter)
    services: Counter[int] = field(default_factory=Counter)  # Cyphal service transfers recorded, by kind
    callback_errors: int = 0


class Recorder:
    """Start inside a running asyncio loop (``await start()``), call :meth:`tick` every ~0.2 s, ``await close()``."""

    def __init__(self, gen: GeneratedPackage, config: RecorderConfig) -> None:
        self.gen, self.config = gen, config
        self.tables = gen.tables()
        self.names = RosNamespace(config.namespace or "/", config.frame_prefix)
        self.layout, self.protocols = layout_protocols(self.tables, config.layout)
        self.writer = RecordingWriter(config.path)  # RecordingTargetError before anything starts
        self.counts = _Counts()
        self._ctx: Any = None
        self._node: Any = None
        self._executor: Any = None
        self._spin: threading.Thread | None = None
        self._last_seq: dict[str, int] = {}  # topic -> the publication sequence number of its last message
        self._transport: Any = None
        self._tasks: list[asyncio.Task[None]] = []
        self._dronecan_stop = threading.Event()
        self._dronecan_thread: threading.Thread | None = None
        self._taps: DroneCanTaps | None = None
        self._dronecan_drops: DropCounter | None = None
        self.subjects: dict[int, str] = {}
        self.services: dict[int, str] = {}
        self._service_transports: list[Any] = []
        self.ros_errors: list[str] = []

    # ------------------------------------------------------------------ setup
    def _describe(self) -> None:
        w, tables = self.writer, self.tables
        meta = {"format": FORMAT, "vehicle": str(tables.VEHICLE), "layout": self.layout,
                "protocols": ",".join(self.protocols), "generated": str(self.gen.root),
                "log_time": "ROS: rclpy receive time; transfers: the listener's receive time (system clock, ns)",
                "publish_time": "ROS: the publisher's source timestamp; transfers: the listener's receive time",
                **recorded_metadata(self.names)}
        if CYPHAL.name in self.protocols:
            self.subjects = {p.subject_id: p.dsdl_type for d in tables.DEVICES for p in (*d.publishes, *d.subscribes)}
            self.subjects[HEARTBEAT_SUBJECT] = HEARTBEAT_TYPE
            self.services = dict(CYPHAL_SERVICES)
            services = self.gen.services()
            for m in getattr(services, "SERVICE_MAPPINGS", ()) if services is not None else ():
                if m.protocol == CYPHAL.name:
                    self.services[int(m.data_type_id)] = str(m.data_type)
            meta["cyphal.iface"] = f"udp:{self.config.iface}"
            meta["cyphal.subjects"] = json.dumps({str(k): v for k, v in sorted(self.subjects.items())})
            meta["cyphal.services"] = json.dumps({str(k): v for k, v in sorted(self.services.items())})
            standard = {t for t in (*self.subjects.values(), *self.services.values())
                        if not t.startswith(f"{tables.DSDL_ROOT_NAMESPACE}.")}
            try:
                for name, data in cyphal_definition_files(self.gen.dsdl_dirs, dsdl_lookup_roots(),
                                                          sorted(standard)).items():
                    w.add_attachment(name, data)
            except Exception as ex:  # the recording is still worth having; the payloads stay bytes
                log.warning("the DSDL definitions could not be stored: %s: %s", type(ex).__name__, ex)
            w.add_channel(CYPHAL_TOPIC, TRANSFER_TYPE, "ros2msg", TRANSFER_MSG,
                          metadata={"offered_qos_profiles": qos_yaml("reliable", "volatile", 1)})
        if DRONECAN.name in self.protocols:
            import dronecan

            ensure_types(self.gen)
            names = [t.name for t in tables.DRONECAN_TYPES]
            names += ["uavcan.protocol.NodeStatus", "uavcan.protocol.GetNodeInfo", "uavcan.protocol.RestartNode",
                      "uavcan.protocol.Panic", "uavcan.protocol.GlobalTimeSync"]
            dtypes = [dronecan.TYPENAMES[n] for n in names if n in dronecan.TYPENAMES]
            meta["dronecan.iface"] = self.config.dronecan_iface
            meta["dronecan.types"] = json.dumps({str(t.default_dtid): t.full_name for t in dtypes})
            for name, data in dronecan_definition_files(dtypes).items():
                w.add_attachment(name, data)
            w.add_channel(DRONECAN_TOPIC, TRANSFER_TYPE, "ros2msg", TRANSFER_MSG,
                          metadata={"offered_qos_profiles": qos_yaml("reliable", "volatile", 1)})
        w.add_metadata(METADATA_NAME, meta)

    def _ros_channels(self) -> dict[str, tuple[str, Any]]:
        """topic -> (ROS type, QoS profile) of the topics whose definitions were found (the others are reported)."""
        share = [*ros_share_dirs(), self.gen.root / "ros"]
        out = {}
        for name, (ros_type, rel, dur, depth) in topic_qos(self.tables).items():
            topic = self.names.resolve(name)  # as the run's nodes resolve it (rosbag2 records resolved names too)
            try:
                definition = ros2msg_definition(ros_type, share)
            except LookupError as ex:
                self.ros_errors.append(f"{topic}: {ex}")
                log.error("%s is not recorded: %s", topic, ex)
                continue
            self.writer.add_channel(topic, ros_type, "ros2msg", definition,
                                    metadata={"offered_qos_profiles": qos_yaml(rel, dur, depth)})
            out[topic] = (ros_type, qos_profile(rel, dur, depth))
        return out

    async def start(self) -> None:
        self._describe()
        channels = self._ros_channels()
        if self.config.bus and CYPHAL.name in self.protocols:  # the bus first: its side spans the ROS side
            await self._start_cyphal()
        if self.config.bus and DRONECAN.name in self.protocols:
            self._start_dronecan()
        if self.config.ros:
            self._start_ros(channels)

    # ------------------------------------------------------------------ ROS
    def _start_ros(self, channels: dict[str, tuple[str, Any]]) -> None:
        import importlib

        import rclpy
        from rclpy.executors import SingleThreadedExecutor
        from rclpy.node import Node
        from rclpy.signals import SignalHandlerOptions

        self._ctx = rclpy.Context()
        rclpy.init(args=[], context=self._ctx, signal_handler_options=SignalHandlerOptions.NO)
        self._node = Node(f"{self.tables.BRIDGE_NAME}_recorder", namespace=self.config.namespace, context=self._ctx)
        for topic, (ros_type, qos) in channels.items():
            pkg, _, cls_name = ros_type.split("/")
            try:
                cls = getattr(importlib.import_module(f"{pkg}.msg"), cls_name)
            except (ImportError, AttributeError) as ex:
                self.ros_errors.append(f"{topic}: {ex}")
                log.error("%s is not recorded: %s", topic, ex)
                continue
            self._node.create_subscription(cls, topic, self._ros_callback(topic), qos, raw=True)
        # Not the EventsExecutor (sam_runtime.common.executors): rclpy 7.1.5's fails on a callback that takes the
        # message info, as these do ("SystemError: null argument to internal routine" at the first message).
        self._executor = SingleThreadedExecutor(context=self._ctx)
        self._executor.add_node(self._node)
        self._spin = threading.Thread(target=self._spin_ros, name="recorder-ros", daemon=True)
        self._spin.start()

    def _spin_ros(self) -> None:
        try:
            while self._ctx.ok():
                self._executor.spin_once(timeout_sec=0.1)
        except Exception as ex:  # the context shut down under the executor: the recording of ROS ends
            if self._ctx.ok():
                log.error("the ROS side of the recorder stopped: %s: %s", type(ex).__name__, ex)

    def _ros_callback(self, topic: str) -> Callable[[bytes, Any], None]:
        def on_message(data: bytes, info: Any) -> None:
            try:
                received = int(info.get("received_timestamp", 0)) or time.time_ns()
                source = int(info.get("source_timestamp", 0)) or received
                if self.writer.write(topic, data, received, source):
                    self.counts.ros[topic] += 1
                self._check_sequence(topic, info.get("publication_sequence_number"))
            except Exception as ex:  # never into rclpy's executor
                self.counts.callback_errors += 1
                log.error("recording %s: %s: %s", topic, type(ex).__name__, ex)

        return on_message

    def _check_sequence(self, topic: str, seq: int | None) -> None:
        """Count the messages of ``topic`` the middleware lost before this one: a gap in its publisher's sequence
        numbers. Only for a topic with one publisher: rclpy gives no publisher id with a message, and the numbers of
        several publishers interleave (a lower one only starts the count again)."""
        if not seq:  # (an RMW that does not give it)
            return
        last = self._last_seq.get(topic)
        self._last_seq[topic] = seq
        if last is not None and seq > last + 1 and self._node is not None and \
                self._node.count_publishers(topic) == 1:
            self.counts.ros_lost[topic] += seq - last - 1
            log.warning("%s: %d message(s) lost before the recorder got them (publisher sequence %d -> %d)", topic,
                        seq - last - 1, last, seq)

    def ros_publishers(self) -> dict[str, int]:
        """topic -> publishers the recorder's node sees (for waiting on discovery)."""
        if self._node is None:
            return {}
        return {t: self._node.count_publishers(t) for t in self.writer.channels if t.startswith("/")
                and t not in (CYPHAL_TOPIC, DRONECAN_TOPIC)}

    # ------------------------------------------------------------------ Cyphal/UDP
    async def _start_cyphal(self) -> None:
        from pycyphal.transport import InputSessionSpecifier, MessageDataSpecifier, PayloadMetadata
        from pycyphal.transport import ServiceDataSpecifier as Service

        self.gen.compile_dsdl()  # cached; the extents come from the compiled classes
        self._transport = make_transport("udp", node_id=None, iface=self.config.iface)
        loop = asyncio.get_running_loop()
        for sid, dsdl_type in sorted(self.subjects.items()):
            session = self._transport.get_input_session(
                InputSessionSpecifier(MessageDataSpecifier(sid), None), PayloadMetadata(_extent(dsdl_type)))
            self._tasks.append(loop.create_task(self._receive(session, sid, dsdl_type), name=f"recorder-rx-{sid}"))
        # services: as each node that takes part (module docstring)
        # a device is asked (requests to it), the bridge asks and is asked (responses and requests to it)
        bridge = None if self.tables.BRIDGE_NODE_ID is None else int(self.tables.BRIDGE_NODE_ID)
        roles: dict[int, tuple[tuple[Any, int], ...]] = {
            d.node_id: ((Service.Role.REQUEST, KIND_REQUEST),) for d in self.tables.DEVICES}
        if bridge is not None:
            roles[bridge] = ((Service.Role.REQUEST, KIND_REQUEST), (Service.Role.RESPONSE, KIND_RESPONSE))
        for nid in sorted(roles):
            transport = make_transport("udp", node_id=nid, iface=self.config.iface)
            self._service_transports.append(transport)
            for sid, dsdl_type in sorted(self.services.items()):
                for role, kind in roles[nid]:
                    session = transport.get_input_session(InputSessionSpecifier(Service(sid, role), None),
                                                          PayloadMetadata(_SERVICE_EXTENT))
                    self._tasks.append(loop.create_task(self._receive(session, sid, dsdl_type, kind, nid),
                                                        name=f"recorder-rx-{nid}-{sid}-{kind}"))

    async def _receive(self, session: Any, sid: int, dsdl_type: str, kind: int = KIND_MESSAGE,
                       destination: int | None = None) -> None:
        from pycyphal.transport import ResourceClosedError

        loop = asyncio.get_running_loop()
        try:
            while True:
                # services are rare: a longer wait than the subjects' (~100 sessions), short enough that a
                # cancellation Python 3.11 loses inside pycyphal's wait_for still ends the task within the stop
                # budget of `run` (a 60 s wait got the recorder killed and its file cut)
                tr = await session.receive(loop.time() + (_RECEIVE_TIMEOUT_S if kind == KIND_MESSAGE
                                                          else _SERVICE_RECEIVE_TIMEOUT_S))
                if tr is None:
                    continue
                try:
                    payload = b"".join(bytes(f) for f in tr.fragmented_payload)
                    now = int(tr.timestamp.system_ns) or time.time_ns()  # when the transport read the datagram
                    t = Transfer("cyphal", sid, dsdl_type, tr.source_node_id, int(tr.transfer_id),
                                 int(tr.priority), now, payload, kind=kind, destination_node_id=destination)
                    if self.writer.write(CYPHAL_TOPIC, encode_transfer(t), now, now):
                        self.counts.transfers["cyphal"] += 1
                        if kind != KIND_MESSAGE:
                            self.counts.services[kind] += 1
                except Exception as ex:
                    self.counts.callback_errors += 1
                    log.error("recording subject %d: %s: %s", sid, type(ex).__name__, ex)
        except (asyncio.CancelledError, ResourceClosedError):
            pass

    # ------------------------------------------------------------------ DroneCAN
    def _start_dronecan(self) -> None:
        drops = DropCounter()
        gate = FrameGate(make_driver(self.config.dronecan_iface, drops=drops), drops=drops)

        def on_transfer(t: Transfer) -> None:
            if self.writer.write(DRONECAN_TOPIC, encode_transfer(t), t.timestamp_ns, t.timestamp_ns):
                self.counts.transfers["dronecan"] += 1

        self._taps = gate.taps = DroneCanTaps(drops, on_transfer)
        self._dronecan_drops = drops

        def run() -> None:
            try:
                while not self._dronecan_stop.is_set():
                    try:
                        gate.receive(0.2)
                        if gate.drained:
                            gate.sweep()
                    except Exception as ex:  # a broken frame: counted, the listener goes on
                        self.counts.callback_errors += 1
                        log.error("DroneCAN listener: %s: %s", type(ex).__name__, ex)
            finally:
                gate.close()

        self._dronecan_thread = threading.Thread(target=run, name="recorder-dronecan", daemon=True)
        self._dronecan_thread.start()

    # ------------------------------------------------------------------ run and stop
    def tick(self) -> None:
        self.writer.tick()

    async def close(self) -> dict[str, Any]:
        """Stop ROS first, then the listeners (the bus side of the recording spans its ROS side: every recorded
        publication's transfer is in it, which replay relies on), then finish the file; returns the summary."""
        if self._ctx is not None:
            try:
                self._ctx.shutdown()
            except Exception as ex:
                log.debug("rclpy shutdown: %s", ex)
            if self._spin is not None:
                await asyncio.get_running_loop().run_in_executor(None, self._spin.join, 2.0)
            try:
                self._executor.shutdown(timeout_sec=1.0)
                self._node.destroy_node()
            except Exception as ex:
                log.debug("closing the ROS node: %s", ex)
        self._dronecan_stop.set()
        for t in self._tasks:
            t.cancel()
        # pycyphal's UDP close waits for each session's socket reader (~60 ms each): the service listeners' ~70
        # sessions closed one after the other took 8 s, past the stop budget of `run`; in threads, at once, ~1 s
        await asyncio.gather(*(asyncio.to_thread(t.close) for t in self._service_transports))
        closables = [t for t in (self._transport, *self._service_transports) if t is not None]
        if closables:
            await aclose(*closables)  # the tasks of what closed (close() again does nothing)
        await asyncio.gather(*self._tasks, return_exceptions=True)
        if self._dronecan_thread is not None:
            await asyncio.get_running_loop().run_in_executor(None, self._dronecan_thread.join, 2.0)
        if self._ctx is not None:  # (written also when nothing was lost: the recording was checked)
            self.writer.add_metadata(ROS_LOST_METADATA, {t: str(n) for t, n in sorted(self.counts.ros_lost.items())})
        self.writer.close()
        out = self.writer.summary()
        out["ros_not_recorded"] = self.ros_errors
        out["ros_lost"] = dict(self.counts.ros_lost)
        out["callback_errors"] = self.counts.callback_errors
        if self._taps is not None:
            out["dronecan_crc_failures"] = dict(self._taps.crc_failures)
        return out


def _received_ns(frame: Any) -> int:
    """When the driver read the transfer's last frame (dronecan stamps every frame it reads), else now."""
    real = getattr(frame, "ts_real", None)
    return int(real * 1e9) if real else time.time_ns()


def _extent(dsdl_type: str) -> int:
    """The extent [bytes] of a compiled DSDL type (full name with version); 1 KiB when it cannot be found."""
    import importlib

    *ns, short, major, minor = dsdl_type.split(".")
    try:
        import nunavut_support

        cls = getattr(importlib.import_module(".".join(ns)), f"{short}_{major}_{minor}")
        return int(nunavut_support.get_extent_bytes(cls))
    except Exception:
        return 1024
