"""Issue 17 classes 8 and 9 in the generator: the spec chooses the namespaces of dronecan's own definitions it uses
(`dronecan_namespaces`), so a vendor data type id of a namespace it never loads (20100: com.hobbywing.esc.RawCommand)
is free for its own type; and uavcan.protocol.Panic is an ordinary mapping onto the spec's topics (`reason_text`
uint8[<=7] <-> a ROS string), with `bridge.panic_duty` saying whether the bridge's built-in Panic duty runs beside it.

The TRAWLER_CASES of tests/broken_cases.py break tests/specs/trawler_v0.yaml one way each (exact messages); the
catalog is tested on dronecan's own definitions; the generated tables and converters of the trawler spec are read.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from broken_cases import TRAWLER_CASES, Case
from helpers.spec_errors import spec_errors

from sam_codegen.catalogs.dronecan import DRONECAN_ROOTS, V0Catalog, in_namespaces
from sam_codegen.frontend.loader import load_spec_file, parse_spec
from sam_codegen.frontend.yaml_source import load_yaml
from sam_codegen.model.spec import Spec
from sam_codegen.validate.resolve import validate

SPECS = Path(__file__).parents[1] / "specs"
TRAWLER = SPECS / "trawler_v0.yaml"
BASE = TRAWLER.read_text(encoding="utf-8")
MINIMAL = "spec_version: 1\nvehicle: {name: t}\nros: {package: t_msgs}\n"

pytest.importorskip("dronecan")  # the standard definitions: the dronecan package's


def _spec(text: str) -> Spec:
    return parse_spec(load_yaml(text, "t.yaml"), "t.yaml")


def _with(tmp_path: Path, *edits: tuple[str, str]) -> list[str]:
    text = BASE
    for old, new in edits:
        assert text.count(old) == 1, old
        text = text.replace(old, new, 1)
    path = tmp_path / "trawler_v0.yaml"
    path.write_text(text, encoding="utf-8")
    return spec_errors(path)


def test_trawler_spec_is_valid() -> None:
    assert spec_errors(TRAWLER) == []


@pytest.mark.parametrize("case", TRAWLER_CASES, ids=lambda c: c.name)
def test_broken_trawler_spec(case: Case, tmp_path: Path) -> None:
    assert _with(tmp_path, (case.old, case.new)) == list(case.errors)


# ---- the catalog -----------------------------------------------------------------------------------------------


def test_default_namespaces_are_every_root_so_20100_stays_taken() -> None:
    catalog = V0Catalog(_spec(MINIMAL))
    assert set(catalog.namespaces) == set(DRONECAN_ROOTS) and catalog.namespaces[0] == "uavcan"
    assert catalog.standard_ids()[(False, 20100)] == "com.hobbywing.esc.RawCommand"
    assert catalog.files() == catalog.all_files()


def test_chosen_namespaces_leave_the_others_out() -> None:
    catalog = V0Catalog(_spec(MINIMAL + "dronecan_namespaces: [ardupilot]\n"))
    assert catalog.namespaces == ("uavcan", "ardupilot")  # uavcan always, first
    ids = catalog.standard_ids()
    assert (False, 20100) not in ids and ids[(False, 20000)] == "ardupilot.indication.SafetyState"
    assert ids[(False, 1003)] == "uavcan.equipment.ahrs.RawIMU"
    assert {name.split(".")[0] for name in catalog.files()} == {"uavcan", "ardupilot"}
    assert catalog.get("com.hobbywing.esc.RawCommand") is None and not catalog.is_standard("dronecan.remoteid.BasicID")
    assert catalog.get("ardupilot.gnss.Heading") is not None
    assert "com.hobbywing.esc.RawCommand" in catalog.all_files()  # still known, for the error that names it


def test_a_namespace_inside_a_root_takes_only_its_own_types() -> None:
    catalog = V0Catalog(_spec(MINIMAL + "dronecan_namespaces: [com.xacti]\n"))
    roots = {name.rsplit(".", 1)[0] for name in catalog.files() if not name.startswith("uavcan.")}
    assert roots == {"com.xacti"}
    assert (False, 20100) not in catalog.standard_ids() and (False, 20305) in catalog.standard_ids()
    assert {"com", "com.hobbywing", "com.hobbywing.esc", "uavcan.protocol"} <= catalog.known_namespaces()


def test_in_namespaces_matches_whole_components() -> None:
    assert in_namespaces("com.hobbywing.esc.RawCommand", ("com",))
    assert not in_namespaces("com.hobbywingx.esc.Thing", ("com.hobbywing",))
    assert not in_namespaces("comx.Thing", ("com",))


# ---- the bridge's Panic duty ------------------------------------------------------------------------------------


def test_both_refuses_a_mapping_on_the_builtin_duty_topics(tmp_path: Path) -> None:
    builtin = "/trawler_bridge/panic_received"
    errors = _with(tmp_path, ("  panic_duty: mappings\n", "  panic_duty: both\n"),
                   ("  /panic_in: {type: std_msgs/String}", f"  {builtin}: {{type: std_msgs/String}}"),
                   ("      topic: /panic_in\n", f"      topic: {builtin}\n"),
                   ("    subscribes: [/panel_level, /panic_in]", f"    subscribes: [/panel_level, {builtin}]"))
    assert errors == [
        "trawler_v0.yaml:58:5: error: DroneCAN mapping 'panic_in' uses topic /trawler_bridge/panic_received, one of "
        "the bridge's built-in Panic duty (expected a topic of its own, or `panic_duty: mappings` (the built-in "
        "duty off))"]


def test_both_with_topics_of_its_own_is_valid(tmp_path: Path) -> None:
    assert _with(tmp_path, ("  panic_duty: mappings\n", "  panic_duty: both\n")) == []


def test_a_spec_without_a_panic_mapping_keeps_the_builtin_duty() -> None:
    from sam_codegen.validate.panic_duty import panic_duty

    resolved = validate(load_spec_file(SPECS / "minimal_v0.yaml"))
    assert panic_duty(resolved.spec) == "builtin"


# ---- what the generator emits ------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def emitted() -> dict[str, str]:
    from sam_codegen.targets.python import convert, convert_v0
    from sam_codegen.targets.wire import codec_v0

    resolved = validate(load_spec_file(TRAWLER))
    out: dict[str, str] = {}
    for emitter in (convert, convert_v0, codec_v0):  # convert: the package (tables.py, conversion_support.py)
        out.update(emitter.emit(resolved))
    return out


def test_tables_say_the_namespaces_and_the_panic_duty(emitted: dict[str, str]) -> None:
    text = emitted["python/trawler_bridge/tables.py"]
    assert "DRONECAN_NAMESPACES: tuple[str, ...] | None = ('uavcan', 'ardupilot')\n" in text
    assert "DRONECAN_PANIC_DUTY: str = 'mappings'\n" in text
    assert "DroneCanTypeInfo('trawler.io.Switch', 20100, " in text


def test_generated_dsdl_has_the_type_at_20100() -> None:
    from sam_codegen.targets import dsdl_v0

    files = dsdl_v0.emit(validate(load_spec_file(TRAWLER)))
    assert list(files) == ["dsdl_v0/trawler/io/20100.Switch.uavcan"]


class _Stats:
    def __init__(self) -> None:
        self.saturated: list[str] = []

    def saturate(self, key: str) -> None:
        self.saturated.append(key)

    def reject(self, key: str) -> None:  # pragma: no cover - the Panic mappings never reject
        raise AssertionError(key)

    def reject_nan(self, key: str) -> None:  # pragma: no cover - the Panic mappings never reject
        raise AssertionError(key)


def _cdr_string(text: str) -> bytes:
    data = text.encode() + b"\0"
    return b"\0\1\0\0" + len(data).to_bytes(4, "little") + data


def test_panic_codec_cuts_reason_text_at_7_bytes_on_a_character_boundary_and_counts(
        emitted: dict[str, str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    import importlib
    import sys

    for path, text in emitted.items():
        if path.startswith("python/trawler_bridge/"):
            (tmp_path / path).parent.mkdir(parents=True, exist_ok=True)
            (tmp_path / path).write_text(text, encoding="utf-8")
    monkeypatch.syspath_prepend(str(tmp_path / "python"))
    for name in [m for m in sys.modules if m.split(".")[0] == "trawler_bridge"]:
        monkeypatch.delitem(sys.modules, name)
    codec = importlib.import_module("trawler_bridge.codec_v0")  # standard library only: no dronecan, no rclpy
    stats = _Stats()
    assert codec.panic_out_ros_to_wire(_cdr_string("LEAK"), stats) == b"LEAK" and stats.saturated == []
    assert codec.panic_out_ros_to_wire(_cdr_string("WATER-INGRESS"), stats) == b"WATER-I"
    # 8 bytes: the 4th Å would be cut in two, so 6 bytes go
    assert codec.panic_out_ros_to_wire(_cdr_string("ÅÅÅÅ"), stats) == "ÅÅÅ".encode()
    assert stats.saturated == ["panic_out.reason_text"] * 2
    assert codec.panic_in_wire_to_ros(b"LEAK", 0, stats) == (_cdr_string("LEAK"), -1)
    # this test's copy leaves with it (monkeypatch only puts back what was there before): another copy in
    # sys.modules would shadow the shared build the system tests import (GeneratedPackage refuses it)
    for name in [m for m in sys.modules if m.split(".")[0] == "trawler_bridge"]:
        del sys.modules[name]


def test_the_reference_says_the_namespaces_and_who_handles_panic() -> None:
    from sam_codegen.targets.docs import emit

    text = emit(validate(load_spec_file(TRAWLER)))["docs/interfaces.md"]
    assert "- Standard definitions used: `uavcan`, `ardupilot` (`dronecan_namespaces`: the data type ids of the " \
           "other namespaces are free for the spec's own types).\n" in text
    assert "- `uavcan.protocol.Panic` is handled by the spec's DroneCAN mappings of `uavcan.protocol.Panic` " \
           "(`panic_duty: mappings`; the built-in duty is off).\n" in text
    assert "| `data` | → | `reason_text` | string → uint8\\[&lt;=7\\] (longer than 7 bytes cut) |" in text
    assert "- Data type id 20100, signature" in text
