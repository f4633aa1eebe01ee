"""Independent rclpy clients of a bridge's services, each in its own process with the spec's ROS package on its path.
One command line, one scenario a subcommand; every scenario writes its result to --out as JSON (also when it fails
part way: what it got until then), and waits on conditions with one deadline (--deadline s), never fixed sleeps.

python ros_service_client.py --out result.json battery --service /bms/update_battery \
    --status bridge/service/update_battery [--duties] [--device 30]
  tests/specs/auv_services.yaml's UpdateBattery: command 1 (answered), 2 (never answered: the timeout), 3
  (answered twice), 4 (answered late), 5 (a malformed answer); then 2 and 1 at once, recording which comes back
  first (a slow call must not hold up another). Each call's response, its duration and its completion order go to
  the JSON; with --duties then GetNodeInfo, GetTransportStats, RestartNode of the device and GetNodeInfo of node
  99; then it waits until the bridge's /diagnostics status of the mapping counts every call and the late and
  duplicate responses, and writes that status too.

python ros_service_client.py --out result.json charger [--device 31]
  tests/specs/auv_cyphal_services.yaml: /charger/set_limits (20, 80) (accepted), (90, 10) (refused), (0, 50)
  (answered late by the charger: the timeout), then /bridge/get_node_info of the device and of node 99 (no answer).
  Each response and its duration go to the JSON; then it waits until the bridge's /diagnostics status of
  set_charge_limits counts the three calls and the late response, and writes that status too.

python ros_service_client.py --out result.json duties --package lolo_msgs --device 30 --not-device 99 \
    [--namespace /x] [--suffix _can] [--reboot-evidence uptime|transfers_tx]
  The bridge's device duties (`bridge.node_services`: the typed services uavcan_get_node_info, uavcan_restart_node,
  uavcan_get_transport_stats): get_node_info of the device and of a node that is no device; get_transport_stats of
  the device until its counters have grown past the first answer's (each call is itself a transfer both ways;
  polled, with the deadline); restart_node of the device (once its uptime is 2 s or more), then get_node_info and
  get_transport_stats until the reboot is seen by the evidence asked for: the device's uptime (GetNodeInfo
  answered with an uptime below the one before the restart) or its transfer count (below the one before) (polled
  every 0.1 s, with the deadline; a call that fails while the device is rebooting is recorded and polled past).
  Every response (all its fields) goes to the JSON.
"""

from __future__ import annotations

import argparse
import importlib
import json
import os
import sys
import threading
import time
from collections.abc import Callable
from typing import Any


class Session:
    """One rclpy node with its executor and the deadline every wait of a scenario shares."""

    def __init__(self, name: str, deadline: float, namespace: str = "/") -> None:
        import rclpy
        from rclpy.executors import SingleThreadedExecutor

        self._rclpy = rclpy
        rclpy.init()
        self.node = rclpy.create_node(name, namespace=namespace)
        self.executor = SingleThreadedExecutor()
        self.executor.add_node(self.node)
        self.end = time.monotonic() + deadline
        self._statuses: dict[str, dict[str, str]] = {}
        self._lock = threading.Lock()

    def late(self) -> bool:
        return time.monotonic() > self.end

    def spin(self, timeout: float = 0.05) -> None:
        self.executor.spin_once(timeout_sec=timeout)

    def watch_status(self, name: str) -> None:
        """Keep the last /diagnostics status called `name` (level, message and its key/values, all strings)."""
        from diagnostic_msgs.msg import DiagnosticArray

        def on_diag(msg: Any) -> None:
            for st in msg.status:
                if st.name == name:
                    level = int.from_bytes(st.level, "little") if isinstance(st.level, bytes) else int(st.level)
                    with self._lock:
                        self._statuses["last"] = {"level": str(level), "message": st.message,
                                                  **{kv.key: kv.value for kv in st.values}}

        self.node.create_subscription(DiagnosticArray, "/diagnostics", on_diag, 50)

    def status_when(self, done: Callable[[dict[str, str]], bool]) -> dict[str, str]:
        """The watched status once `done` holds for it (or the last one seen at the deadline)."""
        while True:
            with self._lock:
                last = dict(self._statuses.get("last", {}))
            if (last and done(last)) or self.late():
                return last
            self.spin(0.1)

    def ready(self, client: Any) -> Any:
        """The client once its service is there (discovery, with the deadline)."""
        while not client.wait_for_service(timeout_sec=0.2):
            self.spin()
            if self.late():
                raise SystemExit(f"no service {client.srv_name}")
        return client

    def wait(self, futures: list[Any], order: list[int] | None = None) -> None:
        """Spin until every future is done, appending each one's index to `order` as it completes."""
        while not all(f.done() for f in futures):
            self.spin()
            for i, f in enumerate(futures):
                if order is not None and f.done() and i not in order:
                    order.append(i)
            if self.late():
                raise SystemExit("a call never returned")

    def call(self, client: Any, request: Any) -> Any:
        """One call of a ready client: its response."""
        future = self.ready(client).call_async(request)
        self.wait([future])
        return future.result()

    def pause(self, seconds: float) -> None:
        """A poll interval (spinning), not a verdict."""
        until = time.monotonic() + seconds
        while time.monotonic() < until:
            self.spin(seconds)

    def close(self) -> None:
        self.executor.shutdown()
        self.node.destroy_node()
        self._rclpy.try_shutdown()


def fields(response: Any) -> dict[str, Any]:
    """Every field of a response, arrays as lists of ints (JSON)."""
    return {f: ([int(b) for b in v] if not isinstance(v, (bool, int, float, str)) else v)
            for f in response.get_fields_and_field_types() for v in [getattr(response, f)]}


def battery(s: Session, args: argparse.Namespace, result: dict[str, Any]) -> None:
    from lolo_msgs.srv import GetNodeInfo, GetTransportStats, RestartNode, UpdateBattery

    s.watch_status(args.status)
    client = s.ready(s.node.create_client(UpdateBattery, args.service))

    def call(command: int, charge: float) -> Any:
        return client.call_async(UpdateBattery.Request(command=command, charge_percent=charge))

    result["calls"], result["concurrent"] = [], []
    for command, charge in ((1, 42.5), (2, 10.0), (3, 0.0), (4, 0.0), (5, 0.0)):
        t0 = time.monotonic()
        future = call(command, charge)
        s.wait([future])
        r = future.result()
        result["calls"].append({"command": command, "success": bool(r.success), "status": int(r.status),
                                "elapsed_s": time.monotonic() - t0})
    order: list[int] = []
    futures = [call(2, 1.0), call(1, 2.0)]
    s.wait(futures, order)
    result["concurrent"] = [{"command": (2, 1)[i], "success": bool(futures[i].result().success)} for i in order]
    if args.duties:  # the typed node duties of the device and of a node that does not exist (99)
        duties: dict[str, Any] = {}
        result["duties"] = duties
        services = {GetNodeInfo: "get_node_info", RestartNode: "restart_node", GetTransportStats: "get_transport_stats"}
        for name, srv, nid in (("info", GetNodeInfo, args.device), ("info_missing", GetNodeInfo, 99),
                               ("stats", GetTransportStats, args.device), ("restart", RestartNode, args.device)):
            r = s.call(s.node.create_client(srv, f"/bridge/{services[srv]}"), srv.Request(node_id=nid))
            duties[name] = {f: getattr(r, f) for f in r.get_fields_and_field_types()}
    # The counters: every call (7), the duplicate and the late answer (which comes after its call ended).
    result["status"] = s.status_when(lambda last: int(last.get("calls", 0)) >= 7
                                     and int(last.get("late_responses", 0)) >= 1
                                     and int(last.get("duplicate_responses", 0)) >= 1)


def charger(s: Session, args: argparse.Namespace, result: dict[str, Any]) -> None:
    from ran_msgs.srv import GetNodeInfo, SetChargeLimits

    s.watch_status("bridge/service/set_charge_limits")
    result["limits"], result["info"] = [], []

    def call(srv: Any, name: str, request: Any) -> dict[str, Any]:
        client = s.ready(s.node.create_client(srv, name))
        t0 = time.monotonic()
        r = s.call(client, request)
        out = {f: getattr(r, f) for f in r.get_fields_and_field_types()}
        out["elapsed_s"] = time.monotonic() - t0
        return out

    for low, high in ((20.0, 80.0), (90.0, 10.0), (0.0, 50.0)):
        result["limits"].append(call(SetChargeLimits, "/charger/set_limits",
                                     SetChargeLimits.Request(low=low, high=high)))
    for nid in (args.device, 99):
        result["info"].append(call(GetNodeInfo, "/bridge/get_node_info", GetNodeInfo.Request(node_id=nid)))
    result["status"] = s.status_when(lambda last: int(last.get("calls", 0)) >= 3
                                     and int(last.get("late_responses", 0)) >= 1)


def duties(s: Session, args: argparse.Namespace, result: dict[str, Any]) -> None:
    srv = importlib.import_module(f"{args.package}.srv")
    clients = {duty: s.node.create_client(getattr(srv, type_), f"uavcan_{duty}{args.suffix}")
               for duty, type_ in (("get_node_info", "UavcanGetNodeInfo"), ("restart_node", "UavcanRestartNode"),
                                   ("get_transport_stats", "UavcanGetTransportStats"))}

    def call(duty: str, node_id: int) -> dict[str, Any]:
        client = clients[duty]
        return fields(s.call(client, client.srv_type.Request(node_id=node_id)))

    result["info"] = call("get_node_info", args.device)
    # where the bridge serves the duties, as the ROS graph has them (the srv types of its package)
    while True:  # (discovery: until the three are there, or the deadline)
        result["services"] = sorted(f"{name} {types[0]}" for name, types in s.node.get_service_names_and_types()
                                    if any("/srv/Uavcan" in t for t in types))
        if len(result["services"]) >= 3 or s.late():
            break
        s.spin()
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
        s.pause(0.1)
        before = call("get_node_info", args.device)
        if s.late():
            raise SystemExit(f"the device's uptime stayed at {before['uptime_sec']}")
    result["before_restart"] = before
    last_stats = call("get_transport_stats", args.device)
    result["stats_before_restart"] = last_stats
    result["restart"] = call("restart_node", args.device)
    # The reboot seen by the evidence the caller asked for, whichever other shows first: the node's uptime went
    # down (DroneCAN's GetNodeInfo carries its own), or its transport counters started again (Cyphal: GetInfo has
    # no uptime; the bridge's heartbeat record follows the new node's heartbeats only once pycyphal lets them through).
    after: list[dict[str, Any]] = []
    result["after_restart"] = after
    while not s.late():
        info, stats = call("get_node_info", args.device), call("get_transport_stats", args.device)
        after.append({"info": info, "stats": stats})
        if args.reboot_evidence == "uptime" and info["success"] and info["uptime_sec"] < before["uptime_sec"]:
            result["rebooted_by"] = "uptime"
            break
        if args.reboot_evidence == "transfers_tx" and stats["success"] \
                and stats["transfers_tx"] < last_stats["transfers_tx"]:
            result["rebooted_by"] = "transfers_tx"
            break
        s.pause(0.1)


SCENARIOS: dict[str, tuple[str, Callable[[Session, argparse.Namespace, dict[str, Any]], None]]] = {
    "battery": ("battery_service_client", battery),
    "charger": ("cyphal_service_client", charger),
    "duties": ("node_services_client", duties),
}


def main() -> int:
    p = argparse.ArgumentParser()
    p.add_argument("--out", required=True)
    p.add_argument("--deadline", type=float, default=60.0)
    sub = p.add_subparsers(dest="scenario", required=True)
    b = sub.add_parser("battery")
    b.add_argument("--service", required=True)
    b.add_argument("--status", required=True)
    b.add_argument("--duties", action="store_true", help="then GetNodeInfo, GetTransportStats, RestartNode")
    b.add_argument("--device", type=int, default=30)
    c = sub.add_parser("charger")
    c.add_argument("--device", type=int, default=31)
    n = sub.add_parser("duties")
    n.add_argument("--package", required=True)
    n.add_argument("--device", type=int, required=True)
    n.add_argument("--not-device", type=int, required=True)
    n.add_argument("--namespace", default="/")
    n.add_argument("--suffix", default="", help="the services' protocol suffix (a mixed layout)")
    n.add_argument("--reboot-evidence", choices=("uptime", "transfers_tx"), default="uptime",
                   help="what shows the device rebooted: GetNodeInfo's uptime (DroneCAN) or its transfer counters")
    args = p.parse_args()
    os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")

    node_name, scenario = SCENARIOS[args.scenario]
    session = Session(node_name, args.deadline, getattr(args, "namespace", "/"))
    result: dict[str, Any] = {}
    try:
        scenario(session, args, result)
    finally:
        with open(args.out, "w") as fh:
            json.dump(result, fh)
        session.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
