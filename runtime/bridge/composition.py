"""The composition root: the bridge's parts created, wired through their handlers, and attached to its lifetime in
start order (ROS node, device health, UAVCAN -> ROS, ROS -> UAVCAN, the link that opens the backend, /diagnostics,
the rclpy executor thread); they close in reverse order."""

from __future__ import annotations

import threading
from collections.abc import Mapping, Sequence
from typing import Any

from sam_codegen.model.spec import UAVCAN_TO_ROS
from sam_runtime.bridge.backend import Backend, BridgeConfigError
from sam_runtime.bridge.backends.cyphal import DEFAULT_RX_QUEUE_SIZE, TransportConfig
from sam_runtime.bridge.backends.part import BackendSettings, BridgePart
from sam_runtime.bridge.backends.service_mappings import ServiceMappingsRos
from sam_runtime.bridge.counters import DEFAULT_LOG_INTERVAL_S, MappingStats, log
from sam_runtime.bridge.device_params import DeviceParams, ros_parameter_name
from sam_runtime.bridge.health import DeviceHealth
from sam_runtime.bridge.inbound import Inbound
from sam_runtime.bridge.interface_check import InterfaceCheck, board_switches
from sam_runtime.bridge.layout import select
from sam_runtime.bridge.lifetime import Lifetime
from sam_runtime.bridge.link import LinkSupervisor
from sam_runtime.bridge.loss import TransferLoss
from sam_runtime.bridge.outbound import DEFAULT_QUEUE_SIZE, Outbound
from sam_runtime.bridge.reporting import Reporter
from sam_runtime.bridge.ros_side import RosSide
from sam_runtime.bridge.silence import SilenceWatch
from sam_runtime.bridge.switches import EnableServices, switches_of
from sam_runtime.bridge.time_sync import DEFAULT_TIME_SYNC_PERIOD_S, StampWatch, TimeSyncMaster
from sam_runtime.bridge.wiring import (
    check_destinations,
    codec_gaps,
    in_groups,
    missing_codecs,
    nominal_rates,
    out_mappings,
)
from sam_runtime.common.rate_log import RateLimitedLog
from sam_runtime.common.ros_namespace import RosNamespace
from sam_runtime.genpkg import GeneratedPackage
from sam_runtime.protocols import RuntimeProtocol, runtime_protocol

__all__ = ["Bridge"]

# The housekeeping round (stack counters, the rate-limited log's pending counts, the link and silence checks, and
# /diagnostics at its default period): one wake-up of the loop a second for all of them, as slow as their bounds
# allow (the offline timeout and the silence graces are 3 s or more; the log sums per 10 s).
HOUSEKEEPING_PERIOD_S = 1.0
WIRE_PATHS = ("codec", "object")


class Bridge:
    """The bridge. Create it, then inside a running asyncio loop ``await start()``; ``await close()`` to stop.

    :param gen: the generated package (tables + converters).
    :param node_id: Cyphal node id; default ``UAVCAN__NODE__ID`` for an ``env`` transport, else the spec's
        bridge node id.
    :param transport: see :class:`~.backends.cyphal.TransportConfig`.
    :param ros_args: extra ROS arguments (``--ros-args ...``) for rclpy.init, e.g. remappings.
    :param parameter_overrides: initial values of the spec's parameters, by spec or ROS name.
    :param qos_depth: history depth of the ROS publishers and subscriptions (keep-last); default: each topic's
        from the spec (its ``qos``, like reliability and durability).
    :param command_reliability: ``reliable`` or ``best_effort`` for the ROS command subscriptions; default: the
        topic's from the spec.
    :param diagnostics_period: seconds between /diagnostics messages (0 disables them).
    :param queue_size: bound of each ROS -> UAVCAN mapping's publish queue (beyond: ``queue_full``).
    :param rx_queue_size: bound of each subject's pycyphal receive queue (beyond: ``overrun``); 0 = unbounded.
    :param log_interval: seconds between two log lines of one (mapping, reason); the first is immediate.
    :param layout: the spec's layout (which firmware each device runs; default: the spec's default layout).
    :param protocol: ``cyphal`` or ``dronecan``: the half of a mixed layout this bridge serves (see
        :mod:`.layout`); default: the layout's only protocol.
    :param dronecan_iface: the DroneCAN interface (sam_runtime.dronecan_io: ``mcast-lo:`` between processes on this
        machine, ``socketcan:can0``, ``slcan:/dev/ttyACM0``).
    :param dronecan_services: the DroneCAN node duties of :mod:`.backends.dronecan_duties` (Panic both ways;
        options ``time_sync`` and ``dna_server``; the devices' GetNodeInfo, RestartNode and GetTransportStats are
        the typed services of the spec's ``bridge.node_services``, served with the service mappings).
    :param wire: ``codec`` (default): the generated wire codecs, from the UAVCAN payload bytes straight to the ROS
        message's CDR and back, with raw ROS publishers and subscriptions and the backend's transport-level ports;
        ``object``: the object converters between the protocol library's message objects and ROS messages (the
        readable reference; also taken, with a warning, when the generated package has no codecs).
    :param namespace: the vehicle's namespace and frame prefix (sam_runtime.common.ros_namespace): the ROS nodes
        are created in it, so the spec's relative topics resolve there; the frame prefix goes before every
        frame_id the bridge writes and the namespace before its diagnostic statuses' names. The wire codecs take
        it at start (a copy of the codec module bound to it: sam_runtime.genpkg.bound_codec).
    :param time_sync: be the bus's time-sync master (:mod:`.time_sync`): True/False override the spec's
        ``bridge.time_sync`` (None: the spec's; on by default).
    :param ros_host: a managed bridge's lifecycle node (sam_runtime.bridge.managed.ManagedNode): the bridge runs on
        its node and executor and starts inactive (:attr:`active`).
    """

    def __init__(
        self,
        gen: GeneratedPackage,
        *,
        node_id: int | None = None,
        transport: TransportConfig | None = None,
        ros_args: Sequence[str] = (),
        parameter_overrides: Mapping[str, Any] | None = None,
        qos_depth: int | None = None,
        queue_size: int = DEFAULT_QUEUE_SIZE,
        command_reliability: str | None = None,
        diagnostics_period: float = 1.0,
        rx_queue_size: int = DEFAULT_RX_QUEUE_SIZE,
        log_interval: float = DEFAULT_LOG_INTERVAL_S,
        layout: str | None = None,
        protocol: str | None = None,
        dronecan_iface: str = "mcast-lo:",
        dronecan_options: Mapping[str, Any] | None = None,
        wire: str = "codec",
        namespace: RosNamespace | None = None,
        time_sync: bool | None = None,
        ros_host: Any = None,
    ) -> None:
        if wire not in WIRE_PATHS:
            raise BridgeConfigError(f"wire path {wire!r}: expected one of {', '.join(WIRE_PATHS)}")
        self.namespace = namespace or RosNamespace()
        self.wire = wire
        self.gen = gen
        self.tables = tables = gen.tables()
        self.selection = sel = select(tables, layout, protocol)
        self.transport_config = transport or TransportConfig()
        if node_id is not None:
            self.node_id = int(node_id)
        elif tables.BRIDGE_NODE_ID is None:
            raise BridgeConfigError(f"{gen.root}: the spec declares no bridge (bridge.node_id), so there is nothing to "
                                    f"bridge")
        else:
            self.node_id = self.transport_config.node_id(tables.BRIDGE_NODE_ID)
        self.log = RateLimitedLog(log, log_interval)
        self.lifetime = Lifetime(self.name, self.log)
        lock = threading.Lock()
        self.mappings = sel.mappings
        self.counters = {m.name: MappingStats(lock, m.name, self.log) for m in sel.mappings}
        self.switches = switches_of(sel.mappings)  # enable/disable per mapping (sam_runtime.bridge.switches)
        self.protocol: RuntimeProtocol = runtime_protocol(sel.protocol)
        self.part: BridgePart = self.protocol.bridge()  # its backend, converters, duties (sam_runtime.protocols)
        self.backend: Backend = self.part.backend(BackendSettings(
            f"org.{tables.VEHICLE}.{self.name}", self.node_id, self.log, self.lifetime.errors,
            transport=self.transport_config, rx_queue_size=rx_queue_size, dronecan_iface=dronecan_iface))
        self._dronecan_options = dict(dronecan_options or {})
        # The bus's time-sync master: the spec's bridge.time_sync unless the caller says (dronecan_options'
        # "time_sync", the older spelling, too).
        override = self._dronecan_options.pop("time_sync", None) if time_sync is None else time_sync
        self._dronecan_options.pop("time_sync", None)
        period = tables.TIME_SYNC_PERIOD_S
        if override is not None:
            period = (period or DEFAULT_TIME_SYNC_PERIOD_S) if override else None
        self.time_sync_period: float | None = period
        self.time_sync: StampWatch | None = None
        # overrides of the boards' settings (<device>.<setting>) go to device_params, the rest to the node's own
        settings = {ros_parameter_name(p.device, p.name) for p in tables.DEVICE_PARAMETERS
                    if p.device in sel.devices.values()}
        given = dict(parameter_overrides or {})
        self._setting_overrides = {k: v for k, v in given.items() if k in settings}
        self.ros = RosSide(self.lifetime, self.name, ros_args=ros_args, parameters=tables.PARAMETERS,
                           rules=tables.PARAMETER_RULES,
                           overrides={k: v for k, v in given.items() if k not in settings},
                           qos_depth=qos_depth, command_reliability=command_reliability,
                           namespace=self.namespace.node_namespace, host=ros_host)
        # commands to the bus: a managed bridge (ros_host) starts inactive, its lifecycle manager activates it
        self._active = ros_host is None
        self.health = DeviceHealth(sel.devices, self.node_id)
        self.backend.on_device_status(self.health.on_status)
        self.link = LinkSupervisor(self.lifetime, self.backend)
        self._queue_size = int(queue_size)
        self._diagnostics_period = float(diagnostics_period)
        self.inbound: Inbound | None = None
        self.outbound: Outbound | None = None
        self.reporter: Reporter | None = None
        self.duties: Any = None  # the protocol's built-in duties (DroneCAN: backends.dronecan_duties), if any
        self.services: ServiceMappingsRos | None = None  # the spec's service mappings of this protocol
        self.interface_check: InterfaceCheck | None = None  # the boards' firmware interface versions (issue 28)
        self.device_params: DeviceParams | None = None  # the boards' settings as ROS parameters

    @property
    def name(self) -> str:
        """The ROS node's name: the spec's bridge name; with the protocol appended for one half of a mixed
        layout (two bridges)."""
        base = str(self.tables.BRIDGE_NAME)
        return f"{base}_{self.selection.protocol}" if self.selection.shared else base

    @property
    def active(self) -> bool:
        """Whether commands go to the bus (False: a managed bridge its lifecycle manager has not activated, or
        deactivated: every command is dropped as ``inactive``; sam_runtime.bridge.managed)."""
        return self._active

    @active.setter
    def active(self, value: bool) -> None:
        """(on the loop)"""
        self._active = bool(value)
        if self.outbound is not None:
            self.outbound.active = self._active
        if self.services is not None:
            self.services.active = self._active
        if self.reporter is not None and self.lifetime.loop is not None:
            self.reporter.publish_now()  # the state on /diagnostics at once

    async def start(self) -> None:
        """Import the converters, assemble the parts, start them in order."""
        if self.lifetime.loop is not None or self.inbound is not None:
            raise RuntimeError("Bridge.start() called twice")
        convert = self.part.converters(self.gen)  # loads the protocol's types first
        codec = self._codec()
        try:
            self._assemble(convert, codec)
        except BaseException:
            await self.lifetime.close()
            raise
        await self.lifetime.start()
        assert self.inbound is not None and self.outbound is not None
        log.info("%s started: %s node %d on %s, %d UAVCAN->ROS and %d ROS->UAVCAN mappings, %s path", self.name,
                 self.backend.label, self.node_id, self.backend.describe(),
                 sum(len(g.mappings) for g in self.inbound.groups.values()), len(self.outbound.mappings), self.wire)

    def _codec(self) -> Any:
        """The generated wire codecs of this bridge's protocol, when the wire path is ``codec`` and they cover every
        selected mapping; else None (the object path)."""
        if self.wire != "codec":
            return None
        codec = self.gen.codec(self.selection.protocol, self.namespace.frame_prefix)
        missing = missing_codecs(codec, self.selection.mappings)
        if missing:
            log.warning("%s: the generated package has no wire codecs for %s: using the object converters",
                        self.name, codec_gaps(codec, missing))
            self.wire = "object"
            return None
        return codec

    def _assemble(self, convert: Any, codec: Any = None) -> None:
        tables, lifetime, backend, health, link = self.tables, self.lifetime, self.backend, self.health, self.link
        sel = self.selection
        check_destinations(tables, sel.mappings, sel.device_infos)
        rates = nominal_rates(tables, sel.device_infos)

        def loss(port_id: int) -> TransferLoss:
            return TransferLoss(port_id, rates, lambda: backend.transfer_id_modulo, health.uptime_of,
                                lambda: link.outage_windows, self._forget_stamps,
                                last_overflow=lambda: backend.last_rx_overflow)

        self.inbound = inbound = Inbound(lifetime, in_groups(self.gen, convert, self.counters, loss, sel.mappings,
                                                             codec), self.ros, backend)
        inbound.frame_prefix = self.namespace.frame_prefix
        self.outbound = outbound = Outbound(lifetime, out_mappings(self.gen, convert, self.counters, sel.mappings,
                                                                   codec),
                                            lambda: link.up, queue_size=self._queue_size, ros=self.ros,
                                            backend=backend)
        outbound.active = self._active
        for im in (im for g in inbound.groups.values() for im in g.mappings):
            im.switch = self.switches[im.info.name]
        for om in outbound.mappings.values():
            om.switch = self.switches[om.info.name]
        silence = SilenceWatch([(m.name, m.rate_hz, m.source_node_ids) for m in sel.mappings
                                if m.direction == UAVCAN_TO_ROS], health.devices,
                               alive_since=health.alive_since, last_message=inbound.last_message,
                               listening_since=lambda: link.up_since, last_heartbeat=health.last_heartbeat)
        self.reporter = reporter = Reporter(
            lifetime, self.namespace.status_name(self.name), sel.mappings, self.counters, backend=backend,
            health=health, link=link, inbound=inbound, outbound=outbound, silence=silence, ros=self.ros,
            period=self._diagnostics_period, switches=self.switches)
        health.add_handler(self._on_health)
        self.interface_check = check = InterfaceCheck(
            {info.node_id: (info.name, info.interface_hash) for info in sel.device_infos},
            self.part.interface_ask(backend), on_mismatch=tables.INTERFACE_ON_MISMATCH,
            switches=board_switches(sel.mappings, self.switches), on_verdict=reporter.publish_now)
        backend.on_device_status(check.on_status)  # (after the tracker's: a first heartbeat is recorded first)
        health.add_handler(check.on_health)
        reporter.interface_check = check
        link.add_handler(lambda _event: reporter.publish_now())
        silence.add_handler(reporter.publish_now)

        self.ros.attach()
        self.device_params = DeviceParams(lifetime, self.ros, sel.devices, tables.DEVICE_PARAMETERS,
                                          sel.protocol, self.part.param_access(backend),
                                          overrides=self._setting_overrides)
        self.device_params.attach()
        health.add_handler(self.device_params.on_health)
        reporter.device_settings = self.device_params.differing_by_device
        EnableServices(lifetime, self.ros, self.switches, on_change=reporter.publish_now).attach()
        health.attach(lifetime)
        inbound.attach()
        outbound.attach()
        if not 0 < self._diagnostics_period <= HOUSEKEEPING_PERIOD_S:  # (else each /diagnostics polls them)
            lifetime.every(HOUSEKEEPING_PERIOD_S, "stack counters", backend.poll_statistics)
        silence.attach(lifetime)
        lifetime.every(HOUSEKEEPING_PERIOD_S, "log", self.log.flush)
        self.duties = self.part.duties(lifetime, backend, self.ros, sel.devices, tables, self._dronecan_options)
        services = self.gen.services()
        served = [m for m in (services.SERVICE_MAPPINGS if services is not None else ())
                  if m.protocol == sel.protocol
                  and (m.destination_node_id in sel.devices or m.destination_field is not None)]
        if served:
            self.services = self.part.services(lifetime, backend, self.ros, served,
                                               diagnostics_period=self._diagnostics_period)
            self._duty_options(self.services)
            self.services.attach()
        if self.services is not None:
            self.services.active = self._active
        self.time_sync = self._time_sync()
        inbound.on_stamp = self.time_sync.on_stamp
        reporter.time_sync = self.time_sync
        link.attach()
        reporter.attach()
        self.ros.attach_spinner()

    def _duty_options(self, services: ServiceMappingsRos) -> None:
        """The device duties (bridge.node_services) answer for this bridge's devices; in a mixed layout two bridges
        share the namespace, so their duty services take the protocol as a suffix (uavcan_get_node_info_cyphal)."""
        services.status_prefix = self.namespace.status_name(self.name)  # (a namespaced run's statuses say so)
        services.devices = dict(self.selection.devices)
        services.health = self.health
        services.duty_suffix = f"_{self.selection.protocol}" if self.selection.shared else ""

    def _time_sync(self) -> StampWatch:
        """The time-sync master (advertised before the link opens; its task starts after it) and the stamp watch."""
        master = None
        if self.time_sync_period is not None:
            msg = self.part.sync_message()
            # (a port name with a dot: no mapping's, as mapping names are identifiers; the type's fixed port id, no
            # register)
            outlet = self.backend.advertise("time.synchronization", msg.port_id, msg.dtype, raw=msg.raw)
            outlet.fixed_port = True
            master = TimeSyncMaster(self.lifetime, outlet, msg.make, self.ros.receive_ns, self.time_sync_period,
                                    msg.max_interval_s, msg.label)
            master.attach()
        return StampWatch(self.lifetime, self.protocol.device_stamped(self.tables), self.selection.devices, master)

    def _on_health(self, nid: int, event: str, device: bool) -> None:
        if event == "first":
            return  # (device_params reads the board's settings)
        if event == "restarted":
            self._forget_stamps(nid)  # its clock may have restarted: its next stamp is no out_of_order
        elif device:
            assert self.reporter is not None
            self.reporter.publish_now()  # a device lost or back: at once, not at the next period

    def _forget_stamps(self, nid: int) -> None:
        if self.inbound is not None:
            self.inbound.forget_stamps(nid)

    def stats(self) -> dict[str, Any]:
        """A JSON-serialisable snapshot of every counter, the devices' heartbeats and the bridge itself (`wire`: the
        path its mappings run on)."""
        if self.reporter is None:
            raise RuntimeError("start() the bridge first")
        snapshot = self.reporter.snapshot()
        snapshot["wire"] = self.wire  # the path the mappings run on: "codec", or "object" (chosen, or fallen back)
        if self.services is not None:
            snapshot["services"] = self.services.snapshot()
        if self.device_params is not None and self.device_params.settings:
            snapshot["device_parameters"] = self.device_params.snapshot()
        return snapshot

    def diagnostics_message(self) -> Any:
        """The /diagnostics message now (diagnostic_msgs/DiagnosticArray)."""
        if self.reporter is None:
            raise RuntimeError("start() the bridge first")
        return self.reporter.diagnostics_message()

    async def close(self) -> None:
        """Stop the ROS half first (no more hand-offs), then the backend's ports and node, then the ROS node."""
        await self.lifetime.close()

    async def __aenter__(self) -> Bridge:
        await self.start()
        return self

    async def __aexit__(self, *exc: object) -> None:
        await self.close()

