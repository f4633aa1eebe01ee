"""The build's bus budget (sam_codegen.validate.bus_budget) against the frames SAM's simulated devices actually put on
the bus: under the `dronecan` layout (every device a dronecan node on a private ``mcast-lo:`` bus) and under the
`default` layout on Cyphal/CAN classic (MTU 8, a python-can ``virtual`` bus in this process).

A passive listener counts every frame by source node and port (data type id or subject id, from the CAN id) and
reassembles each transfer's payload size from the tail bytes. Judged, as the other rate tests, without wall-clock luck:

- every transfer a device sent is on the bus, and each took exactly the frames the budget's rule gives its payload
  (``dronecan_frame_lengths``, ``cyphal_frame_lengths``): the frame rules are exact;
- a fixed-size type takes exactly the predicted frames per transfer; a variable-length one at most that (the budget
  counts the largest size; the simulator sends shorter arrays, e.g. RawIMU's 6 covariance values of 36);
- the rates are the schedule (sent + skipped ticks over the window between two quiet points) against the nominal rate,
  within 20 % + 1 Hz; so each device's frames/s, schedule x measured frames per transfer + its heartbeat/NodeStatus,
  is within 20 % + 2 frames/s of the prediction for fixed-size devices and at most 120 % + 2 of it for the others.
  (pycyphal's uavcan.node.port.List, every 10 s, is outside the budget and outside the comparison.)
"""

from __future__ import annotations

import asyncio
import os
import threading
import time
from collections import Counter
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("dronecan")
pytest.importorskip("pycyphal")

from helpers.dronecan_support import private_iface, until
from helpers.runtime_support import generated_or_skip
from helpers.settling import until_stable

from sam_codegen.frontend.loader import load_spec_file
from sam_codegen.validate.bus_budget import cyphal_frame_lengths, dronecan_frame_lengths, layout_budgets
from sam_codegen.validate.resolve import Resolved, validate
from sam_runtime.dronecan_io import NodeLoop, make_node
from sam_runtime.sim.simulator import SimConfig, Simulator

pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning:pydsdl")

REPO = Path(__file__).resolve().parents[3]
LIVENESS = {"dronecan": 341, "cyphal": 7509}  # NodeStatus's data type id, Heartbeat's subject id
PORT_LIST = 7510  # pycyphal's uavcan.node.port.List: not in the budget
RATE_REL, RATE_ABS = 0.2, 1.0  # the schedule against the nominal rate, as the other rate tests
FRAMES_ABS = 2.0


class FrameCounter:
    """Frames and whole transfers of messages on the bus per (source node, port), with each transfer's payload
    size; ``protocol`` says how to read the CAN id (v0: data type id in bits 8-23, service flag bit 7; Cyphal v1:
    subject id in bits 8-20, service flag bit 25)."""

    def __init__(self, protocol: str) -> None:
        self.protocol = protocol
        self._lock = threading.Lock()
        self.frames: Counter[tuple[int, int]] = Counter()
        self.transfers: Counter[tuple[int, int]] = Counter()
        self.shapes: dict[tuple[int, int], Counter[tuple[int, int]]] = {}  # (payload bytes, frames) -> count
        self._open: dict[tuple[int, int], list[int]] = {}

    def count(self, can_id: int, data: bytes) -> None:
        if not data:
            return
        if self.protocol == "dronecan":
            if (can_id >> 7) & 1:
                return
            key = (can_id & 0x7F, (can_id >> 8) & 0xFFFF)
        else:
            if (can_id >> 25) & 1:
                return
            key = (can_id & 0x7F, (can_id >> 8) & 0x1FFF)
        tail = data[-1]
        with self._lock:
            self.frames[key] += 1
            if tail & 0x80:  # start of transfer
                self._open[key] = []
            lengths = self._open.get(key)
            if lengths is None:
                return
            lengths.append(len(data))
            if tail & 0x40:  # end of transfer: payload = data bytes - tail bytes (- the CRC of a multi-frame one)
                payload = sum(n - 1 for n in lengths) - (2 if len(lengths) > 1 else 0)
                self.transfers[key] += 1
                self.shapes.setdefault(key, Counter())[(payload, len(lengths))] += 1
                del self._open[key]

    def on_dronecan_frame(self, direction: str, frame: Any) -> None:
        if frame.extended:
            self.count(frame.id, bytes(frame.data))

    def snapshot(self) -> dict[str, Any]:
        with self._lock:
            return {"frames": Counter(self.frames), "transfers": Counter(self.transfers),
                    "shapes": {k: Counter(v) for k, v in self.shapes.items()}}


async def _quiet_point(sim: Simulator, counter: FrameCounter) -> dict[str, Any]:
    """Devices paused, every frame they sent counted (liveness goes on meanwhile: not part of the stability)."""
    paused_at = time.monotonic()
    await sim.pause()
    steady = (LIVENESS[counter.protocol], PORT_LIST)
    await until_stable(lambda: {k: v for k, v in counter.snapshot()["frames"].items() if k[1] not in steady},
                       0.3, 10.0)
    snap = counter.snapshot()
    snap["paused_at"] = paused_at
    snap["sim"] = {(d.info.name, pp.key): (pp.sent, pp.late) for d in sim.devices for pp in d.pubs}
    return snap


async def _window(sim: Simulator, counter: FrameCounter, node_ids: set[int], seconds: float) -> dict[str, Any]:
    await sim.start(publish_now=True)
    liveness = LIVENESS[counter.protocol]
    await until(lambda: all(counter.snapshot()["frames"][(n, liveness)] for n in node_ids), 15,
                "a heartbeat or NodeStatus from every device")
    start = await _quiet_point(sim, counter)
    sim.resume()
    resumed_at = time.monotonic()
    await asyncio.sleep(seconds)
    end = await _quiet_point(sim, counter)
    # The devices published from the resume to the pause; their liveness messages all along.
    return {"start": start, "end": end, "window": end["paused_at"] - resumed_at,
            "liveness_window": end["paused_at"] - start["paused_at"]}


async def _measure_dronecan(gen: Any, node_ids: set[int], seconds: float) -> dict[str, Any]:
    iface = private_iface()
    sim = Simulator(gen, SimConfig(layout="dronecan", dronecan_iface=iface))
    listener = make_node(iface, None)  # passive: it only listens
    counter = FrameCounter("dronecan")
    listener.can_driver.add_io_hook(counter.on_dronecan_frame)
    loop = NodeLoop(listener)
    loop.start()
    try:
        return await _window(sim, counter, node_ids, seconds)
    finally:
        loop.stop()
        listener.close()
        await sim.close()


async def _measure_cyphal_classic(gen: Any, node_ids: set[int], seconds: float) -> dict[str, Any]:
    import can

    channel = f"budget{os.getpid()}"
    counter = FrameCounter("cyphal")
    bus = can.Bus(interface="virtual", channel=channel)
    stop = threading.Event()

    def listen() -> None:
        while not stop.is_set():
            msg = bus.recv(0.05)
            if msg is not None and msg.is_extended_id:
                counter.count(msg.arbitration_id, bytes(msg.data))

    thread = threading.Thread(target=listen, daemon=True)
    thread.start()
    sim = Simulator(gen, SimConfig("can", f"virtual:{channel}", 8))
    try:
        return await _window(sim, counter, node_ids, seconds)
    finally:
        await sim.close()
        stop.set()
        thread.join(5)
        bus.shutdown()


def _compare(resolved: Resolved, layout: str, res: dict[str, Any]) -> list[tuple[str, float, float, bool]]:
    """Per device: (name, predicted frames/s, measured frames/s, fixed size), asserting the module's verdicts."""
    assert resolved.dronecan is not None
    budget = next(b for b in layout_budgets(resolved.spec, resolved.layouts,
                                            {"cyphal": resolved.mappings, "dronecan": resolved.dronecan_mappings},
                                            resolved.dsdl.get, resolved.dronecan.get) if b.layout == layout)
    start, end, window = res["start"], res["end"], res["window"]
    rows = []
    for node in budget.nodes:
        device = resolved.spec.devices.get(node.name)
        if device is None:
            continue  # the bridge: none runs here, its commands are not on this bus
        if node.protocol == "dronecan":
            ports = [(resolved.dronecan.get(p.type).data_type_id, f"dronecan:{p.type}")  # type: ignore[union-attr]
                     for p in device.dronecan_publishes]
        else:
            ports = [(p.subject_id, str(p.subject_id)) for p in device.publishes]
        *sent_transfers, liveness = node.transfers
        assert len(ports) == len(sent_transfers)
        key = (node.node_id, LIVENESS[node.protocol])
        measured = (end["frames"][key] - start["frames"][key]) / res["liveness_window"]  # its own 1 Hz timer
        fixed = True
        for (port, sim_key), t in zip(ports, sent_transfers, strict=True):
            key = (node.node_id, port)
            frames = end["frames"][key] - start["frames"][key]
            transfers = end["transfers"][key] - start["transfers"][key]
            sent = end["sim"][(node.name, sim_key)][0] - start["sim"][(node.name, sim_key)][0]
            late = end["sim"][(node.name, sim_key)][1] - start["sim"][(node.name, sim_key)][1]
            assert transfers == sent > 0, (node.name, t.type, transfers, sent)  # every sent transfer on the bus
            rule = dronecan_frame_lengths if node.protocol == "dronecan" else cyphal_frame_lengths
            for payload, count in end["shapes"][key]:
                assert count == len(rule(payload)), (node.name, t.type, payload, count)
            per_transfer = frames / transfers
            predicted_per_transfer = len(t.frame_lengths(budget.bus))
            assert per_transfer <= predicted_per_transfer, (node.name, t.type, per_transfer)
            fixed = fixed and per_transfer == predicted_per_transfer
            schedule = (sent + late) / window
            assert schedule == pytest.approx(t.rate_hz, rel=RATE_REL, abs=RATE_ABS), (node.name, t.type, schedule)
            measured += schedule * per_transfer
        predicted = node.frames_per_s(budget.bus)
        rows.append((node.name, predicted, measured, fixed))
        if fixed:
            assert measured == pytest.approx(predicted, rel=RATE_REL, abs=FRAMES_ABS), rows[-1]
        else:
            assert measured <= (1 + RATE_REL) * predicted + FRAMES_ABS, rows[-1]
        assert liveness.rate_hz == 1.0
    assert {name for name, *_ in rows} == set(resolved.spec.devices)
    print(f"\nbus budget vs simulator, layout {layout} on {budget.bus.describe()}, window {window:.1f} s (frames/s):")
    for name, predicted, measured, fixed in rows:
        kind = "fixed size" if fixed else "variable size: the budget counts the largest"
        print(f"  {name:20} predicted {predicted:7.1f}  measured {measured:7.1f}  ({kind})")
    print(f"  {'devices in all':20} predicted {sum(r[1] for r in rows):7.1f}  measured {sum(r[2] for r in rows):7.1f}")
    port_list = sum(v for k, v in end["frames"].items() if k[1] == PORT_LIST) - sum(
        v for k, v in start["frames"].items() if k[1] == PORT_LIST)
    if port_list:
        print(f"  (not budgeted: uavcan.node.port.List, {port_list / res['liveness_window']:.1f} frames/s)")
    return rows


def _run(coro: Any, timeout: float = 90.0) -> Any:
    async def bounded() -> Any:
        async with asyncio.timeout(timeout):
            return await coro

    return asyncio.run(bounded())


def _sam() -> tuple[Any, Resolved]:
    gen = generated_or_skip()
    tables = gen.tables()
    if tables.VEHICLE != "sam" or not getattr(tables, "DRONECAN_DEVICES", ()):
        pytest.skip("SAM's DroneCAN devices")
    return gen, validate(load_spec_file(REPO / "spec" / "interfaces.yaml"))


@pytest.mark.slow
def test_the_dronecan_layouts_budget_matches_the_simulators_frames() -> None:
    gen, resolved = _sam()
    ids = {d.node_id for d in resolved.spec.devices.values()}
    _compare(resolved, "dronecan", _run(_measure_dronecan(gen, ids, 4.0)))


@pytest.mark.slow
def test_the_default_layouts_budget_matches_the_simulators_frames_on_classic_cyphal_can() -> None:
    pytest.importorskip("can")
    gen, resolved = _sam()
    ids = {d.node_id for d in resolved.spec.devices.values()}
    _compare(resolved, "default", _run(_measure_cyphal_classic(gen, ids, 4.0)))
