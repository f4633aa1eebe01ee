"""Broken service specs (issue 19) give exact errors, all at once: the SERVICE_CASES of tests/broken_cases.py, each
breaking tests/specs/auv_services.yaml one way."""

from __future__ import annotations

from pathlib import Path

import pytest
from broken_cases import SERVICE_CASES, Case

from sam_codegen.frontend.loader import load_spec_file
from sam_codegen.model.diagnostics import SpecError
from sam_codegen.validate.resolve import validate

pytest.importorskip("dronecan")

SPECS = Path(__file__).parents[1] / "specs"
BASE = (SPECS / "auv_services.yaml").read_text(encoding="utf-8")


def _errors(path: Path) -> list[str]:
    try:
        validate(load_spec_file(path))
    except SpecError as exc:
        return [str(d).replace(str(path), path.name) for d in exc.diagnostics]
    return []


def test_base_spec_is_valid() -> None:
    assert _errors(SPECS / "auv_services.yaml") == []


def test_cases_are_distinct() -> None:
    assert len({c.name for c in SERVICE_CASES}) == len(SERVICE_CASES) >= 25


@pytest.mark.parametrize("case", SERVICE_CASES, ids=lambda c: c.name)
def test_broken_spec(case: Case, tmp_path: Path) -> None:
    assert BASE.count(case.old) == 1, f"case {case.name} no longer applies to auv_services.yaml"
    path = tmp_path / "auv_services.yaml"
    path.write_text(BASE.replace(case.old, case.new, 1), encoding="utf-8")
    assert _errors(path) == list(case.errors)
