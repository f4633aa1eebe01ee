"""The documentation emitter: golden files, determinism, coverage of the spec and hostile text.

SAM_UPDATE_GOLDEN=1 rewrites tests/golden/docs/ from the current output.
"""

from __future__ import annotations

import difflib
import json
import os
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
import yaml

from sam_codegen.frontend.loader import load_spec_file
from sam_codegen.model.diagnostics import SpecError
from sam_codegen.render.filters import md_cell, md_code, one_line
from sam_codegen.targets.docs import MD_PATH, SVG_PATH, emit
from sam_codegen.targets.docs.graph import mermaid_label
from sam_codegen.targets.docs.wording import describe_step
from sam_codegen.validate.resolve import Resolved, validate

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "spec" / "interfaces.yaml"
GOLDEN = ROOT / "tests" / "golden"
SVG_NS = "{http://www.w3.org/2000/svg}"


@pytest.fixture(scope="module")
def resolved() -> Resolved:
    return validate(load_spec_file(SPEC))


@pytest.fixture(scope="module")
def output(resolved: Resolved) -> dict[str, str]:
    return emit(resolved)


def _spec_from_text(text: str, tmp_path: Path, name: str = "interfaces.yaml") -> Resolved:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return validate(load_spec_file(path))


# ---- Markdown helpers ------------------------------------------------------------------------------------

def split_row(line: str) -> list[str]:
    """The cells of a Markdown table row; a pipe after an odd number of backslashes is escaped."""
    assert line.startswith("|") and line.endswith("|"), line
    cells, current, backslashes = [], "", 0
    for ch in line[1:]:
        if ch == "|" and backslashes % 2 == 0:
            cells.append(current.strip())
            current = ""
        else:
            current += ch
        backslashes = backslashes + 1 if ch == "\\" else 0
    assert current == "", line
    return cells


def tables(md: str) -> list[tuple[str, list[str], list[list[str]]]]:
    """Every table outside code fences: (section heading "## ...", header cells, rows of cells)."""
    result: list[tuple[str, list[str], list[list[str]]]] = []
    section, fenced, current = "", False, None
    for line in md.split("\n"):
        if line.startswith("```"):
            fenced = not fenced
            continue
        if fenced:
            continue
        if line.startswith("## "):
            section = line[3:]
        if line.startswith("|"):
            if current is None:
                current = (section, split_row(line), [])
                result.append(current)
            elif not re.fullmatch(r"\|(\s*:?-+:?\s*\|)+", line):
                current[2].append(split_row(line))
        else:
            current = None
    return result


def first_cells(md: str, section: str) -> set[str]:
    return {row[0] for sec, _, rows in tables(md) if sec == section for row in rows}


def check_well_formed(md: str, svg: str) -> None:
    """Every table row has as many cells as its header; the SVG parses; no raw HTML from the spec."""
    for section, header, rows in tables(md):
        for row in rows:
            assert len(row) == len(header), (section, header, row)
    assert "<script" not in md.lower()
    assert "<script" not in svg.lower()
    for tag in re.findall(r"<(/?[A-Za-z][A-Za-z0-9]*)", md):  # only the HTML the template writes
        assert tag in ("br",), tag
    assert md.count("```") % 2 == 0
    root = ET.fromstring(svg.encode("utf-8"))
    assert root.tag == f"{SVG_NS}svg"


def svg_texts(svg: str) -> set[str]:
    root = ET.fromstring(svg.encode("utf-8"))
    return {el.text or "" for el in root.iter(f"{SVG_NS}text")}


# ---- golden and determinism -------------------------------------------------------------------------------

def test_golden(output: dict[str, str]) -> None:
    if os.environ.get("SAM_UPDATE_GOLDEN") == "1":
        for rel, text in output.items():
            path = GOLDEN / rel
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_bytes(text.encode("utf-8"))
    assert sorted(output) == sorted(str(p.relative_to(GOLDEN)) for p in (GOLDEN / "docs").rglob("*") if p.is_file())
    for rel, text in output.items():
        expected = (GOLDEN / rel).read_bytes()
        if text.encode("utf-8") != expected:
            diff = difflib.unified_diff(expected.decode("utf-8").splitlines(), text.splitlines(), "golden", "emitted",
                                        lineterm="", n=1)
            pytest.fail(f"{rel} differs from its golden file (SAM_UPDATE_GOLDEN=1 rewrites it):\n"
                        + "\n".join(list(diff)[:40]))


def test_deterministic_and_relative(resolved: Resolved, output: dict[str, str]) -> None:
    assert emit(resolved) == output
    assert emit(validate(load_spec_file(SPEC))) == output  # emit does not change the resolved spec
    for text in output.values():
        assert str(ROOT) not in text
        assert "interfaces.yaml" in text
        assert not re.search(r"\b20\d\d-\d\d-\d\d", text)  # no dates


# ---- the SVG --------------------------------------------------------------------------------------------------

def test_svg_shows_everything(resolved: Resolved, output: dict[str, str]) -> None:
    svg = output[SVG_PATH]
    root = ET.fromstring(svg.encode("utf-8"))
    assert root.get("version") == "1.1" and root.get("viewBox")
    texts = svg_texts(svg)
    spec = resolved.spec
    assert spec.bridge is not None and spec.bridge.name in texts
    for name in [*spec.devices, *spec.topics, *spec.nodes]:
        assert name in texts, name
    for device in spec.devices.values():
        assert f"node id {device.node_id}" in texts
    for mapping in spec.bridge.mappings:  # every subject the bridge uses labels an edge
        assert str(mapping.subject_id) in texts
    markers = {m.get("id") for m in root.iter(f"{SVG_NS}marker")}
    edges = [p for p in root.iter(f"{SVG_NS}path") if "edge" in (p.get("class") or "").split()]
    assert edges
    for path in edges:
        assert re.fullmatch(r"url\(#(.+)\)", path.get("marker-end", ""))[1] in markers
        assert re.fullmatch(r"M-?\d+,-?\d+ (L-?\d+,-?\d+|C-?\d+,-?\d+ -?\d+,-?\d+ -?\d+,-?\d+)", path.get("d"))
    width, height = int(root.get("width")), int(root.get("height"))
    for rect in root.iter(f"{SVG_NS}rect"):  # everything inside the picture
        x, y, w, h = (int(rect.get(k)) for k in ("x", "y", "width", "height"))
        assert 0 <= x and 0 <= y and x + w <= width and y + h <= height


def test_svg_boxes_do_not_overlap(output: dict[str, str]) -> None:
    root = ET.fromstring(output[SVG_PATH].encode("utf-8"))
    boxes = []
    for group in root.iter(f"{SVG_NS}g"):
        if "box" in (group.get("class") or "").split():
            rect = group.find(f"{SVG_NS}rect")
            boxes.append(tuple(int(rect.get(k)) for k in ("x", "y", "width", "height")))
    assert len(boxes) > 20
    for i, (x1, y1, w1, h1) in enumerate(boxes):
        for x2, y2, w2, h2 in boxes[i + 1:]:
            assert x1 + w1 <= x2 or x2 + w2 <= x1 or y1 + h1 <= y2 or y2 + h2 <= y1


# ---- the Markdown -----------------------------------------------------------------------------------------

def test_markdown_covers_the_spec(resolved: Resolved, output: dict[str, str]) -> None:
    md = output[MD_PATH]
    spec = resolved.spec
    assert md.startswith("# sam interface reference\n")
    assert "Generated from interfaces.yaml" in md and "do not edit" in md
    assert "![Dataflow](dataflow.svg)" in md
    assert {md_code(t) for t in spec.topics} <= first_cells(md, "ROS topics")
    assert {md_code(n) for n in spec.nodes} <= first_cells(md, "ROS nodes")
    assert {md_code(p) for p in spec.parameters} <= first_cells(md, "Parameters")
    assert {md_code(f) for f in spec.frames} <= first_cells(md, "TF frames")
    assert {md_code(d) for d in spec.devices} <= first_cells(md, "UAVCAN devices")
    assert spec.bridge is not None
    assert {md_code(m.name) for m in spec.bridge.mappings} <= first_cells(md, "Bridge mappings")
    for message in resolved.messages:
        assert f"### {md_code(message.full_name)}\n" in md
        if message.derived_from:
            assert f"Derived from {md_code(message.derived_from)}" in md
    for struct in resolved.dsdl_types:
        assert f"### {md_code(struct.name)}\n" in md
    assert {md_code(f.name) for s in resolved.dsdl_types for f in s.fields} <= first_cells(md, "DSDL types")
    message_fields = {md_code(f.name) for m in resolved.messages for f in m.fields}
    assert message_fields <= first_cells(md, f"Messages of {md_code('sam_msgs')}")


def test_topic_publishers_include_the_bridge(resolved: Resolved, output: dict[str, str]) -> None:
    rows = {row[0]: row for sec, _, rs in tables(output[MD_PATH]) if sec == "ROS topics" for row in rs}
    bridge = md_code("uavcan_ros_bridge")
    assert bridge in rows["`/imu`"][5] and bridge not in rows["`/imu`"][6]
    assert bridge in rows["`/thruster_rpms`"][6] and "`controller`" in rows["`/thruster_rpms`"][5]
    assert rows["`/nav_goal`"][5] == "`mission`" and rows["`/nav_goal`"][6] == "`motion_planner`"
    assert rows["`/tf`"][5] == "`dead_reckoning`, `slam`"
    # both sides (REP 2003): a reliable publisher, best-effort subscribers
    assert rows["`/imu`"][4].startswith("publishers reliable, volatile, keep last 5; subscribers sensor\\_data "
                                        "(best\\_effort, volatile, keep last 5)")
    assert rows["`/nav_goal`"][4].startswith("publishers and subscribers reliable (reliable, volatile, keep last 10)")


def test_mapping_field_tables(resolved: Resolved, output: dict[str, str]) -> None:
    md = output[MD_PATH]
    for rm in resolved.mappings:
        section = md.split(f"\n### {md_code(rm.mapping.name)}\n", 1)[1].split("\n### ", 1)[0].split("\n## ", 1)[0]
        rows = [split_row(line) for line in section.split("\n") if line.startswith("| ")][1:]
        ros_fields = {row[0] for row in rows}
        for step in rm.steps:
            assert md_code(step.ros) in ros_fields, (rm.mapping.name, step.ros)
            assert md_cell(describe_step(step, rm.mapping.direction, rm.mapping.on_out_of_range)) in section
        for ignored in rm.mapping.ignore:
            assert ["—", "", md_code(ignored), "ignored"] in rows


def test_conversion_wording(output: dict[str, str]) -> None:
    md = output[MD_PATH]
    for text in (
        "int18 → int32 (widened)",
        "float16 → float64 × 1e-4",
        "usec → builtin_interfaces/Time (0 = receive time)",
        "uint2 → int8 table {0: -1, 1: -1, 2: 0, 3: 0}",
        "constant -1.0",
        "constant NaN",
        "float16 → float32 - 273.15",
        "float32 → float16 limits [0, 100]",
        "int32 → int18 (narrowed, saturating)",
        "float16[<=9] → float64[9] × 1e-8 (padded to 9)",
    ):
        assert md_cell(text) in md, text


def test_mermaid_block(resolved: Resolved, output: dict[str, str]) -> None:
    md = output[MD_PATH]
    block = md.split("```mermaid\n", 1)[1].split("\n```", 1)[0]
    lines = block.split("\n")
    assert lines[0] == "flowchart LR"
    declared = {}
    for line in lines[1:]:
        match = re.fullmatch(r"  ([A-Za-z_][A-Za-z0-9_]*)(\[\[|\(\[|\[|\()\"([^\"]*)\"(\]\]|\]\)|\]|\))", line)
        if match:
            declared[match[1]] = match[3]
    assert len(declared) == len(resolved.spec.devices) + len(resolved.spec.topics) + len(resolved.spec.nodes) + 1
    edges = [line for line in lines if "-->" in line]
    assert edges
    for line in edges:
        match = re.fullmatch(r"  (\w+) -->(?:\|\"[^\"]*\"\|)? (\w+)", line)
        assert match and match[1] in declared and match[2] in declared, line
    assert mermaid_label('a "b" <c>') == "a #quot;b#quot; #lt;c#gt;"


# ---- hostile text ---------------------------------------------------------------------------------------------

HOSTILE = (
    'Evil | pipe `tick` <script>alert("x")</script> {{ x }} {% raw %}\n'
    "second line \"dq\" 'sq' ünïcødé 日本 & &amp; ]]> \\| --> <!--"
)


def test_hostile_text_stays_inert(tmp_path: Path) -> None:
    text = SPEC.read_text(encoding="utf-8")
    quoted = json.dumps(HOSTILE, ensure_ascii=False)
    replacements = [
        ('description: "IMU samples."', f"description: {quoted}"),
        ('comment: "Thruster 1 speed [rpm]; the device takes int18, larger values saturate."', f"comment: {quoted}"),
        ('comment: "Latest angular rate sample [rad/s]."', f"comment: {quoted}"),
        ("description: Inertial measurement unit.", f"description: {quoted}"),
        ('description: "The global reference frame: a local metric frame (ENU) around the first GPS fix."',
         f"description: {quoted}"),
        ("section: IV.C.1,", f"section: {quoted},"),
    ]
    for old, new in replacements:
        assert text.count(old) == 1, old
        text = text.replace(old, new)
    text = text.replace("description: Dead reckoning; high-rate",
                        "description: >-\n      <b>|</b> ` Dead reckoning; high-rate")
    text = text.replace("unit: m, default: 5.0", f"unit: {json.dumps('m|<i>`', ensure_ascii=False)}, default: 5.0")
    resolved = _spec_from_text(text, tmp_path, "evil `x`|<y>.yaml")
    assert resolved.spec.topics["/imu"].description == HOSTILE
    out = emit(resolved)
    md, svg = out[MD_PATH], out[SVG_PATH]
    check_well_formed(md, svg)
    assert emit(resolved) == out
    # The text is there, escaped: one line, pipes and markup neutralised, template markers left as they were.
    row = next(row for sec, _, rows in tables(md) if sec == "ROS topics" for row in rows if row[0] == "`/imu`")
    assert row[3] == md_cell(HOSTILE)
    assert "Evil \\| pipe \\`tick\\` &lt;script&gt;" in row[3] and "{{ x }} {% raw %} second line" in row[3]
    assert md_cell(HOSTILE) in md.split("## Messages of", 1)[1]  # the .msg comment
    assert md_cell(HOSTILE) in md.split("## DSDL types", 1)[1]  # the DSDL comment
    assert "Generated from evil \\`x\\`\\|&lt;y&gt;.yaml" in md
    # In the SVG it comes back exactly from the parsed tooltips, and the file name in the title.
    root = ET.fromstring(svg.encode("utf-8"))
    titles = [el.text for el in root.iter(f"{SVG_NS}title")]
    assert HOSTILE in titles
    assert any("evil `x`|<y>.yaml" in (t or "") for t in titles)
    assert f"sensor_msgs/Imu  ({one_line(HOSTILE)[:23]}…)" in svg_texts(svg)  # the section, clipped


def test_spec_without_bridge(tmp_path: Path) -> None:
    data = yaml.safe_load(SPEC.read_text(encoding="utf-8"))
    del data["bridge"]
    for node in data["nodes"].values():  # with no bridge nobody publishes the sensor topics
        node.pop("subscribes", None)
    resolved = _spec_from_text(yaml.safe_dump(data, sort_keys=False, allow_unicode=True), tmp_path)
    out = emit(resolved)
    check_well_formed(out[MD_PATH], out[SVG_PATH])
    assert "The spec declares no bridge." in out[MD_PATH]
    texts = svg_texts(out[SVG_PATH])
    assert "uavcan_ros_bridge" not in texts and "/nav_goal" in texts and "imu" in texts


OTHER_SPECS = sorted((ROOT / "tests" / "specs").glob("*.yaml"))


@pytest.mark.parametrize("path", OTHER_SPECS, ids=[p.name for p in OTHER_SPECS])
def test_other_specs(path: Path) -> None:
    try:
        resolved = validate(load_spec_file(path))
    except SpecError:
        pytest.skip(f"{path.name} is not a valid spec")
    out = emit(resolved)
    md, svg = out[MD_PATH], out[SVG_PATH]
    check_well_formed(md, svg)
    spec = resolved.spec
    texts = svg_texts(svg)
    for name in [*spec.devices, *spec.topics, *spec.nodes]:
        assert name in texts, name
    assert {md_code(t) for t in spec.topics} <= first_cells(md, "ROS topics")
    assert {md_code(d) for d in spec.devices} <= first_cells(md, "UAVCAN devices")
    assert {md_code(p) for p in spec.parameters} <= first_cells(md, "Parameters")
    if spec.bridge is not None:
        assert {md_code(m.name) for m in spec.bridge.mappings} <= first_cells(md, "Bridge mappings")
