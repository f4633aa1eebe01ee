"""YAML spec -> model: structure, field names and value types. Cross-references are checked in validate.

The top level is read here; its sections in spec_types, spec_bridge and spec_nodes, all with spec_reading's helpers.
"""

from __future__ import annotations

from pathlib import Path

from sam_codegen.frontend.bridge import parse_device, parse_layout, parse_mapping
from sam_codegen.frontend.nodes import QOS_DEPTH_MAX, parse_frame, parse_node, parse_parameter, parse_qos
from sam_codegen.frontend.reading import Reader, map_items, scalar, seq_items, text_of
from sam_codegen.frontend.types import parse_dronecan_type, parse_dsdl_struct, parse_ros_message
from sam_codegen.frontend.yaml_source import YMap, YNode, YScalar, load_yaml
from sam_codegen.model.diagnostics import Diagnostics, Pos, SpecError
from sam_codegen.model.spec import Bridge, ParameterRule, RosPackageInfo, Spec, Topic, Transform

# scalar, parse_qos and QOS_DEPTH_MAX have been importable from here since before the split.
__all__ = ["QOS_DEPTH_MAX", "load_spec_file", "parse_qos", "parse_spec", "scalar"]


_TOP_KEYS = (
    "spec_version", "vehicle", "ros", "cyphal", "external_messages", "messages", "dsdl_types", "dronecan_types",
    "frames", "transforms", "topics", "parameters", "parameter_rules", "devices", "layouts", "bridge", "nodes",
)


def parse_spec(root: YNode, file: str) -> Spec:
    """Build the model from a YAML tree; raises SpecError with every structural problem found."""
    diag = Diagnostics()
    top = Reader(root, "the spec", diag, _TOP_KEYS)
    if not top.ok:
        diag.check()
    version = top.get("spec_version", int)
    if version is not None and version != 1:
        diag.error(top.key_pos("spec_version"), f"spec_version {version} is not supported", "1")
    vehicle = Reader(top.node("vehicle") or YMap(top.pos), "vehicle", diag, ("name", "description"))
    ros = Reader(top.node("ros") or YMap(top.pos), "ros", diag,
                  ("package", "version", "description", "maintainer", "maintainer_email", "license"))
    cyphal = Reader(top.node("cyphal") or YMap(top.pos), "cyphal", diag, ("root_namespace",))
    package = ros.get("package", str) or ""
    spec = Spec(
        file, vehicle.get("name", str) or "", text_of(vehicle, "description"),
        RosPackageInfo(package, ros.get("version", str, "0.1.0"), text_of(ros, "description"),
                       ros.get("maintainer", str, "maintainer"),
                       ros.get("maintainer_email", str, "maintainer@example.org"), ros.get("license", str, "MIT")),
        cyphal.get("root_namespace", str) or "",
    )
    for key, pos, node in map_items(top.node("external_messages"), "external_messages", diag):
        if "/" not in key:
            diag.error(pos, f"external message {key!r} needs its package", "pkg/Name")
            continue
        message = parse_ros_message(key, pos, node, package, True, diag)
        spec.external_messages[message.full_name] = message
    for key, pos, node in map_items(top.node("messages"), "messages", diag):
        if "/" in key:
            diag.error(pos, f"message {key!r} is declared in package {package}: give its bare name", "Name")
            continue
        message = parse_ros_message(key, pos, node, package, False, diag)
        spec.messages[message.full_name] = message
    for key, pos, node in map_items(top.node("dsdl_types"), "dsdl_types", diag):
        spec.dsdl_types[key] = parse_dsdl_struct(key, pos, node, diag)
    for key, pos, node in map_items(top.node("frames"), "frames", diag):
        spec.frames[key] = parse_frame(key, pos, node, diag)
    for item in seq_items(top.node("transforms"), "transforms", diag):
        r = Reader(item, "a transform", diag, ("parent", "child", "publisher", "description"))
        parent, child, publisher = r.get("parent", str), r.get("child", str), r.get("publisher", str)
        if parent and child and publisher:
            spec.transforms.append(Transform(parent, child, publisher, text_of(r, "description"), item.pos))
    topics = top.node("topics")
    if isinstance(topics, YMap):
        for key, pos, again in topics.duplicates:
            first = topics.entries[key]
            types = [n.entries["type"].value for n in (first, again)
                     if isinstance(n, YMap) and isinstance(n.entries.get("type"), YScalar)]
            diag.error(pos, f"topic {key!r} is declared twice (first at line {topics.key_pos[key].line}"
                       + (f", types {' and '.join(map(str, types))}" if types else "")
                       + "): two types on one topic", "one type per topic; give the second its own topic")
    for key, pos, node in map_items(topics, "topics", diag, duplicates=False):
        r = Reader(node, f"topic {key!r}", diag, ("type", "description", "section", "qos"))
        type_ = r.get("type", str)
        qos_node = r.node("qos")
        qos = parse_qos(qos_node, f"the QoS of topic {key!r}", diag) if qos_node is not None else None
        if type_ is not None:
            spec.topics[key] = Topic(key, type_.replace("/msg/", "/"), text_of(r, "description"),
                                     str(r.get("section", (str, float, int), "")), pos, qos,
                                     qos_node.pos if qos_node is not None else pos)
    for key, pos, node in map_items(top.node("parameters"), "parameters", diag):
        parse_parameter(spec, key, pos, node, diag)
    for item in seq_items(top.node("parameter_rules"), "parameter_rules", diag):
        r = Reader(item, "a parameter rule", diag, ("left", "op", "right", "description"))
        left, op, right = r.get("left", str), r.get("op", str), r.get("right", str)
        if op is not None and op not in ("<", "<=", ">", ">="):
            diag.error(r.key_pos("op"), f"parameter rule operator {op!r} is unknown", "<, <=, > or >=")
        elif left and op and right:
            spec.parameter_rules.append(ParameterRule(left, op, right, text_of(r, "description"), item.pos))
    for key, pos, node in map_items(top.node("dronecan_types"), "dronecan_types", diag):
        spec.dronecan_types[key] = parse_dronecan_type(key, pos, node, diag)
    for key, pos, node in map_items(top.node("devices"), "devices", diag):
        spec.devices[key] = parse_device(key, pos, node, diag)
    for key, pos, node in map_items(top.node("layouts"), "layouts", diag):
        spec.layouts[key] = parse_layout(key, pos, node, diag)
    bridge_node = top.node("bridge")
    if bridge_node is not None:
        r = Reader(bridge_node, "bridge", diag, ("name", "node_id", "mappings", "dronecan_mappings"))
        bridge = Bridge(r.get("name", str) or "bridge", r.get("node_id", int) or 0, pos=bridge_node.pos)
        for key, pos, node in map_items(r.node("mappings"), "bridge mappings", diag):
            mapping = parse_mapping(key, pos, node, diag)
            if mapping is not None:
                bridge.mappings.append(mapping)
        for key, pos, node in map_items(r.node("dronecan_mappings"), "bridge dronecan_mappings", diag):
            mapping = parse_mapping(key, pos, node, diag, "dronecan")
            if mapping is not None:
                bridge.dronecan_mappings.append(mapping)
        spec.bridge = bridge
    for key, pos, node in map_items(top.node("nodes"), "nodes", diag):
        parse_node(spec, key, pos, node, diag)
    diag.check()
    return spec


def load_spec_file(path: Path) -> Spec:
    """Read and structurally parse a spec file (no cross-reference checks)."""
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        from sam_codegen.model.diagnostics import Diagnostic

        raise SpecError([Diagnostic(Pos(str(path)), f"cannot read the spec: {exc}")]) from None
    return parse_spec(load_yaml(text, str(path)), str(path))
