"""Read a run's MCAP recording into per-topic time series, whatever state the file is in.

Invariants:

- Messages come back per topic in log-time order, timed in seconds since the recording's first message.
- A file that is not an MCAP at all (no magic), or of which no message can be read, is a RecordingError naming the
  file; one that was cut short (a killed run, a full disk) or has a corrupt tail gives every message read before the
  damage, and says so in `problems`.
- A message that does not decode is counted per topic (`problems` names the topic and the count), never raised.
- A namespaced run's recording (issue 30) is read with the names it used (its recorder metadata,
  sam_runtime.common.run_names): `Recording.get` takes SAM's topic name and finds the channel the run recorded it
  on (under its namespace when the spec names it relative); `names` gives the frame prefix and namespace to take
  off frame ids and status names.
- Needs `mcap` and `mcap-ros2-support` (the `runtime` extra), imported when a file is read.
"""

from __future__ import annotations

from collections import Counter, defaultdict
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any

from sam_runtime.common.ros_namespace import RosNamespace
from sam_runtime.common.run_names import RECORDING_METADATA, run_names

__all__ = ["MCAP_MAGIC", "Recording", "RecordingError", "read_recording"]

MCAP_MAGIC = b"\x89MCAP0\r\n"


class RecordingError(Exception):
    """The file cannot be read as a recording at all."""


@dataclass
class Recording:
    path: Path
    series: dict[str, list[tuple[float, Any]]] = field(default_factory=dict)  # topic -> (s since start, message)
    types: dict[str, str] = field(default_factory=dict)  # topic -> ROS type (sensor_msgs/msg/Imu)
    start_ns: int = 0
    end_s: float = 0.0
    problems: list[str] = field(default_factory=list)
    names: RosNamespace = field(default_factory=RosNamespace)  # the run's namespace and frame prefix

    def get(self, topic: str) -> list[tuple[float, Any]]:
        """A topic's messages, by the name SAM's spec gives it: the run's own first (a spec with relative names
        recorded under the run's namespace: /sam1/pressure for /pressure), else as written."""
        return self.series.get(self.names.resolve(topic.lstrip("/"))) or self.series.get(topic, [])


_METADATA_SCAN = 256  # records: the recorder writes its metadata before the first chunk closes


def _recorded_names(stream: IO[bytes]) -> RosNamespace:
    """The run's names from the recorder's metadata record near the file's start (chunks are not opened); the root
    namespace when there is none or the start is unreadable."""
    from mcap.records import Metadata
    from mcap.stream_reader import StreamReader

    try:
        for k, r in enumerate(StreamReader(stream, skip_magic=False, emit_chunks=True).records):
            if isinstance(r, Metadata) and r.name == RECORDING_METADATA:
                return run_names(dict(r.metadata))
            if k >= _METADATA_SCAN:
                break
    except Exception:  # a damaged start: the messages' reader reports it
        pass
    return RosNamespace()


def _messages(stream: IO[bytes], topics: list[str] | None, problems: list[str]
              ) -> Iterator[tuple[Any, Any, Any]]:
    """(schema, channel, message) of every readable record: from the summary's index when the file is whole, else
    streamed from the start until the damage."""
    from mcap.reader import NonSeekingReader, SeekingReader

    count = 0
    try:
        reader = SeekingReader(stream)
        if reader.get_summary() is not None:
            yield from reader.iter_messages(topics=topics, log_time_order=True)
            return
    except Exception as exc:  # a damaged summary or index: stream the records instead
        problems.append(f"its index is unreadable ({type(exc).__name__})")
    stream.seek(0)
    try:
        # in file order: log_time_order would read the whole file before yielding anything (sorted after)
        for schema, channel, message in NonSeekingReader(stream).iter_messages(topics=topics, log_time_order=False):
            count += 1
            yield schema, channel, message
    except Exception as exc:  # a truncated or corrupt tail: keep what came before it
        problems.append(f"it is cut short or damaged after {count} messages ({type(exc).__name__}): "
                        "what was read before is shown")


def read_recording(path: Path, topics: Iterable[str] | None = None) -> Recording:
    """Every message of ``topics`` (default: all) decoded; see the module's invariants."""
    from mcap_ros2.decoder import DecoderFactory

    path = Path(path)
    try:
        stream = open(path, "rb")  # closed below, once the generator is drained
    except OSError as exc:
        raise RecordingError(f"cannot read {path}: {exc.strerror or exc}") from None
    rec = Recording(path)
    factory = DecoderFactory()
    decoders: dict[int, Callable[[bytes], Any] | None] = {}
    failed: Counter[str] = Counter()
    raw: dict[str, list[tuple[int, Any]]] = defaultdict(list)
    with stream:
        if stream.read(len(MCAP_MAGIC)) != MCAP_MAGIC:
            raise RecordingError(f"{path} is not an MCAP file (no MCAP magic at its start)")
        stream.seek(0)
        rec.names = _recorded_names(stream)
        stream.seek(0)
        # the spec's names and the run's resolved ones (a recording of an older version kept the spec's)
        wanted = sorted({n for t in topics for n in (t, rec.names.resolve(t.lstrip("/")))}) \
            if topics is not None else None
        for schema, channel, message in _messages(stream, wanted, rec.problems):
            if schema is None:
                failed[channel.topic] += 1
                continue
            if schema.id not in decoders:
                try:
                    decoders[schema.id] = factory.decoder_for(channel.message_encoding, schema)
                except Exception:  # an unreadable schema: its topic is counted as undecodable
                    decoders[schema.id] = None
            decode = decoders[schema.id]
            if decode is None:
                failed[channel.topic] += 1
                continue
            try:
                obj = decode(message.data)
            except Exception:  # one bad message is counted, the rest of the topic still plots
                failed[channel.topic] += 1
                continue
            rec.types.setdefault(channel.topic, schema.name)
            raw[channel.topic].append((message.log_time, obj))
    if not raw and rec.problems:
        raise RecordingError(f"no message of {path} could be read: {'; '.join(rec.problems)}")
    for topic, count in sorted(failed.items()):
        rec.problems.append(f"{topic}: {count} message{'s' if count != 1 else ''} could not be decoded")
    if raw:
        rec.start_ns = min(t for items in raw.values() for t, _ in items)
    for topic, items in raw.items():
        items.sort(key=lambda item: item[0])
        rec.series[topic] = [((t - rec.start_ns) / 1e9, obj) for t, obj in items]
    rec.end_s = max((items[-1][0] for items in rec.series.values() if items), default=0.0)
    return rec
