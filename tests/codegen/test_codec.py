"""The generated Cyphal wire codecs (codec.py) against the object path they replace, with the real classes.

For every Cyphal mapping of six specs (SAM; tests/specs/rover.yaml: odd widths, bool, utf8, arrays, a nested
composite; tests/specs/tractor.yaml: void padding, int3/5/7 arrays, fixed arrays of composites;
tests/specs/barge.yaml: nested delimited composites, a variable-length array of them, bool arrays, a standard type
with padding; tests/specs/relay.yaml: expressions; tests/specs/dredger.yaml: element mappings, arrays of delimited and
sealed composites of bit fields as records, ROS element messages of mixed alignment), with hypothesis:

(a) random pycyphal objects (every field over its whole range) -> pycyphal serialize -> ``m_wire_to_ros`` ->
    rclpy deserialize_message == what the object path gives (pycyphal deserialize, ``m_to_ros``, rclpy), NaN-aware,
    with the same stamp and the same counters, None where it gives None;
(b) random ROS messages -> serialize_message -> ``m_ros_to_wire`` -> pycyphal deserialize == ``m_to_uavcan``'s
    object, same counters, same None;
(c) malformed payloads (every truncation, each byte at 0xFF and at a random value: length prefixes and delimiter
    headers among them; extended; random bytes): WireError exactly where pycyphal's deserialize gives no object,
    else (a)'s equality; never another exception. Malformed CDR: WireError or a result equal to rclpy's.
Plus the wire layers alone against rclpy (every ROS message the mappings use) and pycyphal (standard types with
unions, arrays of composites and padding), the golden copy of SAM's codec.py (``SAM_UPDATE_GOLDEN=1`` rewrites
it), determinism, and codec.py in a user's project.

The checks with ROS classes run in a child pytest, as tests/test_converters.py does (whose build helpers this uses:
the generated ROS package is loadable only by a process started with its LD_LIBRARY_PATH).
"""

from __future__ import annotations

import ast
import importlib
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest
import test_converters as tc

from sam_codegen.frontend.loader import load_spec_file
from sam_codegen.targets.python import convert as emit_python
from sam_codegen.targets.wire import codec as emit_codec
from sam_codegen.validate.resolve import validate

ROOT = Path(__file__).resolve().parents[2]
SPECS = {**tc.SPECS, "barge": Path(__file__).resolve().parents[1] / "specs" / "barge.yaml",
         "relay": Path(__file__).resolve().parents[1] / "specs" / "relay.yaml",
         "dredger": Path(__file__).resolve().parents[1] / "specs" / "dredger.yaml",
         "retrofit": Path(__file__).resolve().parents[1] / "specs" / "retrofit.yaml"}
GOLDEN = Path(__file__).resolve().parents[1] / "golden" / "python" / "python" / "sam_bridge" / "codec.py.golden"
UPDATE = os.environ.get("SAM_UPDATE_GOLDEN") == "1"
WORKER_ENV = "SAM_CODEC_WORKER"
WORKER = os.environ.get(WORKER_ENV)


def _codec(spec: Path) -> str:
    files = emit_codec.emit(validate(load_spec_file(spec)))
    (text,) = files.values()
    return text


# ============================================================================================ parent: no ROS needed

if not WORKER:

    def test_golden() -> None:
        """SAM's codec.py, byte for byte."""
        text = _codec(SPECS["sam"])
        if UPDATE:
            GOLDEN.parent.mkdir(parents=True, exist_ok=True)
            GOLDEN.write_bytes(text.encode("utf-8"))
        assert text == GOLDEN.read_bytes().decode("utf-8"), "codec.py changed: SAM_UPDATE_GOLDEN=1 rewrites it"

    @pytest.mark.system  # starts a process: not in the unit tier
    def test_deterministic() -> None:
        """The same bytes from a fresh model and from another process with another hash seed."""
        text = _codec(SPECS["sam"])
        assert _codec(SPECS["sam"]) == text
        code = ("import sys; from pathlib import Path; from sam_codegen.targets.wire import codec as emit_codec; "
                "from sam_codegen.frontend import load_spec_file; from sam_codegen.validate import validate; "
                "sys.stdout.write(*emit_codec.emit(validate(load_spec_file(Path(sys.argv[1])))).values())")
        proc = subprocess.run([sys.executable, "-c", code, str(SPECS["sam"])], capture_output=True, text=True,
                              env={**os.environ, "PYTHONHASHSEED": "4242"}, check=True)
        assert proc.stdout == text
        assert text.startswith("# Generated from interfaces.yaml by sam-codegen; do not edit.\n")
        assert "/work/" not in text and "/tmp" not in text and "\t" not in text

    @pytest.mark.system  # starts a process: not in the unit tier
    @pytest.mark.parametrize("spec", sorted(SPECS))
    def test_ruff_clean_and_standard_library_only(spec: str, tmp_path: Path) -> None:
        text = _codec(SPECS[spec])
        support = emit_python.emit(validate(load_spec_file(SPECS[spec])))
        (support_text,) = (t for path, t in support.items() if path.endswith("/conversion_support.py"))
        for module in (text, support_text):
            imported = set()
            for node in ast.walk(ast.parse(module)):
                if isinstance(node, ast.Import):
                    imported |= {alias.name.split(".")[0] for alias in node.names}
                elif isinstance(node, ast.ImportFrom) and node.level:  # this package's own
                    imported |= {"." + (node.module or alias.name) for alias in node.names}
                elif isinstance(node, ast.ImportFrom):
                    imported.add((node.module or "").split(".")[0])
            assert imported <= set(sys.stdlib_module_names) | {"__future__", ".conversion_support"}, imported
        ruff = shutil.which("ruff") or str(Path(sys.executable).with_name("ruff"))
        if not Path(ruff).exists():
            pytest.skip("ruff is not installed (pip extra 'test')")
        (tmp_path / "codec.py").write_text(text, encoding="utf-8")
        proc = subprocess.run(
            [ruff, "check", "--isolated", "--no-cache", "--line-length", "110", "--target-version", "py311",
             "--select", "E,F,W,I,B,UP,RUF", "--ignore", "RUF001,RUF002,RUF003", str(tmp_path / "codec.py")],
            capture_output=True, text=True, check=False)
        assert proc.returncode == 0, proc.stdout + proc.stderr

    @pytest.mark.system  # starts a process: not in the unit tier
    def test_user_project_gets_a_codec(tmp_path: Path) -> None:
        """`build` in a project of its own (outside this repository) writes codec.py, importable without ROS or
        pycyphal: a codec for each mapping, both directions."""
        from sam_codegen.build import build

        project = tmp_path / "skiff"
        (project / "spec").mkdir(parents=True)
        shutil.copy(ROOT / "tests" / "specs" / "skiff.yaml", project / "spec" / "interfaces.yaml")
        build(project / "spec" / "interfaces.yaml", project / "generated")
        resolved = validate(load_spec_file(project / "spec" / "interfaces.yaml"))
        package = project / "generated" / "python" / f"{resolved.spec.vehicle}_bridge"
        code = ("import sys, json; sys.path.insert(0, sys.argv[1]); import importlib; "
                f"m = importlib.import_module('{package.name}.codec'); "
                "bad = [n for n in sys.modules if n.split('.')[0] in ('rclpy', 'pycyphal', 'numpy')]; "
                "print(json.dumps([sorted(m.CODECS), bad, issubclass(m.WireError, ValueError)]))")
        proc = subprocess.run([sys.executable, "-I", "-c", code, str(package.parent)], capture_output=True,
                              text=True, check=True)
        names, heavy, is_value_error = json.loads(proc.stdout)
        assert names == sorted(rm.mapping.name for rm in resolved.mappings) and names
        assert heavy == [] and is_value_error

    @pytest.mark.slow
    @pytest.mark.skipif(importlib.util.find_spec("pycyphal") is None, reason="pycyphal is not installed")
    def test_wire_cyphal_on_standard_types(tmp_path: Path) -> None:
        """wire_cyphal's reader and writer on standard types the spec tests do not reach: unions (tags, default
        variant), variable-length arrays of delimited composites holding unions, bool[8192], void padding."""
        from helpers.wire_check import check_standard_types

        check_standard_types(tmp_path, ["uavcan.node.port.List.1.0", "uavcan.register.Value.1.0",
                                        "reg.udral.service.battery.Parameters.0.3", "uavcan.node.port.ID.1.0",
                                        "reg.udral.service.actuator.common.FaultFlags.0.1"])

    @pytest.fixture(scope="session")
    def built(tmp_path_factory: pytest.TempPathFactory) -> Any:
        cache: dict[str, dict[str, str]] = {}

        def get(name: str) -> dict[str, str]:
            if name not in cache:
                config = tc._build(SPECS[name], tmp_path_factory.mktemp(f"codec-{name}"))
                target = Path(config["python"]) / config["package"] / "codec.py"
                target.write_text(_codec(SPECS[name]), encoding="utf-8")
                cache[name] = config
            return cache[name]

        return get

    @pytest.mark.ros
    @pytest.mark.slow
    @tc.needs_tools
    @pytest.mark.parametrize("spec", sorted(SPECS))
    def test_codecs_with_real_classes(spec: str, built: Any) -> None:
        """Run this file's worker tests for `spec` in a child pytest that can load the built ROS package."""
        from sam_codegen.project.ros_install import ros_runtime_env

        config = built(spec)
        env = ros_runtime_env(Path(config["prefix"]))
        env[WORKER_ENV] = json.dumps(config)
        env.pop("ROS_PYTHON_CHECK_FIELDS", None)
        env.pop("PYTEST_ADDOPTS", None)
        proc = subprocess.run(
            [sys.executable, "-m", "pytest", __file__, "-q", "-p", "no:cacheprovider", "--rootdir", str(ROOT),
             "-W", "error::RuntimeWarning"],
            cwd=ROOT, env=env, capture_output=True, text=True, timeout=1800, check=False,
        )
        report = proc.stdout[-12000:] + proc.stderr[-4000:]
        assert proc.returncode == 0, f"worker tests for {spec} failed:\n{report}"
        assert " passed" in proc.stdout and " skipped" not in proc.stdout, report


# ============================================================================================ worker

if WORKER:
    from helpers.codec_worker import *  # noqa: F403  (the worker's tests, collected here)
