"""The build's bus budget (sam_codegen.validate.bus_budget) against the frames SAM's simulated devices actually put on
the bus under the `dronecan` layout (every device a dronecan node on a private ``mcast-lo:`` bus).

A passive listener counts every frame by source node and data type (the CAN id) and reassembles the transfers' sizes
from the tail bytes. Judged, as the other rate tests, without wall-clock luck:

- every transfer a device sent is on the bus, and each took exactly the frames the budget's v0 rule gives its payload
  (``dronecan_frame_lengths``): the frame rule is exact;
- a fixed-size type takes exactly the predicted frames per transfer; a variable-length one at most that (the budget
  counts the largest size; the simulator sends shorter arrays, e.g. RawIMU's 6 covariance values of 36);
- the rates are the schedule (sent + skipped ticks over the window between two quiet points) against the nominal rate,
  within 20 % + 1 Hz; so each device's frames/s, schedule x measured frames per transfer + its NodeStatus, is within
  20 % + 2 frames/s of the prediction for fixed-size devices and at most 120 % + 2 of it for the others.
"""

from __future__ import annotations

import asyncio
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
from sam_codegen.validate.bus_budget import dronecan_frame_lengths, layout_budgets
from sam_codegen.validate.resolve import validate
from sam_runtime.dronecan_io import NodeLoop, make_node
from sam_runtime.sim.simulator import SimConfig, Simulator

pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning:pydsdl")

REPO = Path(__file__).resolve().parents[3]
NODE_STATUS_ID = 341
RATE_REL, RATE_ABS = 0.2, 1.0  # the schedule against the nominal rate, as the other rate tests
FRAMES_ABS = 2.0


class FrameCounter:
    """Frames and whole transfers on the bus per (source node, data type id), with each transfer's payload size."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self.frames: Counter[tuple[int, int]] = Counter()
        self.transfers: Counter[tuple[int, int]] = Counter()
        self.shapes: dict[tuple[int, int], Counter[tuple[int, int]]] = {}  # (payload bytes, frames) -> count
        self._open: dict[tuple[int, int], list[int]] = {}

    def on_frame(self, direction: str, frame: Any) -> None:
        if not frame.extended or (frame.id >> 7) & 1 or not frame.data:  # v0 message frames only
            return
        key = (frame.id & 0x7F, (frame.id >> 8) & 0xFFFF)
        tail = frame.data[-1]
        with self._lock:
            self.frames[key] += 1
            if tail & 0x80:  # start of transfer
                self._open[key] = []
            lengths = self._open.get(key)
            if lengths is None:
                return
            lengths.append(len(frame.data))
            if tail & 0x40:  # end of transfer: payload = data bytes - tail bytes (- the CRC of a multi-frame one)
                payload = sum(n - 1 for n in lengths) - (2 if len(lengths) > 1 else 0)
                self.transfers[key] += 1
                self.shapes.setdefault(key, Counter())[(payload, len(lengths))] += 1
                del self._open[key]

    def snapshot(self) -> dict[str, Any]:
        with self._lock:
            return {"frames": Counter(self.frames), "transfers": Counter(self.transfers),
                    "shapes": {k: Counter(v) for k, v in self.shapes.items()}}


async def _quiet_point(sim: Simulator, counter: FrameCounter) -> dict[str, Any]:
    """Devices paused, every frame they sent counted (NodeStatus goes on meanwhile: not part of the stability)."""
    paused_at = time.monotonic()
    await sim.pause()
    await until_stable(lambda: {k: v for k, v in counter.snapshot()["frames"].items() if k[1] != NODE_STATUS_ID},
                       0.3, 10.0)
    snap = counter.snapshot()
    snap["paused_at"] = paused_at
    snap["sim"] = {(d.info.name, pp.key): (pp.sent, pp.late) for d in sim.devices for pp in d.pubs}
    return snap


async def _measure(gen: Any, seconds: float) -> dict[str, Any]:
    iface = private_iface()
    sim = Simulator(gen, SimConfig(layout="dronecan", dronecan_iface=iface))
    listener = make_node(iface, None)  # passive: it only listens
    counter = FrameCounter()
    listener.can_driver.add_io_hook(counter.on_frame)
    loop = NodeLoop(listener)
    loop.start()
    await sim.start(publish_now=True)
    try:
        ids = {d.node_id for d in gen.tables().DRONECAN_DEVICES}
        await until(lambda: all(counter.snapshot()["frames"][(n, NODE_STATUS_ID)] for n in ids), 10,
                    "NodeStatus from every device")
        start = await _quiet_point(sim, counter)
        sim.resume()
        resumed_at = time.monotonic()
        await asyncio.sleep(seconds)
        end = await _quiet_point(sim, counter)
    finally:
        loop.stop()
        listener.close()
        await sim.close()
    # The devices published from the resume to the pause; NodeStatus all along.
    return {"start": start, "end": end, "window": end["paused_at"] - resumed_at,
            "status_window": end["paused_at"] - start["paused_at"]}


def _run(coro: Any, timeout: float = 90.0) -> Any:
    async def bounded() -> Any:
        async with asyncio.timeout(timeout):
            return await coro

    return asyncio.run(bounded())


@pytest.mark.slow
def test_the_dronecan_layouts_budget_matches_the_simulators_frames() -> None:
    gen = generated_or_skip()
    tables = gen.tables()
    if tables.VEHICLE != "sam" or not getattr(tables, "DRONECAN_DEVICES", ()):
        pytest.skip("SAM's DroneCAN devices")
    resolved = validate(load_spec_file(REPO / "spec" / "interfaces.yaml"))
    assert resolved.dronecan is not None
    budget = next(b for b in layout_budgets(resolved.spec, resolved.layouts,
                                            {"cyphal": resolved.mappings, "dronecan": resolved.dronecan_mappings},
                                            resolved.dsdl.get, resolved.dronecan.get) if b.layout == "dronecan")
    ids = {s.name: s.data_type_id for s in (resolved.dronecan.get(p.type) for d in resolved.spec.devices.values()
                                             for p in d.dronecan_publishes) if s is not None}
    res = _run(_measure(gen, 4.0))
    start, end = res["start"], res["end"]
    window, status_window = res["window"], res["status_window"]
    rows = []
    for node in budget.nodes:
        if resolved.spec.bridge is not None and node.node_id == resolved.spec.bridge.node_id:
            continue  # no bridge runs here: its commands are not on this bus
        predicted = node.frames_per_s(budget.bus)
        equivalent = 0.0
        fixed = True
        for t in node.transfers:
            if t.type == "uavcan.protocol.NodeStatus":
                key = (node.node_id, NODE_STATUS_ID)
                equivalent += (end["frames"][key] - start["frames"][key]) / status_window  # its own 1 Hz timer
                continue
            key = (node.node_id, ids[t.type])
            frames = end["frames"][key] - start["frames"][key]
            transfers = end["transfers"][key] - start["transfers"][key]
            sent0, late0 = start["sim"][(node.name, f"dronecan:{t.type}")]
            sent1, late1 = end["sim"][(node.name, f"dronecan:{t.type}")]
            sent, late = sent1 - sent0, late1 - late0
            assert transfers == sent > 0, (node.name, t.type, transfers, sent)  # every sent transfer on the bus
            for (payload, count), _ in end["shapes"][key].items():
                assert count == len(dronecan_frame_lengths(payload)), (node.name, t.type, payload, count)
            per_transfer = frames / transfers
            predicted_per_transfer = len(t.frame_lengths(budget.bus))
            assert per_transfer <= predicted_per_transfer, (node.name, t.type, per_transfer)
            fixed = fixed and per_transfer == predicted_per_transfer
            schedule = (sent + late) / window
            assert schedule == pytest.approx(t.rate_hz, rel=RATE_REL, abs=RATE_ABS), (node.name, t.type, schedule)
            equivalent += schedule * per_transfer
        rows.append((node.name, predicted, equivalent, fixed))
        if fixed:
            assert equivalent == pytest.approx(predicted, rel=RATE_REL, abs=FRAMES_ABS), (node.name, rows[-1])
        else:
            assert equivalent <= (1 + RATE_REL) * predicted + FRAMES_ABS, (node.name, rows[-1])
    print(f"\nbus budget vs simulator, layout dronecan, window {window:.1f} s (frames/s):")
    for name, predicted, equivalent, fixed in rows:
        kind = "fixed size" if fixed else "variable size: the budget counts the largest"
        print(f"  {name:20} predicted {predicted:7.1f}  measured {equivalent:7.1f}  ({kind})")
    print(f"  {'devices in all':20} predicted {sum(r[1] for r in rows):7.1f}  measured {sum(r[2] for r in rows):7.1f}")
    assert {name for name, *_ in rows} == {d.name for d in tables.DRONECAN_DEVICES}
