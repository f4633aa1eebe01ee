"""`source_node_ids: any` at run time (issue 17 class 6), on tests/specs/seiner.yaml through the bridge's own
inbound path (OfflineBridge: the live bridge's groups, source filter, select routing and counters, the generated
codecs), both protocols: a node id the spec never names is accepted by an `any` mapping and routed by the ids in
its message, and what no mapping selects is still counted (`unselected`), never silent."""

from __future__ import annotations

import struct
from typing import Any

import pytest

pytest.importorskip("rclpy")
pytest.importorskip("dronecan")

from helpers.runtime_support import generated_or_skip
from helpers.spec_build import generated_spec

from sam_runtime.bridge.inbound import accepts
from sam_runtime.bridge.offline import OfflineBridge
from sam_runtime.genpkg import GeneratedPackage

RX = 1_700_000_000_123_456_789


@pytest.fixture(scope="module")
def gen() -> Any:
    return GeneratedPackage(generated_spec("seiner"))


def _vector3(cdr: bytes) -> tuple[float, float, float]:
    return struct.unpack_from("<3d", cdr, 4)  # the CDR header, then x, y, z (8-aligned from the header's end)


def test_any_node_takes_a_node_the_spec_never_names(gen: Any) -> None:
    import dronecan
    from dronecan import transport

    bridge = OfflineBridge(gen, protocol="dronecan")
    status = dronecan.TYPENAMES["uavcan.equipment.esc.Status"]

    def payload(esc_index: int, rpm: int) -> bytes:
        return bytes(transport.Transfer(payload=status(esc_index=esc_index, rpm=rpm, temperature=300.0)).payload)

    # node 77 is no device of the spec (dynamic node id allocation): routed by esc_index alone
    out = bridge.feed(1034, payload(1, 4321), 77, 1, 0.0, RX)
    assert [(p.topic, p.mapping) for p in out] == [("/esc1/status", "esc1_status")]
    assert _vector3(out[0].cdr) == (4321.0, 1.0, 300.0)  # the select field is published too (class 7)
    out = bridge.feed(1034, payload(0, -55), 30, 1, 0.0, RX)  # a declared device, the other index
    assert [p.topic for p in out] == ["/esc0/status"] and _vector3(out[0].cdr) == (-55.0, 0.0, 300.0)
    assert bridge.feed(1034, payload(9, 1), 78, 1, 0.0, RX) == []  # an index no mapping selects
    stats = bridge.stats()["mappings"]
    assert stats["esc1_status"]["published"] == 1 and stats["esc0_status"]["published"] == 1
    assert stats["esc0_status"]["dropped"] == {"unselected": 1}  # counted on the first mapping accepting node 78
    assert all("unknown_source" not in s["dropped"] for s in stats.values())


def test_any_node_on_cyphal(gen: Any) -> None:
    bridge = OfflineBridge(gen, protocol="cyphal")
    payload = bytes([7]) + struct.pack("<f", 12.5)  # seiner.Winch.0.1: winch_id uint8, tension float32
    for node_id, tid in ((40, 1), (99, 1), (3, 1), (99, 2)):  # the winch, then nodes the spec never names
        out = bridge.feed(700, payload, node_id, tid, 0.0, RX)
        assert [p.topic for p in out] == ["/winch/tension"], node_id
        assert struct.unpack_from("<f", out[0].cdr, 4) == (12.5,)
    winch = bridge.stats()["mappings"]["winch"]
    assert winch["published"] == 4 and winch["dropped"] == {}


def test_static_ids_stay_static(gen: Any) -> None:
    """Only the mappings that say `any` accept every node: the others' filter is what it was (SAM's spec)."""
    tables = gen.tables()
    infos = {m.name: m for m in (*tables.MAPPINGS, *tables.DRONECAN_MAPPINGS)}
    assert accepts(infos["esc0_status"], 77) and accepts(infos["winch"], 99)
    assert not accepts(infos["esc0_status"], None)  # an anonymous transfer has no node to accept
    sam = {m.name: m for m in generated_or_skip().tables().DRONECAN_MAPPINGS}
    assert not sam["thruster_1_feedback"].any_node
    assert accepts(sam["thruster_1_feedback"], 21) and not accepts(sam["thruster_1_feedback"], 77)
