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
import unicodedata
from collections.abc import Hashable, Iterable
from dataclasses import dataclass, field
from decimal import Decimal
from pathlib import Path

from .filters import one_line
from .mapping_rules import ResolvedMapping, Step, format_path
from .model import Device, Mapping, Port, Scalar, Spec
from .templating import render
from .validate import Resolved

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
    if transform:
        text += " " + transform
    if step.limits is not None:
        text += f" limits [{fmt_number(step.limits[0])}, {fmt_number(step.limits[1])}]"
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
        for topic in node.subscribes:
            if topic in spec.topics:
                add(Edge(SUBSCRIBE, ("topic", topic), ("node", node.name)))
        for topic in node.publishes:
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


# ---- SVG layout ------------------------------------------------------------------------------------------

MONO_ADVANCE = 0.6  # advance of a monospace glyph, in em
NAME_SIZE, SMALL_SIZE = 12, 10
NAME_LINE, SMALL_LINE = 16, 13
PAD_X, PAD_Y = 10, 6
ROW_GAP = 10
MARGIN = 20
GAP_DEVICE_BRIDGE = 110  # room for the subject id labels
GAP_BRIDGE_TOPIC = 60
GAP_TOPIC_NODE = 160
TOP = 52  # below the title: column headings
CONTENT_TOP = 76
PORT_GAP = {"device": 16, "bridge": 0, "topic": 7, "node": 10}  # least distance between the ports of a box


def text_width(text: str, size: int) -> int:
    """Estimated width of monospace text; wide (East Asian) characters count twice."""
    cells = sum(2 if unicodedata.east_asian_width(ch) in "WF" else 1 for ch in text)
    return math.ceil(cells * size * MONO_ADVANCE)


@dataclass
class Box:
    kind: str
    name: str
    lines: list[tuple[str, str]]  # (css class: name | small, text)
    title: str
    x: int = 0
    y: int = 0
    w: int = 0
    h: int = 0

    @property
    def cy(self) -> float:
        return self.y + self.h / 2

    def text_rows(self) -> list[dict[str, object]]:
        rows, top = [], self.y + PAD_Y
        for cls, text in self.lines:
            size, line = (NAME_SIZE, NAME_LINE) if cls == "name" else (SMALL_SIZE, SMALL_LINE)
            rows.append({"x": self.x + PAD_X, "y": top + (line + size) // 2 - 1, "cls": cls, "text": text})
            top += line
        return rows


def _clip(text: str, limit: int) -> str:
    """Free text for a box line, cut to `limit` characters.

    >>> _clip("IV.C.1", 24), _clip("x" * 30, 8)
    ('IV.C.1', 'xxxxxxx…')
    """
    return text if len(text) <= limit else text[: limit - 1] + "…"


def _content_height(lines: list[tuple[str, str]]) -> int:
    return 2 * PAD_Y + sum(NAME_LINE if cls == "name" else SMALL_LINE for cls, _ in lines)


def _content_width(lines: list[tuple[str, str]]) -> int:
    return 2 * PAD_X + max(text_width(t, NAME_SIZE if c == "name" else SMALL_SIZE) for c, t in lines)


def _stack(boxes: list[Box], desired: dict[str, float], top: int, bottom: int) -> None:
    """Place boxes at their desired centres, in that order, without overlaps; within [top, bottom] if they fit."""
    order = sorted(boxes, key=lambda b: desired[b.name])
    y = top
    for b in order:
        b.y = max(y, round(desired[b.name] - b.h / 2))
        y = b.y + b.h + ROW_GAP
    limit = bottom
    for b in reversed(order):  # pull back up what ran past the bottom
        if b.y + b.h > limit:
            b.y = max(top, limit - b.h)
        limit = b.y - ROW_GAP
    y = top
    for b in order:  # and never above the top
        b.y = max(b.y, y)
        y = b.y + b.h + ROW_GAP


def _spread(box: Box, count: int, index: int) -> int:
    return round(box.y + box.h * (index + 1) / (count + 1))


def _curve(x1: int, y1: int, x2: int, y2: int) -> str:
    if y1 == y2:
        return f"M{x1},{y1} L{x2},{y2}"
    c = (x2 - x1) // 2
    return f"M{x1},{y1} C{x1 + c},{y1} {x2 - c},{y2} {x2},{y2}"


def svg_context(resolved: Resolved, graph: Graph) -> dict[str, object]:
    spec = resolved.spec
    boxes: dict[tuple[str, str], Box] = {}
    for name in graph.devices:
        d = spec.devices[name]
        lines = [("name", name), ("small", f"node id {d.node_id}")]
        lines += [("small", f"pub {p.subject_id} {p.type}") for p in d.publishes]
        lines += [("small", f"sub {p.subject_id} {p.type}") for p in d.subscribes]
        boxes[("device", name)] = Box("device", name, lines, d.description)
    for name in graph.topics:
        t = spec.topics[name]
        lines = [("name", name), ("small", t.type + (f"  ({_clip(one_line(t.section), 24)})" if t.section else ""))]
        boxes[("topic", name)] = Box("topic", name, lines, t.description)
    for name in graph.nodes:
        n = spec.nodes[name]
        lines = [("name", name)]
        lines += [("small", f"tf {parent} -> {child}") for parent, child in n.transforms]
        lines += [("small", f"param {p}") for p in n.parameters]
        boxes[("node", name)] = Box("node", name, lines, n.description)
    bridge_box = None
    if graph.bridge is not None and spec.bridge is not None:
        lines = [("name", graph.bridge), ("small", f"node id {spec.bridge.node_id}"),
                 ("small", f"{len(spec.bridge.mappings)} mappings")]
        bridge_box = Box("bridge", graph.bridge, lines, "The UAVCAN <-> ROS bridge (document section IV.B).")
        boxes[("bridge", graph.bridge)] = bridge_box

    def column(kind: str) -> list[Box]:
        return [b for b in boxes.values() if b.kind == kind]

    degree = {key: 0 for key in boxes}  # edges per box; a box is tall enough to keep its ports apart
    for e in graph.edges:
        degree[e.src] += 1
        degree[e.dst] += 1
    widths = {}
    for kind in ("device", "bridge", "topic", "node"):
        members = column(kind)
        widths[kind] = max([140, *(_content_width(b.lines) for b in members)])
        for b in members:
            b.w, b.h = widths[kind], max(_content_height(b.lines), (degree[(kind, b.name)] + 1) * PORT_GAP[kind])

    x_device = MARGIN
    x_bridge = x_device + widths["device"] + GAP_DEVICE_BRIDGE
    x_topic = (x_bridge + widths["bridge"] + GAP_BRIDGE_TOPIC) if bridge_box is not None else x_bridge
    x_node = x_topic + widths["topic"] + GAP_TOPIC_NODE
    for kind, x in (("device", x_device), ("bridge", x_bridge), ("topic", x_topic), ("node", x_node)):
        for b in column(kind):
            b.x = x

    # Rows: topics stacked in graph order; devices and nodes at the mean height of the topics they reach.
    title_h = bridge_box.h if bridge_box is not None else 0
    top = CONTENT_TOP + (title_h + 14 if bridge_box is not None else 0)
    y = top
    for name in graph.topics:
        b = boxes[("topic", name)]
        b.y = y
        y += b.h + ROW_GAP
    topics_bottom = y - ROW_GAP

    # Heights of the topics each box is linked to, in link order then edge order (one pass: large specs).
    linked_ys: dict[tuple[str, str], list[float]] = {}
    topic_of_edge: dict[int, int] = {}  # device edge -> the topic edge of its mapping (first link wins)
    for _, dev_edges, topic_edge in graph.links:
        t = graph.edges[topic_edge]
        ty = boxes[t.src if t.src[0] == "topic" else t.dst].cy
        for key in dict.fromkeys(k for i in dev_edges for k in (graph.edges[i].src, graph.edges[i].dst)):
            linked_ys.setdefault(key, []).append(ty)
        for i in dev_edges:
            topic_of_edge.setdefault(i, topic_edge)
    for e in graph.edges:
        if e.kind in (SUBSCRIBE, PUBLISH):
            ty = boxes[e.src if e.src[0] == "topic" else e.dst].cy
            for key in dict.fromkeys((e.src, e.dst)):
                linked_ys.setdefault(key, []).append(ty)

    def neighbours(key: tuple[str, str]) -> list[float]:
        return linked_ys.get(key, [])

    for kind in ("device", "node"):
        members = column(kind)
        desired = {}
        for i, b in enumerate(members):
            ys = neighbours((kind, b.name))
            desired[b.name] = sum(ys) / len(ys) if ys else 1e9 + i  # unconnected: at the bottom, in spec order
        _stack(members, desired, top, max(topics_bottom, top))

    # Ports: where each edge meets each box side.
    ports: dict[tuple[int, str], tuple[int, int]] = {}  # (edge index, "src"|"dst") -> point

    def other_y(i: int, end: str) -> float:
        e = graph.edges[i]
        other = e.dst if end == "src" else e.src
        if other[0] == "bridge" and i in topic_of_edge:  # follow the bridge to the topic the mapping leads to
            t = graph.edges[topic_of_edge[i]]
            return boxes[t.src if t.src[0] == "topic" else t.dst].cy
        return boxes[other].cy

    def attach(box: Box, side: str, ends: list[tuple[int, str]]) -> None:
        ends = sorted(ends, key=lambda ie: (other_y(*ie), ie[0]))
        x = box.x + box.w if side == "right" else box.x
        for k, end in enumerate(ends):
            ports[end] = (x, _spread(box, len(ends), k))

    ends_of: dict[tuple[str, str], list[tuple[int, str]]] = {}  # box -> its edge ends, in edge order
    for i, e in enumerate(graph.edges):
        for end, which in (("src", e.src), ("dst", e.dst)):
            ends_of.setdefault(which, []).append((i, end))
    for key, box in boxes.items():
        if box.kind == "bridge":
            continue
        left: list[tuple[int, str]] = []
        right: list[tuple[int, str]] = []
        for i, end in ends_of.get(key, []):
            e = graph.edges[i]
            other = e.dst if end == "src" else e.src
            faces_left = (box.kind == "topic" and other[0] == "bridge") or box.kind == "node"
            (left if faces_left else right).append((i, end))
        attach(box, "left", left)
        attach(box, "right", right)
    if bridge_box is not None:  # the bridge meets each edge level with its other end
        for i, e in enumerate(graph.edges):
            for end, which in (("src", e.src), ("dst", e.dst)):
                if which[0] != "bridge":
                    continue
                other_end = "dst" if end == "src" else "src"
                other = e.dst if end == "src" else e.src
                x = bridge_box.x if other[0] == "device" else bridge_box.x + bridge_box.w
                ports[(i, end)] = (x, ports[(i, other_end)][1])
        levels = [p[1] for (i, _), p in ports.items() if "bridge" in (graph.edges[i].src[0], graph.edges[i].dst[0])]
        bridge_box.y = CONTENT_TOP
        bridge_box.h = max([bridge_box.h + 14, *(y - CONTENT_TOP + 16 for y in levels)])

    edges = []
    for i, e in enumerate(graph.edges):
        x1, y1 = ports[(i, "src")]
        x2, y2 = ports[(i, "dst")]
        edge = {"kind": e.kind, "d": _curve(x1, y1, x2, y2), "label": None}
        if e.label:
            w = text_width(e.label, SMALL_SIZE) + 6
            mx, my = (x1 + x2) // 2, (y1 + y2) // 2
            edge["label"] = {"text": e.label, "x": mx, "y": my + 3, "rx": mx - w // 2, "ry": my - 7, "w": w, "h": 13}
        edges.append(edge)
    inner = []
    for direction, dev_edges, topic_edge in graph.links:
        t_end = "dst" if direction == UAVCAN_TO_ROS else "src"
        d_end = "src" if direction == UAVCAN_TO_ROS else "dst"
        for i in dev_edges:
            x1, y1 = ports[(i, d_end)]
            x2, y2 = ports[(topic_edge, t_end)]
            inner.append({"kind": direction, "d": _curve(x1, y1, x2, y2)})

    content_bottom = max([topics_bottom, *(b.y + b.h for b in boxes.values())])
    legend_top = content_bottom + 28
    legend = []
    for k, (kind, text) in enumerate(LEGEND):
        y = legend_top + k * 18
        legend.append({"kind": kind, "y": y, "d": f"M{MARGIN},{y} L{MARGIN + 40},{y}", "tx": MARGIN + 50,
                       "ty": y + 4, "text": text})
    teensy_y = legend_top + len(LEGEND) * 18
    width = x_node + widths["node"] + MARGIN
    width = max(width, MARGIN + 50 + max(text_width(t, SMALL_SIZE + 1) for _, t in LEGEND) + MARGIN)
    height = teensy_y + 24
    headings = [
        {"x": x_device, "text": "UAVCAN devices (via Teensy)"},
        {"x": x_topic, "text": "ROS topics"},
        {"x": x_node, "text": "ROS nodes"},
    ]
    if bridge_box is not None:
        headings.insert(1, {"x": x_bridge, "text": "Bridge (IV.B)"})
    spec_name = Path(spec.file).name
    return {
        "width": width,
        "height": height,
        "title": f"{spec.vehicle} dataflow, generated from {spec_name}",
        "headings": headings,
        "heading_y": TOP + 10,
        "title_y": 26,
        "margin": MARGIN,
        "colours": EDGE_COLOURS,
        "teensy_colour": TEENSY_COLOUR,
        "boxes": [
            {"kind": b.kind, "x": b.x, "y": b.y, "w": b.w, "h": b.h, "title": b.title, "rows": b.text_rows()}
            for b in boxes.values()
        ],
        "edges": edges,
        "inner": inner,
        "legend": legend,
        "teensy": {"y": teensy_y, "ty": teensy_y + 4},
    }


# ---- Markdown context -------------------------------------------------------------------------------------

def _range(minimum: float | None, maximum: float | None) -> str:
    if minimum is not None and maximum is not None:
        return f"[{fmt_number(minimum)}, {fmt_number(maximum)}]"
    if minimum is not None:
        return f">= {fmt_number(minimum)}"
    if maximum is not None:
        return f"<= {fmt_number(maximum)}"
    return ""


def _field_rows(rm: ResolvedMapping) -> list[dict[str, object]]:
    """The field table of a mapping: the header the bridge fills, then each link, constants and ignored fields."""
    m = rm.mapping
    rows: list[dict[str, object]] = []
    arrow = "←" if m.direction == UAVCAN_TO_ROS else "→"

    def step_row(step: Step) -> dict[str, object]:
        return {"ros": step.ros, "arrow": arrow, "uavcan": step.uavcan or None,
                "conversion": describe_step(step, m.direction, m.on_out_of_range)}

    steps = list(rm.steps)
    if m.direction == UAVCAN_TO_ROS and rm.has_header:
        stamp = next((s for s in steps if s.ros == "header.stamp"), None)
        if stamp is not None:
            steps.remove(stamp)
            rows.append(step_row(stamp))
        else:
            rows.append({"ros": "header.stamp", "arrow": arrow, "uavcan": None, "conversion": "receive time"})
        if m.frame_id is not None:
            rows.append({"ros": "header.frame_id", "arrow": arrow, "uavcan": None,
                         "conversion": f"constant {m.frame_id}"})
    rows.extend(step_row(step) for step in steps)
    for path, _, value in rm.uavcan_values:
        rows.append({"ros": None, "arrow": arrow, "uavcan": format_path(list(path)),
                     "conversion": f"constant {fmt_number(value)}"})
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
    node_publishers = _users((n.name, n.publishes) for n in spec.nodes.values())  # topic -> nodes
    node_subscribers = _users((n.name, n.subscribes) for n in spec.nodes.values())
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
        topics.append({"name": name, "type": t.type, "section": t.section, "description": t.description,
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

    frames = [{"name": f.name, "parent": f.parent, "description": f.description} for f in spec.frames.values()]
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
              "parameters": n.parameters, "transforms": [f"{p}->{c}" for p, c in n.transforms]}
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


def emit(resolved: Resolved) -> dict[str, str]:
    """The documentation files, by path under generated/."""
    graph = build_graph(resolved)
    return {
        MD_PATH: render("docs/interfaces.md.j2", **markdown_context(resolved, graph)).rstrip("\n") + "\n",
        SVG_PATH: render("docs/dataflow.svg.j2", **svg_context(resolved, graph)),
    }


__all__ = ["MD_PATH", "SVG_PATH", "describe_step", "emit", "fmt_number"]
