"""Broken `bridge.node_services` specs give exact errors, all at once: the NODE_SERVICE_CASES of
tests/broken_cases_node_services.py, each breaking tests/specs/auv_services.yaml one way."""

from __future__ import annotations

from pathlib import Path

import pytest
from broken_cases import Case
from broken_cases_node_services import NODE_SERVICE_CASES
from helpers.spec_errors import spec_errors

pytest.importorskip("dronecan")

SPECS = Path(__file__).parents[1] / "specs"
BASE = (SPECS / "auv_services.yaml").read_text(encoding="utf-8")


def test_cases_are_distinct() -> None:
    assert len({c.name for c in NODE_SERVICE_CASES}) == len(NODE_SERVICE_CASES) >= 10


@pytest.mark.parametrize("case", NODE_SERVICE_CASES, ids=lambda c: c.name)
def test_broken_spec(case: Case, tmp_path: Path) -> None:
    assert BASE.count(case.old) == 1, f"case {case.name} no longer applies to auv_services.yaml"
    path = tmp_path / "auv_services.yaml"
    path.write_text(BASE.replace(case.old, case.new, 1), encoding="utf-8")
    assert spec_errors(path) == list(case.errors)
