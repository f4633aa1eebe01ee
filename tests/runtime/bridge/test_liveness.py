"""sam_runtime.bridge.liveness: the rules for a mapping that is silent while its device is alive (issue 11, defect 6).
Pure logic on times passed in: no waiting. The bridge's use of it: tests/test_glider_bridge.py."""

from __future__ import annotations

import math

import pytest

from sam_runtime.bridge.liveness import LivenessCheck, grace_s, silence_of


@pytest.mark.parametrize(("rate", "grace"), [(100.0, 3.0), (10.0, 3.0), (5 / 3, 3.0), (1.0, 5.0), (0.1, 50.0),
                                              (0.0, math.inf), (-1.0, math.inf), (math.nan, math.inf)])
def test_grace_is_the_heartbeat_timeout_or_five_periods(rate: float, grace: float) -> None:
    assert grace_s(rate) == pytest.approx(grace)


@pytest.mark.parametrize(("alive_since", "last", "listening", "now", "expected"), [
    (None, None, 0.0, 100.0, None),  # no heartbeat: the device's own status says it
    (10.0, None, 0.0, 13.0, None),  # exactly the grace: not yet
    (10.0, None, 0.0, 13.5, (3.5, 3.0)),  # never received
    (10.0, 20.0, 0.0, 22.0, None),
    (10.0, 20.0, 0.0, 24.0, (4.0, 3.0)),  # stopped
    (30.0, 20.0, 0.0, 32.0, None),  # the heartbeat came back at 30: counted from then
    (10.0, None, 50.0, 52.0, None),  # the bridge (re)opened its link at 50: counted from then
    (10.0, None, 50.0, 54.0, (4.0, 3.0)),
])
def test_silence_counts_from_the_latest_reason_to_expect_data(alive_since: float | None, last: float | None,
                                                             listening: float, now: float,
                                                             expected: tuple[float, float] | None) -> None:
    assert silence_of(now, rate_hz=10.0, alive_since=alive_since, last_message=last,
                      listening_since=listening) == expected


def test_monitor_reports_changes_only_and_names_the_device() -> None:
    alive: dict[int, float | None] = {22: 0.0, 23: None}
    last: dict[tuple[str, int], float] = {}
    mon = LivenessCheck([("altitude", 10.0, [22]), ("ctd", 0.5, [23]), ("both", 10.0, [23, 22])],
                          {22: "altimeter"})

    def update(now: float) -> list[tuple[str, str | None, str | None]]:
        changes = mon.update(now, alive_since=alive.get, last_message=lambda m, n: last.get((m, n)),
                             listening_since=0.0)
        return [(name, b and b.state, f and f.state) for name, b, f in changes]

    assert update(2.0) == []
    assert update(3.5) == [("altitude", None, "never_received"), ("both", None, "never_received")]
    found = mon.findings["altitude"]
    assert found is not None and found.device == "altimeter" and found.node_id == 22
    assert mon.findings["both"] is not None and mon.findings["both"].node_id == 22  # 23 is not alive
    assert update(3.7) == []  # still silent: no new change
    last[("altitude", 22)] = 3.8
    assert update(4.0) == [("altitude", "never_received", None)]
    assert update(7.0) == [("altitude", None, "stopped")]
    assert mon.findings["altitude"].last_message_age_s == pytest.approx(3.2)
    alive[22] = None  # its heartbeat timed out: no longer this monitor's business
    assert update(8.0) == [("altitude", "stopped", None), ("both", "never_received", None)]
    alive[23] = 8.0  # the CTD appears: "both" (10 Hz) waits 3 s, "ctd" (0.5 Hz) 10 s
    assert update(11.5) == [("both", None, "never_received")]
    assert mon.findings["both"].node_id == 23
    assert update(17.0) == []
    assert update(18.5) == [("ctd", None, "never_received")]
    assert mon.findings["ctd"].message() == (  # no device name in the spec: the node id
        "no message for 10 s while device node 23 (node 23) is alive; nominal 0.5 Hz; never received")


def test_a_device_that_went_quiet_altogether_is_never_flagged_silent() -> None:
    """Data (5 Hz) and heartbeat (1 Hz) stop together, the last heartbeat a little after the last message: between
    the grace after the last message and the offline timeout after the last heartbeat the device still reads alive,
    but it sent no heartbeat after its data stopped, so its mapping is not silent. A device whose data stops while
    its heartbeats go on is flagged once the grace has passed."""
    # (a powered-off pump in the glider system test; and one whose last data ticks came late on a loaded machine)
    for last_msg, last_hb in ((15.303, 15.452), (15.303, 16.1)):
        _never_flagged(last_msg, last_hb)
    # the data stopped at 15.303, the heartbeats go on once a second: flagged as soon as the grace has passed
    last_msg = 15.303
    for now, flagged in ((18.2, False), (18.31, True)):
        hb = 15.452 + int(now - 15.452)  # the last of the 1 Hz heartbeats by now
        mon = LivenessCheck([("pump_status", 5.0, [21])], {21: "pump"})
        changes = mon.update(now, alive_since=lambda n: 0.0, last_message=lambda m, n: last_msg,
                             listening_since=0.0, last_heartbeat=lambda n, hb=hb: hb)
        assert bool(changes) is flagged, now


def _never_flagged(last_msg: float, last_hb: float) -> None:
    from sam_runtime.bridge.health import OFFLINE_TIMEOUT_S

    def alive(last_hb: float, now: float) -> float | None:
        return 0.0 if now - last_hb < OFFLINE_TIMEOUT_S else None

    for k in range(400):
        now = last_msg + k * 0.01
        mon = LivenessCheck([("pump_status", 5.0, [21])], {21: "pump"})
        changes = mon.update(now, alive_since=lambda n, now=now: alive(last_hb, now),
                             last_message=lambda m, n: last_msg, listening_since=0.0,
                             last_heartbeat=lambda n: last_hb)
        assert changes == [], (last_msg, last_hb, now)
