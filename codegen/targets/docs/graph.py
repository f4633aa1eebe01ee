"""Documentation emitter: the interface reference (Markdown) and the dataflow picture (SVG).

`emit(resolved)` returns {path under generated/: text}:

- docs/interfaces.md: the document's `type / topic / contents` tables generated from the spec: topics,
  messages, parameters, frames, devices, DSDL types and the bridge's mappings with their conversions;
- docs/dataflow.svg: a picture like the document's Fig. 1, devices -> bridge -> topics -> nodes, laid out
  here (columns, barycentric rows) so that it needs no graphviz and comes out byte for byte the same.

Everything that comes from the spec reaches the output through md_cell / md_code / xml_text in the
templates; this module only computes structure, numbers and the conversion wording.
"""

from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass, field
from decimal import Decimal

from sam_codegen.conversion_plan import (
    TO_ROS,
    TO_UAVCAN,
    Clamp,
    Constant,
    Convert,
    DecodeUtf8,
    FixedLength,
    Limits,
    LinkPlan,
    MaxLength,
    Offset,
    Pad,
    Scale,
    Table,
    TimestampFromRos,
    TimestampToRos,
    Utf8Length,
    lower_link,
)
from sam_codegen.model.spec import Device, Mapping, Scalar, Spec
from sam_codegen.render.templating import render
from sam_codegen.validate.mapping_rules import Step
from sam_codegen.validate.nodes import node_published_topics, node_subscribed_topics
from sam_codegen.validate.resolve import Resolved

MD_PATH = "docs/interfaces.md"
SVG_PATH = "docs/dataflow.svg"
SVG_NAME = "dataflow.svg"

# Edge kinds, also the CSS class and arrow marker of each.
UAVCAN_TO_ROS = "uavcan_to_ros"
ROS_TO_UAVCAN = "ros_to_uavcan"
SUBSCRIBE = "subscribe"
PUBLISH = "publish"
EDGE_COLOURS = {
    UAVCAN_TO_ROS: "#1f77b4",
    ROS_TO_UAVCAN: "#c0392b",
    SUBSCRIBE: "#2e8b57",
    PUBLISH: "#7d3c98",
}
LEGEND = [
    (UAVCAN_TO_ROS, "UAVCAN -> ROS: device publishes a subject, the bridge publishes a topic"),
    (ROS_TO_UAVCAN, "ROS -> UAVCAN: the bridge subscribes a topic and commands a device"),
    (SUBSCRIBE, "a node subscribes to a topic"),
    (PUBLISH, "a node publishes a topic"),
]
TEENSY_COLOUR = "#f39c12"


# ---- numbers and conversions -------------------------------------------------------------------------

def fmt_number(value: Scalar | None) -> str:
    """A number as a reader expects it: exact, short, powers of ten as 1e-4.

    >>> [fmt_number(v) for v in (1.0e-4, 1.0e-8, 0.01, -273.15, 5.0, 100, float("nan"), True, "ok")]
    ['1e-4', '1e-8', '0.01', '-273.15', '5.0', '100', 'NaN', 'true', '"ok"']
    """
    if value is None:
        return ""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, float):
        if math.isnan(value):
            return "NaN"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        if value != 0 and (abs(value) < 1e-3 or abs(value) >= 1e6):
            return format(Decimal(repr(value)).normalize(), "e")
        return repr(value)
    return repr(value)


def fmt_rate(rate: float) -> str:
    """A nominal rate.

    >>> fmt_rate(100.0), fmt_rate(2.5)
    ('100 Hz', '2.5 Hz')
    """
    return f"{int(rate) if float(rate).is_integer() else rate} Hz"


def _arithmetic(op: Scale | Offset) -> str:
    """Scale and offset as the bridge applies them: ros = uavcan × scale + offset, and the inverse."""
    if isinstance(op, Scale):
        return f"{'÷' if op.inverse else '×'} {fmt_number(op.factor)}"
    subtract = (op.amount < 0) != op.inverse
    return ("- " if subtract else "+ ") + fmt_number(abs(op.amount))


def _policy(link: LinkPlan, saturated: str) -> str:
    return "rejected" if link.reject else saturated


def describe_link(link: LinkPlan) -> str:
    """The conversion of one field link in words, from its planned operations (conversion_plan), in the
    direction the bridge runs it. Out-of-range handling follows the mapping's on_out_of_range."""
    step, ops, to_ros = link.step, link.ops, link.to_ros
    first = ops[0] if ops else None
    if isinstance(first, Constant):
        return f"constant {fmt_number(first.value)}"
    ros = step.ros_type
    uav = step.uavcan_type
    assert uav is not None
    if isinstance(first, TimestampToRos):
        return f"usec → {ros.base} (0 = receive time)"
    if isinstance(first, TimestampFromRos):
        return f"{ros.base} → usec"
    src, dst = (str(uav), str(ros)) if to_ros else (str(ros), str(uav))
    if isinstance(first, DecodeUtf8):
        return f"{src} → {dst} (invalid UTF-8 replaced)"
    cut = link.first(Utf8Length)
    if isinstance(cut, Utf8Length):
        return f"{src} → {dst} (longer than {cut.capacity} bytes {_policy(link, 'cut')})"
    src_elem, dst_elem = (uav.base_name, ros.base) if to_ros else (ros.base, uav.base_name)
    text = f"{src} → {dst}" if step.kind == "array" else f"{src_elem} → {dst_elem}"
    notes: list[str] = []
    if isinstance(first, Table):
        pairs = ", ".join(f"{k}: {v}" for k, v in first.pairs)
        if first.default is not None:  # the inverse rejects what has no key
            pairs += f", default: {first.default}"
        text += f" inverse of table {{{pairs}}}" if first.inverse else f" table {{{pairs}}}"
        if not step.exact:
            notes.append("not one to one")
        return text + (f" ({', '.join(notes)})" if notes else "")
    arithmetic: list[str] = []
    for op in [*ops, None]:
        if isinstance(op, (Scale, Offset)):
            arithmetic.append(_arithmetic(op))
            continue
        if arithmetic:  # a run of scale / offset: "× s + o" to ROS, "- o, then ÷ s" to UAVCAN
            text += " " + (" " if to_ros else ", then ").join(arithmetic)
            arithmetic = []
        if isinstance(op, Limits):  # in ROS units, before the inverse scale / offset
            text += f" limits [{fmt_number(op.declared[0])}, {fmt_number(op.declared[1])}]"
    convert = link.first(Convert)
    change = convert.change if isinstance(convert, Convert) else ""
    if change in ("narrowed", "rounded") or (change and not link.has(Scale, Offset)):
        notes.append(change)
    if link.has(Limits, Clamp):  # values beyond the limits or the target's range
        policy = "out of range rejected" if link.reject else "saturating"
        notes = [f"{notes[0]}, {policy}"] if notes else [policy]
    for op in ops:
        if isinstance(op, Pad):
            notes.append(f"padded to {op.size}")
        elif isinstance(op, FixedLength):
            notes.append(f"other lengths {_policy(link, 'padded or cut')}")
        elif isinstance(op, MaxLength):
            notes.append(f"over {op.capacity} elements {_policy(link, 'cut')}")
    return text + (f" ({', '.join(notes)})" if notes else "")


def describe_step(step: Step, direction: str, on_out_of_range: str) -> str:
    """The conversion of one field link in words, in the direction the bridge runs it (its plan, described)."""
    plan_direction = TO_ROS if direction == UAVCAN_TO_ROS else TO_UAVCAN
    return describe_link(lower_link(step, plan_direction, "", on_out_of_range == "reject"))


# ---- the graph (shared by the Mermaid block and the SVG) -----------------------------------------------

@dataclass
class Edge:
    kind: str  # UAVCAN_TO_ROS | ROS_TO_UAVCAN | SUBSCRIBE | PUBLISH
    src: tuple[str, str]  # (box kind, name)
    dst: tuple[str, str]
    label: str = ""


@dataclass
class Graph:
    devices: list[str]
    bridge: str | None
    topics: list[str]  # in layout order
    nodes: list[str]
    edges: list[Edge] = field(default_factory=list)
    # per mapping: (direction, its device-side edges, its topic-side edge), joined inside the bridge
    links: list[tuple[str, list[int], int]] = field(default_factory=list)


class PortIndex:
    """Who uses each subject, built in one pass over the spec: the emitters ask per mapping, topic and subject,
    and a scan of every device's ports per question made large specs quadratic. Lists keep spec order."""

    def __init__(self, spec: Spec) -> None:
        self.publishers: dict[int, list[Device]] = {}  # subject id -> devices publishing it, each once
        self.subscribers: dict[int, list[Device]] = {}
        self.rates: dict[int, set[float]] = {}  # subject id -> nominal rates of its ports
        for d in spec.devices.values():
            for ports, users in ((d.publishes, self.publishers), (d.subscribes, self.subscribers)):
                for p in ports:
                    devices = users.setdefault(p.subject_id, [])
                    if not devices or devices[-1] is not d:
                        devices.append(d)
            for p in d.publishes + d.subscribes:
                self.rates.setdefault(p.subject_id, set()).add(p.rate_hz)


def mapping_devices(spec: Spec, mapping: Mapping, index: PortIndex | None = None) -> list[Device]:
    """The devices a mapping reads from (uavcan_to_ros) or commands (ros_to_uavcan)."""
    index = index if index is not None else PortIndex(spec)
    if mapping.direction == UAVCAN_TO_ROS:
        candidates = index.publishers.get(mapping.subject_id, [])
        if mapping.source_node_ids:
            return [d for d in candidates if d.node_id in mapping.source_node_ids]
        return list(candidates)
    candidates = index.subscribers.get(mapping.subject_id, [])
    if mapping.destination_node_id is not None:
        return [d for d in candidates if d.node_id == mapping.destination_node_id]
    return list(candidates)


def build_graph(resolved: Resolved) -> Graph:
    spec = resolved.spec
    bridge = spec.bridge
    mappings = bridge.mappings if bridge is not None else []
    device_index = {name: i for i, name in enumerate(spec.devices)}
    ports = PortIndex(spec)
    devices_of = [mapping_devices(spec, m, ports) for m in mappings]
    linked_devices: dict[str, list[int]] = {}  # topic -> indexes of the devices its mappings reach
    for m, devices in zip(mappings, devices_of, strict=True):
        linked_devices.setdefault(m.topic, []).extend(device_index[d.name] for d in devices)

    # Topics: those the bridge links, in the order of the devices they come from or go to, then the rest
    # in spec order; so the bridge's lines run roughly straight across.
    def topic_key(item: tuple[int, str]) -> tuple[int, int, int]:
        index, name = item
        linked = linked_devices.get(name)
        if linked:
            return (0, min(linked), index)
        return (1, 0, index)

    topics = [name for _, name in sorted(enumerate(spec.topics), key=topic_key)]
    graph = Graph(list(spec.devices), bridge.name if bridge is not None else None, topics, list(spec.nodes))
    edge_ids: dict[tuple, int] = {}

    def add(edge: Edge) -> int:
        key = (edge.kind, edge.src, edge.dst, edge.label)
        if key not in edge_ids:
            edge_ids[key] = len(graph.edges)
            graph.edges.append(edge)
        return edge_ids[key]

    if bridge is not None:
        b = ("bridge", bridge.name)
        for m, devices in zip(mappings, devices_of, strict=True):
            if m.topic not in spec.topics:
                continue
            t = ("topic", m.topic)
            label = str(m.subject_id)
            if m.direction == UAVCAN_TO_ROS:
                dev_edges = [add(Edge(UAVCAN_TO_ROS, ("device", d.name), b, label)) for d in devices]
                topic_edge = add(Edge(UAVCAN_TO_ROS, b, t))
            else:
                topic_edge = add(Edge(ROS_TO_UAVCAN, t, b))
                dev_edges = [add(Edge(ROS_TO_UAVCAN, b, ("device", d.name), label)) for d in devices]
            graph.links.append((m.direction, dev_edges, topic_edge))
    for node in spec.nodes.values():
        for topic in node_subscribed_topics(spec, node):
            if topic in spec.topics:
                add(Edge(SUBSCRIBE, ("topic", topic), ("node", node.name)))
        for topic in node_published_topics(spec, node):
            if topic in spec.topics:
                add(Edge(PUBLISH, ("node", node.name), ("topic", topic)))
    return graph


# ---- Mermaid -------------------------------------------------------------------------------------------

def mermaid_label(text: str) -> str:
    """Text for a quoted Mermaid label: entity codes for what Mermaid or HTML would interpret.

    >>> mermaid_label('a "b" <c> #d `e`')
    'a #quot;b#quot; #lt;c#gt; #35;d #96;e#96;'
    """
    text = " ".join(str(text).split())
    out = []
    for ch in text:
        if ch == "#":
            out.append("#35;")
        elif ch == '"':
            out.append("#quot;")
        elif ch == "<":
            out.append("#lt;")
        elif ch == ">":
            out.append("#gt;")
        elif ch == "&":
            out.append("#amp;")
        elif ch == "`":
            out.append("#96;")
        elif ch.isprintable():
            out.append(ch)
    return "".join(out)


def mermaid_context(resolved: Resolved, graph: Graph) -> dict[str, object]:
    spec = resolved.spec
    ids: dict[tuple[str, str], str] = {}
    used: set[str] = set()

    def node_id(kind: str, name: str) -> str:
        key = (kind, name)
        if key not in ids:
            prefix = {"device": "dev", "bridge": "bridge", "topic": "topic", "node": "node"}[kind]
            base = prefix + "_" + (re.sub(r"[^A-Za-z0-9]+", "_", name).strip("_") or "x")
            candidate, n = base, 2
            while candidate in used:
                candidate, n = f"{base}_{n}", n + 1
            used.add(candidate)
            ids[key] = candidate
        return ids[key]

    vertices = []
    for name in graph.devices:
        d = spec.devices[name]
        vertices.append({"id": node_id("device", name), "open": '["', "close": '"]', "cls": "device",
                         "label": [name, f"node {d.node_id}"]})
    if graph.bridge is not None and spec.bridge is not None:
        vertices.append({"id": node_id("bridge", graph.bridge), "open": '[["', "close": '"]]', "cls": "bridge",
                         "label": [graph.bridge, f"node {spec.bridge.node_id}"]})
    for name in graph.topics:
        vertices.append({"id": node_id("topic", name), "open": '(["', "close": '"])', "cls": "topic",
                         "label": [name, spec.topics[name].type]})
    for name in graph.nodes:
        vertices.append({"id": node_id("node", name), "open": '("', "close": '")', "cls": "rosnode",
                         "label": [name]})
    for v in vertices:
        v["text"] = "<br/>".join(mermaid_label(part) for part in v["label"])
    edges = []
    for e in graph.edges:
        edges.append({"src": node_id(*e.src), "dst": node_id(*e.dst),
                      "label": mermaid_label(e.label) if e.label else "", "kind": e.kind})
    styles = []
    for kind, colour in EDGE_COLOURS.items():
        indexes = [str(i) for i, e in enumerate(edges) if e["kind"] == kind]
        if indexes:
            styles.append({"indexes": ",".join(indexes), "colour": colour})
    classes = []
    for cls in ("device", "bridge", "topic", "rosnode"):
        members = [v["id"] for v in vertices if v["cls"] == cls]
        if members:
            classes.append({"name": cls, "members": ",".join(members)})
    return {"vertices": vertices, "edges": edges, "link_styles": styles, "classes": classes}


def emit(resolved: Resolved) -> dict[str, str]:
    """The documentation files, by path under generated/."""
    from sam_codegen.targets.docs.dronecan import dronecan_context  # they import this module's helpers
    from sam_codegen.targets.docs.markdown import markdown_context
    from sam_codegen.targets.docs.svg import svg_context

    graph = build_graph(resolved)
    return {
        MD_PATH: render("docs/interfaces.md.j2", **markdown_context(resolved, graph),
                        **dronecan_context(resolved)).rstrip("\n") + "\n",
        SVG_PATH: render("docs/dataflow.svg.j2", **svg_context(resolved, graph)),
    }


__all__ = ["MD_PATH", "SVG_PATH", "describe_link", "describe_step", "emit", "fmt_number"]
