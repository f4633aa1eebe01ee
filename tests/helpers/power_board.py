"""The power board of tests/specs/power_v0.yaml (node 30) in its own process: a plain ``dronecan`` node that knows
the spec's own types the way the runtime gives them to dronecan (sam_runtime.dronecan_io.types.ensure_types).

python power_board.py --generated DIR --iface mcast-lo:<bus>:<port> --start-file F [--namespace power]
    [--node-id 30] [--panic TEXT]

Prints ``READY {...}`` with the array's data type id and the type dronecan decodes that id as; once F exists,
broadcasts one <namespace>.ConsumedChargeArray (timestamp 1 700 000 000.25 s, circuits 1..15 with charge
circuit * 0.5 Ah) and one with no element, then (with ``--panic``) one uavcan.protocol.Panic with that reason_text,
printing ``PUBLISHED``. (tests/specs/lolo_v0.yaml has the same types under sabre.power, its array at vendor id
20100.) On SIGTERM or when ``--max-life`` runs out: ``SUMMARY {}``, exit 0.
"""

from __future__ import annotations

import argparse
import json
import sys

BOARD_ID = 30
USEC = 1_700_000_000_250_000


def main() -> int:
    p = argparse.ArgumentParser()
    p.add_argument("--generated", required=True)
    p.add_argument("--iface", required=True)
    p.add_argument("--start-file", required=True)
    p.add_argument("--max-life", type=float, default=120.0)
    p.add_argument("--namespace", default="power", help="the namespace of the spec's ConsumedCharge types")
    p.add_argument("--node-id", type=int, default=BOARD_ID)
    p.add_argument("--panic", help="also broadcast one Panic with this reason_text")
    args = p.parse_args()

    from plain_dronecan_node import loopback_node, serve, stop_on_sigterm, with_spec_types

    dronecan = with_spec_types(args.generated)
    array = dronecan.TYPENAMES[f"{args.namespace}.ConsumedChargeArray"]
    charge = dronecan.TYPENAMES[f"{args.namespace}.ConsumedCharge"]
    stamp = dronecan.TYPENAMES["uavcan.Timestamp"]
    node = loopback_node(args.iface, args.node_id)
    stop = stop_on_sigterm()
    decoded_as = dronecan.DATATYPES.get((array.default_dtid, array.kind))
    print("READY " + json.dumps({"data_type_id": array.default_dtid,
                                 "decoded_as": decoded_as.full_name if decoded_as is not None else None}), flush=True)

    def publish() -> None:
        node.broadcast(array(timestamp=stamp(usec=USEC),
                             charges=[charge(circuit_id=c, charge=c * 0.5) for c in range(1, 16)]))
        node.spin(0.01)
        node.broadcast(array(timestamp=stamp(usec=USEC + 1_000_000), charges=[]))
        if args.panic is not None:
            node.spin(0.01)
            node.broadcast(dronecan.uavcan.protocol.Panic(reason_text=args.panic.encode()))
        print("PUBLISHED", flush=True)

    serve(node, stop, args.max_life, args.start_file, publish)
    print("SUMMARY {}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
