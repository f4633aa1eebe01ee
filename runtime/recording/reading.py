"""Reading a recording back, whole or cut short (a recorder killed mid-run), and laying it out for rosbags.

Invariants:

- :func:`read_recording` refuses a file that does not begin as an MCAP (ValueError), then streams it record by
  record (no summary or footer needed), each record parsed by mcap's record classes from its own bytes: a record
  whose body is damaged is skipped and counted in ``Recording.damaged`` (its length prefix still says where the next
  one starts), and the reading stops only where a record runs past the end of the file. A cut file yields every
  message of every complete chunk, in file order, and ``Recording.complete`` says whether the file ended with its
  footer.
- :func:`rosbag2_folder` makes a rosbag2 folder (what ``ros2 bag info/play`` and other rosbag2 readers open; rosbags
  0.11 also reads a bare MCAP that has its footer): the recording itself (a symbolic link, or the file as it is when
  it was written inside the folder, as ``sam-codegen record --rosbag2`` does) when complete, else a complete copy of
  everything readable (as ``mcap recover`` does; in place when written inside); the ``metadata.yaml`` lists the ROS
  topics (CDR) with their message counts and the file, as rosbag2 writes it (version 9).
"""

from __future__ import annotations

import io
import json
import os
import stat
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from sam_runtime.recording.schemas import TRANSFER_TYPE, Transfer, decode_transfer

__all__ = ["MCAP_MAGIC", "RecordedMessage", "Recording", "read_recording", "recording_file_problem", "rosbag2_folder"]

MCAP_MAGIC = b"\x89MCAP0\r\n"


@dataclass(frozen=True)
class RecordedMessage:
    topic: str
    log_time: int
    publish_time: int
    data: bytes
    sequence: int


@dataclass
class Recording:
    """What a recording holds, in file order."""

    schemas: dict[int, Any] = field(default_factory=dict)  # id -> mcap.records.Schema
    channels: dict[int, Any] = field(default_factory=dict)  # id -> mcap.records.Channel
    messages: list[RecordedMessage] = field(default_factory=list)
    attachments: dict[str, bytes] = field(default_factory=dict)
    metadata: dict[str, dict[str, str]] = field(default_factory=dict)
    complete: bool = False  # the file ended with its footer
    stopped_by: str | None = None  # why reading stopped early (a cut file)
    damaged: Counter[str] = field(default_factory=Counter)  # record kind -> records skipped as unreadable

    def damage(self) -> str:
        """The damaged records skipped, as words: `2 attachment records` ('' when none)."""
        return ", ".join(f"{n} {kind} record{'s' if n != 1 else ''}" for kind, n in sorted(self.damaged.items()))

    def schema_of(self, topic: str) -> Any:
        ch = next((c for c in self.channels.values() if c.topic == topic), None)
        return None if ch is None else self.schemas.get(ch.schema_id)

    def topics(self) -> dict[str, str]:
        """topic -> schema name (the ROS type)."""
        return {c.topic: (self.schemas[c.schema_id].name if c.schema_id in self.schemas else "")
                for c in self.channels.values()}

    def by_topic(self) -> dict[str, list[RecordedMessage]]:
        out: dict[str, list[RecordedMessage]] = {}
        for m in self.messages:
            out.setdefault(m.topic, []).append(m)
        return out

    def transfers(self) -> list[tuple[RecordedMessage, Transfer]]:
        """The raw bus: every recorded UAVCAN transfer with its envelope decoded, in file order."""
        raw = {c.topic for c in self.channels.values()
               if c.schema_id in self.schemas and self.schemas[c.schema_id].name == TRANSFER_TYPE}
        return [(m, decode_transfer(m.data)) for m in self.messages if m.topic in raw]


def recording_file_problem(path: Path) -> str | None:
    """What keeps `path` from being a recording to read, in words (`no such file`, `is a directory, not a
    recording`, ...); None for a regular file. A directory or /dev/zero is not "no such file"."""
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        return "no such file"
    except OSError as exc:
        return f"cannot be read: {exc.strerror or exc}"
    if stat.S_ISREG(mode):
        return None
    kinds = ((stat.S_ISDIR, "a directory"), (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
             (stat.S_ISFIFO, "a FIFO (named pipe)"), (stat.S_ISSOCK, "a socket"))
    kind = next((what for test, what in kinds if test(mode)), "not a regular file")
    return f"is {kind}, not a recording (expected an MCAP file, as `sam-codegen run --record FILE.mcap` writes)"


def read_recording(path: Path) -> Recording:
    """Everything readable in the file (see the module docstring)."""
    from mcap.data_stream import ReadDataStream
    from mcap.opcode import Opcode
    from mcap.records import Attachment, Channel, Chunk, Footer, Message, Metadata, Schema
    from mcap.stream_reader import breakup_chunk

    readers: dict[int, Any] = {Opcode.SCHEMA: Schema.read, Opcode.CHANNEL: Channel.read, Opcode.CHUNK: Chunk.read,
                               Opcode.ATTACHMENT: Attachment.read, Opcode.METADATA: Metadata.read,
                               Opcode.FOOTER: Footer.read}
    rec = Recording()
    topic_of: dict[int, str] = {}

    def take(r: Any) -> None:
        if isinstance(r, Schema):
            rec.schemas[r.id] = r
        elif isinstance(r, Channel):
            rec.channels[r.id] = r
            topic_of[r.id] = r.topic
        elif isinstance(r, Message):
            rec.messages.append(RecordedMessage(topic_of.get(r.channel_id, ""), r.log_time,
                                                r.publish_time, bytes(r.data), r.sequence))
        elif isinstance(r, Attachment):
            rec.attachments[r.name] = bytes(r.data)
        elif isinstance(r, Metadata):
            rec.metadata[r.name] = dict(r.metadata)

    with open(path, "rb") as fh:
        if fh.read(len(MCAP_MAGIC)) != MCAP_MAGIC:
            raise ValueError(f"{path} is not an MCAP file")
        # Record by record, each parsed from its own bytes (opcode, length, body): a record whose body is damaged
        # is skipped and counted, and cannot shift where the next one starts. Only a length that runs past the end
        # of the file (a cut file) stops the reading: everything before it is kept.
        while True:
            prefix = fh.read(9)
            if len(prefix) < 9:
                rec.stopped_by = "the file ends inside a record" if prefix else "the file ends without a footer"
                break
            opcode, length = prefix[0], int.from_bytes(prefix[1:], "little")
            body = fh.read(length) if length <= _MAX_RECORD_BYTES else b""
            if len(body) < length:
                rec.stopped_by = f"the file ends inside a {_record_kind(opcode)} record"
                break
            read = readers.get(opcode)
            if opcode == Opcode.MESSAGE:
                read = lambda stream, n=length: Message.read(stream, n)  # noqa: E731  (its data runs to the end)
            if read is None:
                continue  # indexes, statistics, the header: nothing a recording's reader needs
            try:
                stream = ReadDataStream(io.BytesIO(body))
                record = read(stream)
                records = breakup_chunk(record) if isinstance(record, Chunk) else [record]
            except Exception:  # a damaged record: its length still says where the next one starts
                rec.damaged[_record_kind(opcode)] += 1
                continue
            for r in records:
                take(r)
            if isinstance(record, Footer):
                rec.complete = True
                break  # only the closing magic follows
    return rec


# mcap's own reader refuses records above 4 GiB; a length beyond it is damage, not a record to read.
_MAX_RECORD_BYTES = 4 * 2 ** 30


def _record_kind(opcode: int) -> str:
    from mcap.opcode import Opcode

    try:
        return Opcode(opcode).name.lower()
    except ValueError:
        return f"opcode 0x{opcode:02x}"


def rosbag2_folder(mcap_path: Path, folder: Path) -> Path:
    """``folder`` holding the recording and a rosbag2 ``metadata.yaml`` (see the module docstring); returns it."""
    from mcap.writer import CompressionType, Writer

    mcap_path = Path(mcap_path).absolute()
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    rec = read_recording(mcap_path)
    target = folder / mcap_path.name
    in_place = target.absolute() == mcap_path  # recorded inside the folder: the file is the bag's own
    if not in_place and (target.exists() or target.is_symlink()):
        target.unlink()
    if rec.complete:
        if not in_place:
            os.symlink(mcap_path, target)
    else:
        recovered = target.with_name(target.name + ".recovering") if in_place else target
        with open(recovered, "wb") as fh:
            w = Writer(fh, compression=CompressionType.ZSTD)
            w.start(profile="ros2", library="sam-codegen recover")
            sids = {sid: w.register_schema(s.name, s.encoding, s.data) for sid, s in rec.schemas.items()}
            cids = {c.topic: w.register_channel(c.topic, c.message_encoding, sids.get(c.schema_id, 0), c.metadata)
                    for c in rec.channels.values()}
            for m in rec.messages:
                w.add_message(cids[m.topic], m.log_time, m.data, m.publish_time, m.sequence)
            for name, data in rec.attachments.items():
                w.add_attachment(0, 0, name, "text/plain", data)
            for name, meta in rec.metadata.items():
                w.add_metadata(name, meta)
            w.finish()
        if in_place:
            os.replace(recovered, target)
    counts = Counter(m.topic for m in rec.messages)
    times = [m.log_time for m in rec.messages] or [0]
    topics: list[dict[str, Any]] = []
    for c in rec.channels.values():
        if c.message_encoding != "cdr":
            continue
        qos = c.metadata.get("offered_qos_profiles", "")
        topics.append({"topic_metadata": {"name": c.topic, "type": rec.schemas[c.schema_id].name,
                                          "serialization_format": "cdr", "offered_qos_profiles": qos,
                                          "type_description_hash": ""},
                       "message_count": counts.get(c.topic, 0)})
    info: dict[str, Any] = {"rosbag2_bagfile_information": {
        "version": 9, "storage_identifier": "mcap", "relative_file_paths": [target.name],
        "duration": {"nanoseconds": max(times) - min(times)}, "starting_time": {"nanoseconds_since_epoch": min(times)},
        "message_count": sum(t["message_count"] for t in topics), "topics_with_message_count": topics,
        "compression_format": "", "compression_mode": "",
        "files": [{"path": target.name, "starting_time": {"nanoseconds_since_epoch": min(times)},
                   "duration": {"nanoseconds": max(times) - min(times)},
                   "message_count": sum(t["message_count"] for t in topics)}],
        "custom_data": {}, "ros_distro": "jazzy"}}
    # JSON is YAML: no YAML writer needed, and every string is quoted safely.
    (folder / "metadata.yaml").write_text(json.dumps(info, indent=1) + "\n")
    return folder
