"""The simulated devices' DroneCAN (UAVCAN v0) firmware: what :class:`~sam_runtime.sim.simulator.Simulator`
does for a device
that its layout puts on DroneCAN.

- One ``dronecan`` node per device (the node id of ``DRONECAN_DEVICES``, 1..125) on ``SimConfig.dronecan_iface``
  (an interface URI of :mod:`sam_runtime.dronecan_io`, ``mcast-lo:`` by default), run in the simulator's asyncio
  loop by a :class:`~sam_runtime.dronecan_io.NodeLoop`: NodeStatus once a second (health OK, mode OPERATIONAL, its
  uptime), GetNodeInfo (``org.<vehicle>.sim.<device>``, answered by dronecan), RestartNode (the magic number:
  a real reboot, as ``power_off`` + ``power_on``: a new node whose uptime starts at 0) and GetTransportStats (the
  node's transfers out and in, counted by a transfer hook; its errors: the transfers its loop dropped).
- On ``mcast-lo:`` each node has the acceptance filter of a CAN controller (in the kernel: the service transfers
  addressed to it and the broadcasts it subscribes to), so a sensor is not woken by every frame of the bus.
- Broadcasts: each v0 port on the simulator's publish loop (same schedule as the Cyphal ports), its values from
  :mod:`sam_runtime.sim.devices_dronecan` (the same physics of the shared vehicle), then the values the spec's
  DroneCAN mappings from this device select on (``esc_index``, ``device_id``) and the items they read. Every
  mapping that accepts the device (its ``source_node_ids``, or ``any``) gets its ``select`` values in turn: the
  device's broadcasts of a type go round the distinct selections of the mappings that accept it, one a tick (the
  nominal rate is kept; each select-routed topic gets its share), so every such topic publishes in simulation.
- Commands: a v0 command is a broadcast; a device takes its element of it (``rpm[1]``, ``commands[actuator_id=4]``):
  the elements of the DroneCAN mappings whose ``destination_node_ids`` hold the device (for SAM's devices the ones
  :data:`~sam_runtime.sim.devices_dronecan.SAM_ACTUATORS_V0` gives them; else by position when a mapping has one
  element per destination, else all), and the mappings' ``select`` values. A broadcast without the device's
  element is not a command for it (counted as ``not_addressed``, neither accepted nor rejected).
- Types: the spec's own v0 types are added to dronecan before the first node (:func:`ensure_types`), beside the
  types loaded already: ``dronecan.load_dsdl`` would replace every type object of the process, and a handler
  registered on an old one never fires. The nodes' message handler takes every transfer and dispatches by type
  name, so a later ``load_dsdl`` elsewhere in the process (a bridge's ``load_types``) does not silence the commands.
"""

from __future__ import annotations

import asyncio
import hashlib
import logging
import time
from dataclasses import dataclass
from typing import Any

from sam_codegen.model.spec import ROS_TO_UAVCAN, UAVCAN_TO_ROS
from sam_runtime.common.board_settings import BoardSettings
from sam_runtime.dronecan_io import Acceptance, FrameGate, HandlerError, NodeLoop, make_driver, parse_iface
from sam_runtime.dronecan_io.node_loop import close_node
from sam_runtime.dronecan_io.types import ensure_types, type_problems
from sam_runtime.sim.devices_dronecan import (
    SAM_ACTUATORS_V0,
    Element,
    element_value,
    ensure_element,
    generic_fill_v0,
    parse_element,
    physics_v0,
    sam_command_fields,
    to_builtin_v0,
)
from sam_runtime.sim.params_dronecan import PARAM_GETSET, PARAM_OPCODE, param_getset_handler, param_opcode_handler
from sam_runtime.sim.ports import DeviceHost, PubPort, SimDevice, SubPort
from sam_runtime.sim.time_sync import DRONECAN_MAX_INTERVAL_S

__all__ = ["DroneCanDevices", "ensure_types", "type_problems"]

_log = logging.getLogger("sam_runtime.sim.simulator")
NODE_STATUS_INTERVAL_S = 1.0
RESTART_NODE = "uavcan.protocol.RestartNode"
TRANSPORT_STATS = "uavcan.protocol.GetTransportStats"
TIME_SYNC = "uavcan.protocol.GlobalTimeSync"


@dataclass
class Selections:
    """What a device's broadcasts of one type carry for the bridge: the distinct ``select`` values of the mappings
    that accept the device, sent in turn (``turn`` counts the broadcasts), and the items they read (all of them)."""

    selects: tuple[tuple[tuple[str, Any], ...], ...]
    elements: list[Element]
    turn: int = 0

    def next_select(self) -> tuple[tuple[str, Any], ...]:
        if not self.selects:
            return ()
        select = self.selects[self.turn % len(self.selects)]
        self.turn += 1
        return select


@dataclass(frozen=True)
class Addressing:
    """One way a broadcast command is meant for a device: its ``select`` values and the elements it takes (none:
    the whole message)."""

    select: tuple[tuple[str, Any], ...]
    elements: tuple[Element, ...]


def _get(obj: Any, path: str) -> Any:
    for part in path.split("."):
        obj = getattr(obj, part)
    return obj


def _put(obj: Any, path: str, value: Any) -> None:
    *head, last = path.split(".")
    for part in head:
        obj = getattr(obj, part)
    setattr(obj, last, value)


def _field_names(type_name: str) -> set[str]:
    import dronecan

    t = dronecan.TYPENAMES.get(type_name)
    return {f.name for f in getattr(t, "fields", ()) if f.name}


class _Broadcaster:
    """A publisher for the simulator's publish loop: ``node.broadcast`` sends every frame (or raises) at once."""

    send_timeout = 0.1  # the loopback driver's

    def __init__(self, node: Any) -> None:
        self.node = node

    async def publish(self, obj: Any) -> bool:
        self.node.broadcast(obj)
        return True


class DroneCanDevices:
    """The DroneCAN adapter of a :class:`~sam_runtime.sim.simulator.Simulator`: node, broadcasts, commands, closing."""

    protocol = "dronecan"

    def __init__(self, sim: DeviceHost) -> None:
        self.sim = sim
        self.iface = sim.config.dronecan_iface
        self._kind = parse_iface(self.iface).kind  # IfaceError (a ValueError) for a bad or refused URI
        self._restarts: set[asyncio.Task[None]] = set()
        # each board's settings, kept across its node's reboots (their saved values are its non-volatile memory)
        self.settings: dict[str, BoardSettings] = {}
        if sim.bridge_node_id is not None and not 1 <= sim.bridge_node_id <= 127:
            raise ValueError(f"a DroneCAN node id is 1..127, not the bridge's {sim.bridge_node_id}")
        for dev in sim.devices:
            if dev.protocol == self.protocol and not 1 <= dev.info.node_id <= 125:
                raise ValueError(f"{dev.info.name}: a DroneCAN device's node id is 1..125, not {dev.info.node_id}")

    def prepare(self) -> None:
        ensure_types(self.sim.gen)

    # ------------------------------------------------------------------------------------------ ports
    def ports(self, dev: SimDevice) -> None:
        for port in dev.info.publishes:
            t = port.data_type
            pp = PubPort(port, t.name, physics_v0(t.name, t.custom), key=f"dronecan:{t.name}", ident=t.data_type_id)
            pp.extra = self._fixed_values(dev, t.name)
            dev.pubs.append(pp)
        for port in dev.info.subscribes:
            t = port.data_type
            sp = SubPort(port, t.name, key=f"dronecan:{t.name}", ident=t.data_type_id)
            sp.extra = self._addressing(dev, t.name)
            dev.subs.append(sp)

    def _fixed_values(self, dev: SimDevice, type_name: str) -> Selections:
        """What the bridge's mappings from this device look for in its broadcasts of ``type_name``."""
        selects: dict[tuple[tuple[str, Any], ...], None] = {}
        elements: dict[str, Element] = {}
        for m in self.sim.tables.DRONECAN_MAPPINGS:
            if m.direction == UAVCAN_TO_ROS and m.data_type.name == type_name and (
                    dev.info.node_id in m.source_node_ids or getattr(m, "any_node", False)):
                selects[tuple(m.select)] = None
                elements.update({e: parse_element(e) for e in m.elements})
        # a mapping without `select` takes every message, those of the other selections too: no turn of its own
        return Selections(tuple(s for s in selects if s or len(selects) == 1), list(elements.values()))

    def _destinations(self, m: Any) -> list[int]:
        """A command mapping's destination node ids; with ``any`` the devices that subscribe to its type."""
        if not getattr(m, "any_node", False):
            return sorted(m.destination_node_ids)
        return sorted(d.node_id for d in self.sim.tables.DRONECAN_DEVICES
                      if any(p.data_type.name == m.data_type.name for p in d.subscribes))

    def _addressing(self, dev: SimDevice, type_name: str) -> list[Addressing]:
        name, node_id = dev.info.name, dev.info.node_id
        sam = SAM_ACTUATORS_V0.get(name, {})
        out = []
        for m in self.sim.tables.DRONECAN_MAPPINGS:
            destinations = self._destinations(m) if m.direction == ROS_TO_UAVCAN else []
            if m.direction != ROS_TO_UAVCAN or m.data_type.name != type_name or node_id not in destinations:
                continue
            elements = list(m.elements)
            if any(e in sam for e in elements):  # SAM's firmware: its own elements of a shared broadcast
                elements = [e for e in elements if e in sam]
            elif len(destinations) > 1 and len(elements) == len(destinations):
                # one element per destination: the i-th lowest position for the i-th lowest node id (a spec may
                # name them in any order, e.g. a constant rpm[0] after rpm[1] from the topic)
                if all(parse_element(e).index is not None for e in elements):
                    elements.sort(key=lambda e: parse_element(e).index or 0)
                elements = [elements[destinations.index(node_id)]]
            out.append(Addressing(tuple(m.select), tuple(parse_element(e) for e in elements)))
        if not out and sam:  # no mapping sends it: the firmware's own elements, where the type has them
            fields = _field_names(type_name)
            own = tuple(el for el in map(parse_element, sam) if el.path.split(".")[0] in fields)
            if own:
                out.append(Addressing((), own))
        return out

    # ------------------------------------------------------------------------------------------ the node
    def open(self, dev: SimDevice) -> None:
        import dronecan

        status = dronecan.TYPENAMES["uavcan.protocol.NodeStatus"]
        name = f"org.{self.sim.tables.VEHICLE}.sim.{dev.info.name}"[:80]
        info = dronecan.TYPENAMES["uavcan.protocol.GetNodeInfo"].Response()
        info.name = name
        info.software_version.major = 1
        info.hardware_version.major = 1
        info.hardware_version.unique_id = hashlib.sha256(name.encode()).digest()[:16]
        # its firmware's interface version (issue 28), what the bridge compares with its spec's; the flag says the
        # field holds it (a board without one reports no flag: "unknown")
        image_crc = self.sim.config.firmware_hash(dev.info.name, dev.info.interface_hash)
        if image_crc:
            info.software_version.image_crc = image_crc
            info.software_version.optional_field_flags |= info.software_version.OPTIONAL_FIELD_FLAG_IMAGE_CRC
        sync_id = {int(dronecan.TYPENAMES[TIME_SYNC].default_dtid)} if dev.clock is not None else set()
        accept = Acceptance(dev.info.node_id, frozenset({sp.ident for sp in dev.subs} | sync_id))
        driver = make_driver(self.iface, accept=accept) if self._kind == "mcast-lo" else make_driver(self.iface)
        gate = FrameGate(driver)
        try:
            node = dronecan.node.Node(gate, node_id=dev.info.node_id, node_status_interval=NODE_STATUS_INTERVAL_S,
                                      node_info=info, mode=status().MODE_OPERATIONAL,
                                      catch_handler_exceptions=False)
            node.health = status().HEALTH_OK
            loop = NodeLoop(node, logger=_log, log_interval=self.sim.config.log_interval)
            node.add_handler(None, self._message_handler(dev))
            loop.add_handler(dronecan.TYPENAMES[RESTART_NODE], self._restart_handler(dev))
            counts = {"tx": 0, "rx": 0}  # this node's transfers (the hook sees each one, both ways)
            node.add_transfer_hook(lambda transfer: counts.__setitem__(
                transfer.direction, counts.get(transfer.direction, 0) + 1))
            loop.add_handler(dronecan.TYPENAMES[TRANSPORT_STATS], self._stats_handler(counts, loop))
            board = self._board(dev)
            if board is not None:
                loop.add_handler(dronecan.TYPENAMES[PARAM_GETSET], param_getset_handler(dev.info.name, board))
                loop.add_handler(dronecan.TYPENAMES[PARAM_OPCODE], param_opcode_handler(dev.info.name, board))
            loop.start()
        except BaseException:
            gate.close()
            raise
        dev.node, dev.extra = node, loop
        for pp in dev.pubs:
            pp.publisher = _Broadcaster(node)
        for sp in dev.subs:
            sp.subscriber = node

    def _message_handler(self, dev: SimDevice) -> Any:
        subs = {sp.dtype: sp for sp in dev.subs}

        def on_transfer(event: Any) -> None:
            transfer = event.transfer
            if transfer.service_not_message:
                return  # requests: GetNodeInfo (dronecan's), RestartNode (below)
            type_name = str(event.message._type.full_name)
            if type_name == TIME_SYNC:  # its clock follows the bus's GlobalTimeSync master
                if dev.node is event.node and transfer.source_node_id:
                    ts = transfer.ts_monotonic
                    rx_ns = time.monotonic_ns() if ts is None else int(ts * 1e9)
                    self.sim.on_time_sync(dev, int(transfer.source_node_id), int(transfer.transfer_id),
                                          int(event.message.previous_transmission_timestamp_usec), rx_ns)
                return
            sp = subs.get(type_name)
            if sp is None or dev.node is not event.node:
                return
            try:
                self.sim.on_command(dev, sp, event.message, transfer)
            except Exception as ex:
                raise HandlerError(f"{dev.info.name}: {type(ex).__name__}: {ex}") from ex

        return on_transfer

    def _board(self, dev: SimDevice) -> BoardSettings | None:
        """The device's settings, as a (re)boot loads them; None if the spec gives it none."""
        params = tuple(p for p in self.sim.tables.DEVICE_PARAMETERS if p.device == dev.info.name)
        if not params:
            return None
        board = self.settings.get(dev.info.name)
        if board is None:
            board = self.settings[dev.info.name] = BoardSettings(params, self.protocol)
        board.reboot()
        return board

    def _stats_handler(self, counts: dict[str, int], loop: NodeLoop) -> Any:
        import dronecan

        def on_stats(event: Any) -> Any:
            # the transfers the node sent and received; its errors are what its loop dropped (CRC, toggle, ...)
            return dronecan.TYPENAMES[TRANSPORT_STATS].Response(
                transfers_tx=counts.get("tx", 0), transfers_rx=counts.get("rx", 0), transfer_errors=loop.drops.total)

        return on_stats

    def _restart_handler(self, dev: SimDevice) -> Any:
        import dronecan

        def on_restart(event: Any) -> Any:
            req = event.request
            ok = int(req.magic_number) == int(req.MAGIC_NUMBER) and dev.node is event.node
            if ok:  # after this response is sent: the handler returns it first
                task = asyncio.get_running_loop().create_task(self.sim.restart(dev.info.name),
                                                             name=f"sim-restart-{dev.info.name}")
                self._restarts.add(task)
                task.add_done_callback(self._restarts.discard)
            _log.info("%s: RestartNode from node %s: %s", dev.info.name, event.transfer.source_node_id,
                      "rebooting" if ok else "refused (magic number)")
            return dronecan.TYPENAMES[RESTART_NODE].Response(ok=ok)

        return on_restart

    async def close(self, devices: list[SimDevice]) -> None:
        """Stop and close the devices' nodes (never raises)."""
        for dev in devices:
            loop, node = dev.extra, dev.node
            dev.extra = dev.node = None
            for pp in dev.pubs:
                pp.publisher = None
            for sp in dev.subs:
                sp.subscriber = None
            close_node(loop, node, _log, f"{dev.info.name}: closing its DroneCAN node")

    # ------------------------------------------------------------------------------------------ messages
    def command_report(self, sp: SubPort) -> dict[str, Any]:
        return {"not_addressed": sp.not_addressed}  # broadcasts whose node-id field names another device

    def blank(self, pp: PubPort, t: float, now_us: int) -> Any:
        import dronecan

        return generic_fill_v0(dronecan.TYPENAMES[pp.dtype](), t, now_us, seed=pp.ident)

    def finish(self, dev: SimDevice, pp: PubPort, obj: Any, t: float, now_us: int) -> None:
        selections: Selections = pp.extra
        for path, value in selections.next_select():
            _put(obj, path, value)
        claimed = {el.value for el in selections.elements if el.key is not None and el.value is not None}
        for el in selections.elements:
            ensure_element(obj, el, claimed, t, now_us)

    def command_values(self, dev: SimDevice, sp: SubPort, msg: Any) -> dict[str, Any] | None:
        """This device's part of a broadcast command: {element: value} (an item as a dict), the whole message as a
        dict when it is addressed as a whole, or None when it is not meant for this device."""
        if not sp.extra:
            return to_builtin_v0(msg)
        found: dict[str, Any] | None = None
        for a in sp.extra:
            try:
                if any(_get(msg, path) != value for path, value in a.select):
                    continue
            except AttributeError:
                continue
            if not a.elements:
                return to_builtin_v0(msg)
            for el in a.elements:
                value = element_value(msg, el)
                if value is not None:
                    found = found or {}
                    found[el.text] = to_builtin_v0(value)
        return found

    def apply(self, dev: SimDevice, values: dict[str, Any]) -> dict[str, float]:
        """Note an accepted command in the device's state; the vehicle model's inputs it sets (SAM's devices)."""
        state = dev.state.command
        state.update(values)
        table = SAM_ACTUATORS_V0.get(dev.info.name, {})
        names = sam_command_fields(dev.info.name)
        inputs: dict[str, float] = {}
        for text, value in values.items():
            scalar = value.get("command_value") if isinstance(value, dict) else value
            if not isinstance(scalar, int | float):
                continue
            try:
                el = parse_element(text)
            except ValueError:
                continue
            state[el.path if el.index is not None else "command_value"] = scalar  # for the devices' own models
            if text in table:
                inp, scale = table[text]
                inputs[inp] = float(scalar) * scale
                if inp in names:
                    state[names[inp]] = inputs[inp]  # as the Cyphal command field (rpm, percent, ...)
        return inputs

    def sync_params(self, dev: SimDevice) -> tuple[float, int]:
        return DRONECAN_MAX_INTERVAL_S, 32  # v0 transfer ids are 5 bits

    def record(self, port: Any, obj: Any, transmitted: bool) -> dict[str, Any]:
        t = port.port.data_type
        if transmitted:  # the values as they went out (float16 rounding, saturation)
            import dronecan

            copy = dronecan.TYPENAMES[t.name]()
            copy._unpack(obj._pack())
            obj = copy
        return {"protocol": "dronecan", "data_type": t.name, "data_type_id": t.data_type_id,
                "value": to_builtin_v0(obj)}
