"""The context of tables.py (devices, topics, mappings, parameters and frames as Python literals) and the literal
helpers the other tables emitters share."""

from __future__ import annotations

import re
from typing import Any

from sam_codegen.model.spec import Port
from sam_codegen.render.filters import py_str
from sam_codegen.targets.python.names import LINE_LIMIT, py_class_name, py_module
from sam_codegen.targets.python.statements import py_literal
from sam_codegen.validate.resolve import Resolved


def _ros_type_parts(full: str) -> tuple[str, str, str]:
    """`sensor_msgs/Imu` -> ("sensor_msgs/msg/Imu", "sensor_msgs.msg", "Imu")."""
    package, name = full.split("/")
    return f"{package}/msg/{name}", f"{package}.msg", name


def _text(text: str, indent: int) -> str:
    """A string literal (py_str: repr, inert) at `indent`; long text becomes implicitly concatenated chunks."""
    literal = py_str(text)
    if indent + len(literal) <= LINE_LIMIT - 10:
        return literal
    chunks: list[str] = []
    for word in re.findall(r"\S*\s*", text):
        if chunks and len(py_str(chunks[-1] + word)) + indent + 4 <= LINE_LIMIT - 2:
            chunks[-1] += word
        elif word:
            chunks.append(word)
    pad = " " * (indent + 4)
    return "(\n" + "".join(f"{pad}{py_str(c)}\n" for c in chunks) + " " * indent + ")"


def _tuple(items: list[str], indent: int) -> str:
    """A tuple literal of rendered items, on one line if it fits."""
    if not items:
        return "()"
    one = "(" + ", ".join(items) + ("," if len(items) == 1 else "") + ")"
    if indent + len(one) <= LINE_LIMIT - 30:
        return one
    pad = " " * (indent + 4)
    return "(\n" + "".join(f"{pad}{item},\n" for item in items) + " " * indent + ")"


def _port_info(resolved: Resolved, port: Port, indent: int, prefix: int = 0) -> str:
    """A PortInfo(...) at `indent`, after `prefix` characters on its line and before a comma."""
    struct = resolved.dsdl.get(port.type)
    assert struct is not None, port.type
    args = [str(port.subject_id), py_str(port.type), py_str(py_module(struct.namespace)),
            py_str(py_class_name(struct)), py_literal(float(port.rate_hz))]
    one = "PortInfo(" + ", ".join(args) + ")"
    if indent + prefix + len(one) + 1 <= LINE_LIMIT:
        return one
    names = ("subject_id", "dsdl_type", "dsdl_module", "dsdl_class", "rate_hz")
    pad = " " * (indent + 4)
    return "PortInfo(\n" + "".join(f"{pad}{k}={v},\n" for k, v in zip(names, args, strict=True)) + " " * indent + ")"


def _tables_context(resolved: Resolved) -> dict[str, Any]:
    spec = resolved.spec
    devices = [{
        "name": py_str(d.name), "node_id": str(d.node_id), "description": _text(d.description, 8),
        "publishes": [_port_info(resolved, p, 12) for p in d.publishes],
        "subscribes": [_port_info(resolved, p, 12) for p in d.subscribes],
    } for d in spec.devices.values() if "cyphal" in d.protocols]
    topics = []
    for topic in spec.topics.values():
        ros_type, module, cls = _ros_type_parts(topic.type)
        topics.append({"name": py_str(topic.name), "ros_type": py_str(ros_type), "ros_module": py_str(module),
                       "ros_class": py_str(cls), "description": _text(topic.description, 8)})
    ports = {}
    for d in spec.devices.values():
        for p in [*d.publishes, *d.subscribes]:
            ports.setdefault(p.subject_id, p)
    mappings = []
    for rm in resolved.mappings:
        m = rm.mapping
        linked = [py_str(s.uavcan) for s in rm.steps if s.uavcan_path]
        exact = [py_str(s.uavcan) for s in rm.steps if s.uavcan_path and s.exact]
        sources = sorted(set(m.source_node_ids))
        mappings.append({
            "name": py_str(m.name), "direction": py_str(m.direction), "topic": py_str(m.topic),
            "port": _port_info(resolved, ports[m.subject_id], 8, len("port=")),
            "source_node_ids": "frozenset({" + ", ".join(map(str, sources)) + "})" if sources else "frozenset()",
            "destination_node_id": py_literal(m.destination_node_id),
            "frame_id": py_str(m.frame_id) if m.frame_id is not None else "None",
            "rate_hz": py_literal(float(rm.rate_hz)), "on_out_of_range": py_str(m.on_out_of_range),
            "to_ros": py_str(f"{m.name}_to_ros"), "to_uavcan": py_str(f"{m.name}_to_uavcan"),
            "exact_uavcan_fields": _tuple(exact, 8), "linked_uavcan_fields": _tuple(linked, 8),
        })
    parameters = []
    for p in spec.parameters.values():
        default = p.default
        if p.type == "double":
            default = float(default)
        parameters.append({
            "name": py_str(p.name), "type": py_str(p.type),
            "default": _text(default, 8) if isinstance(default, str) else py_literal(default),
            "minimum": py_literal(None if p.minimum is None else float(p.minimum)),
            "maximum": py_literal(None if p.maximum is None else float(p.maximum)),
            "unit": py_str(p.unit), "description": _text(p.description, 8),
        })
    rules = [{"left": py_str(r.left), "op": py_str(r.op), "right": py_str(r.right),
              "description": _text(r.description, 8)} for r in spec.parameter_rules]
    frames = [(py_str(f.name), py_str(f.parent) if f.parent is not None else "None") for f in spec.frames.values()]
    bridge = spec.bridge
    return {
        "vehicle_literal": py_str(spec.vehicle), "ros_package": py_str(spec.ros.name),
        "dsdl_root": py_str(spec.dsdl_root),
        "bridge_name": py_str(bridge.name) if bridge else "None",
        "bridge_node_id": str(bridge.node_id) if bridge else "None",
        "devices": devices, "topics": topics,
        "mappings": mappings, "parameters": parameters, "rules": rules, "frames": frames,
    }
