"""Hostile text in descriptions, comments and units ends up inert in every generated language, or is rejected
(in names) with a clear error."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pydsdl
import pytest
import yaml

from sam_codegen.build import generate
from sam_codegen.cli import main
from sam_codegen.frontend.loader import load_spec_file
from sam_codegen.model.diagnostics import SpecError
from sam_codegen.validate.resolve import validate

ROOT = Path(__file__).parents[2]
SPEC_TEXT = (ROOT / "spec" / "interfaces.yaml").read_text(encoding="utf-8")

HOSTILE = [
    'quote " and \' and """ triple',
    "newline\nimport os; os.system('echo pwned')",
    "backslash \\ and \\n and trailing \\",
    "{{ 7 * 7 }} and {% raw %} and {# c #}",
    "<script>alert(1)</script> & <!-- -->",
    "pipe | and `code` and [link](x) and *star*",
    "non-ASCII: Ångström µs ° 深度 🐟",
    "#!/bin/sh\r\n# carriage\rreturn\x00nul\x1bESC",
    "@sealed\nuint8 injected_field",
    "'''\nraise SystemExit(3)\n'''",
]


def _hostile_spec(text: str) -> dict:
    tree = yaml.safe_load(SPEC_TEXT)
    tree["vehicle"]["description"] = text
    tree["ros"]["description"] = text
    tree["ros"]["maintainer"] = text
    tree["messages"]["ThrusterRPMs"]["description"] = text
    tree["messages"]["ThrusterRPMs"]["fields"][1]["comment"] = text
    tree["dsdl_types"]["sam.sensor.RawIMU.0.1"]["description"] = text
    tree["dsdl_types"]["sam.sensor.RawIMU.0.1"]["fields"][1]["comment"] = text
    tree["dsdl_types"]["sam.sensor.GNSSFix.0.1"]["constants"][0]["comment"] = text
    tree["topics"]["/imu"]["description"] = text
    tree["topics"]["/imu"]["section"] = text
    tree["parameters"]["/safe_depth"]["description"] = text
    tree["parameters"]["/safe_depth"]["unit"] = text
    tree["devices"]["imu"]["description"] = text
    tree["frames"]["imu_link"]["description"] = text
    tree["nodes"]["slam"]["description"] = text
    tree["parameter_rules"][0]["description"] = text
    return tree


@pytest.mark.parametrize("text", HOSTILE, ids=range(len(HOSTILE)))
def test_hostile_text_is_inert(text: str, tmp_path: Path) -> None:
    spec = tmp_path / "interfaces.yaml"
    spec.write_text(yaml.safe_dump(_hostile_spec(text), allow_unicode=True, sort_keys=False), encoding="utf-8")
    files = generate(spec)
    out = tmp_path / "generated"
    assert main(["build", "--spec", str(spec), "--out", str(out)]) == 0

    # Python: compiles, and the tables give back exactly the text (control characters aside).
    for path, source in files.items():
        if path.endswith(".py"):
            compile(source, path, "exec")
    module_spec = importlib.util.spec_from_file_location("hostile_tables", out / "python/sam_bridge/tables.py")
    assert module_spec and module_spec.loader
    tables = importlib.util.module_from_spec(module_spec)
    sys.modules["hostile_tables"] = tables
    try:
        module_spec.loader.exec_module(tables)
    finally:
        del sys.modules["hostile_tables"]
    device = next(d for d in tables.DEVICES if d.name == "imu")
    assert device.description == text
    assert next(p for p in tables.PARAMETERS if p.name == "/safe_depth").description == text

    # .msg: rosidl reads the same fields and constants as without the hostile text.
    parser = pytest.importorskip("rosidl_adapter.parser")
    parsed = parser.parse_message_string("sam_msgs", "ThrusterRPMs", files["ros/sam_msgs/msg/ThrusterRPMs.msg"])
    assert [f.name for f in parsed.fields] == ["thruster_1_rpm", "thruster_2_rpm", "header"]
    assert "<script>" not in files["ros/sam_msgs/package.xml"]

    # DSDL: pydsdl reads the namespace and sees exactly the declared fields (no injected attribute).
    types = pydsdl.read_namespace(out / "dsdl" / "sam", [str(p) for p in validate(load_spec_file(spec)).dsdl.roots])
    raw_imu = next(t for t in types if t.full_name == "sam.sensor.RawIMU")
    assert [f.name for f in raw_imu.fields] == ["timestamp", "integration_interval", "rate_gyro_latest",
                                                "rate_gyro_integral", "accelerometer_latest",
                                                "accelerometer_integral", "covariance"]

    # Markdown: no raw HTML from the spec, table rows keep their shape.
    markdown = files["docs/interfaces.md"]
    assert "<script>" not in markdown and "\x00" not in markdown
    # SVG: still well-formed XML.
    import xml.etree.ElementTree as ET

    ET.fromstring(files["docs/dataflow.svg"])


@pytest.mark.parametrize("where,value", [
    ("topic", "/imu; rm -rf /"),
    ("field", "x\ny"),
    ("dsdl_field", "a-b"),
    ("device", "imu\n"),
    ("mapping", "imu()"),
    ("frame", "imu link"),
])
def test_hostile_names_are_rejected(where: str, value: str, tmp_path: Path) -> None:
    tree = yaml.safe_load(SPEC_TEXT)
    if where == "topic":
        tree["topics"][value] = tree["topics"].pop("/global_plan")
    elif where == "field":
        tree["messages"]["HeadingStamped"]["fields"][1]["name"] = value
    elif where == "dsdl_field":
        tree["dsdl_types"]["sam.actuator.ThrusterRPM.0.1"]["fields"][0]["name"] = value
    elif where == "device":
        tree["devices"][value] = tree["devices"].pop("ballast")
    elif where == "mapping":
        tree["bridge"]["mappings"][value] = tree["bridge"]["mappings"].pop("ballast")
    elif where == "frame":
        tree["frames"][value] = tree["frames"].pop("gps_link")
    spec = tmp_path / "interfaces.yaml"
    spec.write_text(yaml.safe_dump(tree, allow_unicode=True, sort_keys=False), encoding="utf-8")
    with pytest.raises(SpecError) as info:
        validate(load_spec_file(spec))
    assert any("not valid" in str(d) or "not a valid" in str(d) for d in info.value.diagnostics), info.value
