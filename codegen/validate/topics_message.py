"""The generated message of the spec's topic names (`ros.topics_message: Topics`, opt-in): a constants-only message
of the spec's own package, one `string` constant per topic, so that code on the vehicle names topics through
`tug_msgs.msg.Topics.THRUST` instead of string literals.

Invariants:
- One constant per topic of the spec, implied ones (/tf, /tf_static) included, in the spec's topic order; its value
  is the topic name exactly as the spec writes it; its comment is the topic's type and description.
- The constant's name depends on the topic name alone (topic_constant_name): upper case, every run of other
  characters than letters and digits one `_`, none at either end, `TOPIC_` before a leading digit. Two topics that
  give one name are an exact error at the second (never a silent suffix: a name must not depend on which topics
  exist).
- The message is built here, in validation, and reaches the emitters in Resolved.messages only (never the Spec).
"""

from __future__ import annotations

import re

from sam_codegen.model.diagnostics import Diagnostics
from sam_codegen.model.spec import Constant, RosMessage, Spec
from sam_codegen.model.types import ROS_MESSAGE_NAME, RosType

__all__ = ["topic_constant_name", "topics_message"]

_OTHER = re.compile(r"[^A-Z0-9]+")


def topic_constant_name(topic: str) -> str:
    """The constant of a topic in the topics message ("" when the name has no letter or digit).

    >>> topic_constant_name("/imu"), topic_constant_name("/thruster_1/feedback"), topic_constant_name("core/imu")
    ('IMU', 'THRUSTER_1_FEEDBACK', 'CORE_IMU')
    >>> topic_constant_name("~/status"), topic_constant_name("/2d/map"), topic_constant_name("/navGoal")
    ('STATUS', 'TOPIC_2D_MAP', 'NAVGOAL')
    """
    name = _OTHER.sub("_", topic.upper()).strip("_")
    return f"TOPIC_{name}" if name[:1].isdigit() else name


def topics_message(spec: Spec, diag: Diagnostics) -> RosMessage | None:
    """The topics message `ros.topics_message` asks for, or None (not asked for, or an error reported)."""
    name = spec.ros.topics_message
    if name is None:
        return None
    pos = spec.ros.topics_message_pos
    if not ROS_MESSAGE_NAME.fullmatch(name):
        diag.error(pos, f"ros.topics_message {name!r} is not a valid ROS message name", "CamelCase, e.g. Topics")
        return None
    full_name = f"{spec.ros.name}/{name}"
    if full_name in spec.messages:
        diag.error(pos, f"ros.topics_message {name} is also declared under messages (line "
                   f"{spec.messages[full_name].pos.line}): the generated message would replace it",
                   "another name for the topics message")
        return None
    if not spec.topics:
        diag.error(pos, f"ros.topics_message {name} would have no constant: the spec has no topics",
                   "topics, or no ros.topics_message")
        return None
    constants: list[Constant] = []
    first: dict[str, str] = {}  # constant -> the topic that gave it
    for topic in spec.topics.values():
        constant = topic_constant_name(topic.name)
        if not constant:
            diag.error(topic.pos, f"topic {topic.name} gives no constant name in ros.topics_message {name}",
                       "a topic name with a letter or digit")
            continue
        if constant in first:
            diag.error(topic.pos, f"topics {first[constant]} and {topic.name} both give constant {constant} of "
                       f"ros.topics_message {name}", "topic names that stay distinct in upper case with `_` for "
                       "every other character, or no ros.topics_message")
            continue
        first[constant] = topic.name
        comment = f"{topic.type}: {topic.description}" if topic.description else topic.type
        constants.append(Constant(constant, RosType("string"), topic.name, comment, topic.pos))
    if len(first) < len(spec.topics):
        return None
    return RosMessage(spec.ros.name, name, [], constants,
                      "The topic names of the spec, one constant per topic (generated: ros.topics_message).", pos=pos)
