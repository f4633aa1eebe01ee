"""The dataflow graph of the docs target, shared by the Mermaid block of interfaces.md and by dataflow.svg.

Holds the edge kinds (which are also the CSS classes, arrow markers and colours of both pictures), Edge and Graph,
PortIndex (who publishes and subscribes each subject, and at what rates), mapping_devices, build_graph, and the
Mermaid form of the graph (mermaid_label, mermaid_context).

Invariants:

- build_graph computes structure only; it adds each edge once (same kind, ends and label) and keeps spec order, so
  both pictures come out byte for byte the same for the same spec.
- Graph.topics is in layout order: topics the bridge links, in the order of the devices they come from or go to,
  then the rest in spec order.
- Every Graph.links entry (one per bridge mapping whose topic exists) names edges of Graph.edges by index.
- Names from the spec reach Mermaid only through mermaid_label; the SVG escapes in its template (xml_text).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from sam_codegen.model.spec import Device, Mapping, Spec
from sam_codegen.validate.nodes import node_published_topics, node_subscribed_topics
from sam_codegen.validate.resolve import Resolved

SVG_NAME = "dataflow.svg"  # the picture's file name, beside interfaces.md (which links it)

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
# Topics `published_by: external`: one box per distinct "who" in the nodes' column, its edges in their own colour.
# Drawn (and in the legend) only for a spec that has them, so the pictures of other specs stay as they were.
EXTERNAL = "external"
EXTERNAL_COLOUR = "#7f8c8d"
EXTERNAL_LEGEND = (EXTERNAL, "published from outside the spec (published_by: external)")


def external_box(who: str) -> str:
    """The name of the box of an external publisher: never a node's name (those are identifiers).

    >>> external_box(""), external_box("the operator GUI")
    ('(external)', '(external) the operator GUI')
    """
    return f"(external) {who}" if who else "(external)"


# ---- the graph (shared by the Mermaid block and the SVG) -----------------------------------------------

@dataclass
class Edge:
    """One arrow: a box (kind, name) to another, with the subject id as label on the device side of the bridge."""

    kind: str  # UAVCAN_TO_ROS | ROS_TO_UAVCAN | SUBSCRIBE | PUBLISH | EXTERNAL
    src: tuple[str, str]  # (box kind, name)
    dst: tuple[str, str]
    label: str = ""


@dataclass
class Graph:
    """The boxes of the four columns (devices, the bridge, topics, nodes and external publishers), the edges between
    them, and how each bridge mapping runs through the bridge."""

    devices: list[str]
    bridge: str | None
    topics: list[str]  # in layout order
    nodes: list[str]
    edges: list[Edge] = field(default_factory=list)
    # per mapping: (direction, its device-side edges, its topic-side edge), joined inside the bridge
    links: list[tuple[str, list[int], int]] = field(default_factory=list)
    externals: dict[str, str] = field(default_factory=dict)  # box name -> who (external_box), in topic order

    @property
    def colours(self) -> dict[str, str]:
        """The edge kinds this graph draws, with their colours."""
        return {**EDGE_COLOURS, EXTERNAL: EXTERNAL_COLOUR} if self.externals else dict(EDGE_COLOURS)

    @property
    def legend(self) -> list[tuple[str, str]]:
        return [*LEGEND, EXTERNAL_LEGEND] if self.externals else list(LEGEND)


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
    """The dataflow of the spec: devices -> bridge -> topics for each mapping (reversed for ROS -> UAVCAN), and the
    topics each node subscribes or publishes. Topics the spec does not declare are left out."""
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
    for name in topics:
        who = spec.topics[name].external_publisher
        if who is not None:
            box = external_box(who)
            graph.externals.setdefault(box, who)
            add(Edge(EXTERNAL, (EXTERNAL, box), ("topic", name)))
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
    """The Mermaid flowchart of the graph for interfaces.md: vertices with unique ids, edges, and the link styles and
    classes that colour them like the SVG."""
    spec = resolved.spec
    ids: dict[tuple[str, str], str] = {}
    used: set[str] = set()

    def node_id(kind: str, name: str) -> str:
        key = (kind, name)
        if key not in ids:
            prefix = {"device": "dev", "bridge": "bridge", "topic": "topic", "node": "node", EXTERNAL: "ext"}[kind]
            base = prefix + "_" + (re.sub(r"[^A-Za-z0-9]+", "_", name).strip("_") or "x")
            candidate, n = base, 2
            while candidate in used:
                candidate, n = f"{base}_{n}", n + 1
            used.add(candidate)
            ids[key] = candidate
        return ids[key]

    vertices: list[dict[str, str]] = []

    def vertex(kind: str, name: str, shape: tuple[str, str], cls: str, label: list[str]) -> None:
        vertices.append({"id": node_id(kind, name), "open": shape[0], "close": shape[1], "cls": cls,
                         "text": "<br/>".join(mermaid_label(part) for part in label)})

    for name in graph.devices:
        vertex("device", name, ('["', '"]'), "device", [name, f"node {spec.devices[name].node_id}"])
    if graph.bridge is not None and spec.bridge is not None:
        vertex("bridge", graph.bridge, ('[["', '"]]'), "bridge", [graph.bridge, f"node {spec.bridge.node_id}"])
    for name in graph.topics:
        vertex("topic", name, ('(["', '"])'), "topic", [name, spec.topics[name].type])
    for name in graph.nodes:
        vertex("node", name, ('("', '")'), "rosnode", [name])
    for name, who in graph.externals.items():
        vertex(EXTERNAL, name, ('[/"', '"/]'), EXTERNAL, [EXTERNAL, *([who] if who else [])])
    edges = []
    for e in graph.edges:
        edges.append({"src": node_id(*e.src), "dst": node_id(*e.dst),
                      "label": mermaid_label(e.label) if e.label else "", "kind": e.kind})
    styles = []
    for kind, colour in graph.colours.items():
        indexes = [str(i) for i, e in enumerate(edges) if e["kind"] == kind]
        if indexes:
            styles.append({"indexes": ",".join(indexes), "colour": colour})
    classes = []
    for cls in ("device", "bridge", "topic", "rosnode", EXTERNAL):
        members = [v["id"] for v in vertices if v["cls"] == cls]
        if members:
            classes.append({"name": cls, "members": ",".join(members)})
    return {"vertices": vertices, "edges": edges, "link_styles": styles, "classes": classes,
            "has_external": bool(graph.externals)}


__all__ = [
    "EDGE_COLOURS",
    "EXTERNAL",
    "EXTERNAL_COLOUR",
    "LEGEND",
    "PUBLISH",
    "ROS_TO_UAVCAN",
    "SUBSCRIBE",
    "SVG_NAME",
    "TEENSY_COLOUR",
    "UAVCAN_TO_ROS",
    "Edge",
    "Graph",
    "PortIndex",
    "build_graph",
    "external_box",
    "mapping_devices",
    "mermaid_context",
    "mermaid_label",
]
