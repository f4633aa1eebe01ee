"""Broken specs of issue 27's constructs give exact errors, all at once: the RETROFIT_CASES of
tests/broken_cases_spec27.py, each breaking tests/specs/retrofit.yaml one way."""

from __future__ import annotations

from pathlib import Path

import pytest
from broken_cases import Case
from broken_cases_spec27 import RETROFIT_CASES
from helpers.spec_errors import spec_errors

pytest.importorskip("dronecan")

SPECS = Path(__file__).parents[1] / "specs"
BASE = (SPECS / "retrofit.yaml").read_text(encoding="utf-8")


def test_base_spec_is_valid() -> None:
    assert spec_errors(SPECS / "retrofit.yaml") == []


def test_cases_are_distinct() -> None:
    assert len({c.name for c in RETROFIT_CASES}) == len(RETROFIT_CASES)


@pytest.mark.parametrize("case", RETROFIT_CASES, ids=lambda c: c.name)
def test_broken_spec(case: Case, tmp_path: Path) -> None:
    assert BASE.count(case.old) == 1, f"case {case.name} no longer applies to retrofit.yaml"
    path = tmp_path / "retrofit.yaml"
    path.write_text(BASE.replace(case.old, case.new, 1), encoding="utf-8")
    assert spec_errors(path) == list(case.errors)
