"""Transfer-loss accounting of one subscribed port: transfers of an accepted source that never reached the bridge,
found by the gaps in that source's transfer ids (any protocol that numbers transfers per source and port).

- Transfer ids that wrap at 2**32 or beyond (Cyphal/UDP: 64 bits) are exact: a gap of d means d - 1 lost; ids
  that go backwards mean the source restarted (``on_restart``), nothing lost.
- Ids modulo 32 (Cyphal/CAN, DroneCAN) are exact while the gap is shorter than the transfer-id timeout (2 s); for
  a longer gap the number of wraps is unknown, so the source's rate decides (measured over a long window, else
  the spec's nominal rate): a source whose heartbeat uptime is shorter than the gap restarted meanwhile (nothing
  counted); if the bridge's own link was down in between (it knows it was deaf), an estimate is counted apart
  (``lost_link_down``): the gap modulo 32 plus the multiple of 32 closest to rate x elapsed time; otherwise, if
  fewer than 16 transfers were due (no wrap possible) and the gap fits, the gap is exact (``lost``).

A transfer id further ahead than the time since the source's previous transfer allows (beyond
:func:`~sam_runtime.common.transfer_ids.plausible_gap`; 64-bit ids only: a 5-bit gap is at most 15, one frame can
add at most 14 there) is no loss: a restart with another counter, or a spoof with the device's node id. It is a
``jump`` (its transfer is dropped and counted as ``transfer_id_jump``) and the source's sequence stays where it was,
so that one frame can neither add 2**40 to ``lost`` nor make the real device's next transfers look old; the
transfer right after a jump that continues it (a restarted device's second transfer) starts the new sequence. A gap
across a kernel receive-buffer overflow (``last_overflow``) is a loss whatever its size: a burst beyond what the
bridge reads loses thousands in microseconds of its reading.

Pure logic on the times and ids passed in; the rest of the bridge is reached through the callables given.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping

from sam_runtime.common.transfer_ids import plausible_gap

__all__ = ["JUMP", "TRANSFER_ID_TIMEOUT_S", "TransferLoss"]

TRANSFER_ID_TIMEOUT_S = 2.0  # Cyphal's default transfer-id timeout (DroneCAN's is the same)
JUMP = -1  # TransferLoss.track's "lost" for a transfer-id jump


class TransferLoss:
    """:param port_id: the spec's port id of the subscription (for the nominal rates).
    :param nominal_rates: (source node id, port id) -> the spec's nominal rate in Hz.
    :param modulo: the transport's transfer-id modulo now (it may change when the link is reopened).
    :param uptime_of: a node's heartbeat uptime in seconds, or None when never heard.
    :param outages: the bridge's recent link outages as (start, end) monotonic times.
    :param on_restart: called with a source whose transfer ids started over (Cyphal/UDP: it restarted).
    :param last_overflow: when (monotonic s) the kernel last dropped received frames for a full buffer: a gap
        across such a drop is a loss, not a jump, however fast.

    >>> loss = TransferLoss(1, {}, lambda: 2**64, lambda nid: None, lambda: (), lambda nid: None)
    >>> [loss.track(11, tid, 0.01 * tid) for tid in (5, 6, 9, 10, 10)]
    [(0, 0), (0, 0), (2, 0), (0, 0), (0, 0)]
    >>> loss.last_message(11), loss.last_message(12)
    (0.1, None)
    >>> loss.track(11, 2**40, 0.11), loss.track(11, 11, 0.12)  # a spoof: no loss, the real stream goes on
    ((-1, 0), (0, 0))
    """

    def __init__(self, port_id: int, nominal_rates: Mapping[tuple[int, int], float], modulo: Callable[[], int],
                 uptime_of: Callable[[int], int | None], outages: Callable[[], Iterable[tuple[float, float]]],
                 on_restart: Callable[[int], None], last_overflow: Callable[[], float] = lambda: -math.inf
                 ) -> None:
        self.port_id = port_id
        self._nominal = nominal_rates
        self._modulo = modulo
        self._uptime_of = uptime_of
        self._outages = outages
        self._on_restart = on_restart
        self._last_overflow = last_overflow
        self.last_tid: dict[int, tuple[int, float]] = {}  # source -> (transfer id, monotonic s)
        self.rate: dict[int, tuple[float, int, float]] = {}  # source -> (since, count, rate)
        self._jumped: dict[int, int] = {}  # source -> the transfer id its last jump went to

    def last_message(self, src: int) -> float | None:
        """When the last transfer of ``src`` arrived (monotonic s), or None."""
        last = self.last_tid.get(src)
        return None if last is None else last[1]

    def track(self, src: int, tid: int, now: float) -> tuple[int, int]:
        """(lost, estimated): transfers lost before this one from ``src`` (a gap in its transfer ids), and, for
        wrapping ids only, an estimate of those missed while the bridge's own link was down. A jump (see the
        module's docstring) returns (:data:`JUMP`, 0): the caller drops its transfer."""
        prev = self.last_tid.get(src)
        if prev is None:
            self.last_tid[src] = (tid, now)
            return 0, 0
        modulo = self._modulo()
        d = (tid - prev[0]) % modulo
        if modulo >= 2**32 and 1 < d < modulo // 2 and d - 1 > plausible_gap(now - prev[1]) and \
                self._last_overflow() < prev[1]:  # (a kernel drop since then explains any gap)
            jumped = self._jumped.get(src)
            self._jumped[src] = tid
            if jumped is None or (tid - jumped) % modulo != 1:
                return JUMP, 0
            self._on_restart(src)  # it goes on from its jump: a restart with another counter (nothing lost)
            d = 1
        if self._jumped:
            self._jumped.pop(src, None)
        self.last_tid[src] = (tid, now)
        if modulo < 2**32 and now - prev[1] > TRANSFER_ID_TIMEOUT_S:  # the ids may have wrapped meanwhile
            res = self._wrapped_gap(src, prev[1], now, d, modulo)
            self.rate.pop(src, None)
            return res
        if d == 1:  # the source's actual rate over a long window (for _wrapped_gap)
            t0, n, rate = self.rate.get(src, (prev[1], 0, 0.0))
            n += 1
            if now - t0 >= 2.0:
                rate = n / (now - t0)
            if now - t0 > 60.0:  # a new window, the old rate kept meanwhile
                t0, n = now, 0
            self.rate[src] = (t0, n, rate)
        elif d != 0:
            self.rate.pop(src, None)
        if d <= 1 or d >= modulo // 2:  # next in sequence, duplicate, or backwards (the source restarted)
            if d >= modulo // 2 and modulo >= 2**32:  # UDP: ids start over only when the node restarts
                self._on_restart(src)  # (whether its heartbeat said so before this message or not)
            return 0, 0
        return d - 1, 0

    def _wrapped_gap(self, src: int, t_prev: float, t_now: float, d: int, modulo: int) -> tuple[int, int]:
        rate = self.rate.get(src, (0.0, 0, 0.0))[2] or self._nominal.get((src, self.port_id))
        if not rate:
            return 0, 0
        elapsed = t_now - t_prev
        uptime = self._uptime_of(src)
        if uptime is not None and uptime + 1 < elapsed:
            return 0, 0
        base = (d - 1) % modulo
        expected = rate * elapsed - 1.0
        if any(start < t_now and end > t_prev for start, end in self._outages()):
            k = max(0, round((expected - base) / modulo))
            return 0, base + k * modulo
        if expected < modulo / 2 and base <= expected + 2:
            return base, 0
        return 0, 0
