"""A slow ROS subscriber in its own process, for tests/test_faults.py: subscribes to a bridged topic with the
spec's subscribers' QoS (reliability and durability of the generated tables' subscriber side, as any ROS node of
the vehicle would; keep-last DEPTH) and sleeps SLEEP seconds in every callback.

python slow_subscriber.py --topic /imu --sleep 0.1 --depth 10 --out OUT.json   (SAM_GENERATED_DIR or --generated)
Prints READY once the topic has a publisher, then ``COUNT n`` (messages received so far) every 0.2 s; writes
OUT.json ({"received": n, "slept_s": s}) at SIGTERM.
"""

from __future__ import annotations

import os

os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")

import argparse
import json
import signal
import sys
import time
from pathlib import Path


def main() -> int:
    p = argparse.ArgumentParser()
    p.add_argument("--topic", default="/imu")
    p.add_argument("--sleep", type=float, default=0.1)
    p.add_argument("--depth", type=int, default=10)
    p.add_argument("--out", type=Path, required=True)
    p.add_argument("--generated", type=Path, default=None, help="default: SAM_GENERATED_DIR or the project's")
    p.add_argument("--discovery-timeout", type=float, default=20.0)
    args = p.parse_args()

    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.node import Node

    from sam_runtime.genpkg import GeneratedPackage
    from sam_runtime.node_support import qos_profile

    gen = GeneratedPackage() if args.generated is None else GeneratedPackage(args.generated)
    topic = next((m.topic for m in gen.tables().MAPPINGS if m.topic.name == args.topic), None)
    if topic is None:
        raise SystemExit(f"{args.topic} is no bridged topic of the generated tables")
    rclpy.init(args=[])
    node = Node("test_slow_subscriber")
    state = {"received": 0, "slept_s": 0.0}

    def cb(msg: object) -> None:
        state["received"] += 1
        time.sleep(args.sleep)
        state["slept_s"] += args.sleep

    node.create_subscription(gen.ros_class(topic), args.topic, cb,
                             qos_profile(topic.subscriber_qos.reliability, topic.subscriber_qos.durability,
                                         args.depth))
    stop: list[int] = []
    signal.signal(signal.SIGTERM, lambda *_: stop.append(1))
    signal.signal(signal.SIGINT, lambda *_: stop.append(1))
    ex = SingleThreadedExecutor()
    ex.add_node(node)

    def write() -> None:
        tmp = args.out.with_name(args.out.name + ".tmp")
        tmp.write_text(json.dumps(state))
        os.replace(tmp, args.out)

    deadline = time.monotonic() + args.discovery_timeout
    while not stop and node.count_publishers(args.topic) == 0:
        if time.monotonic() > deadline:
            print("TIMEOUT", flush=True)
            return 1
        ex.spin_once(timeout_sec=0.05)
    print("READY", flush=True)
    next_report = 0.0
    while not stop:
        ex.spin_once(timeout_sec=0.05)
        if time.monotonic() >= next_report:
            print(f"COUNT {state['received']}", flush=True)
            next_report = time.monotonic() + 0.2
    write()
    node.destroy_node()
    rclpy.shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
