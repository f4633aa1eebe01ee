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

from .mapping_rules import Step
from .model import Device, Mapping, Scalar, Spec
from .templating import render
from .validate import Resolved
from .validate_nodes import node_published_topics, node_subscribed_topics

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


def _bits(type_name: str) -> int:
    match = re.search(r"(\d+)$", type_name)
    return int(match[1]) if match else 0


def _is_int(type_name: str) -> bool:
    return bool(re.match(r"^u?int\d+$", type_name)) or type_name in ("byte", "char")


def _is_float(type_name: str) -> bool:
    return type_name.startswith("float")


def _width_change(src: str, dst: str) -> str:
    """'widened', 'narrowed' or '' for a scalar going from type src to type dst."""
    if src == dst:
        return ""
    if _is_int(src) and _is_float(dst):
        return "as float"
    if _is_float(src) and _is_int(dst):
        return "rounded"
    if _bits(dst) > _bits(src):
        return "widened"
    if _bits(dst) < _bits(src):
        return "narrowed"
    return ""


def _transform(step: Step, direction: str) -> str:
    """Scale and offset as the bridge applies them: ros = uavcan × scale + offset, and the inverse."""
    if direction == UAVCAN_TO_ROS:
        parts = [f"× {fmt_number(step.scale)}"] if step.scale is not None else []
        if step.offset is not None:
            parts.append(("- " if step.offset < 0 else "+ ") + fmt_number(abs(step.offset)))
        return " ".join(parts)
    parts = [("+ " if step.offset < 0 else "- ") + fmt_number(abs(step.offset))] if step.offset is not None else []
    if step.scale is not None:
        parts.append(f"÷ {fmt_number(step.scale)}")
    return ", then ".join(parts)


def describe_step(step: Step, direction: str, on_out_of_range: str) -> str:
    """The conversion of one field link in words, in the direction the bridge runs it.

    Out-of-range handling (narrowing, rounding, lengths) follows the mapping's on_out_of_range.
    """
    if step.kind == "value":
        return f"constant {fmt_number(step.value)}"
    ros = step.ros_type
    uav = step.uavcan_type
    assert uav is not None
    to_ros = direction == UAVCAN_TO_ROS
    saturate = on_out_of_range == "saturate"
    if step.kind == "time":
        return f"usec → {ros.base} (0 = receive time)" if to_ros else f"{ros.base} → usec"
    src, dst = (str(uav), str(ros)) if to_ros else (str(ros), str(uav))
    if step.kind == "string":
        note = "invalid UTF-8 replaced" if to_ros else \
            f"longer than {uav.capacity} bytes {'cut' if saturate else 'rejected'}"
        return f"{src} → {dst} ({note})"
    src_elem, dst_elem = (uav.base_name, ros.base) if to_ros else (ros.base, uav.base_name)
    text = f"{src} → {dst}" if step.kind == "array" else f"{src_elem} → {dst_elem}"
    notes: list[str] = []
    if step.kind == "table":
        pairs = ", ".join(f"{k}: {v}" for k, v in step.table)
        if to_ros and step.table_default is not None:  # the inverse rejects what has no key
            pairs += f", default: {step.table_default}"
        text += f" table {{{pairs}}}" if to_ros else f" inverse of table {{{pairs}}}"
        if not step.exact:
            notes.append("not one to one")
        return text + (f" ({', '.join(notes)})" if notes else "")
    transform = _transform(step, direction)
    limits = "" if step.limits is None else f" limits [{fmt_number(step.limits[0])}, {fmt_number(step.limits[1])}]"
    if transform and limits and not to_ros:  # limits are in ROS units: they come first
        text += limits + " " + transform
    else:
        text += (" " + transform if transform else "") + limits
    change = _width_change(src_elem, dst_elem)
    if change in ("narrowed", "rounded"):
        notes.append(change + (", saturating" if saturate else ", out of range rejected"))
    elif change and not transform:
        notes.append(change)
    if step.kind == "array":
        cap = uav.capacity or 0
        if to_ros and uav.array == "bounded" and ros.array == "fixed":
            notes.append(f"padded to {ros.capacity}")
        elif not to_ros and uav.array == "fixed" and ros.array != "fixed":
            notes.append(f"other lengths {'padded or cut' if saturate else 'rejected'}")
        elif not to_ros and uav.array == "bounded" and (ros.array != "fixed" or (ros.capacity or 0) > cap):
            notes.append(f"over {cap} elements {'cut' if saturate else 'rejected'}")
    return text + (f" ({', '.join(notes)})" if notes else "")


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
    from .docs_dronecan import dronecan_context  # they import this module's helpers
    from .docs_markdown import markdown_context
    from .docs_svg import svg_context

    graph = build_graph(resolved)
    return {
        MD_PATH: render("docs/interfaces.md.j2", **markdown_context(resolved, graph),
                        **dronecan_context(resolved)).rstrip("\n") + "\n",
        SVG_PATH: render("docs/dataflow.svg.j2", **svg_context(resolved, graph)),
    }


__all__ = ["MD_PATH", "SVG_PATH", "describe_step", "emit", "fmt_number"]
