"""The receive path's per-frame work made cheaper (issue 26) against its references, on random frame sequences:

- the transfer CRC (binascii's crc_hqx) is dronecan's own ``crc16_from_bytes`` for any bytes and any seed;
- the FrameGate's classification, the tail byte read inline, is the one of :class:`~sam_runtime.dronecan_io.can_id.Tail`
  frame by frame: the frames it passes on are those a per-frame reference passes on, with the same drops;
- a batch is handled identically to frame-at-a-time: the same frames come out, in the same order, with the same
  drops and the same tapped payloads, whatever batch limit the event loop sets between its wake-ups.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

dronecan = pytest.importorskip("dronecan")

from dronecan.driver.common import CANFrame  # noqa: E402
from dronecan.dsdl.common import crc16_from_bytes  # noqa: E402
from helpers.dronecan_peer import raw_imu_message  # noqa: E402
from helpers.dronecan_support import frames_of  # noqa: E402

from sam_runtime.dronecan_io.can_id import Tail  # noqa: E402
from sam_runtime.dronecan_io.drops import DropCounter, DropReason  # noqa: E402
from sam_runtime.dronecan_io.frame_gate import FrameGate  # noqa: E402
from sam_runtime.dronecan_io.wire import TransferTaps, crc16  # noqa: E402


@settings(max_examples=200, deadline=None)
@given(st.binary(max_size=300), st.integers(0, 0xFFFF))
def test_transfer_crc_is_dronecans(data: bytes, seed: int) -> None:
    assert crc16(data, seed) == crc16_from_bytes(data, seed)


class _Script:
    def __init__(self, frames: list[CANFrame]) -> None:
        self.frames = list(frames)

    def receive(self, timeout: float | None = None) -> CANFrame | None:
        return self.frames.pop(0) if self.frames else None

    def close(self) -> None: ...


def _copy(f: CANFrame) -> CANFrame:
    return CANFrame(f.id, bytearray(f.data), f.extended, ts_monotonic=1.0, ts_real=1.0)


_IMU = dronecan.uavcan.equipment.ahrs.RawIMU
_STATUS = dronecan.uavcan.protocol.NodeStatus


@st.composite
def _frames(draw: Any) -> list[CANFrame]:
    """Whole RawIMU transfers (tapped) and NodeStatus ones (the node's), interleaved across sources, with frames
    lost, repeated or corrupted, Cyphal v1 frames, 11-bit and empty frames among them."""
    pieces: list[list[CANFrame]] = []
    for _ in range(draw(st.integers(1, 8))):
        src, tid = draw(st.sampled_from([11, 12, 30])), draw(st.integers(0, 31))
        msg = raw_imu_message(draw(st.integers(0, 3)), 5) if draw(st.booleans()) else _STATUS(uptime_sec=tid)
        pieces.append(frames_of(msg, src, tid))
    frames: list[CANFrame] = []
    while any(pieces):  # interleave the transfers' frames, each transfer's in order
        piece = draw(st.sampled_from([p for p in pieces if p]))
        frames.append(piece.pop(0))
    for _ in range(draw(st.integers(0, 4))):
        at = draw(st.integers(0, len(frames)))
        kind = draw(st.sampled_from(["drop", "repeat", "flip", "v1", "std", "empty"]))
        if kind == "drop" and frames:
            del frames[min(at, len(frames) - 1)]
        elif kind == "repeat" and frames:
            frames.insert(at, _copy(frames[min(at, len(frames) - 1)]))
        elif kind == "flip" and frames:
            f = _copy(frames[min(at, len(frames) - 1)])
            if len(f.data) > 1:  # (never the tail byte)
                f.data[0] ^= 0xFF  # a CRC byte or payload: a multi-frame transfer's CRC fails
            frames[min(at, len(frames) - 1)] = f
        elif kind == "v1":
            frames.insert(at, CANFrame(0x107D552A, bytearray(b"\x01\xe3"), True))
        elif kind == "std":
            frames.insert(at, CANFrame(0x123, bytearray(b"\x01\xc0"), False))
        elif kind == "empty":
            frames.insert(at, CANFrame(0x1403EB0B, bytearray(), True))
    return [_copy(f) for f in frames]


def _run(frames: list[CANFrame], batches: Callable[[], int | None]) -> tuple[list[Any], dict[Any, int], list[Any]]:
    """What the gate passes on, its drops and the tapped payloads, the event loop setting a batch limit before
    each wake-up as the NodeLoop does."""
    gate = FrameGate(_Script(frames), clock=lambda: 0.0)
    tapped: list[Any] = []
    taps = TransferTaps(gate.drops)
    taps.add(_IMU.default_dtid, _IMU.base_crc, lambda payload, src, tid, ts: tapped.append((payload, src, tid)))
    gate.taps = taps
    passed: list[Any] = []
    while True:
        gate.limit_batch(batches())
        while (f := gate.receive(0)) is not None:
            passed.append((f.id, bytes(f.data)))
        gate.limit_batch(None)
        if gate.drained and not gate.has_ready_frames():
            break
    return passed, gate.drops.detailed(), tapped


@settings(max_examples=150, deadline=None)
@given(_frames(), st.lists(st.integers(1, 9), min_size=1, max_size=20))
def test_a_batch_is_handled_as_frame_at_a_time(frames: list[CANFrame], sizes: list[int]) -> None:
    whole = _run([_copy(f) for f in frames], lambda: None)
    one_by_one = _run([_copy(f) for f in frames], lambda: 1)
    it = iter(sizes * (len(frames) + 1))
    mixed = _run([_copy(f) for f in frames], lambda: next(it))
    assert whole == one_by_one == mixed


@settings(max_examples=150, deadline=None)
@given(_frames())
def test_the_inline_tail_classifies_as_tail(frames: list[CANFrame]) -> None:
    """Which frames the gate drops on their own (without their transfer's context) is what Tail says of them."""
    gate = FrameGate(_Script([_copy(f) for f in frames]), clock=lambda: 0.0)
    while gate.receive(0) is not None:
        pass
    counts = gate.drops.snapshot()
    expected = DropCounter()
    for f in frames:
        tail = Tail.of(f.data)
        if not f.extended:
            expected.add(DropReason.NOT_EXTENDED_ID)
        elif tail is None:
            expected.add(DropReason.EMPTY_FRAME)
        elif tail.is_cyphal_v1_start:
            expected.add(DropReason.CYPHAL_V1_FRAME)
    for reason in ("not_extended_id", "empty_frame"):
        assert counts.get(reason, 0) == expected.snapshot().get(reason, 0)
    # v1 first frames; the v1 frames after them (none here: single-frame v1 transfers) would add to it
    assert counts.get("cyphal_v1_frame", 0) == expected.snapshot().get("cyphal_v1_frame", 0)
