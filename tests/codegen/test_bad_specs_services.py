"""Broken service specs (issue 19) give exact errors, all at once: the SERVICE_CASES of tests/broken_cases.py, each
breaking tests/specs/auv_services.yaml one way."""

from __future__ import annotations

from pathlib import Path

import pytest
from broken_cases import SERVICE_CASES, Case
from helpers.spec_errors import spec_errors

pytest.importorskip("dronecan")

SPECS = Path(__file__).parents[1] / "specs"
BASE = (SPECS / "auv_services.yaml").read_text(encoding="utf-8")


def test_base_spec_is_valid() -> None:
    assert spec_errors(SPECS / "auv_services.yaml") == []


def test_cases_are_distinct() -> None:
    assert len({c.name for c in SERVICE_CASES}) == len(SERVICE_CASES) >= 25


@pytest.mark.parametrize("case", SERVICE_CASES, ids=lambda c: c.name)
def test_broken_spec(case: Case, tmp_path: Path) -> None:
    assert BASE.count(case.old) == 1, f"case {case.name} no longer applies to auv_services.yaml"
    path = tmp_path / "auv_services.yaml"
    path.write_text(BASE.replace(case.old, case.new, 1), encoding="utf-8")
    assert spec_errors(path) == list(case.errors)
