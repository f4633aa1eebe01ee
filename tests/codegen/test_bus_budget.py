"""The bus budget's numbers: frame rules against the protocol libraries (pycyphal's Cyphal/CAN serializer, dronecan's
v0 frames), serialized sizes against pydsdl and dronecan, hand-computed single- and multi-frame examples on each
protocol, and SAM's layouts."""

from __future__ import annotations

from functools import cache
from pathlib import Path
from typing import Any

import pydsdl
import pytest
from helpers.spec_errors import spec_errors

from sam_codegen.frontend.loader import load_spec_file
from sam_codegen.model.diagnostics import Pos, SpecError
from sam_codegen.validate.bus_budget import (
    Bus,
    LayoutBudget,
    NodeBudget,
    Transfer,
    classic_frame_bits,
    cyphal_frame_lengths,
    cyphal_max_bytes,
    dronecan_frame_lengths,
    dronecan_max_bytes,
    fd_frame_bits,
    layout_budgets,
)
from sam_codegen.validate.resolve import Resolved, validate

REPO = Path(__file__).resolve().parents[2]


@cache
def sam() -> Resolved:
    return validate(load_spec_file(REPO / "spec" / "interfaces.yaml"))


def budgets(resolved: Resolved, *, fd: bool | None = None) -> dict[str, LayoutBudget]:
    found = layout_budgets(resolved.spec, resolved.layouts,
                           {"cyphal": resolved.mappings, "dronecan": resolved.dronecan_mappings},
                           resolved.dsdl.get, resolved.dronecan.get if resolved.dronecan else lambda _: None, fd=fd)
    return {b.layout: b for b in found}


# ---- frames per transfer, as the libraries make them -------------------------------------------------------------

@pytest.mark.parametrize("mtu", [8, 64])
def test_cyphal_frames_are_pycyphals(mtu: int) -> None:
    pytest.importorskip("pycyphal")
    from pycyphal.transport.can._session._transfer_sender import serialize_transfer

    for n in range(300):
        frames = serialize_transfer(0x107D552A, 3, [memoryview(bytes(n))], mtu - 1)
        assert [len(f.compile().data) for f in frames] == cyphal_frame_lengths(n, mtu), n


def test_dronecan_frames_are_dronecans() -> None:
    transport = pytest.importorskip("dronecan.transport")
    for n in range(300):
        t = transport.Transfer(transfer_id=1, source_node_id=11, transfer_priority=20)
        t.payload, t.data_type_id, t.data_type_signature, t.data_type_crc = bytes(n), 1003, 0x8280632C40E574B5, 0xFFFF
        assert [len(f.bytes) for f in t.to_frames()] == dronecan_frame_lengths(n), n


def test_frame_bits_agree_with_the_runtimes_bus_meter() -> None:
    from sam_runtime.dronecan_io.bus_load import frame_bits

    for n in range(9):
        assert classic_frame_bits(n) == frame_bits(n)
        assert classic_frame_bits(n, worst_case=True) == frame_bits(n, worst_case_stuffing=True)


# ---- serialized sizes -------------------------------------------------------------------------------------------

def test_cyphal_sizes_are_pydsdls() -> None:
    resolved = sam()
    generated = REPO / "generated" / "dsdl"
    types = pydsdl.read_namespace(generated / "sam", [str(r) for r in resolved.dsdl.roots])
    heartbeat = resolved.dsdl.get("uavcan.node.Heartbeat.1.0")
    assert heartbeat is not None and cyphal_max_bytes(heartbeat, resolved.dsdl.get) == 7
    assert types
    for t in types:
        struct = resolved.dsdl.get(f"{t.full_name}.{t.version.major}.{t.version.minor}")
        assert struct is not None
        # A top-level type's payload is its own fields (a delimited type's header only goes with nesting).
        largest = max(t.inner_type.bit_length_set if isinstance(t, pydsdl.DelimitedType) else t.bit_length_set)
        assert cyphal_max_bytes(struct, resolved.dsdl.get) == largest // 8, t.full_name


def _filled(value: Any) -> Any:
    """A dronecan message with every dynamic array at its capacity."""
    for f in value._type.fields:
        ft = f.type
        if ft.category == ft.CATEGORY_COMPOUND:
            _filled(getattr(value, f.name))
        elif ft.category == ft.CATEGORY_ARRAY:
            array, item = getattr(value, f.name), ft.value_type
            while ft.mode == ft.MODE_DYNAMIC and len(array) < ft.max_size:
                array.append(array.new_item() if item.category == item.CATEGORY_COMPOUND else 0)
            if item.category == item.CATEGORY_COMPOUND:
                for element in array:
                    _filled(element)
    return value


def test_dronecan_sizes_are_dronecans_with_the_tail_array_optimisation() -> None:
    dronecan = pytest.importorskip("dronecan")
    from dronecan import transport

    resolved = sam()
    assert resolved.dronecan is not None
    names = {p.type for d in resolved.spec.devices.values() for p in d.dronecan_publishes + d.dronecan_subscribes}
    standard = [*sorted(n for n in names if n in dronecan.TYPENAMES), "uavcan.protocol.NodeStatus"]
    assert "uavcan.equipment.ahrs.RawIMU" in standard and "uavcan.equipment.gnss.Fix2" in standard
    for name in standard:
        struct = resolved.dronecan.get(name)
        assert struct is not None
        largest = len(transport.Transfer(payload=_filled(dronecan.TYPENAMES[name]())).payload)
        assert dronecan_max_bytes(struct, resolved.dronecan.get) == largest, name


def test_a_broadcast_command_counts_the_elements_its_mapping_writes() -> None:
    resolved = sam()
    assert resolved.dronecan is not None
    array_command = resolved.dronecan.get("uavcan.equipment.actuator.ArrayCommand")
    rpm_command = resolved.dronecan.get("uavcan.equipment.esc.RPMCommand")
    assert array_command is not None and rpm_command is not None
    # Command: actuator_id uint8, command_type uint8, command_value float16 = 4 bytes; the tail array has no prefix.
    assert dronecan_max_bytes(array_command, resolved.dronecan.get) == 60  # 15 commands
    assert dronecan_max_bytes(array_command, resolved.dronecan.get, {"commands": 2}) == 8
    assert dronecan_max_bytes(rpm_command, resolved.dronecan.get, {"rpm": 2}) == 5  # 2 x int18 = 36 bits


# ---- hand-computed examples -------------------------------------------------------------------------------------
# Classic frame, 29-bit id: 67 + 8 * DLC bits (131 for 8 bytes); worst-case stuffing adds (54 + 8 * DLC - 1) // 4.
# CAN FD: 48 bits at the nominal rate, 32 + 8 * DLC (DLC <= 16) or 37 + 8 * DLC at the data rate.

CLASSIC = Bus()
FD = Bus(1_000_000, 4_000_000)


def test_cyphal_single_frame_staticpressure_at_20_hz() -> None:
    t = Transfer("sam.sensor.StaticPressure.0.1", 20.0, 6, "cyphal")  # float32 + float16 = 6 bytes
    assert t.frame_lengths(CLASSIC) == [7]  # 6 + the tail byte
    assert t.frames_per_s(CLASSIC) == 20.0
    assert t.bus_seconds_per_s(CLASSIC) == pytest.approx(20 * (67 + 56) / 1e6)  # 0.246 %
    assert t.bus_seconds_per_s(CLASSIC, worst_case=True) == pytest.approx(20 * (123 + (54 + 56 - 1) // 4) / 1e6)
    assert t.frame_lengths(FD) == [7]
    assert t.bus_seconds_per_s(FD) == pytest.approx(20 * (48 / 1e6 + (32 + 56) / 4e6))


def test_a_huge_payload_is_budgeted_arithmetically() -> None:
    """Issue 29 item 9: a payload of 10^9 bytes (a `uint8[<=1000000000]`) is 1.4 * 10^8 frames; listing them one by
    one raised MemoryError. The split is computed: the same figures as the frame-by-frame rule for small payloads."""
    for protocol in ("cyphal", "dronecan"):
        for n in (0, 7, 8, 62, 63, 64, 121, 500):
            t = Transfer("x", 1.0, n, protocol)
            for bus in (CLASSIC, FD):
                assert t.frame_count(bus) == len(t.frame_lengths(bus)), (protocol, n)
        huge = Transfer("x", 10.0, 10 ** 9, protocol)
        assert huge.frame_count(CLASSIC) == -(-(10 ** 9 + 2) // 7)
        assert huge.frames_per_s(CLASSIC) == 10 * huge.frame_count(CLASSIC)
        assert huge.bus_seconds_per_s(CLASSIC) > 1000  # far over any bus, and said so without materialising a list
    assert Transfer("x", 1.0, 10 ** 9, "cyphal").frame_count(FD) == -(-(10 ** 9 + 2) // 63)


def test_cyphal_multi_frame_rawimu_at_100_hz() -> None:
    t = Transfer("sam.sensor.RawIMU.0.1", 100.0, 120, "cyphal")
    # Classic: 120 + 2 CRC = 122 bytes, 7 a frame: 17 full frames and 3 bytes + tail in the last.
    assert t.frame_lengths(CLASSIC) == [8] * 17 + [4]
    assert t.frames_per_s(CLASSIC) == 1800.0
    assert t.bus_seconds_per_s(CLASSIC) == pytest.approx(100 * (17 * 131 + 99) / 1e6)  # 23.26 %
    # CAN FD: 63 a frame: 64 + 59 + tail = 60, padded to the DLC length 64.
    assert t.frame_lengths(FD) == [64, 64]
    assert t.bus_seconds_per_s(FD) == pytest.approx(100 * 2 * (48 / 1e6 + (37 + 512) / 4e6))  # 3.705 %


def test_dronecan_single_and_multi_frame() -> None:
    pressure = Transfer("uavcan.equipment.air_data.StaticPressure", 20.0, 6, "dronecan")
    assert pressure.frame_lengths(CLASSIC) == [7] and pressure.frames_per_s(CLASSIC) == 20.0
    assert pressure.bus_seconds_per_s(CLASSIC) == pytest.approx(20 * 123 / 1e6)
    imu = Transfer("uavcan.equipment.ahrs.RawIMU", 100.0, 119, "dronecan")
    # 2 CRC first + 119 = 121 bytes, 7 a frame: 17 full frames and 2 bytes + tail in the last.
    assert imu.frame_lengths(CLASSIC) == [8] * 17 + [3]
    assert imu.bus_seconds_per_s(CLASSIC) == pytest.approx(100 * (17 * 131 + 91) / 1e6)
    # DroneCAN stays classic on a CAN FD bus.
    assert imu.frame_lengths(FD) == imu.frame_lengths(CLASSIC)
    assert imu.bus_seconds_per_s(FD) == imu.bus_seconds_per_s(CLASSIC)


def test_the_usual_figures_of_a_saturated_bus() -> None:
    assert round(1e6 / classic_frame_bits(8)) == 7634  # "~7,600 frames/s"
    assert 1e6 / classic_frame_bits(8, worst_case=True) == 6250  # "~6,250 with worst-case stuffing"
    assert fd_frame_bits(64) == (48, 549)


# ---- SAM's layouts and the verdicts -----------------------------------------------------------------------------

def test_sams_layouts() -> None:
    found = budgets(sam())
    assert set(found) == {"default", "dronecan", "mixed"}
    summary = {name: (round(b.frames_per_s), round(100 * b.load, 1), round(100 * b.load_worst_case, 1), b.verdict)
               for name, b in found.items()}
    assert summary == {"default": (2297, 29.3, 35.8, "ok"), "dronecan": (2421, 31.0, 37.8, "ok"),
                       "mixed": (2307, 29.6, 36.1, "ok")}
    imu = next(n for n in found["dronecan"].nodes if n.name == "imu")
    assert imu.frames_per_s(found["dronecan"].bus) == 18 * 100 + 1  # RawIMU at its largest + NodeStatus
    bridge = [n for n in found["mixed"].nodes if n.name == "uavcan_ros_bridge"]
    assert [n.protocol for n in bridge] == ["cyphal", "dronecan"]
    fd = budgets(sam(), fd=True)
    assert round(fd["default"].frames_per_s) == 409 and fd["dronecan"].frames_per_s == found["dronecan"].frames_per_s


def _one_node(rate: float, bus: Bus) -> LayoutBudget:
    node = NodeBudget("imu", 11, "dronecan", (Transfer("uavcan.equipment.ahrs.RawIMU", rate, 119, "dronecan"),))
    return LayoutBudget("test", bus, (node,), Pos("spec.yaml", 3, 5))


def test_warning_above_the_threshold_and_error_above_capacity() -> None:
    # One RawIMU transfer: 17 x 160 + 115 = 2835 bits with worst-case stuffing.
    ok = _one_node(200.0, Bus())  # 56.7 %
    assert ok.verdict == "ok" and ok.warning() is None and ok.diagnostic() is None
    warn = _one_node(300.0, Bus())  # 85.1 %
    assert warn.verdict == "above 70 %" and warn.diagnostic() is None
    assert warn.warning() == ("spec.yaml:3:5: warning: layout 'test' uses 85 % of its bus with worst-case stuffing, "
                              "above the 70 % threshold")
    assert _one_node(300.0, Bus(warning_percent=90.0)).warning() is None
    over = _one_node(400.0, Bus())  # 113.4 %
    diagnostic = over.diagnostic()
    assert over.verdict == "over capacity" and over.warning() is None and diagnostic is not None
    assert str(diagnostic).startswith("spec.yaml:3:5: error: layout 'test' needs 113 % of its bus (classic CAN "
                                      "1 Mbit/s, worst-case bit stuffing; 7,200 frames/s; most from imu: 113 %)")


def _minimal(tmp_path: Path, rate: str) -> Path:
    text = (REPO / "tests" / "specs" / "minimal.yaml").read_text()
    assert "type: buoy.Level.0.1, rate_hz: 10}" in text
    spec = tmp_path / "spec" / "interfaces.yaml"
    spec.parent.mkdir(parents=True)
    spec.write_text(text.replace("type: buoy.Level.0.1, rate_hz: 10}", f"type: buoy.Level.0.1, rate_hz: {rate}}}"))
    return spec


def test_build_prints_the_budget_and_refuses_a_bus_it_overloads(tmp_path: Path) -> None:
    from sam_codegen.build import generate

    lines: list[str] = []
    generate(_minimal(tmp_path / "ok", "10"), report=lines.append)
    assert lines == ["bus budget: layout default: 24 frames/s on classic CAN 1 Mbit/s, load 0.3 % (0.4 % with "
                     "worst-case stuffing): ok"]
    lines.clear()
    spec = _minimal(tmp_path / "busy", "3000")  # one frame each: 3000 x 160 bits = 48 % worst case + the rest
    generate(spec, report=lines.append)
    assert lines[-1].startswith(f"{spec}:") and ": warning: layout 'default' uses" in lines[-1]
    with pytest.raises(SpecError) as info:
        generate(_minimal(tmp_path / "over", "8000"))
    (diagnostic,) = info.value.diagnostics
    text = (tmp_path / "over" / "spec" / "interfaces.yaml").read_text().splitlines()
    assert "buoy.Level.0.1, rate_hz: 8000" in "\n".join(text[diagnostic.pos.line - 1: diagnostic.pos.line + 6])
    assert "error: layout 'default' needs" in str(diagnostic) and "most from" in str(diagnostic)


# ---- the spec's `bus` key ---------------------------------------------------------------------------------------

def _spec_with(tmp_path: Path, old: str, new: str) -> Path:
    text = (REPO / "tests" / "specs" / "minimal.yaml").read_text()
    assert old in text
    spec = tmp_path / "minimal.yaml"
    spec.write_text(text.replace(old, new, 1))
    return spec


LAYOUT = "  all_dronecan: {description: Everything on DroneCAN., protocol: dronecan}"
BUS_CASES = {
    "not_a_mapping": ("bus: fast\n", ["minimal.yaml:{line}:6: error: bus must be a mapping or none, found str 'fast' "
                                       "(expected {{bitrate: ..., fd_data_bitrate: ..., load_warning_percent: ...}} "
                                       "or none)"]),
    "unknown_key": ("bus: {speed: 5}\n", ["minimal.yaml:{line}:7: error: unknown field 'speed' in bus (expected one of "
                                            "bitrate, fd_data_bitrate, load_warning_percent)"]),
    "bitrate_range": ("bus: {bitrate: 2000000}\n", ["minimal.yaml:{line}:7: error: bitrate 2000000 of bus is out of "
                                                     "range (expected 10000..1000000 bit/s (classic CAN, or CAN FD's "
                                                     "arbitration phase))"]),
    "data_below_nominal": ("bus: {bitrate: 500000, fd_data_bitrate: 250000}\n",
                           ["minimal.yaml:{line}:24: error: fd_data_bitrate 250000 of bus is out of range (expected "
                            "500000..12000000 bit/s (at least the bitrate))"]),
    "warning_range": ("bus: {load_warning_percent: 0}\n", ["minimal.yaml:{line}:7: error: load_warning_percent 0 of "
                                                           "bus is out of range (expected a percentage above 0, at "
                                                           "most 100)"]),
    "bitrate_type": ("bus: {bitrate: 1000000.0}\n", ["minimal.yaml:{line}:16: error: 'bitrate' of bus must be int, "
                                                     "found float 1000000.0 (expected int)"]),
}


@pytest.mark.parametrize("name", sorted(BUS_CASES))
def test_a_wrong_bus_is_a_spec_error_at_its_key(name: str, tmp_path: Path) -> None:
    text, errors = BUS_CASES[name]
    base = (REPO / "tests" / "specs" / "minimal.yaml").read_text()
    line = base[: base.index("devices:")].count("\n") + 1
    spec = _spec_with(tmp_path, "devices:\n", text + "devices:\n")
    assert spec_errors(spec) == [e.format(line=line) for e in errors]


def test_the_spec_sets_the_bus_and_a_layout_its_own(tmp_path: Path) -> None:
    spec = _spec_with(tmp_path, "devices:\n", "bus: {bitrate: 500000, fd_data_bitrate: 2000000, "
                      "load_warning_percent: 50}\ndevices:\n")
    resolved = validate(load_spec_file(spec))
    (budget,) = budgets(resolved).values()
    assert budget.bus == Bus(500_000, 2_000_000, 50.0, budget.bus.pos) and budget.bus.fd
    assert budget.bus.describe() == "CAN FD 500 kbit/s, data 2 Mbit/s"
    v0 = (REPO / "tests" / "specs" / "buoy_v0.yaml").read_text()
    assert LAYOUT in v0
    layout_spec = tmp_path / "buoy_v0.yaml"
    layout_spec.write_text(v0.replace(LAYOUT, LAYOUT[:-1] + ", bus: {bitrate: 125000}}", 1))
    found = budgets(validate(load_spec_file(layout_spec)))
    assert found["default"].bus == Bus() and found["all_dronecan"].bus.bitrate == 125_000


def test_bus_none_has_no_budget(tmp_path: Path) -> None:
    from sam_codegen.build import generate

    spec = _spec_with(tmp_path, "type: buoy.Level.0.1, rate_hz: 10}", "type: buoy.Level.0.1, rate_hz: 100000}")
    assert spec_errors(spec) and "needs" in spec_errors(spec)[0]  # 100 kHz on one bus: refused ...
    text = spec.read_text().replace("devices:\n", "bus: none\ndevices:\n", 1)
    spec.write_text(text)
    lines: list[str] = []
    files = generate(spec, report=lines.append)  # ... unless the vehicle has no CAN bus
    assert lines == [] and "## CAN bus budget" not in files["docs/interfaces.md"]


def test_the_overload_of_a_named_layout_is_reported_at_its_bus(tmp_path: Path) -> None:
    v0 = (REPO / "tests" / "specs" / "buoy_v0.yaml").read_text()
    spec = tmp_path / "buoy_v0.yaml"
    changed = LAYOUT[:-1] + ", bus: {bitrate: 10000}}"
    assert "{type: spar.Status, rate_hz: 2}" in v0
    spec.write_text(v0.replace(LAYOUT, changed, 1).replace("{type: spar.Status, rate_hz: 2}",
                                                           "{type: spar.Status, rate_hz: 200}", 1))
    errors = spec_errors(spec)
    lines = spec.read_text().splitlines()
    line = lines.index(changed) + 1
    column = changed.index("bus: {") + len("bus: ") + 1
    assert len(errors) == 1 and errors[0].startswith(f"buoy_v0.yaml:{line}:{column}: error: layout 'all_dronecan' "
                                                     "needs ")
