"""Simulated devices: one node per device of the spec, with the spec's node id, in one asyncio loop.

- Protocols: the layout (``SimConfig.layout``, one of the spec's ``layouts``; :func:`layout_protocols`) says which
  firmware each device runs: a pycyphal node on ``kind``/``iface`` (:mod:`sam_runtime.sim.cyphal`), or a dronecan
  (UAVCAN v0) node on ``dronecan_iface`` (:mod:`sam_runtime.sim.dronecan`). The node, its ports, the messages'
  generic values and closing are one small adapter per protocol; the schedule, physics, command policy, counters
  and faults are shared.
- Every published port runs at its nominal rate (``rate_hz`` of the spec, optionally scaled), on an
  absolute schedule (no drift; a late tick is published late, never twice).
- Values (:mod:`sam_runtime.sim.devices`): generic in-range values for any DSDL type; where the type is
  known, measurements of one shared simulated vehicle (:mod:`sam_runtime.physics.vehicle`): IMU, magnetometer,
  pressure, altimeter, GNSS (a fix only at the surface), battery, and the actuators' feedback.
- One vehicle: the SAM actuator devices (:data:`SAM_ACTUATORS`, by device name) drive the model's inputs; the
  model moves toward them at finite rates and integrates in fixed 10 ms steps up to the time a device reads it,
  so a seed and a command sequence give one trajectory. Devices of other specs keep their own simple feedback
  model (moving toward the last command at a finite rate).
- Actuators accept commands only from the bridge's node id; commands from any other node are counted and
  ignored.
- Timestamps: microseconds on a monotonic clock whose epoch is the wall-clock time at start (realistic
  ROS stamps, never jumping); with ``time_scale`` the vehicle's clock (and the stamps) run that many times
  faster than the wall clock, and so do the publication rates. Device clocks (``SimConfig.device_clocks``, at time
  scale 1): each device's own clock runs 5..120 s off (:mod:`sam_runtime.sim.time_sync`) and follows the bus's
  time-sync master (Cyphal ``uavcan.time.Synchronization``, DroneCAN ``GlobalTimeSync``); its messages carry
  the synchronised time, or 0 ("unknown", both protocols' convention, which the bridge stamps with its receive
  time and counts) until it has synchronised, again after each reboot. Counted per device (``time_sync`` in
  :meth:`Simulator.report`, with the synchronised clock's error against the computers' clock).
- Ground truth: ``Simulator.truth()`` in process, and ``truth_file`` (JSON lines when it ends in ``.jsonl``,
  else one JSON object replaced atomically) at ``truth_rate_hz`` of vehicle time.

``Simulator.report()`` gives counts per device and port (published, commands accepted/rejected, the last command):
a Cyphal port is keyed by its subject id (``"1100"``), a DroneCAN one by ``"dronecan:<data type name>"``
(``"dronecan:uavcan.equipment.ahrs.RawIMU"``); a DroneCAN command port also counts ``not_addressed`` (broadcasts
without this device's element). ``record`` writes every transmitted and received message (as transmitted) as JSON
lines (``subject`` for Cyphal, ``protocol``/``data_type``/``data_type_id`` for DroneCAN).
For fault tests: ``power_off(name)``/``power_on(name)`` (a device that stops - its heartbeat too - and
reboots; ``restart(name)``: both, ``SimConfig.reboot_s`` apart, as DroneCAN's RestartNode and Cyphal's
ExecuteCommand RESTART) and ``pause()``/``resume()`` (hold every publication, heartbeats go on, nothing left in
flight).
"""

from __future__ import annotations

import asyncio
import json
import logging
import math
import os
import time
from typing import TYPE_CHECKING, Any, TextIO

from sam_runtime.common.rate_log import RateLimitedLog
from sam_runtime.common.tasks import cancel_and_wait
from sam_runtime.genpkg import GeneratedPackage
from sam_runtime.protocols import default_protocol, registered, runtime_protocol
from sam_runtime.sim.config import SimConfig
from sam_runtime.sim.devices import (
    PHYSICS,
    SAM_ACTUATORS,
    DeviceState,
    VehicleState,
    generic_fill,
    physics_key,
)
from sam_runtime.sim.ports import DeviceAdapter, PubPort, SimDevice, SubPort
from sam_runtime.sim.time_sync import DeviceClock, SyncSlave, device_offset_us

if TYPE_CHECKING:
    from sam_codegen.contracts.tables_api import TablesModule

# The device models live in sam_runtime.sim.devices; re-exported here, where the tests and benchmarks import them.
__all__ = ["PHYSICS", "SAM_ACTUATORS", "DeviceState", "SimConfig", "Simulator", "VehicleState", "generic_fill",
           "layout_protocols", "physics_key"]

_log = logging.getLogger("sam_runtime.sim.simulator")


# ============================================================================================ simulator
def layout_protocols(tables: TablesModule, layout: str = "default") -> dict[str, str]:
    """Device name -> ``"cyphal"`` | ``"dronecan"`` under a layout of the spec (the generated ``LAYOUTS``, in spec
    order; ``default``: every device on its own ``protocol``, or on Cyphal for tables without layouts). ValueError
    names the spec's layouts."""
    layouts = {lay.name: lay for lay in tables.LAYOUTS}
    lay = layouts.get(layout)
    if lay is not None:
        return dict(lay.protocols)
    if layout == "default" and not layouts:
        return {d.name: default_protocol().name for d in default_protocol().devices(tables)}
    raise ValueError(f"the spec has no layout {layout!r}; its layouts: {', '.join(sorted(layouts) or ['default'])}")


class Simulator:
    """All simulated devices of a spec. In a running loop: ``await start()``, ``start_publishing()`` (or pass
    ``publish_now=True``), ..., ``await close()``."""

    def __init__(self, gen: GeneratedPackage, config: SimConfig | None = None) -> None:
        self.gen = gen
        self.tables = gen.tables()
        self.config = config or SimConfig()
        if not (math.isfinite(self.config.time_scale) and self.config.time_scale > 0):
            raise ValueError(f"time_scale must be > 0, got {self.config.time_scale}")
        if not (math.isfinite(self.config.truth_rate_hz) and self.config.truth_rate_hz > 0):
            raise ValueError(f"truth_rate_hz must be > 0, got {self.config.truth_rate_hz}")
        self.vehicle = VehicleState(time_scale=self.config.time_scale, model=self.config.make_vehicle())
        self._truth_task: asyncio.Task[None] | None = None
        self.truth_written = 0
        # A spec without a bridge has no node to take commands from: the actuators then accept none.
        self.bridge_node_id: int | None = (self.config.bridge_node_id if self.config.bridge_node_id is not None
                                           else self.tables.BRIDGE_NODE_ID)
        protocols = layout_protocols(self.tables, self.config.layout)
        wanted = None if self.config.devices is None else set(self.config.devices)
        if wanted is not None and wanted - set(protocols):
            raise ValueError(f"unknown device(s) {sorted(wanted - set(protocols))}; the spec has {sorted(protocols)}")
        firmware: dict[str, dict[str, Any]] = {p.name: {d.name: d for d in p.devices(self.tables)}
                                               for p in registered()}
        self.devices = []
        for name, protocol in protocols.items():
            info = firmware.get(protocol, {}).get(name)
            if info is None:
                raise ValueError(f"layout {self.config.layout!r} puts {name} on {protocol}, but the spec gives it no "
                                 f"{protocol} firmware")
            if wanted is None or name in wanted:
                self.devices.append(SimDevice(info, DeviceState(name, info.node_id), protocol=protocol))
        if self.config.device_clocks and self.vehicle.time_scale == 1.0:
            for dev in self.devices:
                dev.clock = DeviceClock(self.vehicle.epoch_us, self.vehicle.mono0_ns, device_offset_us(dev.info.name))
        self._adapters: dict[str, DeviceAdapter] = {}
        for protocol in {d.protocol for d in self.devices}:
            entry = runtime_protocol(protocol)
            try:  # (DroneCAN's imports dronecan, the runtime extra: only when a device runs it)
                adapter = entry.sim()
            except ImportError as ex:
                raise ValueError(f"layout {self.config.layout!r} has {entry.label} devices: {ex}") from None
            self._adapters[protocol] = adapter(self)
        self._go: asyncio.Event | None = None  # created in start() (inside the loop)
        self._running: asyncio.Event | None = None  # cleared by pause()
        self._record: TextIO | None = None
        self._publishing_since: float | None = None
        self._publishing_until: float | None = None
        self._closed = False
        self.log = RateLimitedLog(_log, self.config.log_interval)  # bounded, like the bridge's

    # ---------------------------------------------------------------------------------- lifecycle
    async def start(self, *, publish_now: bool = False) -> None:
        """Create every device's node (heartbeats start at once) and its ports; sensors wait for
        :meth:`start_publishing` unless ``publish_now``."""
        for adapter in self._adapters.values():
            adapter.prepare()
        self._go = asyncio.Event()
        self._running = asyncio.Event()
        self._running.set()
        if self.config.record is not None:
            self._record = open(self.config.record, "w", buffering=1)
        try:
            for dev in self.devices:
                self._adapter(dev).ports(dev)
                self._open_device(dev)
            for dev in self.devices:
                self._start_device_tasks(dev)
            if self.config.truth_file is not None:
                self._truth_task = asyncio.create_task(self._truth_loop(), name="sim-truth")
        except BaseException:
            await self.close()
            raise
        if publish_now:
            self.start_publishing()

    def _adapter(self, dev: SimDevice) -> DeviceAdapter:
        return self._adapters[dev.protocol]

    def _open_device(self, dev: SimDevice) -> None:
        """The device's node (heartbeats start at once) and its ports."""
        self._adapter(dev).open(dev)
        if dev.clock is not None:  # a (re)booted device has not synchronised yet
            max_interval, modulo = self._adapter(dev).sync_params(dev)
            dev.sync = SyncSlave(max_interval_s=max_interval, tid_modulo=modulo)
        dev.powered = True

    def _start_device_tasks(self, dev: SimDevice, restart: bool = False) -> None:
        for pp in dev.pubs:
            pp.task = asyncio.create_task(self._publish_loop(dev, pp, restart), name=f"sim-{dev.info.name}-{pp.key}")

    def device(self, name: str) -> SimDevice:
        for dev in self.devices:
            if dev.info.name == name:
                return dev
        raise KeyError(f"no simulated device {name!r}")

    async def power_off(self, name: str) -> None:
        """Cut the device's power: its node closes, so its heartbeats and publications stop (a device that stops
        sending, for heartbeat-timeout tests). Its counters are kept."""
        dev = self.device(name)
        if not dev.powered:
            return
        dev.powered = False
        if "rpm" in SAM_ACTUATORS.get(name, {}):  # a motor without power stops; servos hold their position
            self.vehicle.sync(self.vehicle.t())
            self.vehicle.vehicle.command(**{SAM_ACTUATORS[name]["rpm"]: 0.0})
        await cancel_and_wait([pp.task for pp in dev.pubs if pp.task is not None])
        for pp in dev.pubs:
            pp.task = None
        await self._adapter(dev).close([dev])
        dev.power_cycles += 1

    async def power_on(self, name: str) -> None:
        """Power a device back on: a new node (uptime and transfer ids from 0, like a reboot) that publishes on
        its schedule again (if publishing was started)."""
        dev = self.device(name)
        if dev.powered or self._closed:
            return
        self._open_device(dev)
        self._start_device_tasks(dev, restart=True)

    async def restart(self, name: str) -> None:
        """A reboot (DroneCAN's RestartNode, Cyphal's ExecuteCommand RESTART): power off, silent for
        ``config.reboot_s`` (a real device's reset, bootloader and firmware start), then on again (uptime and
        transfer ids from 0)."""
        if self._closed:
            return
        await self.power_off(name)
        await asyncio.sleep(self.config.reboot_s)
        await self.power_on(name)

    def start_publishing(self, duration: float | None = None) -> None:
        """Open the gate: every publisher starts its schedule now; with ``duration``, stops after it."""
        assert self._go is not None, "start() first"
        now = time.monotonic()
        self._publishing_since = now
        self._publishing_until = None if duration is None else now + duration
        self._go.set()

    async def pause(self, timeout: float = 2.0) -> None:
        """Hold every publication (heartbeats go on) and wait until none is in flight: afterwards the counts of
        sent messages do not move (for exact before/after accounting in tests)."""
        assert self._running is not None, "start() first"
        self._running.clear()
        deadline = time.monotonic() + timeout
        while any(pp.busy for d in self.devices for pp in d.pubs) and time.monotonic() < deadline:
            await asyncio.sleep(0.005)

    def resume(self) -> None:
        """Publish again, each port on a new schedule from now (no burst to catch up, no late ticks)."""
        assert self._running is not None, "start() first"
        self._running.set()

    @property
    def synchronised(self) -> bool:
        """Whether every powered device with its own clock follows the time-sync master (True without clocks)."""
        return all(d.sync is not None and d.sync.synchronised for d in self.devices if d.clock is not None and
                   d.powered)

    @property
    def publishing_done(self) -> bool:
        return self._publishing_until is not None and time.monotonic() >= self._publishing_until and all(
            pp.task is None or pp.task.done() for d in self.devices for pp in d.pubs)

    async def wait_publishing_done(self) -> None:
        tasks = [pp.task for d in self.devices for pp in d.pubs if pp.task is not None]
        if tasks:
            await asyncio.gather(*tasks, return_exceptions=True)

    async def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        stuck = await cancel_and_wait([pp.task for d in self.devices for pp in d.pubs if pp.task is not None]
                                      + ([self._truth_task] if self._truth_task is not None else []))
        if self.config.truth_file is not None:
            self._write_truth()
        if stuck:
            _log.warning("%d publish tasks did not stop", len(stuck))
        for protocol, adapter in self._adapters.items():
            try:
                await adapter.close([d for d in self.devices if d.protocol == protocol and d.node is not None])
            except Exception as ex:  # the adapters log their own; never raise out of close()
                _log.warning("closing the simulated %s nodes: %s: %s", protocol, type(ex).__name__, ex)
        if self._record is not None:
            self._record.close()
            self._record = None
        self.log.flush(force=True)  # no count stays unlogged

    # ---------------------------------------------------------------------------------- publishing
    def make_sample(self, dev: SimDevice, pp: PubPort, dt: float) -> Any:
        """One message of the port: generic values, then the device's physics (if known)."""
        t, now_us = self.vehicle.t(), self.vehicle.now_us()
        if dev.clock is not None:  # its synchronised time, or 0 ("unknown") before it synchronised
            synced = None if dev.sync is None else dev.sync.to_master(dev.clock.local_us(time.monotonic_ns()))
            if synced is not None:  # an adjustment never sends its stamps back in time (the port's last one)
                synced = pp.last_stamp_us = max(synced, pp.last_stamp_us + 1)
            now_us = dev.state.stamp_us = 0 if synced is None else synced
        adapter = self._adapter(dev)
        obj = adapter.blank(pp, t, now_us)
        if dev.clock is not None and hasattr(obj, "timestamp"):  # counted where the message carries its stamp
            if now_us == 0:
                dev.stamps_unknown += 1
            else:
                dev.stamps_synchronised += 1
        if pp.physics is not None:
            pp.physics(obj, dev.state, self.vehicle, t, dt * self.vehicle.time_scale, self.vehicle.rng)
        adapter.finish(dev, pp, obj, t, now_us)
        dev.state.last_update = t
        return obj

    async def _publish_loop(self, dev: SimDevice, pp: PubPort, restart: bool = False) -> None:
        assert self._go is not None
        await self._go.wait()
        rate = float(pp.port.rate_hz) * float(self.config.rate_scale) * self.vehicle.time_scale  # per wall second
        if rate <= 0:
            return
        period = 1.0 / rate
        # Align every port to the gate, offset a little per subject so that not all fire at once.
        offset = (pp.ident % 17) * period / 17.0
        started = self._publishing_since if self._publishing_since is not None else time.monotonic()
        if restart:  # powered on again: a new schedule from now
            started = time.monotonic() - offset
        k = 0
        while not self._closed:
            if self._running is not None and not self._running.is_set():
                await self._running.wait()
                started, k = time.monotonic() - offset, 0
                continue
            due = started + offset + k * period
            until = self._publishing_until
            if until is not None and due >= until:
                return
            delay = due - time.monotonic()
            if delay > 0:
                await asyncio.sleep(delay)
            elif delay < -period:
                # Too late for this tick: skip the missed ones (counted), never burst.
                missed = int(-delay // period)
                pp.late += missed
                k += missed
                continue
            if self._running is not None and not self._running.is_set():
                continue  # paused while sleeping
            obj = self.make_sample(dev, pp, period)
            if pp.publisher is None:  # powered off meanwhile
                return
            pp.busy = True
            pub = pp.publisher
            try:
                ok = await pub.publish(obj)
            except asyncio.CancelledError:
                raise
            except Exception as ex:
                pp.failed += 1
                self.log.note((dev.info.name, f"publish on {pp.key}"), logging.WARNING, "failed: %s: %s",
                              type(ex).__name__, ex)
                ok = None
            finally:
                pp.busy = False
            if ok:
                pp.sent += 1
                if self._record is not None:
                    self._write_record("tx", dev, pp, obj, seq=pp.sent)
            elif ok is False:
                pp.failed += 1
                self.log.note((dev.info.name, f"publish on {pp.key}"), logging.WARNING,
                              "not every frame sent within %.1f s", pub.send_timeout)
            if pp.failed:
                self.log.flush()  # a count whose interval has passed, also when the failures have stopped
            k += 1

    # ---------------------------------------------------------------------------------- commands
    def on_command(self, dev: SimDevice, sp: SubPort, msg: Any, transfer: Any) -> None:
        adapter = self._adapter(dev)
        values = adapter.command_values(dev, sp, msg)
        if values is None:  # a broadcast without this device's element: not a command for it
            sp.not_addressed += 1
            return
        src = transfer.source_node_id
        accepted = src == self.bridge_node_id
        if accepted:
            sp.accepted += 1
            sp.last = values
            inputs = adapter.apply(dev, values)
            if inputs:  # from now on (the model first catches up with the time of arrival)
                self.vehicle.sync(self.vehicle.t())
                self.vehicle.vehicle.command(**inputs)
        else:
            sp.rejected += 1
            sp.rejected_sources[-1 if src is None else int(src)] += 1
        if self._record is not None:
            self._write_record("rx", dev, sp, msg, source=src, accepted=accepted,
                               seq=sp.accepted if accepted else sp.rejected)

    def on_time_sync(self, dev: SimDevice, master: int, transfer_id: int, prev_tx_us: int, rx_mono_ns: int) -> None:
        """A time-sync message reached ``dev``: its slave follows the master (the local time of reception from the
        transport's receive timestamp)."""
        if dev.clock is None or dev.sync is None:
            return
        if dev.sync.on_message(master, transfer_id, prev_tx_us, dev.clock.local_us(rx_mono_ns), rx_mono_ns * 1e-9) \
                and dev.sync.adjustments == 1:
            _log.info("%s: synchronised to the time of node %d (offset %+.6f s)", dev.info.name, master,
                      dev.sync.offset_us * 1e-6 if dev.sync.offset_us is not None else 0.0)

    # ---------------------------------------------------------------------------------- truth
    def truth(self) -> dict[str, Any]:
        """The vehicle's true state now (see :meth:`sam_runtime.physics.vehicle.Vehicle.truth`), with the sim's stamp
        clock (``stamp_us``, as in the devices' timestamps), the wall clock and the GPS origin."""
        veh = self.vehicle.sync(self.vehicle.t())
        return {**veh.truth(), "stamp_us": self.vehicle.epoch_us + round(veh.t * 1e6), "wall_ns": time.time_ns(),
                "gps_origin": list(self.config.gps_origin), "time_scale": self.vehicle.time_scale}

    def _write_truth(self) -> None:
        path = self.config.truth_file
        assert path is not None
        line = json.dumps(self.truth(), default=_json_default)
        try:
            if path.suffix == ".jsonl":
                with open(path, "a") as f:
                    f.write(line + "\n")
            else:
                tmp = path.with_name(f"{path.name}.tmp{os.getpid()}")
                tmp.write_text(line + "\n")
                os.replace(tmp, path)
            self.truth_written += 1
        except OSError as ex:
            _log.warning("truth file %s: %s", path, ex)

    async def _truth_loop(self) -> None:
        if self.config.truth_file is not None and self.config.truth_file.suffix == ".jsonl":
            self.config.truth_file.write_text("")  # a new run
        period = 1.0 / (self.config.truth_rate_hz * self.vehicle.time_scale)  # wall seconds
        start = time.monotonic()
        k = 0
        while not self._closed:
            self._write_truth()
            k += 1
            await asyncio.sleep(max(0.0, start + k * period - time.monotonic()))

    # ---------------------------------------------------------------------------------- reporting
    def _write_record(self, direction: str, dev: SimDevice, port: PubPort | SubPort, obj: Any,
                      **extra: Any) -> None:
        fields = self._adapter(dev).record(port, obj, direction == "tx")
        value = fields.pop("value")
        assert self._record is not None
        line = {"dir": direction, "device": dev.info.name, "node_id": dev.info.node_id, **fields,
                "wall_ns": time.time_ns(), **extra, "value": value}
        self._record.write(json.dumps(line, default=_json_default) + "\n")

    def report(self) -> dict[str, Any]:
        devices: dict[str, Any] = {}
        for d in self.devices:
            devices[d.info.name] = {
                "protocol": d.protocol,
                "node_id": d.info.node_id,
                "powered": d.powered,
                "power_cycles": d.power_cycles,
                "published": {p.key: p.sent for p in d.pubs},
                "late": {p.key: p.late for p in d.pubs if p.late},
                "failed": {p.key: p.failed for p in d.pubs if p.failed},
                "commands": {
                    s.key: {
                        "accepted": s.accepted, "rejected": s.rejected,
                        "rejected_sources": {str(k): v for k, v in s.rejected_sources.items()},
                        "last": s.last,
                        **self._adapter(d).command_report(s),
                    } for s in d.subs
                },
                "position": dict(d.state.position),
                **({"time_sync": _time_sync_report(d)} if d.clock is not None else {}),
            }
        truth = self.truth()
        since = self._publishing_since
        return {
            "layout": self.config.layout,
            "bridge_node_id": self.bridge_node_id,
            "publishing_s": None if since is None else round(
                (min(time.monotonic(), self._publishing_until or math.inf)) - since, 3),
            "devices": devices,
            "vehicle": truth,
            "rejected_vehicle_commands": self.vehicle.vehicle.rejected_commands,
        }


def _time_sync_report(d: SimDevice) -> dict[str, Any]:
    """A device's clock and time sync: its offset from the computers' time, whether it follows a master, and
    the error of its synchronised time against the computers' clock now (the simulator shares it: ground truth)."""
    assert d.clock is not None
    sync = d.sync
    now_ns = time.time_ns()
    synced = None if sync is None else sync.to_master(d.clock.local_us(time.monotonic_ns()))
    return {"clock_offset_us": d.clock.offset_us, "synchronised": synced is not None,
            "master": None if sync is None else sync.master, "adjustments": 0 if sync is None else sync.adjustments,
            "restarts": 0 if sync is None else sync.restarts,
            "last_correction_us": None if sync is None else sync.last_correction_us,
            "error_us": None if synced is None else synced - now_ns // 1000,
            "stamps_synchronised": d.stamps_synchronised, "stamps_unknown": d.stamps_unknown}


def _json_default(o: Any) -> Any:
    try:
        import numpy

        if isinstance(o, numpy.ndarray):
            return o.tolist()
        if isinstance(o, numpy.generic):
            return o.item()
    except ImportError:  # pragma: no cover
        pass
    if isinstance(o, bytes | bytearray):
        return o.decode(errors="replace")
    return str(o)
