"""Broken specs of issue 27's constructs give exact errors, all at once: the RETROFIT_CASES of
tests/broken_cases_spec27.py, each breaking tests/specs/retrofit.yaml one way, and the SERVICE27_CASES (nested
service response fields, none left unwritten) on tests/specs/auv_services.yaml; a case without errors is a spelling
the spec accepts (the duty with the spec's own srv holding a nested `status`, the issue's example, is checked for
what it writes)."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import pytest
from broken_cases import Case
from broken_cases_spec27 import RETROFIT_CASES, SERVICE27_CASES, V0_RESPONSE_CASES, Edits
from helpers.spec_errors import spec_errors

from sam_codegen.frontend.loader import load_spec_file
from sam_codegen.validate.resolve import Resolved, validate
from sam_runtime.bridge.backends.service_mappings import set_field

pytest.importorskip("dronecan")

SPECS = Path(__file__).parents[1] / "specs"
BASE = (SPECS / "retrofit.yaml").read_text(encoding="utf-8")


def test_base_spec_is_valid() -> None:
    assert spec_errors(SPECS / "retrofit.yaml") == []


def test_cases_are_distinct() -> None:
    cases = [*RETROFIT_CASES, *V0_RESPONSE_CASES, *SERVICE27_CASES]
    assert len({c.name for c in cases}) == len(cases)


@pytest.mark.parametrize("case", [*RETROFIT_CASES, *V0_RESPONSE_CASES], ids=lambda c: c.name)
def test_broken_spec(case: Case, tmp_path: Path) -> None:
    assert BASE.count(case.old) == 1, f"case {case.name} no longer applies to retrofit.yaml"
    path = tmp_path / "retrofit.yaml"
    path.write_text(BASE.replace(case.old, case.new, 1), encoding="utf-8")
    assert spec_errors(path) == list(case.errors)


SERVICES = (SPECS / "auv_services.yaml").read_text(encoding="utf-8")


@pytest.mark.parametrize("case", SERVICE27_CASES, ids=lambda c: c.name)
def test_broken_service_spec(case: Edits, tmp_path: Path) -> None:
    text = SERVICES
    for old, new in case.edits:
        assert text.count(old) == 1, f"case {case.name} no longer applies to auv_services.yaml"
        text = text.replace(old, new, 1)
    path = tmp_path / "auv_services.yaml"
    path.write_text(text, encoding="utf-8")
    assert spec_errors(path) == list(case.errors)


def _resolved(case: str, tmp_path: Path) -> Resolved:
    (edits,) = (c.edits for c in SERVICE27_CASES if c.name == case)
    text = SERVICES
    for old, new in edits:
        text = text.replace(old, new, 1)
    path = tmp_path / "auv_services.yaml"
    path.write_text(text, encoding="utf-8")
    return validate(load_spec_file(path))


def test_a_duty_writes_the_nested_status(tmp_path: Path) -> None:
    """The issue's example: a duty given the spec's own srv with a nested `status` answered `status` all zero;
    now the duty writes status.uptime_sec, health, mode and the vendor code from the device's answer, and the
    bridge sets them in the nested message (set_field)."""
    resolved = _resolved("duty_nested_status", tmp_path)
    (duty,) = (m for m in resolved.service_mappings if m.mapping.name == "node_services.get_node_info")
    assert {(link.target, link.source) for link in duty.response} >= {
        ("status.uptime_sec", "status.uptime_sec"), ("status.health", "status.health"),
        ("status.mode", "status.mode"), ("status.vendor_specific_status_code", "status.vendor_specific_status_code")}
    response = SimpleNamespace(status=SimpleNamespace(uptime_sec=0, health=0))
    set_field(response, "status.uptime_sec", 4242)
    assert response.status.uptime_sec == 4242


def test_a_mapping_writes_a_nested_response_field(tmp_path: Path) -> None:
    resolved = _resolved("mapping_nested_ros_response", tmp_path)
    (m,) = (m for m in resolved.service_mappings if m.mapping.name == "get_node_info")
    assert ("status.uptime_sec", "status.uptime_sec") in {(link.target, link.source) for link in m.response}
