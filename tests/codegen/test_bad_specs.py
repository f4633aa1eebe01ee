"""Broken specs give clear errors (file:line:column, what and what was expected), all at once, exit 1,
and leave generated output untouched."""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

import pytest
from broken_cases import CASES, Case
from helpers.spec_errors import spec_errors

from sam_codegen.build import generate
from sam_codegen.cli import main
from sam_codegen.frontend.loader import MAX_SPEC_BYTES
from sam_codegen.model.diagnostics import MAX_SHOWN

SPECS = Path(__file__).parents[1] / "specs"
BASE = (SPECS / "minimal.yaml").read_text(encoding="utf-8")
REAL_SPEC = Path(__file__).parents[2] / "spec" / "interfaces.yaml"


def test_base_spec_is_valid() -> None:
    assert spec_errors(SPECS / "minimal.yaml") == []


def test_there_are_many_cases() -> None:
    assert len(CASES) >= 30
    assert len({c.name for c in CASES}) == len(CASES)


@pytest.mark.parametrize("case", CASES, ids=lambda c: c.name)
def test_broken_spec(case: Case, tmp_path: Path) -> None:
    assert case.old in BASE, f"case {case.name} no longer applies to minimal.yaml"
    path = tmp_path / "minimal.yaml"
    path.write_text(BASE.replace(case.old, case.new, 1), encoding="utf-8")
    assert spec_errors(path) == list(case.errors)


def test_cli_reports_all_errors_and_leaves_output_alone(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "generated"
    assert main(["build", "--spec", str(SPECS / "minimal.yaml"), "--out", str(out)]) == 0
    before = {p: p.read_bytes() for p in out.rglob("*") if p.is_file()}
    broken = tmp_path / "broken.yaml"
    text = BASE.replace("    node_id: 10", "    node_id: 128")
    text = text.replace("{name: level, type: int32", "{name: Level, type: int32")
    broken.write_text(text, encoding="utf-8")
    capsys.readouterr()
    assert main(["build", "--spec", str(broken), "--out", str(out)]) == 1
    err = capsys.readouterr().err
    assert f"{broken}:33:3: error: node id 128 of device gauge is out of range for Cyphal/CAN" in err
    assert f"{broken}:11:9: error: 'Level' is not a valid ROS field name" in err
    assert "Traceback" not in err
    assert "left unchanged" in err
    assert {p: p.read_bytes() for p in out.rglob("*") if p.is_file()} == before


def test_unreadable_spec_is_a_clear_error(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["build", "--spec", str(tmp_path / "nope.yaml"), "--out", str(tmp_path / "g")]) == 1
    err = capsys.readouterr().err
    assert "cannot read the spec" in err and "Traceback" not in err
    assert not (tmp_path / "g").exists()


def test_document_puts_two_types_on_thruster_angles(tmp_path: Path) -> None:
    """The design document lists BallastAngles on /thruster_angles; the validator must reject that."""
    text = REAL_SPEC.read_text(encoding="utf-8")
    ours = "  /ballast_angles: {type: sam_msgs/BallastAngles"
    assert ours in text
    path = tmp_path / "interfaces.yaml"
    path.write_text(text.replace(ours, "  /thruster_angles: {type: sam_msgs/BallastAngles"), encoding="utf-8")
    errors = spec_errors(path)
    assert any("topic '/thruster_angles' is declared twice" in e and "two types on one topic" in e
               and "sam_msgs/ThrusterAngles and sam_msgs/BallastAngles" in e for e in errors), errors


# ---- the spec file itself (issue 29 item 11) -----------------------------------------------------------------------

def _fifo(tmp_path: Path) -> Path:
    path = tmp_path / "spec.yaml"
    os.mkfifo(path)  # no writer: opening it for reading the usual way waits for one forever
    return path


def _oversize(tmp_path: Path) -> Path:
    path = tmp_path / "spec.yaml"
    with open(path, "wb") as handle:
        handle.write(b"# " + b"x" * MAX_SPEC_BYTES + b"\n")
    return path


@pytest.mark.parametrize(("make", "error"), [
    (lambda tmp: Path("/dev/zero"), "PATH: error: cannot read the spec: it is a character device (expected a "
     "regular file holding the YAML spec)"),
    (_fifo, "PATH: error: cannot read the spec: it is a FIFO (named pipe) (expected a regular file holding the "
     "YAML spec)"),
    (lambda tmp: tmp, "PATH: error: cannot read the spec: it is a directory (expected a regular file holding the YAML "
     "spec)"),
    (_oversize, "PATH: error: cannot read the spec: it is larger than 8,388,608 bytes (expected a spec of at "
     "most 8 MiB)"),
], ids=["dev_zero", "fifo", "directory", "oversize"])
def test_a_spec_is_a_regular_file_of_bounded_size(tmp_path: Path, make: Callable[[Path], Path], error: str) -> None:
    """/dev/zero gave a MemoryError traceback and a FIFO hung: each is now an exact error, at once."""
    path = make(tmp_path)
    assert spec_errors(path) == [error.replace("PATH", path.name)]


def test_errors_stop_after_a_cap_with_a_count(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """5 MB of junk keys printed 260,000 error lines (0.5 GB): the first MAX_SHOWN, then how many more."""
    path = tmp_path / "junk.yaml"
    path.write_text("spec_version: 1\n" + "".join(f"junk{i}: 1\n" for i in range(MAX_SHOWN + 70)), encoding="utf-8")
    assert main(["build", "--spec", str(path), "--out", str(tmp_path / "g")]) == 1
    err = capsys.readouterr().err.splitlines()
    assert len(err) == MAX_SHOWN + 2
    assert f"{path}:2:1: error: unknown field 'junk0' in the spec" in "\n".join(err)
    assert err[-2] == "... and 71 more errors"
    assert err[-1].startswith("sam-codegen: 121 errors in the spec;")
    assert main(["validate", "--spec", str(path)]) == 1
    assert capsys.readouterr().err.splitlines()[-1] == "... and 71 more errors"


def test_a_parameter_may_allow_nan(tmp_path: Path) -> None:
    """Issue 29 item 10: `allow_nan: true` lets a double parameter default to NaN (no rule orders it); the generated
    modules spell it as an expression (`nan` or `_NAN` alone would be a NameError when the node starts)."""
    old = "  /warn_level: {type: double, unit: m, default: 1.0, min: 0.0, max: 10.0}"
    path = tmp_path / "minimal.yaml"
    path.write_text(BASE.replace(old, old.replace("1.0,", ".nan,").replace("}", ", allow_nan: true}")),
                    encoding="utf-8")
    files = generate(path)
    for name in ("python/buoy_bridge/tables.py", "python/buoy_nodes/logger.py"):
        assert "default=float('nan')," in files[name], name
        compile(files[name], name, "exec")
    assert "warn_level: .nan" in files["params/buoy.params.yaml"]
