"""Issue 19, the ROS graph's outside sources: topics `published_by: external`, tf2_msgs/TFMessage known to the tool
with /tf and /tf_static implied by the nodes' transforms, and the generated topics message (`ros.topics_message`).

tests/specs/tug.yaml uses all three (an operator GUI's thrust commands to the bridge, a mission executive's goals to a
node, transforms without a tf2_msgs declaration or TF topics); tests/specs/boat.yaml still declares both and must keep
building the same. The broken specs are rows of tests/broken_cases_nodes.py.
"""

from __future__ import annotations

import itertools
import json
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from helpers.ros_packages import built_prefix, missing_tools, run_child
from helpers.runtime_support import domain_id

from sam_codegen.catalogs.ros_known import KNOWN_MESSAGES, external_messages_to_generate
from sam_codegen.frontend.loader import load_spec_file
from sam_codegen.frontend.yaml_source import load_yaml
from sam_codegen.model.diagnostics import SpecError
from sam_codegen.model.spec import QOS_PROFILES
from sam_codegen.targets import docs as emit_docs
from sam_codegen.targets import ros as emit_ros
from sam_codegen.targets.docs.graph import build_graph
from sam_codegen.validate.nodes import node_published_topics, node_subscribed_topics, publishers
from sam_codegen.validate.resolve import Resolved, validate
from sam_codegen.validate.topics_message import topic_constant_name

ROOT = Path(__file__).resolve().parents[2]
SPECS = ROOT / "tests" / "specs"
TUG = SPECS / "tug.yaml"
SVG_NS = "{http://www.w3.org/2000/svg}"


@pytest.fixture(scope="module")
def tug() -> Resolved:
    return validate(load_spec_file(TUG))


def _validate_text(text: str, tmp_path: Path, name: str = "spec.yaml") -> Resolved:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return validate(load_spec_file(path))


# ---- tf2_msgs known, TF topics implied ---------------------------------------------------------------------------

def test_tf_topics_are_implied_by_the_nodes_transforms(tug: Resolved) -> None:
    spec = tug.spec
    assert spec.external_messages == {}
    tf, static = spec.topics["/tf"], spec.topics["/tf_static"]
    assert (tf.type, tf.implied, tf.qos) == ("tf2_msgs/TFMessage", True, QOS_PROFILES["tf"])
    assert (static.type, static.implied, static.qos) == ("tf2_msgs/TFMessage", True, QOS_PROFILES["latched"])
    assert list(spec.topics)[-2:] == ["/tf", "/tf_static"]  # after the declared ones, /tf first
    assert not any(t.implied for name, t in spec.topics.items() if name not in ("/tf", "/tf_static"))
    assert node_published_topics(spec, spec.nodes["localizer"]) == ["/tf"]
    assert node_subscribed_topics(spec, spec.nodes["pilot"]) == ["/goal", "/tf", "/tf_static"]
    ends = publishers(spec)
    assert [e.who for e in ends["/tf"]] == ["node localizer"]
    assert [e.who for e in ends["/tf_static"]] == ["the node host (static frames)"]


def test_known_package_generated_as_upstream_writes_it(tug: Resolved) -> None:
    files = emit_ros.emit(tug)
    assert files["ros/tf2_msgs/msg/TFMessage.msg"] == KNOWN_MESSAGES["tf2_msgs/TFMessage"]
    assert sorted(p for p in files if p.startswith("ros/tf2_msgs/")) == [
        "ros/tf2_msgs/CMakeLists.txt", "ros/tf2_msgs/msg/TFMessage.msg", "ros/tf2_msgs/package.xml"]
    assert emit_ros.build_order(tug) == ["tf2_msgs", "tug_msgs"]
    description = ET.fromstring(files["ros/tf2_msgs/package.xml"]).findtext("description") or ""
    assert "built-in copy of the upstream definitions, for tug.yaml" in description


def test_a_spec_that_declares_them_keeps_building_the_same() -> None:
    """boat.yaml declares tf2_msgs/TFMessage and /tf, /tf_static itself: no duplicate, the same message file."""
    boat = validate(load_spec_file(SPECS / "boat.yaml"))
    assert not boat.spec.topics["/tf"].implied and boat.spec.topics["/tf"].description == "Dynamic transforms."
    assert list(external_messages_to_generate(boat.spec)) == ["tf2_msgs/TFMessage"]
    assert external_messages_to_generate(boat.spec)["tf2_msgs/TFMessage"] is boat.spec.external_messages[
        "tf2_msgs/TFMessage"]
    files = emit_ros.emit(boat)
    assert files["ros/tf2_msgs/msg/TFMessage.msg"] == KNOWN_MESSAGES["tf2_msgs/TFMessage"]
    assert "from the external_messages of boat.yaml" in files["ros/tf2_msgs/package.xml"]


def test_no_tf_topics_without_transforms(tmp_path: Path) -> None:
    """Static frames alone imply nothing: the TF topics come with nodes that publish or read transforms."""
    text = (SPECS / "minimal.yaml").read_text(encoding="utf-8").replace(
        "frames:\n  base_link: {}\n", "frames:\n  base_link: {}\n  sensor: {parent: base_link}\n")
    spec = _validate_text(text, tmp_path).spec
    assert "/tf" not in spec.topics and "/tf_static" not in spec.topics
    assert external_messages_to_generate(spec) == {}


def test_only_tf_without_static_frames(tmp_path: Path) -> None:
    text = (SPECS / "minimal.yaml").read_text(encoding="utf-8")
    text = text.replace("frames:\n  base_link: {}\n", "frames:\n  base_link: {}\n  odom: {}\ntransforms:\n"
                        "  - {parent: odom, child: base_link, publisher: logger}\n")
    text = text.replace("    parameters: [/warn_level]\n",
                        "    parameters: [/warn_level]\n    transforms: [odom->base_link]\n")
    spec = _validate_text(text, tmp_path).spec
    assert spec.topics["/tf"].implied and "/tf_static" not in spec.topics
    assert spec.topics["/tf"].pos.line == text.splitlines().index("    transforms: [odom->base_link]") + 1


# ---- external publishers -----------------------------------------------------------------------------------------

def test_external_publishers_are_publishers(tug: Resolved) -> None:
    spec = tug.spec
    assert spec.topics["/thrust"].external_publisher == "the operator GUI"
    assert spec.topics["/goal"].external_publisher == ""
    assert spec.topics["/status"].external_publisher is None
    ends = publishers(spec)
    assert [e.who for e in ends["/thrust"]] == ["an external publisher (the operator GUI)"]
    assert [e.who for e in ends["/goal"]] == ["an external publisher"]
    assert ends["/goal"][0].pos.line == TUG.read_text().splitlines().index(
        next(line for line in TUG.read_text().splitlines() if line.startswith("  /goal:"))) + 1


def test_the_description_is_one_line(tmp_path: Path) -> None:
    text = (SPECS / "minimal.yaml").read_text(encoding="utf-8").replace(
        "  /valve: {type: std_msgs/UInt8}\n",
        "  /valve: {type: std_msgs/UInt8, published_by: {external: \"  the\n   GUI \"}}\n")
    text = text.replace("    publishes: [/valve]\n", "")
    spec = _validate_text(text, tmp_path).spec
    assert spec.topics["/valve"].external_publisher == "the GUI"


def test_without_the_declaration_the_command_topic_is_refused(tmp_path: Path) -> None:
    """The same spec as tug.yaml less `published_by` on /thrust: the bridge's command has no publisher."""
    text = TUG.read_text(encoding="utf-8").replace(", published_by: {external: \"the operator GUI\"}", "")
    with pytest.raises(SpecError) as caught:
        _validate_text(text, tmp_path, "tug.yaml")
    assert [d.message for d in caught.value.diagnostics] == [
        "the bridge subscribes to /thrust (mapping thrust), which nobody publishes"]


def test_an_external_publisher_and_a_node_may_share_a_topic(tmp_path: Path) -> None:
    text = (SPECS / "minimal.yaml").read_text(encoding="utf-8").replace(
        "  /valve: {type: std_msgs/UInt8}\n",
        "  /valve: {type: std_msgs/UInt8, published_by: {external: the operator}}\n")
    spec = _validate_text(text, tmp_path).spec
    assert [e.who for e in publishers(spec)["/valve"]] == [
        "an external publisher (the operator)", "node valve_control"]


def test_docs_show_the_external_sources(tug: Resolved) -> None:
    files = emit_docs.emit(tug)
    md = files["docs/interfaces.md"]
    assert "| `/thrust` | `tug_msgs/Thrust` |" in md
    row = next(line for line in md.splitlines() if line.startswith("| `/thrust` |"))
    assert row.endswith("| `external (the operator GUI)` | `bridge` |")
    row = next(line for line in md.splitlines() if line.startswith("| `/goal` |"))
    assert row.endswith("| `external` | `pilot` |")
    assert 'ext_external_the_operator_GUI[/"external<br/>the operator GUI"/]' in md
    assert "classDef external" in md and "ext_external_the_operator_GUI --> topic_thrust" in md
    assert "Known to sam-codegen" in md  # tf2_msgs/TFMessage in the external messages

    graph = build_graph(tug)
    assert graph.externals == {"(external) the operator GUI": "the operator GUI", "(external)": ""}
    root = ET.fromstring(files["docs/dataflow.svg"].encode("utf-8"))
    rects = {(r.get("class"), int(r.get("x") or 0), int(r.get("y") or 0), int(r.get("height") or 0))
             for r in root.iter(f"{SVG_NS}rect") if r.get("class") in ("node", "external")}
    externals = sorted(r for r in rects if r[0] == "external")
    nodes = sorted(r for r in rects if r[0] == "node")
    assert len(externals) == 2 and len(nodes) == 2
    assert {x for _, x, _, _ in externals} == {x for _, x, _, _ in nodes}  # the nodes' column
    spans = sorted((y, y + h) for _, _, y, h in rects)
    assert all(a[1] <= b[0] for a, b in itertools.pairwise(spans)), spans  # no two overlap
    edges = [p for p in root.iter(f"{SVG_NS}path") if p.get("class") == "edge external"]
    assert len(edges) == 3  # two arrows and the legend's
    legend = [t.text for t in root.iter(f"{SVG_NS}text") if t.get("class") == "legend"]
    assert "published from outside the spec (published_by: external)" in legend


def test_specs_without_externals_draw_no_external_box() -> None:
    svg = (ROOT / "generated" / "docs" / "dataflow.svg").read_text(encoding="utf-8")
    assert "external" not in svg
    assert "classDef external" not in (ROOT / "generated" / "docs" / "interfaces.md").read_text(encoding="utf-8")


# ---- the topics message ------------------------------------------------------------------------------------------

def test_topics_message_of_the_tug(tug: Resolved) -> None:
    files = emit_ros.emit(tug)
    text = files["ros/tug_msgs/msg/Topics.msg"]
    constants = [line for line in text.splitlines() if line and not line.startswith("#")]
    assert constants == ['string HEADING="/heading"', 'string THRUST="/thrust"', 'string GOAL="/goal"',
                         'string STATUS="/status"', 'string TF="/tf"', 'string TF_STATIC="/tf_static"']
    assert "# tug_msgs/Thrust: Thrust commands.\nstring THRUST=" in text
    assert '"msg/Topics.msg"' in files["ros/tug_msgs/CMakeLists.txt"]
    parser = pytest.importorskip("rosidl_adapter.parser")
    parsed = parser.parse_message_string("tug_msgs", "Topics", text)
    assert parsed.fields == [] and {c.name: c.value for c in parsed.constants} == {
        topic_constant_name(name): name for name in tug.spec.topics}


def test_sam_has_a_topics_constant_per_topic() -> None:
    resolved = validate(load_spec_file(ROOT / "spec" / "interfaces.yaml"))
    [topics] = [m for m in resolved.messages if m.name == "Topics"]
    assert [(c.name, c.value) for c in topics.constants] == [
        (topic_constant_name(t), t) for t in resolved.spec.topics]
    assert ("THRUSTER_1_FEEDBACK", "/thruster_1/feedback") in [(c.name, c.value) for c in topics.constants]
    generated = (ROOT / "generated" / "ros" / "sam_msgs" / "msg" / "Topics.msg").read_text(encoding="utf-8")
    assert 'string IMU="/imu"\n' in generated


def test_no_topics_message_unless_asked(tmp_path: Path) -> None:
    resolved = _validate_text((SPECS / "minimal.yaml").read_text(encoding="utf-8"), tmp_path)
    assert [m.name for m in resolved.messages] == ["Level"]


def test_yaml_of_the_tug_is_plain() -> None:
    """The spec the tests lean on keeps its three features (a guard against an edit that drops one)."""
    text = TUG.read_text(encoding="utf-8")
    load_yaml(text, str(TUG))
    assert "external_messages" not in text and "/tf" not in text.split("topics:", 1)[1]
    assert "published_by: external" in text and "topics_message: Topics" in text


_IMPORT = r"""
import json
from tug_msgs.msg import Topics, Thrust
print(json.dumps({"constants": {k: getattr(Topics, k) for k in ("HEADING", "THRUST", "GOAL", "STATUS", "TF",
                                                               "TF_STATIC")},
                  "instance": type(Topics()).__name__, "thrust": Thrust().percent}))
"""


@pytest.mark.ros
@pytest.mark.slow
@pytest.mark.skipif(missing_tools() is not None, reason=str(missing_tools()))
def test_topics_message_builds_and_imports(tug: Resolved, tmp_path: Path) -> None:
    """Built with rosidl (CMake, as `sam-codegen ros-install` builds it) and imported: the constants are the topics."""
    out = ROOT / ".cache" / "graph-sources" / "tug"
    files = emit_ros.emit(tug)
    for path, text in files.items():
        if path.startswith("ros/tug_msgs/"):
            target = out / path
            target.parent.mkdir(parents=True, exist_ok=True)
            if not target.is_file() or target.read_text(encoding="utf-8") != text:
                target.write_text(text, encoding="utf-8")
    prefix = built_prefix([out / "ros" / "tug_msgs"])
    proc = run_child(["-c", _IMPORT], prefix, domain_id(41), timeout=120)
    assert proc.returncode == 0, proc.stderr[-3000:]
    report = json.loads(proc.stdout.strip().splitlines()[-1])
    assert report == {"constants": {"HEADING": "/heading", "THRUST": "/thrust", "GOAL": "/goal", "STATUS": "/status",
                                    "TF": "/tf", "TF_STATIC": "/tf_static"},
                      "instance": "Topics", "thrust": 0.0}
