"""Synthetic specs of N message types for the generator benchmark (issue 5, part 1).

``write_spec(n, path)`` writes a valid spec with
- N DSDL types ``syn.gK.TypeI.0.1`` (100 per namespace), each a handful of fields of varied widths: a timestamp
  on half of them, variable-size integers (int3..int37, uint2..uint31), float16/float32/float64, a fixed
  float16[3], a bounded uint8[<=8], a bool;
- N ROS messages: even-numbered types are ``derive_from`` their DSDL type and mapped UAVCAN->ROS with
  ``fields: auto``; odd-numbered ones are declared field by field (widened by hand, a scale on one float) and
  mapped ROS->UAVCAN line by line;
- N topics, N mappings, N subjects (ids 1000..1000+N-1 < 8192) on ceil(N/10) devices (node ids 1..100: at most
  100 devices, so a device carries up to N/100 subjects), a few frames, parameters and ROS nodes.

Run as a script to write and validate the specs: ``python -m bench.synthetic [N ...]``.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path
from typing import Any

import yaml

INT_WIDTHS = (3, 7, 13, 18, 27, 37)  # signed: int3 .. int37
UINT_WIDTHS = (2, 6, 11, 16, 24, 31)
FLOAT_WIDTHS = (16, 32, 64)
FIRST_SUBJECT = 1000
MAX_DEVICES = 100
BRIDGE_NODE_ID = 127


def _widen(kind: str, bits: int) -> str:
    for size in (8, 16, 32, 64):
        if bits <= size:
            return f"{kind}{size}"
    raise ValueError(bits)


def _dsdl_fields(i: int) -> list[dict[str, Any]]:
    """The fields of type i: varied widths, the same shape every 6 types."""
    ib, ub, fb = INT_WIDTHS[i % 6], UINT_WIDTHS[(i // 2) % 6], FLOAT_WIDTHS[i % 3]
    fields: list[dict[str, Any]] = []
    if i % 2 == 0 or i % 4 == 1:
        fields.append({"name": "timestamp", "type": "uavcan.time.SynchronizedTimestamp.1.0",
                       "comment": "Sample time [us]; 0 = unknown."})
    fields += [
        {"name": "value_a", "type": f"int{ib}", "comment": f"A signed {ib}-bit value."},
        {"name": "value_b", "type": f"uint{ub}", "comment": f"An unsigned {ub}-bit value."},
        {"name": "level", "type": f"float{fb}", "comment": "A float."},
        {"name": "vector", "type": "float16[3]", "comment": "A three-vector."},
        {"name": "flag", "type": "bool", "comment": "A flag."},
    ]
    if i % 3 == 0:
        fields.append({"name": "samples", "type": "uint8[<=8]", "comment": "Up to 8 bytes."})
    if i % 5 == 0:
        fields.append({"name": "gain", "type": "float32", "comment": "A gain."})
    return fields


def _ros_type(dsdl_type: str) -> str:
    if dsdl_type.startswith("int"):
        return _widen("int", int(dsdl_type[3:]))
    if dsdl_type.startswith("uint") and "[" not in dsdl_type:
        return _widen("uint", int(dsdl_type[4:]))
    return {"float16": "float32", "float32": "float32", "float64": "float64", "bool": "bool",
            "float16[3]": "float32[3]", "uint8[<=8]": "uint8[<=8]"}[dsdl_type]


def make_spec(n: int) -> dict[str, Any]:
    """The spec of n types as a plain dict (YAML-ready)."""
    if not 1 <= n <= 8192 - FIRST_SUBJECT:
        raise ValueError(f"n must be 1..{8192 - FIRST_SUBJECT}")
    n_dev = min(MAX_DEVICES, max(1, math.ceil(n / 10)))
    spec: dict[str, Any] = {
        "spec_version": 1,
        "vehicle": {"name": "syn", "description": f"A synthetic vehicle with {n} message types (benchmark)."},
        "ros": {"package": "syn_msgs", "version": "0.1.0", "description": "Synthetic messages (benchmark)."},
        "cyphal": {"root_namespace": "syn"},
        "messages": {},
        "dsdl_types": {},
        "frames": {"base_link": {"description": "Body frame."}, "sensor_link": {"parent": "base_link"}},
        "topics": {},
        "parameters": {
            "/warn_level": {"type": "double", "unit": "m", "default": 1.0, "min": 0.0, "max": 10.0},
            "/alarm_level": {"type": "double", "unit": "m", "default": 2.0, "min": 0.0, "max": 10.0},
        },
        "parameter_rules": [{"left": "/alarm_level", "op": ">", "right": "/warn_level"}],
        "devices": {},
        # N subjects at 10-60 Hz is far more than one CAN bus carries (the build refuses an overloaded bus): the
        # synthetic vehicle is Cyphal/UDP only, which has no bus budget.
        "bus": "none",
        "bridge": {"name": "syn_bridge", "node_id": BRIDGE_NODE_ID, "mappings": {}},
        "nodes": {"consumer": {"description": "Reads every sensor topic.", "subscribes": [],
                               "parameters": ["/warn_level"]},
                  "producer": {"description": "Writes every command topic.", "publishes": []}},
    }
    devices: list[dict[str, Any]] = [
        {"node_id": 1 + d, "description": f"Synthetic device {d}.", "publishes": [], "subscribes": []}
        for d in range(n_dev)
    ]
    for i in range(n):
        dsdl_name = f"syn.g{i // 100}.Type{i}.0.1"
        fields = _dsdl_fields(i)
        struct: dict[str, Any] = {"description": f"Synthetic type {i}.", "fields": fields}
        if i % 2:
            struct["sealed"] = True
        else:
            struct["extent"] = 128
        if i % 7 == 0:
            struct["constants"] = [{"name": "MODE_IDLE", "type": "uint8", "value": 0},
                                   {"name": "MODE_RUN", "type": "uint8", "value": 1}]
        spec["dsdl_types"][dsdl_name] = struct
        msg_name = f"Msg{i}"
        topic = f"/syn/g{i // 100}/t{i}"
        subject = FIRST_SUBJECT + i
        dev = devices[i % n_dev]
        spec["topics"][topic] = {"type": f"syn_msgs/{msg_name}", "description": f"Topic of type {i}."}
        names = {f["name"] for f in fields}
        if i % 2 == 0:  # derived, UAVCAN -> ROS, fields: auto
            spec["messages"][msg_name] = {"description": f"Derived from type {i}.", "derive_from": dsdl_name}
            dev["publishes"].append({"subject_id": subject, "type": dsdl_name, "rate_hz": 10 + i % 50})
            spec["bridge"]["mappings"][f"m{i}"] = {
                "direction": "uavcan_to_ros", "subject_id": subject, "topic": topic,
                "source_node_ids": [dev["node_id"]], "frame_id": "sensor_link" if i % 4 == 0 else "base_link",
                "fields": "auto",
            }
            spec["nodes"]["consumer"]["subscribes"].append(topic)
        else:  # declared by hand, ROS -> UAVCAN, line by line
            ros_fields = [{"name": "header", "type": "std_msgs/Header"}]
            links: dict[str, Any] = {}
            for f in fields:
                if f["name"] == "timestamp":
                    links["header.stamp"] = "timestamp.microsecond"
                    continue
                ros_name = f"ros_{f['name']}"
                ros_fields.append({"name": ros_name, "type": _ros_type(f["type"]), "comment": f["comment"]})
                if f["name"] == "level" and f["type"] != "float64":
                    links[ros_name] = {"from": "level", "scale": 0.5}
                elif f["name"] == "gain":
                    links[ros_name] = {"from": "gain", "limits": [0, 100]}
                else:
                    links[ros_name] = f["name"]
            assert names
            spec["messages"][msg_name] = {"description": f"Declared for type {i}.", "fields": ros_fields}
            dev["subscribes"].append({"subject_id": subject, "type": dsdl_name, "rate_hz": 5 + i % 20})
            spec["bridge"]["mappings"][f"m{i}"] = {
                "direction": "ros_to_uavcan", "subject_id": subject, "topic": topic,
                "destination_node_id": dev["node_id"], "fields": links,
            }
            spec["nodes"]["producer"]["publishes"].append(topic)
    for d, dev in enumerate(devices):
        entry = {k: v for k, v in dev.items() if v != []}
        spec["devices"][f"dev{d}"] = entry
    if not spec["nodes"]["producer"]["publishes"]:
        del spec["nodes"]["producer"]
    if not spec["nodes"]["consumer"]["subscribes"]:
        del spec["nodes"]["consumer"]["subscribes"]
    return spec


def write_spec(n: int, path: Path) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    text = f"# Synthetic spec of {n} message types, written by bench/synthetic.py; do not edit.\n"
    text += yaml.safe_dump(make_spec(n), sort_keys=False, width=120)
    path.write_text(text, encoding="utf-8")
    return path


def validate_spec(path: Path) -> Any:
    """Parse and validate with sam_codegen (raises SpecError with every problem)."""
    from sam_codegen.frontend.loader import load_spec_file
    from sam_codegen.validate.resolve import validate

    return validate(load_spec_file(Path(path)))


def main(argv: list[str]) -> int:
    out = Path(__file__).resolve().parent / "results" / "tmp" / "specs"
    for n in [int(a) for a in argv] or [10, 100, 1000]:
        p = write_spec(n, out / f"syn{n}.yaml")
        resolved = validate_spec(p)
        print(f"{p}: valid, {len(resolved.dsdl_types)} DSDL types, {len(resolved.messages)} ROS messages, "
              f"{len(resolved.mappings)} mappings")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
