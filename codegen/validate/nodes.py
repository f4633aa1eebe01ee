"""Checks of the ROS side the nodes see: QoS per topic, the nodes' topics, parameters and transforms.

Run by validate.validate after the topic and frame checks; reports into the same Diagnostics, each error at the
list item it is about (file:line:col). It reads each topic's effective QoS (`Topic.qos`, which the frontend chose:
the spec's `qos:` or the ROS-convention default of model.spec.default_qos) and changes nothing in the spec.

The names the generated node bases use (on_<topic>, publish_<topic>, lookup_<parent>_to_<child>, a property per
parameter) are derived here, so that the checks and emit_nodes agree on them.
"""

from __future__ import annotations

import keyword
import re
from collections.abc import Iterable
from dataclasses import dataclass

from sam_codegen.catalogs.ros import RosCatalog
from sam_codegen.catalogs.ros_known import known_message
from sam_codegen.model.diagnostics import Diagnostics, Pos

# `X as X`: re-exported, importable from here since before they moved down to the model (where the frontend and
# the runtime reach them).
from sam_codegen.model.names import ros_parameter_name as ros_parameter_name
from sam_codegen.model.spec import QOS_PROFILES as QOS_PROFILES
from sam_codegen.model.spec import ROS_TO_UAVCAN, UAVCAN_TO_ROS, Node, NodeTopic, Qos, Spec, Topic
from sam_codegen.model.spec import TF_MESSAGE as TF_MESSAGE
from sam_codegen.model.spec import TF_STATIC_TOPIC as TF_STATIC_TOPIC
from sam_codegen.model.spec import TF_TOPIC as TF_TOPIC
from sam_codegen.model.spec import default_qos as default_qos
from sam_codegen.model.types import ROS_PACKAGE_NAME
from sam_codegen.validate.external_publishers import check_external_publishers

_NODE_NAME = re.compile(r"[a-z][a-z0-9_]*")

# The public attributes of rclpy's Node (rclpy 7.1, Jazzy) and of the generated base: a parameter property with
# one of these names would shadow them. tests/test_node_base.py checks the list against the installed rclpy.
RCLPY_NODE_ATTRIBUTES = frozenset({
    "PARAM_REL_TOL", "add_on_set_parameters_callback", "add_post_set_parameters_callback",
    "add_pre_set_parameters_callback", "add_waitable", "clients", "context", "count_clients", "count_publishers",
    "count_services", "count_subscribers", "create_client", "create_guard_condition", "create_publisher",
    "create_rate", "create_service", "create_subscription", "create_timer", "declare_parameter",
    "declare_parameters", "default_callback_group", "describe_parameter", "describe_parameters", "destroy_client",
    "destroy_guard_condition", "destroy_node", "destroy_publisher", "destroy_rate", "destroy_service",
    "destroy_subscription", "destroy_timer", "executor", "get_client_names_and_types_by_node", "get_clock",
    "get_fully_qualified_name", "get_fully_qualified_node_names", "get_logger", "get_name", "get_namespace",
    "get_node_names", "get_node_names_and_namespaces", "get_node_names_and_namespaces_with_enclaves",
    "get_parameter", "get_parameter_or", "get_parameter_type", "get_parameter_types", "get_parameters",
    "get_parameters_by_prefix", "get_publisher_names_and_types_by_node", "get_publishers_info_by_topic",
    "get_service_names_and_types", "get_service_names_and_types_by_node", "get_subscriber_names_and_types_by_node",
    "get_subscriptions_info_by_topic", "get_topic_names_and_types", "guards", "handle", "has_parameter",
    "list_parameters", "publishers", "remove_on_set_parameters_callback", "remove_post_set_parameters_callback",
    "remove_pre_set_parameters_callback", "remove_waitable", "resolve_service_name", "resolve_topic_name",
    "services", "set_descriptor", "set_parameters", "set_parameters_atomically", "subscriptions", "timers",
    "undeclare_parameter", "wait_for_node", "waitables",
})
BASE_ATTRIBUTES = frozenset({"tf", "report_status", "NODE_NAME", "frame", "frame_prefix"})


# ---- names ---------------------------------------------------------------------------------------------------


def topic_identifier(topic: str) -> str:
    """The part of on_<...>/publish_<...> a topic gives.

    >>> topic_identifier("/nav_goal"), topic_identifier("/thruster_1/feedback")
    ('nav_goal', 'thruster_1_feedback')
    """
    return topic.strip("/").replace("/", "_")


def parameter_identifier(spec_name: str) -> str:
    """The property a generated base gives a parameter.

    >>> parameter_identifier("/limits/depth")
    'limits_depth'
    """
    return ros_parameter_name(spec_name).replace(".", "_")


def transform_identifier(parent: str, child: str) -> str:
    """
    >>> transform_identifier("world", "base_link")
    'world_to_base_link'
    """
    return f"{parent}_to_{child}"


def class_name(node: str) -> str:
    """The generated base class of a node.

    >>> class_name("motion_planner")
    'MotionPlannerBase'
    """
    return "".join(part[:1].upper() + part[1:] for part in node.split("_")) + "Base"


def node_published_topics(spec: Spec, node: Node) -> list[str]:
    """Every topic a node publishes: its `publishes`, and /tf when it publishes transforms."""
    return unique([*node.publishes, *([TF_TOPIC] if node.transform_items and TF_TOPIC in spec.topics else [])])


def node_subscribed_topics(spec: Spec, node: Node) -> list[str]:
    """Every topic a node subscribes: its `subscribes`, and /tf and /tf_static when it reads transforms."""
    tf = [t for t in (TF_TOPIC, TF_STATIC_TOPIC) if t in spec.topics] if node.read_transform_items else []
    return unique([*node.subscribes, *tf])


# ---- QoS -----------------------------------------------------------------------------------------------------


def incompatibility(offered: Qos, requested: Qos) -> str | None:
    """Why a subscription requesting `requested` gets nothing from a publisher offering `offered` (DDS rules).

    >>> incompatibility(QOS_PROFILES["sensor_data"], QOS_PROFILES["reliable"])
    'a best_effort publisher cannot serve a reliable subscription'
    >>> incompatibility(QOS_PROFILES["reliable"], QOS_PROFILES["latched"])
    'a volatile publisher cannot serve a transient_local subscription'
    >>> incompatibility(QOS_PROFILES["latched"], QOS_PROFILES["sensor_data"]) is None
    True
    """
    if offered.reliability == "best_effort" and requested.reliability == "reliable":
        return "a best_effort publisher cannot serve a reliable subscription"
    if offered.durability == "volatile" and requested.durability == "transient_local":
        return "a volatile publisher cannot serve a transient_local subscription"
    return None


# ---- the graph -----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Endpoint:
    """Who publishes or subscribes a topic, for messages: 'node controller', 'the bridge (mapping imu)'."""

    who: str
    pos: Pos


def publishers(spec: Spec) -> dict[str, list[Endpoint]]:
    """topic -> its publishers: nodes (their `publishes`, /tf for their transforms), the bridge's uavcan_to_ros
    mappings, the node host for /tf_static when the spec has static frames, and the tools outside the spec of a
    topic `published_by: external` (which use the topic's QoS, as every publisher does)."""
    result: dict[str, list[Endpoint]] = {}
    for topic in spec.topics.values():
        if topic.external_publisher is not None:
            result.setdefault(topic.name, []).append(Endpoint(external_endpoint(topic.external_publisher),
                                                              topic.external_pos))
    for node in spec.nodes.values():
        for item in node.publish_items:
            result.setdefault(item.topic, []).append(Endpoint(f"node {node.name}", item.pos))
        if node.transform_items:
            result.setdefault(TF_TOPIC, []).append(Endpoint(f"node {node.name}", node.transform_items[0].pos))
    if spec.bridge is not None:
        for m in spec.bridge.all_mappings:
            if m.direction == UAVCAN_TO_ROS:
                result.setdefault(m.topic, []).append(Endpoint(f"the bridge (mapping {m.name})", m.pos))
    static = [f for f in spec.frames.values() if f.parent is not None]
    if static:
        result.setdefault(TF_STATIC_TOPIC, []).append(Endpoint("the node host (static frames)", static[0].pos))
    return result


def external_endpoint(who: str) -> str:
    """How messages name an external publisher.

    >>> external_endpoint(""), external_endpoint("the operator GUI")
    ('an external publisher', 'an external publisher (the operator GUI)')
    """
    return f"an external publisher ({who})" if who else "an external publisher"


def static_edges(spec: Spec) -> set[tuple[str, str]]:
    return {(f.parent, f.name) for f in spec.frames.values() if f.parent is not None}


def frame_chain(spec: Spec, a: str, b: str) -> list[tuple[str, str]] | None:
    """The edges (parent, child) of a path between frames a and b through declared transforms and static frames,
    in any direction; None when they are not connected."""
    edges = {(t.parent, t.child) for t in spec.transforms} | static_edges(spec)
    neighbours: dict[str, list[tuple[str, tuple[str, str]]]] = {}
    for parent, child in sorted(edges):
        neighbours.setdefault(parent, []).append((child, (parent, child)))
        neighbours.setdefault(child, []).append((parent, (parent, child)))
    paths: dict[str, list[tuple[str, str]]] = {a: []}
    todo = [a]
    while todo:
        frame = todo.pop(0)
        if frame == b:
            return paths[frame]
        for other, edge in neighbours.get(frame, []):
            if other not in paths:
                paths[other] = [*paths[frame], edge]
                todo.append(other)
    return None


def rule_partners(spec: Spec, node: Node) -> list[str]:
    """Parameters a node does not read but compares with one it reads in a parameter rule (spec order)."""
    own = set(node.parameters)
    wanted = set()
    for rule in spec.parameter_rules:
        if rule.left in own and rule.right not in own:
            wanted.add(rule.right)
        if rule.right in own and rule.left not in own:
            wanted.add(rule.left)
    return [name for name in spec.parameters if name in wanted]


# ---- checks --------------------------------------------------------------------------------------------------


class _NodeChecks:
    def __init__(self, spec: Spec, ros: RosCatalog, diag: Diagnostics) -> None:
        self.spec, self.ros, self.diag = spec, ros, diag
        self.publishers = publishers(spec)

    def error(self, pos: Pos, message: str, expected: str | None = None) -> None:
        self.diag.error(pos, message, expected)

    def check_tf_topics(self) -> None:
        for name in (TF_TOPIC, TF_STATIC_TOPIC):
            topic = self.spec.topics.get(name)
            if topic is not None and topic.type != TF_MESSAGE:
                self.error(topic.pos, f"topic {name} carries {topic.type}: tf2 tools read {TF_MESSAGE} there",
                           TF_MESSAGE)

    def check(self) -> None:
        self.check_topic_sides()
        self.check_tf_topics()
        self.check_transform_list()
        for node in self.spec.nodes.values():
            self.check_node(node)
        self.check_bridge_commands()
        if self.spec.bridge is not None and self.spec.bridge.name in self.spec.nodes:
            self.error(self.spec.nodes[self.spec.bridge.name].pos, f"node {self.spec.bridge.name!r} is the bridge: "
                       "its topics follow from its mappings, do not declare it under nodes")

    def check_transform_list(self) -> None:
        s = self.spec
        parents: dict[str, tuple[str, Pos]] = {f.name: (f.parent, f.pos) for f in s.frames.values() if f.parent}
        for t in s.transforms:
            node = s.nodes.get(t.publisher)
            if node is not None and (t.parent, t.child) not in node.transforms:
                self.error(t.pos, f"transform {t.parent}->{t.child} is given to node {t.publisher}, which does not "
                           "list it in its transforms", f"{t.parent}->{t.child} in the transforms of {t.publisher}")
            known = parents.get(t.child)
            if known is not None and known[0] != t.parent:
                self.error(t.pos, f"frame {t.child!r} gets two parents: {known[0]!r} (line {known[1].line}) and "
                           f"{t.parent!r}", "one parent per frame (a TF tree)")
            parents.setdefault(t.child, (t.parent, t.pos))

    def check_node(self, node: Node) -> None:
        what = f"node {node.name}"
        if not _NODE_NAME.fullmatch(node.name) or keyword.iskeyword(node.name):
            self.error(node.pos, f"node name {node.name!r} is not a valid ROS node name",
                       "lower_case, not a Python keyword")
        members: dict[str, str] = {}  # generated member -> what it is for

        def member(name: str, purpose: str, pos: Pos) -> None:
            if name in members:
                self.error(pos, f"{what}: {purpose} and {members[name]} would both be {name} in the generated base",
                           "names that stay distinct as Python identifiers")
            elif name in RCLPY_NODE_ATTRIBUTES or name in BASE_ATTRIBUTES:
                self.error(pos, f"{what}: {purpose} would be {name}, which shadows rclpy's Node.{name} or the "
                           "generated base's own", "another name")
            members.setdefault(name, purpose)

        self.check_topics(node, node.publish_items, "publishes", member)
        self.check_topics(node, node.subscribe_items, "subscribes", member)
        seen: set[str] = set()
        for item in node.parameter_items:
            if item.name in seen:
                self.error(item.pos, f"{what} lists parameter {item.name} twice")
                continue
            seen.add(item.name)
            if item.name not in self.spec.parameters:
                self.error(item.pos, f"{what} reads undeclared parameter {item.name!r}", "a parameter of `parameters`")
                continue
            member(parameter_identifier(item.name), f"parameter {item.name}", item.pos)
        self.check_transforms(node, member)

    def check_topics(self, node: Node, items: list[NodeTopic], key: str, member) -> None:
        what = f"node {node.name}"
        verb = "publishes" if key == "publishes" else "subscribes to"
        seen: set[str] = set()
        for item in items:
            if item.topic in seen:
                self.error(item.pos, f"{what} {verb} {item.topic} twice")
                continue
            seen.add(item.topic)
            if item.topic in (TF_TOPIC, TF_STATIC_TOPIC):
                how = "`transforms` (published with publish_<parent>_to_<child>)" if key == "publishes" else \
                    "`reads_transforms` (looked up in self.tf, fed from /tf and /tf_static)"
                self.error(item.pos, f"{what} lists {item.topic} in {key}: a node's transforms are declared with "
                           f"{how}", "frames, not the TF topics")
                continue
            topic = self.spec.topics.get(item.topic)
            if topic is None:
                self.error(item.pos, f"{what} {verb} undeclared topic {item.topic!r}", "a topic of `topics`")
                continue
            if item.type is not None and item.type != topic.type:
                self.error(item.pos, f"{what} {verb} {item.topic} as {item.type}, but the topic carries "
                           f"{topic.type}", topic.type)
            ident = topic_identifier(item.topic)
            if key == "publishes":
                member(f"publish_{ident}", f"publishing {item.topic}", item.pos)
            else:
                member(f"on_{ident}", f"subscribing {item.topic}", item.pos)
                self.check_subscription(node, item, topic)

    def check_topic_sides(self) -> None:
        """A topic's subscribers' QoS (declared, or the default beside a declared publishers' side) must be one its
        publishers' QoS serves: otherwise no subscription that takes the topic's QoS would get anything."""
        for topic in self.spec.topics.values():
            pub, sub = topic.qos, topic.subscriber_qos
            if pub is None or sub is None or (topic.declared_qos is None and topic.declared_subscriber_qos is None):
                continue
            why = incompatibility(pub, sub)
            if why is not None:
                self.error(topic.qos_pos, f"the QoS of topic {topic.name!r} has subscribers {sub.describe()}, which "
                           f"its publishers {pub.describe()} cannot serve: {why}",
                           "a subscribers' side the publishers' side serves (best_effort subscribers take reliable "
                           "publishers, volatile ones transient_local publishers)")

    def check_subscription(self, node: Node, item: NodeTopic, topic: Topic) -> None:
        ends = self.publishers.get(item.topic, [])
        if not ends:
            self.error(item.pos, f"node {node.name} subscribes to {item.topic}, which nobody publishes",
                       "a topic some node publishes, or one the bridge publishes from UAVCAN, or "
                       "`published_by: external` on the topic")
            return
        if item.qos is None or topic.qos is None:
            return
        for end in ends:
            why = incompatibility(topic.qos, item.qos)
            if why is not None:
                self.error(item.pos, f"node {node.name} subscribes to {item.topic} with {item.qos.describe()}, but "
                           f"{end.who} publishes it with {topic.qos.describe()}: {why}",
                           "a QoS the publishers can serve")

    def check_transforms(self, node: Node, member) -> None:
        s, what = self.spec, f"node {node.name}"
        seen: set[tuple[str, str]] = set()
        for item in node.transform_items:
            edge = (item.parent, item.child)
            if self.check_frames(node, item.parent, item.child, item.pos, "publishes transform", edge in seen):
                if not any(t.parent == item.parent and t.child == item.child and t.publisher == node.name
                           for t in s.transforms):
                    self.error(item.pos, f"{what} claims transform {item.parent}->{item.child}, which the "
                               "transforms list does not give to it",
                               f"{{parent: {item.parent}, child: {item.child}, publisher: {node.name}}} in transforms")
                member(f"publish_{transform_identifier(*edge)}", f"publishing {item.parent}->{item.child}", item.pos)
            seen.add(edge)
        seen = set()
        for item in node.read_transform_items:
            edge = (item.parent, item.child)
            if self.check_frames(node, item.parent, item.child, item.pos, "reads transform", edge in seen):
                chain = frame_chain(s, item.parent, item.child)
                if chain is None:
                    self.error(item.pos, f"{what} reads transform {item.parent}->{item.child}, but no chain of "
                               "declared transforms and static frames connects them",
                               "frames linked by `transforms` entries or `parent`s")
                member(f"lookup_{transform_identifier(*edge)}", f"reading {item.parent}->{item.child}", item.pos)
            seen.add(edge)

    def check_frames(self, node: Node, parent: str, child: str, pos: Pos, verb: str, repeated: bool) -> bool:
        what = f"node {node.name}"
        if repeated:
            self.error(pos, f"{what} {verb} {parent}->{child} twice")
            return False
        unknown = [f for f in (parent, child) if f not in self.spec.frames]
        for frame in unknown:
            self.error(pos, f"{what} {verb} {parent}->{child}, but frame {frame!r} is not declared",
                       "a frame of `frames`")
        if parent == child and not unknown:
            self.error(pos, f"{what} {verb} {parent}->{child}: a frame relative to itself", "two different frames")
            return False
        return not unknown

    def check_bridge_commands(self) -> None:
        """The bridge subscribes its ros_to_uavcan topics: somebody must publish them, with a QoS it can read."""
        if self.spec.bridge is None:
            return
        seen: set[str] = set()
        for m in self.spec.bridge.all_mappings:
            if m.direction != ROS_TO_UAVCAN or m.topic in seen or m.topic not in self.spec.topics:
                continue
            seen.add(m.topic)
            if not self.publishers.get(m.topic):
                self.error(m.pos, f"the bridge subscribes to {m.topic} (mapping {m.name}), which nobody publishes",
                           "a node that publishes the commands, or `published_by: external` on the topic")


def check_external_packages(spec: Spec, ros: RosCatalog, diag: Diagnostics) -> None:
    """external_messages become ament packages of their own (emit_ros): never the spec's package, and never a
    different definition of a message an installed package already has (the build would replace it)."""
    for message in spec.external_messages.values():
        if message.package == spec.ros.name:
            diag.error(message.pos, f"external message {message.full_name} is in the spec's own package "
                       f"{spec.ros.name}", "a message of `messages`, or another package")
            continue
        if not ROS_PACKAGE_NAME.fullmatch(message.package):
            diag.error(message.pos, f"package {message.package!r} of external message {message.name} is not valid",
                       "lower case letters, digits and single underscores, starting with a letter")
            continue
        known = known_message(message.full_name)  # a standard message the tool knows: the spec may restate it
        if known is not None:
            if [(f.name, str(f.type)) for f in known.fields] != [(f.name, str(f.type)) for f in message.fields]:
                diag.error(message.pos, f"external message {message.full_name} differs from ROS 2's definition, "
                           f"which the tool knows ({', '.join(f'{f.type} {f.name}' for f in known.fields)})",
                           f"the known fields, or no declaration: the tool knows {message.full_name}")
            continue
        installed = ros.read_installed(message.full_name)  # not the spec's override
        if installed is None:
            continue
        theirs = [(f.name, str(f.type)) for f in installed.fields]
        ours = [(f.name, str(f.type)) for f in message.fields]
        if theirs != ours:
            diag.error(message.pos, f"external message {message.full_name} differs from the installed definition "
                       f"{installed.pos.file} ({', '.join(f'{t} {n}' for n, t in theirs)})",
                       "the installed fields, or another package")


def check_nodes(spec: Spec, ros: RosCatalog, diag: Diagnostics) -> None:
    """Every check of this module; errors go to diag."""
    check_external_packages(spec, ros, diag)
    check_external_publishers(spec, diag)
    _NodeChecks(spec, ros, diag).check()


def node_topic_qos(spec: Spec, item: NodeTopic, *, subscription: bool) -> Qos:
    """The QoS a node's endpoint uses: its own (subscriptions may override) or its topic's side (publishers' or
    subscribers')."""
    if item.qos is not None:
        return item.qos
    topic = spec.topics[item.topic]
    qos = topic.subscriber_qos if subscription else topic.qos
    assert qos is not None, "a topic the frontend built"
    return qos


def unique(items: Iterable[str]) -> list[str]:
    """
    >>> unique(["b", "a", "b"])
    ['b', 'a']
    """
    return list(dict.fromkeys(items))
