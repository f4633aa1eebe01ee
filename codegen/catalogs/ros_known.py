"""Standard ROS 2 messages the tool knows without an installed package or a spec declaration: tf2_msgs/TFMessage,
the message of /tf and /tf_static, which no ROS wheel on PyPI provides.

A spec names them like any installed message (a topic `type:`, a field type); the build generates each package of
the known messages the spec uses under generated/ros/<package>/ (as it does for the spec's `external_messages`), with
the definition exactly as ROS 2 writes it, so that its type hash (RIHS01) is upstream's.

Invariants:
- KNOWN_MESSAGES holds upstream's .msg text byte for byte (ros2/geometry2, Jazzy); the parsed messages are built
  once, are never changed, and are marked `external` (not the spec's package).
- A spec may still declare one of them in `external_messages` (specs written before the tool knew it): the
  declaration wins where it is used, and validation requires its fields to equal the known ones.
- Which known messages a spec uses depends only on the spec (its topics, after the implied TF topics, and the fields
  of its messages), never on what is installed: the generated output is the same on every machine.
"""

from __future__ import annotations

from functools import cache

from sam_codegen.model.diagnostics import Pos
from sam_codegen.model.spec import Field, RosMessage, Spec
from sam_codegen.model.types import RosType, parse_ros_type

__all__ = ["KNOWN_MESSAGES", "external_messages_to_generate", "known_message"]

# full name -> upstream's .msg text (ros2/geometry2 tf2_msgs/msg/TFMessage.msg, the whole file). Fields only, one
# `type name` a line (known_message reads no constants, defaults or comments: add a parser before a message with them).
KNOWN_MESSAGES: dict[str, str] = {
    "tf2_msgs/TFMessage": "geometry_msgs/TransformStamped[] transforms\n",
}
_SOURCE = "sam_codegen.catalogs.ros_known"


@cache
def known_message(full_name: str) -> RosMessage | None:
    """The known standard message `pkg/Name`, or None."""
    text = KNOWN_MESSAGES.get(full_name)
    if text is None:
        return None
    package, _, name = full_name.partition("/")
    where = f"{_SOURCE} ({full_name})"
    fields = []
    for number, line in enumerate(text.splitlines(), 1):
        type_text, field_name = line.split()
        fields.append(Field(field_name, parse_ros_type(type_text, package), "", Pos(where, number, 1)))
    return RosMessage(package, name, fields, external=True, pos=Pos(where))


def _used_types(spec: Spec) -> list[str]:
    names = [t.type for t in spec.topics.values()]
    for message in (*spec.messages.values(), *spec.external_messages.values()):
        for f in message.fields:
            if isinstance(f.type, RosType) and not f.type.is_primitive:
                names.append(f.type.base)
    return names


def external_messages_to_generate(spec: Spec) -> dict[str, RosMessage]:
    """Every message of another package the build generates: the spec's `external_messages` (in spec order), then
    the known messages the spec uses and does not declare (by name)."""
    result = dict(spec.external_messages)
    for name in sorted(set(_used_types(spec))):
        known = known_message(name)
        if known is not None and name not in result:
            result[name] = known
    return result
