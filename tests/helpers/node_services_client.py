"""An independent rclpy client of the bridge's device duties (`bridge.node_services`: the typed services
uavcan_get_node_info, uavcan_restart_node, uavcan_get_transport_stats), in its own process with the spec's ROS
package on its path.

python node_services_client.py --package lolo_msgs --device 30 --not-device 99 --out result.json [--namespace /x]

Calls, in order: get_node_info of the device and of a node that is no device; get_transport_stats of the device
until its counters have grown past the first answer's (each call is itself a transfer both ways; polled, with a
deadline); restart_node of the device (once its uptime is 2 s or more), then get_node_info until the device's
uptime went below the one it had before the restart (the reboot seen; polled, with a deadline). Every response
(all its fields) goes to the JSON.
"""

from __future__ import annotations

import argparse
import importlib
import json
import os
import sys
import time
from typing import Any


def main() -> int:
    p = argparse.ArgumentParser()
    p.add_argument("--package", required=True)
    p.add_argument("--device", type=int, required=True)
    p.add_argument("--not-device", type=int, required=True)
    p.add_argument("--namespace", default="/")
    p.add_argument("--suffix", default="", help="the services' protocol suffix (a mixed layout)")
    p.add_argument("--out", required=True)
    p.add_argument("--deadline", type=float, default=60.0)
    args = p.parse_args()
    os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")

    import rclpy
    from rclpy.executors import SingleThreadedExecutor

    srv = importlib.import_module(f"{args.package}.srv")
    rclpy.init()
    node = rclpy.create_node("node_services_client", namespace=args.namespace)
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    end = time.monotonic() + args.deadline
    clients = {duty: node.create_client(getattr(srv, type_), f"uavcan_{duty}{args.suffix}")
               for duty, type_ in (("get_node_info", "UavcanGetNodeInfo"), ("restart_node", "UavcanRestartNode"),
                                   ("get_transport_stats", "UavcanGetTransportStats"))}

    def call(duty: str, node_id: int) -> dict[str, Any]:
        client = clients[duty]
        while not client.wait_for_service(timeout_sec=0.2):
            executor.spin_once(timeout_sec=0.05)
            if time.monotonic() > end:
                raise SystemExit(f"no service {client.srv_name}")
        future = client.call_async(client.srv_type.Request(node_id=node_id))
        while not future.done():
            executor.spin_once(timeout_sec=0.05)
            if time.monotonic() > end:
                raise SystemExit(f"{client.srv_name} never returned")
        r = future.result()
        return {f: (list(v) if not isinstance(v, (bool, int, float, str)) else v)
                for f in r.get_fields_and_field_types() for v in [getattr(r, f)]}

    result: dict[str, Any] = {"services": {d: c.srv_name for d, c in clients.items()}}
    try:
        result["info"] = call("get_node_info", args.device)
        result["info_not_device"] = call("get_node_info", args.not_device)
        result["stats_not_device"] = call("get_transport_stats", args.not_device)
        first = call("get_transport_stats", args.device)
        result["stats"] = [first]
        while True:
            later = call("get_transport_stats", args.device)
            result["stats"].append(later)
            if not later["success"] or (later["transfers_tx"] > first["transfers_tx"]
                                        and later["transfers_rx"] > first["transfers_rx"]):
                break
        result["restart_not_device"] = call("restart_node", args.not_device)
        before = call("get_node_info", args.device)
        while not before["success"] or before["uptime_sec"] < 2:  # up long enough that a reboot shows
            before = call("get_node_info", args.device)
            if time.monotonic() > end:
                raise SystemExit(f"the device's uptime stayed at {before['uptime_sec']}")
        result["before_restart"] = before
        result["restart"] = call("restart_node", args.device)
        after = []
        while time.monotonic() < end:
            info = call("get_node_info", args.device)
            after.append(info)
            if info["success"] and info["uptime_sec"] < before["uptime_sec"]:
                break
        result["after_restart"] = after
    finally:
        with open(args.out, "w") as fh:
            json.dump(result, fh)
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
