"""Broken specs give clear errors (file:line:column, what and what was expected), all at once, exit 1,
and leave generated output untouched."""

from __future__ import annotations

from pathlib import Path

import pytest
from broken_cases import CASES, Case
from helpers.spec_errors import spec_errors

from sam_codegen.cli import main

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
