"""The node, QoS, TF and external-package checks: each broken spec of tests/broken_cases_nodes.py gives exactly its
diagnostics (file:line:column, what, what was expected), all at once, and `sam-codegen build` leaves the output
alone."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from broken_cases_nodes import CASES, Case

from sam_codegen.cli import main
from sam_codegen.frontend.loader import load_spec_file
from sam_codegen.model.diagnostics import SpecError
from sam_codegen.validate.resolve import validate

SPECS = Path(__file__).parents[1] / "specs"
BASE = (SPECS / "minimal.yaml").read_text(encoding="utf-8")
SHARE = str(Path(sys.prefix) / "share")


def _apply(case: Case) -> str:
    text = BASE
    for old, new in case.edits:
        assert old in text, f"case {case.name}: {old!r} is not in minimal.yaml (any more)"
        text = text.replace(old, new, 1)
    return text


def _errors(path: Path) -> list[str]:
    try:
        validate(load_spec_file(path))
    except SpecError as exc:
        return [str(d).replace(str(path), path.name).replace(SHARE, "{share}") for d in exc.diagnostics]
    return []


def test_cases_are_distinct_and_many() -> None:
    assert len(CASES) >= 15 and len({c.name for c in CASES}) == len(CASES)


@pytest.mark.parametrize("case", CASES, ids=lambda c: c.name)
def test_broken_spec(case: Case, tmp_path: Path) -> None:
    path = tmp_path / "minimal.yaml"
    path.write_text(_apply(case), encoding="utf-8")
    assert _errors(path) == list(case.errors)


def test_build_reports_and_leaves_output_alone(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "generated"
    assert main(["build", "--spec", str(SPECS / "minimal.yaml"), "--out", str(out)]) == 0
    before = {p: p.read_bytes() for p in out.rglob("*") if p.is_file()}
    broken = tmp_path / "broken.yaml"
    broken.write_text(_apply(next(c for c in CASES if c.name == "generated_names_that_clash")), encoding="utf-8")
    capsys.readouterr()
    assert main(["build", "--spec", str(broken), "--out", str(out)]) == 1
    err = capsys.readouterr().err
    assert "4 errors in the spec" in err and "Traceback" not in err
    assert f"{broken}:72:32: error: node valve_control: parameter /executor would be executor" in err
    assert {p: p.read_bytes() for p in out.rglob("*") if p.is_file()} == before
