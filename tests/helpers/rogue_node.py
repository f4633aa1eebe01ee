"""A Cyphal node the spec does not know, publishing on the spec's subjects (for the static-routing tests).

python rogue_node.py --generated DIR --node-id 42 --publish 1100:20 --publish 1204:20 [--iface 127.0.0.1]
Publishes N messages of the subject's type (plausible generic values) at 50 Hz each over Cyphal/UDP, then
prints DONE {"1100": 20, ...} and exits.
"""

from __future__ import annotations

import argparse
import asyncio
import json
import sys
from pathlib import Path


async def run(args: argparse.Namespace) -> dict[str, int]:
    from sam_runtime.cyphal_io.transport import aclose, make_node
    from sam_runtime.genpkg import GeneratedPackage
    from sam_runtime.sim.simulator import generic_fill

    gen = GeneratedPackage(args.generated)
    gen.compile_dsdl()
    ports = {p.subject_id: p for d in gen.tables().DEVICES for p in (*d.publishes, *d.subscribes)}
    node = make_node("org.test.rogue", args.node_id, "udp", iface=args.iface)
    plan = []
    for item in args.publish:
        sid, n = (int(x) for x in item.split(":"))
        dtype = gen.dsdl_class(ports[sid])
        plan.append((sid, n, dtype, node.make_publisher(dtype, sid)))
    sent: dict[str, int] = {}
    try:
        for sid, n, dtype, pub in plan:
            sent[str(sid)] = 0
            for i in range(n):
                ok = await pub.publish(generic_fill(dtype(), i * 0.1, 1_000_000 + i))
                sent[str(sid)] += int(bool(ok))
                await asyncio.sleep(0.02)
    finally:
        await aclose(*(p for *_, p in plan))
        await aclose(node)
    return sent


def main() -> int:
    p = argparse.ArgumentParser()
    p.add_argument("--generated", type=Path, required=True)
    p.add_argument("--node-id", type=int, required=True)
    p.add_argument("--iface", default="127.0.0.1")
    p.add_argument("--publish", action="append", default=[], metavar="SUBJECT:COUNT")
    args = p.parse_args()
    sent = asyncio.run(run(args))
    print("DONE " + json.dumps(sent), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
