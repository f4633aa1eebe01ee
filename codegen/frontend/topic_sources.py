"""Where a topic's messages come from, beyond the spec's nodes and bridge: `published_by: external`, and the TF
topics the nodes' transforms imply.

- `published_by: external` (or `published_by: {external: "who"}`) on a topic says that tools outside the spec (an
  operator GUI, a mission executive, a rosbag) publish it, so that a topic the bridge sends to the devices or a node
  subscribes needs no placeholder node. Only the literal `external` is accepted; the text of the mapping form says
  who, for the docs.
- /tf and /tf_static are implied: a spec whose nodes declare `transforms` or `reads_transforms` gets /tf
  (tf2_msgs/TFMessage, which the tool knows: catalogs.ros_known), and /tf_static too when it has static frames (a
  frame with a `parent`, which the node host publishes there). A spec that declares them keeps its declaration
  (description, section, QoS); an implied topic comes after the declared ones, /tf first, marked `implied`.

Invariant: nothing here changes a Topic after it is built; implied topics are new Topic objects whose position is
the first node item that implies them (errors about them point there).
"""

from __future__ import annotations

from sam_codegen.frontend.reading import Reader, kind_of
from sam_codegen.frontend.yaml_source import YMap, YNode, YScalar
from sam_codegen.model.diagnostics import Diagnostics, Pos
from sam_codegen.model.spec import TF_MESSAGE, TF_STATIC_TOPIC, TF_TOPIC, Frame, Node, Topic

__all__ = ["EXTERNAL", "implied_tf_topics", "parse_published_by"]

EXTERNAL = "external"
_EXPECTED = "external, or {external: who publishes it}"


def parse_published_by(node: YNode | None, topic: str, diag: Diagnostics) -> tuple[str | None, Pos]:
    """`published_by` of a topic -> (who publishes it from outside the spec: "" when unsaid; None: not external,
    or an error reported), and the position of the key's value."""
    if node is None:
        return None, Pos("")
    what = f"published_by of topic {topic!r}"
    if isinstance(node, YScalar):
        if node.value == EXTERNAL:
            return "", node.pos
        diag.error(node.pos, f"{what} is {kind_of(node)}: only `external` is a publisher the spec does not declare "
                   "(nodes say what they publish under `nodes`)", _EXPECTED)
        return None, node.pos
    if not isinstance(node, YMap):
        diag.error(node.pos, f"{what} must be `external` or a mapping, found {kind_of(node)}", _EXPECTED)
        return None, node.pos
    r = Reader(node, what, diag, (EXTERNAL,))
    who = r.get(EXTERNAL, str)
    if who is None:
        return None, node.pos
    if not who.strip():
        diag.error(r.key_pos(EXTERNAL), f"{what}: the text of `external` is empty",
                   "who publishes it (e.g. \"the operator GUI\"), or plain `published_by: external`")
        return None, node.pos
    return " ".join(who.split()), node.pos


def implied_tf_topics(topics: dict[str, Topic], nodes: dict[str, Node], frames: dict[str, Frame]) -> list[Topic]:
    """The TF topics the nodes' transforms imply and `topics` does not declare (QoS not yet chosen)."""
    items = [item for n in nodes.values() for item in (*n.transform_items, *n.read_transform_items)]
    if not items:
        return []
    pos = items[0].pos
    implied = []
    if TF_TOPIC not in topics:
        implied.append(Topic(TF_TOPIC, TF_MESSAGE, "Transforms between the spec's frames (implied by the nodes' "
                             "transforms; tf2's topic).", pos=pos, qos_pos=pos, implied=True))
    if TF_STATIC_TOPIC not in topics and any(f.parent is not None for f in frames.values()):
        implied.append(Topic(TF_STATIC_TOPIC, TF_MESSAGE, "The static child frames, published once (implied by "
                             "the static frames; tf2's topic).", pos=pos, qos_pos=pos, implied=True))
    return implied
