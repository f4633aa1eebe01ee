"""The dataflow picture (docs/dataflow.svg): what its template draws, laid out here so that it needs no graphviz and
comes out byte for byte the same.

svg_context lays out the Graph (graph.py) in steps, one function each: the boxes and their text (_boxes), their sizes
(_size_boxes), the columns devices -> bridge -> topics -> nodes and external publishers (_place_columns), the rows
(_place_rows: topics stacked in graph order, devices, nodes and external publishers at the barycentre of the topics
they reach), the ports where edges meet boxes (_side_ports, _bridge_ports), the paths (_edge_paths, _inner_paths)
and the legend.

Invariants:

- Integer coordinates, computed only from the spec, in spec and edge order: no randomness, no measuring of fonts (text
  widths are estimated for a monospace font, wide characters counting twice).
- Boxes of one column never overlap; a box is tall enough to keep its ports apart.
- The bridge meets every edge level with the edge's other end, so its lines run straight across it; inside the
  bridge, each mapping's device edges join its topic edge (the `inner` paths).
- Text is plain; the template escapes it (xml_text). Imported only by the package (emit).
"""

from __future__ import annotations

import math
import unicodedata
from dataclasses import dataclass
from pathlib import Path

from sam_codegen.model.spec import Spec
from sam_codegen.render.filters import one_line
from sam_codegen.targets.docs.graph import (
    EXTERNAL,
    PUBLISH,
    SUBSCRIBE,
    TEENSY_COLOUR,
    UAVCAN_TO_ROS,
    Edge,
    Graph,
)
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
PORT_GAP = {"device": 16, "bridge": 0, "topic": 7, "node": 10, EXTERNAL: 10}  # least distance between a box's ports
COLUMNS = ("device", "bridge", "topic", "node")  # box kinds, left to right
BRIDGE_TITLE = "The UAVCAN <-> ROS bridge (document section IV.B)."

BoxKey = tuple[str, str]  # (box kind, name), as Edge.src / Edge.dst
EdgeEnd = tuple[int, str]  # (edge index, "src" | "dst")
Point = tuple[int, int]


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
    def column(self) -> str:
        """The column it stands in: an external publisher's box stands with the nodes."""
        return "node" if self.kind == EXTERNAL else self.kind

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
    """The variables of templates/docs/dataflow.svg.j2: the laid-out boxes, edges and legend, and the canvas."""
    spec = resolved.spec
    boxes = _boxes(spec, graph)
    bridge_box = boxes.get(("bridge", graph.bridge)) if graph.bridge is not None else None
    widths = _size_boxes(boxes, graph)
    x = _place_columns(boxes, widths, bridge_box is not None)
    topics_bottom, topic_of_edge = _place_rows(boxes, graph, bridge_box)
    ports = _side_ports(boxes, graph, topic_of_edge)
    if bridge_box is not None:
        _bridge_ports(bridge_box, graph, ports)
    content_bottom = max([topics_bottom, *(b.y + b.h for b in boxes.values())])
    legend, teensy_y = _legend(content_bottom, graph.legend)
    width = x["node"] + widths["node"] + MARGIN
    width = max(width, MARGIN + 50 + max(text_width(t, SMALL_SIZE + 1) for _, t in graph.legend) + MARGIN)
    return {
        "width": width,
        "height": teensy_y + 24,
        "title": f"{spec.vehicle} dataflow, generated from {Path(spec.file).name}",
        "headings": _headings(x, bridge_box is not None),
        "heading_y": TOP + 10,
        "title_y": 26,
        "margin": MARGIN,
        "colours": graph.colours,
        "has_external": bool(graph.externals),
        "teensy_colour": TEENSY_COLOUR,
        "boxes": [
            {"kind": b.kind, "x": b.x, "y": b.y, "w": b.w, "h": b.h, "title": b.title, "rows": b.text_rows()}
            for b in boxes.values()
        ],
        "edges": _edge_paths(graph, ports),
        "inner": _inner_paths(graph, ports),
        "legend": legend,
        "teensy": {"y": teensy_y, "ty": teensy_y + 4},
    }


# ---- boxes and columns ------------------------------------------------------------------------------------

def _boxes(spec: Spec, graph: Graph) -> dict[BoxKey, Box]:
    """A box per device, topic, node and the bridge (in that order), with its lines of text; not yet placed."""
    boxes: dict[BoxKey, Box] = {}
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
    for name, who in graph.externals.items():
        lines = [("name", "external"), *([("small", _clip(who, 40))] if who else [])]
        boxes[(EXTERNAL, name)] = Box(EXTERNAL, name, lines, f"Published from outside the spec: {who or 'external'}")
    if graph.bridge is not None and spec.bridge is not None:
        lines = [("name", graph.bridge), ("small", f"node id {spec.bridge.node_id}"),
                 ("small", f"{len(spec.bridge.mappings)} mappings")]
        boxes[("bridge", graph.bridge)] = Box("bridge", graph.bridge, lines, BRIDGE_TITLE)
    return boxes


def _column(boxes: dict[BoxKey, Box], kind: str) -> list[Box]:
    return [b for b in boxes.values() if b.column == kind]


def _size_boxes(boxes: dict[BoxKey, Box], graph: Graph) -> dict[str, int]:
    """Size every box: one width per column (its widest text, at least 140), each box tall enough for its text and to
    keep its ports apart. Returns the width of each column."""
    degree = dict.fromkeys(boxes, 0)  # edges per box
    for e in graph.edges:
        degree[e.src] += 1
        degree[e.dst] += 1
    widths = {}
    for kind in COLUMNS:
        members = _column(boxes, kind)
        widths[kind] = max([140, *(_content_width(b.lines) for b in members)])
        for b in members:
            b.w, b.h = widths[kind], max(_content_height(b.lines), (degree[(b.kind, b.name)] + 1) * PORT_GAP[b.kind])
    return widths


def _place_columns(boxes: dict[BoxKey, Box], widths: dict[str, int], has_bridge: bool) -> dict[str, int]:
    """Set each box's x from its column; returns the left edge of each column (the bridge's takes no room when
    there is no bridge)."""
    x = {"device": MARGIN}
    x["bridge"] = x["device"] + widths["device"] + GAP_DEVICE_BRIDGE
    x["topic"] = (x["bridge"] + widths["bridge"] + GAP_BRIDGE_TOPIC) if has_bridge else x["bridge"]
    x["node"] = x["topic"] + widths["topic"] + GAP_TOPIC_NODE
    for kind in COLUMNS:
        for b in _column(boxes, kind):
            b.x = x[kind]
    return x


def _headings(x: dict[str, int], has_bridge: bool) -> list[dict[str, object]]:
    headings: list[dict[str, object]] = [
        {"x": x["device"], "text": "UAVCAN devices (via Teensy)"},
        {"x": x["topic"], "text": "ROS topics"},
        {"x": x["node"], "text": "ROS nodes"},
    ]
    if has_bridge:
        headings.insert(1, {"x": x["bridge"], "text": "Bridge (IV.B)"})
    return headings


# ---- rows ----------------------------------------------------------------------------------------------------

def _topic_y(boxes: dict[BoxKey, Box], edge: Edge) -> float:
    """The height of the topic at one end of an edge that has a topic end."""
    return boxes[edge.src if edge.src[0] == "topic" else edge.dst].cy


def _place_rows(boxes: dict[BoxKey, Box], graph: Graph, bridge_box: Box | None) -> tuple[int, dict[int, int]]:
    """Set each box's y: topics stacked in graph order below the bridge's title, devices and nodes at the mean height
    of the topics they reach (unconnected ones at the bottom, in spec order). Returns the bottom of the topics, and
    {device edge: the topic edge of its mapping} (first link wins)."""
    top = CONTENT_TOP + (bridge_box.h + 14 if bridge_box is not None else 0)
    y = top
    for name in graph.topics:
        b = boxes[("topic", name)]
        b.y = y
        y += b.h + ROW_GAP
    topics_bottom = y - ROW_GAP
    linked_ys, topic_of_edge = _linked_heights(boxes, graph)
    for kind in ("device", "node"):
        members = _column(boxes, kind)
        desired = {}
        for i, b in enumerate(members):
            ys = linked_ys.get((b.kind, b.name), [])
            desired[b.name] = sum(ys) / len(ys) if ys else 1e9 + i  # unconnected: at the bottom, in spec order
        _stack(members, desired, top, max(topics_bottom, top))
    return topics_bottom, topic_of_edge


def _linked_heights(boxes: dict[BoxKey, Box], graph: Graph) -> tuple[dict[BoxKey, list[float]], dict[int, int]]:
    """The heights of the topics each box is linked to, in link order then edge order (one pass: large specs), and
    {device edge: the topic edge of its mapping} (first link wins)."""
    linked_ys: dict[BoxKey, list[float]] = {}
    topic_of_edge: dict[int, int] = {}
    for _, dev_edges, topic_edge in graph.links:
        ty = _topic_y(boxes, graph.edges[topic_edge])
        for key in dict.fromkeys(k for i in dev_edges for k in (graph.edges[i].src, graph.edges[i].dst)):
            linked_ys.setdefault(key, []).append(ty)
        for i in dev_edges:
            topic_of_edge.setdefault(i, topic_edge)
    for e in graph.edges:
        if e.kind in (SUBSCRIBE, PUBLISH, EXTERNAL):
            ty = _topic_y(boxes, e)
            for key in dict.fromkeys((e.src, e.dst)):
                linked_ys.setdefault(key, []).append(ty)
    return linked_ys, topic_of_edge


# ---- ports and paths -----------------------------------------------------------------------------------------

def _side_ports(boxes: dict[BoxKey, Box], graph: Graph, topic_of_edge: dict[int, int]) -> dict[EdgeEnd, Point]:
    """Where each edge meets each box other than the bridge: a topic's bridge edges and all of a node's on its left,
    the rest on the right; on each side, spread evenly in the order of the heights of the other ends."""
    ports: dict[EdgeEnd, Point] = {}

    def other_y(i: int, end: str) -> float:
        e = graph.edges[i]
        other = e.dst if end == "src" else e.src
        if other[0] == "bridge" and i in topic_of_edge:  # follow the bridge to the topic the mapping leads to
            return _topic_y(boxes, graph.edges[topic_of_edge[i]])
        return boxes[other].cy

    def attach(box: Box, side: str, ends: list[EdgeEnd]) -> None:
        ends = sorted(ends, key=lambda ie: (other_y(*ie), ie[0]))
        x = box.x + box.w if side == "right" else box.x
        for k, end in enumerate(ends):
            ports[end] = (x, _spread(box, len(ends), k))

    ends_of: dict[BoxKey, list[EdgeEnd]] = {}  # box -> its edge ends, in edge order
    for i, e in enumerate(graph.edges):
        for end, which in (("src", e.src), ("dst", e.dst)):
            ends_of.setdefault(which, []).append((i, end))
    for key, box in boxes.items():
        if box.kind == "bridge":
            continue
        left: list[EdgeEnd] = []
        right: list[EdgeEnd] = []
        for i, end in ends_of.get(key, []):
            e = graph.edges[i]
            other = e.dst if end == "src" else e.src
            faces_left = (box.kind == "topic" and other[0] == "bridge") or box.column == "node"
            (left if faces_left else right).append((i, end))
        attach(box, "left", left)
        attach(box, "right", right)
    return ports


def _bridge_ports(bridge_box: Box, graph: Graph, ports: dict[EdgeEnd, Point]) -> None:
    """Add the bridge's ends to `ports`, each level with the edge's other end (devices on the left, topics on the
    right), and make the bridge box reach from the top of the content past its lowest port."""
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


def _edge_paths(graph: Graph, ports: dict[EdgeEnd, Point]) -> list[dict[str, object]]:
    """Each edge as a path between its ports, with its label (the subject id) on a background at the middle."""
    edges = []
    for i, e in enumerate(graph.edges):
        x1, y1 = ports[(i, "src")]
        x2, y2 = ports[(i, "dst")]
        edge: dict[str, object] = {"kind": e.kind, "d": _curve(x1, y1, x2, y2), "label": None}
        if e.label:
            w = text_width(e.label, SMALL_SIZE) + 6
            mx, my = (x1 + x2) // 2, (y1 + y2) // 2
            edge["label"] = {"text": e.label, "x": mx, "y": my + 3, "rx": mx - w // 2, "ry": my - 7, "w": w, "h": 13}
        edges.append(edge)
    return edges


def _inner_paths(graph: Graph, ports: dict[EdgeEnd, Point]) -> list[dict[str, object]]:
    """Inside the bridge, for each mapping: from each of its device edges to its topic edge."""
    inner: list[dict[str, object]] = []
    for direction, dev_edges, topic_edge in graph.links:
        t_end = "dst" if direction == UAVCAN_TO_ROS else "src"
        d_end = "src" if direction == UAVCAN_TO_ROS else "dst"
        for i in dev_edges:
            x1, y1 = ports[(i, d_end)]
            x2, y2 = ports[(topic_edge, t_end)]
            inner.append({"kind": direction, "d": _curve(x1, y1, x2, y2)})
    return inner


def _legend(content_bottom: int, rows: list[tuple[str, str]]) -> tuple[list[dict[str, object]], int]:
    """The legend rows below the content, and the height of the Teensy note below them."""
    legend_top = content_bottom + 28
    legend: list[dict[str, object]] = []
    for k, (kind, text) in enumerate(rows):
        y = legend_top + k * 18
        legend.append({"kind": kind, "y": y, "d": f"M{MARGIN},{y} L{MARGIN + 40},{y}", "tx": MARGIN + 50,
                       "ty": y + 4, "text": text})
    return legend, legend_top + len(rows) * 18


__all__ = ["svg_context", "text_width"]
