"""The bridge's inbound path offline (what replay runs): the live bridge's source filter, select routing, loss and
drop counters and codecs, on the generated SAM package, without a bus or ROS."""

from __future__ import annotations

from typing import Any

import pytest

pytest.importorskip("rclpy")
pytest.importorskip("dronecan")

from helpers.runtime_support import generated_or_skip

from sam_runtime.bridge.offline import RECEIVE_TIME_PROBE_NS, OfflineBridge

RX = 1_700_000_000_123_456_789


@pytest.fixture(scope="module")
def gen() -> Any:
    return generated_or_skip()


@pytest.mark.ros  # the bridge builds the ROS messages: needs the built sam_msgs (not in the unit tier)
def test_cyphal_transfers_become_what_the_bridge_publishes(gen: Any) -> None:
    bridge = OfflineBridge(gen)
    codec = gen.codec("cyphal")
    payload = bytes(range(40))
    out = bridge.feed(1100, payload, 11, 1, 0.0, RX)
    assert [(p.topic, p.ros_type, p.mapping) for p in out] == [("/imu", "sensor_msgs/msg/Imu", "imu")]
    assert out[0].cdr == codec.CODECS["imu"][0](payload, RX, _Stats())[0]
    assert bridge.feed(1100, payload, 99, 2, 0.01, RX) == []  # not the imu's node: dropped as the bridge drops it
    assert bridge.feed(1100, payload, 11, 5, 0.02, RX)  # transfer ids 2..4 of node 11 never came
    assert bridge.feed(4000, payload, 11, 1, 0.0, RX) == []  # no mapping's port
    imu = bridge.stats()["mappings"]["imu"]
    assert imu["published"] == 2 and imu["dropped"] == {"unknown_source": 1, "lost": 3}


@pytest.mark.ros  # the bridge builds the ROS messages: needs the built sam_msgs (not in the unit tier)
def test_the_probe_tells_receive_time_fields(gen: Any) -> None:
    """/pressure is stamped with the receive time: the probe conversion differs; /imu carries the device's."""
    bridge = OfflineBridge(gen)
    pressure = bridge.feed(1103, bytes(16), 14, 1, 0.0, RX)[0]
    assert pressure.cdr != pressure.cdr_later
    assert gen.codec("cyphal").CODECS["pressure"][0](bytes(16), RX + RECEIVE_TIME_PROBE_NS, _Stats())[0] == \
        pressure.cdr_later
    imu = bridge.feed(1100, bytes(range(1, 41)), 11, 1, 0.0, RX)[0]
    assert imu.cdr == imu.cdr_later


@pytest.mark.ros  # the bridge builds the ROS messages: needs the built sam_msgs (not in the unit tier)
def test_dronecan_select_routes_by_source_and_field(gen: Any) -> None:
    import dronecan
    from dronecan import transport

    bridge = OfflineBridge(gen, layout="dronecan")
    status = dronecan.TYPENAMES["uavcan.equipment.esc.Status"]

    def payload(esc_index: int) -> bytes:
        return bytes(transport.Transfer(payload=status(esc_index=esc_index, rpm=321)).payload)

    assert [p.topic for p in bridge.feed(1034, payload(0), 21, 1, 0.0, RX)] == ["/thruster_1/feedback"]
    assert [p.topic for p in bridge.feed(1034, payload(1), 22, 1, 0.0, RX)] == ["/thruster_2/feedback"]
    assert bridge.feed(1034, payload(1), 21, 2, 0.01, RX) == []  # node 21 with esc_index 1: no mapping selects it
    stats = bridge.stats()["mappings"]
    assert stats["thruster_1_feedback"]["dropped"] == {"unselected": 1}
    assert stats["thruster_2_feedback"]["published"] == 1


class _Stats:
    def saturate(self, key: str) -> None:
        pass

    def reject(self, key: str) -> None:
        pass

    def reject_nan(self, key: str) -> None:
        pass


def test_the_dronecan_listener_records_every_transfer_checked() -> None:
    """Messages and services, multi-frame ones CRC-checked with the data type's signature, as dronecan checks."""
    import dronecan
    from dronecan import transport
    from dronecan.driver.common import CANFrame

    from sam_runtime.dronecan_io.drops import DropCounter
    from sam_runtime.recording.recorder import DroneCanTaps
    from sam_runtime.recording.schemas import KIND_MESSAGE, KIND_REQUEST

    got: list[Any] = []
    taps = DroneCanTaps(DropCounter(), got.append)

    def frames(t: Any) -> list[CANFrame]:
        return [CANFrame(f.message_id, bytearray(f.bytes), True) for f in t.to_frames()]

    raw_imu = dronecan.TYPENAMES["uavcan.equipment.ahrs.RawIMU"]
    imu = transport.Transfer(payload=raw_imu(), source_node_id=11, transfer_id=5, transfer_priority=20,
                             service_not_message=False)
    assert taps.take(frames(imu))
    info = dronecan.TYPENAMES["uavcan.protocol.GetNodeInfo"]
    request = transport.Transfer(payload=info.Request(), source_node_id=100, dest_node_id=21, transfer_id=3,
                                 transfer_priority=30, service_not_message=True, request_not_response=True)
    assert taps.take(frames(request))
    bad = frames(imu)
    bad[0].data[0] ^= 0xFF  # the transfer CRC
    assert taps.take(bad)
    assert [(t.kind, t.port_id, t.data_type, t.source_node_id, t.destination_node_id, t.transfer_id, t.priority)
            for t in got] == [(KIND_MESSAGE, 1003, "uavcan.equipment.ahrs.RawIMU", 11, None, 5, 20),
                              (KIND_REQUEST, 1, "uavcan.protocol.GetNodeInfo", 100, 21, 3, 30)]
    assert got[0].payload == bytes(imu.payload) and got[0].data_type_signature == raw_imu.get_data_type_signature()
    assert dict(taps.crc_failures) == {"uavcan.equipment.ahrs.RawIMU": 1}


def test_dronecan_payloads_decode_from_the_attached_definitions_alone(gen: Any, tmp_path: Any) -> None:
    """The .uavcan files a recording attaches parse on their own (dronecan's parser, nothing else loaded from it)
    and decode what the listener recorded, down to the signature that seeds the CRC."""
    import dronecan
    from dronecan import dsdl, transport

    from sam_runtime.dronecan_io.types import ensure_types
    from sam_runtime.recording.schemas import dronecan_definition_files

    ensure_types(gen)
    names = ["uavcan.equipment.ahrs.RawIMU", "uavcan.equipment.esc.Status", "sam.sensor.Altitude"]
    files = dronecan_definition_files([dronecan.TYPENAMES[n] for n in names])
    for name, data in files.items():
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_bytes(data)
    roots = sorted(str(p) for p in (tmp_path / "dsdl_v0").iterdir())
    parsed = {t.full_name: t for t in dsdl.parse_namespaces(roots)}
    assert set(names) <= set(parsed)
    sent = dronecan.TYPENAMES["uavcan.equipment.ahrs.RawIMU"](rate_gyro_latest=[0.5, -1.0, 2.0],
                                                               integration_interval=0.01)
    payload = bytes(transport.Transfer(payload=sent).payload)
    got = transport.CompoundValue(parsed["uavcan.equipment.ahrs.RawIMU"], None)
    got._unpack(transport.bits_from_bytes(bytearray(payload)), True)
    assert list(got.rate_gyro_latest) == [0.5, -1.0, 2.0]
    assert got.integration_interval == pytest.approx(0.01)
    for n in names:
        assert parsed[n].get_data_type_signature() == dronecan.TYPENAMES[n].get_data_type_signature()


def test_rate_limit_runs_on_the_recorded_times() -> None:
    """tests/specs/weir.yaml: `level` at most 4 Hz, trailing edge, on the transfers' recorded receive times;
    `level_raw` starts disabled (dropped, counted); what is still held comes out of finish()."""
    from helpers.spec_build import generated_spec

    from sam_runtime.genpkg import GeneratedPackage

    gen = GeneratedPackage(generated_spec("weir"))
    bridge = OfflineBridge(gen)
    codec = gen.codec("cyphal")
    times = [10.0 + 0.02 * i for i in range(30)]  # 50 Hz for 0.6 s: slots at 10.0, 10.25, 10.5
    outs = [bridge.feed(100, bytes([i, 0, 0]), 10, i, t, RX + i) for i, t in enumerate(times)]
    published = [(i, p.mapping) for i, out in enumerate(outs) for p in out]
    # at once at 10.0; the one held at 10.24 out at its slot 10.25, with the next feed (10.26); the one held at
    # 10.48 at its slot 10.5, with the transfer of 10.5 (before it: that one is held in turn)
    assert published == [(0, "level"), (13, "level"), (25, "level")]
    assert outs[13][0].cdr == codec.CODECS["level"][0](bytes([12, 0, 0]), RX + 12, _Stats())[0]
    assert outs[25][0].cdr == codec.CODECS["level"][0](bytes([24, 0, 0]), RX + 24, _Stats())[0]
    last = bridge.finish()
    assert [p.mapping for p in last] == ["level"] and bridge.finish() == []
    assert last[0].cdr == codec.CODECS["level"][0](bytes([29, 0, 0]), RX + 29, _Stats())[0]
    st = bridge.stats()["mappings"]
    assert st["level"]["published"] == 4 and st["level"]["dropped"] == {"rate_limited": 26}
    assert st["level_raw"]["published"] == 0 and st["level_raw"]["dropped"] == {"disabled": 30}
