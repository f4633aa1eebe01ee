"""The bridge's periodic work (issue 26): one housekeeping round a second on the event loop, nothing faster.

- the assembled bridge's periodic jobs, per protocol: all at 1 s, in one task (one wake-up a second): the link and
  silence checks, the bounded log's pending counts, /diagnostics (which polls the stack's counters itself; without
  /diagnostics a job of its own polls them), the service mappings' /diagnostics, the Cyphal services' counters;
- the bounds that rate keeps: the offline timeout and every silence grace are 3 s or more, so a check a second
  finds a silence within a second of its grace;
- the rounds run at fixed deadlines (:func:`~sam_runtime.bridge.lifetime.next_round`): a job's own time does not
  stretch the period, and rounds missed while the loop was held up are skipped, not run back to back.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from sam_runtime.bridge import link, silence
from sam_runtime.bridge.composition import HOUSEKEEPING_PERIOD_S, Bridge
from sam_runtime.bridge.health import OFFLINE_TIMEOUT_S
from sam_runtime.bridge.lifetime import next_round
from sam_runtime.bridge.liveness import MIN_GRACE_S, grace_s
from sam_runtime.genpkg import GeneratedPackage

GENERATED = Path(__file__).resolve().parents[3] / "generated"


@pytest.mark.ros  # the bridge's parts load SAM's ROS messages (sam_msgs): not in the unit tier, which builds none
@pytest.mark.parametrize(("layout", "services"), [("dronecan", []), ("default", ["Cyphal service statistics"])])
@pytest.mark.parametrize("diagnostics_period", [1.0, 0.0])
def test_one_housekeeping_round_a_second(layout: str, services: list[str], diagnostics_period: float) -> None:
    if layout == "dronecan":
        pytest.importorskip("dronecan")
    gen = GeneratedPackage(GENERATED)
    bridge = Bridge(gen, layout=layout, diagnostics_period=diagnostics_period)
    convert = gen.convert_v0() if bridge.selection.protocol == "dronecan" else gen.convert()
    bridge._assemble(convert, bridge._codec())  # the parts attached as start() attaches them, nothing started
    # the service mappings' /diagnostics (every layout has its node duties' services) in the round, no rclpy timer
    jobs = ["silence", "log", *(["service diagnostics"] if diagnostics_period else []), *services, "link check"]
    if diagnostics_period:
        jobs.append("diagnostics")  # last in the round: after the checks whose findings it reports
    else:
        jobs.insert(0, "stack counters")
    assert bridge.lifetime.schedule == {HOUSEKEEPING_PERIOD_S: jobs}
    assert HOUSEKEEPING_PERIOD_S == link.CHECK_PERIOD_S == silence.CHECK_PERIOD_S == 1.0


def test_the_checks_rate_fits_the_timeouts_it_serves() -> None:
    assert OFFLINE_TIMEOUT_S >= 3 * silence.CHECK_PERIOD_S
    assert MIN_GRACE_S >= 3 * silence.CHECK_PERIOD_S
    assert all(grace_s(rate) >= MIN_GRACE_S for rate in (0.5, 1.0, 10.0, 100.0, 1000.0))


def test_rounds_at_fixed_deadlines() -> None:
    period = 1.0
    due = 100.0
    seen = []
    # the loop runs each round a little late (a job's time, a loaded machine), once 2.5 rounds late
    for now in (100.05, 101.2, 102.01, 105.5, 106.3):
        due = next_round(due, period, now)
        seen.append(due)
        assert now < due <= now + period
    assert seen == [101.0, 102.0, 103.0, 106.0, 107.0]  # no drift; 104 and 105 skipped, not run back to back
