"""The ``mcast-lo:`` driver's times (sam_runtime.dronecan_io.loopback): a frame sent leaves the bounds of its send
system call (``last_tx_ns``, ``frames_sent``), and a frame received carries the time the kernel received it, not
the time it was read: a reader held up for a while still gets the arrival time (the time-sync slave's need)."""

from __future__ import annotations

import sys
import time

import pytest

pytest.importorskip("dronecan")

from dronecan.driver.common import CANFrame
from helpers.dronecan_support import private_iface

from sam_runtime.dronecan_io import LoopbackMulticastDriver, parse_iface

HELD_UP_S = 0.005  # the reader comes late by this much (not a verdict: the gap the stamps must show)


def _pair() -> tuple[LoopbackMulticastDriver, LoopbackMulticastDriver]:
    where = parse_iface(private_iface())
    assert where.bus is not None and where.port is not None
    return LoopbackMulticastDriver(where.bus, where.port), LoopbackMulticastDriver(where.bus, where.port)


def _one(tx: LoopbackMulticastDriver, rx: LoopbackMulticastDriver, k: int) -> tuple[CANFrame, tuple[int, int], float]:
    tx.send_frame(CANFrame(0x1000 + k, bytearray([k]), True))
    window = tx.last_tx_ns
    assert window is not None
    time.sleep(HELD_UP_S)
    read_mono = time.monotonic()
    frame = rx.receive(1.0)
    assert frame is not None and frame.id == 0x1000 + k
    return frame, window, read_mono


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="SO_TIMESTAMPNS is Linux's")
def test_sent_window_and_arrival_time() -> None:
    tx, rx = _pair()
    try:
        sent = tx.frames_sent
        # The kernel turns arrival stamps on for the machine a moment after the first socket asks (deferred
        # work); until then a datagram is stamped when read. Wait for that (a condition, with a deadline).
        deadline = time.monotonic() + 10
        while True:
            frame, (before, after), read_mono = _one(tx, rx, 0)
            if frame.ts_real * 1e9 <= after + 1e5:
                break
            assert time.monotonic() < deadline, "the kernel never stamped a datagram on arrival"
        for k in range(1, 6):
            frame, (before, after), read_mono = _one(tx, rx, k)
            assert before <= after and after - before < 50_000_000
            # arrived within its send system call (loopback: delivered inside it; float seconds: 1 us slack)
            assert before - 1_000 <= frame.ts_real * 1e9 <= after + 1_000, (before, frame.ts_real * 1e9, after)
            assert frame.ts_monotonic <= read_mono - HELD_UP_S * 0.9  # not the (late) reading time
        assert tx.frames_sent > sent + 5
    finally:
        tx.close()
        rx.close()
