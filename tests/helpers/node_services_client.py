"""An independent rclpy client of the bridge's device duties (`bridge.node_services`: the typed services
uavcan_get_node_info, uavcan_restart_node, uavcan_get_transport_stats), in its own process with the spec's ROS
package on its path.

python node_services_client.py --package lolo_msgs --device 30 --not-device 99 --out result.json [--namespace /x]

Calls, in order: get_node_info of the device and of a node that is no device; get_transport_stats of the device
until its counters have grown past the first answer's (each call is itself a transfer both ways; polled, with a
deadline); restart_node of the device (once its uptime is 2 s or more), then get_node_info and
get_transport_stats until the device's uptime or its transfer count went below the one it had before the restart
(the reboot seen; polled every 0.1 s, with a deadline). Every response (all its fields) goes to the JSON.
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
        return {f: ([int(b) for b in v] if not isinstance(v, (bool, int, float, str)) else v)
                for f in r.get_fields_and_field_types() for v in [getattr(r, f)]}

    def wait(seconds: float) -> None:
        """A poll interval (spinning), not a verdict."""
        pause = time.monotonic() + seconds
        while time.monotonic() < pause:
            executor.spin_once(timeout_sec=seconds)

    result: dict[str, Any] = {}
    try:
        result["info"] = call("get_node_info", args.device)
        # where the bridge serves the duties, as the ROS graph has them (the srv types of its package)
        while True:  # (discovery: until the three are there, or the deadline)
            result["services"] = sorted(f"{name} {types[0]}" for name, types in node.get_service_names_and_types()
                                        if any("/srv/Uavcan" in t for t in types))
            if len(result["services"]) >= 3 or time.monotonic() > end:
                break
            executor.spin_once(timeout_sec=0.05)
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
            wait(0.1)
            before = call("get_node_info", args.device)
            if time.monotonic() > end:
                raise SystemExit(f"the device's uptime stayed at {before['uptime_sec']}")
        result["before_restart"] = before
        last_stats = call("get_transport_stats", args.device)
        result["stats_before_restart"] = last_stats
        result["restart"] = call("restart_node", args.device)
        # The reboot seen: the node's uptime went down (DroneCAN's GetNodeInfo carries its own), or its transport
        # counters started again (Cyphal: GetInfo has no uptime, and the bridge's heartbeat record may not see the
        # new node's first heartbeats, which reuse transfer ids that pycyphal takes for duplicates for 2 s).
        after: list[dict[str, Any]] = []
        result["after_restart"] = after
        while time.monotonic() < end:
            info, stats = call("get_node_info", args.device), call("get_transport_stats", args.device)
            after.append({"info": info, "stats": stats})
            if info["success"] and info["uptime_sec"] < before["uptime_sec"]:
                result["rebooted_by"] = "uptime"
                break
            if stats["success"] and stats["transfers_tx"] < last_stats["transfers_tx"]:
                result["rebooted_by"] = "transfers_tx"
                break
            wait(0.1)
    finally:
        with open(args.out, "w") as fh:
            json.dump(result, fh)
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
