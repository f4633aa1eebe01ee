"""An independent rclpy client of the Cyphal service mappings of tests/specs/auv_cyphal_services.yaml, in its own
process with the spec's ROS package on its path.

python cyphal_service_client.py --out result.json [--device 31]

Calls, in order: /charger/set_limits (20, 80) (accepted), (90, 10) (refused), (0, 50) (answered late by the
charger: the timeout), then /bridge/get_node_info of the device and of node 99 (no answer). Each response and its
duration go to the JSON; then it waits until the bridge's /diagnostics status of set_charge_limits counts the three
calls and the late response, and writes that status too.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import threading
import time
from typing import Any

STATUS = "bridge/service/set_charge_limits"


def main() -> int:
    p = argparse.ArgumentParser()
    p.add_argument("--out", required=True)
    p.add_argument("--deadline", type=float, default=60.0)
    p.add_argument("--device", type=int, default=31)
    args = p.parse_args()
    os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")

    import rclpy
    from diagnostic_msgs.msg import DiagnosticArray
    from ran_msgs.srv import GetNodeInfo, SetChargeLimits
    from rclpy.executors import SingleThreadedExecutor

    rclpy.init()
    node = rclpy.create_node("cyphal_service_client")
    statuses: dict[str, dict[str, str]] = {}
    lock = threading.Lock()

    def on_diag(msg: Any) -> None:
        for st in msg.status:
            if st.name == STATUS:
                level = int.from_bytes(st.level, "little") if isinstance(st.level, bytes) else int(st.level)
                with lock:
                    statuses["last"] = {"level": str(level), "message": st.message,
                                        **{kv.key: kv.value for kv in st.values}}

    node.create_subscription(DiagnosticArray, "/diagnostics", on_diag, 50)
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    end = time.monotonic() + args.deadline
    result: dict[str, Any] = {"limits": [], "info": []}

    def call(srv: Any, name: str, request: Any) -> dict[str, Any]:
        client = node.create_client(srv, name)
        while not client.wait_for_service(timeout_sec=0.2):
            executor.spin_once(timeout_sec=0.05)
            if time.monotonic() > end:
                raise SystemExit(f"{name} never appeared")
        t0 = time.monotonic()
        future = client.call_async(request)
        while not future.done():
            executor.spin_once(timeout_sec=0.05)
            if time.monotonic() > end:
                raise SystemExit(f"a call of {name} never returned")
        r = future.result()
        out = {f: getattr(r, f) for f in r.get_fields_and_field_types()}
        out["elapsed_s"] = time.monotonic() - t0
        return out

    last: dict[str, str] = {}
    try:
        for low, high in ((20.0, 80.0), (90.0, 10.0), (0.0, 50.0)):
            result["limits"].append(call(SetChargeLimits, "/charger/set_limits",
                                         SetChargeLimits.Request(low=low, high=high)))
        for nid in (args.device, 99):
            result["info"].append(call(GetNodeInfo, "/bridge/get_node_info", GetNodeInfo.Request(node_id=nid)))
        while time.monotonic() < end:
            with lock:
                last = dict(statuses.get("last", {}))
            if last and int(last.get("calls", 0)) >= 3 and int(last.get("late_responses", 0)) >= 1:
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


if __name__ == "__main__":
    sys.exit(main())
