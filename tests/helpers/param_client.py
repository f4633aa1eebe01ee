"""An independent rclpy client of a bridge's ROS parameters (the boards' settings, issue 28), through the standard
rcl parameter services only (rclpy's AsyncParameterClient: list_parameters, describe_parameters, get_parameters,
set_parameters). Writes what it got as JSON to --out (also when it fails part way); every wait shares one deadline.

python param_client.py --out r.json --node /glider_bridge --prefix pump --get pump.pump.direction \
    --set pump.pump.volume_limit=0.0008 --set ... [--trigger /pump/store_settings] \
    [--restart glider_msgs/srv/UavcanRestartNode=21@/uavcan_restart_node] [--wait-value NAME=JSON] [--rtt NAME=A,B]
  Lists the parameters under --prefix, describes and gets them; waits until --wait-value's parameter shows that
  value (the board's, read on first contact); then the steps in the order given: each --set (a JSON value), its
  result (successful, reason, seconds) and the value got afterwards ("sets"); each --atomic "N=V;N=V", one
  set_parameters_atomically of them, its result and the values got afterwards ("atomic"); each --trigger, a
  std_srvs/Trigger call of that service (success, message, seconds: "triggers"); each --restart, the device duty
  restart_node's srv called with that node id ("restarts"); --rtt sets NAME 20 times alternating A and B and
  records each duration.
"""

from __future__ import annotations

import argparse
import importlib
import json
import sys
import time
from typing import Any


def _value(v: Any) -> Any:
    from rclpy.parameter import parameter_value_to_python

    return parameter_value_to_python(v)


class _Step(argparse.Action):
    """--set, --trigger and --restart share one list, so that they run in the order given."""

    def __call__(self, parser: Any, namespace: Any, values: Any, option_string: Any = None) -> None:
        namespace.steps.append((self.const, values))


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", required=True)
    ap.add_argument("--node", required=True)
    ap.add_argument("--prefix", action="append", default=[])
    ap.add_argument("--set", action=_Step, const="set", default=[], dest="steps")
    ap.add_argument("--atomic", action=_Step, const="atomic", dest="steps")
    ap.add_argument("--trigger", action=_Step, const="trigger", dest="steps")
    ap.add_argument("--restart", action=_Step, const="restart", dest="steps")
    ap.add_argument("--wait-value", action="append", default=[])
    ap.add_argument("--rtt", default="")
    ap.add_argument("--deadline", type=float, default=60.0)
    args = ap.parse_args()

    import rclpy
    from rclpy.parameter import Parameter
    from rclpy.parameter_client import AsyncParameterClient

    result: dict[str, Any] = {}
    end = time.monotonic() + args.deadline
    rclpy.init()
    node = rclpy.create_node("param_client")
    client = AsyncParameterClient(node, args.node)

    def wait(future: Any) -> Any:
        rclpy.spin_until_future_complete(node, future, timeout_sec=max(0.0, end - time.monotonic()))
        if not future.done():
            raise TimeoutError("deadline")
        return future.result()

    def call(srv_type: Any, service: str, request: Any) -> Any:
        cli = node.create_client(srv_type, service)
        try:
            if not cli.wait_for_service(timeout_sec=max(0.0, end - time.monotonic())):
                raise TimeoutError(f"no service {service}")
            return wait(cli.call_async(request))
        finally:
            node.destroy_client(cli)

    try:
        if not client.wait_for_services(timeout_sec=max(0.0, end - time.monotonic())):
            raise TimeoutError("no parameter services")
        listed = wait(client.list_parameters(prefixes=args.prefix, depth=0)).result.names
        result["list"] = sorted(listed)
        described = wait(client.describe_parameters(listed)).descriptors
        result["describe"] = {d.name: {
            "type": int(d.type), "description": d.description, "read_only": d.read_only,
            "integer_range": [[r.from_value, r.to_value] for r in d.integer_range],
            "floating_point_range": [[r.from_value, r.to_value] for r in d.floating_point_range],
            "additional_constraints": d.additional_constraints} for d in described}
        for item in args.wait_value:
            name, text = item.split("=", 1)
            want, got = json.loads(text), None
            while time.monotonic() < end:
                got = _value(wait(client.get_parameters([name])).values[0])
                close = isinstance(got, float) and isinstance(want, float) and abs(got - want) <= 1e-6 * abs(want)
                if got == want or close:  # (a real travels as float32)
                    break
                time.sleep(0.05)  # polling the bridge's value (no event tells a client of a board's answer)
            result.setdefault("waited", {})[name] = got
        result["get"] = {n: _value(v) for n, v in zip(listed, wait(client.get_parameters(listed)).values,
                                                         strict=True)}
        result["sets"], result["triggers"], result["restarts"] = [], [], []
        for kind, item in args.steps:
            started = time.monotonic()
            if kind == "set":
                name, text = item.split("=", 1)
                res = wait(client.set_parameters([Parameter(name, value=json.loads(text))])).results[0]
                seconds = time.monotonic() - started
                after = _value(wait(client.get_parameters([name])).values[0])
                result["sets"].append({"name": name, "value": json.loads(text), "successful": res.successful,
                                       "reason": res.reason, "seconds": seconds, "after": after})
            elif kind == "atomic":  # NAME=JSON;NAME=JSON: one set_parameters_atomically
                pairs = [pair.split("=", 1) for pair in item.split(";")]
                parameters = [Parameter(name, value=json.loads(text)) for name, text in pairs]
                res = wait(client.set_parameters_atomically(parameters)).result
                seconds = time.monotonic() - started
                names = [name for name, _ in pairs]
                after = {n: _value(v) for n, v in zip(names, wait(client.get_parameters(names)).values, strict=True)}
                result.setdefault("atomic", []).append({"values": {n: json.loads(t) for n, t in pairs},
                                                        "successful": res.successful, "reason": res.reason,
                                                        "seconds": seconds, "after": after})
            elif kind == "trigger":
                from std_srvs.srv import Trigger

                answer = call(Trigger, item, Trigger.Request())
                result["triggers"].append({"service": item, "success": answer.success, "message": answer.message,
                                           "seconds": time.monotonic() - started})
            else:
                srv, rest = item.split("=", 1)
                nid, service = rest.split("@", 1)
                package, _, name = srv.split("/")
                srv_type = getattr(importlib.import_module(f"{package}.srv"), name)
                answer = call(srv_type, service, srv_type.Request(node_id=int(nid)))
                result["restarts"].append({"service": service, "success": answer.success, "message": answer.message})
        if args.rtt:
            name, pair = args.rtt.split("=", 1)
            values = [json.loads(v) for v in pair.split(",")]
            times, oks = [], []
            for i in range(20):
                started = time.monotonic()
                res = wait(client.set_parameters([Parameter(name, value=values[i % 2])])).results[0]
                times.append(time.monotonic() - started)
                oks.append(res.successful)
            result["rtt"] = {"seconds": times, "successful": oks}
    except Exception as ex:
        result["error"] = f"{type(ex).__name__}: {ex}"
    finally:
        with open(args.out, "w") as f:
            json.dump(result, f, indent=1)
        node.destroy_node()
        rclpy.shutdown()
    return 1 if "error" in result else 0


if __name__ == "__main__":
    sys.exit(main())
