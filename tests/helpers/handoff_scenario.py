"""The bridge's ROS -> UAVCAN hand-off and receive stamps end to end, in ONE process on a python-can ``virtual``
CAN FD bus, for tests/test_bridge_handoff.py: the bridge, an rclpy probe node (own context) and pycyphal nodes
for the IMU device and the thrust vector actuator.

python handoff_scenario.py --iface virtual:bus1 --out OUT.json
Writes OUT.json:
- ``paced``: commands on /thruster_angles in chunks no larger than the bridge's queue, each chunk delivered
  before the next: the sequence numbers at the actuator and the mapping's counters;
- ``burst``: then one burst of commands beyond the queue as fast as the probe publishes;
- ``stamps``: the header.stamp of /imu for a RawIMU with timestamp 0 (unknown) under the system clock, under
  use_sim_time with a /clock message, and under the system clock again, with the times around each.
"""

from __future__ import annotations

import os

os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")

import argparse
import asyncio
import json
import struct
import sys
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))
from ros_probe import ThreadedProbe

QUEUE_SIZE = 32
PACED_CHUNKS, CHUNK = 8, 20
BURST = 400
SIM_CLOCK_NS = 1_234_000_000_000 + 5678


# A sequence number (below 2048**2) travels in the thrust vector's two float16 angles: each half as a float16
# normal's bit pattern 0x0400 + half (2**-14 .. 0.00025 rad), exact in float16, float32 and float64 and well inside
# the spec's limits (+-0.12 rad, which saturate anything larger).
def seq_angles(seq: int) -> tuple[float, float]:
    """The two angles of ``seq``.

    >>> [angles_seq(*seq_angles(s)) for s in (0, 1, 2047, 2048, 2048 * 2048 - 1)], max(seq_angles(2048 * 2048 - 1))
    ([0, 1, 2047, 2048, 4194303], 0.00024402141571044922)
    """
    hi, lo = divmod(seq, 2048)
    return (struct.unpack("<e", struct.pack("<H", 0x0400 + hi))[0],
            struct.unpack("<e", struct.pack("<H", 0x0400 + lo))[0])


def angles_seq(vertical: float, horizontal: float) -> int:
    """The sequence number of :func:`seq_angles`' two angles."""
    def half(x: float) -> int:
        return int(struct.unpack("<H", struct.pack("<e", float(x)))[0]) - 0x0400

    return half(vertical) * 2048 + half(horizontal)


class Probe(ThreadedProbe):
    node_name = "test_handoff_probe"

    def setup(self) -> None:
        from rosgraph_msgs.msg import Clock

        self.imu: list[Any] = []
        self.clock_pub = self.node.create_publisher(Clock, "/clock", 10)

    def on_message(self, topic: str, msg: Any) -> None:
        self.imu.append(msg)


async def wait_for(cond: Any, timeout: float, what: str) -> None:
    deadline = time.monotonic() + timeout
    while not cond():
        if time.monotonic() > deadline:
            raise TimeoutError(f"timed out after {timeout} s waiting for {what}")
        await asyncio.sleep(0.01)


async def main(args: argparse.Namespace) -> dict[str, Any]:
    from rclpy.parameter import Parameter

    from sam_runtime.bridge import Bridge, TransportConfig
    from sam_runtime.cyphal_io.transport import aclose, make_node
    from sam_runtime.genpkg import GeneratedPackage
    from sam_runtime.sim.simulator import generic_fill

    gen = GeneratedPackage()
    gen.compile_dsdl()
    tables = gen.tables()
    cmd_map = next(m for m in tables.MAPPINGS if m.topic.name == "/thruster_angles")
    imu_map = next(m for m in tables.MAPPINGS if m.topic.name == "/imu")
    bridge = Bridge(gen, transport=TransportConfig("can", args.iface, 64), queue_size=QUEUE_SIZE, qos_depth=1000)
    await bridge.start()
    nodes = [make_node("org.test.actuator", cmd_map.destination_node_id, "can", iface=args.iface, mtu=64),
             make_node("org.test.imu", next(iter(imu_map.source_node_ids)), "can", iface=args.iface, mtu=64)]
    at_actuator: list[int] = []

    def on_cmd(msg: Any, transfer: Any) -> None:
        at_actuator.append(angles_seq(msg.vertical_radians, msg.horizontal_radians))

    cmd_sub = nodes[0].make_subscriber(gen.dsdl_class(cmd_map.port), cmd_map.port.subject_id)
    cmd_sub.receive_in_background(on_cmd)
    imu_cls = gen.dsdl_class(imu_map.port)
    imu_pub = nodes[1].make_publisher(imu_cls, imu_map.port.subject_id)
    probe = Probe(gen, ["/imu"], ["/thruster_angles"])
    result: dict[str, Any] = {"queue_size": QUEUE_SIZE}

    def stats() -> dict[str, Any]:
        return bridge.stats()["mappings"][cmd_map.name]

    def settled() -> bool:
        s = stats()
        return s["published"] + s["dropped_total"] == s["received"] and len(at_actuator) == s["published"]

    seq = 0

    def command() -> None:
        nonlocal seq
        vertical, horizontal = seq_angles(seq)
        probe.publish("/thruster_angles", {"thruster_vertical_radians": vertical,
                                           "thruster_horizontal_radians": horizontal})
        seq += 1

    try:
        await wait_for(lambda: probe.node.count_publishers("/imu") > 0
                       and probe.pubs["/thruster_angles"].get_subscription_count() > 0, 20, "ROS discovery")

        for _ in range(PACED_CHUNKS):
            for _ in range(CHUNK):
                command()
            await wait_for(lambda: len(at_actuator) >= seq, 10, "a chunk at the actuator")
        await wait_for(settled, 10, "the paced commands settled")
        result["paced"] = {"sent": seq, "at_actuator": list(at_actuator), "stats": stats()}

        paced = len(at_actuator)
        for _ in range(BURST):
            command()
        await wait_for(lambda: stats()["received"] >= seq, 20, "the burst at the bridge")
        await wait_for(settled, 20, "the burst settled")
        await asyncio.sleep(0.2)
        result["burst"] = {"sent": BURST, "at_actuator": at_actuator[paced:], "stats": stats()}

        async def stamp(phase: str) -> dict[str, Any]:
            n = len(probe.imu)
            before = time.time_ns()
            await imu_pub.publish(generic_fill(imu_cls(), 0.5, 0))  # timestamp 0: unknown
            await wait_for(lambda: len(probe.imu) > n, 10, f"/imu ({phase})")
            after = time.time_ns()
            st = probe.imu[n].header.stamp
            return {"stamp_ns": st.sec * 1_000_000_000 + st.nanosec, "before_ns": before, "after_ns": after,
                    "ros_time_active": bridge.ros.ros_time_active}

        stamps = {"system": await stamp("system")}
        res = bridge.ros.node.set_parameters([Parameter("use_sim_time", value=True)])[0]
        assert res.successful, res.reason
        from rosgraph_msgs.msg import Clock

        clock = Clock()
        clock.clock.sec, clock.clock.nanosec = divmod(SIM_CLOCK_NS, 1_000_000_000)
        await wait_for(lambda: probe.clock_pub.get_subscription_count() > 0, 20, "the bridge's /clock subscription")

        def on_clock() -> bool:
            probe.clock_pub.publish(clock)  # again until it is there (the /clock subscription may be best effort)
            return bool(bridge.ros.clock.now().nanoseconds == SIM_CLOCK_NS)

        await wait_for(on_clock, 10, "the bridge on /clock")
        stamps["sim"] = await stamp("sim") | {"clock_ns": SIM_CLOCK_NS}
        res = bridge.ros.node.set_parameters([Parameter("use_sim_time", value=False)])[0]
        assert res.successful, res.reason
        stamps["system_again"] = await stamp("system again")
        result["stamps"] = stamps
    finally:
        probe.close()
        await bridge.close()
        await aclose(cmd_sub, imu_pub, *nodes)
    return result


if __name__ == "__main__":
    p = argparse.ArgumentParser()
    p.add_argument("--iface", required=True)
    p.add_argument("--out", type=Path, required=True)
    a = p.parse_args()
    res = asyncio.run(main(a))
    a.out.write_text(json.dumps(res, default=str))
    print("DONE", flush=True)
