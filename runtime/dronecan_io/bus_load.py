"""Classic CAN frame accounting for UAVCAN v0: frames and bits per transfer, and the load on a real bus.

A v0 transfer of N payload bytes is one frame if N <= 7, else ceil((N + 2) / 7) frames (the 2-byte transfer CRC
goes first), each carrying up to 7 payload bytes and the tail byte. A classic CAN data frame with a 29-bit id and
D data bytes is 67 + 8*D bits on the wire (SOF, arbitration, control, data, CRC, delimiters, ACK, EOF and the
3-bit intermission), plus at most one stuff bit per 4 bits of the 54 + 8*D stuffed bits (SOF to CRC): 131 bits
for 8 bytes nominally, 160 in the worst case. So a saturated 1 Mbit/s bus carries 6,250-7,600 frames a second.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass
from typing import Any

__all__ = [
    "BusLoadMeter",
    "TransferCost",
    "frame_bits",
    "payload_length",
    "transfer_cost",
    "transfer_frame_lengths",
]

_PAYLOAD_PER_FRAME = 7


def transfer_frame_lengths(payload_bytes: int) -> list[int]:
    """Data lengths (tail byte included) of the classic CAN frames of a v0 transfer.

    >>> transfer_frame_lengths(2)
    [3]
    >>> transfer_frame_lengths(47)  # RawIMU: 49 bytes with the CRC
    [8, 8, 8, 8, 8, 8, 8]
    >>> transfer_frame_lengths(8)
    [8, 4]
    """
    if payload_bytes < 0:
        raise ValueError(f"payload length must be >= 0, got {payload_bytes}")
    if payload_bytes <= _PAYLOAD_PER_FRAME:
        return [payload_bytes + 1]
    total = payload_bytes + 2
    full, rest = divmod(total, _PAYLOAD_PER_FRAME)
    return [_PAYLOAD_PER_FRAME + 1] * full + ([rest + 1] if rest else [])


def frame_bits(data_bytes: int, *, extended: bool = True, worst_case_stuffing: bool = False) -> int:
    """Bits one classic CAN data frame takes on the bus, intermission included.

    >>> frame_bits(8), frame_bits(8, worst_case_stuffing=True)
    (131, 160)
    >>> frame_bits(8, extended=False), frame_bits(0)
    (111, 67)
    """
    if not 0 <= data_bytes <= 8:
        raise ValueError(f"a classic CAN frame has 0..8 data bytes, got {data_bytes}")
    # Stuffed part: SOF 1, base id 11, (SRR 1, IDE 1, id extension 18, RTR 1, r1 r0 2 | RTR 1, IDE 1, r0 1),
    # DLC 4, data, CRC 15.
    stuffed = (54 if extended else 34) + 8 * data_bytes
    unstuffed_tail = 13  # CRC delimiter 1, ACK slot + delimiter 2, EOF 7, intermission 3
    bits = stuffed + unstuffed_tail
    if worst_case_stuffing:
        bits += (stuffed - 1) // 4
    return bits


@dataclass(frozen=True)
class TransferCost:
    frames: int
    bits: int
    bits_worst_case: int

    def bus_fraction(self, rate_hz: float, bitrate: int = 1_000_000, *, worst_case: bool = False) -> float:
        """The share of a ``bitrate`` bus this transfer takes when sent ``rate_hz`` times a second.

        >>> round(transfer_cost(47).bus_fraction(100), 4)  # RawIMU at 100 Hz on 1 Mbit/s
        0.0917
        """
        return rate_hz * (self.bits_worst_case if worst_case else self.bits) / bitrate


def transfer_cost(payload_bytes: int) -> TransferCost:
    """Frames and bits of one v0 transfer on a classic CAN bus (29-bit ids).

    >>> transfer_cost(47)
    TransferCost(frames=7, bits=917, bits_worst_case=1120)
    """
    lengths = transfer_frame_lengths(payload_bytes)
    return TransferCost(len(lengths), sum(frame_bits(n) for n in lengths),
                        sum(frame_bits(n, worst_case_stuffing=True) for n in lengths))


def payload_length(message: Any) -> int:
    """Encoded payload bytes of a dronecan message object (classic CAN: tail array optimisation on)."""
    from dronecan import transport

    return len(transport.Transfer(payload=message).payload)


class BusLoadMeter:
    """Counts the frames and bits a dronecan driver sends and receives (attach with ``driver.add_io_hook``).

    ``meter = BusLoadMeter(); remover = driver.add_io_hook(meter.on_frame)``; :meth:`snapshot` gives totals per
    direction ('tx', 'rx'); :meth:`bus_fraction` the share of a bus those frames took over ``seconds``.
    """

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._frames = {"rx": 0, "tx": 0}
        self._bits = {"rx": 0, "tx": 0}
        self._bits_worst = {"rx": 0, "tx": 0}
        self.canfd_frames = 0

    def on_frame(self, direction: str, frame: Any) -> None:
        if getattr(frame, "canfd", False):
            # CAN FD frames switch bit rate in the data phase: not a classic-bus figure; counted apart.
            with self._lock:
                self.canfd_frames += 1
            return
        n = len(frame.data)
        bits = frame_bits(n, extended=frame.extended)
        worst = frame_bits(n, extended=frame.extended, worst_case_stuffing=True)
        with self._lock:
            self._frames[direction] += 1
            self._bits[direction] += bits
            self._bits_worst[direction] += worst

    def snapshot(self) -> dict[str, dict[str, int]]:
        with self._lock:
            return {d: {"frames": self._frames[d], "bits": self._bits[d], "bits_worst_case": self._bits_worst[d]}
                    for d in ("rx", "tx")}

    def bus_fraction(self, seconds: float, bitrate: int = 1_000_000, *, worst_case: bool = False,
                     directions: tuple[str, ...] = ("rx", "tx")) -> float:
        """The share of a ``bitrate`` classic CAN bus the counted frames would take if sent in ``seconds``."""
        snap = self.snapshot()
        key = "bits_worst_case" if worst_case else "bits"
        return sum(snap[d][key] for d in directions) / (bitrate * seconds)
