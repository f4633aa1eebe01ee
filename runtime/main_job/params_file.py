"""``sam-codegen params save FILE`` / ``params restore FILE``: every board's settings (the bridge's ROS parameters
``<device>.<setting>``, issue 28) to and from a ROS 2 params file, for a board swap: save before, restore after.

The file is the standard layout ``ros2 param dump`` writes and ``--params-file`` reads
(``/<bridge node>: {ros__parameters: {thruster_1: {motor: {pole_count: 14}}}}``). Restore reads the bridge's values
first, sets only what differs, one parameter per request (each is written to its board and confirmed, or refused
with its reason: sam_runtime.bridge.device_params), and prints the diff: ``name: old -> new`` for each change, the
reason of each refusal; exit status 1 if any was refused. Only the standard parameter services are used (an rclpy
AsyncParameterClient), so it works against any running bridge of the spec.
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from sam_runtime.cli_support import add_generated_args, generated_package

__all__ = ["flatten", "nest", "params_main"]

_TIMEOUT_S = 10.0


def nest(values: dict[str, Any]) -> dict[str, Any]:
    """``{"a.b.c": 1}`` -> ``{"a": {"b": {"c": 1}}}`` (the params-file nesting).

    >>> nest({"thruster_1.motor.pole_count": 14, "thruster_1.esc.index": 0})
    {'thruster_1': {'esc': {'index': 0}, 'motor': {'pole_count': 14}}}
    """
    out: dict[str, Any] = {}
    for name in sorted(values):
        *parents, leaf = name.split(".")
        node = out
        for part in parents:
            node = node.setdefault(part, {})
        node[leaf] = values[name]
    return out


def flatten(tree: dict[str, Any], prefix: str = "") -> dict[str, Any]:
    """The inverse of :func:`nest` (dotted keys in the file are kept as they are).

    >>> flatten({"thruster_1": {"motor": {"pole_count": 14}}, "imu.rate_hz": 100})
    {'thruster_1.motor.pole_count': 14, 'imu.rate_hz': 100}
    """
    out: dict[str, Any] = {}
    for key, value in tree.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            out.update(flatten(value, name + "."))
        else:
            out[name] = value
    return out


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="sam-codegen params", description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("action", choices=("save", "restore"))
    p.add_argument("file", type=Path, help="the params file (YAML)")
    p.add_argument("--node", default=None,
                   help="the bridge's node (default: the spec's bridge name, /<name>)")
    p.add_argument("--dry-run", action="store_true", help="restore: print the diff, set nothing")
    add_generated_args(p)
    return p


def _bridge_node(args: argparse.Namespace) -> tuple[str, list[str]]:
    """The bridge's node name and the devices that have settings (from the generated tables)."""
    tables = generated_package(args).tables()
    node = args.node or f"/{tables.BRIDGE_NAME or 'uavcan_ros_bridge'}"
    return node, sorted({p.device for p in tables.DEVICE_PARAMETERS})


def params_main(argv: Sequence[str] | None = None) -> int:
    import yaml

    args = _parser().parse_args(argv)
    os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
    node_name, devices = _bridge_node(args)
    import rclpy
    from rclpy.parameter import Parameter, parameter_value_to_python
    from rclpy.parameter_client import AsyncParameterClient

    rclpy.init()
    node = rclpy.create_node("sam_params")
    try:
        client = AsyncParameterClient(node, node_name)

        def wait(future: Any) -> Any:
            rclpy.spin_until_future_complete(node, future, timeout_sec=_TIMEOUT_S)
            if not future.done():
                raise TimeoutError(f"{node_name} did not answer within {_TIMEOUT_S:g} s")
            return future.result()

        if not client.wait_for_services(timeout_sec=_TIMEOUT_S):
            print(f"sam-codegen params: no parameter services of {node_name} (is the bridge running?)",
                  file=sys.stderr)
            return 1
        names = sorted(wait(client.list_parameters(prefixes=devices, depth=0)).result.names)
        values = [parameter_value_to_python(v) for v in wait(client.get_parameters(names)).values]
        current = dict(zip(names, values, strict=True))
        if args.action == "save":
            args.file.write_text(yaml.safe_dump({node_name: {"ros__parameters": nest(current)}}, sort_keys=False))
            print(f"saved {len(current)} settings of {len(devices)} boards from {node_name} to {args.file}")
            return 0
        document = yaml.safe_load(args.file.read_text()) or {}
        section = document.get(node_name) or document.get(node_name.lstrip("/")) or document.get("/**") or {}
        wanted = flatten(section.get("ros__parameters", {}))
        failed = 0
        for name, value in wanted.items():
            if name not in current:
                print(f"{name}: not a setting of {node_name} (skipped)")
                continue
            if current[name] == value:
                continue
            if args.dry_run:
                print(f"{name}: {current[name]!r} -> {value!r} (dry run)")
                continue
            result = wait(client.set_parameters([Parameter(name, value=value)])).results[0]
            if result.successful:
                print(f"{name}: {current[name]!r} -> {value!r}")
            else:
                failed += 1
                print(f"{name}: {current[name]!r} -> {value!r} REFUSED: {result.reason}")
        return 1 if failed else 0
    except TimeoutError as ex:
        print(f"sam-codegen params: {ex}", file=sys.stderr)
        return 1
    finally:
        node.destroy_node()
        rclpy.shutdown()
