"""A DroneCAN ESC that the spec does not know (a node id from dynamic allocation), in its own process, written
against the plain dronecan API.

python esc_status_peer.py --iface mcast-lo:<bus>:<port> --node-id 77 --wait-for 100 --esc-index 1 --rpm 4321
    --count 20 [--rate 50] [--max-life 60]

Waits until node ``--wait-for`` (the bridge) is heard, broadcasts ``--count`` uavcan.equipment.esc.Status with the
given esc_index and rpm at ``--rate``, prints ``PUBLISHED n`` and exits 0.
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
    p.add_argument("--esc-index", type=int, required=True)
    p.add_argument("--rpm", type=int, required=True)
    p.add_argument("--count", type=int, required=True)
    p.add_argument("--rate", type=float, default=50.0)
    p.add_argument("--max-life", type=float, default=60.0)
    args = p.parse_args()
    import dronecan

    from sam_runtime.dronecan_io import LoopbackMulticastDriver, parse_iface

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
        while sent < args.count and time.monotonic() < end:
            node.broadcast(dronecan.uavcan.equipment.esc.Status(esc_index=args.esc_index, rpm=args.rpm,
                                                                temperature=300.0))
            sent += 1
            node.spin(1.0 / args.rate)
        node.spin(0.2)  # the last frames out
    finally:
        node.close()
    print(f"PUBLISHED {sent}", flush=True)
    return 0 if sent == args.count else 1


if __name__ == "__main__":
    sys.exit(main())
