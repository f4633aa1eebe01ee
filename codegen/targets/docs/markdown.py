"""The interface reference (docs/interfaces.md) of emit_docs: what its template shows, computed from the spec."""

from __future__ import annotations

from collections.abc import Hashable, Iterable
from pathlib import Path

from sam_codegen.conversion_plan import Constant, LinkPlan, ReceiveTime, lower_mapping
from sam_codegen.model.spec import QOS_PROFILES, Node, Port, Qos, Spec
from sam_codegen.targets.docs.graph import (
    ROS_TO_UAVCAN,
    SVG_NAME,
    UAVCAN_TO_ROS,
    Graph,
    PortIndex,
    describe_link,
    fmt_number,
    fmt_rate,
    mermaid_context,
)
from sam_codegen.targets.nodes import nodes_package, params_file
from sam_codegen.validate.mapping_rules import ResolvedMapping, format_path
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

# ---- Markdown context -------------------------------------------------------------------------------------

def _vector(values: tuple[float, float, float]) -> str:
    """
    >>> _vector((0.35, 0.0, -0.08))
    '[0.35, 0.0, -0.08]'
    """
    return "[" + ", ".join(fmt_number(float(v) + 0.0) for v in values) + "]"


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


def _range(minimum: float | None, maximum: float | None) -> str:
    if minimum is not None and maximum is not None:
        return f"[{fmt_number(minimum)}, {fmt_number(maximum)}]"
    if minimum is not None:
        return f">= {fmt_number(minimum)}"
    if maximum is not None:
        return f"<= {fmt_number(maximum)}"
    return ""


def _field_rows(rm: ResolvedMapping) -> list[dict[str, object]]:
    """The field table of a mapping, worded from its conversion plan in the mapping's direction: DroneCAN's select,
    the header the bridge fills, then each link, the constants it sets and the ignored fields."""
    m = rm.mapping
    plan = lower_mapping(rm)
    to_ros = m.direction == UAVCAN_TO_ROS
    arrow = "←" if to_ros else "→"
    rows: list[dict[str, object]] = [
        {"ros": None, "arrow": "", "uavcan": format_path(list(fs.path)), "conversion": f"select {fs.op.value}"}
        for fs in plan.uavcan_fields if isinstance(fs.op, Constant) and fs.op.select]

    def link_row(link: LinkPlan) -> dict[str, object]:
        return {"ros": link.step.ros, "arrow": arrow, "uavcan": link.step.uavcan or None,
                "conversion": describe_link(link)}

    links = list(plan.to_ros if to_ros else plan.to_uavcan)
    if to_ros and rm.has_header:
        stamp = next((link for link in links if link.step.ros == "header.stamp"), None)
        if stamp is not None:
            links.remove(stamp)
            rows.append(link_row(stamp))
        for fs in plan.ros_fields:  # the receive-time stamp (when no link sets it), the frame id
            text = "receive time" if isinstance(fs.op, ReceiveTime) else f"constant {fs.op.value}"
            rows.append({"ros": format_path(list(fs.path)), "arrow": arrow, "uavcan": None, "conversion": text})
    rows.extend(link_row(link) for link in links)
    for fs in plan.uavcan_fields:
        if isinstance(fs.op, Constant) and not fs.op.select:
            rows.append({"ros": None, "arrow": arrow, "uavcan": format_path(list(fs.path)),
                         "conversion": f"constant {fmt_number(fs.op.value)}"})
    for ignored in m.ignore:
        rows.append({"ros": None, "arrow": "", "uavcan": ignored, "conversion": "ignored"})
    return rows


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


def markdown_context(resolved: Resolved, graph: Graph) -> dict[str, object]:
    spec = resolved.spec
    bridge = spec.bridge
    mappings = bridge.mappings if bridge is not None else []
    devices_by_id = spec.devices_by_node_id()
    # Indexes built once (spec order kept): asking every node, mapping or port per topic, message and subject
    # made the reference quadratic in the size of the spec.
    ports = PortIndex(spec)
    node_publishers = _users((n.name, node_published_topics(spec, n)) for n in spec.nodes.values())  # topic -> nodes
    node_subscribers = _users((n.name, node_subscribed_topics(spec, n)) for n in spec.nodes.values())
    static_frames = [f for f in spec.frames.values() if f.parent is not None]
    node_readers = _users((n.name, n.parameters) for n in spec.nodes.values())  # parameter -> nodes
    topics_of_type = _users((t.name, [t.type]) for t in spec.topics.values())  # ROS type -> topics
    mappings_of_subject = _users((m.name, [m.subject_id]) for m in mappings)
    bridged_topics = {(m.topic, m.direction) for m in mappings}
    bridged_subjects = {(m.subject_id, m.direction) for m in mappings}

    topics = []
    for name, t in spec.topics.items():
        publishers = list(node_publishers.get(name, []))
        subscribers = list(node_subscribers.get(name, []))
        if bridge is not None:
            if (name, UAVCAN_TO_ROS) in bridged_topics:
                publishers.append(bridge.name)
            if (name, ROS_TO_UAVCAN) in bridged_topics:
                subscribers.append(bridge.name)
        if name == TF_STATIC_TOPIC and static_frames:
            publishers.append("node host (static frames)")
        qos = t.qos.describe() + (f"; default: {t.qos_origin}" if t.qos_origin != "declared" else "") \
            if t.qos is not None else ""
        topics.append({"name": name, "type": t.type, "section": t.section, "description": t.description, "qos": qos,
                       "publishers": publishers, "subscribers": subscribers})

    def used_by(full_name: str) -> list[str]:
        return list(topics_of_type.get(full_name, []))

    messages = []
    for msg in resolved.messages:
        messages.append({
            "name": msg.full_name, "description": msg.description, "derived_from": msg.derived_from,
            "topics": used_by(msg.full_name),
            "fields": [{"name": f.name, "type": str(f.type), "comment": f.comment} for f in msg.fields],
            "constants": [{"name": c.name, "type": str(c.type), "value": fmt_number(c.value), "comment": c.comment}
                          for c in msg.constants],
        })
    externals = []
    for msg in spec.external_messages.values():
        externals.append({
            "name": msg.full_name, "description": msg.description, "topics": used_by(msg.full_name),
            "fields": [{"name": f.name, "type": str(f.type), "comment": f.comment} for f in msg.fields],
        })

    parameters = []
    for p in spec.parameters.values():
        parameters.append({
            "name": p.name, "type": p.type, "unit": p.unit, "default": fmt_number(p.default),
            "range": _range(p.minimum, p.maximum), "section": p.section, "description": p.description,
            "nodes": list(node_readers.get(p.name, [])),
        })
    rules = [{"left": r.left, "op": r.op, "right": r.right, "description": r.description,
              "defaults": f"{fmt_number(spec.parameters[r.left].default)} {r.op} "
                          f"{fmt_number(spec.parameters[r.right].default)}"
              if r.left in spec.parameters and r.right in spec.parameters else ""}
             for r in spec.parameter_rules]

    frames = [{"name": f.name, "parent": f.parent, "description": f.description,
               "mounting": f"xyz {_vector(f.xyz)}, rpy {_vector(f.rpy)}" if f.parent is not None else ""}
              for f in spec.frames.values()]
    transforms = [{"parent": t.parent, "child": t.child, "publisher": t.publisher, "description": t.description}
                  for t in spec.transforms]

    def port_mappings(subject_id: int) -> list[str]:
        return list(mappings_of_subject.get(subject_id, []))

    def port_text(port: Port) -> dict[str, object]:
        return {"subject_id": port.subject_id, "type": port.type, "rate": fmt_rate(port.rate_hz)}

    devices = []
    for d in spec.devices.values():
        devices.append({"name": d.name, "node_id": d.node_id, "description": d.description,
                        "publishes": [port_text(p) for p in d.publishes],
                        "subscribes": [port_text(p) for p in d.subscribes]})

    subject_types = spec.subject_types()
    subjects = []
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
                         "subscribers": subscribers, "mappings": port_mappings(subject_id)})

    def bridge_ports(direction: str) -> list[dict[str, object]]:
        seen: dict[int, dict[str, object]] = {}
        for m in mappings:
            if m.direction == direction and m.subject_id not in seen:
                seen[m.subject_id] = {"subject_id": m.subject_id, "type": subject_types.get(m.subject_id, "")}
        return list(seen.values())

    dsdl_users: dict[str, dict[str, None]] = {}  # DSDL type -> its subject ids, in order (a dict as ordered set)
    for d in spec.devices.values():
        for p in d.publishes + d.subscribes:
            dsdl_users.setdefault(p.type, {})[str(p.subject_id)] = None
    derived_messages = _users((m.full_name, [m.derived_from]) for m in resolved.messages if m.derived_from)
    dsdl_types = []
    for s in resolved.dsdl_types:
        dsdl_types.append({
            "name": s.name, "description": s.description,
            "layout": "Sealed" if s.sealed else f"Delimited, extent {s.extent} bytes" if s.extent else "Delimited",
            "subjects": list(dsdl_users.get(s.name, {})),
            "derived": list(derived_messages.get(s.name, [])),
            "fields": [{"name": f.name, "type": str(f.type), "comment": f.comment or ("padding" if not f.name else "")}
                       for f in s.declared_fields],
            "constants": [{"name": c.name, "type": str(c.type), "value": fmt_number(c.value), "comment": c.comment}
                          for c in s.constants],
        })

    def node_ref(node_id: int) -> dict[str, object]:
        device = devices_by_id.get(node_id)
        return {"id": node_id, "device": device.name if device is not None else None}

    resolved_by_name = {rm.mapping.name: rm for rm in resolved.mappings}
    bridge_mappings = []
    for m in mappings:
        rm = resolved_by_name.get(m.name)
        topic = spec.topics.get(m.topic)
        if m.direction == UAVCAN_TO_ROS:
            nodes = [node_ref(n) for n in m.source_node_ids]
            nodes_note = "" if nodes else "any publisher"
        else:
            nodes = [node_ref(m.destination_node_id)] if m.destination_node_id is not None else []
            nodes_note = "" if nodes else "broadcast"
        bridge_mappings.append({
            "name": m.name,
            "direction": "UAVCAN → ROS" if m.direction == UAVCAN_TO_ROS else "ROS → UAVCAN",
            "uavcan_to_ros": m.direction == UAVCAN_TO_ROS,
            "dsdl_type": rm.dsdl_struct.name if rm is not None else subject_types.get(m.subject_id, ""),
            "subject_id": m.subject_id,
            "topic": m.topic,
            "ros_type": topic.type if topic is not None else "",
            "nodes": nodes,
            "nodes_note": nodes_note,
            "frame_id": m.frame_id,
            "rate": fmt_rate(rm.rate_hz) if rm is not None else "",
            "auto": m.auto,
            "on_out_of_range": m.on_out_of_range,
            "rows": _field_rows(rm) if rm is not None else [],
        })

    nodes = [{"name": n.name, "description": n.description, "publishes": n.publishes, "subscribes": n.subscribes,
              "parameters": n.parameters, "transforms": [f"{p}->{c}" for p, c in n.transforms],
              "reads_transforms": [f"{p}->{c}" for p, c in n.reads_transforms],
              "interface": node_interface(spec, n), "base": f"{nodes_package(spec)}.{n.name}.{class_name(n.name)}"}
             for n in spec.nodes.values()]

    return {
        "spec_name": Path(spec.file).name,
        "vehicle": spec.vehicle,
        "vehicle_description": spec.description,
        "package": spec.ros.name,
        "package_description": spec.ros.description,
        "dsdl_root": spec.dsdl_root,
        "svg_name": SVG_NAME,
        "mermaid": mermaid_context(resolved, graph),
        "topics": topics,
        "nodes": nodes,
        "nodes_package": nodes_package(spec),
        "params_file": params_file(spec),
        "qos_profiles": [{"name": name, "text": Qos(q.reliability, q.durability, q.depth).describe()}
                         for name, q in QOS_PROFILES.items()],
        "external_packages": sorted({m.package for m in spec.external_messages.values()}),
        "messages": messages,
        "externals": externals,
        "parameters": parameters,
        "rules": rules,
        "frames": frames,
        "transforms": transforms,
        "devices": devices,
        "subjects": subjects,
        "bridge": {
            "name": bridge.name, "node_id": bridge.node_id,
            "publishes": [t["name"] for t in topics if bridge.name in t["publishers"]],
            "subscribes": [t["name"] for t in topics if bridge.name in t["subscribers"]],
            "uavcan_publishes": bridge_ports(ROS_TO_UAVCAN),
            "uavcan_subscribes": bridge_ports(UAVCAN_TO_ROS),
        } if bridge is not None else None,
        "dsdl_types": dsdl_types,
        "mappings": bridge_mappings,
    }
