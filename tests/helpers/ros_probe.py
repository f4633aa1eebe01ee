"""A separate rclpy process for the bridge tests: listens to topics or publishes commands.

listen:  python ros_probe.py listen --generated DIR --topics /imu,/pressure --out OUT.json [--record REC.jsonl]
    Subscribes (the spec's QoS, deep history) to the topics with the generated package's types, prints READY once
    every topic has a publisher, records every message as a JSON line (topic, receive wall time, fields) and
    rewrites OUT.json ({"counts": {topic: n}}) every 0.2 s and at exit (SIGTERM/SIGINT).
publish: python ros_probe.py publish --generated DIR --plan PLAN.json --out OUT.json
    PLAN.json: {"rate_hz": 20, "topics": {"/thruster_rpms": [{"thruster_1_rpm": 5, ...}, ...], ...}}. Waits
    until every topic has a subscriber (the bridge), publishes the messages in order, interleaved across
    topics, writes {"sent": {topic: n}} and exits.
"""

from __future__ import annotations

import os

os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")

import argparse
import importlib
import json
import math
import signal
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

PROBE_DEPTH = 1000


def topic_qos(topic: Any, depth: int = PROBE_DEPTH) -> Any:
    """The spec's QoS of a topic (reliability and durability, so that the probe matches the bridge's endpoints:
    a reliable probe gets nothing from a best-effort publisher) with a deep keep-last history, so that a probe
    that falls behind for a while loses nothing."""
    from sam_runtime.node_support import qos_profile

    q = topic.qos
    return qos_profile(q.reliability, q.durability, max(depth, q.depth))


def to_plain(msg: Any) -> Any:
    """A ROS message as JSON-able nested dicts/lists."""
    if hasattr(msg, "get_fields_and_field_types"):
        return {name: to_plain(getattr(msg, name)) for name in msg.get_fields_and_field_types()}
    if isinstance(msg, bytes | bytearray):
        return list(msg)
    if hasattr(msg, "tolist"):
        return msg.tolist()
    if isinstance(msg, list | tuple):
        return [to_plain(x) for x in msg]
    if isinstance(msg, float) and not math.isfinite(msg):
        return repr(msg)  # "nan", "inf": JSON has no such numbers
    return msg


class SpunNode:
    """An rclpy node in a context of its own (and a domain of its own, if given), spun by a daemon thread from
    `start_spinning` (called once its subscriptions exist) until `close`: the base of the tests' in-process probes."""

    def __init__(self, node_name: str, domain: int | None = None) -> None:
        import rclpy
        from rclpy.node import Node
        from rclpy.signals import SignalHandlerOptions

        self.ctx = rclpy.Context()
        domain_arg = {} if domain is None else {"domain_id": domain}
        rclpy.init(args=[], context=self.ctx, signal_handler_options=SignalHandlerOptions.NO, **domain_arg)
        self.node = Node(node_name, context=self.ctx)

    def start_spinning(self, thread_name: str | None = None) -> None:
        import threading

        from rclpy.executors import SingleThreadedExecutor

        self.ex = SingleThreadedExecutor(context=self.ctx)
        self.ex.add_node(self.node)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._spin, name=thread_name, daemon=True)
        self._thread.start()

    def _spin(self) -> None:
        while not self._stop.is_set():
            self.ex.spin_once(timeout_sec=0.05)

    def call_duty(self, service: str, srv_name: str, node_id: int, timeout: float = 10.0,
                  package: str = "sam_msgs") -> Any:
        """One call of a node duty service (`srv_name` of `package`, its request the node id) from another thread
        than the spinning one: the response, or None if it did not come within `timeout`."""
        srv = getattr(importlib.import_module(f"{package}.srv"), srv_name)
        client = self.node.create_client(srv, service)
        if not client.wait_for_service(timeout_sec=timeout):
            raise AssertionError(f"no service {service}")
        future = client.call_async(srv.Request(node_id=node_id))
        deadline = time.monotonic() + timeout
        while not future.done() and time.monotonic() < deadline:
            time.sleep(0.02)
        return future.result()

    def close(self, join_timeout_s: float = 5.0) -> None:
        self._stop.set()
        self._thread.join(timeout=join_timeout_s)
        self.ex.shutdown(timeout_sec=1.0)
        self.node.destroy_node()
        self.ctx.shutdown()


class ThreadedProbe(SpunNode):
    """A SpunNode that subscribes to bridged topics (each message goes to ``on_message``) and publishes commands;
    the in-process scenarios extend it."""

    node_name = "test_probe"

    def __init__(self, gen: Any, in_topics: list[str], out_topics: list[str], depth: int = 1000) -> None:
        info = {m.topic.name: m.topic for m in gen.tables().MAPPINGS}
        super().__init__(self.node_name)
        self.setup()
        for t in in_topics:
            self.node.create_subscription(gen.ros_class(info[t]), t, lambda msg, t=t: self.on_message(t, msg),
                                          topic_qos(info[t], depth))
        self.classes = {t: gen.ros_class(info[t]) for t in out_topics}
        self.pubs = {t: self.node.create_publisher(self.classes[t], t, topic_qos(info[t], depth)) for t in out_topics}
        self.start_spinning()

    def setup(self) -> None:
        """Extra state and subscriptions, before the topics are subscribed."""

    def on_message(self, topic: str, msg: Any) -> None:
        raise NotImplementedError

    def publish(self, topic: str, values: dict[str, Any]) -> None:
        msg = self.classes[topic]()
        for k, v in values.items():
            setattr(msg, k, v)
        self.pubs[topic].publish(msg)


class DroneCanTopics:
    """A generated package as ThreadedProbe reads it, with the DroneCAN mappings' topics (it reads MAPPINGS)."""

    def __init__(self, gen: Any) -> None:
        self.gen = gen

    def tables(self) -> Any:
        from types import SimpleNamespace

        return SimpleNamespace(MAPPINGS=self.gen.tables().DRONECAN_MAPPINGS)

    def ros_class(self, topic: Any) -> Any:
        return self.gen.ros_class(topic)


def _tables_and_classes(generated: Path, topics: list[str]) -> tuple[dict[str, type], dict[str, Any]]:
    """The message class and the spec's QoS (deep history) of each topic."""
    from sam_runtime.genpkg import GeneratedPackage

    gen = GeneratedPackage(generated)
    tables = gen.tables()
    by_topic = {m.topic.name: m.topic for m in [*tables.MAPPINGS, *getattr(tables, "DRONECAN_MAPPINGS", ())]}
    missing = [t for t in topics if t not in by_topic]
    if missing:
        raise SystemExit(f"topics not in the generated tables: {missing}")
    return {t: gen.ros_class(by_topic[t]) for t in topics}, {t: topic_qos(by_topic[t]) for t in topics}


def _write(path: Path, data: Any) -> None:
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(json.dumps(data))
    os.replace(tmp, path)


def listen(args: argparse.Namespace) -> int:
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.node import Node

    topics = [t for t in args.topics.split(",") if t]
    classes, qos = _tables_and_classes(args.generated, topics)
    rclpy.init(args=[])
    node = Node("test_probe_listener")
    counts = dict.fromkeys(topics, 0)
    rec = open(args.record, "w", buffering=1 << 16) if args.record else None

    def make_cb(topic: str) -> Any:
        def cb(msg: Any) -> None:
            counts[topic] += 1
            if rec is not None:
                rec.write(json.dumps({"topic": topic, "wall_ns": time.time_ns(), "msg": to_plain(msg)}) + "\n")
        return cb

    subs = {t: node.create_subscription(classes[t], t, make_cb(t), qos[t]) for t in topics}
    diagnostics: dict[str, Any] = {}
    if args.diagnostics:
        from diagnostic_msgs.msg import DiagnosticArray

        def on_diag(arr: Any) -> None:
            for st in arr.status:
                diagnostics[st.name] = {"level": st.level[0] if isinstance(st.level, bytes) else int(st.level),
                                        "message": st.message, "values": {kv.key: kv.value for kv in st.values}}

        subs["/diagnostics"] = node.create_subscription(DiagnosticArray, "/diagnostics", on_diag, 10)
    stop = []
    signal.signal(signal.SIGTERM, lambda *_: stop.append(1))
    signal.signal(signal.SIGINT, lambda *_: stop.append(1))
    ex = SingleThreadedExecutor()
    ex.add_node(node)
    ready = False
    deadline = time.monotonic() + args.discovery_timeout
    next_write = 0.0
    while not stop:
        ex.spin_once(timeout_sec=0.05)
        now = time.monotonic()
        if not ready:
            if all(node.count_publishers(t) > 0 for t in topics):
                ready = True
                print("READY", flush=True)
            elif now > deadline:
                print("TIMEOUT no publisher on " + ",".join(t for t in topics if node.count_publishers(t) == 0),
                      flush=True)
                deadline = math.inf
        if now >= next_write:
            _write(args.out, {"counts": counts, "ready": ready, "diagnostics": diagnostics})
            next_write = now + 0.2
    # Drain what is already here, then the final counts.
    end = time.monotonic() + 0.2
    while time.monotonic() < end:
        ex.spin_once(timeout_sec=0.02)
    _write(args.out, {"counts": counts, "ready": ready, "diagnostics": diagnostics, "final": True})
    if rec is not None:
        rec.close()
    del subs
    node.destroy_node()
    rclpy.shutdown()
    return 0


def _fill(msg: Any, values: dict[str, Any]) -> Any:
    """`msg` with `values` set; a dict fills a nested message, a list of dicts a sequence of messages."""
    for k, v in values.items():
        if isinstance(v, dict):
            _fill(getattr(msg, k), v)
            continue
        if isinstance(v, list) and v and isinstance(v[0], dict):
            type_name = msg.get_fields_and_field_types()[k]  # sequence<pkg/Name> or pkg/Name[N] / [<=N]
            package, name = type_name.removeprefix("sequence<").split(">")[0].split(",")[0].split("[")[0].split("/")
            cls = getattr(importlib.import_module(f"{package}.msg"), name)
            v = [_fill(cls(), item) for item in v]
        setattr(msg, k, v)
    return msg


def publish(args: argparse.Namespace) -> int:
    import rclpy
    from rclpy.duration import Duration
    from rclpy.node import Node

    plan = json.loads(args.plan.read_text())
    topics = list(plan["topics"])
    classes, qos = _tables_and_classes(args.generated, topics)
    rclpy.init(args=[])
    node = Node("test_probe_publisher")
    pubs = {t: node.create_publisher(classes[t], t, qos[t]) for t in topics}
    deadline = time.monotonic() + args.discovery_timeout
    while not all(p.get_subscription_count() > 0 for p in pubs.values()):
        if time.monotonic() > deadline:
            print("TIMEOUT no subscriber on " + ",".join(t for t, p in pubs.items()
                                                          if p.get_subscription_count() == 0), flush=True)
            return 1
        rclpy.spin_once(node, timeout_sec=0.02)
    print("READY", flush=True)
    period = 1.0 / float(plan.get("rate_hz", 20.0))
    sent = dict.fromkeys(topics, 0)
    n = max(len(v) for v in plan["topics"].values())
    t0 = time.monotonic()
    for i in range(n):
        for t in topics:
            items = plan["topics"][t]
            if i < len(items):
                msg = _fill(classes[t](), items[i])
                if hasattr(msg, "header"):  # (a message without a header, std_msgs/Bool, is sent as it is)
                    msg.header.stamp = node.get_clock().now().to_msg()
                pubs[t].publish(msg)
                sent[t] += 1
        delay = t0 + (i + 1) * period - time.monotonic()
        if delay > 0:
            time.sleep(delay)
    # Reliable delivery: wait until the writers have no unacknowledged samples (bounded).
    for p in pubs.values():
        p.wait_for_all_acked(Duration(seconds=5.0))
    _write(args.out, {"sent": sent})
    print("DONE", flush=True)
    node.destroy_node()
    rclpy.shutdown()
    return 0


def listen_cmd(generated: Path | str, topics: Sequence[str], out: Path, record: Path | None = None,
               diagnostics: bool = False) -> list[str]:
    """The command line of `listen` (this script in a process of its own), for the tests that start it."""
    return [sys.executable, str(Path(__file__).resolve()), "listen", "--generated", str(generated),
            "--topics", ",".join(topics), "--out", str(out), *(["--record", str(record)] if record else []),
            *(["--diagnostics"] if diagnostics else [])]


def publish_cmd(generated: Path | str, plan: Path, out: Path) -> list[str]:
    """The command line of `publish`, for the tests that start it."""
    return [sys.executable, str(Path(__file__).resolve()), "publish", "--generated", str(generated),
            "--plan", str(plan), "--out", str(out)]


def main() -> int:
    p = argparse.ArgumentParser()
    sub = p.add_subparsers(dest="mode", required=True)
    a = sub.add_parser("listen")
    a.add_argument("--generated", type=Path, required=True)
    a.add_argument("--topics", required=True)
    a.add_argument("--out", type=Path, required=True)
    a.add_argument("--record", type=Path, default=None)
    a.add_argument("--diagnostics", action="store_true", help="also keep the last /diagnostics per status name")
    a.add_argument("--discovery-timeout", type=float, default=15.0)
    b = sub.add_parser("publish")
    b.add_argument("--generated", type=Path, required=True)
    b.add_argument("--plan", type=Path, required=True)
    b.add_argument("--out", type=Path, required=True)
    b.add_argument("--discovery-timeout", type=float, default=15.0)
    args = p.parse_args()
    return listen(args) if args.mode == "listen" else publish(args)


if __name__ == "__main__":
    sys.exit(main())
