"""An independent DroneCAN board for the bridge's settings (issue 28): a plain ``dronecan`` node that answers
uavcan.protocol.param.GetSet and ExecuteOpcode the way AP_Periph-style firmware does, written from the DroneCAN
specification, not from the project's simulator (runtime/sim/), so that a test of the bridge against it does not
test the simulator against itself. Only the bus driver is the project's (the loopback bus ``mcast-lo:``; dronecan's
own ``mcast:`` driver sends out of the machine).

python dronecan_board.py --iface mcast-lo:B:P --node-id 50 --state board.json \
    --param ESC_NUM_POLES=int:20:2:48 --param ESC_REV=bool:0 --param ESC_MAX_RPM=int:3000:0:6000 [--read-only NAME]

- GetSet by name (when the request names one) or else by index (the enumeration order of --param); an unknown name
  or an index past the end: an empty response (empty name, empty value), as the specification says;
- a request with a value sets the parameter when the value's type is the parameter's (an integer or real within
  min..max, clamped as firmware does; a --read-only one keeps its value) and answers with the value it now holds;
- ExecuteOpcode SAVE marks the values saved (ok=true), ERASE restores the defaults;
- NodeStatus at 1 Hz (OPERATIONAL), GetNodeInfo answered by dronecan.
The state file (JSON, rewritten after every change) holds the values, the saved values and the requests seen.
Prints READY once its node runs; stops on SIGTERM/SIGINT.
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import sys
from pathlib import Path
from typing import Any


def _parse_param(text: str) -> tuple[str, dict[str, Any]]:
    name, _, spec = text.partition("=")
    kind, *rest = spec.split(":")
    if kind == "bool":
        return name, {"kind": "bool", "value": bool(int(rest[0])), "default": bool(int(rest[0]))}
    conv = int if kind == "int" else float
    value, lo, hi = (conv(x) for x in rest)
    return name, {"kind": kind, "value": value, "default": value, "min": lo, "max": hi}


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--iface", required=True)
    ap.add_argument("--node-id", type=int, required=True)
    ap.add_argument("--state", type=Path, required=True)
    ap.add_argument("--param", action="append", default=[])
    ap.add_argument("--read-only", action="append", default=[])
    args = ap.parse_args()

    import dronecan

    from sam_runtime.dronecan_io.iface import make_driver

    params = dict(_parse_param(p) for p in args.param)
    order = list(params)
    seen: dict[str, int] = {"get_by_name": 0, "get_by_index": 0, "set": 0, "set_kept": 0, "unknown": 0,
                            "save": 0, "erase": 0}
    saved: dict[str, Any] = {}

    def write_state() -> None:
        tmp = args.state.with_suffix(".tmp")
        tmp.write_text(json.dumps({"values": {n: p["value"] for n, p in params.items()}, "saved": saved,
                                   "seen": seen}))
        os.replace(tmp, args.state)

    uavcan = dronecan.uavcan
    get_set = uavcan.protocol.param.GetSet

    def numeric(p: dict[str, Any], key: str) -> Any:
        v = uavcan.protocol.param.NumericValue()
        if key in p:
            if p["kind"] == "int":
                v.integer_value = p[key]
            else:
                v.real_value = p[key]
        return v

    def value_of(p: dict[str, Any], key: str) -> Any:
        v = uavcan.protocol.param.Value()
        if p["kind"] == "bool":
            v.boolean_value = p[key]
        elif p["kind"] == "int":
            v.integer_value = p[key]
        else:
            v.real_value = p[key]
        return v

    def on_get_set(event: Any) -> Any:
        req = event.request
        name = bytes(req.name).decode()
        if name:
            seen["get_by_name"] += 1
        else:
            seen["get_by_index"] += 1
            name = order[req.index] if req.index < len(order) else ""
        p = params.get(name)
        if p is None:
            seen["unknown"] += 1
            write_state()
            return get_set.Response()  # empty name and value: no such parameter
        given = dronecan.get_active_union_field(req.value)
        if given != "empty":
            seen["set"] += 1
            wanted = {"bool": "boolean_value", "int": "integer_value", "real": "real_value"}[p["kind"]]
            if given == wanted and name not in args.read_only:
                v = getattr(req.value, given)
                p["value"] = bool(v) if p["kind"] == "bool" else min(max(v, p["min"]), p["max"])
            else:
                seen["set_kept"] += 1
        write_state()
        resp = get_set.Response(name=name)
        resp.value = value_of(p, "value")
        resp.default_value = value_of(p, "default")
        resp.min_value = numeric(p, "min")
        resp.max_value = numeric(p, "max")
        return resp

    def on_opcode(event: Any) -> Any:
        op = event.request.opcode
        ok = op in (event.request.OPCODE_SAVE, event.request.OPCODE_ERASE)
        if op == event.request.OPCODE_SAVE:
            seen["save"] += 1
            saved.clear()
            saved.update({n: p["value"] for n, p in params.items()})
        elif op == event.request.OPCODE_ERASE:
            seen["erase"] += 1
            for p in params.values():
                p["value"] = p["default"]
        write_state()
        return uavcan.protocol.param.ExecuteOpcode.Response(ok=ok)

    info = uavcan.protocol.GetNodeInfo.Response()
    info.name = "org.test.independent_board"
    node = dronecan.node.Node(make_driver(args.iface), node_id=args.node_id, node_status_interval=1.0,
                              mode=uavcan.protocol.NodeStatus().MODE_OPERATIONAL, node_info=info)
    node.add_handler(get_set, on_get_set)
    node.add_handler(uavcan.protocol.param.ExecuteOpcode, on_opcode)
    stop = []
    for sig in (signal.SIGTERM, signal.SIGINT):
        signal.signal(sig, lambda *_: stop.append(True))
    write_state()
    print("READY", flush=True)
    try:
        while not stop:
            node.spin(0.1)
    finally:
        node.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
