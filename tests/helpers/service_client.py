"""An independent rclpy client of a bridge's service mapping (tests/specs/auv_services.yaml's UpdateBattery), in
its own process with the spec's ROS package on its path.

python service_client.py --service /bms/update_battery --status bridge/service/update_battery --out result.json

Calls, in order: command 1 (answered), 2 (never answered: the timeout), 3 (answered twice), 4 (answered late),
5 (a malformed answer); then 2 and 1 at once, recording which comes back first (a slow call must not hold up
another). Each call's response, its duration and its completion order go to the JSON; then it waits until the
bridge's /diagnostics status of the mapping counts every call and the late and duplicate responses, and writes
that status too.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import threading
import time
from typing import Any


def main() -> int:
    p = argparse.ArgumentParser()
    p.add_argument("--service", required=True)
    p.add_argument("--status", required=True)
    p.add_argument("--out", required=True)
    p.add_argument("--deadline", type=float, default=60.0)
    p.add_argument("--duties", action="store_true", help="then GetNodeInfo, GetTransportStats, RestartNode")
    p.add_argument("--device", type=int, default=30)
    args = p.parse_args()
    os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")

    import rclpy
    from diagnostic_msgs.msg import DiagnosticArray
    from lolo_msgs.srv import UpdateBattery
    from rclpy.executors import SingleThreadedExecutor

    rclpy.init()
    node = rclpy.create_node("battery_service_client")
    client = node.create_client(UpdateBattery, args.service)
    statuses: dict[str, dict[str, str]] = {}
    lock = threading.Lock()

    def on_diag(msg: Any) -> None:
        for st in msg.status:
            if st.name == args.status:
                with lock:
                    statuses["last"] = {"level": str(int.from_bytes(st.level, "little") if isinstance(st.level, bytes)
                                                     else int(st.level)), "message": st.message,
                                        **{kv.key: kv.value for kv in st.values}}

    node.create_subscription(DiagnosticArray, "/diagnostics", on_diag, 50)
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    result: dict[str, Any] = {"calls": [], "concurrent": []}
    try:
        end = time.monotonic() + args.deadline
        while not client.wait_for_service(timeout_sec=0.2):
            executor.spin_once(timeout_sec=0.05)
            if time.monotonic() > end:
                raise SystemExit("the service never appeared")

        def call(command: int, charge: float) -> Any:
            return client.call_async(UpdateBattery.Request(command=command, charge_percent=charge))

        def wait(futures: list[Any], order: list[int]) -> None:
            while not all(f.done() for f in futures):
                executor.spin_once(timeout_sec=0.05)
                for i, f in enumerate(futures):
                    if f.done() and i not in order:
                        order.append(i)
                if time.monotonic() > end:
                    raise SystemExit("a call never returned")

        for command, charge in ((1, 42.5), (2, 10.0), (3, 0.0), (4, 0.0), (5, 0.0)):
            t0 = time.monotonic()
            future = call(command, charge)
            wait([future], [])
            r = future.result()
            result["calls"].append({"command": command, "success": bool(r.success), "status": int(r.status),
                                    "elapsed_s": time.monotonic() - t0})
        order: list[int] = []
        futures = [call(2, 1.0), call(1, 2.0)]
        wait(futures, order)
        result["concurrent"] = [{"command": (2, 1)[i], "success": bool(futures[i].result().success)} for i in order]
        if args.duties:
            result["duties"] = duties(node, executor, wait, args.device)
        # The counters: every call (7), the duplicate and the late answer (which comes after its call ended).
        while True:
            with lock:
                last = dict(statuses.get("last", {}))
            if last and int(last.get("calls", 0)) >= 7 and int(last.get("late_responses", 0)) >= 1 \
                    and int(last.get("duplicate_responses", 0)) >= 1:
                break
            if time.monotonic() > end:
                break
            executor.spin_once(timeout_sec=0.1)
        result["status"] = last
    finally:
        with open(args.out, "w") as fh:
            json.dump(result, fh)
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


def duties(node: Any, executor: Any, wait: Any, device: int) -> dict[str, Any]:
    """The typed node duties of the device and of a node that does not exist (99)."""
    from lolo_msgs.srv import GetNodeInfo, GetTransportStats, RestartNode

    out: dict[str, Any] = {}
    services = {GetNodeInfo: "get_node_info", RestartNode: "restart_node", GetTransportStats: "get_transport_stats"}
    for name, srv, nid in (("info", GetNodeInfo, device), ("info_missing", GetNodeInfo, 99),
                           ("stats", GetTransportStats, device), ("restart", RestartNode, device)):
        client = node.create_client(srv, f"/bridge/{services[srv]}")
        while not client.wait_for_service(timeout_sec=0.2):
            executor.spin_once(timeout_sec=0.05)
        future = client.call_async(srv.Request(node_id=nid))
        wait([future], [])
        r = future.result()
        out[name] = {f: getattr(r, f) for f in r.get_fields_and_field_types()}
    return out


if __name__ == "__main__":
    sys.exit(main())
