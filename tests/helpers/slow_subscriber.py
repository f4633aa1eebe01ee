"""A slow ROS subscriber in its own process, for tests/test_faults.py: subscribes to a sensor_msgs/Imu topic
(reliable, keep-last DEPTH) and sleeps SLEEP seconds in every callback.

python slow_subscriber.py --topic /imu --sleep 0.1 --depth 10 --out OUT.json
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
    p.add_argument("--discovery-timeout", type=float, default=20.0)
    args = p.parse_args()

    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.node import Node
    from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy
    from sensor_msgs.msg import Imu

    rclpy.init(args=[])
    node = Node("test_slow_subscriber")
    state = {"received": 0, "slept_s": 0.0}

    def cb(msg: Imu) -> None:
        state["received"] += 1
        time.sleep(args.sleep)
        state["slept_s"] += args.sleep

    qos = QoSProfile(depth=args.depth, history=HistoryPolicy.KEEP_LAST, reliability=ReliabilityPolicy.RELIABLE)
    node.create_subscription(Imu, args.topic, cb, qos)
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
