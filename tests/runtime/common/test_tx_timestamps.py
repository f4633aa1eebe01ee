"""The kernel's transmission timestamps of a UDP socket (sam_runtime.common.tx_timestamps): a take after one send
gives that send's time, between the bounds of the send call; a take that finds none or several gives none, so a
timestamp is never matched to another send; and the Cyphal/CAN frames the python-can transmit thread times
(sam_runtime.cyphal_io.can_tx_times) are the subject's messages from the node, nothing else."""

from __future__ import annotations

import socket
import sys
import time

import pytest

from sam_runtime.common.tx_timestamps import KernelTxStamps

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="SO_TIMESTAMPING is Linux's")


def test_one_send_one_timestamp_within_the_send_call() -> None:
    tx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    rx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        rx.bind(("127.0.0.1", 0))
        stamps = KernelTxStamps.attach(tx)
        assert stamps is not None
        assert stamps.take() is None  # nothing sent yet
        for _ in range(3):
            before = time.time_ns()
            tx.sendto(b"x", rx.getsockname())
            after = time.time_ns()
            time.sleep(0.001)  # read late, as a held-up loop would: the time is the send's all the same
            w = stamps.take()
            assert w is not None and w.source == "kernel" and w.span_ns == 0
            assert before <= w.earliest_ns <= after
        tx.sendto(b"x", rx.getsockname())
        tx.sendto(b"y", rx.getsockname())
        assert stamps.take() is None  # two since the last take: which is which is not guessed
        assert stamps.take() is None and stamps.read == 5 and stamps.missing == 3
    finally:
        tx.close()
        rx.close()


def test_can_frames_watched_are_the_subjects_messages_from_the_node() -> None:
    from sam_runtime.cyphal_io.can_tx_times import CanTxTimes

    t = CanTxTimes(7168, 100)
    msg = (4 << 26) | (3 << 21) | (7168 << 8) | 100  # priority 4, subject 7168, from node 100
    assert t.watched(msg)
    assert not t.watched(msg & ~0x7F | 101)  # another node
    assert not t.watched(msg & ~(0x1FFF << 8) | (7169 << 8))  # another subject
    assert not t.watched(msg | 1 << 24)  # anonymous
    assert not t.watched(msg | 1 << 25)  # a service frame
    n = t.count
    t.note(msg, 10, 20)
    t.note(msg | 1 << 25, 30, 40)  # not watched: no effect
    w = t.take(n)
    assert w is not None and (w.earliest_ns, w.latest_ns, w.source) == (10, 20, "can_thread")
    t.note(msg, 50, 60)
    assert t.take(n) is None  # two since: none
