"""Everything in ONE process over a python-can CAN bus: simulated devices, the bridge, an rclpy probe node
(own context) and a rogue Cyphal node, for tests/test_bridge_can.py.

python can_scenario.py --iface virtual:bus1 --mtu 8 --rate-scale 0.25 --duration 4 --out OUT.json
    [--bridge-env]   (configure the bridge through UAVCAN__CAN__IFACE / UAVCAN__CAN__MTU instead of arguments)
    [--wire object]  (the bridge's object converters instead of the generated wire codecs)
Writes OUT.json: counts, the bridge's stats, the sim's report, sent/received value pairs, parameter checks.
"""

from __future__ import annotations

import os

os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")

import argparse
import asyncio
import json
import math
import sys
import time
from collections import defaultdict
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(1, str(Path(__file__).resolve().parents[1]))  # runtime_support imports helpers.*
from ros_probe import ThreadedProbe, to_plain
from runtime_support import command_plan

ROGUE_NODE_ID = 42
ROGUE_COUNT = 10


async def wait_for(cond: Any, timeout: float, what: str) -> None:
    deadline = time.monotonic() + timeout
    while not cond():
        if time.monotonic() > deadline:
            raise TimeoutError(f"timed out after {timeout} s waiting for {what}")
        await asyncio.sleep(0.02)


class Probe(ThreadedProbe):
    """Records the bridged topics as plain values, publishes commands."""

    node_name = "test_can_probe"

    def setup(self) -> None:
        self.received: defaultdict[str, list[Any]] = defaultdict(list)

    def on_message(self, topic: str, msg: Any) -> None:
        self.received[topic].append(to_plain(msg))


def check_parameters(bridge: Any) -> dict[str, Any]:
    """The bridge's ROS parameters: declared from the spec with ranges; rules enforced."""
    from rclpy.parameter import Parameter

    from sam_runtime.node_support import ros_parameter_name

    node = bridge.ros.node
    out: dict[str, Any] = {"declared": {}, "sets": []}
    for p in bridge.tables.PARAMETERS:
        name = ros_parameter_name(p.name)
        desc = node.describe_parameter(name)
        rng = desc.floating_point_range[0] if desc.floating_point_range else None
        out["declared"][name] = {
            "value": node.get_parameter(name).value,
            "range": None if rng is None else [rng.from_value, rng.to_value],
            "spec": [p.default, p.minimum, p.maximum],
        }

    def try_set(name: str, value: float) -> None:
        res = node.set_parameters([Parameter(name, value=value)])[0]
        out["sets"].append({"name": name, "value": value, "ok": res.successful, "reason": res.reason,
                            "now": node.get_parameter(name).value})

    if {"safe_depth", "critical_depth"} <= set(out["declared"]):
        try_set("critical_depth", 40.0)  # below safe_depth (50): breaks critical_depth > safe_depth
        try_set("safe_depth", 500.0)  # beyond the range [0, 200]
        try_set("safe_depth", 45.0)  # fine
        try_set("critical_depth", 46.0)  # fine now
    return out


async def main(args: argparse.Namespace) -> dict[str, Any]:
    from sam_runtime.bridge import Bridge, TransportConfig
    from sam_runtime.cyphal_io.transport import aclose, make_node
    from sam_runtime.genpkg import GeneratedPackage
    from sam_runtime.sim.simulator import SimConfig, Simulator, generic_fill

    gen = GeneratedPackage()
    gen.compile_dsdl()
    tables = gen.tables()
    if args.bridge_env:
        env = {"UAVCAN__CAN__IFACE": args.iface, "UAVCAN__CAN__MTU": str(args.mtu)}
        tcfg = TransportConfig("env", environ=env)
    else:
        tcfg = TransportConfig("can", args.iface, args.mtu)
    bridge = Bridge(gen, transport=tcfg, wire=args.wire)
    await bridge.start()
    record = Path(args.out).with_suffix(".sim.jsonl")
    # The devices' own clocks follow the bridge's time-sync master: on this shared, loaded loop the master takes
    # its transmission times from python-can's transmit thread (sam_runtime.cyphal_io.can_tx_times), not from its
    # held-up send calls
    sim = Simulator(gen, SimConfig("can", args.iface, args.mtu, rate_scale=args.rate_scale, record=record))
    await sim.start()
    in_maps = [m for m in tables.MAPPINGS if m.direction == "uavcan_to_ros"]
    in_topics = sorted({m.topic.name for m in in_maps})
    out_topics = sorted({m.topic.name for m in tables.MAPPINGS if m.direction == "ros_to_uavcan"})
    probe = Probe(gen, in_topics, out_topics)
    result: dict[str, Any] = {"iface": args.iface, "mtu": args.mtu, "rate_scale": args.rate_scale,
                              "wire": bridge.wire}
    rogue = None
    try:
        # Discovery both ways, polled: the probe sees the bridge's publishers and the bridge sees the probe.
        await wait_for(lambda: all(probe.node.count_publishers(t) > 0 for t in in_topics)
                       and all((bridge.stats()["mappings"][m.name].get("ros_subscribers") or 0) > 0 for m in in_maps)
                       and all(p.get_subscription_count() > 0 for p in probe.pubs.values()), 20, "ROS discovery")
        await wait_for(lambda: all(d["seen"] for d in bridge.stats()["devices"].values()), 10, "heartbeats")
        result["devices"] = bridge.stats()["devices"]
        result["parameters"] = check_parameters(bridge)

        # the devices' clocks follow the bridge's (its time-sync master): every stamp is a device's own
        await wait_for(lambda: sim.synchronised, 20, "the devices' clocks synchronised")
        result["time_sync_master"] = bridge.stats()["time_sync"]["master"]
        plan = command_plan(tables, args.commands)
        t0 = time.monotonic()
        sim.start_publishing(duration=args.duration)
        n = max((len(v) for v in plan.values()), default=0)
        for i in range(n):  # commands at 10 Hz while the sensors run
            for t, items in plan.items():
                if i < len(items):
                    probe.publish(t, items[i])
            await asyncio.sleep(max(0.0, t0 + (i + 1) * 0.1 - time.monotonic()))
        await sim.wait_publishing_done()
        report = sim.report()
        sent = {str(sid): c for d in report["devices"].values() for sid, c in d["published"].items()}
        expected = {t: sum(sent.get(str(m.port.subject_id), 0) for m in in_maps if m.topic.name == t)
                    for t in in_topics}
        expected_cmds = {str(m.port.subject_id): len(plan.get(m.topic.name, [])) for m in tables.MAPPINGS
                         if m.direction == "ros_to_uavcan"}

        def commands_in() -> dict[str, int]:
            return {sid: c["accepted"] for d in sim.report()["devices"].values() for sid, c in d["commands"].items()}

        await wait_for(lambda: all(len(probe.received[t]) >= expected[t] for t in in_topics)
                       and all(commands_in().get(s, 0) >= c for s, c in expected_cmds.items()), 20,
                       "every message on its way")
        result["elapsed_s"] = time.monotonic() - t0

        # A node the spec does not know, on the same bus: its sensor data and its commands are not bridged.
        rogue = make_node("org.test.rogue", ROGUE_NODE_ID, "can", iface=args.iface, mtu=args.mtu)
        imu_map = next(m for m in in_maps if m.topic.name == "/imu")
        cmd_map = next(m for m in tables.MAPPINGS if m.direction == "ros_to_uavcan")
        pubs = [(rogue.make_publisher(gen.dsdl_class(m.port), m.port.subject_id), gen.dsdl_class(m.port))
                for m in (imu_map, cmd_map)]
        for i in range(ROGUE_COUNT):
            for pub, dtype in pubs:
                await pub.publish(generic_fill(dtype(), 0.1 * i, 1_000_000 + i))
        await wait_for(lambda: bridge.stats()["mappings"][imu_map.name]["dropped"].get("unknown_source", 0)
                       >= ROGUE_COUNT, 10, "the rogue's drops")
        await wait_for(lambda: sum(c["rejected"] for d in sim.report()["devices"].values()
                                   for c in d["commands"].values()) >= ROGUE_COUNT, 10, "the rogue's commands")
        await aclose(*(p for p, _ in pubs))
        await aclose(rogue)
        rogue = None

        result.update({
            "expected": expected,
            "received_counts": {t: len(v) for t, v in probe.received.items()},
            "received": {t: v for t, v in probe.received.items()},
            "bridge": bridge.stats(),
            "sim": sim.report(),
            "plan": plan,
            "rogue": {"node_id": ROGUE_NODE_ID, "count": ROGUE_COUNT, "imu_mapping": imu_map.name,
                      "command_subject": cmd_map.port.subject_id},
        })
    finally:
        if rogue is not None:
            await aclose(rogue)
        probe.close()
        await sim.close()
        await bridge.close()
    return result


def _clean(o: Any) -> Any:
    if isinstance(o, float) and not math.isfinite(o):
        return repr(o)
    if isinstance(o, dict):
        return {str(k): _clean(v) for k, v in o.items()}
    if isinstance(o, list | tuple):
        return [_clean(x) for x in o]
    return o


if __name__ == "__main__":
    p = argparse.ArgumentParser()
    p.add_argument("--iface", required=True)
    p.add_argument("--mtu", type=int, required=True)
    p.add_argument("--rate-scale", type=float, default=1.0)
    p.add_argument("--duration", type=float, default=3.0)
    p.add_argument("--commands", type=int, default=20)
    p.add_argument("--bridge-env", action="store_true")
    p.add_argument("--wire", choices=("codec", "object"), default="codec")
    p.add_argument("--out", type=Path, required=True)
    a = p.parse_args()
    res = asyncio.run(main(a))
    a.out.write_text(json.dumps(_clean(res), default=str))
    print("DONE", flush=True)
