"""The Python emitter's output: golden copies, determinism, valid and lint-clean Python, inert hostile text.

These tests need neither ROS nor compiled DSDL; tests/test_converters.py runs the converters with real classes.
``SAM_UPDATE_GOLDEN=1`` rewrites tests/golden/python/ from the current emitter. The copies are stored as
``<path>.golden`` (e.g. python/sam_bridge/convert.py.golden) so that pytest's --doctest-modules does not import
them (convert.py imports ROS and DSDL packages).
"""

from __future__ import annotations

import ast
import importlib.util
import json
import keyword
import os
import shutil
import subprocess
import sys
from dataclasses import replace
from pathlib import Path
from types import ModuleType

import pytest

from sam_codegen.frontend.loader import load_spec_file
from sam_codegen.targets.python import convert as emit_python
from sam_codegen.targets.python.names import py_attr, ros_closure
from sam_codegen.validate.resolve import Resolved, validate

ROOT = Path(__file__).resolve().parents[2]
SAM_SPEC = ROOT / "spec" / "interfaces.yaml"
ROVER_SPEC = Path(__file__).resolve().parents[1] / "specs" / "rover.yaml"
GOLDEN = Path(__file__).resolve().parents[1] / "golden" / "python"
UPDATE = os.environ.get("SAM_UPDATE_GOLDEN") == "1"
# Golden copies of other emitters kept beside these (tests/test_codec_cyphal.py checks and rewrites codec.py's).
OTHER_EMITTERS = frozenset({"codec.py"})
HOSTILE = 'a "quote", an \'apostrophe\', """triple""", {{ jinja }} {% x %}\n# newline\\ and \x00 \u2028 end'


@pytest.fixture(scope="module")
def sam() -> Resolved:
    return validate(load_spec_file(SAM_SPEC))


@pytest.fixture(scope="module")
def rover() -> Resolved:
    return validate(load_spec_file(ROVER_SPEC))


@pytest.fixture(scope="module")
def sam_files(sam: Resolved) -> dict[str, str]:
    return emit_python.emit(sam)


def _load(path: Path, name: str) -> ModuleType:
    spec = importlib.util.spec_from_file_location(name, path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # dataclasses look their module up
    try:
        spec.loader.exec_module(module)
    finally:
        del sys.modules[name]
    return module


def _tables(files: dict[str, str], tmp_path: Path, vehicle: str) -> ModuleType:
    path = tmp_path / f"{vehicle}_tables.py"
    path.write_text(files[f"python/{vehicle}_bridge/tables.py"], encoding="utf-8")
    return _load(path, f"_golden_{vehicle}_tables")


def test_golden(sam_files: dict[str, str]) -> None:
    """The SAM spec's Python package, byte for byte (SAM_UPDATE_GOLDEN=1 rewrites the copies)."""
    if UPDATE:
        for old in GOLDEN.rglob("*.golden"):
            if old.name.removesuffix(".golden") not in OTHER_EMITTERS:
                old.unlink()
        for path, text in sam_files.items():
            (GOLDEN / f"{path}.golden").parent.mkdir(parents=True, exist_ok=True)
            (GOLDEN / f"{path}.golden").write_bytes(text.encode("utf-8"))
    golden = {p.relative_to(GOLDEN).as_posix().removesuffix(".golden"): p.read_bytes().decode("utf-8")
              for p in sorted(GOLDEN.rglob("*"))
              if p.is_file() and p.name.removesuffix(".golden") not in OTHER_EMITTERS}
    assert sorted(golden) == sorted(sam_files), "run with SAM_UPDATE_GOLDEN=1 after an intended change"
    for path, text in sam_files.items():
        assert text == golden[path], f"{path} differs from its golden copy; SAM_UPDATE_GOLDEN=1 rewrites it"


def test_layout_and_determinism(sam: Resolved, sam_files: dict[str, str], rover: Resolved) -> None:
    assert sorted(sam_files) == ["python/sam_bridge/__init__.py", "python/sam_bridge/conversion_support.py",
                                 "python/sam_bridge/convert.py", "python/sam_bridge/tables.py"]
    assert emit_python.emit(sam) == sam_files
    assert emit_python.emit(validate(load_spec_file(SAM_SPEC))) == sam_files  # a fresh model too
    assert emit_python.emit(rover) == emit_python.emit(validate(load_spec_file(ROVER_SPEC)))
    for path, text in sam_files.items():
        assert text.startswith("# Generated from interfaces.yaml by sam-codegen; do not edit.\n"), path
        assert str(ROOT) not in text and "/work/" not in text and "/tmp" not in text, path
        assert text.endswith("\n") and not text.endswith("\n\n"), path
        assert "\t" not in text and not any(line != line.rstrip() for line in text.splitlines()), path


@pytest.mark.parametrize("which", ["sam", "rover"])
def test_modules_compile(which: str, request: pytest.FixtureRequest) -> None:
    files = emit_python.emit(request.getfixturevalue(which))
    for path, text in files.items():
        compile(text, path, "exec")


@pytest.mark.parametrize("which", ["sam", "rover"])
def test_imports(which: str, request: pytest.FixtureRequest) -> None:
    """tables.py imports only the standard library; convert.py adds only ROS message and DSDL packages: those of
    the mapped types and of the messages nested in them (the converters build those too), and numpy."""
    resolved: Resolved = request.getfixturevalue(which)
    files = emit_python.emit(resolved)
    package = f"python/{resolved.spec.vehicle}_bridge"

    def imports(text: str) -> set[str]:
        found = set()
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, ast.Import):
                found |= {alias.name for alias in node.names}
            elif isinstance(node, ast.ImportFrom) and node.level:  # this package's own: ".module"
                found |= {"." + (node.module or alias.name) for alias in node.names}
            elif isinstance(node, ast.ImportFrom):
                found.add(node.module or "")
        return found

    assert imports(files[f"{package}/__init__.py"]) == set()
    assert imports(files[f"{package}/tables.py"]) <= set(sys.stdlib_module_names) | {"__future__"}
    assert imports(files[f"{package}/conversion_support.py"]) <= {"__future__"}
    mapped = {f"{rm.ros_message.package}.msg" for rm in resolved.mappings}
    nested = {f"{full.split('/')[0]}.msg" for full in ros_closure(resolved)}
    dsdl = {s.namespace for s in resolved.dsdl_types} | {"uavcan.time"}
    convert = imports(files[f"{package}/convert.py"])
    own = {".conversion_support"}
    assert convert - {"__future__", "collections.abc", "copy", "numpy", "typing"} - own <= nested | dsdl
    assert mapped <= convert


def test_sam_tables(sam: Resolved, sam_files: dict[str, str], tmp_path: Path) -> None:
    tables = _tables(sam_files, tmp_path, "sam")
    assert (tables.VEHICLE, tables.ROS_PACKAGE, tables.DSDL_ROOT_NAMESPACE) == ("sam", "sam_msgs", "sam")
    assert (tables.BRIDGE_NAME, tables.BRIDGE_NODE_ID) == ("uavcan_ros_bridge", 100)
    assert [d.name for d in tables.DEVICES] == list(sam.spec.devices)
    thruster = next(d for d in tables.DEVICES if d.name == "thruster_1")
    assert thruster.node_id == 21
    assert thruster.subscribes == (tables.PortInfo(1200, "sam.actuator.ThrusterRPM.0.1", "sam.actuator",
                                                   "ThrusterRPM_0_1", 10.0),)
    assert [t.name for t in tables.TOPICS] == list(sam.spec.topics)
    imu = next(m for m in tables.MAPPINGS if m.name == "imu")
    assert imu.topic == tables.TopicInfo("/imu", "sensor_msgs/msg/Imu", "sensor_msgs.msg", "Imu", "IMU samples.",
                                         tables.QosInfo("reliable", "volatile", 5, ""),
                                         tables.QosInfo("best_effort", "volatile", 5, "sensor_data"))
    assert imu.port == tables.PortInfo(1100, "sam.sensor.RawIMU.0.1", "sam.sensor", "RawIMU_0_1", 100.0)
    assert (imu.direction, imu.source_node_ids, imu.destination_node_id) == ("uavcan_to_ros", frozenset({11}), None)
    assert (imu.frame_id, imu.rate_hz, imu.on_out_of_range) == ("imu_link", 100.0, "saturate")
    assert (imu.to_ros, imu.to_uavcan) == ("imu_to_ros", "imu_to_uavcan")
    assert imu.linked_uavcan_fields[:2] == ("timestamp.microsecond", "rate_gyro_latest[0]")
    assert imu.exact_uavcan_fields == imu.linked_uavcan_fields
    gps = next(m for m in tables.MAPPINGS if m.name == "gps_fix")
    assert "status" in gps.linked_uavcan_fields and "status" not in gps.exact_uavcan_fields  # a lossy table
    assert "position_covariance" not in gps.exact_uavcan_fields  # padded into a fixed array
    rpm = next(m for m in tables.MAPPINGS if m.name == "thruster_1_rpm")
    assert (rpm.direction, rpm.source_node_ids, rpm.destination_node_id, rpm.frame_id) == (
        "ros_to_uavcan", frozenset(), 21, None)
    assert [p.name for p in tables.PARAMETERS] == list(sam.spec.parameters)
    assert tables.PARAMETERS[0] == tables.ParameterInfo("/safe_altitude", "double", 5.0, 0.0, 100.0, "m",
                                                        sam.spec.parameters["/safe_altitude"].description)
    rule = tables.PARAMETER_RULES[0]
    assert (rule.left, rule.op, rule.right) == ("/critical_altitude", "<", "/safe_altitude")
    assert ("imu_link", "base_link") in tables.FRAMES and ("world", None) in tables.FRAMES


def test_rover_tables(rover: Resolved, tmp_path: Path) -> None:
    tables = _tables(emit_python.emit(rover), tmp_path, "rover")
    command = next(m for m in tables.MAPPINGS if m.name == "drive_command")
    assert command.on_out_of_range == "reject"
    status = next(m for m in tables.MAPPINGS if m.name == "drive_status")
    assert "id" in status.exact_uavcan_fields and "label" in status.exact_uavcan_fields
    params = {p.name: p for p in tables.PARAMETERS}
    assert params["/wheel_count"] == tables.ParameterInfo("/wheel_count", "integer", 4, 4.0, 6.0, "",
                                                          "Number of driven wheels.")
    assert params["/log_drive"].default is True and params["/log_drive"].minimum is None
    assert params["/operator"].default == "O'Neil \"Ops\""
    assert tables.FRAMES == (("map", None), ("base_link", "map"), ("air_sensor", "base_link"))
    assert "\\" in rover.spec.description  # the description's backslash is kept as data


def test_hostile_text_stays_inert(sam: Resolved, tmp_path: Path) -> None:
    """Text from the spec reaches the generated modules only as data."""
    s = sam.spec  # the model is frozen: the hostile spec is a new one
    hostile = replace(sam, spec=replace(
        s,
        topics={k: replace(t, description=HOSTILE) for k, t in s.topics.items()},
        devices={k: replace(d, description=HOSTILE * 3) for k, d in s.devices.items()},
        parameters={k: replace(p, description=HOSTILE, unit=HOSTILE) for k, p in s.parameters.items()},
        parameter_rules=[replace(r, description=HOSTILE) for r in s.parameter_rules],
    ))
    files = emit_python.emit(hostile)
    for path, text in files.items():
        compile(text, path, "exec")
    tables = _tables(files, tmp_path, "sam")
    assert {t.description for t in tables.TOPICS} == {HOSTILE}
    assert {d.description for d in tables.DEVICES} == {HOSTILE * 3}
    assert {p.description for p in tables.PARAMETERS} | {p.unit for p in tables.PARAMETERS} == {HOSTILE}
    assert {r.description for r in tables.PARAMETER_RULES} == {HOSTILE}


@pytest.mark.system  # starts a process: not in the unit tier
def test_python_names_follow_pycyphal() -> None:
    """Attribute names are mangled exactly as nunavut's Python target does (keywords and builtins get `_`)."""
    names = ["rpm", "id", "type", "match", "case", "print", "self", "async", "max", "len", "Exception", "x_", "_x"]
    # The builtins of a fresh interpreter: this process's may have gained names at run time (doctest sets `_`).
    fresh = subprocess.run([sys.executable, "-I", "-c", "import builtins; print(' '.join(dir(builtins)))"],
                           capture_output=True, text=True, check=True).stdout.split()
    names += sorted(set(fresh) | set(keyword.kwlist))[:400]
    nunavut = pytest.importorskip("nunavut.lang")
    language = nunavut.LanguageContextBuilder().set_target_language("py").create().get_target_language()
    for name in names:
        if name.isidentifier():
            assert py_attr(name) == language.filter_id(name), name


@pytest.mark.system  # starts a process: not in the unit tier
@pytest.mark.parametrize("which", ["sam", "rover"])
def test_ruff_clean(which: str, request: pytest.FixtureRequest, tmp_path: Path) -> None:
    ruff = shutil.which("ruff") or str(Path(sys.executable).with_name("ruff"))
    if not Path(ruff).exists():
        pytest.skip("ruff is not installed (pip extra 'test')")
    files = emit_python.emit(request.getfixturevalue(which))
    for path, text in files.items():
        (tmp_path / path).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / path).write_text(text, encoding="utf-8")
    proc = subprocess.run(
        [ruff, "check", "--isolated", "--no-cache", "--line-length", "110", "--target-version", "py311",
         "--select", "E,F,W,I,B,UP,RUF", "--ignore", "RUF001,RUF002,RUF003", str(tmp_path / "python")],
        capture_output=True, text=True, check=False,
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr


@pytest.mark.system  # starts a process: not in the unit tier
def test_same_output_in_another_process(sam_files: dict[str, str]) -> None:
    """No dependence on set or dict order: another process with another hash seed emits the same bytes."""
    code = ("import json, pathlib, sys; from sam_codegen.targets.python import convert as emit_python; "
            "from sam_codegen.frontend.loader import "
            "load_spec_file; from sam_codegen.validate.resolve import validate; "
            "json.dump(emit_python.emit(validate(load_spec_file(pathlib.Path(sys.argv[1])))), sys.stdout)")
    env = {**os.environ, "PYTHONHASHSEED": "12345"}
    proc = subprocess.run([sys.executable, "-c", code, str(SAM_SPEC)], capture_output=True, text=True, env=env,
                          check=True)
    assert json.loads(proc.stdout) == sam_files
