"""The monitor's demo publisher on one spec, in its own process (a segmentation fault fails the test, not pytest).

python demo_check.py --generated DIR --out RESULT.json [--messages 3] [--timeout 20]

1. Every ROS message class the spec uses (topics and the ROS package's own messages): demo messages at several
   times have no field rclpy's checks refuse, survive serialize/deserialize with their shapes, and a message
   with a scalar put into an array field (what the old demo publisher did) is caught by the checker.
2. A LiveView with demo_commands publishes on every command topic until a subscriber in another context has
   received ``--messages`` of each; every received message is checked again.
Writes a JSON report; exit code 0 when it ran to the end (the checks are the test's business).
"""

from __future__ import annotations

import argparse
import importlib
import json
import os
import sys
import time
from pathlib import Path
from typing import Any

os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")


def _shapes(msg: Any) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for name in msg.get_fields_and_field_types():
        v = getattr(msg, name)
        if hasattr(v, "get_fields_and_field_types"):
            out[name] = _shapes(v)
        elif hasattr(v, "__len__") and not isinstance(v, str):
            out[name] = len(v)
        else:
            out[name] = type(v).__name__
    return out


# Standard messages with every other kind of rosidl field: sequences of nested messages, byte and char fields,
# uint8[] and float32[] sequences, strings, bounded strings, octet scalars.
STANDARD = ("diagnostic_msgs.msg.DiagnosticArray", "nav_msgs.msg.Path", "sensor_msgs.msg.BatteryState",
            "sensor_msgs.msg.PointCloud2", "sensor_msgs.msg.Imu", "std_msgs.msg.Float32MultiArray",
            "std_msgs.msg.ByteMultiArray", "std_msgs.msg.Char", "std_msgs.msg.Byte",
            "builtin_interfaces.msg.Duration", "rcl_interfaces.msg.ParameterDescriptor")


def check_classes(gen: Any) -> dict[str, Any]:
    from rclpy.serialization import deserialize_message, serialize_message
    from rosidl_parser import definition as d

    from sam_runtime.main_job.demo import demo_message, field_problems

    tables = gen.tables()
    classes = {m.topic.ros_type: gen.ros_class(m.topic) for m in tables.MAPPINGS}
    for t in tables.TOPICS:  # also the spec's other topics whose package is installed here (no tf2_msgs wheel)
        try:
            classes[t.ros_type] = gen.ros_class(t)
        except ImportError:
            pass
    for path in STANDARD:
        module, _, name = path.rpartition(".")
        try:
            classes[path] = getattr(importlib.import_module(module), name)
        except ImportError:  # not installed here: the spec's own types are what matters
            pass
    own = importlib.import_module(f"{tables.ROS_PACKAGE}.msg")
    for name in dir(own):
        cls = getattr(own, name)
        if isinstance(cls, type) and hasattr(cls, "SLOT_TYPES"):
            classes[f"{tables.ROS_PACKAGE}/msg/{name}"] = cls
    report: dict[str, Any] = {}
    for ros_type, cls in sorted(classes.items()):
        problems: list[str] = []
        shapes: list[Any] = []
        for t in (0.0, 3.7, 7.5, 15.0, 22.5):
            msg = demo_message(cls, t)
            problems += field_problems(msg)
            back = deserialize_message(serialize_message(msg), cls)
            problems += [f"after a round trip: {p}" for p in field_problems(back)]
            if _shapes(back) != _shapes(msg):
                problems.append(f"shapes changed in a round trip: {_shapes(msg)} -> {_shapes(back)}")
            shapes.append(_shapes(msg))
        # The checker must catch the old defect, a scalar in an array field (never published: that crashes).
        caught = None
        for (name, _), slot in zip(cls.get_fields_and_field_types().items(), cls.SLOT_TYPES, strict=True):
            if not isinstance(slot, d.AbstractNestedType):
                continue
            bad = cls()  # rclpy's default: fields unchecked, as the old demo publisher had them
            try:
                setattr(bad, name, 0.5)
            except TypeError:  # e.g. array.array('b', 0.5): refused by rclpy's setter itself
                continue
            caught = bool(field_problems(bad)) if caught is None else caught and bool(field_problems(bad))
        report[ros_type] = {"problems": problems, "shapes": shapes[0], "scalar_in_array_caught": caught}
    return report


def run_monitor(gen: Any, want: int, timeout: float) -> dict[str, Any]:
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.node import Node
    from rclpy.signals import SignalHandlerOptions

    from sam_runtime.main_job.demo import field_problems
    from sam_runtime.main_job.job import LiveView

    tables = gen.tables()
    commands = sorted({m.topic.name: m.topic for m in tables.MAPPINGS if m.direction == "ros_to_uavcan"}.items())
    ctx = rclpy.Context()
    rclpy.init(args=[], context=ctx, signal_handler_options=SignalHandlerOptions.NO)
    node = Node("demo_check", context=ctx)
    got: dict[str, list[Any]] = {name: [] for name, _ in commands}
    for name, topic in commands:
        node.create_subscription(gen.ros_class(topic), name, got[name].append, 100)
    executor = SingleThreadedExecutor(context=ctx)
    executor.add_node(node)
    monitor = LiveView(tables, gen, demo_commands=True)
    deadline = time.monotonic() + timeout
    try:
        while time.monotonic() < deadline and any(len(v) < want for v in got.values()):
            monitor.spin_for(0.05)
            executor.spin_once(timeout_sec=0.01)
    finally:
        published, errors = dict(monitor.demo_published), dict(monitor.demo_errors)
        monitor.close()
        executor.shutdown(timeout_sec=1.0)
        node.destroy_node()
        ctx.shutdown()
    return {
        "received": {k: len(v) for k, v in got.items()},
        "received_problems": {k: [p for msg in v for p in field_problems(msg)] for k, v in got.items()},
        "published": published,
        "errors": errors,
    }


def main() -> int:
    p = argparse.ArgumentParser()
    p.add_argument("--generated", type=Path, required=True)
    p.add_argument("--out", type=Path, required=True)
    p.add_argument("--messages", type=int, default=3)
    p.add_argument("--timeout", type=float, default=20.0)
    args = p.parse_args()
    from sam_runtime.genpkg import GeneratedPackage

    gen = GeneratedPackage(args.generated)
    result = {"classes": check_classes(gen), "monitor": run_monitor(gen, args.messages, args.timeout)}
    args.out.write_text(json.dumps(result, indent=1, sort_keys=True))
    print("DONE", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
