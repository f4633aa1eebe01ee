# ruff: noqa: E501  (a table of exact diagnostics, one per line, as tests/broken_cases.py)
"""Broken specs for the node, QoS, TF and external-package checks (codegen/validate/nodes.py).

Each case edits tests/specs/minimal.yaml (every `old` is replaced by its `new` once, in order; the case fails
loudly if an `old` is not there) and names the exact diagnostics, with the file shown as its base name, all at
once. Positions are those of the list item (or key) at fault, not of the node. Run by tests/test_bad_specs_nodes.py.
"""

from __future__ import annotations

from dataclasses import dataclass

LOGGER = "  logger:\n    subscribes: [/level]\n    parameters: [/warn_level]\n"
VALVE_CONTROL = "  valve_control:\n    subscribes: [/level]\n    publishes: [/valve]\n    parameters: [/alarm_level]\n"
TOPICS_END = "  /valve: {type: std_msgs/UInt8}\n"
FRAMES = "frames:\n  base_link: {}\n"
BRIDGE_MAPPINGS = (  # the minimal spec's two mappings, to cut out whole
    '    level:\n      direction: uavcan_to_ros\n      subject_id: 100\n      topic: /level\n      source_node_ids: [10]\n      frame_id: base_link\n      fields:\n        header.stamp: timestamp.microsecond\n        level: level_mm\n    valve:\n      direction: ros_to_uavcan\n      subject_id: 101\n      topic: /valve\n      destination_node_id: 11\n      fields:\n        data: open_pct\n'
)
TF_TOPICS = "  /tf: {type: tf2_msgs/TFMessage}\n  /tf_static: {type: tf2_msgs/TFMessage}\n"
TF2_MSGS = ("external_messages:\n  tf2_msgs/TFMessage:\n    fields:\n"
            "      - {name: transforms, type: \"geometry_msgs/TransformStamped[]\"}\nmessages:\n")


@dataclass(frozen=True)
class Case:
    name: str
    edits: tuple[tuple[str, str], ...]
    errors: tuple[str, ...]


CASES: tuple[Case, ...] = (
    Case(
        "subscribes_to_a_topic_nobody_publishes",
        ((TOPICS_END, TOPICS_END + "  /alarm: {type: std_msgs/Bool}\n"),
         ("    subscribes: [/level]\n    parameters: [/warn_level]", "    subscribes: [/level, /alarm]\n    parameters: [/warn_level]")),
        (
            "minimal.yaml:64:26: error: node logger subscribes to /alarm, which nobody publishes (expected a topic some node publishes, or one the bridge publishes from UAVCAN, or `published_by: external` on the topic)",
        ),
    ),
    Case(
        "bridge_command_nobody_publishes",
        (("    publishes: [/valve]\n", "    publishes: []\n"),),
        (
            "minimal.yaml:54:5: error: the bridge subscribes to /valve (mapping valve), which nobody publishes (expected a node that publishes the commands, or `published_by: external` on the topic)",
        ),
    ),
    Case(
        "publishes_a_topic_of_another_type",
        (("    publishes: [/valve]\n", "    publishes: [{topic: /valve, type: std_msgs/UInt16}]\n"),),
        (
            "minimal.yaml:67:17: error: node valve_control publishes /valve as std_msgs/UInt16, but the topic carries std_msgs/UInt8 (expected std_msgs/UInt8)",
        ),
    ),
    Case(
        "subscribes_as_another_type",
        (("    subscribes: [/level]\n    parameters: [/warn_level]", "    subscribes: [{topic: /level, type: buoy_msgs/msg/Level2}]\n    parameters: [/warn_level]"),),
        (
            "minimal.yaml:63:18: error: node logger subscribes to /level as buoy_msgs/Level2, but the topic carries buoy_msgs/Level (expected buoy_msgs/Level)",
        ),
    ),
    Case(
        "reads_an_undeclared_parameter",
        (("    parameters: [/alarm_level]", "    parameters: [/alarm_level, /alarm_lvl]"),),
        (
            "minimal.yaml:68:32: error: node valve_control reads undeclared parameter '/alarm_lvl' (expected a parameter of `parameters`)",
        ),
    ),
    Case(
        "lists_a_parameter_twice",
        (("    parameters: [/alarm_level]", "    parameters: [/alarm_level, /alarm_level]"),),
        (
            "minimal.yaml:68:32: error: node valve_control lists parameter /alarm_level twice",
        ),
    ),
    Case(
        "unknown_qos_profile",
        (("  /level: {type: buoy_msgs/Level}", "  /level: {type: buoy_msgs/Level, qos: fast}"),),
        (
            "minimal.yaml:25:40: error: unknown QoS profile 'fast' in the QoS of topic '/level' (expected one of sensor_data, reliable, latched, tf, a mapping {reliability, durability, depth}, or a mapping {publishers, subscribers} of those)",
        ),
    ),
    Case(
        "bad_qos_mapping",
        (("  /level: {type: buoy_msgs/Level}", "  /level: {type: buoy_msgs/Level, qos: {reliability: reliable, durability: durable, depth: 0, history: all}}"),),
        (
            "minimal.yaml:25:64: error: durability 'durable' in the QoS of topic '/level' is unknown (expected volatile or transient_local)",
            "minimal.yaml:25:85: error: depth 0 in the QoS of topic '/level' is out of range (expected 1..10000)",
            "minimal.yaml:25:95: error: unknown field 'history' in the QoS of topic '/level' (expected one of reliability, durability, depth)",
        ),
    ),
    Case(
        "reliable_subscription_of_a_best_effort_sensor",
        (("  /level: {type: buoy_msgs/Level}", "  /level: {type: buoy_msgs/Level, qos: {publishers: sensor_data}}"),
         ("    subscribes: [/level]\n    parameters: [/warn_level]", "    subscribes: [{topic: /level, qos: reliable}]\n    parameters: [/warn_level]"),),
        (
            "minimal.yaml:63:18: error: node logger subscribes to /level with reliable (reliable, volatile, keep last 10), but the bridge (mapping level) publishes it with sensor_data (best_effort, volatile, keep last 5): a best_effort publisher cannot serve a reliable subscription (expected a QoS the publishers can serve)",
        ),
    ),
    Case(
        "transient_local_subscription_of_a_volatile_topic",
        (("    subscribes: [/level]\n    parameters: [/warn_level]", "    subscribes: [{topic: /level, qos: {reliability: best_effort, durability: transient_local, depth: 1}}]\n    parameters: [/warn_level]"),),
        (
            "minimal.yaml:63:18: error: node logger subscribes to /level with best_effort, transient_local, keep last 1, but the bridge (mapping level) publishes it with reliable, volatile, keep last 5: a volatile publisher cannot serve a transient_local subscription (expected a QoS the publishers can serve)",
        ),
    ),
    Case(
        "qos_mixes_sides_and_both",
        (("  /level: {type: buoy_msgs/Level}", "  /level: {type: buoy_msgs/Level, qos: {publishers: reliable, depth: 5}}"),),
        (
            "minimal.yaml:25:63: error: the QoS of topic '/level' gives depth beside per-side publishers: which side is it for? (expected either {reliability, durability, depth} for both sides, or each side in {publishers, subscribers})",
        ),
    ),
    Case(
        "qos_sides_a_publisher_cannot_serve",
        (("  /level: {type: buoy_msgs/Level}", "  /level: {type: buoy_msgs/Level, qos: {publishers: sensor_data, subscribers: reliable}}"),),
        (
            "minimal.yaml:25:40: error: the QoS of topic '/level' has subscribers reliable (reliable, volatile, keep last 10), which its publishers sensor_data (best_effort, volatile, keep last 5) cannot serve: a best_effort publisher cannot serve a reliable subscription (expected a subscribers' side the publishers' side serves (best_effort subscribers take reliable publishers, volatile ones transient_local publishers))",
        ),
    ),
    Case(
        "qos_one_side_against_the_default_other",
        (("  /valve: {type: std_msgs/UInt8}", "  /valve: {type: std_msgs/UInt8, qos: {subscribers: latched}}"),),
        (
            "minimal.yaml:26:39: error: the QoS of topic '/valve' has subscribers latched (reliable, transient_local, keep last 1), which its publishers reliable (reliable, volatile, keep last 10) cannot serve: a volatile publisher cannot serve a transient_local subscription (expected a subscribers' side the publishers' side serves (best_effort subscribers take reliable publishers, volatile ones transient_local publishers))",
        ),
    ),
    Case(
        "qos_bad_side",
        (("  /level: {type: buoy_msgs/Level}", "  /level: {type: buoy_msgs/Level, qos: {publishers: fast, subscribers: {reliability: sure, durability: volatile, depth: 5}, readers: reliable}}"),),
        (
            "minimal.yaml:25:53: error: unknown QoS profile 'fast' in the publishers' side of the QoS of topic '/level' (expected one of sensor_data, reliable, latched, tf, or a mapping {reliability, durability, depth})",
            "minimal.yaml:25:73: error: reliability 'sure' in the subscribers' side of the QoS of topic '/level' is unknown (expected reliable or best_effort)",
            "minimal.yaml:25:125: error: unknown field 'readers' in the QoS of topic '/level' (expected one of publishers, subscribers)",
        ),
    ),
    Case(
        "per_side_qos_on_a_subscription",
        (("    subscribes: [/level]\n    parameters: [/warn_level]", "    subscribes: [{topic: /level, qos: {subscribers: reliable}}]\n    parameters: [/warn_level]"),),
        (
            "minimal.yaml:63:40: error: the QoS of /level in subscribes of node 'logger' is one side, it cannot give subscribers (expected a profile name or a mapping {reliability, durability, depth}; per-side QoS is a topic's `qos:`)",
        ),
    ),
    Case(
        "tf_topic_listed_and_transforms_without_tf",
        ((TOPICS_END, TOPICS_END + "  /tf: {type: std_msgs/UInt8}\n"),
         (LOGGER, "  logger:\n    subscribes: [/level, /tf]\n    parameters: [/warn_level]\n    transforms: [map->base_link]\n")),
        (
            "minimal.yaml:27:3: error: topic /tf carries std_msgs/UInt8: tf2 tools read tf2_msgs/TFMessage there (expected tf2_msgs/TFMessage)",
            "minimal.yaml:64:26: error: node logger lists /tf in subscribes: a node's transforms are declared with `reads_transforms` (looked up in self.tf, fed from /tf and /tf_static) (expected frames, not the TF topics)",
            "minimal.yaml:66:18: error: node logger publishes transform map->base_link, but frame 'map' is not declared (expected a frame of `frames`)",
        ),
    ),
    Case(
        "transform_claims_and_gifts_disagree",
        (("messages:\n", TF2_MSGS), (TOPICS_END, TOPICS_END + TF_TOPICS),
         (FRAMES, FRAMES + "  odom: {}\n  map: {}\ntransforms:\n  - {parent: odom, child: base_link, publisher: valve_control}\n"),
         (LOGGER, LOGGER + "    transforms: [odom->base_link, map->odom]\n")),
        (
            "minimal.yaml:31:5: error: transform odom->base_link is given to node valve_control, which does not list it in its transforms (expected odom->base_link in the transforms of valve_control)",
            "minimal.yaml:75:18: error: node logger claims transform odom->base_link, which the transforms list does not give to it (expected {parent: odom, child: base_link, publisher: logger} in transforms)",
            "minimal.yaml:75:35: error: node logger claims transform map->odom, which the transforms list does not give to it (expected {parent: map, child: odom, publisher: logger} in transforms)",
        ),
    ),
    Case(
        "a_frame_with_two_parents",
        (("messages:\n", TF2_MSGS), (TOPICS_END, TOPICS_END + TF_TOPICS),
         (FRAMES, FRAMES + "  odom: {}\n  sensor: {parent: base_link}\ntransforms:\n  - {parent: odom, child: sensor, publisher: logger}\n"),
         (LOGGER, LOGGER + "    transforms: [odom->sensor]\n")),
        (
            "minimal.yaml:31:5: error: frame 'sensor' gets two parents: 'base_link' (line 29) and 'odom' (expected one parent per frame (a TF tree))",
        ),
    ),
    Case(
        "reads_unconnected_frames_and_static_ones_without_tf_static",
        (("messages:\n", TF2_MSGS), (TOPICS_END, TOPICS_END + "  /tf: {type: tf2_msgs/TFMessage}\n"),
         (FRAMES, FRAMES + "  map: {}\n  sensor: {parent: base_link}\n"),
         (LOGGER, LOGGER + "    reads_transforms: [map->base_link, base_link->sensor, sensor->sensor, base_link->nowhere]\n")),
        (
            "minimal.yaml:72:24: error: node logger reads transform map->base_link, but no chain of declared transforms and static frames connects them (expected frames linked by `transforms` entries or `parent`s)",
            "minimal.yaml:72:59: error: node logger reads transform sensor->sensor: a frame relative to itself (expected two different frames)",
            "minimal.yaml:72:75: error: node logger reads transform base_link->nowhere, but frame 'nowhere' is not declared (expected a frame of `frames`)",
        ),
    ),
    Case(
        "generated_names_that_clash",
        (("  /alarm_level:", "  /executor: {type: integer, default: 1}\n  /on_level: {type: bool, default: false}\n  /alarm_level:"),
         (TOPICS_END, TOPICS_END + "  /a/b: {type: std_msgs/Bool}\n  /a_b: {type: std_msgs/Bool}\n"),
         (VALVE_CONTROL, "  valve_control:\n    subscribes: [/level, /a/b, /a_b]\n    publishes: [/valve, /a/b, /a_b]\n    parameters: [/alarm_level, /executor, /on_level]\n")),
        (
            "minimal.yaml:70:32: error: node valve_control: subscribing /a_b and subscribing /a/b would both be on_a_b in the generated base (expected names that stay distinct as Python identifiers)",
            "minimal.yaml:71:31: error: node valve_control: publishing /a_b and publishing /a/b would both be publish_a_b in the generated base (expected names that stay distinct as Python identifiers)",
            "minimal.yaml:72:32: error: node valve_control: parameter /executor would be executor, which shadows rclpy's Node.executor or the generated base's own (expected another name)",
            "minimal.yaml:72:43: error: node valve_control: parameter /on_level and subscribing /level would both be on_level in the generated base (expected names that stay distinct as Python identifiers)",
        ),
    ),
    Case(
        "node_named_like_a_python_keyword",
        ((VALVE_CONTROL, VALVE_CONTROL.replace("valve_control", "import")),),
        (
            "minimal.yaml:65:3: error: node name 'import' is not a valid ROS node name (expected lower_case, not a Python keyword)",
        ),
    ),
    Case(
        "external_messages_of_the_own_package_or_differing",
        (("messages:\n", "external_messages:\n  buoy_msgs/Extra:\n    fields: [{name: x, type: int8}]\n"
                         "  std_msgs/UInt8:\n    fields: [{name: value, type: uint8}]\nmessages:\n"),),
        (
            "minimal.yaml:7:3: error: external message buoy_msgs/Extra is in the spec's own package buoy_msgs (expected a message of `messages`, or another package)",
            "minimal.yaml:9:3: error: external message std_msgs/UInt8 differs from the installed definition {share}/std_msgs/msg/UInt8.msg (uint8 data) (expected the installed fields, or another package)",
            "minimal.yaml:65:9: error: mapping 'valve', field 'data': std_msgs/UInt8 has no field 'data'",
        ),
    ),
    Case(
        "mounting_offsets",
        ((FRAMES, "frames:\n  base_link: {xyz: [1, 0, 0]}\n  sensor: {parent: base_link, xyz: [1, 0], rpy: [0, .nan, 0]}\n"),),
        (
            "minimal.yaml:23:15: error: frame 'base_link' has no parent: its xyz would offset it from nothing (expected a `parent` for a static child frame)",
            "minimal.yaml:24:36: error: xyz of frame 'sensor' must have 3 elements, found 2 (expected [x, y, z])",
            "minimal.yaml:24:53: error: an element of rpy of frame 'sensor' must be finite",
        ),
    ),
    Case(
        "qos_on_a_publication",
        (("    publishes: [/valve]\n", "    publishes: [{topic: /valve, qos: latched}]\n"),),
        (
            "minimal.yaml:67:33: error: unknown field 'qos' in an entry of publishes of node 'valve_control' (expected one of topic, type)",
        ),
    ),
    Case(
        "subscribes_twice",
        (("    subscribes: [/level]\n    publishes", "    subscribes: [/level, /level]\n    publishes"),),
        (
            "minimal.yaml:66:26: error: node valve_control subscribes to /level twice",
        ),
    ),
    # Issue 19: topics published from outside the spec, tf2_msgs known to the tool, the generated topics message.
    Case(
        "published_by_something_else_than_external",
        ((TOPICS_END, "  /valve: {type: std_msgs/UInt8, published_by: operator}\n  /a: {type: std_msgs/Bool, published_by: [external]}\n"
                      "  /b: {type: std_msgs/Bool, published_by: {external: \" \"}}\n  /c: {type: std_msgs/Bool, published_by: {who: gui}}\n"),),
        (
            "minimal.yaml:26:48: error: published_by of topic '/valve' is str 'operator': only `external` is a publisher the spec does not declare (nodes say what they publish under `nodes`) (expected external, or {external: who publishes it})",
            "minimal.yaml:27:43: error: published_by of topic '/a' must be `external` or a mapping, found a list (expected external, or {external: who publishes it})",
            "minimal.yaml:28:44: error: published_by of topic '/b': the text of `external` is empty (expected who publishes it (e.g. \"the operator GUI\"), or plain `published_by: external`)",
            "minimal.yaml:29:43: error: missing field 'external' in published_by of topic '/c'",
            "minimal.yaml:29:44: error: unknown field 'who' in published_by of topic '/c' (expected one of external)",
        ),
    ),
    Case(
        "external_publisher_on_a_topic_the_bridge_publishes",
        (("  /level: {type: buoy_msgs/Level}\n", "  /level: {type: buoy_msgs/Level, published_by: {external: a rosbag}}\n"),),
        (
            "minimal.yaml:25:49: error: topic /level is published_by external, but the bridge publishes it from UAVCAN (mapping level): a second source would pass for the device's data (expected published_by on a topic the bridge does not publish, or another topic for the outside source)",
        ),
    ),
    Case(
        "restated_tf2_message_differs_from_the_known_one",
        (("messages:\n", "external_messages:\n  tf2_msgs/TFMessage:\n    fields:\n      - {name: transforms, type: \"geometry_msgs/Transform[]\"}\nmessages:\n"),
         (FRAMES, FRAMES + "  odom: {}\ntransforms:\n  - {parent: odom, child: base_link, publisher: logger}\n"),
         (LOGGER, LOGGER + "    transforms: [odom->base_link]\n")),
        (
            "minimal.yaml:7:3: error: external message tf2_msgs/TFMessage differs from ROS 2's definition, which the tool knows (geometry_msgs/TransformStamped[] transforms) (expected the known fields, or no declaration: the tool knows tf2_msgs/TFMessage)",
        ),
    ),
    Case(
        "topics_message_name_not_camel_case",
        (("ros: {package: buoy_msgs}", "ros: {package: buoy_msgs, topics_message: topic_names}"),),
        (
            "minimal.yaml:4:27: error: ros.topics_message 'topic_names' is not a valid ROS message name (expected CamelCase, e.g. Topics)",
        ),
    ),
    Case(
        "topics_message_is_a_declared_message",
        (("ros: {package: buoy_msgs}", "ros: {package: buoy_msgs, topics_message: Level}"),),
        (
            "minimal.yaml:4:27: error: ros.topics_message Level is also declared under messages (line 7): the generated message would replace it (expected another name for the topics message)",
        ),
    ),
    Case(
        "topic_names_that_give_one_constant",
        (("ros: {package: buoy_msgs}", "ros: {package: buoy_msgs, topics_message: Topics}"),
         (TOPICS_END, TOPICS_END + "  /a/b: {type: std_msgs/Bool, published_by: external}\n  /a_b: {type: std_msgs/Bool, published_by: external}\n  /A/B: {type: std_msgs/Bool, published_by: external}\n")),
        (
            "minimal.yaml:28:3: error: topics /a/b and /a_b both give constant A_B of ros.topics_message Topics (expected topic names that stay distinct in upper case with `_` for every other character, or no ros.topics_message)",
            "minimal.yaml:29:3: error: topics /a/b and /A/B both give constant A_B of ros.topics_message Topics (expected topic names that stay distinct in upper case with `_` for every other character, or no ros.topics_message)",
        ),
    ),
    Case(
        "external_publisher_cannot_serve_a_latched_subscription",
        ((TOPICS_END, TOPICS_END + "  /mode: {type: std_msgs/UInt8, published_by: {external: the operator GUI}}\n"),
         ("    subscribes: [/level]\n    parameters: [/warn_level]", "    subscribes: [/level, {topic: /mode, qos: latched}]\n    parameters: [/warn_level]")),
        (
            "minimal.yaml:64:26: error: node logger subscribes to /mode with latched (reliable, transient_local, keep last 1), but an external publisher (the operator GUI) publishes it with reliable (reliable, volatile, keep last 10): a volatile publisher cannot serve a transient_local subscription (expected a QoS the publishers can serve)",
        ),
    ),
    Case(
        "topics_message_without_topics",
        (("ros: {package: buoy_msgs}", "ros: {package: buoy_msgs, topics_message: Topics}"),
         ("topics:\n  /level: {type: buoy_msgs/Level}\n  /valve: {type: std_msgs/UInt8}\n", "topics: {}\n"),
         ("    subscribes: [/level]\n    parameters: [/warn_level]\n", "    parameters: [/warn_level]\n"),
         ("  valve_control:\n    subscribes: [/level]\n    publishes: [/valve]\n", "  valve_control:\n"),
         ("bridge:\n  name: bridge\n  node_id: 100\n  mappings:\n", "bridge:\n  name: bridge\n  node_id: 100\n  mappings: {}\nunused_mappings:\n"),
         ("unused_mappings:\n" + BRIDGE_MAPPINGS, "")),
        (
            "minimal.yaml:4:27: error: ros.topics_message Topics would have no constant: the spec has no topics (expected topics, or no ros.topics_message)",
        ),
    ),
    Case(
        "parameter_shadows_the_frame_helpers",
        (("  /alarm_level:", "  /frame: {type: integer, default: 1}\n  frame_prefix: {type: bool, default: false}\n  /alarm_level:"),
         (VALVE_CONTROL, "  valve_control:\n    subscribes: [/level]\n    publishes: [/valve]\n    parameters: [/alarm_level, /frame, frame_prefix]\n")),
        (
            "minimal.yaml:70:32: error: node valve_control: parameter /frame would be frame, which shadows rclpy's Node.frame or the generated base's own (expected another name)",
            "minimal.yaml:70:40: error: node valve_control: parameter frame_prefix would be frame_prefix, which shadows rclpy's Node.frame_prefix or the generated base's own (expected another name)",
        ),
    ),
    Case(
        "relative_and_absolute_topic_same_identifier",
        ((TOPICS_END, TOPICS_END + "  gauge/level: {type: std_msgs/Bool}\n  /gauge/level: {type: std_msgs/Bool}\n"),
         (VALVE_CONTROL, "  valve_control:\n    subscribes: [/level, gauge/level, /gauge/level]\n    publishes: [/valve]\n    parameters: [/alarm_level]\n")),
        (
            "minimal.yaml:68:26: error: node valve_control subscribes to gauge/level, which nobody publishes (expected a topic some node publishes, or one the bridge publishes from UAVCAN, or `published_by: external` on the topic)",
            "minimal.yaml:68:39: error: node valve_control subscribes to /gauge/level, which nobody publishes (expected a topic some node publishes, or one the bridge publishes from UAVCAN, or `published_by: external` on the topic)",
            "minimal.yaml:68:39: error: node valve_control: subscribing /gauge/level and subscribing gauge/level would both be on_gauge_level in the generated base (expected names that stay distinct as Python identifiers)",
        ),
    ),
)
