"""A battery management system on DroneCAN in its own process, written against the plain dronecan API: it serves
the vendor v0 service ``<root>.power.UpdateBattery`` of a generated folder (tests/specs/auv_services.yaml, id 201)
and answers each request by its ``command``:

- 1 (or anything not below): at once, ``success = command``;
- 2: never (the caller's timeout);
- 3: twice (a duplicate response);
- 4: ``--late`` seconds later (after the bridge's timeout: a late response);
- 5: a malformed response (a single frame with an empty payload, which dronecan cannot decode);

and the node duties: GetNodeInfo (dronecan's own answer, name ``org.lolo.bms``), RestartNode (``ok`` when the
magic number is right; prints ``RESTART``) and GetTransportStats (11 sent, 22 received, 3 errors).

python battery_peer.py --iface mcast-lo:<bus>:<port> --node-id 30 --generated <generated> [--late 1.5]

Prints ``READY`` when the node is up, ``REQUEST {json}`` for every request and ``ANSWERED {json}`` for every
response sent, and exits on SIGTERM or SIGINT (the test's way to stop it) or when ``--max-life`` runs out.
"""

from __future__ import annotations

import argparse
import json
import signal
import sys
import threading
import time
from pathlib import Path
from types import SimpleNamespace
from typing import Any

NEVER, TWICE, LATE, MALFORMED = 2, 3, 4, 5


def main() -> int:
    p = argparse.ArgumentParser()
    p.add_argument("--iface", required=True)
    p.add_argument("--node-id", type=int, required=True)
    p.add_argument("--generated", required=True)
    p.add_argument("--type", default="lolo.power.UpdateBattery")
    p.add_argument("--late", type=float, default=1.5)
    p.add_argument("--max-life", type=float, default=180.0)
    args = p.parse_args()

    import dronecan
    from dronecan.driver.common import CANFrame  # noqa: F401  (the driver's frame type: imported with dronecan)

    from sam_runtime.dronecan_io import LoopbackMulticastDriver, parse_iface

    root = args.type.split(".")[0]
    dronecan.load_dsdl(str(Path(args.generated) / "dsdl_v0" / root))
    dtype = dronecan.TYPENAMES[args.type]
    spec = parse_iface(args.iface)
    info = dronecan.uavcan.protocol.GetNodeInfo.Response()
    info.name = "org.lolo.bms"
    node = dronecan.node.Node(LoopbackMulticastDriver(spec.bus, spec.port), node_id=args.node_id, node_info=info,
                              node_status_interval=0.5, mode=0)
    lock = threading.Lock()

    def say(kind: str, **fields: Any) -> None:
        with lock:
            print(kind, json.dumps(fields), flush=True)

    def respond(event: Any, success: int) -> None:
        response = dtype.Response()
        response.success = success
        t = event.transfer
        node.respond(response, t.source_node_id, t.transfer_id, t.transfer_priority)
        say("ANSWERED", transfer_id=int(t.transfer_id), success=success)

    def malformed(event: Any) -> None:
        t = event.transfer
        # a v0 service frame: priority, type id, response (bit 15 clear), destination, service bit, source
        can_id = (t.transfer_priority << 24) | (dtype.default_dtid << 16) | (t.source_node_id << 8) | 0x80 \
            | args.node_id
        node.can_driver.send(can_id, bytes([0xC0 | int(t.transfer_id)]), extended=True)
        say("ANSWERED", transfer_id=int(t.transfer_id), malformed=True)

    def on_request(event: Any) -> None:
        command, charge = int(event.request.command), float(event.request.charge)
        say("REQUEST", source=int(event.transfer.source_node_id), transfer_id=int(event.transfer.transfer_id),
            command=command, charge=charge)
        if command == NEVER:
            return
        if command == TWICE:
            respond(event, command)
            node.defer(0.05, lambda: respond(event, command))
        elif command == LATE:
            node.defer(args.late, lambda: respond(event, command))
        elif command == MALFORMED:
            malformed(event)
        else:
            respond(event, min(command, 255))

    protocol = dronecan.uavcan.protocol

    def on_duty(transfer: Any) -> None:
        """RestartNode (ok when the magic number is right; the node does not really restart) and
        GetTransportStats (fixed figures); dronecan answers GetNodeInfo itself."""
        if transfer.data_type_id == protocol.RestartNode.default_dtid:
            ok = int(transfer.payload.magic_number) == protocol.RestartNode.Request().MAGIC_NUMBER
            say("RESTART", ok=ok)
            response: Any = protocol.RestartNode.Response(ok=ok)
        else:
            response = protocol.GetTransportStats.Response(transfers_tx=11, transfers_rx=22, transfer_errors=3)
        node.respond(response, transfer.source_node_id, transfer.transfer_id, transfer.transfer_priority)

    duties = {protocol.RestartNode.default_dtid, protocol.GetTransportStats.default_dtid}

    def hook(transfer: Any) -> None:
        # Requests are taken here, not by a dronecan handler, which must answer each request at once.
        if not (getattr(transfer, "direction", "") == "rx" and transfer.service_not_message
                and transfer.request_not_response and transfer.dest_node_id == args.node_id):
            return
        if transfer.data_type_id == dtype.default_dtid:
            on_request(SimpleNamespace(request=transfer.payload, transfer=transfer))
        elif transfer.data_type_id in duties:
            on_duty(transfer)

    node.add_transfer_hook(hook)
    stop = threading.Event()
    for sig in (signal.SIGTERM, signal.SIGINT):
        signal.signal(sig, lambda *_: stop.set())
    say("READY", node_id=args.node_id)
    deadline = time.monotonic() + args.max_life
    while not stop.is_set() and time.monotonic() < deadline:
        try:
            node.spin(0.05)
        except Exception as ex:  # a bad frame on the shared test bus: keep serving
            say("ERROR", error=f"{type(ex).__name__}: {ex}")
    node.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
