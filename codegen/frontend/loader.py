"""YAML spec -> model: structure, field names and value types. Cross-references are checked in validate.

The top level is read here; its sections in frontend.types, frontend.bridge and frontend.nodes, all with
frontend.reading's helpers. Every model object is built whole from what was read, and the Spec last: nothing is
changed after it is built (the model is frozen). Each topic's effective QoS is chosen here, once the bridge's
mappings are known; the TF topics the nodes' transforms imply join the declared ones first (frontend.topic_sources).
"""

from __future__ import annotations

import os
import stat
from dataclasses import replace
from pathlib import Path

from sam_codegen.frontend.bridge import parse_device, parse_layout, parse_mapping
from sam_codegen.frontend.bus import parse_bus
from sam_codegen.frontend.node_services import parse_node_services, with_duty_srvs
from sam_codegen.frontend.nodes import (
    QOS_DEPTH_MAX,
    parse_frame,
    parse_node,
    parse_parameter,
    parse_qos,
    parse_topic_qos,
)
from sam_codegen.frontend.reading import Reader, map_items, scalar, seq_items, str_list, text_of
from sam_codegen.frontend.services import parse_service_mapping
from sam_codegen.frontend.time_sync import parse_time_sync
from sam_codegen.frontend.topic_sources import implied_tf_topics, parse_published_by
from sam_codegen.frontend.traffic import check_enable_services
from sam_codegen.frontend.types import (
    parse_dronecan_type,
    parse_dsdl_service,
    parse_dsdl_struct,
    parse_ros_message,
    parse_ros_service,
)
from sam_codegen.frontend.yaml_source import YMap, YNode, YScalar, load_yaml
from sam_codegen.model.diagnostics import Diagnostic, Diagnostics, Pos, SpecError
from sam_codegen.model.protocols.cyphal import CYPHAL
from sam_codegen.model.protocols.dronecan import DRONECAN
from sam_codegen.model.protocols.registry import registered
from sam_codegen.model.spec import (
    UAVCAN_TO_ROS,
    Bridge,
    DsdlService,
    DsdlStruct,
    Frame,
    Mapping,
    Node,
    Parameter,
    ParameterRule,
    RosMessage,
    RosPackageInfo,
    RosService,
    Spec,
    Topic,
    Transform,
    V0Struct,
    default_qos,
)

# scalar, parse_qos and QOS_DEPTH_MAX have been importable from here since before the split.
__all__ = ["QOS_DEPTH_MAX", "load_spec_file", "parse_qos", "parse_spec", "scalar"]


_TOP_KEYS = (
    "spec_version", "vehicle", "ros", "cyphal", "external_messages", "messages", "dsdl_types", "dronecan_types",
    "frames", "transforms", "topics", "parameters", "parameter_rules", "devices", "layouts", "bridge", "nodes",
    "bus", "dronecan_namespaces", "services", "external_services",
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
                  ("package", "version", "description", "maintainer", "maintainer_email", "license",
                   "topics_message"))
    cyphal = Reader(top.node("cyphal") or YMap(top.pos), "cyphal", diag, ("root_namespace",))
    package = ros.get("package", str) or ""
    info = _package_info(ros, package)
    external_messages, messages = _ros_messages(top, package, diag)
    dsdl_types, dsdl_services = _dsdl_types(top, diag)
    frames: dict[str, Frame] = {}
    for key, pos, node in map_items(top.node("frames"), "frames", diag):
        frames[key] = parse_frame(key, pos, node, diag)
    transforms = _transforms(top, diag)
    declared_topics = _declared_topics(top, diag)  # their effective QoS comes once the bridge is read
    parameters: dict[str, Parameter] = {}
    for key, pos, node in map_items(top.node("parameters"), "parameters", diag):
        parameter = parse_parameter(key, pos, node, diag)
        if parameter is not None:
            parameters[key] = parameter
    parameter_rules = _parameter_rules(top, diag)
    dronecan_types: dict[str, V0Struct] = {}
    for key, pos, node in map_items(top.node("dronecan_types"), "dronecan_types", diag):
        dronecan_types[key] = parse_dronecan_type(key, pos, node, diag)
    devices = {key: parse_device(key, pos, node, diag)
               for key, pos, node in map_items(top.node("devices"), "devices", diag)}
    layouts = {key: parse_layout(key, pos, node, diag)
               for key, pos, node in map_items(top.node("layouts"), "layouts", diag)}
    bridge = _bridge(top.node("bridge"), package, diag)
    nodes: dict[str, Node] = {}
    for key, pos, node in map_items(top.node("nodes"), "nodes", diag):
        nodes[key] = parse_node(key, pos, node, diag)
    bridged = {m.topic for m in bridge.all_mappings if m.direction == UAVCAN_TO_ROS} if bridge is not None else set()
    declared_topics += implied_tf_topics({t.name: t for t in declared_topics}, nodes, frames)
    topics = {topic.name: _with_effective_qos(topic, bridged) for topic in declared_topics}
    bus = parse_bus(top.node("bus"), "bus", diag)
    namespaces = str_list(top.node("dronecan_namespaces"), "dronecan_namespaces", diag) \
        if top.node("dronecan_namespaces") is not None else None
    services = _ros_services(top, package, diag)
    services = with_duty_srvs(services, bridge, package)  # the device duties' default srvs (frontend.node_services)
    diag.check()
    return Spec(
        file, vehicle.get("name", str) or "", text_of(vehicle, "description"), info,
        cyphal.get("root_namespace", str) or "", external_messages, messages, dsdl_types, frames, transforms, topics,
        parameters, parameter_rules, devices, bridge, nodes, dronecan_types, layouts, bus,
        dronecan_namespaces=tuple(n for n, _ in namespaces) if namespaces is not None else None,
        dronecan_namespaces_pos=tuple(p for _, p in namespaces) if namespaces is not None else (),
        services=services, dsdl_services=dsdl_services,
    )


def _package_info(ros: Reader, package: str) -> RosPackageInfo:
    """The `ros` section: the spec's own ROS package."""
    return RosPackageInfo(package, ros.get("version", str, "0.1.0"), text_of(ros, "description"),
                          ros.get("maintainer", str, "maintainer"),
                          ros.get("maintainer_email", str, "maintainer@example.org"), ros.get("license", str, "MIT"),
                          ros.get("topics_message", str, None), ros.key_pos("topics_message"))


def _ros_messages(top: Reader, package: str,
                  diag: Diagnostics) -> tuple[dict[str, RosMessage], dict[str, RosMessage]]:
    """`external_messages` (pkg/Name) and `messages` (bare names, of the spec's package), by full name."""
    external_messages: dict[str, RosMessage] = {}
    for key, pos, node in map_items(top.node("external_messages"), "external_messages", diag):
        if "/" not in key:
            diag.error(pos, f"external message {key!r} needs its package", "pkg/Name")
            continue
        message = parse_ros_message(key, pos, node, package, True, diag)
        external_messages[message.full_name] = message
    messages: dict[str, RosMessage] = {}
    for key, pos, node in map_items(top.node("messages"), "messages", diag):
        if "/" in key:
            diag.error(pos, f"message {key!r} is declared in package {package}: give its bare name", "Name")
            continue
        message = parse_ros_message(key, pos, node, package, False, diag)
        messages[message.full_name] = message
    return external_messages, messages


def _dsdl_types(top: Reader, diag: Diagnostics) -> tuple[dict[str, DsdlStruct], dict[str, DsdlService]]:
    """`dsdl_types`: the structures, and the service types (an entry with a request or a response)."""
    dsdl_types: dict[str, DsdlStruct] = {}
    dsdl_services: dict[str, DsdlService] = {}
    for key, pos, node in map_items(top.node("dsdl_types"), "dsdl_types", diag):
        if isinstance(node, YMap) and ("request" in node.entries or "response" in node.entries):
            dsdl_services[key] = parse_dsdl_service(key, pos, node, diag)  # a service type
            continue
        dsdl_types[key] = parse_dsdl_struct(key, pos, node, diag)
    return dsdl_types, dsdl_services


def _transforms(top: Reader, diag: Diagnostics) -> list[Transform]:
    transforms: list[Transform] = []
    for item in seq_items(top.node("transforms"), "transforms", diag):
        r = Reader(item, "a transform", diag, ("parent", "child", "publisher", "description"))
        parent, child, publisher = r.get("parent", str), r.get("child", str), r.get("publisher", str)
        if parent and child and publisher:
            transforms.append(Transform(parent, child, publisher, text_of(r, "description"), item.pos))
    return transforms


def _declared_topics(top: Reader, diag: Diagnostics) -> list[Topic]:
    """`topics` as declared (a topic declared twice is an error), each with its declared QoS only."""
    topics_node = top.node("topics")
    if isinstance(topics_node, YMap):
        for key, pos, again in topics_node.duplicates:
            first = topics_node.entries[key]
            types = [t.value for n in (first, again) if isinstance(n, YMap)
                     for t in [n.entries.get("type")] if isinstance(t, YScalar)]
            diag.error(pos, f"topic {key!r} is declared twice (first at line {topics_node.key_pos[key].line}"
                       + (f", types {' and '.join(map(str, types))}" if types else "")
                       + "): two types on one topic", "one type per topic; give the second its own topic")
    declared_topics: list[Topic] = []
    for key, pos, node in map_items(topics_node, "topics", diag, duplicates=False):
        r = Reader(node, f"topic {key!r}", diag, ("type", "description", "section", "qos", "published_by"))
        type_ = r.get("type", str)
        qos_node = r.node("qos")
        pub_qos, sub_qos = (parse_topic_qos(qos_node, f"the QoS of topic {key!r}", diag) if qos_node is not None
                            else (None, None))
        external, external_pos = parse_published_by(r.node("published_by"), key, diag)
        if type_ is not None:
            declared_topics.append(Topic(key, type_.replace("/msg/", "/"), text_of(r, "description"),
                                         str(r.get("section", (str, float, int), "")), pos, pub_qos,
                                         qos_node.pos if qos_node is not None else pos,
                                         declared_subscriber_qos=sub_qos,
                                         external_publisher=external, external_pos=external_pos))
    return declared_topics


def _parameter_rules(top: Reader, diag: Diagnostics) -> list[ParameterRule]:
    parameter_rules: list[ParameterRule] = []
    for item in seq_items(top.node("parameter_rules"), "parameter_rules", diag):
        r = Reader(item, "a parameter rule", diag, ("left", "op", "right", "description"))
        left, op, right = r.get("left", str), r.get("op", str), r.get("right", str)
        if op is not None and op not in ("<", "<=", ">", ">="):
            diag.error(r.key_pos("op"), f"parameter rule operator {op!r} is unknown", "<, <=, > or >=")
        elif left and op and right:
            parameter_rules.append(ParameterRule(left, op, right, text_of(r, "description"), item.pos))
    return parameter_rules


def _bridge(bridge_node: YNode | None, package: str, diag: Diagnostics) -> Bridge | None:
    """The `bridge` section (None without one): its Cyphal and DroneCAN mappings, service mappings, time sync."""
    if bridge_node is None:
        return None
    r = Reader(bridge_node, "bridge", diag, ("name", "node_id", *(p.mappings_key for p in registered()),
                                             "panic_duty", "service_mappings", "time_sync", "node_services",
                                             "interface_check"))
    name, node_id = r.get("name", str) or "bridge", r.get("node_id", int) or 0
    mappings: dict[str, list[Mapping]] = {p.name: [] for p in registered()}
    for p in registered():
        for key, pos, node in map_items(r.node(p.mappings_key), f"bridge {p.mappings_key}", diag):
            mapping = parse_mapping(key, pos, node, diag, p.name)
            if mapping is not None:
                mappings[p.name].append(mapping)
    for protocol, protocol_mappings in mappings.items():
        check_enable_services(protocol_mappings, protocol, diag)
    service_mappings = [m for key, pos, node in map_items(r.node("service_mappings"), "bridge service_mappings",
                                                          diag)
                        for m in [parse_service_mapping(key, pos, node, diag)] if m is not None]
    return Bridge(name, node_id, mappings[CYPHAL.name], bridge_node.pos, mappings[DRONECAN.name],
                  service_mappings=service_mappings,
                  time_sync=parse_time_sync(r.node("time_sync"), "bridge time_sync", diag),
                  panic_duty=r.get("panic_duty", str, None), panic_duty_pos=r.key_pos("panic_duty"),
                  node_services=parse_node_services(r.node("node_services"), bridge_node.pos, package, diag),
                  interface_on_mismatch=_interface_check(r.node("interface_check"), diag))


INTERFACE_ON_MISMATCH = ("warn", "stop")


def _interface_check(node: YNode | None, diag: Diagnostics) -> str:
    """`bridge.interface_check: {on_mismatch: warn | stop}` (default warn): the bridge's answer to a board whose
    firmware reports another interface version than the spec's."""
    if node is None:
        return "warn"
    r = Reader(node, "bridge interface_check", diag, ("on_mismatch",))
    value = r.get("on_mismatch", str, "warn")
    if value not in INTERFACE_ON_MISMATCH:
        diag.error(r.key_pos("on_mismatch"), f"on_mismatch {value!r} of bridge interface_check is unknown",
                   " or ".join(INTERFACE_ON_MISMATCH))
        return "warn"
    return str(value)


def _ros_services(top: Reader, package: str, diag: Diagnostics) -> dict[str, RosService]:
    """`services`: the spec's own .srv types (bare names, of the spec's package), by full name."""
    services: dict[str, RosService] = {}
    for key, pos, node in map_items(top.node("services"), "services", diag):
        if "/" in key:
            diag.error(pos, f"service type {key!r} is declared in package {package}: give its bare name", "Name")
            continue
        srv = parse_ros_service(key, pos, node, package, diag)
        services[srv.full_name] = srv
    # `external_services`: srvs of other packages that existing clients are built against (as external_messages):
    # generated under generated/ros/<pkg>/ exactly as declared, named pkg/Name
    for key, pos, node in map_items(top.node("external_services"), "external_services", diag):
        pkg = key.split("/", 1)[0] if "/" in key else ""
        if not pkg or key.count("/") != 1:
            diag.error(pos, f"external service {key!r} needs its package", "pkg/Name")
            continue
        if pkg == package:
            diag.error(pos, f"external service {key!r} is of the spec's own package {package}",
                       "a srv of `services` (bare name)")
            continue
        srv = parse_ros_service(key, pos, node, pkg, diag, external=True)
        services[srv.full_name] = srv
    return services


def _with_effective_qos(topic: Topic, bridged: set[str]) -> Topic:
    """The topic with the QoS its endpoints use, per side: the declared one, else the ROS-convention default
    (validate.nodes checks that the subscribers' side is one the publishers' side serves)."""
    publishers, subscribers, origin = default_qos(topic, bridged)
    pub, sub = topic.declared_qos, topic.declared_subscriber_qos
    if pub is not None and sub is not None:
        origin = "declared"
    elif pub is not None or sub is not None:
        origin = f"{'publishers' if pub is not None else 'subscribers'} declared, the other side: {origin}"
    return replace(topic, qos=pub or publishers, subscriber_qos=sub or subscribers, qos_origin=origin)


# The largest spec file read: SAM's is 43 KB, a generated spec of 1000 types under 1 MB. A bound keeps `--spec
# /dev/zero` (or a runaway generator's output) from filling memory before the YAML reader's own bounds can act.
MAX_SPEC_BYTES = 8 * 1024 * 1024

_FILE_KINDS = ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO (named pipe)"),
               (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"))


def load_spec_file(path: Path) -> Spec:
    """Read and structurally parse a spec file (no cross-reference checks)."""
    return parse_spec(load_yaml(read_spec_text(path), str(path)), str(path))


def read_spec_text(path: Path) -> str:
    """The text of a spec file: a regular file of at most MAX_SPEC_BYTES bytes in UTF-8; else a SpecError that says
    what the path is. Opened without blocking, so that a FIFO is refused instead of waiting for a writer."""
    def refuse(why: str, expected: str | None = None) -> SpecError:
        return SpecError([Diagnostic(Pos(str(path)), f"cannot read the spec: {why}", expected)])

    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except OSError as exc:
        raise refuse(str(exc)) from None
    try:
        mode = os.fstat(fd).st_mode
        kind = next((what for test, what in _FILE_KINDS if test(mode)), None)
        if kind is not None or not stat.S_ISREG(mode):
            raise refuse(f"it is {kind or 'not a regular file'}", "a regular file holding the YAML spec")
        with os.fdopen(fd, "rb", closefd=False) as handle:
            data = handle.read(MAX_SPEC_BYTES + 1)  # a file that grows meanwhile is still read no further
    except OSError as exc:
        raise refuse(str(exc)) from None
    finally:
        os.close(fd)
    if len(data) > MAX_SPEC_BYTES:
        raise refuse(f"it is larger than {MAX_SPEC_BYTES:,} bytes", "a spec of at most 8 MiB")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise refuse(str(exc)) from None
