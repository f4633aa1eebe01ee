"""The interface reference (docs/interfaces.md): what its template shows, computed from the spec.

markdown_context gives the template's variables, one builder per part of the document: topics, messages (the
package's and the external ones), parameters and their rules, frames and transforms, devices, subjects, the bridge,
DSDL types, the bridge's mappings and the nodes. (The DroneCAN part is dronecan.py; the conversion wording is
wording.py; the Mermaid block comes from graph.py.)

Invariants:

- Rows keep spec order; who publishes or subscribes a topic or subject lists each user once, nodes (or devices) in
  spec order, then the bridge.
- The indexes (users of topics, parameters, types and subjects) are built once per document: asking every node,
  mapping or port per topic, message and subject made the reference quadratic in the size of the spec.
- Text is plain; the template escapes what comes from the spec. Imported only by the package (emit).
"""

from __future__ import annotations

from collections.abc import Hashable, Iterable
from pathlib import Path

from sam_codegen.catalogs.ros_known import external_messages_to_generate
from sam_codegen.model.device_params import DeviceParameter, ParamValue
from sam_codegen.model.protocols.registry import protocol
from sam_codegen.model.spec import QOS_PROFILES, Mapping, Node, Port, Qos, Spec, describe_sides, topic_profile
from sam_codegen.targets.docs.graph import ROS_TO_UAVCAN, SVG_NAME, UAVCAN_TO_ROS, Graph, PortIndex, mermaid_context
from sam_codegen.targets.docs.traffic import traffic_words
from sam_codegen.targets.docs.wording import field_rows, fmt_number, fmt_rate
from sam_codegen.targets.nodes import nodes_package, params_file
from sam_codegen.validate.mapping_rules import ResolvedMapping
from sam_codegen.validate.nodes import (
    TF_STATIC_TOPIC,
    class_name,
    node_published_topics,
    node_subscribed_topics,
    parameter_identifier,
    ros_parameter_name,
    topic_identifier,
    transform_identifier,
)
from sam_codegen.validate.resolve import Resolved

Row = dict[str, object]
TopicUsers = dict[str, tuple[list[str], list[str]]]  # topic -> (its publishers, its subscribers), in spec order


def markdown_context(resolved: Resolved, graph: Graph) -> dict[str, object]:
    """The variables of templates/docs/interfaces.md.j2 (all but `dronecan`)."""
    spec = resolved.spec
    subject_types = spec.subject_types()
    topic_users = _topic_users(spec)
    return {
        "spec_name": Path(spec.file).name,
        "vehicle": spec.vehicle,
        "vehicle_description": spec.description,
        "package": spec.ros.name,
        "package_description": spec.ros.description,
        "dsdl_root": spec.dsdl_root,
        "svg_name": SVG_NAME,
        "mermaid": mermaid_context(resolved, graph),
        "topics": _topic_rows(spec, topic_users),
        "nodes": _node_rows(spec),
        "nodes_package": nodes_package(spec),
        "params_file": params_file(spec),
        "qos_profiles": [{"name": name, "text": describe_sides(*_unnamed(name))} for name in QOS_PROFILES],
        "external_packages": sorted({m.package for m in external_messages_to_generate(spec).values()}),
        **_message_rows(resolved),
        "parameters": _parameter_rows(spec),
        "rules": _rule_rows(spec),
        "frames": _frame_rows(spec),
        "transforms": [{"parent": t.parent, "child": t.child, "publisher": t.publisher, "description": t.description}
                       for t in spec.transforms],
        "devices": _device_rows(spec),
        "device_parameters": _device_parameter_rows(spec),
        "subjects": _subject_rows(spec, subject_types),
        "bridge": _bridge_summary(spec, topic_users, subject_types),
        "dsdl_types": _dsdl_type_rows(resolved),
        "mappings": _mapping_rows(resolved, subject_types),
    }


# ---- indexes and small words ------------------------------------------------------------------------------

def _users(pairs: Iterable[tuple[str, Iterable[Hashable]]]) -> dict[Hashable, list[str]]:
    """{thing: the users that name it}, users in the given order and each at most once per thing.

    >>> _users([("a", ["/x", "/y", "/x"]), ("b", ["/x"])])
    {'/x': ['a', 'b'], '/y': ['a']}
    """
    out: dict[Hashable, list[str]] = {}
    for user, things in pairs:
        for thing in things:
            users = out.setdefault(thing, [])
            if not users or users[-1] != user:
                users.append(user)
    return out


def _bridge_mappings(spec: Spec) -> list[Mapping]:
    return spec.bridge.mappings if spec.bridge is not None else []


def _vector(values: tuple[float, float, float]) -> str:
    """
    >>> _vector((0.35, 0.0, -0.08))
    '[0.35, 0.0, -0.08]'
    """
    return "[" + ", ".join(fmt_number(float(v) + 0.0) for v in values) + "]"


def _range(minimum: float | None, maximum: float | None) -> str:
    if minimum is not None and maximum is not None:
        return f"[{fmt_number(minimum)}, {fmt_number(maximum)}]"
    if minimum is not None:
        return f">= {fmt_number(minimum)}"
    if maximum is not None:
        return f"<= {fmt_number(maximum)}"
    return ""


# ---- ROS: topics, nodes, messages, parameters, frames -----------------------------------------------------

def _topic_users(spec: Spec) -> TopicUsers:
    """{topic: (its publishers, its subscribers)} in spec order: nodes, then the bridge, then the node host for the
    static frames on /tf_static, then the tools outside the spec (`published_by: external`)."""
    bridge = spec.bridge
    node_publishers = _users((n.name, node_published_topics(spec, n)) for n in spec.nodes.values())  # topic -> nodes
    node_subscribers = _users((n.name, node_subscribed_topics(spec, n)) for n in spec.nodes.values())
    static_frames = [f for f in spec.frames.values() if f.parent is not None]
    bridged_topics = {(m.topic, m.direction) for m in _bridge_mappings(spec)}
    users: TopicUsers = {}
    for name in spec.topics:
        publishers = list(node_publishers.get(name, []))
        subscribers = list(node_subscribers.get(name, []))
        if bridge is not None:
            if (name, UAVCAN_TO_ROS) in bridged_topics:
                publishers.append(bridge.name)
            if (name, ROS_TO_UAVCAN) in bridged_topics:
                subscribers.append(bridge.name)
        if name == TF_STATIC_TOPIC and static_frames:
            publishers.append("node host (static frames)")
        who = spec.topics[name].external_publisher
        if who is not None:
            publishers.append(f"external ({who})" if who else "external")
        users[name] = (publishers, subscribers)
    return users


def _unnamed(profile: str) -> tuple[Qos, Qos]:
    """A topic profile's two sides, spelled out (the list explains the names)."""
    sides = topic_profile(profile)
    assert sides is not None, "a profile of QOS_PROFILES"
    return tuple(Qos(q.reliability, q.durability, q.depth) for q in sides)  # type: ignore[return-value]


def _topic_rows(spec: Spec, users: TopicUsers) -> list[Row]:
    """Each topic with its type, QoS (and where the QoS comes from) and who publishes and subscribes it."""
    topics: list[Row] = []
    for name, t in spec.topics.items():
        publishers, subscribers = users[name]
        qos = describe_sides(t.qos, t.subscriber_qos) \
            + (f"; default: {t.qos_origin}" if t.qos_origin != "declared" else "") \
            if t.qos is not None and t.subscriber_qos is not None else ""
        topics.append({"name": name, "type": t.type, "section": t.section, "description": t.description, "qos": qos,
                       "publishers": publishers, "subscribers": subscribers})
    return topics


def node_interface(spec: Spec, node: Node) -> list[str]:
    """The members of a node's generated base class, as the reference lists them."""
    items = []
    for item in node.subscribe_items:
        own = f", own QoS {item.qos.describe()}" if item.qos is not None else ""
        items.append(f"on_{topic_identifier(item.topic)}({spec.topics[item.topic].type.split('/')[1]}){own}")
    items += [f"publish_{topic_identifier(t)}({spec.topics[t].type.split('/')[1]})" for t in node.publishes]
    items += [f"{parameter_identifier(p)} (parameter {ros_parameter_name(p)})" for p in node.parameters]
    items += [f"lookup_{transform_identifier(p, c)}()" for p, c in node.reads_transforms]
    items += [f"publish_{transform_identifier(p, c)}(stamp, translation, rotation)" for p, c in node.transforms]
    return [*items, "report_status(level, message, **values)"]


def _node_rows(spec: Spec) -> list[Row]:
    """Each ROS node: its topics, parameters and transforms, and the generated base class it implements."""
    return [{"name": n.name, "description": n.description, "publishes": n.publishes, "subscribes": n.subscribes,
             "parameters": n.parameters, "transforms": [f"{p}->{c}" for p, c in n.transforms],
             "reads_transforms": [f"{p}->{c}" for p, c in n.reads_transforms],
             "interface": node_interface(spec, n), "base": f"{nodes_package(spec)}.{n.name}.{class_name(n.name)}"}
            for n in spec.nodes.values()]


def _message_rows(resolved: Resolved) -> dict[str, list[Row]]:
    """{"messages": the package's messages (declared and derived), "externals": the messages of other packages},
    each with the topics that carry it."""
    spec = resolved.spec
    topics_of_type = _users((t.name, [t.type]) for t in spec.topics.values())  # ROS type -> topics
    messages: list[Row] = [{
        "name": msg.full_name, "description": msg.description, "derived_from": msg.derived_from,
        "topics": list(topics_of_type.get(msg.full_name, [])),
        "fields": [{"name": f.name, "type": str(f.type), "comment": f.comment} for f in msg.fields],
        "constants": [{"name": c.name, "type": str(c.type), "value": fmt_number(c.value), "comment": c.comment}
                      for c in msg.constants],
    } for msg in resolved.messages]
    externals: list[Row] = [{
        "name": msg.full_name, "description": msg.description, "topics": list(topics_of_type.get(msg.full_name, [])),
        "fields": [{"name": f.name, "type": str(f.type), "comment": f.comment} for f in msg.fields],
        "known": msg.full_name not in spec.external_messages,
    } for msg in external_messages_to_generate(spec).values()]
    return {"messages": messages, "externals": externals}


def _parameter_rows(spec: Spec) -> list[Row]:
    """Each parameter with its default, range and the nodes that read it."""
    node_readers = _users((n.name, n.parameters) for n in spec.nodes.values())  # parameter -> nodes
    return [{
        "name": p.name, "type": p.type, "unit": p.unit, "default": fmt_number(p.default),
        "range": _range(p.minimum, p.maximum), "section": p.section, "description": p.description,
        "nodes": list(node_readers.get(p.name, [])),
    } for p in spec.parameters.values()]


def _rule_rows(spec: Spec) -> list[Row]:
    """Each rule between two parameters, with the defaults it compares when both parameters exist."""
    return [{"left": r.left, "op": r.op, "right": r.right, "description": r.description,
             "defaults": f"{fmt_number(spec.parameters[r.left].default)} {r.op} "
                         f"{fmt_number(spec.parameters[r.right].default)}"
             if r.left in spec.parameters and r.right in spec.parameters else ""}
            for r in spec.parameter_rules]


def _frame_rows(spec: Spec) -> list[Row]:
    """Each frame, with its static mounting on its parent when it has one."""
    return [{"name": f.name, "parent": f.parent, "description": f.description,
             "mounting": f"xyz {_vector(f.xyz)}, rpy {_vector(f.rpy)}" if f.parent is not None else ""}
            for f in spec.frames.values()]


# ---- UAVCAN: devices, subjects, the bridge, DSDL types, mappings ------------------------------------------

def _port_text(port: Port) -> Row:
    return {"subject_id": port.subject_id, "type": port.type, "rate": fmt_rate(port.rate_hz)}


def _device_rows(spec: Spec) -> list[Row]:
    """Each device with the subjects it publishes and subscribes."""
    return [{"name": d.name, "node_id": d.node_id, "description": d.description,
             "publishes": [_port_text(p) for p in d.publishes],
             "subscribes": [_port_text(p) for p in d.subscribes]}
            for d in spec.devices.values()]


def _setting_value(p: DeviceParameter, value: ParamValue) -> str:
    if p.type == "enum":
        return f"{value} ({p.stored(value)})"
    if isinstance(value, bool):
        return "true" if value else "false"
    return fmt_number(value) if isinstance(value, (int, float)) else repr(value)


def _device_parameter_rows(spec: Spec) -> list[Row]:
    """Each board's settings (model.device_params) with the name its firmware knows each by on every protocol."""
    rows = []
    for d in spec.devices.values():
        if not d.parameters:
            continue
        rows.append({"device": d.name, "node_id": d.node_id, "parameters": [{
            "name": p.name, "type": p.type, "range": _range(p.minimum, p.maximum) if p.minimum is not None else "",
            "choices": ", ".join(f"{name} ({number})" for name, number in p.values),
            "max_length": p.max_length, "unit": p.unit, "default": _setting_value(p, p.default),
            "restart": p.restart, "description": p.description,
            "names": [f"{protocol(proto).label} {protocol(proto).setting_noun} `{wire}`" for proto, wire in p.names],
        } for p in d.parameters]})
    return rows


def _subject_rows(spec: Spec, subject_types: dict[int, str]) -> list[Row]:
    """Each subject, by id: its type and rates, its publishers and subscribers (devices, then the bridge) and the
    mappings that carry it."""
    bridge = spec.bridge
    mappings = _bridge_mappings(spec)
    ports = PortIndex(spec)
    mappings_of_subject = _users((m.name, [m.subject_id]) for m in mappings)
    bridged_subjects = {(m.subject_id, m.direction) for m in mappings}
    subjects: list[Row] = []
    for subject_id in sorted(subject_types):
        rates = sorted(ports.rates.get(subject_id, ()))
        publishers = [d.name for d in ports.publishers.get(subject_id, [])]
        subscribers = [d.name for d in ports.subscribers.get(subject_id, [])]
        if bridge is not None:
            if (subject_id, ROS_TO_UAVCAN) in bridged_subjects:
                publishers.append(bridge.name)
            if (subject_id, UAVCAN_TO_ROS) in bridged_subjects:
                subscribers.append(bridge.name)
        subjects.append({"subject_id": subject_id, "type": subject_types[subject_id],
                         "rate": ", ".join(fmt_rate(r) for r in rates), "publishers": publishers,
                         "subscribers": subscribers, "mappings": list(mappings_of_subject.get(subject_id, []))})
    return subjects


def _bridge_summary(spec: Spec, topic_users: TopicUsers, subject_types: dict[int, str]) -> Row | None:
    """The bridge's node: the topics it publishes and subscribes and its UAVCAN ports."""
    bridge = spec.bridge
    if bridge is None:
        return None

    def bridge_ports(direction: str) -> list[Row]:
        seen: dict[int, Row] = {}
        for m in bridge.mappings:
            if m.direction == direction and m.subject_id not in seen:
                seen[m.subject_id] = {"subject_id": m.subject_id, "type": subject_types.get(m.subject_id, "")}
        return list(seen.values())

    return {
        "name": bridge.name, "node_id": bridge.node_id,
        "publishes": [name for name, (publishers, _) in topic_users.items() if bridge.name in publishers],
        "subscribes": [name for name, (_, subscribers) in topic_users.items() if bridge.name in subscribers],
        "uavcan_publishes": bridge_ports(ROS_TO_UAVCAN),
        "uavcan_subscribes": bridge_ports(UAVCAN_TO_ROS),
        "time_sync_period": bridge.time_sync.period_s if bridge.time_sync.enabled else None,
    }


def _dsdl_type_rows(resolved: Resolved) -> list[Row]:
    """Each DSDL type of the spec: its layout, the subjects that use it, the messages derived from it, its fields."""
    dsdl_users: dict[str, dict[str, None]] = {}  # DSDL type -> its subject ids, in order (a dict as ordered set)
    for d in resolved.spec.devices.values():
        for p in d.publishes + d.subscribes:
            dsdl_users.setdefault(p.type, {})[str(p.subject_id)] = None
    derived_messages = _users((m.full_name, [m.derived_from]) for m in resolved.messages if m.derived_from)
    return [{
        "name": s.name, "description": s.description,
        "layout": "Sealed" if s.sealed else f"Delimited, extent {s.extent} bytes" if s.extent else "Delimited",
        "subjects": list(dsdl_users.get(s.name, {})),
        "derived": list(derived_messages.get(s.name, [])),
        "fields": [{"name": f.name, "type": str(f.type), "comment": f.comment or ("padding" if not f.name else "")}
                   for f in s.declared_fields],
        "constants": [{"name": c.name, "type": str(c.type), "value": fmt_number(c.value), "comment": c.comment}
                      for c in s.constants],
    } for s in resolved.dsdl_types]


def _mapping_rows(resolved: Resolved, subject_types: dict[int, str]) -> list[Row]:
    """Each Cyphal mapping of the bridge: its ends, the nodes it reads from or commands, and its field table."""
    spec = resolved.spec
    devices_by_id = spec.devices_by_node_id()
    resolved_by_name = {rm.mapping.name: rm for rm in resolved.mappings}

    def node_ref(node_id: int) -> Row:
        device = devices_by_id.get(node_id)
        return {"id": node_id, "device": device.name if device is not None else None}

    rows: list[Row] = []
    for m in _bridge_mappings(spec):
        rm: ResolvedMapping | None = resolved_by_name.get(m.name)
        topic = spec.topics.get(m.topic)
        if m.direction == UAVCAN_TO_ROS:
            nodes = [node_ref(n) for n in m.source_node_ids]
            nodes_note = "any node" if m.any_node else "" if nodes else "any publisher"
        else:
            nodes = [node_ref(m.destination_node_id)] if m.destination_node_id is not None else []
            nodes_note = "" if nodes else "broadcast"
        rows.append({
            "name": m.name,
            "direction": "UAVCAN → ROS" if m.direction == UAVCAN_TO_ROS else "ROS → UAVCAN",
            "uavcan_to_ros": m.direction == UAVCAN_TO_ROS,
            "dsdl_type": rm.dsdl_struct.name if rm is not None else subject_types.get(m.subject_id, ""),
            "subject_id": m.subject_id,
            "topic": m.topic,
            "ros_type": topic.type if topic is not None else "",
            "nodes": nodes,
            "nodes_note": nodes_note,
            "any_node": m.any_node,
            "frame_id": m.frame_id,
            "rate": fmt_rate(rm.rate_hz) if rm is not None else "",
            "auto": m.auto,
            "on_out_of_range": m.on_out_of_range,
            "rows": field_rows(rm) if rm is not None else [],
            "traffic": traffic_words(m),
        })
    return rows


__all__ = ["markdown_context", "node_interface"]
