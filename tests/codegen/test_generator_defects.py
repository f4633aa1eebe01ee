"""Regression tests of issue 11's generator defects, on specs of our own: tests/specs/tractor.yaml (a hitch
controller with a fixed wire format), variants of it, and a spec written here with every signed array width.

5. arrays of signed integers narrower than 8 bits (and int15/int31/int63 arrays with negative values) could not
   be serialized (nunavut 2.3 under numpy 2): the runtime's DSDL compile fixes the serializer (runtime/nunavut_fix);
7. a UAVCAN->ROS table must give every value of its source a ROS value, or a `default`;
8. no follow-on errors (failed derive_from, unknown field types, rejected fields), and an output folder problem
   is not a spec error;
9. per-element links into fixed arrays of composites, with coverage per element;
10. `void N` padding fields.

The converters of tractor.yaml run with real classes in tests/test_converters.py (hypothesis round trips).
"""

from __future__ import annotations

import importlib
import importlib.util
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pydsdl
import pytest
from helpers.spec_errors import spec_errors

from sam_codegen.build import MARKER, generate
from sam_codegen.cli import main
from sam_codegen.frontend.loader import load_spec_file
from sam_codegen.validate.resolve import validate

ROOT = Path(__file__).resolve().parents[2]
SPECS = Path(__file__).parents[1] / "specs"
TRACTOR = SPECS / "tractor.yaml"
TRACTOR_TEXT = TRACTOR.read_text(encoding="utf-8")

needs_pycyphal = pytest.mark.skipif(importlib.util.find_spec("pycyphal") is None,
                                    reason="pycyphal is not installed (pip extra 'runtime')")


def _variant(tmp_path: Path, *changes: tuple[str, str]) -> Path:
    """tractor.yaml with each (old, new) replaced once; `old` must be there."""
    text = TRACTOR_TEXT
    for old, new in changes:
        assert text.count(old) == 1, old
        text = text.replace(old, new)
    path = tmp_path / "tractor.yaml"
    path.write_text(text, encoding="utf-8")
    return path


def test_tractor_spec_is_valid() -> None:
    assert spec_errors(TRACTOR) == []


# ---- 5: narrow signed integer arrays -----------------------------------------------------------------------

# One type per width: a single type of all of them is beyond pydsdl's recursion limit.
_SIGNED_TYPES = "".join(
    f"  widthcheck.Signed{w}.1.0:\n    sealed: true\n    fields:\n      - {{name: flag, type: bool}}\n"
    f"      - {{name: fixed, type: \"int{w}[2]\"}}\n      - {{name: bounded, type: \"int{w}[<=2]\"}}\n"
    for w in range(2, 65))
WIDTHS_SPEC = """\
spec_version: 1
vehicle: {name: bench}
ros: {package: widthcheck_msgs}
cyphal: {root_namespace: widthcheck}
dsdl_types:
  widthcheck.Padded.1.0:
    sealed: true
    fields:
      - {name: rate, type: uint12}
      - {type: void4}
      - {name: open, type: bool}
      - {type: void7, comment: Reserved.}
""" + _SIGNED_TYPES


@pytest.fixture(scope="module")
def widthcheck(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Any]:
    """The widths spec generated, compiled by the runtime (its DSDL cache) and imported."""
    from sam_runtime.cyphal_io.dsdl_cache import ensure_compiled

    folder = tmp_path_factory.mktemp("widthcheck")
    spec = folder / "widths.yaml"
    spec.write_text(WIDTHS_SPEC, encoding="utf-8")
    for path, text in generate(spec).items():
        if path.startswith("dsdl/"):
            (folder / path).parent.mkdir(parents=True, exist_ok=True)
            (folder / path).write_text(text, encoding="utf-8")
    saved = list(sys.path)
    try:
        entry = ensure_compiled([folder / "dsdl" / "widthcheck"], ROOT / ".cache" / "dsdl")
        module = importlib.import_module("widthcheck")
        yield module, entry
    finally:
        sys.path[:] = saved


def _roundtrip(obj: Any) -> Any:
    import pycyphal.dsdl

    return pycyphal.dsdl.deserialize(type(obj), list(pycyphal.dsdl.serialize(obj)))


@needs_pycyphal
def test_every_signed_array_width_serializes(widthcheck: Any) -> None:
    """Fixed and bounded, after a bool (odd bit offsets): int2..int7 failed on every element, int15/31/63 on
    negative ones."""
    module, _ = widthcheck
    for w in range(2, 65):
        lo, hi = -(2 ** (w - 1)), 2 ** (w - 1) - 1
        for fixed, bounded in (([lo, -1], [hi, lo]), ([0, 1], [])):
            back = _roundtrip(getattr(module, f"Signed{w}_1_0")(flag=True, fixed=fixed, bounded=bounded))
            assert (back.fixed.tolist(), back.bounded.tolist()) == (fixed, bounded), w


@needs_pycyphal
def test_the_simulated_device_can_publish_narrow_signed_arrays(widthcheck: Any) -> None:
    """What the issue saw: the sim's generic values of an int5[<=8] type failed every publication."""
    from sam_runtime.sim.simulator import generic_fill

    module, _ = widthcheck
    for w in range(2, 9):
        cls = getattr(module, f"Signed{w}_1_0")
        for step in range(8):
            obj = generic_fill(cls(), tt=2.5 * step, now_us=0, seed=step)
            assert len(obj.bounded) > 0
            back = _roundtrip(obj)
            assert (back.fixed.tolist(), back.bounded.tolist()) == (obj.fixed.tolist(), obj.bounded.tolist())


def test_the_support_fix_applies_once_and_only_to_what_it_knows(tmp_path: Path) -> None:
    from sam_runtime.cyphal_io.nunavut_fix import fix_support

    line = "        self.add_{}_unsigned((2**bit_length + value) if value < 0 else value, bit_length)\n"
    source = "".join(f"    def add_{kind}_signed(self, value, bit_length):\n" + line.format(kind)
                     for kind in ("aligned", "unaligned"))
    path = tmp_path / "nunavut_support.py"
    path.write_text(source, encoding="utf-8")
    assert fix_support(path) is True
    fixed = path.read_text(encoding="utf-8")
    assert fixed.count("value = int(value)") == 2
    assert fix_support(path) is False and path.read_text(encoding="utf-8") == fixed
    other = "def add_aligned_signed(self, value, bit_length):\n    return value\n"
    path.write_text(other, encoding="utf-8")
    assert fix_support(path) is False and path.read_text(encoding="utf-8") == other


# ---- 7: tables ---------------------------------------------------------------------------------------------

def test_uavcan_to_ros_table_must_cover_every_value_or_have_a_default(tmp_path: Path) -> None:
    path = _variant(tmp_path, ("{0: 0, 1: 1, 2: 2, 3: 3, 7: -1, default: -1}", "{0: 0, 1: 1, 2: 2, 3: 3, 7: -1}"))
    assert spec_errors(path) == [
        "tractor.yaml:100:9: error: mapping 'hitch_status', field 'state': the table has no entry for 3 of the 8 "
        "values of uint3 (4, 5, 6); a message carrying one would be dropped (expected an entry for each value, or "
        "`default: <ROS value>` for the values it does not list)",
    ]
    complete = _variant(tmp_path, ("{0: 0, 1: 1, 2: 2, 3: 3, 7: -1, default: -1}",
                                   "{0: 0, 1: 1, 2: 2, 3: 3, 4: -1, 5: -1, 6: -1, 7: -1}"))
    assert spec_errors(complete) == []


def test_a_ros_to_uavcan_table_need_not_list_every_ros_value() -> None:
    """ROS int8 has 256 values; a command with one the table does not give is rejected (counted), by design."""
    mapping = next(rm for rm in validate(load_spec_file(TRACTOR)).mappings if rm.mapping.name == "hitch_command")
    step = next(s for s in mapping.steps if s.ros == "mode")
    assert step.kind == "table" and step.table_default is None and len(step.table) == 4


def test_table_default_reaches_the_converter_and_the_docs() -> None:
    files = generate(TRACTOR)
    convert = files["python/tractor_bridge/convert.py"]
    assert "state = _HITCH_STATUS_STATE_TO_ROS.get(src.state, -1)\n" in convert
    assert "stats.reject('hitch_status.state')" in convert  # only the inverse (ROS -> UAVCAN) still rejects
    assert "table {0: 0, 1: 1, 2: 2, 3: 3, 7: -1, default: -1}" in files["docs/interfaces.md"]


# ---- 8: follow-on errors -----------------------------------------------------------------------------------

def test_a_failed_derive_from_adds_no_errors_about_its_fields(tmp_path: Path) -> None:
    path = _variant(
        tmp_path,
        ("messages:\n", "messages:\n  StatusCopy:\n    derive_from: tractor.hitch.Status.1.0\n"
                        "  Wrapper:\n    fields:\n      - {name: copy, type: tractor_msgs/StatusCopy}\n"),
        ("  /hitch/command: {", "  /hitch/copy: {type: tractor_msgs/StatusCopy}\n"
                                "  /hitch/wrapped: {type: tractor_msgs/Wrapper}\n  /hitch/command: {"),
        ("    hitch_command:\n", """\
    copy:
      direction: uavcan_to_ros
      subject_id: 600
      topic: /hitch/copy
      source_node_ids: [20]
      frame_id: hitch_link
      fields:
        header.stamp: timestamp
        state: {from: state, table: {0: 0, default: 1}}
        tilt: tilt
        trim: trim
        sections: sections
        missing: nothing
    wrapped:
      direction: uavcan_to_ros
      subject_id: 600
      topic: /hitch/wrapped
      source_node_ids: [20]
      fields:
        copy.state: {from: state, table: {0: 0, default: 1}}
      ignore: [timestamp, tilt, trim, sections]
    hitch_command:
"""),
    )
    assert spec_errors(path) == [
        "tractor.yaml:19:3: error: cannot derive tractor_msgs/StatusCopy from tractor.hitch.Status.1.0: field "
        "'sections': a tractor.hitch.Section.1.0[3] field cannot be derived automatically; declare the ROS message "
        "by hand",
    ]


def test_an_unknown_field_type_is_reported_once(tmp_path: Path) -> None:
    path = _variant(tmp_path, ('type: "tractor.hitch.Section.1.0[3]"', 'type: "tractor.hitch.Sektion.1.0[3]"'),
                    ("      ignore: [", "      ignore: [\"sections[0]\", "))
    assert spec_errors(path) == [
        "tractor.yaml:59:9: error: unknown DSDL type 'tractor.hitch.Sektion.1.0' in DSDL type "
        "tractor.hitch.Status.1.0 (expected a type of this spec or of CYPHAL_PATH (uavcan.*, reg.*))",
    ]


def test_an_output_folder_problem_is_not_a_spec_error(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    foreign = tmp_path / "mine"
    foreign.mkdir()
    (foreign / "notes.txt").write_text("keep me", encoding="utf-8")
    assert main(["build", "--spec", str(TRACTOR), "--out", str(foreign)]) == 1
    err = capsys.readouterr().err
    assert err == (f"sam-codegen: refusing to replace {foreign}: sam-codegen did not generate it (no {MARKER} "
                   "marker); choose an empty or generated output folder\n")
    assert [p.name for p in foreign.iterdir()] == ["notes.txt"]
    a_file = tmp_path / "file"
    a_file.write_text("x", encoding="utf-8")
    assert main(["build", "--spec", str(TRACTOR), "--out", str(a_file)]) == 1
    err = capsys.readouterr().err
    assert err == f"sam-codegen: {a_file} is not a folder; choose an empty or generated output folder\n"
    assert "error" not in err and a_file.read_text(encoding="utf-8") == "x"


# ---- 9: elements of fixed arrays of composites -------------------------------------------------------------

def test_coverage_is_per_element(tmp_path: Path) -> None:
    path = _variant(tmp_path, ('      ignore: ["sections[1]", "sections[2].open"]\n', ""))
    assert spec_errors(path) == [
        "tractor.yaml:91:5: error: required field left unmapped: UAVCAN field 'sections[1]' "
        "(tractor.hitch.Section.1.0) of tractor.hitch.Status.1.0 is neither mapped nor ignored in mapping "
        "'hitch_status' (expected a `ros_field: sections[1]` line or `sections[1]` in ignore)",
        "tractor.yaml:91:5: error: required field left unmapped: UAVCAN field 'sections[2].open' (bool) of "
        "tractor.hitch.Status.1.0 is neither mapped nor ignored in mapping 'hitch_status' (expected a "
        "`ros_field: sections[2].open` line or `sections[2].open` in ignore)",
    ]
    path = _variant(tmp_path, ("      uavcan_values:\n        sections[1].open: true\n", ""))
    assert spec_errors(path) == [
        "tractor.yaml:107:5: error: required field left unmapped: UAVCAN field 'sections[1].open' (bool) of "
        "tractor.hitch.Command.1.0 gets no value in mapping 'hitch_command' (expected a `ros_field: "
        "sections[1].open` line or an entry in uavcan_values)",
    ]
    path = _variant(tmp_path, ("        right_rate: sections[2].rate", "        right_rate: sections[3].rate"))
    assert spec_errors(path) == [
        "tractor.yaml:105:9: error: mapping 'hitch_status', field 'right_rate': sections[3]: index out of range, "
        "sections has 3 elements",
    ]


def test_a_whole_element_may_be_ignored_while_another_is_mapped(tmp_path: Path) -> None:
    """The issue's case: mapping one element's field needed the whole element ignored as well."""
    path = _variant(tmp_path, ('      ignore: ["sections[1]", "sections[2].open"]',
                               '      ignore: ["sections[1]", "sections[2]"]'),
                    ("        right_rate: sections[2].rate\n", "        right_rate: {value: 0}\n"))
    assert spec_errors(path) == []


# ---- 10: void padding --------------------------------------------------------------------------------------

def test_void_padding_is_emitted_in_place_and_read_by_pydsdl(tmp_path: Path) -> None:
    files = generate(TRACTOR)  # verify_dsdl has pydsdl read every emitted type
    section = files["dsdl/tractor/hitch/Section.1.0.dsdl"]
    assert "uint12 rate\nvoid4\nbool open\n# Reserved.\nvoid7\n" in section
    for path, text in files.items():
        if path.startswith("dsdl/"):
            (tmp_path / path).parent.mkdir(parents=True, exist_ok=True)
            (tmp_path / path).write_text(text, encoding="utf-8")
    types = {str(t.full_name): t for t in pydsdl.read_namespace(
        str(tmp_path / "dsdl" / "tractor"), [str(r) for r in validate(load_spec_file(TRACTOR)).dsdl.roots])}
    assert types["tractor.hitch.Section"].bit_length_set == {24}  # 12 + 4 + 1 + 7
    status = types["tractor.hitch.Status"]
    assert [f.name for f in status.fields][:3] == ["timestamp", "state", ""]  # the padding, unnamed
    # timestamp, state, void5, an empty tilt (its length byte), trim; padded to a byte for the composites
    assert status.bit_length_set.min == 88 + 3 * 24 and 56 + 3 + 5 + 8 + 4 * 3 == 84
    assert "| — | `void4` | padding |" in files["docs/interfaces.md"]


@needs_pycyphal
def test_void_padding_keeps_the_bits_where_the_device_has_them(widthcheck: Any) -> None:
    import pycyphal.dsdl

    module, _ = widthcheck
    data = b"".join(pycyphal.dsdl.serialize(module.Padded_1_0(rate=0xABC, open_=True)))
    assert data == b"\xbc\x0a\x01"  # rate in bits 0..11, 4 bits of padding, open in bit 16, 7 more bits
    padded = module.Padded_1_0()
    assert "open_" in dir(padded) and not any(n.startswith("void") for n in dir(padded))
