"""The interface version (sam_codegen.validate.interface_version): one hash per board and for the whole spec, the
same whatever the YAML's formatting, comments and order, different when anything a board's firmware must agree on
changes (its node id, a port, a type it carries or one nested in it, a setting), and only that board's."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
import yaml

from sam_codegen.frontend.loader import load_spec_file
from sam_codegen.model.diagnostics import SpecError
from sam_codegen.targets.python.convert import emit as emit_python
from sam_codegen.validate.interface_version import InterfaceVersions, hash_form, hex_hash, interface_versions
from sam_codegen.validate.resolve import validate

ROOT = Path(__file__).resolve().parents[2]
GLIDER = ROOT / "tests" / "specs" / "glider.yaml"
LOLO = ROOT / "tests" / "specs" / "lolo_v0.yaml"


def tables_py(resolved: Any) -> str:
    return next(text for path, text in emit_python(resolved).items() if path.endswith("/tables.py"))


def versions_of(data: dict[str, Any], tmp_path: Path, name: str = "spec.yaml") -> InterfaceVersions:
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    return interface_versions(validate(load_spec_file(path)))


def changed(before: InterfaceVersions, after: InterfaceVersions) -> set[str]:
    return {name for (name, a), (_, b) in zip(before.boards, after.boards, strict=True) if a != b}


def test_hash_is_a_nonzero_uint64() -> None:
    assert 0 < hash_form({"a": 1}) < 2**64
    assert hash_form({"a": 1}) == hash_form({"a": 1}) != hash_form({"a": 2})
    assert hex_hash(0xAB) == "00000000000000ab"


@pytest.mark.parametrize("spec", [GLIDER, LOLO], ids=["glider", "lolo_v0"])
def test_independent_of_formatting_comments_and_order(spec: Path, tmp_path: Path) -> None:
    original = interface_versions(validate(load_spec_file(spec)))
    data = yaml.safe_load(spec.read_text(encoding="utf-8"))
    # no comments, flow style, other line breaks; devices, ports and settings in reverse order
    data["devices"] = dict(reversed(list(data["devices"].items())))
    for device in data["devices"].values():
        for key in ("publishes", "subscribes"):
            if key in device:
                device[key] = list(reversed(device[key]))
        if "parameters" in device:
            device["parameters"] = dict(reversed(list(device["parameters"].items())))
    path = tmp_path / "reformatted.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=True, default_flow_style=True, width=60), encoding="utf-8")
    again = interface_versions(validate(load_spec_file(path)))
    assert dict(again.boards) == dict(original.boards)
    assert again.whole == original.whole


def _set(path: tuple[Any, ...], value: Any) -> Callable[[dict[str, Any]], None]:
    def apply(data: dict[str, Any]) -> None:
        node = data
        for key in path[:-1]:
            node = node[key]
        node[path[-1]] = value
    return apply


GLIDER_CHANGES: dict[str, tuple[Callable[[dict[str, Any]], None], set[str]]] = {
    # what changes -> which boards' hashes change
    "node id": (lambda d: (_set(("devices", "altimeter", "node_id"), 24)(d),
                           _set(("bridge", "mappings", "altitude", "source_node_ids"), [24])(d)), {"altimeter"}),
    "subject id": (lambda d: (_set(("devices", "ctd", "publishes", 0, "subject_id"), 631)(d),
                              _set(("bridge", "mappings", "ctd_altitude", "subject_id"), 631)(d)), {"ctd"}),
    "a field of a type it receives": (_set(("dsdl_types", "glider.pump.Command.0.1", "fields", 0, "type"), "int13"),
                                      {"pump"}),
    "a type two boards carry": (_set(("dsdl_types", "glider.sensor.Altitude.0.1", "fields", 2, "type"), "uint8"),
                                {"altimeter", "ctd"}),
    "a setting's default": (_set(("devices", "pump", "parameters", "pump.volume_limit", "default"), 0.0004), {"pump"}),
    "a setting's name on Cyphal": (_set(("devices", "ctd", "parameters", "ctd.pumped", "cyphal"), "ctd.pump_on"),
                                   {"ctd"}),
    "a setting's range": (_set(("devices", "ctd", "parameters", "ctd.sample_rate", "range"), [1, 8]), {"ctd"}),
    "a rate (not part of it)": (_set(("devices", "ctd", "publishes", 0, "rate_hz"), 4), set()),
    "a description (not part of it)": (_set(("devices", "pump", "parameters", "pump.volume_limit", "description"),
                                            "Other words."), set()),
}


@pytest.mark.parametrize("what", list(GLIDER_CHANGES))
def test_glider_changes(what: str, tmp_path: Path) -> None:
    data = yaml.safe_load(GLIDER.read_text(encoding="utf-8"))
    before = versions_of(data, tmp_path, "before.yaml")
    change, boards = GLIDER_CHANGES[what]
    change(data)
    after = versions_of(data, tmp_path, "after.yaml")
    assert changed(before, after) == boards
    assert (after.whole != before.whole) == bool(boards)


def test_dronecan_type_and_setting_changes(tmp_path: Path) -> None:
    data = yaml.safe_load(LOLO.read_text(encoding="utf-8"))
    before = versions_of(data, tmp_path, "before.yaml")
    # the spec's own DroneCAN type gets another id: its data type id, a port of the power board
    data["dronecan_types"]["sabre.power.ConsumedChargeArray"]["id"] = 20101
    after = versions_of(data, tmp_path, "id.yaml")
    assert changed(before, after) == {"power_board"}
    # a setting's name on DroneCAN
    data["devices"]["esc_port"]["parameters"]["esc.poles"]["dronecan"] = "MOT_POLES"
    assert changed(after, versions_of(data, tmp_path, "name.yaml")) == {"esc_port"}


@pytest.mark.parametrize(("value", "expected"), [(None, "warn"), ({"on_mismatch": "stop"}, "stop"),
                                                 ({"on_mismatch": "warn"}, "warn")])
def test_the_bridge_option(value: Any, expected: str, tmp_path: Path) -> None:
    data = yaml.safe_load(GLIDER.read_text(encoding="utf-8"))
    if value is not None:
        data["bridge"]["interface_check"] = value
    path = tmp_path / "spec.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    resolved = validate(load_spec_file(path))
    assert resolved.spec.bridge is not None and resolved.spec.bridge.interface_on_mismatch == expected
    assert f"INTERFACE_ON_MISMATCH: str = {expected!r}" in tables_py(resolved)


def test_an_unknown_on_mismatch_is_an_error(tmp_path: Path) -> None:
    data = yaml.safe_load(GLIDER.read_text(encoding="utf-8"))
    data["bridge"]["interface_check"] = {"on_mismatch": "halt", "retries": 3}
    path = tmp_path / "spec.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    with pytest.raises(SpecError) as info:
        load_spec_file(path)
    text = str(info.value)
    assert "on_mismatch 'halt' of bridge interface_check is unknown (expected warn or stop)" in text
    assert "retries" in text
