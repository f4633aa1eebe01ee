"""The simulator's Cyphal adapter: a pycyphal node per device (heartbeats from the start), a publisher per published
port, a subscriber per command subject; generic values from sam_runtime.sim.devices, records as transmitted. Each
node answers GetInfo (pycyphal's), ExecuteCommand COMMAND_RESTART (a reboot: power off and on, as DroneCAN's
RestartNode) and GetTransportStatistics (its transport sessions' counts).

Closing a node (power off, reboot, the end) stops its servers' tasks while its sockets are still open, then closes
the node: pycyphal's ``Server.close()`` cancels the task without waiting and closes the sockets at once, so a
response in flight (a GetInfo poll during a reboot) would fail on a closed socket (EBADF) and pycyphal would log
it as a "task failure" traceback. A request that arrives meanwhile goes unanswered, as on a device that is off.
(The DroneCAN one is sam_runtime.sim.dronecan; the schedule, physics and counters are sam_runtime.sim.simulator's.)"""

from __future__ import annotations

import asyncio
import logging
from typing import Any

from sam_runtime.common.board_settings import BoardSettings
from sam_runtime.common.tasks import cancel_and_wait
from sam_runtime.cyphal_io.registers import register_stored, register_value
from sam_runtime.cyphal_io.transport import aclose, make_node, quiet_late_media_completions, transport_from_env
from sam_runtime.sim.devices import PHYSICS, SAM_ACTUATORS, generic_fill, physics_key
from sam_runtime.sim.ports import DeviceHost, PubPort, SimDevice, SubPort
from sam_runtime.sim.time_sync import CYPHAL_MAX_INTERVAL_S

__all__ = ["CyphalDevices"]

_log = logging.getLogger("sam_runtime.sim.simulator")
_RESTART_DELAY_S = 0.1  # a restart waits this long, so that its ExecuteCommand response goes out first
# uavcan.node.ExecuteCommand.1.1's standard commands a board's settings answer to
_COMMAND_STORE = 65530  # COMMAND_STORE_PERSISTENT_STATES: save the registers (a reboot keeps them)
_COMMAND_FACTORY_RESET = 65532  # COMMAND_FACTORY_RESET: the spec's defaults, now and after a reboot


class CyphalDevices:
    """The Cyphal adapter: a pycyphal node per device, a publisher per port, a subscriber per command subject."""

    protocol = "cyphal"

    def __init__(self, sim: DeviceHost) -> None:
        self.sim = sim
        self._restarts: set[asyncio.Task[None]] = set()
        # each board's settings, kept across its node's reboots (their saved values are its non-volatile memory)
        self.settings: dict[str, BoardSettings] = {}

    def prepare(self) -> None:
        self.sim.gen.compile_dsdl()
        quiet_late_media_completions(asyncio.get_running_loop())

    def ports(self, dev: SimDevice) -> None:
        gen = self.sim.gen
        dev.subs += [SubPort(port, gen.dsdl_class(port)) for port in dev.info.subscribes]
        dev.pubs += [PubPort(port, gen.dsdl_class(port), PHYSICS.get(physics_key(port.dsdl_type)))
                     for port in dev.info.publishes]

    def open(self, dev: SimDevice) -> None:
        """The device's node (heartbeats start at once) and its ports."""
        import uavcan.node

        cfg = self.sim.config
        name = f"org.{self.sim.tables.VEHICLE}.sim.{dev.info.name}"[:50]
        if cfg.kind == "env":
            env = dict(cfg.environ or {})
            env["UAVCAN__NODE__ID"] = str(dev.info.node_id)
            dev.node = make_node(name, dev.info.node_id, transport=transport_from_env(env))
        else:
            dev.node = make_node(name, dev.info.node_id, cfg.kind, iface=cfg.iface, mtu=cfg.mtu)
        dev.node.heartbeat_publisher.mode = uavcan.node.Mode_1_0.OPERATIONAL
        # its firmware's interface version (issue 28), what the bridge compares with its spec's
        dev.node.info.software_vcs_revision_id = cfg.firmware_hash(dev.info.name, dev.info.interface_hash)
        self._serve_duties(dev)
        self._serve_settings(dev)
        for sp in dev.subs:
            sp.subscriber = dev.node.make_subscriber(sp.dtype, sp.port.subject_id)
            sp.subscriber.receive_in_background(
                lambda msg, tr, dev=dev, sp=sp: self.sim.on_command(dev, sp, msg, tr))
        for pp in dev.pubs:
            pp.publisher = dev.node.make_publisher(pp.dtype, pp.port.subject_id)
            pp.publisher.send_timeout = 1.0
        if dev.clock is not None:  # its clock follows the bus's time-sync master (fixed subject 7168)
            import uavcan.time

            sync = dev.extra = dev.node.make_subscriber(uavcan.time.Synchronization_1_0)
            sync.receive_in_background(
                lambda msg, tr, dev=dev: self.sim.on_time_sync(
                    dev, int(tr.source_node_id if tr.source_node_id is not None else 0xFFFF), int(tr.transfer_id),
                    int(msg.previous_transmission_timestamp_microsecond), int(tr.timestamp.monotonic_ns)))

    def _serve_duties(self, dev: SimDevice) -> None:
        """ExecuteCommand.1.1 (COMMAND_RESTART: a reboot, as DroneCAN's RestartNode; other commands: bad command)
        and GetTransportStatistics.0.1 (the transport's sessions' transfers and errors); GetInfo is pycyphal's."""
        import uavcan.node

        node = dev.node
        execute = uavcan.node.ExecuteCommand_1_1

        async def on_command(request: Any, meta: Any) -> Any:
            board = self.settings.get(dev.info.name)
            if request.command in (_COMMAND_STORE, _COMMAND_FACTORY_RESET) and board is not None:
                board.save() if request.command == _COMMAND_STORE else _factory_reset(board)
                _log.info("%s: command %d from node %s: settings %s", dev.info.name, request.command,
                          meta.client_node_id, "saved" if request.command == _COMMAND_STORE else "reset")
                return execute.Response(status=execute.Response.STATUS_SUCCESS)
            if request.command != execute.Request.COMMAND_RESTART:
                return execute.Response(status=execute.Response.STATUS_BAD_COMMAND)
            _log.info("%s: restart requested by node %s: rebooting", dev.info.name, meta.client_node_id)
            # after the response is out: the reboot closes this node
            asyncio.get_running_loop().call_later(_RESTART_DELAY_S, self._restart, dev)
            return execute.Response(status=execute.Response.STATUS_SUCCESS)

        async def on_stats(_request: Any, _meta: Any) -> Any:
            transport = node.presentation.transport
            out = [s.sample_statistics() for s in transport.output_sessions]
            into = [s.sample_statistics() for s in transport.input_sessions]
            stats = uavcan.node.IOStatistics_0_1(num_emitted=sum(int(st.transfers) for st in out),
                                                 num_received=sum(int(st.transfers) for st in into),
                                                 num_errored=sum(int(st.errors) for st in out + into))
            return uavcan.node.GetTransportStatistics_0_1.Response(transfer_statistics=stats)

        node.get_server(execute).serve_in_background(on_command)
        node.get_server(uavcan.node.GetTransportStatistics_0_1).serve_in_background(on_stats)

    def _serve_settings(self, dev: SimDevice) -> None:
        """The board's settings as registers of its node (served by pycyphal's uavcan.register.Access / List): a
        write the board refuses (a bad type, out of range) leaves the value as it was, which the Access response
        shows, as real firmware does; with each the standard read-only "<name><", "<name>>" and "<name>=" (its
        minimum, maximum and default). A reboot (open again) runs with the saved values."""
        params = tuple(p for p in self.sim.tables.DEVICE_PARAMETERS if p.device == dev.info.name)
        if not params:
            return
        board = self.settings.get(dev.info.name)
        if board is None:
            board = self.settings[dev.info.name] = BoardSettings(params, self.protocol)
        board.reboot()
        registry = dev.node.registry
        for name, p in board.params.items():
            registry[name] = (lambda name=name, p=p: register_value(p.type, board.values[name]),
                              lambda v, name=name, p=p: _write(dev.info.name, board, name, p.type, v))
            registry[name + "="] = lambda name=name, p=p: register_value(p.type, board.defaults[name])
            for suffix, bound in (("<", p.minimum), (">", p.maximum)):
                if bound is not None:
                    registry[name + suffix] = lambda p=p, bound=bound: register_value(p.type, bound)

    def _restart(self, dev: SimDevice) -> None:
        task = asyncio.get_running_loop().create_task(self.sim.restart(dev.info.name),
                                                      name=f"sim-restart-{dev.info.name}")
        self._restarts.add(task)
        task.add_done_callback(self._restarts.discard)

    def sync_params(self, dev: SimDevice) -> tuple[float, int]:
        return CYPHAL_MAX_INTERVAL_S, int(dev.node.presentation.transport.protocol_parameters.transfer_id_modulo)

    async def close(self, devices: list[SimDevice]) -> None:
        """Close the devices' ports, stop their servers, then close their nodes (never raises)."""
        ports = [p.publisher for d in devices for p in d.pubs] + [s.subscriber for d in devices for s in d.subs]
        ports += [d.extra for d in devices]  # the time-sync subscribers
        nodes = [d.node for d in devices]
        for d in devices:
            d.node = d.extra = None
            for pp in d.pubs:
                pp.publisher = None
            for sp in d.subs:
                sp.subscriber = None
        try:
            await aclose(*[p for p in ports if p is not None])
            await _stop_serving([n for n in nodes if n is not None])
            await aclose(*[n for n in nodes if n is not None])
        except Exception as ex:
            _log.warning("closing the simulated Cyphal nodes: %s: %s", type(ex).__name__, ex)

    def command_report(self, sp: SubPort) -> dict[str, Any]:
        return {}

    def blank(self, pp: PubPort, t: float, now_us: int) -> Any:
        return generic_fill(pp.dtype(), t, now_us, seed=pp.ident)

    def finish(self, dev: SimDevice, pp: PubPort, obj: Any, t: float, now_us: int) -> None:
        pass

    def command_values(self, dev: SimDevice, sp: SubPort, msg: Any) -> dict[str, Any] | None:
        import pycyphal.dsdl

        return pycyphal.dsdl.to_builtin(msg)

    def apply(self, dev: SimDevice, values: dict[str, Any]) -> dict[str, float]:
        dev.state.command.update(values)
        inputs = SAM_ACTUATORS.get(dev.info.name, {})
        return {inputs[k]: float(v) for k, v in values.items() if k in inputs}

    def record(self, port: Any, obj: Any, transmitted: bool) -> dict[str, Any]:
        import pycyphal.dsdl

        if transmitted:  # the values as transmitted (float16 rounding etc.)
            obj = pycyphal.dsdl.deserialize(type(obj), list(pycyphal.dsdl.serialize(obj)))
        return {"subject": port.port.subject_id, "value": pycyphal.dsdl.to_builtin(obj)}


def _factory_reset(board: BoardSettings) -> None:
    board.erase()
    board.reboot()


def _write(device: str, board: BoardSettings, name: str, kind: str, value: Any) -> None:
    """A register write (pycyphal converted it to the register's type): stored unless the board refuses it."""
    new = register_stored(kind, value)
    problem = f"not a {kind}" if new is None else board.write(name, new)
    if problem is not None:  # counted (board.refused); the Access response shows the value kept
        _log.info("%s: register %s: write refused: %s", device, name, problem)


async def _stop_serving(nodes: list[Any], timeout: float = 2.0) -> None:
    """End the background tasks of the nodes' servers (ours, pycyphal's GetInfo and register services) while the
    sockets are open: a response being sent completes, and no send meets a closed socket (common.tasks'
    cancel_and_wait: cancelled again until done)."""
    import uavcan.node
    import uavcan.register

    served = (uavcan.node.GetInfo_1_0, uavcan.node.ExecuteCommand_1_1, uavcan.node.GetTransportStatistics_0_1,
              uavcan.register.Access_1_0, uavcan.register.List_1_0)
    tasks: list[asyncio.Task[None]] = []
    for node in nodes:
        for dtype in served:
            try:
                server = node.get_server(dtype)  # the existing instance (pycyphal keeps one per service)
            except Exception:  # a node closed meanwhile (a transport failure): nothing to stop
                continue
            task = getattr(server, "_maybe_task", None)  # serve_in_background's task (pycyphal keeps no public one)
            if isinstance(task, asyncio.Task):
                tasks.append(task)
    pending = await cancel_and_wait(tasks, timeout)
    if pending:
        _log.warning("%d simulated Cyphal servers did not stop within %.0f s", len(pending), timeout)
