# ruff: noqa: E501  (a table of exact diagnostics, one per line, as tests/broken_cases.py)
"""A device's `parameters:` (the settings its board holds, issue 28): what the spec says reaches the model with each
protocol's name, the interface reference documents them per board, and every misuse is one exact error.

The base is tests/specs/minimal_v0.yaml with settings of every type on `gauge` (Cyphal and DroneCAN firmware) and one
on `esc` (DroneCAN only); each case breaks it one way. SAM's spec, tests/specs/glider.yaml (Cyphal) and
tests/specs/lolo_v0.yaml (DroneCAN, AP_Periph-style names) hold real boards' settings.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from broken_cases import Case
from helpers.spec_errors import spec_errors

from sam_codegen.frontend.loader import load_spec_file
from sam_codegen.targets import docs
from sam_codegen.validate.resolve import validate

ROOT = Path(__file__).resolve().parents[2]
SPECS = ROOT / "tests" / "specs"
_GAUGE = """    parameters:
      level.rate_hz: {type: integer, range: [1, 50], unit: Hz, default: 10, description: Output rate.}
      level.offset: {type: real, range: [-1.0, 1.0], unit: m, default: 0.0, cyphal: level.zero_offset}
      level.filter: {type: enum, values: [none, median, mean], default: median, restart: true}
      level.enabled: {type: bool, default: true, dronecan: LVL_ON}
      board.label: {type: string, max_length: 32, default: bow gauge}
"""
_ESC = "    parameters:\n      esc.index: {type: integer, range: [0, 19], default: 0, restart: true}\n"
_BASE = (SPECS / "minimal_v0.yaml").read_text(encoding="utf-8")
BASE = (_BASE.replace("        - {type: skiff.Bilge, rate_hz: 2}\n", "        - {type: skiff.Bilge, rate_hz: 2}\n" + _GAUGE, 1)
        .replace("      - {type: uavcan.equipment.esc.RPMCommand, rate_hz: 10}\n",
                 "      - {type: uavcan.equipment.esc.RPMCommand, rate_hz: 10}\n" + _ESC, 1))

CASES: tuple[Case, ...] = (
    Case('unknown_type', 'level.enabled: {type: bool', 'level.enabled: {type: boolean', (
        "gauge_params.yaml:37:23: error: type 'boolean' of parameter 'level.enabled' of device 'gauge' is unknown (expected bool or integer or real or string or enum)",
    )),
    Case('bad_name_upper', 'level.rate_hz:', 'Level.Rate:', (
        'gauge_params.yaml:34:7: error: parameter \'Level.Rate\' of device \'gauge\': a register name holds lowercase letters, digits, "_" and "." only (expected a name like motor.pole_count (lowercase, digits, \'_\' and \'.\'))',
    )),
    Case('reserved_name', 'level.rate_hz:', 'uavcan.node.id:', (
        'gauge_params.yaml:34:7: error: parameter \'uavcan.node.id\' of device \'gauge\': names under "uavcan." are the standard registers, set from the spec itself (expected a name like motor.pole_count (lowercase, digits, \'_\' and \'.\'))',
    )),
    Case('range_missing', 'range: [1, 50], unit: Hz, ', 'unit: Hz, ', (
        "gauge_params.yaml:34:22: error: parameter 'level.rate_hz' of device 'gauge' is integer: it needs its `range` (expected [minimum, maximum])",
    )),
    Case('range_empty', 'range: [1, 50]', 'range: [50, 1]', (
        "gauge_params.yaml:34:45: error: the range of parameter 'level.rate_hz' of device 'gauge' is empty: 50 > 1 (expected [minimum, maximum])",
    )),
    Case('range_three', 'range: [1, 50]', 'range: [1, 5, 50]', (
        "gauge_params.yaml:34:45: error: the range of parameter 'level.rate_hz' of device 'gauge' must be [minimum, maximum], found 3 elements",
    )),
    Case('range_float_for_integer', 'range: [1, 50]', 'range: [1, 50.5]', (
        "gauge_params.yaml:34:49: error: the range of parameter 'level.rate_hz' of device 'gauge' must be int, found float 50.5 (expected int)",
    )),
    Case('range_beyond_int64', 'range: [1, 50]', 'range: [1, 9223372036854775808]', (
        "gauge_params.yaml:34:45: error: the range of parameter 'level.rate_hz' of device 'gauge': 9223372036854775808 does not fit its type on the wire (expected int64)",
    )),
    Case('range_beyond_float32', 'range: [-1.0, 1.0]', 'range: [-1.0, 1.0e+39]', (
        "gauge_params.yaml:35:41: error: the range of parameter 'level.offset' of device 'gauge': 1e+39 does not fit its type on the wire (expected a finite float32)",
    )),
    Case('default_outside', 'default: 10, description', 'default: 60, description', (
        "gauge_params.yaml:34:64: error: the default 60 of parameter 'level.rate_hz' of device 'gauge' is outside its range [1, 50]",
    )),
    Case('default_wrong_type', 'default: 10, description', 'default: ten, description', (
        "gauge_params.yaml:34:73: error: 'default' of parameter 'level.rate_hz' of device 'gauge' must be int, found str 'ten' (expected int)",
    )),
    Case('default_bool_for_integer', 'default: 10, description', 'default: true, description', (
        "gauge_params.yaml:34:73: error: 'default' of parameter 'level.rate_hz' of device 'gauge' must be int, found bool True (expected int)",
    )),
    Case('default_nan', 'unit: m, default: 0.0', 'unit: m, default: .nan', (
        "gauge_params.yaml:35:63: error: the default of parameter 'level.offset' of device 'gauge' must be finite, found nan",
    )),
    Case('real_without_unit', 'range: [-1.0, 1.0], unit: m, ', 'range: [-1.0, 1.0], ', (
        "gauge_params.yaml:35:21: error: parameter 'level.offset' of device 'gauge' is real: it needs its `unit` (expected an SI unit (REP 103), e.g. m, rad, m/s, 1)",
    )),
    Case('unit_on_bool', 'level.enabled: {type: bool, default: true', 'level.enabled: {type: bool, unit: m, default: true', (
        "gauge_params.yaml:37:35: error: parameter 'level.enabled' of device 'gauge' is bool: `unit` is for integer, real parameters",
    )),
    Case('range_on_string', 'board.label: {type: string, ', 'board.label: {type: string, range: [0, 1], ', (
        "gauge_params.yaml:38:35: error: parameter 'board.label' of device 'gauge' is string: `range` is for integer, real parameters",
    )),
    Case('values_on_integer', 'unit: Hz, default: 10', 'unit: Hz, values: [a], default: 10', (
        "gauge_params.yaml:34:64: error: parameter 'level.rate_hz' of device 'gauge' is integer: `values` is for enum parameters",
    )),
    Case('max_length_on_enum', 'level.filter: {type: enum, ', 'level.filter: {type: enum, max_length: 3, ', (
        "gauge_params.yaml:36:34: error: parameter 'level.filter' of device 'gauge' is enum: `max_length` is for string parameters",
    )),
    Case('enum_without_values', 'values: [none, median, mean], ', '', (
        "gauge_params.yaml:36:21: error: parameter 'level.filter' of device 'gauge' is enum: it needs its `values` (expected {name: integer, ...} or a list of names)",
    )),
    Case('enum_default_not_a_value', 'default: median', 'default: max', (
        "gauge_params.yaml:36:64: error: the default 'max' of parameter 'level.filter' of device 'gauge' is not one of its values (expected none, median, mean)",
    )),
    Case('enum_empty', 'values: [none, median, mean]', 'values: []', (
        "gauge_params.yaml:36:42: error: parameter 'level.filter' of device 'gauge' has no values (expected at least one name)",
    )),
    Case('enum_shared_integer', 'values: [none, median, mean]', 'values: {none: 0, median: 1, mean: 1}', (
        "gauge_params.yaml:36:42: error: value 'median' of parameter 'level.filter' of device 'gauge' shares the integer 1 with another value (expected one integer per name)",
    )),
    Case('string_too_long_default', 'default: bow gauge', 'default: xxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxx', (
        "gauge_params.yaml:38:51: error: the default of parameter 'board.label' of device 'gauge' is 40 bytes long, more than its max_length 32",
    )),
    Case('max_length_beyond_dronecan', 'max_length: 32', 'max_length: 200', (
        "gauge_params.yaml:38:35: error: max_length 200 of parameter 'board.label' of device 'gauge' is outside 1..128 (expected what DroneCAN carries in a string value)",
    )),
    Case('dronecan_name_with_space', 'dronecan: LVL_ON', 'dronecan: LVL ON', (
        "gauge_params.yaml:37:50: error: parameter 'level.enabled' of device 'gauge': DroneCAN parameter name 'LVL ON': a DroneCAN parameter name is printable ASCII without spaces",
    )),
    Case('cyphal_name_upper', 'cyphal: level.zero_offset', 'cyphal: Level.Zero', (
        'gauge_params.yaml:35:77: error: parameter \'level.offset\' of device \'gauge\': Cyphal register name \'Level.Zero\': a register name holds lowercase letters, digits, "_" and "." only',
    )),
    Case('two_on_one_name', 'dronecan: LVL_ON', 'dronecan: LEVEL_RATE_HZ', (
        "gauge_params.yaml:37:7: error: parameters 'level.rate_hz' and 'level.enabled' of device 'gauge' are both parameter 'LEVEL_RATE_HZ' on DroneCAN (expected a name of its own on each protocol)",
    )),
    Case('unknown_key', 'restart: true}', 'restart: true, reboot: true}', (
        "gauge_params.yaml:36:96: error: unknown field 'reboot' in parameter 'level.filter' of device 'gauge' (expected one of type, default, description, restart, max_length, range, unit, values, cyphal, dronecan)",
    )),
    Case('restart_not_bool', 'restart: true}', 'restart: yes please}', (
        "gauge_params.yaml:36:90: error: 'restart' of parameter 'level.filter' of device 'gauge' must be bool, found str 'yes please' (expected bool)",
    )),
    Case('parameters_not_a_mapping', '    parameters:\n      level.rate_hz:', '    parameters: []\n    xparameters:\n      level.rate_hz:', (
        "gauge_params.yaml:33:17: error: the parameters of device 'gauge' must be a mapping, found a list (expected a mapping)",
        "gauge_params.yaml:34:5: error: unknown field 'xparameters' in device 'gauge' (expected one of node_id, description, protocol, publishes, subscribes, parameters, cyphal, dronecan)",
    )),
    Case('name_for_a_protocol_the_board_lacks', 'esc.index: {type: integer,', 'esc.index: {cyphal: esc.idx, type: integer,', (
        "gauge_params.yaml:45:19: error: parameter 'esc.index' of device 'esc' names its Cyphal register, but the board has no Cyphal firmware (expected a name for dronecan only)",
    )),
)


def _write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "gauge_params.yaml"
    path.write_text(text, encoding="utf-8")
    return path


def test_the_settings_reach_the_model_with_each_protocols_name(tmp_path: Path) -> None:
    assert _GAUGE in BASE and _ESC in BASE
    devices = load_spec_file(_write(tmp_path, BASE)).devices
    gauge = {p.name: p for p in devices["gauge"].parameters}
    assert list(gauge) == ["level.rate_hz", "level.offset", "level.filter", "level.enabled", "board.label"]
    rate, offset, filter_, enabled, label = gauge.values()
    assert (rate.type, rate.minimum, rate.maximum, rate.unit, rate.default, rate.restart) == ("integer", 1, 50, "Hz", 10, False)
    assert rate.description == "Output rate."
    assert rate.names == (("cyphal", "level.rate_hz"), ("dronecan", "LEVEL_RATE_HZ"))
    assert offset.names == (("cyphal", "level.zero_offset"), ("dronecan", "LEVEL_OFFSET"))
    assert isinstance(offset.default, float) and (offset.minimum, offset.maximum) == (-1.0, 1.0)
    assert filter_.values == (("none", 0), ("median", 1), ("mean", 2)) and filter_.stored(filter_.default) == 1
    assert filter_.restart and filter_.minimum is None
    assert enabled.default is True and enabled.name_on("dronecan") == "LVL_ON"
    assert (label.max_length, label.default) == (32, "bow gauge")
    (index,) = devices["esc"].parameters  # DroneCAN firmware only: no register name
    assert index.names == (("dronecan", "ESC_INDEX"),)
    assert devices["servo"].parameters == ()


def test_a_string_takes_the_longest_value_its_protocols_carry(tmp_path: Path) -> None:
    text = BASE.replace("{type: string, max_length: 32, default: bow gauge}", "{type: string, default: bow gauge}")
    label = next(p for p in load_spec_file(_write(tmp_path, text)).devices["gauge"].parameters if p.name == "board.label")
    assert label.max_length == 128  # DroneCAN's string_value, shorter than a register's string


@pytest.mark.parametrize("case", CASES, ids=lambda c: c.name)
def test_a_misused_setting_is_one_exact_error(case: Case, tmp_path: Path) -> None:
    assert case.old in BASE, f"case {case.name} no longer applies"
    assert spec_errors(_write(tmp_path, BASE.replace(case.old, case.new, 1))) == list(case.errors)


@pytest.mark.parametrize("spec", [ROOT / "spec" / "interfaces.yaml", SPECS / "glider.yaml", SPECS / "lolo_v0.yaml"],
                         ids=lambda p: p.name)
def test_the_interface_reference_documents_every_boards_settings(spec: Path) -> None:
    resolved = validate(load_spec_file(spec))
    md = docs.emit(resolved)[docs.MD_PATH]
    boards = [d for d in resolved.spec.devices.values() if d.parameters]
    assert boards and "### Device parameters" in md
    for d in boards:
        section = md.split(f"#### `{d.name}` (node {d.node_id})", 1)[1].split("####", 1)[0]
        for p in d.parameters:
            row = next(line for line in section.splitlines() if line.startswith(f"| `{p.name}` |"))
            cells = [c.strip() for c in row.strip("|").split("|")]
            assert cells[1] == p.type and cells[5] == ("yes" if p.restart else "no"), row
            for protocol, wire in p.names:
                assert f"`{wire}`" in cells[6], (p.name, protocol)
            if p.minimum is not None:
                assert cells[2].startswith("[") and cells[2].endswith("]"), row
