"""The recording's file, without processes: the envelope and the ROS definitions decode with the stock readers
(mcap-ros2-support, rosbags), a cut or a full-disk file reads up to its last chunk with both, an unwritable path is
one clear error, and the replay's report tells identical, receive-time-only, differing, missing and extra apart."""

from __future__ import annotations

import errno
import io
from pathlib import Path
from types import SimpleNamespace as NS
from typing import Any

import pytest

pytest.importorskip("mcap")
pytest.importorskip("mcap_ros2")

from mcap.records import Schema
from mcap.stream_reader import StreamReader
from mcap_ros2.decoder import DecoderFactory
from rosbags.rosbag2 import Reader
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from sam_codegen.catalogs.ros import ros_share_dirs
from sam_runtime.cli_support import EXIT_ERROR, EXIT_USAGE
from sam_runtime.main_job.record_replay import replay_main
from sam_runtime.recording.reading import MCAP_MAGIC, read_recording, rosbag2_folder
from sam_runtime.recording.replay import field_differences, replay
from sam_runtime.recording.schemas import (
    CYPHAL_TOPIC,
    ROS_LOST_METADATA,
    TRANSFER_MSG,
    TRANSFER_TYPE,
    Transfer,
    decode_transfer,
    encode_transfer,
    qos_yaml,
    ros2msg_definition,
)
from sam_runtime.recording.target import RecordingTargetError, check_target
from sam_runtime.recording.writer import RecordingWriter

JAZZY = get_typestore(Stores.ROS2_JAZZY)
GENERATED = Path(__file__).resolve().parents[3] / "generated"
IMU = "sensor_msgs/msg/Imu"


def _imu_cdr(sec: int, frame: str = "imu_link", x: float = 0.0) -> bytes:
    t = JAZZY.types
    hdr = t["std_msgs/msg/Header"](stamp=t["builtin_interfaces/msg/Time"](sec=sec, nanosec=5), frame_id=frame)
    q = t["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0)
    v = t["geometry_msgs/msg/Vector3"](x=x, y=0.0, z=0.0)
    import numpy as np

    msg = t[IMU](header=hdr, orientation=q, orientation_covariance=np.zeros(9), angular_velocity=v,
                 angular_velocity_covariance=np.zeros(9), linear_acceleration=v,
                 linear_acceleration_covariance=np.zeros(9))
    return bytes(JAZZY.serialize_cdr(msg, IMU))


def _transfer(i: int) -> Transfer:
    return Transfer("cyphal", 1100, "sam.sensor.RawIMU.0.1", 11, i, 4, 1_000_000_000 + i, bytes([i % 256]) * 9)


def _write(path: Path, n: int, *, chunk_size: int = 2048, stream: Any = None) -> RecordingWriter:
    w = RecordingWriter(path, chunk_size=chunk_size, stream=stream)
    w.add_channel("/imu", IMU, "ros2msg", ros2msg_definition(IMU, ros_share_dirs()),
                  metadata={"offered_qos_profiles": qos_yaml("best_effort", "volatile", 10)})
    w.add_channel(CYPHAL_TOPIC, TRANSFER_TYPE, "ros2msg", TRANSFER_MSG)
    w.add_attachment("dsdl/sam/sensor/RawIMU.0.1.dsdl", b"# a definition\n")
    w.add_metadata("sam_codegen.recording", {"format": "sam-recording/1"})
    for i in range(n):
        w.write("/imu", _imu_cdr(i), 1_000_000_000 + i, 999_000_000 + i)
        w.write(CYPHAL_TOPIC, encode_transfer(_transfer(i)), 1_000_000_000 + i)
    return w


def test_the_envelope_decodes_with_both_stock_readers() -> None:
    t = Transfer("dronecan", 1034, "uavcan.equipment.esc.Status", 21, 31, 16, 123456789, b"\x01\x02\x03", 0, None,
                 0xA9AF28AEA2FBB254)
    data = encode_transfer(t)
    assert decode_transfer(data) == t
    schema = Schema(id=1, name=TRANSFER_TYPE, encoding="ros2msg", data=TRANSFER_MSG.encode())
    got = DecoderFactory().decoder_for("cdr", schema)(data)
    assert (got.protocol, got.port_id, got.data_type, got.source_node_id, got.destination_node_id, got.transfer_id,
            got.priority, got.timestamp_ns, bytes(got.payload), got.data_type_signature) == (
        "dronecan", 1034, "uavcan.equipment.esc.Status", 21, -1, 31, 16, 123456789, b"\x01\x02\x03",
        0xA9AF28AEA2FBB254)
    store = get_typestore(Stores.ROS2_JAZZY)
    store.register(get_types_from_msg(TRANSFER_MSG, TRANSFER_TYPE))
    assert bytes(store.deserialize_cdr(data, TRANSFER_TYPE).payload) == b"\x01\x02\x03"


def test_ros_definitions_are_concatenated_as_rosbag2_writes_them() -> None:
    text = ros2msg_definition(IMU, ros_share_dirs())
    assert [ln for ln in text.splitlines() if ln.startswith("MSG: ")] == [
        "MSG: std_msgs/Header", "MSG: builtin_interfaces/Time", "MSG: geometry_msgs/Quaternion",
        "MSG: geometry_msgs/Vector3"]
    assert "=" * 80 + "\nMSG: std_msgs/Header\n" in text
    schema = Schema(id=1, name=IMU, encoding="ros2msg", data=text.encode())
    got = DecoderFactory().decoder_for("cdr", schema)(_imu_cdr(7, x=2.5))
    assert (got.header.stamp.sec, got.header.frame_id, got.angular_velocity.x) == (7, "imu_link", 2.5)


def test_a_complete_file_reads_with_mcap_and_rosbags(tmp_path: Path) -> None:
    path = tmp_path / "run.mcap"
    _write(path, 200).close()
    rec = read_recording(path)
    assert rec.complete and len(rec.by_topic()["/imu"]) == 200
    assert [t.transfer_id for _, t in rec.transfers()] == list(range(200))
    assert rec.attachments == {"dsdl/sam/sensor/RawIMU.0.1.dsdl": b"# a definition\n"}
    assert rec.metadata["sam_codegen.recording"] == {"format": "sam-recording/1"}
    from mcap.reader import make_reader

    with open(path, "rb") as fh:
        reader = make_reader(fh)
        assert reader.get_header().profile == "ros2"
        counts = reader.get_summary().statistics.channel_message_counts
        assert sorted(counts.values()) == [200, 200]
    with Reader(rosbag2_folder(path, tmp_path / "bag")) as bag:
        assert {c.topic: c.msgcount for c in bag.connections} == {"/imu": 200, CYPHAL_TOPIC: 200}
        imu = next(c for c in bag.connections if c.topic == "/imu")
        stamps = [JAZZY.deserialize_cdr(raw, IMU).header.stamp.sec for _, _, raw in bag.messages([imu])]
        assert stamps == list(range(200))


def test_a_cut_file_reads_up_to_its_last_chunk(tmp_path: Path) -> None:
    """What SIGKILL leaves: no summary, no footer, the last chunk cut in the middle."""
    path = tmp_path / "cut.mcap"
    w = _write(path, 300)  # never closed: chunks of 2 KiB are in the file, the one in progress is not
    size = path.stat().st_size
    assert size > 10_000
    with open(path, "r+b") as fh:
        fh.truncate(size - 700)  # into the last chunk written
    rec = read_recording(path)
    assert not rec.complete and rec.stopped_by
    imu = rec.by_topic()["/imu"]
    assert 100 < len(imu) < 300
    assert [m.log_time for m in imu] == [1_000_000_000 + i for i in range(len(imu))]  # a prefix, in order
    # mcap's own streaming reader gives the same messages before it meets the cut
    seen = 0
    with open(path, "rb") as fh, pytest.raises(Exception):  # noqa: B017  (its error at the cut)
        for r in StreamReader(fh).records:
            seen += type(r).__name__ == "Message"
    assert seen == len(rec.messages)
    with Reader(rosbag2_folder(path, tmp_path / "bag")) as bag:  # rosbags: through the recovered copy
        counts = {c.topic: c.msgcount for c in bag.connections}
        assert counts["/imu"] == len(imu)
        assert sum(1 for _ in bag.messages()) == len(rec.messages)
    del w


class _FullDisk(io.RawIOBase):
    """A file on a disk that fills up after ``room`` bytes."""

    def __init__(self, path: Path, room: int) -> None:
        self._fh = open(path, "wb", buffering=0)
        self.room = room

    def writable(self) -> bool:
        return True

    def write(self, data: Any) -> int:
        if self._fh.tell() + len(data) > self.room:
            raise OSError(errno.ENOSPC, "No space left on device")
        return int(self._fh.write(data))

    def tell(self) -> int:
        return int(self._fh.tell())

    def close(self) -> None:
        self._fh.close()
        super().close()


def test_a_full_disk_stops_the_recording_counted_never_raised(tmp_path: Path,
                                                               caplog: pytest.LogCaptureFixture) -> None:
    path = tmp_path / "full.mcap"
    w = _write(path, 400, stream=_FullDisk(path, 20_000))
    assert w.error is not None and "No space left" in w.error
    assert w.not_recorded > 0
    assert w.written["/imu"] + w.written[CYPHAL_TOPIC] + w.not_recorded == 800
    w.close()  # no raise either
    assert sum(1 for r in caplog.records if "stopped" in r.getMessage()) == 1  # logged once
    rec = read_recording(path)
    # everything counted as written before the error is there (the message whose write met it may be too)
    assert 0 < w.written["/imu"] + w.written[CYPHAL_TOPIC] - 2 * 10 <= len(rec.messages)
    assert len(rec.messages) <= w.written["/imu"] + w.written[CYPHAL_TOPIC] + 1


def test_an_unwritable_path_is_one_clear_error(tmp_path: Path) -> None:
    with pytest.raises(RecordingTargetError, match="does not exist"):
        check_target(tmp_path / "no" / "such" / "x.mcap")
    with pytest.raises(RecordingTargetError, match="is a folder"):
        check_target(tmp_path)
    with pytest.raises(RecordingTargetError, match="not writable"):
        check_target(Path("/proc/sys/x.mcap"))  # read-only even for root
    assert check_target(tmp_path / "ok.mcap") == tmp_path / "ok.mcap"
    assert not (tmp_path / "ok.mcap").exists()


# ============================================================================================ replay report
class _FakeConverter:
    """Publishes /imu per transfer: the recorded message, changed as ``change`` says for some transfer ids."""

    protocol = "cyphal"

    def __init__(self, change: dict[int, str]) -> None:
        self.change = change

    @property
    def topics(self) -> dict[str, str]:
        return {"/imu": IMU}

    def feed(self, port_id: int, payload: bytes, src: int | None, tid: int, mono: float, rx: int) -> list[Any]:
        how = self.change.get(tid, "same")
        if how == "drop":
            return []
        cdr = _imu_cdr(tid, x=9.0 if how == "value" else 0.0) if how != "stamp" else _imu_cdr(tid + 1000)
        later = _imu_cdr(tid + 2000) if how == "stamp" else cdr  # the stamp follows the receive time
        out = [NS(topic="/imu", ros_type=IMU, cdr=cdr, cdr_later=later)]
        return out * 2 if how == "twice" else out

    def stats(self) -> dict[str, Any]:
        return {}


def test_the_report_classifies_every_message(tmp_path: Path) -> None:
    path = tmp_path / "run.mcap"
    _write(path, 10).close()
    same = replay(path, [_FakeConverter({})], out=tmp_path / "same.mcap")
    assert same.same and same.topics["/imu"].identical == 10
    assert len(read_recording(tmp_path / "same.mcap").by_topic()["/imu"]) == 10
    mixed = replay(path, [_FakeConverter({2: "stamp", 4: "value"})]).topics["/imu"]
    assert (mixed.identical, mixed.receive_time, mixed.differing) == (8, 1, 1)
    assert dict(mixed.fields) == {"angular_velocity.x": 1, "linear_acceleration.x": 1}
    assert set(mixed.receive_time_fields) == {"header.stamp.sec"}
    short = replay(path, [_FakeConverter({9: "drop"})])
    assert not short.same and short.topics["/imu"].missing == 1
    extra = replay(path, [_FakeConverter({9: "twice"})])
    assert extra.topics["/imu"].extra == 1
    assert "DIFFERENT" in extra.lines()[-1]


def test_messages_the_recorder_lost_are_no_difference_up_to_its_count(tmp_path: Path) -> None:
    """A best-effort subscription loses messages silently on a loaded machine; the recorder counts the gaps in the
    publisher's sequence numbers (ROS_LOST_METADATA). Replay shows those messages as extra, and only as many as the
    recorder counted are no difference."""

    def recording(name: str, skip: set[int], lost: dict[str, str] | None) -> Path:
        path = tmp_path / name
        w = RecordingWriter(path)
        w.add_channel("/imu", IMU, "ros2msg", ros2msg_definition(IMU, ros_share_dirs()),
                      metadata={"offered_qos_profiles": qos_yaml("best_effort", "volatile", 10)})
        w.add_channel(CYPHAL_TOPIC, TRANSFER_TYPE, "ros2msg", TRANSFER_MSG)
        for i in range(60):
            if i not in skip:
                w.write("/imu", _imu_cdr(i), 1_000_000_000 + i, 999_000_000 + i)
            w.write(CYPHAL_TOPIC, encode_transfer(_transfer(i)), 1_000_000_000 + i)
        if lost is not None:
            w.add_metadata(ROS_LOST_METADATA, lost)
        w.close()
        return path

    counted = replay(recording("counted.mcap", {30}, {"/imu": "1"}), [_FakeConverter({})])
    imu = counted.topics["/imu"]
    assert (imu.identical, imu.missing, imu.extra, imu.lost_by_recorder, counted.same) == (59, 0, 1, 1, True)
    assert any("lost by the recorder" in line and "/imu 1" in line for line in counted.lines())
    uncounted = replay(recording("uncounted.mcap", {30}, {}), [_FakeConverter({})])
    assert uncounted.topics["/imu"].extra == 1 and not uncounted.same
    more = replay(recording("more.mcap", {30, 40}, {"/imu": "1"}), [_FakeConverter({})])
    assert more.topics["/imu"].extra == 2 and not more.same


def test_a_recorder_that_ran_late_at_the_start_is_still_matched(tmp_path: Path) -> None:
    """The recorder's callbacks may run late on a loaded machine: its first messages then carry log times long
    after their transfers', in one burst (a CI run had 0.4 s). The receive times that were not delayed say where
    the recorded messages stand among the replayed ones; the burst's would put them 60 messages too late."""
    path, step = tmp_path / "late.mcap", 10_000_000  # 100 Hz
    w = RecordingWriter(path)
    w.add_channel("/imu", IMU, "ros2msg", ros2msg_definition(IMU, ros_share_dirs()),
                  metadata={"offered_qos_profiles": qos_yaml("best_effort", "volatile", 10)})
    w.add_channel(CYPHAL_TOPIC, TRANSFER_TYPE, "ros2msg", TRANSFER_MSG)
    w.add_metadata("sam_codegen.recording", {"format": "sam-recording/1"})
    rows = []
    for i in range(200):
        t = 1_000_000_000 + i * step
        rows.append((t, CYPHAL_TOPIC, encode_transfer(_transfer(i))))  # the converter publishes _imu_cdr(tid)
        if i >= 20:  # the ROS side began at the 20th transfer; the first 60 it got were handed over at once
            late = 1_000_000_000 + 80 * step + 500_000 + i * 1_000 if i < 80 else t + 1_000_000
            rows.append((late, "/imu", _imu_cdr(i)))
    for t, topic, data in sorted(rows, key=lambda r: r[0]):
        w.write(topic, data, t, t)
    w.close()
    imu = replay(path, [_FakeConverter({})]).topics["/imu"]
    assert (imu.identical, imu.differing, imu.missing, imu.extra, imu.before) == (180, 0, 0, 0, 20)


def test_field_differences_names_paths() -> None:
    schema = Schema(id=1, name=IMU, encoding="ros2msg", data=ros2msg_definition(IMU, ros_share_dirs()).encode())
    dec = DecoderFactory().decoder_for("cdr", schema)
    assert field_differences(dec, _imu_cdr(1), dec, _imu_cdr(1)) == []
    assert field_differences(dec, _imu_cdr(1), dec, _imu_cdr(1, frame="x")) == ["header.frame_id"]
    assert field_differences(dec, b"junk", dec, _imu_cdr(1)) == ["<undecodable>"]


def test_a_file_that_is_no_mcap_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "notes.mcap"
    path.write_text("not a recording\n")
    with pytest.raises(ValueError, match="is not an MCAP file"):
        read_recording(path)


def test_replay_at_the_recorded_pace_takes_the_recorded_time(tmp_path: Path) -> None:
    path = tmp_path / "paced.mcap"
    w = RecordingWriter(path)
    w.add_channel(CYPHAL_TOPIC, TRANSFER_TYPE, "ros2msg", TRANSFER_MSG)
    for i in range(6):  # 0.1 s apart
        w.write(CYPHAL_TOPIC, encode_transfer(_transfer(i)), 1_000_000_000 + i * 100_000_000)
    w.close()
    paced = replay(path, [_FakeConverter({})], speed="recorded")
    assert paced.recorded_span_s == pytest.approx(0.5)
    assert paced.replay_s >= 0.45  # never faster than recorded (a loaded machine may make it slower)
    assert replay(path, [_FakeConverter({})], speed="max").replay_s < paced.replay_s


def _damage_attachments(path: Path) -> int:
    """Overwrite the name length of every attachment record with 2^32 - 1 (a flipped field inside the record, its
    own length prefix intact); returns how many were damaged."""
    data = bytearray(path.read_bytes())
    pos, damaged = len(MCAP_MAGIC), 0
    while pos + 9 <= len(data):
        opcode, length = data[pos], int.from_bytes(data[pos + 1:pos + 9], "little")
        if opcode == 0x09:  # Attachment: log_time u64, create_time u64, name (u32 length + bytes), ...
            data[pos + 9 + 16:pos + 9 + 20] = b"\xff\xff\xff\xff"
            damaged += 1
        if opcode == 0x02:  # the footer
            break
        pos += 9 + length
    path.write_bytes(bytes(data))
    return damaged


def test_damaged_attachment_records_are_skipped_and_counted(tmp_path: Path) -> None:
    """Issue 29 item 12: two damaged attachment records (before the data, where the recorder writes them) stopped
    the reading there, and replay said the file held no UAVCAN transfers (recorded with --no-bus?) while `plot` read
    its 2,955. Each record is parsed from its own bytes: the damaged ones are skipped and counted, the rest read."""
    path = tmp_path / "damaged.mcap"
    w = _write(path, 200)
    w.add_attachment("dsdl/uavcan/node/Heartbeat.1.0.dsdl", b"# another\n")
    w.close()
    assert _damage_attachments(path) == 2
    rec = read_recording(path)
    assert rec.damaged == {"attachment": 2} and rec.damage() == "2 attachment records"
    assert rec.complete and rec.stopped_by is None
    assert len(rec.transfers()) == 200 and len(rec.by_topic()["/imu"]) == 200
    assert rec.attachments == {}


@pytest.mark.parametrize(("make", "error"), [
    (lambda tmp: tmp, "is a directory, not a recording"),
    (lambda tmp: Path("/dev/zero"), "is a character device, not a recording"),
    (lambda tmp: tmp / "nope.mcap", "no such file"),
], ids=["directory", "dev_zero", "missing"])
def test_replay_names_what_the_path_is(tmp_path: Path, capsys: pytest.CaptureFixture[str], make: Any,
                                       error: str) -> None:
    """A directory or /dev/zero was reported as "no such file"."""
    path = make(tmp_path)
    assert replay_main([str(path)]) == EXIT_USAGE
    err = capsys.readouterr().err
    assert err.startswith(f"sam-replay: {path}: {error}") and "Traceback" not in err


def test_replay_says_why_a_recording_gives_it_nothing(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The cause replay names: damaged records that held the bus, not --no-bus."""
    path = tmp_path / "damaged.mcap"
    w = RecordingWriter(path)
    w.add_attachment("dsdl/sam/sensor/RawIMU.0.1.dsdl", b"# a definition\n")
    w.add_channel("/imu", IMU, "ros2msg", ros2msg_definition(IMU, ros_share_dirs()))
    w.write("/imu", _imu_cdr(1), 1_000_000_001)
    w.close()
    _damage_attachments(path)
    assert replay_main([str(path), "--generated", str(GENERATED)]) == EXIT_ERROR
    err = capsys.readouterr().err.splitlines()
    assert err == [f"note: {path} has damaged records, skipped: 1 attachment record",
                   f"sam-replay: {path} holds no readable UAVCAN transfers: 1 attachment record could not be read"]
    intact = tmp_path / "ros_only.mcap"
    w = RecordingWriter(intact)
    w.add_channel("/imu", IMU, "ros2msg", ros2msg_definition(IMU, ros_share_dirs()))
    w.write("/imu", _imu_cdr(1), 1_000_000_001)
    w.close()
    assert replay_main([str(intact), "--generated", str(GENERATED)]) == EXIT_ERROR
    assert capsys.readouterr().err.splitlines() == [
        f"sam-replay: {intact} holds no UAVCAN transfers (recorded with --no-bus?)"]
