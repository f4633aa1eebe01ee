"""The simulated devices' clocks and their time-synchronisation slave (pure logic, no protocol library).

- :class:`DeviceClock`: a device's free-running local clock, the simulator's stamp clock (the wall clock at start,
  advancing monotonically) plus a constant offset, deterministic per device (:func:`device_offset_us`: 5 to 120 s
  either way), so that before synchronising a device's time is visibly not the computers'.
- :class:`SyncSlave`: the slave of both protocols' time synchronisation (Cyphal ``uavcan.time.Synchronization.1.0``,
  DroneCAN ``uavcan.protocol.GlobalTimeSync``), the algorithm of the Cyphal type's definition: the master publishes,
  in each message, the time it transmitted the previous one; a slave that received two consecutive messages of the
  same master (transfer id + 1, at most ``max_interval_s`` apart, the second one's field non-zero) sets its offset
  to ``previous_transmission_timestamp - local time at which it received the previous message``. It follows the
  master with the lowest node id; a master silent for three times its last interval (``timeout_factor``) is
  replaced by the next one heard. A message that breaks the chain only restarts it (the offset is kept: a real
  device's adjusted clock keeps running).
- Invariant: until the first adjustment a device is unsynchronised (:attr:`SyncSlave.synchronised` false,
  :meth:`SyncSlave.to_master` None) and stamps 0, both protocols' "unknown"; afterwards its stamps are master time,
  late by the sync message's one-way latency (the master measures its transmission time, the slave its reception).
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field

__all__ = ["CYPHAL_MAX_INTERVAL_S", "DRONECAN_MAX_INTERVAL_S", "DeviceClock", "SyncSlave", "device_offset_us"]

CYPHAL_MAX_INTERVAL_S = 1.0  # uavcan.time.Synchronization.1.0 MAX_PUBLICATION_PERIOD
DRONECAN_MAX_INTERVAL_S = 1.1  # uavcan.protocol.GlobalTimeSync MAX_BROADCASTING_PERIOD_MS
MIN_OFFSET_S, MAX_OFFSET_S = 5.0, 120.0


def device_offset_us(name: str) -> int:
    """A device's clock offset from the computers' time: 5..120 s, ahead or behind, from its name (deterministic).

    >>> device_offset_us("imu") == device_offset_us("imu"), 5e6 <= abs(device_offset_us("imu")) <= 120e6
    (True, True)
    """
    h = int.from_bytes(hashlib.sha256(name.encode()).digest()[:8], "big")
    magnitude = MIN_OFFSET_S + (h >> 1) % 1_000_000 / 1_000_000 * (MAX_OFFSET_S - MIN_OFFSET_S)
    return round((magnitude if h & 1 else -magnitude) * 1e6)


@dataclass
class DeviceClock:
    """A device's local clock: the simulator's stamp clock at a monotonic time, plus ``offset_us``."""

    epoch_us: int  # the stamp clock at mono0_ns
    mono0_ns: int
    offset_us: int

    def local_us(self, mono_ns: int) -> int:
        return self.epoch_us + (mono_ns - self.mono0_ns) // 1000 + self.offset_us


@dataclass
class SyncSlave:
    """One device's time-sync slave; feed it every sync message (:meth:`on_message`), read time with
    :meth:`to_master`. Times: ``rx_local_us`` the local clock at reception, ``rx_mono_s`` a monotonic clock then."""

    max_interval_s: float = CYPHAL_MAX_INTERVAL_S
    tid_modulo: int = 1 << 64
    timeout_factor: float = 3.0
    offset_us: int | None = None  # master time - local time; None until the first adjustment
    adjustments: int = 0
    ignored: int = 0  # messages of a master other than the one followed
    restarts: int = 0  # chains restarted: a lost message, a zero timestamp, too long an interval
    last_correction_us: int | None = None  # the change of offset at the last adjustment (0 once settled)
    _master: int | None = None
    _prev_tid: int = 0
    _prev_rx_local_us: int = 0
    _prev_rx_mono_s: float = 0.0
    _interval_s: float = field(default=0.0)
    _adjust: bool = False  # STATE_ADJUST: the previous message of the master is usable

    @property
    def synchronised(self) -> bool:
        return self.offset_us is not None

    @property
    def master(self) -> int | None:
        return self._master

    def to_master(self, local_us: int) -> int | None:
        """The master's time at local time ``local_us``; None while unsynchronised."""
        return None if self.offset_us is None else local_us + self.offset_us

    def on_message(self, master: int, transfer_id: int, prev_tx_us: int, rx_local_us: int,
                   rx_mono_s: float) -> bool:
        """A sync message from node ``master``; True when it adjusted the offset."""
        since = rx_mono_s - self._prev_rx_mono_s
        timeout = self.timeout_factor * (self._interval_s or self.max_interval_s)
        if self._master is None or master < self._master or since > timeout:
            self._update(master, transfer_id, rx_local_us, rx_mono_s, since)
            return False
        if master != self._master:
            self.ignored += 1
            return False
        adjusted = False
        if self._adjust:
            if prev_tx_us == 0 or transfer_id != (self._prev_tid + 1) % self.tid_modulo or \
                    since > self.max_interval_s:
                self.restarts += 1
            else:
                offset = prev_tx_us - self._prev_rx_local_us
                self.last_correction_us = None if self.offset_us is None else offset - self.offset_us
                self.offset_us = offset
                self.adjustments += 1
                adjusted = True
        self._update(master, transfer_id, rx_local_us, rx_mono_s, since)
        return adjusted

    def _update(self, master: int, tid: int, rx_local_us: int, rx_mono_s: float, since: float) -> None:
        same = master == self._master
        self._interval_s = since if same and 0 < since else 0.0
        self._master, self._prev_tid = master, tid
        self._prev_rx_local_us, self._prev_rx_mono_s = rx_local_us, rx_mono_s
        self._adjust = True
