"""The dataflow picture (docs/dataflow.svg) of emit_docs: columns devices -> bridge -> topics -> nodes, rows by
barycentre, laid out here so that it needs no graphviz and comes out byte for byte the same."""

from __future__ import annotations

import math
import unicodedata
from dataclasses import dataclass
from pathlib import Path

from sam_codegen.render.filters import one_line
from sam_codegen.targets.docs.graph import EDGE_COLOURS, LEGEND, PUBLISH, SUBSCRIBE, TEENSY_COLOUR, UAVCAN_TO_ROS, Graph
from sam_codegen.validate.resolve import Resolved

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
