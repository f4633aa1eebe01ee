"""UAVCAN v0 (DroneCAN) types: the catalog reads dronecan's standard definitions as dronecan does (ids, signatures,
fields), the emitted custom types are what dronecan's own parser reads back, and the v0 output is golden.

dronecan's parser is used here without loading anything into dronecan (``parse_namespaces``), so that the
process's dronecan types stay as other tests expect them; the converters' tests load the emitted types in a child.
``SAM_UPDATE_GOLDEN=1`` rewrites tests/golden/dsdl_v0/ and tests/golden/python_v0/.
"""

from __future__ import annotations

import os
import shutil
from dataclasses import replace
from pathlib import Path

import pytest

from sam_codegen.build import generate
from sam_codegen.catalogs.dronecan import (
    DRONECAN_ROOTS,
    V0Catalog,
    crc64we,
    normalized_definition,
    parse_definition,
    standard_roots,
)
from sam_codegen.frontend.loader import load_spec_file
from sam_codegen.model.spec import RosPackageInfo, Spec, V0Struct
from sam_codegen.model.types import v0_normalized
from sam_codegen.targets import dsdl_v0 as emit_dsdl_v0
from sam_codegen.targets.python import convert as emit_python
from sam_codegen.targets.python import convert_v0 as emit_python_v0
from sam_codegen.validate.resolve import Resolved, validate

dronecan = pytest.importorskip("dronecan")

ROOT = Path(__file__).resolve().parents[2]
SPECS = {"sam": ROOT / "spec" / "interfaces.yaml", "ferry": ROOT / "tests" / "specs" / "ferry.yaml",
         "minimal_v0": ROOT / "tests" / "specs" / "minimal_v0.yaml"}
GOLDEN = Path(__file__).parents[1] / "golden"
UPDATE = os.environ.get("SAM_UPDATE_GOLDEN") == "1"


@pytest.fixture(scope="module")
def resolved() -> dict[str, Resolved]:
    return {name: validate(load_spec_file(path)) for name, path in SPECS.items()}


def _empty_spec() -> Spec:
    return Spec("none.yaml", "none", "", RosPackageInfo("none_msgs"), "none")


def _dronecan_fields(t: object) -> list[str]:
    fields = t.fields if t.kind == t.KIND_MESSAGE else t.request_fields + t.response_fields  # type: ignore[attr-defined]
    return [f.get_normalized_definition() for f in fields]


def test_every_standard_type_as_dronecan_reads_it() -> None:
    """All of dronecan's loaded definitions: the same names, data type ids, fields and signatures."""
    catalog = V0Catalog(_empty_spec())
    assert {r.name for r in catalog.roots} == set(DRONECAN_ROOTS)
    names = set(catalog.files())
    # The bundled roots only: a spec's own types (sam.*, ferry.*) may have been added in this process by the
    # bridge or the simulator (sam_runtime.dronecan_io.types).
    assert names == {n for n in dronecan.TYPENAMES if n.split(".")[0] in DRONECAN_ROOTS}
    assert len(names) > 100
    for name in sorted(names):
        theirs = dronecan.TYPENAMES[name]
        ours = catalog.get(name)
        assert ours is not None and isinstance(ours, V0Struct)
        assert ours.data_type_id == theirs.default_dtid, name
        assert ours.service == (theirs.kind == theirs.KIND_SERVICE), name
        assert catalog.signature(name) == theirs.get_data_type_signature(), name
        if not ours.service:
            ours_fields = [v0_normalized(f.type) + (f" {f.name}" if f.name else "")  # type: ignore[arg-type]
                           for f in ours.declared_fields]
            assert ours_fields == _dronecan_fields(theirs), name
            assert ours.union == theirs.union, name
    assert catalog.errors == []
    ids = catalog.standard_ids()
    assert ids[(False, 1003)] == "uavcan.equipment.ahrs.RawIMU"
    assert ids[(False, 20100)] == "com.hobbywing.esc.RawCommand"
    assert ids[(True, 1)] == "uavcan.protocol.GetNodeInfo"


@pytest.mark.parametrize("union", [False, True])
def test_signature_of_a_definition_text(union: bool, tmp_path: Path) -> None:
    """A definition parsed from text: its normalized definition, and its signature against dronecan's."""
    text = ("@union\n" if union else "") + "uavcan.Timestamp timestamp\nint13 x # a comment\nuint8[<32] name\n"
    if not union:
        text += "void3\nfloat16[3] v\n"
    parsed = parse_definition(text, "demo.Thing", 20198)
    assert [f.name for f in parsed.struct.fields] == ["timestamp", "x", "name", *([] if union else ["v"])]
    assert str(parsed.struct.field("name").type) == "uint8[<=31]"  # type: ignore[union-attr]
    assert normalized_definition("demo.Thing", parsed.layout, union) == (
        "demo.Thing\n" + ("@union\n" if union else "") + "uavcan.Timestamp timestamp\nsaturated int13 x\n"
        "saturated uint8[<=31] name" + ("" if union else "\nvoid3\nsaturated float16[3] v"))
    (tmp_path / "demo").mkdir()
    (tmp_path / "demo" / "20198.Thing.uavcan").write_text(text, encoding="utf-8")
    theirs = _parse_with_dronecan(tmp_path / "demo")["demo.Thing"]
    spec = replace(_empty_spec(), dronecan_types={"demo.Thing": replace(parsed.struct, standard=False)})
    if not union:  # (the spec's own types are never unions)
        assert V0Catalog(spec).signature("demo.Thing") == theirs.get_data_type_signature()  # type: ignore[attr-defined]
    assert crc64we(b"123456789") == 0x62EC59E3F1A4F00A  # the CRC-64-WE check value
    with pytest.raises(ValueError, match=r"line 2: uint1: a v0 integer has 2\.\.64 bits"):
        parse_definition("bool a\nuint1 b\n", "demo.Bad", None)


def _parse_with_dronecan(folder: Path) -> dict[str, object]:
    """dronecan's parser over an emitted root namespace folder (the standard ones to look nested types up in)."""
    search = [str(r) for r in standard_roots()]
    return {t.full_name: t for t in dronecan.dsdl.parse_namespaces([str(folder)], search)}


@pytest.mark.parametrize("spec", sorted(SPECS))
def test_dronecan_reads_the_emitted_types_back(spec: str, resolved: dict[str, Resolved], tmp_path: Path) -> None:
    """Every emitted type file: dronecan's parser finds the spec's type, with its id, fields and our signature."""
    r = resolved[spec]
    files = emit_dsdl_v0.emit(r)
    assert files and all(p.startswith("dsdl_v0/") and p.endswith(".uavcan") for p in files)
    for path, text in files.items():
        (tmp_path / path).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / path).write_text(text, encoding="utf-8")
    parsed: dict[str, object] = {}
    for folder in emit_dsdl_v0.load_dirs(r):
        parsed |= _parse_with_dronecan(tmp_path / folder)
    assert set(parsed) == {t.name for t in r.dronecan_types}
    for t in r.dronecan_types:
        theirs = parsed[t.name]
        assert theirs.default_dtid == t.data_type_id  # type: ignore[attr-defined]
        assert theirs.get_data_type_signature() == t.signature != 0  # type: ignore[attr-defined]
        assert _dronecan_fields(theirs) == [v0_normalized(f.type) + (f" {f.name}" if f.name else "")  # type: ignore[arg-type]
                                            for f in t.declared_fields]
        assert [(c.name, c.value) for c in theirs.constants] == [(c.name, c.value) for c in t.constants]  # type: ignore[attr-defined]


def test_emitted_names_and_folders(resolved: dict[str, Resolved]) -> None:
    assert sorted(emit_dsdl_v0.emit(resolved["sam"])) == [
        "dsdl_v0/sam/actuator/20101.ThrustVectorFeedback.uavcan", "dsdl_v0/sam/actuator/20102.PositionFeedback.uavcan",
        "dsdl_v0/sam/sensor/20103.Altitude.uavcan"]
    assert emit_dsdl_v0.load_dirs(resolved["sam"]) == ["dsdl_v0/sam"]
    ferry = emit_dsdl_v0.emit(resolved["ferry"])
    assert "dsdl_v0/ferry/hull/LeakState.uavcan" in ferry  # nested only: no id in its name
    assert "void4\n" in ferry["dsdl_v0/ferry/hull/LeakState.uavcan"]
    assert "uint3 MAX_COMPARTMENTS = 6\n" in ferry["dsdl_v0/ferry/hull/20150.LeakReport.uavcan"]
    assert "truncated uint10 pump_duty\n" in ferry["dsdl_v0/ferry/hull/20150.LeakReport.uavcan"]


def test_no_dronecan_output_without_dronecan(tmp_path: Path) -> None:
    """A Cyphal-only spec gets no dsdl_v0/ nor convert_v0.py, and empty DroneCAN tables (one default layout)."""
    files = generate(ROOT / "tests" / "specs" / "rover.yaml")
    assert not [p for p in files if p.startswith("dsdl_v0/") or p.endswith("convert_v0.py")]
    tables = files["python/rover_bridge/tables.py"]
    assert "DRONECAN_MAPPINGS: tuple[DroneCanMappingInfo, ...] = (\n)" in tables
    assert "DRONECAN_DSDL_DIRS: tuple[str, ...] = ()" in tables


def _golden(folder: Path, ours: dict[str, str]) -> None:
    if UPDATE:
        shutil.rmtree(folder, ignore_errors=True)
        for path, text in ours.items():
            (folder / f"{path}.golden").parent.mkdir(parents=True, exist_ok=True)
            (folder / f"{path}.golden").write_bytes(text.encode("utf-8"))
    golden = {p.relative_to(folder).as_posix().removesuffix(".golden"): p.read_bytes().decode("utf-8")
              for p in sorted(folder.rglob("*")) if p.is_file()}
    assert sorted(golden) == sorted(ours), "run with SAM_UPDATE_GOLDEN=1 after an intended change"
    for path, text in ours.items():
        assert text == golden[path], f"{path} differs from its golden copy; SAM_UPDATE_GOLDEN=1 rewrites it"


def test_golden_dsdl(resolved: dict[str, Resolved]) -> None:
    """SAM's v0 DSDL files, byte for byte."""
    _golden(GOLDEN / "dsdl_v0", emit_dsdl_v0.emit(resolved["sam"]))


def test_golden_converters(resolved: dict[str, Resolved]) -> None:
    """SAM's convert_v0.py and codec_v0.py, byte for byte (its tables are in tests/golden/python with the Cyphal
    ones)."""
    from sam_codegen.targets.wire import codec_v0 as emit_codec_v0

    _golden(GOLDEN / "python_v0", {**emit_python_v0.emit(resolved["sam"]), **emit_codec_v0.emit(resolved["sam"])})


@pytest.mark.system  # starts a process: not in the unit tier
@pytest.mark.parametrize("spec", ["sam", "ferry"])
def test_converters_are_lint_clean_and_deterministic(spec: str, resolved: dict[str, Resolved], tmp_path: Path) -> None:
    import subprocess
    import sys

    files = emit_python_v0.emit(resolved[spec])
    assert files == emit_python_v0.emit(validate(load_spec_file(SPECS[spec])))
    for path, text in {**files, **emit_python.emit(resolved[spec])}.items():
        compile(text, path, "exec")
        (tmp_path / path).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / path).write_text(text, encoding="utf-8")
    ruff = shutil.which("ruff") or str(Path(sys.executable).with_name("ruff"))
    if not Path(ruff).exists():
        pytest.skip("ruff is not installed (pip extra 'test')")
    proc = subprocess.run(
        [ruff, "check", "--isolated", "--no-cache", "--line-length", "110", "--target-version", "py311",
         "--select", "E,F,W,I,B,UP,RUF", "--ignore", "RUF001,RUF002,RUF003", str(tmp_path / "python")],
        capture_output=True, text=True, check=False,
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr


def test_bool_constants_written_as_bits(tmp_path: Path) -> None:
    """v0 DSDL as firmware writes it (issue 17): `bool OPEN = 0` is what dronecan's parser reads too, so the spec
    takes 0/1 for a bool constant beside true/false; the emitted file is read back by dronecan with the same values."""
    theirs = tmp_path / "theirs" / "demo"
    theirs.mkdir(parents=True)
    (theirs / "20190.Valve.uavcan").write_text("bool OPEN = 0\nbool SHUT = 1\nbool state\n", encoding="utf-8")
    assert [(c.name, c.value) for c in _parse_with_dronecan(theirs)["demo.Valve"].constants] == [  # type: ignore[attr-defined]
        ("OPEN", 0), ("SHUT", 1)]
    old = "  skiff.Bilge:\n    id: 20120\n"
    base = SPECS["minimal_v0"].read_text(encoding="utf-8")
    spec = tmp_path / "minimal_v0.yaml"
    spec.write_text(base.replace(old, old + "    constants:\n      - {name: OPEN, type: bool, value: 0}\n"
                                 "      - {name: SHUT, type: bool, value: 1}\n"
                                 "      - {name: LOCKED, type: bool, value: true}\n", 1), encoding="utf-8")
    r = validate(load_spec_file(spec))
    files = emit_dsdl_v0.emit(r)
    text = files["dsdl_v0/skiff/20120.Bilge.uavcan"]
    assert "bool OPEN = false\nbool SHUT = true\nbool LOCKED = true\n" in text
    out = tmp_path / "ours"
    for path, body in files.items():
        (out / path).parent.mkdir(parents=True, exist_ok=True)
        (out / path).write_text(body, encoding="utf-8")
    bilge = _parse_with_dronecan(out / "dsdl_v0" / "skiff")["skiff.Bilge"]
    assert [(c.name, c.value) for c in bilge.constants] == [("OPEN", 0), ("SHUT", 1), ("LOCKED", 1)]  # type: ignore[attr-defined]
