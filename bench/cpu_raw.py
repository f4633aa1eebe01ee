"""The raw receiver of the CPU section (bench/cpu.py): the protocol library alone, subscribed to the ports the
bridge listens to, doing nothing with what it receives. Its CPU beside the bridge's, on the same traffic in the
same run, is the floor a bridge in Python on that library cannot go below.

    python -m bench.cpu_raw cyphal|dronecan [--layout NAME] [--generated DIR] [--node-id N]

- ``cyphal``: a pycyphal node (heartbeat, GetInfo: what ``pycyphal.application.make_node`` gives every node) on
  Cyphal/UDP 127.0.0.1 with one subscriber per UAVCAN->ROS subject of the layout and one on
  ``uavcan.node.Heartbeat`` (the bridge watches every device's heartbeat), each ``receive_in_background`` with a
  handler that only counts.
- ``dronecan``: a ``dronecan.node.Node`` (NodeStatus once a second) on the project's loopback bus driver
  (``mcast-lo:``, sam_runtime.dronecan_io.LoopbackMulticastDriver; no FrameGate, no acceptance filter: dronecan
  decodes every transfer a node receives, as it does in the bridge), a counting handler per UAVCAN->ROS data type of
  the layout and NodeStatus, spun by ``node.spin()`` in the main thread: the plain dronecan application.

Prints ``READY raw ...`` once subscribed; on SIGTERM/SIGINT prints ``DONE {json}`` (messages received, spin
errors) and exits 0.
"""

from __future__ import annotations

import argparse
import asyncio
import json
import signal
import sys
import threading
from pathlib import Path
from typing import Any

import bench.common  # noqa: F401  (loopback discovery before anything imports rclpy)
from bench.common import REPO

RAW_NODE_ID = 110  # free in SAM's spec (devices 11..26, the bridge 100)


def uavcan_to_ros(tables: Any, layout: str, protocol: str) -> list[Any]:
    """The layout's UAVCAN->ROS mappings of one protocol (what the bridge subscribes to)."""
    info = next(x for x in tables.LAYOUTS if x.name == layout)
    names = set(info.cyphal_mappings if protocol == "cyphal" else info.dronecan_mappings)
    mappings = tables.MAPPINGS if protocol == "cyphal" else tables.DRONECAN_MAPPINGS
    return [m for m in mappings if m.name in names and m.direction == "uavcan_to_ros"]


class Counter:
    def __init__(self) -> None:
        self.received = 0
        self.errors = 0

    def done(self, extra: dict[str, Any]) -> None:
        print("DONE " + json.dumps({"received": self.received, "errors": self.errors, **extra}), flush=True)


async def run_cyphal(gen: Any, layout: str, node_id: int, count: Counter) -> None:
    import uavcan.node  # compiled by generated_package() (the bridge's own DSDL cache)

    from sam_runtime.cyphal_io.transport import make_node

    node = make_node("org.sam.bench.raw", node_id, "udp", iface="127.0.0.1")
    stop = asyncio.Event()
    loop = asyncio.get_running_loop()
    for sig in (signal.SIGTERM, signal.SIGINT):
        loop.add_signal_handler(sig, stop.set)

    async def nothing(_msg: Any, _meta: Any) -> None:
        count.received += 1

    subjects = {m.port.subject_id: gen.dsdl_class(m.port) for m in uavcan_to_ros(gen.tables(), layout, "cyphal")}
    subs = [node.make_subscriber(dtype, sid) for sid, dtype in sorted(subjects.items())]
    subs.append(node.make_subscriber(uavcan.node.Heartbeat_1_0))
    for s in subs:
        s.receive_in_background(nothing)
    print(f"READY raw cyphal node_id={node_id} subjects={sorted(subjects)} + heartbeat", flush=True)
    try:
        await stop.wait()
    finally:
        for s in subs:
            s.close()
        node.close()
    count.done({"subjects": len(subs)})


def run_dronecan(gen: Any, layout: str, node_id: int, count: Counter) -> None:
    import dronecan

    from sam_runtime.dronecan_io import make_driver
    from sam_runtime.dronecan_io.types import ensure_types

    ensure_types(gen)  # the spec's own v0 types (sam.sensor.Altitude, ...) beside dronecan's
    node = dronecan.node.Node(make_driver("mcast-lo:"), node_id=node_id, node_status_interval=1.0)
    node.node_info.name = b"org.sam.bench.raw"
    node.mode = dronecan.uavcan.protocol.NodeStatus().MODE_OPERATIONAL
    stop = threading.Event()
    for sig in (signal.SIGTERM, signal.SIGINT):
        signal.signal(sig, lambda *_: stop.set())

    def nothing(_event: Any) -> None:
        count.received += 1

    types = sorted({m.data_type.name for m in uavcan_to_ros(gen.tables(), layout, "dronecan")})
    for name in [*types, "uavcan.protocol.NodeStatus"]:
        node.add_handler(dronecan.TYPENAMES[name], nothing)
    print(f"READY raw dronecan node_id={node_id} types={types} + NodeStatus", flush=True)
    try:
        while not stop.is_set():
            try:
                node.spin(0.5)
            except Exception:  # dronecan raises a bad transfer out of spin(): counted, the next one goes on
                count.errors += 1
    finally:
        node.close()
    count.done({"types": len(types) + 1})


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m bench.cpu_raw", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("protocol", choices=("cyphal", "dronecan"))
    ap.add_argument("--layout", default=None, help="default: default (cyphal), dronecan (dronecan)")
    ap.add_argument("--generated", type=Path, default=REPO / "generated")
    ap.add_argument("--node-id", type=int, default=RAW_NODE_ID)
    args = ap.parse_args(argv)
    from sam_runtime.genpkg import GeneratedPackage

    gen = GeneratedPackage(args.generated)
    gen.compile_dsdl()
    layout = args.layout or ("default" if args.protocol == "cyphal" else "dronecan")
    count = Counter()
    if args.protocol == "cyphal":
        asyncio.run(run_cyphal(gen, layout, args.node_id, count))
    else:
        run_dronecan(gen, layout, args.node_id, count)
    return 0


if __name__ == "__main__":
    sys.exit(main())
