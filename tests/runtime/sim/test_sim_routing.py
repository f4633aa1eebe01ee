"""The simulated DroneCAN devices' part of routing (issue 17 class 11, and the commands of class 5), on
tests/specs/seiner.yaml, without a bus: what each device's broadcasts carry for the bridge and which elements of a
broadcast command are its own."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from types import SimpleNamespace
from typing import Any

import pytest

pytest.importorskip("dronecan")

from helpers.spec_build import forget_generated, generated_spec

from sam_runtime.genpkg import GeneratedPackage
from sam_runtime.sim.dronecan import DroneCanDevices

ESC_STATUS = "uavcan.equipment.esc.Status"
RPM = "uavcan.equipment.esc.RPMCommand"


@pytest.fixture(scope="module")
def adapter() -> Iterator[DroneCanDevices]:
    gen = GeneratedPackage(generated_spec("seiner"))
    sim: Any = SimpleNamespace(config=SimpleNamespace(dronecan_iface="mcast-lo:"), bridge_node_id=100, devices=[],
                               tables=gen.tables())
    yield DroneCanDevices(sim)
    forget_generated(gen)


def _dev(node_id: int, name: str) -> Any:
    return SimpleNamespace(info=SimpleNamespace(node_id=node_id, name=name))


def test_each_device_sends_the_select_values_of_every_mapping_that_accepts_it(adapter: DroneCanDevices) -> None:
    """Both esc.Status mappings accept any node: each ESC sends esc_index 0 and 1 in turn (not the last mapping's
    value for every broadcast), so both topics publish."""
    for node_id, name in ((30, "esc_port"), (31, "esc_stbd")):
        sel = adapter._fixed_values(_dev(node_id, name), ESC_STATUS)
        assert sel.selects == ((("esc_index", 0),), (("esc_index", 1),))
        assert [sel.next_select() for _ in range(5)] == [(("esc_index", v),) for v in (0, 1, 0, 1, 0)]
    rudder = adapter._fixed_values(_dev(32, "rudder"), "uavcan.equipment.actuator.Status")
    assert rudder.selects == ((("actuator_id", 3),),)


def test_each_esc_takes_its_own_element_of_every_shared_command(adapter: DroneCanDevices) -> None:
    """[r1, r2] to [30, 31], [r] to [30], [0, r] to any: the port ESC takes rpm[0] of all three, the starboard
    ESC rpm[1] of the two that have it (the i-th lowest position for the i-th lowest node id)."""
    def taken(node_id: int, name: str) -> list[list[str]]:
        return [[el.text for el in a.elements] for a in adapter._addressing(_dev(node_id, name), RPM)]

    assert taken(30, "esc_port") == [["rpm[0]"], ["rpm[0]"], ["rpm[0]"]]
    assert taken(31, "esc_stbd") == [["rpm[1]"], ["rpm[1]"]]


@pytest.fixture
def spec_tables() -> Iterator[Callable[[str], Any]]:
    """The tables of SAM's generated package or of a tests/specs build; the latter leave the process afterwards."""
    imported: list[GeneratedPackage] = []

    def tables(spec: str) -> Any:
        if spec == "sam":
            from helpers.runtime_support import generated_or_skip

            return generated_or_skip().tables()
        imported.append(GeneratedPackage(generated_spec(spec)))
        return imported[-1].tables()

    yield tables
    for gen in imported:
        forget_generated(gen)


@pytest.mark.parametrize("spec", ["sam", "minimal_v0", "buoy_v0", "ferry", "seiner"])
def test_every_select_routed_mapping_has_a_device_sending_its_values(spec: str, spec_tables: Any) -> None:
    """Class 11 for every spec with DroneCAN: each UAVCAN->ROS mapping with `select` is fed by some simulated device
    that sends its values (in turn with the other selections that accept the device), so its topic publishes."""
    tables = spec_tables(spec)
    sim: Any = SimpleNamespace(config=SimpleNamespace(dronecan_iface="mcast-lo:"), bridge_node_id=100, devices=[],
                               tables=tables)
    devices = DroneCanDevices(sim)
    routed = [m for m in tables.DRONECAN_MAPPINGS if m.direction == "uavcan_to_ros" and m.select]
    for m in routed:
        senders = [d.name for d in tables.DRONECAN_DEVICES
                   if any(p.data_type.name == m.data_type.name for p in d.publishes)
                   and tuple(m.select) in devices._fixed_values(_dev(d.node_id, d.name), m.data_type.name).selects]
        assert senders, f"{spec}: no simulated device sends the select values of {m.name}"
    if spec in ("sam", "seiner"):
        assert len(routed) >= 2
