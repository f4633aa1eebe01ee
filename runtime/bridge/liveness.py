"""Mappings that stay silent while their device is alive (issue 11, defect 6).

A UAVCAN -> ROS mapping expects its device to publish at the spec's nominal rate. A device whose heartbeat is
alive but whose subject never arrives (a wrong subject id in its firmware, a port left unconfigured, a sensor
that failed while the node runs on) or stops arriving used to show as a mapping "ok" (0 received) next to a
NOMINAL device. :class:`LivenessCheck` flags it: for each accepted source whose heartbeat is alive, silence
longer than the mapping's grace (:func:`grace_s`: at least 3 s, the Cyphal heartbeat timeout, and at least 5
nominal periods) counted from the latest of: the last message, the moment the device's heartbeat (re)appeared,
the moment the bridge started listening. A device that is not alive is not flagged here: its own status is
ERROR already. Nor is one that went quiet altogether (powered off): its heartbeat and its data stop together, and
the bridge learns that the heartbeat is gone only at the offline timeout (3 s), which may come after the grace
counted from the last message; so the silence counts only when a heartbeat came later than one heartbeat period
(1 s), or one nominal period where that is longer, after the last message: a live device's heartbeats go on once
a second, so one comes that late well within the grace, while a powered-off device's last heartbeat follows its
last message by less (by more than one data period when its last data ticks came late on a loaded machine).
ROS -> UAVCAN mappings are not watched: commands come when ROS nodes send them.

Pure logic on monotonic times passed in (no clock, no I/O), so the rules are tested without waiting.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass

__all__ = ["GRACE_PERIODS", "MIN_GRACE_S", "LivenessCheck", "Silence", "grace_s", "silence_of"]

MIN_GRACE_S = 3.0  # uavcan.node.Heartbeat.OFFLINE_TIMEOUT: no quicker than a lost heartbeat is noticed
HEARTBEAT_PERIOD_S = 1.0  # uavcan.node.Heartbeat.MAX_PUBLICATION_PERIOD (DroneCAN's NodeStatus: the same)
GRACE_PERIODS = 5.0


def grace_s(rate_hz: float) -> float:
    """How long a mapping may stay silent while its device is alive.

    >>> grace_s(100.0), grace_s(1.0), grace_s(0.5), grace_s(0.0)
    (3.0, 5.0, 10.0, inf)
    """
    if not rate_hz or rate_hz <= 0 or not math.isfinite(rate_hz):
        return math.inf
    return max(MIN_GRACE_S, GRACE_PERIODS / rate_hz)


@dataclass(frozen=True)
class Silence:
    """A mapping that gets nothing from an alive source."""

    mapping: str
    node_id: int
    device: str
    silent_s: float  # since the latest of: last message, heartbeat (re)appeared, bridge listening
    grace_s: float
    rate_hz: float
    last_message_age_s: float | None  # None: never received from this source

    @property
    def state(self) -> str:
        return "never_received" if self.last_message_age_s is None else "stopped"

    def message(self) -> str:
        """For /diagnostics and the log.

        >>> Silence("imu", 11, "imu", 12.04, 3.0, 100.0, None).message()
        'no message for 12 s while device imu (node 11) is alive; nominal 100 Hz; never received'
        >>> Silence("gps", 13, "gps", 4.6, 3.0, 5.0, 64.2).message()
        'no message for 5 s while device gps (node 13) is alive; nominal 5 Hz; the last one 64 s ago'
        """
        base = (f"no message for {self.silent_s:.0f} s while device {self.device} (node {self.node_id}) is alive; "
                f"nominal {self.rate_hz:g} Hz")
        if self.last_message_age_s is None:
            return base + "; never received"
        return base + f"; the last one {self.last_message_age_s:.0f} s ago"


def silence_of(now: float, *, rate_hz: float, alive_since: float | None, last_message: float | None,
               listening_since: float, last_heartbeat: float | None = None) -> tuple[float, float] | None:
    """(silent_s, grace_s) of one source when it is silent too long while alive, else None.

    >>> silence_of(10.0, rate_hz=10.0, alive_since=None, last_message=None, listening_since=0.0) is None
    True
    >>> silence_of(10.0, rate_hz=10.0, alive_since=2.0, last_message=None, listening_since=0.0)
    (8.0, 3.0)
    >>> silence_of(10.0, rate_hz=10.0, alive_since=2.0, last_message=9.0, listening_since=0.0) is None
    True
    >>> silence_of(10.0, rate_hz=10.0, alive_since=8.0, last_message=1.0, listening_since=0.0) is None
    True
    >>> silence_of(10.0, rate_hz=10.0, alive_since=2.0, last_message=6.9, listening_since=0.0, last_heartbeat=9.5)
    (3.0999999999999996, 3.0)
    >>> silence_of(10.0, rate_hz=10.0, alive_since=2.0, last_message=6.9, listening_since=0.0, last_heartbeat=7.6)
    """
    if alive_since is None:
        return None
    grace = grace_s(rate_hz)
    since = max(alive_since, listening_since, -math.inf if last_message is None else last_message)
    silent = now - since
    if silent <= grace:
        return None
    if last_heartbeat is not None and last_message is not None and \
            last_heartbeat <= last_message + max(HEARTBEAT_PERIOD_S, 1.0 / rate_hz):
        return None  # no heartbeat since its data stopped: it went quiet altogether (see the module docstring)
    return silent, grace


class LivenessCheck:
    """The UAVCAN -> ROS mappings' silence, evaluated on demand; remembers the current finding per mapping so
    that the caller logs and publishes only the changes.

    :param mappings: (name, nominal rate [Hz], accepted source node ids) per UAVCAN -> ROS mapping.
    :param device_names: node id -> device name (for the messages).
    """

    def __init__(self, mappings: Iterable[tuple[str, float, Iterable[int]]], device_names: Mapping[int, str]) -> None:
        self._mappings = [(name, float(rate), tuple(sorted(sources))) for name, rate, sources in mappings]
        self._names = dict(device_names)
        self.findings: dict[str, Silence | None] = {name: None for name, _, _ in self._mappings}

    def update(self, now: float, *, alive_since: Callable[[int], float | None],
               last_message: Callable[[str, int], float | None], listening_since: float,
               last_heartbeat: Callable[[int], float | None] | None = None
               ) -> list[tuple[str, Silence | None, Silence | None]]:
        """Evaluate every mapping; returns the changes as (mapping, before, now) where one of them is None
        (a mapping went silent, or got messages again / its device went away)."""
        changes = []
        for name, rate, sources in self._mappings:
            found: Silence | None = None
            for nid in sources:
                last = last_message(name, nid)
                res = silence_of(now, rate_hz=rate, alive_since=alive_since(nid), last_message=last,
                                 listening_since=listening_since,
                                 last_heartbeat=None if last_heartbeat is None else last_heartbeat(nid))
                if res is not None:
                    found = Silence(name, nid, self._names.get(nid, f"node {nid}"), res[0], res[1], rate,
                                    None if last is None else now - last)
                    break
            before = self.findings[name]
            self.findings[name] = found
            if (before is None) != (found is None):
                changes.append((name, before, found))
        return changes
