"""The simulated devices' time-sync slave (sam_runtime.sim.time_sync) against a fake master and fake clocks: the
offset from two consecutive messages, the chain rules of the Cyphal definition (transfer id + 1, the interval, a
zero timestamp), the dominant master (lowest node id, replaced after 3 intervals of silence), and the devices'
clocks and stamps in the simulator (unknown before the first adjustment, master time after)."""

from __future__ import annotations

from dataclasses import dataclass

import pytest

from sam_runtime.sim.time_sync import DeviceClock, SyncSlave, device_offset_us

OFFSET_US = -73_250_000  # the device's clock is 73.25 s behind the master's


@dataclass
class FakeBus:
    """A master (node ``nid``) publishing every ``period`` s of true time; the device's local clock is true time +
    OFFSET_US; each message takes ``latency_us`` from the master's transmission to the slave's reception."""

    slave: SyncSlave
    nid: int = 7
    period: float = 0.5
    latency_us: int = 300
    t_us: int = 1_700_000_000_000_000  # true time (the master's clock)
    tid: int = 0
    prev_tx_us: int = 0

    def publish(self, *, skip: bool = False, zero: bool = False, tid_step: int = 1, nid: int | None = None) -> bool:
        tx = self.t_us
        prev = 0 if zero else self.prev_tx_us
        self.prev_tx_us = tx
        self.tid += tid_step
        adjusted = False
        if not skip:
            rx_true = tx + self.latency_us
            adjusted = self.slave.on_message(self.nid if nid is None else nid, self.tid, prev, rx_true + OFFSET_US,
                                             rx_true * 1e-6)
        self.t_us += round(self.period * 1e6)
        return adjusted


def test_second_message_synchronises_to_the_master_within_the_latency() -> None:
    slave = SyncSlave()
    bus = FakeBus(slave)
    assert not bus.publish() and not slave.synchronised and slave.to_master(123) is None
    assert bus.publish() and slave.synchronised and slave.adjustments == 1
    # master time = local + offset: late by the sync message's latency, never more
    local_now = bus.t_us + OFFSET_US
    assert slave.to_master(local_now) == bus.t_us - bus.latency_us
    for _ in range(5):  # every further message adjusts; the correction settles to 0 (constant latency)
        assert bus.publish()
    assert slave.adjustments == 6 and slave.last_correction_us == 0


def test_first_message_after_start_carries_zero_and_does_not_adjust() -> None:
    slave = SyncSlave()
    bus = FakeBus(slave)
    bus.publish()
    assert not bus.publish(zero=True)  # the master restarted: 0 means "no previous transmission"
    assert slave.restarts == 1 and not slave.synchronised
    assert bus.publish() and slave.synchronised


@pytest.mark.parametrize("fault", ["lost", "tid", "slow"])
def test_a_broken_chain_restarts_without_adjusting(fault: str) -> None:
    slave = SyncSlave()
    bus = FakeBus(slave)
    bus.publish()
    if fault == "lost":  # a message never arrived: the next transfer id is 2 ahead
        bus.publish(skip=True)
    elif fault == "tid":
        bus.tid += 5
    else:  # longer than MAX_PUBLICATION_PERIOD (1 s) since the previous one
        bus.t_us += 800_000
    assert not bus.publish()
    assert slave.restarts == 1 and not slave.synchronised
    assert bus.publish() and slave.synchronised


def test_transfer_id_wraps_at_the_modulo() -> None:
    slave = SyncSlave(tid_modulo=32)
    bus = FakeBus(slave, tid=30)
    bus.publish()  # tid 31
    bus.tid = -1  # next is 0: 31 + 1 modulo 32
    assert bus.publish() and slave.adjustments == 1


def test_lowest_node_id_dominates_and_a_silent_master_is_replaced() -> None:
    slave = SyncSlave()
    high = FakeBus(slave, nid=50)
    high.publish()
    assert high.publish() and slave.master == 50
    low = FakeBus(slave, nid=3, t_us=high.t_us, latency_us=1000)
    assert not low.publish() and slave.master == 3  # displaced at once
    assert not high.publish() and slave.ignored == 1  # the higher one is ignored from now on
    assert low.publish()
    assert slave.to_master(low.t_us + OFFSET_US) == low.t_us - 1000
    # node 3 goes silent for more than 3 of its intervals: node 50 takes over
    high.t_us = low.t_us + 2_000_000
    assert not high.publish() and slave.master == 50
    assert high.publish()


def test_offset_kept_while_the_master_is_silent() -> None:
    slave = SyncSlave()
    bus = FakeBus(slave)
    bus.publish()
    bus.publish()
    before = slave.offset_us
    bus.t_us += 60_000_000
    assert not bus.publish()  # re-acquires, keeps its clock meanwhile
    assert slave.offset_us == before and slave.synchronised


def test_device_offsets_deterministic_and_seconds_to_minutes() -> None:
    names = ["imu", "gps", "thruster_1", "thruster_2", "battery", "pressure", "ballast"]
    offsets = [device_offset_us(n) for n in names]
    assert offsets == [device_offset_us(n) for n in names]
    assert all(5_000_000 <= abs(o) <= 120_000_000 for o in offsets)
    assert len(set(offsets)) == len(names) and any(o < 0 for o in offsets) and any(o > 0 for o in offsets)
    clock = DeviceClock(epoch_us=1_000_000, mono0_ns=5_000_000_000, offset_us=-2_000_000)
    assert clock.local_us(5_000_000_000 + 1_500_000_000) == 1_000_000 + 1_500_000 - 2_000_000
