"""A leak sensor on DroneCAN in its own process, written against the plain dronecan API: it reports its flag as the
position of an actuator, 100 when it is wet (the firmware of tests/specs/lolo_v0.yaml and relay.yaml; the
simulator never sends position 100).

python leak_sensor_peer.py --iface mcast-lo:<bus>:<port> --node-id 41 --wait-for 100 --actuator-id 9
    --positions 100,0,100,55.5 [--rate 20] [--max-life 60]

Waits until node ``--wait-for`` (the bridge) is heard, broadcasts one uavcan.equipment.actuator.Status per position
(in order, at ``--rate``), prints ``PUBLISHED n`` and exits 0.
"""

from __future__ import annotations

import argparse
import sys
import time


def main() -> int:
    p = argparse.ArgumentParser()
    p.add_argument("--iface", required=True)
    p.add_argument("--node-id", type=int, required=True)
    p.add_argument("--wait-for", type=int, required=True)
    p.add_argument("--actuator-id", type=int, required=True)
    p.add_argument("--positions", required=True, help="comma-separated positions, one Status each")
    p.add_argument("--rate", type=float, default=20.0)
    p.add_argument("--max-life", type=float, default=60.0)
    args = p.parse_args()
    import dronecan

    from sam_runtime.dronecan_io import LoopbackMulticastDriver, parse_iface

    positions = [float(v) for v in args.positions.split(",")]
    spec = parse_iface(args.iface)
    node = dronecan.node.Node(LoopbackMulticastDriver(spec.bus, spec.port), node_id=args.node_id,
                              node_status_interval=0.5, mode=0)
    seen: set[int] = set()
    node.add_handler(dronecan.uavcan.protocol.NodeStatus, lambda e: seen.add(e.transfer.source_node_id))
    end = time.monotonic() + args.max_life
    sent = 0
    try:
        while args.wait_for not in seen:
            if time.monotonic() > end:
                print(f"TIMEOUT waiting for node {args.wait_for}", flush=True)
                return 1
            node.spin(0.05)
        for position in positions:
            node.broadcast(dronecan.uavcan.equipment.actuator.Status(actuator_id=args.actuator_id,
                                                                     position=position))
            sent += 1
            node.spin(1.0 / args.rate)
        node.spin(0.2)  # the last frames out
    finally:
        node.close()
    print(f"PUBLISHED {sent}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
