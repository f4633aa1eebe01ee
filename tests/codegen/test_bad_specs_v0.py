"""Broken DroneCAN specs give exact errors (file:line:column, what, what was expected), all at once: the V0_CASES of
tests/broken_cases.py, each breaking tests/specs/minimal_v0.yaml one way; and the checks that need another spec
(layouts of SAM's spec, the standard definitions missing)."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from broken_cases import V0_CASES, Case
from helpers.spec_errors import spec_errors

from sam_codegen.cli import main

SPECS = Path(__file__).parents[1] / "specs"
BASE = (SPECS / "minimal_v0.yaml").read_text(encoding="utf-8")
SAM_SPEC = Path(__file__).parents[2] / "spec" / "interfaces.yaml"


def test_base_spec_is_valid() -> None:
    assert spec_errors(SPECS / "minimal_v0.yaml") == []


def test_there_are_many_cases() -> None:
    assert len(V0_CASES) >= 30
    assert len({c.name for c in V0_CASES}) == len(V0_CASES)


@pytest.mark.parametrize("case", V0_CASES, ids=lambda c: c.name)
def test_broken_spec(case: Case, tmp_path: Path) -> None:
    assert BASE.count(case.old) == 1, f"case {case.name} no longer applies to minimal_v0.yaml"
    path = tmp_path / "minimal_v0.yaml"
    path.write_text(BASE.replace(case.old, case.new, 1), encoding="utf-8")
    assert spec_errors(path) == list(case.errors)


def _sam_with(tmp_path: Path, old: str, new: str) -> list[str]:
    text = SAM_SPEC.read_text(encoding="utf-8")
    assert text.count(old) == 1, old
    path = tmp_path / "interfaces.yaml"
    path.write_text(text.replace(old, new, 1), encoding="utf-8")
    return spec_errors(path)


def test_layout_may_not_split_a_mapping(tmp_path: Path) -> None:
    """One RPMCommand drives both thrusters: a layout that moves only one of them to Cyphal is refused."""
    old = "    devices: {imu: cyphal, magnetometer: cyphal, gps: cyphal, pressure: cyphal, altimeter: cyphal}\n"
    errors = _sam_with(tmp_path, old, old.replace("altimeter: cyphal}", "altimeter: cyphal, thruster_1: cyphal}"))
    assert len(errors) == 1, errors
    assert errors[0].endswith(
        "error: layout 'mixed' puts the devices of dronecan mapping 'thruster_rpms' on different protocols: "
        "thruster_2 on dronecan, thruster_1 on cyphal (expected every device a mapping reaches on its protocol)")
    assert errors[0].startswith("interfaces.yaml:")


def test_layout_may_not_run_two_mappings_of_one_name(tmp_path: Path) -> None:
    """A Cyphal and a DroneCAN mapping may share a name (diagnostics, converters) only if never run together."""
    old = "    thruster_1_feedback:\n      direction: uavcan_to_ros\n      data_type: uavcan.equipment.esc.Status\n"
    errors = _sam_with(tmp_path, old, old.replace("thruster_1_feedback:", "imu:"))
    assert any("error: duplicate key 'imu' in bridge dronecan_mappings" in e for e in errors), errors
    old = "    devices: {imu: cyphal, magnetometer: cyphal, gps: cyphal, pressure: cyphal, altimeter: cyphal}\n"
    # battery_state exists in both protocols; only one runs for the battery, whatever the layout
    assert _sam_with(tmp_path, old, old.replace("altimeter: cyphal}", "altimeter: cyphal, battery: cyphal}")) == []


def test_without_the_standard_definitions_one_clear_error(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                          capsys: pytest.CaptureFixture[str]) -> None:
    empty = tmp_path / "nothing"
    empty.mkdir()
    monkeypatch.setenv("DRONECAN_DSDL_PATH", str(empty))
    errors = spec_errors(SPECS / "minimal_v0.yaml")
    assert errors == [
        "minimal_v0.yaml:15:9: error: unknown DroneCAN type 'uavcan.Timestamp' in DroneCAN type skiff.Bilge "
        "(expected a type of dronecan_types or a standard one, by its full name (e.g. uavcan.Timestamp))",
        "minimal_v0.yaml:37:9: error: the DroneCAN standard types are not available, so "
        "'uavcan.equipment.esc.RPMCommand' of device esc cannot be looked up (expected the `dronecan` package "
        "installed (pip install 'sam-codegen[runtime]') or DRONECAN_DSDL_PATH naming folders that hold uavcan/)",
    ], errors
    assert main(["validate", "--spec", str(SPECS / "minimal_v0.yaml")]) == 1
    assert "Traceback" not in capsys.readouterr().err


def test_dronecan_dsdl_path_replaces_the_package_definitions(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """DRONECAN_DSDL_PATH names folders holding root namespaces: a checkout of its own is read instead."""
    from sam_codegen.catalogs.dronecan import standard_roots

    package = standard_roots()
    uavcan = next(r for r in package if r.name == "uavcan")
    own = tmp_path / "dsdl"
    shutil.copytree(uavcan, own / "uavcan")
    monkeypatch.setenv("DRONECAN_DSDL_PATH", str(own))
    assert standard_roots() == [own / "uavcan"]
    assert spec_errors(SPECS / "minimal_v0.yaml") == []
