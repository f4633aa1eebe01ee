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
import math
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
    from plain_dronecan_node import broadcast_paced, loopback_node, wait_until_heard

    positions = [float(v) for v in args.positions.split(",")]
    node = loopback_node(args.iface, args.node_id)
    try:
        if not wait_until_heard(node, args.wait_for, time.monotonic() + args.max_life):
            return 1
        # (--max-life bounds the wait only: the few positions always go out)
        sent = broadcast_paced(node, (dronecan.uavcan.equipment.actuator.Status(actuator_id=args.actuator_id,
                                                                                position=position)
                                      for position in positions), args.rate, math.inf)
    finally:
        node.close()
    print(f"PUBLISHED {sent}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
