"""The MCAP file of a recording, written so that whatever ends the writer leaves a readable file.

Invariants:

- The file is a chunked MCAP (profile ``ros2``, zstd chunks) written through an unbuffered file: a chunk is closed
  when it holds :data:`CHUNK_SIZE` bytes or :data:`CHUNK_INTERVAL_S` after its first message (:meth:`tick`), and
  is then in the kernel at once. A process killed at any moment (SIGKILL, power loss after the page cache reached
  the disk) loses at most the chunk in progress: readers that stream the file (mcap's ``NonSeekingReader``,
  :func:`sam_runtime.recording.reading.read_recording`) read every chunk before it.
- A write that fails (a full disk, the file's device gone) never raises into the caller: the recording stops,
  the error is logged once, and the message whose write met it and every message offered afterwards are counted
  in ``not_recorded`` (that one may still have reached the file). The chunks already written stay readable; the
  messages of the chunk in progress are lost.
- Thread-safe: the ROS executor thread and the bus sniffers write through one lock.
"""

from __future__ import annotations

import logging
import os
import threading
import time
from collections import Counter
from pathlib import Path
from typing import Any, BinaryIO

from sam_runtime.recording.target import check_target

__all__ = ["CHUNK_INTERVAL_S", "CHUNK_SIZE", "PROFILE", "RecordingWriter"]

log = logging.getLogger("sam_runtime.recording")

CHUNK_SIZE = 256 * 1024
CHUNK_INTERVAL_S = 1.0
PROFILE = "ros2"  # rosbag2's profile: readers that check it (rosbags) take the file


class _Unbuffered:
    """The file as the mcap writer sees it: every write goes to the OS at once. (Given a raw file, mcap wraps it in
    a BufferedWriter, which would keep up to 8 KiB from the kernel until later.)"""

    def __init__(self, raw: Any) -> None:
        self._raw = raw

    def write(self, data: Any) -> int:
        view = memoryview(data).cast("B")
        while view.nbytes:  # a raw write may take less than it is given
            n = self._raw.write(view)
            if not n:
                raise OSError(f"short write to {self._raw!r}")
            view = view[n:]
        return len(data)

    def tell(self) -> int:
        return int(self._raw.tell())

    def flush(self) -> None:
        pass

    def close(self) -> None:
        self._raw.close()


class RecordingWriter:
    """One MCAP file; ``add_*`` before or while writing messages; :meth:`close` writes the summary."""

    def __init__(self, path: Path, *, chunk_size: int = CHUNK_SIZE, chunk_interval: float = CHUNK_INTERVAL_S,
                 stream: BinaryIO | None = None) -> None:
        from mcap.writer import CompressionType, Writer

        self.path = Path(path)
        if stream is None:
            check_target(self.path)
            stream = open(self.path, "wb", buffering=0)  # closed in close()
        self._stream = _Unbuffered(stream)
        self._lock = threading.Lock()
        # mcap needs only write() and tell() of its output
        self._mcap = Writer(self._stream, chunk_size=chunk_size,  # type: ignore[arg-type]
                            compression=CompressionType.ZSTD)
        self._chunk_interval = float(chunk_interval)
        self._chunk_started: float | None = None
        self._schemas: dict[tuple[str, str], int] = {}
        self.channels: dict[str, int] = {}
        self.written: Counter[str] = Counter()  # messages per topic
        self.not_recorded = 0
        self.error: str | None = None
        self.closed = False
        self._guard(lambda: self._mcap.start(profile=PROFILE, library="sam-codegen record"))

    @property
    def recording(self) -> bool:
        return self.error is None and not self.closed

    def _guard(self, action: Any) -> Any:
        """Run one mcap call; a failed write stops the recording (logged once), never raises."""
        if not self.recording:
            return None
        try:
            return action()
        except OSError as ex:
            self.error = f"{type(ex).__name__}: {ex}"
            log.error("recording to %s stopped: %s (the chunks written so far stay readable; later messages are "
                      "counted as not recorded)", self.path, self.error)
            return None

    def add_channel(self, topic: str, schema_name: str, schema_encoding: str, schema_data: str | bytes,
                    message_encoding: str = "cdr", metadata: dict[str, str] | None = None) -> int | None:
        """Register ``topic`` (once) with its schema; returns the channel id (None when not recording)."""
        data = schema_data.encode() if isinstance(schema_data, str) else schema_data
        with self._lock:
            if topic in self.channels:
                return self.channels[topic]
            key = (schema_name, schema_encoding)
            sid = self._schemas.get(key)
            if sid is None:
                sid = self._guard(lambda: self._mcap.register_schema(schema_name, schema_encoding, data))
                if sid is None:
                    return None
                self._schemas[key] = sid
            cid = self._guard(lambda: self._mcap.register_channel(topic, message_encoding, sid, metadata or {}))
            if cid is not None:
                self.channels[topic] = cid
            return cid

    def add_attachment(self, name: str, data: bytes, media_type: str = "text/plain") -> None:
        now = time.time_ns()
        with self._lock:
            self._guard(lambda: self._mcap.add_attachment(now, now, name, media_type, data))

    def add_metadata(self, name: str, data: dict[str, str]) -> None:
        with self._lock:
            self._guard(lambda: self._mcap.add_metadata(name, {k: str(v) for k, v in data.items()}))

    def write(self, topic: str, data: bytes, log_time: int, publish_time: int | None = None) -> bool:
        """One message on a registered topic; False when it was not recorded (counted)."""
        with self._lock:
            cid = self.channels.get(topic)
            if cid is None or not self.recording:
                self.not_recorded += 1
                return False
            ok = self._guard(lambda: self._mcap.add_message(cid, log_time, data,
                                                            log_time if publish_time is None else publish_time,
                                                            self.written[topic]))
            if ok is None and not self.recording:
                self.not_recorded += 1
                return False
            self.written[topic] += 1
            if self._chunk_started is None:
                self._chunk_started = time.monotonic()
            return True

    def tick(self) -> None:
        """Close the chunk in progress once it is :data:`CHUNK_INTERVAL_S` old (call about every 0.2 s)."""
        with self._lock:
            if self._chunk_started is not None and time.monotonic() - self._chunk_started >= self._chunk_interval:
                self._chunk_started = None
                self._guard(self._mcap.flush)

    def close(self) -> None:
        """Write the summary (when the file is still writable) and close the file. Never raises."""
        with self._lock:
            if self.closed:
                return
            self._guard(self._mcap.finish)
            self.closed = True
            try:
                self._stream.close()
            except OSError as ex:
                self.error = self.error or f"{type(ex).__name__}: {ex}"
                log.error("closing %s: %s", self.path, ex)

    def summary(self) -> dict[str, Any]:
        size = None
        try:
            size = os.path.getsize(self.path)
        except OSError:
            pass
        return {"file": str(self.path), "bytes": size, "messages": sum(self.written.values()),
                "per_topic": dict(self.written), "not_recorded": self.not_recorded, "error": self.error}
