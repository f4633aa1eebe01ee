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
    from plain_dronecan_node import broadcast_paced, loopback_node, wait_until_heard

    node = loopback_node(args.iface, args.node_id)
    end = time.monotonic() + args.max_life
    try:
        if not wait_until_heard(node, args.wait_for, end):
            return 1
        sent = broadcast_paced(node, (dronecan.uavcan.equipment.esc.Status(esc_index=args.esc_index, rpm=args.rpm,
                                                                           temperature=300.0)
                                      for _ in range(args.count)), args.rate, end)
    finally:
        node.close()
    print(f"PUBLISHED {sent}", flush=True)
    return 0 if sent == args.count else 1


if __name__ == "__main__":
    sys.exit(main())
