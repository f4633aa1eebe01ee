"""The node emitter's output: golden copies (SAM and tests/specs/boat.yaml), determinism, valid and lint-clean
Python, the API the contract names, inert hostile text, the parameters file, and the tables' QoS and node data.

These tests need neither ROS nor a build; tests/test_node_base.py runs the bases in rclpy. ``SAM_UPDATE_GOLDEN=1``
rewrites tests/golden/nodes/ (stored as ``<path>.golden`` so that pytest does not import them).
"""

from __future__ import annotations

import ast
import importlib.util
import json
import math
import os
import shutil
import subprocess
import sys
from dataclasses import replace
from pathlib import Path
from types import ModuleType

import pytest
import yaml

from sam_codegen.catalogs.ros_known import external_messages_to_generate
from sam_codegen.frontend.loader import load_spec_file
from sam_codegen.targets import nodes as emit_nodes
from sam_codegen.targets.python import convert as emit_python
from sam_codegen.validate.resolve import Resolved, validate
from sam_runtime.tf_buffer import quat_from_rpy

ROOT = Path(__file__).resolve().parents[2]
SPECS = {"sam": ROOT / "spec" / "interfaces.yaml", "boat": ROOT / "tests" / "specs" / "boat.yaml"}
GOLDEN = Path(__file__).resolve().parents[1] / "golden" / "nodes"
UPDATE = os.environ.get("SAM_UPDATE_GOLDEN") == "1"
HOSTILE = 'a "quote", an \'apostrophe\', """triple""", {{ jinja }} {% x %}\n# newline\\ and \x00 \u2028 end \\'


@pytest.fixture(scope="module", params=sorted(SPECS))
def spec_name(request: pytest.FixtureRequest) -> str:
    return request.param


@pytest.fixture(scope="module")
def resolved(spec_name: str) -> Resolved:
    return validate(load_spec_file(SPECS[spec_name]))


@pytest.fixture(scope="module")
def files(resolved: Resolved) -> dict[str, str]:
    return emit_nodes.emit(resolved)


def _load(path: Path, name: str) -> ModuleType:
    spec = importlib.util.spec_from_file_location(name, path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    try:
        spec.loader.exec_module(module)
    finally:
        del sys.modules[name]
    return module


def test_golden(spec_name: str, files: dict[str, str]) -> None:
    """The generated node package and parameters file, byte for byte (SAM_UPDATE_GOLDEN=1 rewrites them)."""
    folder = GOLDEN / spec_name
    if UPDATE:
        shutil.rmtree(folder, ignore_errors=True)
        for path, text in files.items():
            (folder / f"{path}.golden").parent.mkdir(parents=True, exist_ok=True)
            (folder / f"{path}.golden").write_bytes(text.encode("utf-8"))
    golden = {p.relative_to(folder).as_posix().removesuffix(".golden"): p.read_bytes().decode("utf-8")
              for p in sorted(folder.rglob("*")) if p.is_file()}
    assert sorted(golden) == sorted(files), "run with SAM_UPDATE_GOLDEN=1 after an intended change"
    for path, text in files.items():
        assert text == golden[path], f"{path} differs from its golden copy; SAM_UPDATE_GOLDEN=1 rewrites it"


def test_layout_and_determinism(spec_name: str, resolved: Resolved, files: dict[str, str]) -> None:
    vehicle = resolved.spec.vehicle
    expected = {f"python/{vehicle}_nodes/__init__.py", f"params/{vehicle}.params.yaml"}
    expected |= {f"python/{vehicle}_nodes/{n}.py" for n in resolved.spec.nodes}
    assert set(files) == expected
    assert emit_nodes.emit(validate(load_spec_file(SPECS[spec_name]))) == files
    for path, text in files.items():
        assert text.startswith(f"# Generated from {Path(SPECS[spec_name]).name} by sam-codegen; do not edit.\n")
        assert str(ROOT) not in text and "/tmp" not in text, path
        assert text.endswith("\n") and not text.endswith("\n\n"), path
        assert "\t" not in text and not any(line != line.rstrip() for line in text.splitlines()), path


@pytest.mark.system  # starts a process: not in the unit tier
def test_same_output_in_another_process(spec_name: str, files: dict[str, str]) -> None:
    """No dependence on set order: another hash seed emits the same bytes."""
    code = ("import json, pathlib, sys; from sam_codegen.targets import nodes as emit_nodes; "
            "from sam_codegen.frontend.loader import "
            "load_spec_file; from sam_codegen.validate.resolve import validate; "
            "json.dump(emit_nodes.emit(validate(load_spec_file(pathlib.Path(sys.argv[1])))), sys.stdout)")
    proc = subprocess.run([sys.executable, "-c", code, str(SPECS[spec_name])], capture_output=True, text=True,
                          env={**os.environ, "PYTHONHASHSEED": "4242"}, check=True)
    assert json.loads(proc.stdout) == files


def _members(source: str, cls: str) -> dict[str, ast.AST]:
    tree = ast.parse(source)
    node = next(n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == cls)
    return {n.name: n for n in node.body if isinstance(n, ast.FunctionDef)}


def test_contract_api(resolved: Resolved, files: dict[str, str]) -> None:
    """Every name derived from the spec: <CamelName>Base, __init__'s keywords, a property per parameter,
    on_<topic>/publish_<topic>, lookup_/publish_<parent>_to_<child>, report_status."""
    spec = resolved.spec
    for node in spec.nodes.values():
        source = files[f"python/{spec.vehicle}_nodes/{node.name}.py"]
        cls = "".join(p.capitalize() for p in node.name.split("_")) + "Base"
        members = _members(source, cls)
        init = members["__init__"]
        assert isinstance(init, ast.FunctionDef)
        assert [a.arg for a in init.args.kwonlyargs] == ["node_name", "namespace", "parameter_overrides",
                                                         "frame_prefix"]
        assert init.args.kwarg is not None and init.args.kwarg.arg == "node_kwargs"
        expected = {"__init__", "report_status", "frame"}
        expected |= {"on_" + t.strip("/").replace("/", "_") for t in node.subscribes}
        expected |= {"publish_" + t.strip("/").replace("/", "_") for t in node.publishes}
        expected |= {p.lstrip("/").replace("/", "_") for p in node.parameters}
        expected |= {f"lookup_{p}_to_{c}" for p, c in node.reads_transforms}
        expected |= {f"publish_{p}_to_{c}" for p, c in node.transforms}
        assert set(members) == expected, node.name
        for p in node.parameters:
            prop = members[p.lstrip("/").replace("/", "_")]
            assert isinstance(prop, ast.FunctionDef)
            assert [d.id for d in prop.decorator_list if isinstance(d, ast.Name)] == ["property"]
        for topic in node.subscribes:
            method = members["on_" + topic.strip("/").replace("/", "_")]
            assert isinstance(method, ast.FunctionDef) and len(method.args.args) == 2
            assert ast.unparse(method.args.args[1].annotation) == spec.topics[topic].type.split("/")[1] or \
                "_" in ast.unparse(method.args.args[1].annotation)  # aliased on a name clash
        # The docstring documents each member.
        doc = ast.get_docstring(ast.parse(source)) or ""
        for name in expected - {"__init__"}:
            assert name in doc, (node.name, name)


def test_sam_nodes_as_the_contract_lists() -> None:
    resolved = validate(load_spec_file(SPECS["sam"]))
    nodes = resolved.spec.nodes
    assert set(nodes["dead_reckoning"].subscribes) >= {"/imu", "/magnetic_field", "/pressure", "/thruster_1/feedback",
                                                       "/thruster_2/feedback"}
    assert nodes["dead_reckoning"].transforms == [("odom", "base_link")]
    assert nodes["slam"].subscribes == ["/gps_fix"] and nodes["slam"].transforms == [("world", "odom")]
    assert nodes["slam"].reads_transforms == [("odom", "base_link")]
    assert set(nodes["motion_planner"].subscribes) == {"/nav_goal", "/nav_heading", "/altitude"}
    assert nodes["motion_planner"].publishes == ["/global_plan"]
    assert set(nodes["motion_planner"].parameters) == {"/safe_depth", "/safe_altitude"}
    assert nodes["motion_planner"].reads_transforms == [("world", "base_link")]
    assert set(nodes["controller"].subscribes) == {"/global_plan", "/abort"}
    assert set(nodes["controller"].publishes) == {"/thruster_rpms", "/thruster_angles", "/ballast_angles",
                                                  "/longitudinal_weight_position", "/buoyancy_piston_position"}
    assert set(nodes["performance_monitor"].subscribes) == {"/pressure", "/altitude", "/battery_state"}
    assert set(nodes["performance_monitor"].publishes) == {"/abort", "/thruster_rpms", "/buoyancy_piston_position"}
    assert set(nodes["performance_monitor"].parameters) == {"/critical_depth", "/critical_altitude",
                                                            "/min_battery_percent"}
    topics = resolved.spec.topics
    assert (topics["/altitude"].type, topics["/abort"].type) == ("sensor_msgs/Range", "sam_msgs/Abort")
    assert topics["/abort"].qos.profile == "latched" and topics["/tf_static"].qos.durability == "transient_local"
    # REP 2003: sensor data published reliably, subscribed best effort
    assert (topics["/imu"].qos.reliability, topics["/imu"].subscriber_qos.reliability) == ("reliable", "best_effort")
    assert topics["/global_plan"].qos.reliability == topics["/global_plan"].subscriber_qos.reliability == "reliable"
    altimeter = resolved.spec.devices["altimeter"]
    assert (altimeter.node_id, altimeter.publishes[0].subject_id, altimeter.publishes[0].rate_hz) == (16, 1106, 10)
    assert altimeter.publishes[0].type == "sam.sensor.Altitude.0.1"
    assert resolved.spec.frames["altimeter_link"].parent == "base_link"
    p = resolved.spec.parameters["/min_battery_percent"]
    assert (p.type, p.default, p.minimum, p.maximum, p.unit) == ("double", 20.0, 0.0, 100.0, "%")


@pytest.mark.system  # starts a process: not in the unit tier
@pytest.mark.parametrize("which", ["files", "hostile"])
def test_modules_compile_and_are_ruff_clean(which: str, resolved: Resolved, files: dict[str, str],
                                            tmp_path: Path) -> None:
    out = files if which == "files" else emit_nodes.emit(_hostile(resolved))
    for path, text in out.items():
        if path.endswith(".py"):
            compile(text, path, "exec")
    if which == "hostile":
        return
    ruff = shutil.which("ruff") or str(Path(sys.executable).with_name("ruff"))
    if not Path(ruff).exists():
        pytest.skip("ruff is not installed (pip extra 'test')")
    for path, text in out.items():
        (tmp_path / path).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / path).write_text(text, encoding="utf-8")
    proc = subprocess.run(
        [ruff, "check", "--isolated", "--no-cache", "--line-length", "110", "--target-version", "py311",
         "--select", "E,F,W,I,B,UP,RUF", "--ignore", "RUF001,RUF002,RUF003", str(tmp_path / "python")],
        capture_output=True, text=True, check=False,
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr


def _hostile(resolved: Resolved) -> Resolved:
    s = resolved.spec  # the model is frozen: the hostile spec is a new one
    return replace(resolved, spec=replace(
        s,
        nodes={k: replace(n, description=HOSTILE) for k, n in s.nodes.items()},
        topics={k: replace(t, description=HOSTILE) for k, t in s.topics.items()},
        parameters={k: replace(p, description=HOSTILE, unit=HOSTILE) for k, p in s.parameters.items()},
        parameter_rules=[replace(r, description=HOSTILE) for r in s.parameter_rules],
        transforms=[replace(t, description=HOSTILE) for t in s.transforms],
    ))


def test_hostile_text_stays_data(resolved: Resolved, tmp_path: Path) -> None:
    """Descriptions reach the modules as docstring text (escaped) or literals; the literals give it back."""
    hostile = _hostile(resolved)
    out = emit_nodes.emit(hostile)
    node = next(n for n in hostile.spec.nodes.values() if n.parameters)
    path = tmp_path / "node.py"
    path.write_text(out[f"python/{hostile.spec.vehicle}_nodes/{node.name}.py"], encoding="utf-8")
    tree = ast.parse(path.read_text(encoding="utf-8"))
    specs = [n for n in ast.walk(tree) if isinstance(n, ast.Call) and ast.unparse(n.func).endswith("ParameterSpec")]
    descriptions = {ast.literal_eval(k.value) for c in specs for k in c.keywords if k.arg == "description"}
    assert descriptions == {HOSTILE}
    params = yaml.safe_load(out[f"params/{hostile.spec.vehicle}.params.yaml"])
    assert set(params["/**"]["ros__parameters"]) == {p.lstrip("/").replace("/", ".") for p in hostile.spec.parameters}


def test_params_file(resolved: Resolved, files: dict[str, str]) -> None:
    """ROS 2's --params-file format: /** -> ros__parameters -> every parameter's default, doubles with a point
    (rcl reads 50 as an integer, which a double parameter refuses)."""
    text = files[f"params/{resolved.spec.vehicle}.params.yaml"]
    values = yaml.safe_load(text)["/**"]["ros__parameters"]
    spec_values = {p.name.lstrip("/").replace("/", "."): p for p in resolved.spec.parameters.values()}
    assert values.keys() == spec_values.keys()
    for name, p in spec_values.items():
        assert values[name] == p.default and type(values[name]) is type(p.default), name
        if p.type == "double":
            assert f"    {name}: {p.default!r}" in text


def test_tables_carry_qos_frames_and_nodes(resolved: Resolved, tmp_path: Path) -> None:
    path = tmp_path / "tables.py"
    path.write_text(emit_python.emit(resolved)[f"python/{resolved.spec.vehicle}_bridge/tables.py"], encoding="utf-8")
    tables = _load(path, f"_nodes_tables_{resolved.spec.vehicle}")
    spec = resolved.spec
    for t in tables.TOPICS:
        for q, info in ((spec.topics[t.name].qos, t.qos), (spec.topics[t.name].subscriber_qos, t.subscriber_qos)):
            assert (info.reliability, info.durability, info.depth, info.profile) == (
                q.reliability, q.durability, q.depth, q.profile)
    static = [f for f in spec.frames.values() if f.parent]
    assert [(s.parent, s.child, s.translation) for s in tables.STATIC_TRANSFORMS] == [
        (f.parent, f.name, f.xyz) for f in static]
    for s, f in zip(tables.STATIC_TRANSFORMS, static, strict=True):
        assert s.rotation == pytest.approx(quat_from_rpy(*f.rpy), abs=1e-15)  # the runtime's own conversion
    assert [n.name for n in tables.NODES] == list(spec.nodes)
    assert tables.ROS_PACKAGES[-1] in (spec.ros.name, "tf2_msgs") and set(tables.ROS_PACKAGES) == {
        spec.ros.name, *(m.package for m in external_messages_to_generate(spec).values())}
    assert tables.PARAMS_FILE == f"params/{spec.vehicle}.params.yaml"
    for n in tables.NODES:
        node = spec.nodes[n.name]
        assert [e.topic for e in n.subscribes] == node.subscribes and n.parameters == tuple(node.parameters)
        own = {i.topic: i.qos for i in node.subscribe_items if i.qos is not None}
        for e in n.subscribes:
            q = own.get(e.topic) or spec.topics[e.topic].subscriber_qos
            assert (e.qos.reliability, e.qos.durability, e.qos.depth) == (q.reliability, q.durability, q.depth)


def test_quaternions_of_the_mountings() -> None:
    assert emit_nodes.quat_from_rpy(0.0, math.pi / 2, 0.0) == pytest.approx(quat_from_rpy(0.0, math.pi / 2, 0.0))
    assert emit_nodes.quat_from_rpy(0.3, -0.2, 2.0) == pytest.approx(quat_from_rpy(0.3, -0.2, 2.0))
