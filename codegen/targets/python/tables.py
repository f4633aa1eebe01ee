"""The whole context of tables.py: the Cyphal devices, topics, mappings, parameters and frames, the DroneCAN devices,
types, mappings and layouts, and the nodes' QoS, transforms and endpoints, as Python literals; texts (descriptions),
lists of literals and calls (Call) are left for templates/python/tables.py.j2 to place and wrap (render.pysource's
filters).

This module owns tables.py: the other targets give it names (targets.nodes, targets.ros, targets.dsdl_v0,
convert_v0.used_types) and import nothing of it. Every spec text reaches the output through py_str (repr: inert).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from sam_codegen.contracts import table_types
from sam_codegen.model.protocols.cyphal import CYPHAL
from sam_codegen.model.protocols.dronecan import DRONECAN
from sam_codegen.model.spec import UAVCAN_TO_ROS, Mapping, Port, Qos, V0Struct
from sam_codegen.render.filters import py_number, py_str
from sam_codegen.render.pysource import Call, float_literal, frozenset_literal, py_literal, text_literal
from sam_codegen.targets import dsdl_v0
from sam_codegen.targets.nodes import nodes_package, params_file, static_transforms
from sam_codegen.targets.python.convert_v0 import used_types
from sam_codegen.targets.python.names import py_class_name, py_module
from sam_codegen.targets.ros import build_order
from sam_codegen.validate.interface_version import interface_versions
from sam_codegen.validate.mapping_rules import format_path
from sam_codegen.validate.nodes import class_name, node_topic_qos
from sam_codegen.validate.panic_duty import panic_duty
from sam_codegen.validate.resolve import Resolved

__all__ = ["cyphal_context", "device_parameters_context", "dronecan_context", "nodes_context", "table_types_source",
           "tables_context", "time_sync_context"]


def _ros_type_parts(full: str) -> tuple[str, str, str]:
    """`sensor_msgs/Imu` -> ("sensor_msgs/msg/Imu", "sensor_msgs.msg", "Imu")."""
    package, name = full.split("/")
    return f"{package}/msg/{name}", f"{package}.msg", name


def _port_info(resolved: Resolved, port: Port) -> Call:
    struct = resolved.dsdl.get(port.type)
    assert struct is not None, port.type
    args = (str(port.subject_id), py_str(port.type), py_str(py_module(struct.namespace)),
            py_str(py_class_name(struct)), py_literal(float(port.rate_hz)))
    return Call("PortInfo", args, ("subject_id", "dsdl_type", "dsdl_module", "dsdl_class", "rate_hz"))


def _traffic(m: Mapping) -> dict[str, str]:
    """A mapping's run-time traffic control as literals (the enable service with its default filled in)."""
    return {"max_rate_hz": py_literal(m.max_rate_hz), "deadline_s": py_literal(m.deadline_s),
            "enabled": py_literal(m.enabled), "enable_service": py_str(m.enable_service_name)}


def cyphal_context(resolved: Resolved) -> dict[str, Any]:
    """The Cyphal part of tables.py and what every spec has (topics, parameters, frames, the bridge)."""
    spec = resolved.spec
    versions = interface_versions(resolved)
    devices = [{
        "name": py_str(d.name), "node_id": str(d.node_id), "description": d.description,
        "interface_hash": f"0x{versions.of(d.name):016x}",
        "publishes": [_port_info(resolved, p) for p in d.publishes],
        "subscribes": [_port_info(resolved, p) for p in d.subscribes],
    } for d in spec.devices.values() if CYPHAL.name in d.protocols]
    topics = []
    for topic in spec.topics.values():
        ros_type, module, cls = _ros_type_parts(topic.type)
        topics.append({"name": py_str(topic.name), "ros_type": py_str(ros_type), "ros_module": py_str(module),
                       "ros_class": py_str(cls), "description": topic.description})
    ports: dict[int, Port] = {}
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
            "port": _port_info(resolved, ports[m.subject_id]),
            "source_node_ids": "frozenset({" + ", ".join(map(str, sources)) + "})" if sources else "frozenset()",
            "destination_node_id": py_literal(m.destination_node_id),
            "frame_id": py_str(m.frame_id) if m.frame_id is not None else "None",
            "rate_hz": py_literal(float(rm.rate_hz)), "on_out_of_range": py_str(m.on_out_of_range),
            "to_ros": py_str(f"{m.name}_to_ros"), "to_uavcan": py_str(f"{m.name}_to_uavcan"),
            "exact_uavcan_fields": exact, "linked_uavcan_fields": linked, "any_node": m.any_node, **_traffic(m),
        })
    parameters = []
    for param in spec.parameters.values():
        default = float(param.default) if param.type == "double" else param.default
        parameters.append({
            "name": py_str(param.name), "type": py_str(param.type),
            # text is the template's to wrap; other values are literals already
            "default_text": default if isinstance(default, str) else None,
            # NaN (`allow_nan: true`) as an expression: the module has no _NAN constant for py_literal to name
            "default": py_number(default) if isinstance(default, float) and math.isnan(default)
            else py_literal(default),
            "minimum": py_literal(None if param.minimum is None else float(param.minimum)),
            "maximum": py_literal(None if param.maximum is None else float(param.maximum)),
            "unit": py_str(param.unit), "description": param.description,
        })
    rules = [{"left": py_str(r.left), "op": py_str(r.op), "right": py_str(r.right),
              "description": r.description} for r in spec.parameter_rules]
    frames = [(py_str(f.name), py_str(f.parent) if f.parent is not None else "None") for f in spec.frames.values()]
    bridge = spec.bridge
    return {
        "vehicle_literal": py_str(spec.vehicle), "ros_package": py_str(spec.ros.name),
        "dsdl_root": py_str(spec.dsdl_root),
        "bridge_name": py_str(bridge.name) if bridge else "None",
        "bridge_node_id": str(bridge.node_id) if bridge else "None",
        "devices": devices, "topics": topics,
        "mappings": mappings, "parameters": parameters, "rules": rules, "frames": frames,
        **time_sync_context(resolved),
    }


def time_sync_context(resolved: Resolved) -> dict[str, Any]:
    """The bridge's time-sync master (its period, None when off or without a bridge) and, per protocol, the
    UAVCAN->ROS mappings whose header.stamp is the device's own timestamp (0 = unknown: the receive time, counted)."""
    bridge = resolved.spec.bridge
    period = bridge.time_sync.period_s if bridge is not None and bridge.time_sync.enabled else None

    def stamped(mappings: list[Any]) -> list[str]:
        return [py_str(n) for n in sorted({rm.mapping.name for rm in mappings
                                           if rm.mapping.direction == UAVCAN_TO_ROS and rm.stamp_from_source})]

    return {"time_sync_period": py_literal(period), "device_stamped": stamped(resolved.mappings),
            "dronecan_device_stamped": stamped(resolved.dronecan_mappings)}


def _type_info(struct: V0Struct) -> str:
    return (f"DroneCanTypeInfo({py_str(struct.name)}, {struct.data_type_id}, 0x{struct.signature:016X}, "
            f"{not struct.standard})")


def _tuple_literal(names: tuple[str, ...]) -> str:
    """
    >>> _tuple_literal(("uavcan",)), _tuple_literal(("uavcan", "ardupilot"))
    ("('uavcan',)", "('uavcan', 'ardupilot')")
    """
    return "(" + ", ".join(py_str(n) for n in names) + ("," if len(names) == 1 else "") + ")"


def _type_ref(struct: V0Struct) -> str:
    return f"_DRONECAN_TYPE[{py_str(struct.name)}]"


def _dronecan_port_info(struct: V0Struct, rate_hz: float) -> Call:
    return Call("DroneCanPortInfo", (_type_ref(struct), py_literal(float(rate_hz))))


def dronecan_context(resolved: Resolved) -> dict[str, Any]:
    """The DroneCAN entries of tables.py (empty for a spec without DroneCAN) and the layouts."""
    spec = resolved.spec
    catalog = resolved.dronecan
    versions = interface_versions(resolved)
    types = {t.name: t for t in used_types(resolved)} if catalog is not None else {}
    devices = []
    for d in spec.devices.values():
        if DRONECAN.name not in d.protocols:
            continue
        devices.append({
            "name": py_str(d.name), "node_id": str(d.node_id), "description": d.description,
            "interface_hash": f"0x{versions.of(d.name):016x}",
            "publishes": [_dronecan_port_info(types[p.type], p.rate_hz) for p in d.dronecan_publishes],
            "subscribes": [_dronecan_port_info(types[p.type], p.rate_hz) for p in d.dronecan_subscribes],
        })
    mappings = []
    for rm in resolved.dronecan_mappings:
        m = rm.mapping
        struct = types[rm.dsdl_struct.name]
        select = [f"({py_str(format_path(list(p)))}, {py_literal(v)})" for p, _, v in rm.select]
        elements = [py_str(f"{format_path(list(path))}[{u}]") for path, uses in rm.elements.items() for u in uses]
        mappings.append({
            "name": py_str(m.name), "direction": py_str(m.direction), "topic": py_str(m.topic),
            "data_type": _type_ref(struct), "select": select, "elements": elements,
            "source_node_ids": frozenset_literal(m.source_node_ids),
            "destination_node_ids": frozenset_literal(m.destination_node_ids),
            "frame_id": py_str(m.frame_id) if m.frame_id is not None else "None",
            "rate_hz": py_literal(float(rm.rate_hz)), "on_out_of_range": py_str(m.on_out_of_range),
            "to_ros": py_str(f"{m.name}_to_ros"), "to_uavcan": py_str(f"{m.name}_to_uavcan"),
            "exact_uavcan_fields": [py_str(s.uavcan) for s in rm.steps if s.uavcan_path and s.exact],
            "linked_uavcan_fields": [py_str(s.uavcan) for s in rm.steps if s.uavcan_path],
            "any_node": m.any_node, **_traffic(m),
        })
    layouts = [{
        "name": py_str(layout.name), "description": layout.description,
        "protocols": [f"({py_str(d)}, {py_str(p)})" for d, p in layout.protocols.items()],
        "cyphal_mappings": [py_str(n) for n in layout.cyphal_mappings],
        "dronecan_mappings": [py_str(n) for n in layout.dronecan_mappings],
    } for layout in resolved.layouts]
    chosen = spec.dronecan_namespaces
    return {
        "dronecan_dirs": [py_str(d) for d in dsdl_v0.load_dirs(resolved)],
        "dronecan_namespaces": "None" if chosen is None or catalog is None else _tuple_literal(catalog.namespaces),
        "panic_duty": py_str(panic_duty(spec)),
        "dronecan_types": [_type_info(t) for t in types.values()],
        "dronecan_devices": devices,
        "dronecan_mappings": mappings,
        "layouts": layouts,
    }


def nodes_context(resolved: Resolved) -> dict[str, Any]:
    """The QoS, transforms and nodes of tables.py (as literals)."""
    spec = resolved.spec
    package = nodes_package(spec)

    def qos_info(qos: Qos) -> str:
        return f"QosInfo({py_str(qos.reliability)}, {py_str(qos.durability)}, {qos.depth}, {py_str(qos.profile)})"

    def endpoints(node_items: list, subscription: bool) -> list[str]:
        return [f"EndpointInfo({py_str(i.topic)}, {qos_info(node_topic_qos(spec, i, subscription=subscription))})"
                for i in node_items]

    nodes = []
    for n in spec.nodes.values():
        nodes.append({
            "name": py_str(n.name), "description": n.description,
            "module": py_str(f"{package}.{n.name}"), "base_class": py_str(class_name(n.name)),
            "publishes": endpoints(n.publish_items, False), "subscribes": endpoints(n.subscribe_items, True),
            "parameters": [py_str(p) for p in n.parameters],
            "transforms": [f"({py_str(p)}, {py_str(c)})" for p, c in n.transforms],
            "reads_transforms": [f"({py_str(p)}, {py_str(c)})" for p, c in n.reads_transforms],
        })
    return {
        "topic_qos": {py_str(t.name): qos_info(t.qos) for t in spec.topics.values() if t.qos is not None},
        "topic_subscriber_qos": {py_str(t.name): qos_info(t.subscriber_qos) for t in spec.topics.values()
                                 if t.subscriber_qos is not None},
        "static_transforms": [{"parent": py_str(p), "child": py_str(c), "xyz": ", ".join(map(float_literal, xyz)),
                               "rotation": ", ".join(map(float_literal, q))}
                              for p, c, xyz, q in static_transforms(spec)],
        "transforms": [f"TransformInfo({py_str(t.parent)}, {py_str(t.child)}, {py_str(t.publisher)})"
                       for t in spec.transforms],
        "nodes": nodes, "nodes_package": py_str(package), "params_file": py_str(params_file(spec)),
        "ros_packages": [py_str(name) for name in build_order(resolved)],
    }


def device_parameters_context(resolved: Resolved) -> dict[str, Any]:
    """Every board's settings (DEVICE_PARAMETERS), device by device in spec order."""
    keywords = ("device", "name", "type", "default", "description", "minimum", "maximum", "unit", "values",
                "max_length", "restart", "names")
    calls = []
    for device in resolved.spec.devices.values():
        for p in device.parameters:
            args = (py_str(device.name), py_str(p.name), py_str(p.type), py_literal(p.default),
                    text_literal(p.description, 20), py_literal(p.minimum), py_literal(p.maximum), py_str(p.unit),
                    repr(tuple(p.values)), py_literal(p.max_length), py_literal(p.restart), repr(tuple(p.names)))
            calls.append(Call("DeviceParameterInfo", args, keywords))
    return {"device_parameters": calls}


def table_types_source() -> str:
    """The classes of table_types.py as source text: the module after its docstring, copied into tables.py."""
    assert table_types.__file__ is not None
    text = Path(table_types.__file__).read_text(encoding="utf-8")
    return text[text.index("from __future__ import annotations"):].rstrip("\n")


def tables_context(resolved: Resolved) -> dict[str, Any]:
    """Everything templates/python/tables.py.j2 renders."""
    return {"table_types": table_types_source(), **cyphal_context(resolved), **nodes_context(resolved),
            **dronecan_context(resolved), "interface_hash": f"0x{interface_versions(resolved).whole:016x}",
            "interface_on_mismatch": py_str(resolved.spec.bridge.interface_on_mismatch
                                            if resolved.spec.bridge is not None else "warn"),
            **device_parameters_context(resolved)}
