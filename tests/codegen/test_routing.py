"""Routing a real bridge needs (issue 17 classes 5, 6 and 7), on tests/specs/seiner.yaml:

- the ROUTING_CASES of tests/broken_cases.py: each breaks seiner.yaml one way and gives exactly its errors;
- `source_node_ids: any` / `destination_node_ids: any` (both protocols for sources): the mapping reaches every
  device with its port (rate, layouts), the tables say `any_node`, the docs say what protection it gives up;
- `shares_data_type`: legacy and new topics broadcast one type, each mapping with its own elements;
- a `select` field that a UAVCAN->ROS mapping also publishes (esc_index), and is still refused ROS->UAVCAN.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from broken_cases import ROUTING_CASES, Case
from helpers.spec_errors import spec_errors

from sam_codegen.build import build
from sam_codegen.frontend.loader import load_spec_file
from sam_codegen.validate.resolve import Resolved, validate
from sam_codegen.validate.routing import routed_node_ids

SPECS = Path(__file__).parents[1] / "specs"
TRAWLER = SPECS / "seiner.yaml"
BASE = TRAWLER.read_text(encoding="utf-8")


@pytest.fixture(scope="module")
def resolved() -> Resolved:
    return validate(load_spec_file(TRAWLER))


@pytest.fixture(scope="module")
def generated(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("seiner") / "generated"
    build(TRAWLER, out)
    return out


def test_base_spec_is_valid() -> None:
    assert spec_errors(TRAWLER) == []


@pytest.mark.parametrize("case", ROUTING_CASES, ids=lambda c: c.name)
def test_broken_spec(case: Case, tmp_path: Path) -> None:
    assert BASE.count(case.old) == 1, f"case {case.name} no longer applies to seiner.yaml"
    path = tmp_path / "seiner.yaml"
    path.write_text(BASE.replace(case.old, case.new, 1), encoding="utf-8")
    assert spec_errors(path) == list(case.errors)


def test_any_node_reaches_every_device_with_the_port(resolved: Resolved) -> None:
    spec = resolved.spec
    by_name = {m.name: m for m in spec.bridge.all_mappings}  # type: ignore[union-attr]
    assert routed_node_ids(spec, by_name["esc0_status"]) == [30, 31]  # both ESCs publish esc.Status
    assert routed_node_ids(spec, by_name["rudder_position"]) == [32]
    assert routed_node_ids(spec, by_name["legacy_stbd_rpm"]) == [30, 31]  # destination any: both subscribe
    assert routed_node_ids(spec, by_name["legacy_rpm"]) == [30]  # static ids stay as they are
    assert routed_node_ids(spec, by_name["winch"]) == [40]  # Cyphal: the publishers of subject 700
    assert by_name["esc0_status"].any_node and not by_name["legacy_rpm"].any_node
    rates = {rm.mapping.name: rm.rate_hz for rm in [*resolved.mappings, *resolved.dronecan_mappings]}
    assert rates["esc0_status"] == 10.0 and rates["legacy_stbd_rpm"] == 10.0 and rates["winch"] == 5.0
    default = next(layout for layout in resolved.layouts if layout.name == "default")
    assert default.cyphal_mappings == ["winch"]
    assert set(default.dronecan_mappings) == {m.name for m in spec.bridge.dronecan_mappings}  # type: ignore[union-attr]


def test_shared_data_type_keeps_each_mappings_elements(resolved: Resolved) -> None:
    """[r1, r2], [r] and [c, r] of one RPMCommand: each mapping builds its own message."""
    elements = {rm.mapping.name: [u for uses in rm.elements.values() for u in uses]
                for rm in resolved.dronecan_mappings}
    assert elements["thrusters"] == [0, 1]
    assert elements["legacy_rpm"] == [0]
    assert elements["legacy_stbd_rpm"] == [1, 0]  # rpm[1] from the topic, rpm[0] a constant
    shared = {rm.mapping.name for rm in resolved.dronecan_mappings if rm.mapping.shares_data_type}
    assert shared == {"thrusters", "legacy_rpm", "legacy_stbd_rpm", "rudder", "legacy_rudder"}


def test_a_select_field_may_also_be_published(resolved: Resolved) -> None:
    rm = next(rm for rm in resolved.dronecan_mappings if rm.mapping.name == "esc0_status")
    assert [(s.ros, s.uavcan) for s in rm.steps if s.uavcan == "esc_index"] == [("y", "esc_index")]
    assert [(p[0][0], v) for p, _, v in rm.select] == [("esc_index", 0)]


def test_a_select_field_published_in_minimal_v0(tmp_path: Path) -> None:
    """The bilge mapping routed by pump_id also reports it (UAVCAN->ROS): valid, where it once was refused."""
    base = (SPECS / "minimal_v0.yaml").read_text(encoding="utf-8")
    old = "        data: level_mm\n      ignore: [timestamp]"
    assert base.count(old) == 1
    path = tmp_path / "minimal_v0.yaml"
    path.write_text(base.replace(old, "        data: pump_id\n      ignore: [timestamp, level_mm]"), encoding="utf-8")
    assert spec_errors(path) == []


def test_generated_tables_say_any_node(generated: Path) -> None:
    import importlib.util
    import sys

    spec = importlib.util.spec_from_file_location("seiner_tables", next(generated.glob("python/*/tables.py")))
    assert spec is not None and spec.loader is not None
    tables = importlib.util.module_from_spec(spec)
    sys.modules["seiner_tables"] = tables  # dataclasses look their module up
    try:
        spec.loader.exec_module(tables)
    finally:
        del sys.modules["seiner_tables"]
    any_v0 = {m.name for m in tables.DRONECAN_MAPPINGS if m.any_node}
    assert any_v0 == {"esc0_status", "esc1_status", "rudder_position", "legacy_stbd_rpm", "legacy_rudder"}
    assert all(not m.source_node_ids for m in tables.DRONECAN_MAPPINGS if m.any_node)
    assert [m.name for m in tables.MAPPINGS if m.any_node] == ["winch"]
    assert {m.name: sorted(m.destination_node_ids) for m in tables.DRONECAN_MAPPINGS
            if not m.any_node and m.direction == "ros_to_uavcan"} == {
        "thrusters": [30, 31], "legacy_rpm": [30], "rudder": [32], "hook": [33]}


def test_docs_show_any_node_and_sharing(generated: Path) -> None:
    md = (generated / "docs" / "interfaces.md").read_text(encoding="utf-8")
    assert ("| `winch` | UAVCAN → ROS | `seiner.Winch.0.1` | 700 | `/winch/tension` | `std_msgs/Float32` | "
            "from any node |") in md
    # the winch (Cyphal) and the three DroneCAN status mappings
    assert md.count("the bridge does not protect this topic against a spoofing or stray node") == 4
    assert ("- Shares `uavcan.equipment.esc.RPMCommand` with `legacy_rpm`, `legacy_stbd_rpm` (`shares_data_type`): "
            "each mapping broadcasts its own messages") in md
    assert ("- Any node (`destination_node_ids: any`): the broadcast is for every device that receives "
            "`uavcan.equipment.esc.RPMCommand`; no destination is checked.") in md
    section = md.split("#### DroneCAN `esc0_status`")[1].split("####")[0]
    assert "| — |  | `esc_index` | select 0 |" in section and "| `y` | ← | `esc_index` |" in section
