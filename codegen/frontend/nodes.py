"""The spec's ROS graph sections: parameters, QoS, frames and nodes."""

from __future__ import annotations

import math

from sam_codegen.frontend.reading import Reader, kind_of, number, scalar, seq_items, str_list, text_of, vector3
from sam_codegen.frontend.yaml_source import YMap, YNode, YScalar
from sam_codegen.model.diagnostics import Diagnostics, Pos
from sam_codegen.model.spec import (
    DURABILITIES,
    QOS_PROFILES,
    QOS_SIDES,
    RELIABILITIES,
    Frame,
    Node,
    NodeParameter,
    NodeTopic,
    NodeTransform,
    Parameter,
    Qos,
    Scalar,
    topic_profile,
)

__all__ = ["QOS_DEPTH_MAX", "parse_frame", "parse_node", "parse_parameter", "parse_qos", "parse_topic_qos"]


def parse_parameter(key: str, pos: Pos, node: YNode, diag: Diagnostics) -> Parameter | None:
    """A parameter, or None when it has no usable type or default (reported)."""
    what = f"parameter {key!r}"
    r = Reader(node, what, diag, ("type", "unit", "default", "min", "max", "description", "section", "allow_nan"))
    type_ = r.get("type", str)
    kinds: dict[str, tuple[type, ...]] = {
        "double": (int, float), "integer": (int,), "bool": (bool,), "string": (str,),
    }
    if type_ is not None and type_ not in kinds:
        diag.error(r.key_pos("type"), f"type {type_!r} of {what} is unknown", "double, integer, bool or string")
        return None
    if type_ is None:
        return None
    default: Scalar | None = r.get("default", kinds[type_])
    minimum = number(r.node("min"), f"min of {what}", diag)
    maximum = number(r.node("max"), f"max of {what}", diag)
    if (minimum is not None or maximum is not None) and type_ not in ("double", "integer"):
        diag.error(pos, f"{what} of type {type_} cannot have a range")
    allow_nan = bool(r.get("allow_nan", bool, False))
    if not _nan_rules_hold(r, what, type_, default, allow_nan, diag):
        return None
    if minimum is not None and maximum is not None and minimum > maximum:
        diag.error(r.key_pos("min"), f"{what}: min {minimum} is above max {maximum}")
    if isinstance(default, (int, float)) and not isinstance(default, bool):
        if (minimum is not None and default < minimum) or (maximum is not None and default > maximum):
            diag.error(r.key_pos("default"), f"default {default} of {what} is outside its range",
                       f"a value in [{minimum}, {maximum}]")
    if default is None:
        return None
    return Parameter(
        key, type_, float(default) if type_ == "double" else default, r.get("unit", str, ""),
        minimum, maximum, text_of(r, "description"), str(r.get("section", (str, int, float), "")), pos,
        allow_nan=allow_nan,
    )


def _nan_rules_hold(r: Reader, what: str, type_: str, default: Scalar | None, allow_nan: bool,
                    diag: Diagnostics) -> bool:
    """NaN is never a parameter value unless the parameter says `allow_nan: true`: a NaN default passes every range
    check (each comparison is false) and would switch off whatever check reads it (a NaN min_battery_percent: no
    low-battery abort, ever). (A NaN range bound is refused by `number`: it must be finite.) False when refused."""
    ok = True
    if allow_nan and type_ != "double":
        diag.error(r.key_pos("allow_nan"), f"{what}: allow_nan applies only to a double parameter, not {type_}")
        ok = False
    if isinstance(default, float) and math.isnan(default) and not allow_nan:
        diag.error(r.key_pos("default"), f"default NaN of {what} is not a valid value",
                   "a number; or `allow_nan: true` when NaN is a meaningful value of this parameter")
        ok = False
    return ok


_QOS_KEYS = ("reliability", "durability", "depth")
QOS_DEPTH_MAX = 10000  # a deeper keep-last history is a mistake rather than a need (and costs memory per endpoint)


def parse_qos(node: YNode, what: str, diag: Diagnostics) -> Qos | None:
    """`qos:` as a profile name (sensor_data, reliable, latched, tf) or a {reliability, durability, depth} mapping."""
    if isinstance(node, YScalar) and isinstance(node.value, str):
        profile = QOS_PROFILES.get(node.value)
        if profile is None:
            diag.error(node.pos, f"unknown QoS profile {node.value!r} in {what}",
                       "one of " + ", ".join(QOS_PROFILES) + ", or a mapping {reliability, durability, depth}")
        return profile
    if not isinstance(node, YMap):
        diag.error(node.pos, f"{what} must be a profile name or a mapping, found {kind_of(node)}",
                   "one of " + ", ".join(QOS_PROFILES) + ", or a mapping {reliability, durability, depth}")
        return None
    sides = [k for k in node.entries if k in QOS_SIDES]
    if sides:  # a subscription's own QoS, or one side of a topic's: it is one side already
        diag.error(node.key_pos[sides[0]], f"{what} is one side, it cannot give {' and '.join(sides)}",
                   "a profile name or a mapping {reliability, durability, depth}; per-side QoS is a topic's `qos:`")
        return None
    r = Reader(node, what, diag, _QOS_KEYS)
    reliability, durability, depth = r.get("reliability", str), r.get("durability", str), r.get("depth", int)
    ok = r.ok
    if reliability is not None and reliability not in RELIABILITIES:
        diag.error(r.key_pos("reliability"), f"reliability {reliability!r} in {what} is unknown",
                   " or ".join(RELIABILITIES))
        ok = False
    if durability is not None and durability not in DURABILITIES:
        diag.error(r.key_pos("durability"), f"durability {durability!r} in {what} is unknown",
                   " or ".join(DURABILITIES))
        ok = False
    if depth is not None and not 1 <= depth <= QOS_DEPTH_MAX:
        diag.error(r.key_pos("depth"), f"depth {depth} in {what} is out of range", f"1..{QOS_DEPTH_MAX}")
        ok = False
    if not ok or reliability is None or durability is None or depth is None:
        return None
    return Qos(reliability, durability, depth)


_TOPIC_QOS_EXPECTED = ("one of " + ", ".join(QOS_PROFILES) + ", a mapping {reliability, durability, depth}, or "
                       "a mapping {publishers, subscribers} of those")


def parse_topic_qos(node: YNode, what: str, diag: Diagnostics) -> tuple[Qos | None, Qos | None]:
    """A topic's `qos:` as (publishers, subscribers); None for a side it does not give (or gives wrongly, reported).

    A profile name or a {reliability, durability, depth} mapping gives both sides (`sensor_data`: REP 2003's pair,
    model.spec.topic_profile); {publishers: ..., subscribers: ...} gives either side or both, each a profile (the
    rclpy profile of that name: `publishers: sensor_data` publishes best effort) or a mapping.
    """
    if isinstance(node, YScalar) and isinstance(node.value, str):
        sides = topic_profile(node.value)
        if sides is None:
            diag.error(node.pos, f"unknown QoS profile {node.value!r} in {what}", _TOPIC_QOS_EXPECTED)
            return None, None
        return sides
    if not isinstance(node, YMap) or not any(k in node.entries for k in QOS_SIDES):
        if not isinstance(node, YMap):
            diag.error(node.pos, f"{what} must be a profile name or a mapping, found {kind_of(node)}",
                       _TOPIC_QOS_EXPECTED)
            return None, None
        both = parse_qos(node, what, diag)
        return both, both
    mixed = [k for k in node.entries if k in _QOS_KEYS]
    if mixed:
        diag.error(node.key_pos[mixed[0]], f"{what} gives {', '.join(mixed)} beside per-side "
                   f"{' and '.join(k for k in QOS_SIDES if k in node.entries)}: which side is it for?",
                   "either {reliability, durability, depth} for both sides, or each side in {publishers, subscribers}")
        return None, None
    r = Reader(node, what, diag, QOS_SIDES)
    pub_node, sub_node = r.node("publishers"), r.node("subscribers")
    publishers = parse_qos(pub_node, f"the publishers' side of {what}", diag) if pub_node is not None else None
    subscribers = parse_qos(sub_node, f"the subscribers' side of {what}", diag) if sub_node is not None else None
    return publishers, subscribers


def parse_frame(key: str, pos: Pos, node: YNode, diag: Diagnostics) -> Frame:
    what = f"frame {key!r}"
    r = Reader(node, what, diag, ("parent", "description", "xyz", "rpy"))
    parent = r.get("parent", str, None)
    offsets: dict[str, tuple[float, float, float]] = {}
    for attr in ("xyz", "rpy"):
        value = vector3(r.node(attr), f"{attr} of {what}", diag)
        if value is None:
            continue
        if parent is None:
            diag.error(r.key_pos(attr), f"{what} has no parent: its {attr} would offset it from nothing",
                       "a `parent` for a static child frame")
        offsets[attr] = value
    return Frame(key, parent, text_of(r, "description"), pos, **offsets)


def _node_topics(node: YNode | None, what: str, diag: Diagnostics, with_qos: bool) -> list[NodeTopic]:
    """Entries `/topic` or `{topic: /topic, type: pkg/Name}` (subscriptions also `qos: ...`)."""
    items = []
    keys = ("topic", "type", "qos") if with_qos else ("topic", "type")
    for item in seq_items(node, what, diag):
        if isinstance(item, YMap):
            r = Reader(item, f"an entry of {what}", diag, keys)
            topic, type_ = r.get("topic", str), r.get("type", str, None)
            qos_node = r.node("qos")
            qos = parse_qos(qos_node, f"the QoS of {topic or '?'} in {what}", diag) if qos_node is not None else None
            if topic is not None:
                items.append(NodeTopic(topic, qos, item.pos, type_.replace("/msg/", "/") if type_ else None))
            continue
        topic = scalar(item, str, f"an entry of {what}", diag)
        if topic is not None:
            items.append(NodeTopic(topic, None, item.pos))
    return items


def _node_transforms(node: YNode | None, what: str, diag: Diagnostics) -> list[NodeTransform]:
    result = []
    for text, item_pos in str_list(node, what, diag):
        parent, sep, child = text.partition("->")
        if not sep or not parent.strip() or not child.strip():
            diag.error(item_pos, f"transform {text!r} in {what} is not parent->child", "parent->child")
            continue
        result.append(NodeTransform(parent.strip(), child.strip(), item_pos))
    return result


_NODE_KEYS = ("description", "publishes", "subscribes", "parameters", "transforms", "reads_transforms")


def parse_node(key: str, pos: Pos, node: YNode, diag: Diagnostics) -> Node:
    what = f"node {key!r}"
    r = Reader(node, what, diag, _NODE_KEYS)
    return Node(
        key, text_of(r, "description"),
        _node_topics(r.node("publishes"), f"publishes of {what}", diag, with_qos=False),
        _node_topics(r.node("subscribes"), f"subscribes of {what}", diag, with_qos=True),
        [NodeParameter(t, p) for t, p in str_list(r.node("parameters"), f"parameters of {what}", diag)],
        _node_transforms(r.node("transforms"), f"transforms of {what}", diag),
        _node_transforms(r.node("reads_transforms"), f"reads_transforms of {what}", diag),
        pos,
    )
