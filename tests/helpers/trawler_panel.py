"""The trawler's switch panel (tests/specs/trawler_v0.yaml, node 30) in its own process: a plain ``dronecan`` node
that knows the spec's own types the way the runtime gives them to dronecan (sam_runtime.dronecan_io.types.ensure_types:
the namespaces the spec uses, its trawler.io.Switch at data type id 20100 instead of com.hobbywing.esc.RawCommand).

python trawler_panel.py --generated DIR --iface mcast-lo:<bus>:<port> --start-file F

Prints ``READY {...}`` with what dronecan decodes data type id 20100 as; once F exists, broadcasts Switch
(switch_id 1, level 100 k + 7, flags k) for k = 0..4, one Switch of switch_id 3 (no mapping selects it) and one Panic
("LEAK"), printing ``PUBLISHED``; records every Switch and Panic it receives (source, type name, values), each
also as a line ``GOT <type> <source> <values>``. On SIGTERM or when ``--max-life`` runs out: ``SUMMARY {...}``, exit 0.
"""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

PANEL_ID = 30


def main() -> int:
    p = argparse.ArgumentParser()
    p.add_argument("--generated", required=True)
    p.add_argument("--iface", required=True)
    p.add_argument("--start-file", required=True)
    p.add_argument("--max-life", type=float, default=120.0)
    args = p.parse_args()

    from plain_dronecan_node import loopback_node, serve, stop_on_sigterm, with_spec_types

    dronecan = with_spec_types(args.generated)
    switch = dronecan.TYPENAMES["trawler.io.Switch"]
    panic = dronecan.TYPENAMES["uavcan.protocol.Panic"]
    node = loopback_node(args.iface, PANEL_ID)
    stop = stop_on_sigterm()
    received: list[dict[str, Any]] = []

    def on_message(e: Any) -> None:
        t = dronecan.get_dronecan_data_type(e.message)
        if t.full_name == "trawler.io.Switch":
            values: dict[str, Any] = {"switch_id": int(e.message.switch_id), "level": int(e.message.level),
                                      "flags": int(e.message.flags)}
        elif t.full_name == "uavcan.protocol.Panic":
            values = {"reason_text": bytes(e.message.reason_text).decode(errors="replace")}
        else:
            return
        received.append({"source": e.transfer.source_node_id, "type": t.full_name, "data_type_id": t.default_dtid,
                         "values": values})
        print(f"GOT {t.full_name} {e.transfer.source_node_id} {json.dumps(values)}", flush=True)

    node.add_handler(None, on_message)
    decoded_as = dronecan.DATATYPES.get((20100, switch.kind))
    print("READY " + json.dumps({"node_id": PANEL_ID,
                                 "20100": decoded_as.full_name if decoded_as is not None else None}), flush=True)

    def publish() -> None:
        for k in range(5):
            node.broadcast(switch(switch_id=1, level=100 * k + 7, flags=k))
            node.spin(0.01)
        node.broadcast(switch(switch_id=3, level=5, flags=0))
        node.broadcast(panic(reason_text=b"LEAK"))
        print("PUBLISHED", flush=True)

    serve(node, stop, args.max_life, args.start_file, publish)
    print("SUMMARY " + json.dumps({"received": received}), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
