"""Counted drops on a DroneCAN bus: why a frame or transfer was not delivered, how often, from whom.

A drop is counted under a :class:`DropReason` and, where the frame's CAN id tells, the data type id and source node
that sent it, so that a bridge can later report drops per mapping. :class:`DropLog` turns drops into log
lines without flooding: the first of a reason at once, then one summary per interval while they keep coming.
"""

from __future__ import annotations

import logging
import threading
import time
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass
from enum import StrEnum

from sam_runtime.common.rate_log import LogLine, RateLimitedLog

__all__ = ["DropCounter", "DropKey", "DropLog", "DropReason"]


class DropReason(StrEnum):
    # A datagram on the loopback bus that is not an mcast: CAN frame (short, bad magic or CRC, bad length).
    BAD_PACKET = "bad_packet"
    # Frames the kernel dropped because the node's receive buffer was full (it did not keep up).
    RX_OVERFLOW = "rx_overflow"
    # Frames dronecan would ignore silently: UAVCAN v0 uses 29-bit ids only, and every frame has a tail byte.
    NOT_EXTENDED_ID = "not_extended_id"
    EMPTY_FRAME = "empty_frame"
    # A Cyphal v1 frame on the v0 bus (first frame with the toggle bit set, or a later frame of such a transfer).
    CYPHAL_V1_FRAME = "cyphal_v1_frame"
    # A frame of a multi-frame transfer whose first frame was not seen.
    ORPHAN_FRAME = "orphan_frame"
    # A multi-frame transfer that never ended: it timed out, or a new transfer restarted the same key.
    INCOMPLETE_TRANSFER = "incomplete_transfer"
    # TransferError out of dronecan's spin(), by its message.
    UNKNOWN_DATA_TYPE = "unknown_data_type"
    CRC_MISMATCH = "crc_mismatch"
    TOGGLE_ERROR = "toggle_error"
    FRAME_SEQUENCE_ERROR = "frame_sequence_error"
    TRANSFER_ID_MISMATCH = "transfer_id_mismatch"
    TRANSFER_ERROR = "transfer_error"
    # A transfer shorter than its data type (dronecan's unpacking raises ValueError "Not enough bits").
    MALFORMED_PAYLOAD = "malformed_payload"
    # Any other exception out of spin() while it handled a frame, or out of a callback its scheduler ran.
    FRAME_EXCEPTION = "frame_exception"
    # A handler registered through NodeLoop.add_handler raised.
    HANDLER_ERROR = "handler_error"
    SCHEDULED_CALLBACK_ERROR = "scheduled_callback_error"
    # A frame the driver could not send (the socket stayed full for the send timeout).
    TX_FAILED = "tx_failed"


@dataclass(frozen=True)
class DropKey:
    reason: DropReason
    data_type_id: int | None = None
    source_node_id: int | None = None


class DropCounter:
    """Drop counts by reason (and data type id and source node where known); safe to read from another thread.

    >>> c = DropCounter()
    >>> c.add(DropReason.CRC_MISMATCH, data_type_id=1003, source_node_id=10)
    >>> c.add(DropReason.CRC_MISMATCH)
    >>> c.snapshot(), c.total
    ({'crc_mismatch': 2}, 2)
    >>> c.detailed()[DropKey(DropReason.CRC_MISMATCH, 1003, 10)]
    1
    """

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._counts: Counter[DropKey] = Counter()
        self._listeners: list[Callable[[DropKey, str], None]] = []

    def add(self, reason: DropReason, *, data_type_id: int | None = None, source_node_id: int | None = None,
            detail: str = "", count: int = 1) -> None:
        key = DropKey(reason, data_type_id, source_node_id)
        with self._lock:
            self._counts[key] += count
        for listener in self._listeners:
            listener(key, detail if count == 1 else f"{count} at once: {detail}")

    def add_listener(self, listener: Callable[[DropKey, str], None]) -> None:
        """``listener(key, detail)`` is called for every drop, in the thread that counted it."""
        self._listeners.append(listener)

    def remove_listener(self, listener: Callable[[DropKey, str], None]) -> None:
        self._listeners.remove(listener)

    def snapshot(self) -> dict[str, int]:
        """Counts by reason (the reason's string value), only reasons seen."""
        out: Counter[str] = Counter()
        with self._lock:
            for key, n in self._counts.items():
                out[key.reason.value] += n
        return dict(sorted(out.items()))

    def detailed(self) -> dict[DropKey, int]:
        with self._lock:
            return dict(self._counts)

    @property
    def total(self) -> int:
        with self._lock:
            return sum(self._counts.values())


class DropLog:
    """Logs drops: the first of a reason at once, then at most one summary per ``interval`` per reason (a
    sam_runtime.common.rate_log.RateLimitedLog keyed by reason).

    Call :meth:`flush` periodically so that a summary is written also when the drops stop.

    >>> lines = []
    >>> now = [0.0]
    >>> log = DropLog(interval=10.0, emit=lines.append, clock=lambda: now[0])
    >>> for _ in range(3): log.report(DropKey(DropReason.CRC_MISMATCH, 1003, 10), "CRC mismatch")
    >>> now[0] = 10.0; log.flush()
    >>> print("\\n".join(lines))
    dronecan drop crc_mismatch (data type 1003 from node 10): CRC mismatch
    dronecan drop crc_mismatch: 2 more in the last 10.0 s (data type 1003 from node 10; last: CRC mismatch)
    """

    def __init__(self, interval: float = 10.0, *, logger: logging.Logger | None = None,
                 emit: Callable[[str], None] | None = None, clock: Callable[[], float] = time.monotonic) -> None:
        log = logger or logging.getLogger("sam_runtime.dronecan_io")
        self._emit = emit or log.warning
        self._log = RateLimitedLog(log, interval, write=self._write, clock=clock)
        # the (data type, source) of the drops of each reason since its last line
        self._sources: dict[DropReason, set[tuple[int | None, int | None]]] = {}

    def report(self, key: DropKey, detail: str) -> None:
        self._sources.setdefault(key.reason, set()).add((key.data_type_id, key.source_node_id))
        self._log.note(key.reason, logging.WARNING, "%s: %s", _origin(key, " (", ")"), detail)

    def flush(self, *, force: bool = False) -> None:
        """Write the summaries that are due (``force``: all that are pending, e.g. at shutdown)."""
        self._log.flush(force)

    def _write(self, line: LogLine) -> None:
        reason = line.key
        assert isinstance(reason, DropReason)
        sources = self._sources.pop(reason, set())
        origin, detail = line.args
        if line.fresh:
            self._emit(f"dronecan drop {reason.value}{origin}: {detail}")
            return
        origins = sorted((_origin(DropKey(reason, d, s)) for d, s in sources), key=str)
        prefix = "".join(f"{o}; " for o in origins if o)
        self._emit(f"dronecan drop {reason.value}: {line.count} more in the last {line.seconds:.1f} s "
                   f"({prefix}last: {detail})")


def _origin(key: DropKey, before: str = "", after: str = "") -> str:
    parts = []
    if key.data_type_id is not None:
        parts.append(f"data type {key.data_type_id}")
    if key.source_node_id is not None:
        parts.append(f"from node {key.source_node_id}")
    return f"{before}{' '.join(parts)}{after}" if parts else ""
