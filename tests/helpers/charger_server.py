"""A Cyphal charger serving the spec's service ran.power.SetChargeLimits.1.0 (tests/specs/auv_cyphal_services.yaml,
service id 200) over Cyphal/UDP, with pycyphal only (no part of the bridge); as a pycyphal application node it also
answers the standard uavcan.node.GetInfo.1.0 (its name: org.ran.charger).

python charger_server.py --generated DIR --node-id 31 --service-id 200 --late 1.5 [--iface 127.0.0.1]

Each request is printed as REQUEST {"low_percent": .., "high_percent": ..}. It accepts limits with low < high
(reason "ok"), else refuses them (reason "low >= high"); a request with low_percent 0 is answered only after
``--late`` seconds (after the bridge's timeout: a late response). Prints READY once it serves.
"""

from __future__ import annotations

import argparse
import asyncio
import json
import sys
from pathlib import Path
from typing import Any


async def run(args: argparse.Namespace) -> None:
    from sam_runtime.bridge.backends.cyphal_services import dsdl_class
    from sam_runtime.cyphal_io.transport import aclose, make_node
    from sam_runtime.genpkg import GeneratedPackage

    GeneratedPackage(args.generated).compile_dsdl()
    dtype = dsdl_class("ran.power.SetChargeLimits.1.0")
    node = make_node("org.ran.charger", args.node_id, "udp", iface=args.iface)
    server = node.presentation.get_server(dtype, args.service_id)

    async def handle(request: Any, _meta: Any) -> Any:
        low, high = int(request.low_percent), int(request.high_percent)
        print("REQUEST " + json.dumps({"low_percent": low, "high_percent": high}), flush=True)
        if low == 0:
            await asyncio.sleep(args.late)
        ok = low < high
        return dtype.Response(accepted=ok, reason=(b"ok" if ok else b"low >= high"))

    server.send_timeout = args.late + 5.0  # (the late answer must still go out)
    server.serve_in_background(handle)
    print("READY", flush=True)
    try:
        await asyncio.Event().wait()
    finally:
        await aclose(server)
        await aclose(node)


def main() -> int:
    p = argparse.ArgumentParser()
    p.add_argument("--generated", type=Path, required=True)
    p.add_argument("--node-id", type=int, default=31)
    p.add_argument("--service-id", type=int, default=200)
    p.add_argument("--late", type=float, default=1.5)
    p.add_argument("--iface", default="127.0.0.1")
    args = p.parse_args()
    try:
        asyncio.run(run(args))
    except KeyboardInterrupt:
        pass
    return 0


if __name__ == "__main__":
    sys.exit(main())
