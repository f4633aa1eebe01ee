"""Device health from heartbeats, for any protocol: which nodes are alive, their health, their restarts.

The design of pycyphal's NodeTracker (pycyphal.application.node_tracker): a registry of the nodes heard, one
offline timer per node re-armed by each heartbeat (``loop.call_later``, no polling), and update handlers called on
a change. NodeTracker itself does not fit the bridge: it reports no heartbeat that changes only the health or the
mode, its registry and timers end with the pycyphal node (the bridge reopens its node when the transport fails, and
a device that stops meanwhile must still time out), it issues GetInfo requests, and DroneCAN's NodeStatus needs the
same tracking. So the backends report every heartbeat as a :class:`~.backend.DeviceStatus`, and this tracker keeps:

- a device is alive while its last heartbeat is younger than ``offline_timeout`` (3 s: Cyphal's
  Heartbeat.OFFLINE_TIMEOUT and DroneCAN's NodeStatus.OFFLINE_TIMEOUT_MS); when its timer fires it is lost
  (logged; handlers get ``lost``), when heartbeats come back it is ``back``;
- a restart (the uptime went down) is counted, logged and reported (``restarted``: its clock may have restarted);
  so is an uptime that fell behind the time since the last heartbeat by more than :data:`UPTIME_SLACK_S` (plus
  :data:`UPTIME_DRIFT` of that time): a node that rebooted quickly whose first heartbeats the transport dropped
  (Cyphal's transfer-id timeout, 2 s: the new node's ids start at 0 again, and pycyphal discards ids below the last
  one until the timeout has passed), so that the first one heard carries an uptime no lower than the last one
  before the reboot. The slack covers whole-second uptimes (1 s) and the heartbeats' delivery jitter; the drift a
  device clock that runs slow over a long gap;
- nodes that are no device of the spec (tools such as yakut) are tracked too; their first appearance is logged at
  INFO, their comings and goings at DEBUG only, and handlers hear of them only with ``device=False``.

Times come from ``clock`` (default time.monotonic, the asyncio loop's clock); timers from ``call_later`` (default
the running loop's), so the rules are tested with a fake clock.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from sam_runtime.bridge.backend import DeviceStatus
from sam_runtime.bridge.counters import log

__all__ = ["OFFLINE_TIMEOUT_S", "UPTIME_DRIFT", "UPTIME_SLACK_S", "DeviceHealth", "NodeRecord", "restarted_since"]

OFFLINE_TIMEOUT_S = 3.0
UPTIME_SLACK_S = 2.5  # whole seconds (1 s) + 1.5 s of delivery jitter between two heartbeats
UPTIME_DRIFT = 0.02  # a device clock 2 % slow over a gap is no restart

# handler(node_id, event, is_device): event is "lost", "back" or "restarted"
HealthHandler = Callable[[int, str, bool], None]


@dataclass
class NodeRecord:
    node_id: int
    last_seen: float
    status: DeviceStatus
    count: int = 1
    alive: bool = True  # as last reported (the transitions are logged and handed to the handlers)
    lost_events: int = 0  # times the heartbeat timed out
    restarts: int = 0  # times the uptime went backwards
    alive_since: float = 0.0  # when the heartbeat (re)appeared
    timer: Any = None


def restarted_since(old_uptime: int, uptime: int, elapsed: float) -> bool:
    """Whether a node restarted between two of its heartbeats ``elapsed`` seconds apart: its uptime went down, or
    grew less than the time that passed, by more than the slack (see the module's docstring).

    >>> restarted_since(40, 3, 1.0), restarted_since(3, 4, 1.0), restarted_since(2, 2, 0.9)
    (True, False, False)

    Up 3 s, rebooted in 1 s, its heartbeats dropped for 2 s: the first one heard (uptime 3, a late one) is no lower,
    but 5.2 s have passed. A device heard again after 10 minutes, its clock 1 % slow, did not restart:

    >>> restarted_since(3, 3, 5.2), restarted_since(100, 694, 600.0)
    (True, False)
    """
    if uptime < old_uptime:
        return True
    return uptime + UPTIME_SLACK_S + UPTIME_DRIFT * elapsed < old_uptime + elapsed


class DeviceHealth:
    """:param devices: node id -> device name of the spec's devices.
    :param own_node_id: the bridge's node id (its own heartbeats are no stranger's).
    """

    def __init__(self, devices: Mapping[int, str], own_node_id: int, *, offline_timeout: float = OFFLINE_TIMEOUT_S,
                 clock: Callable[[], float] = time.monotonic,
                 call_later: Callable[[float, Callable[[], None]], Any] | None = None) -> None:
        self.devices = dict(devices)
        self.own_node_id = own_node_id
        self.offline_timeout = float(offline_timeout)
        self._clock = clock
        self._call_later = call_later
        self.records: dict[int, NodeRecord] = {}
        self._handlers: list[HealthHandler] = []

    def add_handler(self, handler: HealthHandler) -> None:
        self._handlers.append(handler)

    def attach(self, lifetime: Any) -> None:
        lifetime.add_hooks("device health", start=self._start, close=self.close)

    def _start(self) -> None:
        if self._call_later is None:
            import asyncio

            self._call_later = asyncio.get_running_loop().call_later

    def close(self) -> None:
        for rec in self.records.values():
            if rec.timer is not None:
                rec.timer.cancel()
                rec.timer = None

    # -------------------------------------------------------------------------------------------- events in
    def on_status(self, st: DeviceStatus) -> None:
        """A heartbeat of node ``st.node_id`` (the backend's device status event)."""
        nid = st.node_id
        now = self._clock()
        rec = self.records.get(nid)
        if rec is None:
            rec = self.records[nid] = NodeRecord(nid, now, st, alive_since=now)
            if nid not in self.devices and nid != self.own_node_id:  # a tool (yakut, ...): noted once
                log.info("node %d (no device of the spec) appeared on the bus", nid)
            self._arm(rec)
            return
        if not rec.alive or now - rec.last_seen >= self.offline_timeout:
            rec.alive_since = now  # back (possibly before its timer noticed it was gone)
        old_uptime, elapsed = rec.status.uptime_s, now - rec.last_seen
        restarted = restarted_since(old_uptime, st.uptime_s, elapsed)
        if restarted:
            rec.restarts += 1
            rec.alive_since = now  # a device that just booted gets its grace before it must publish
        # last_seen last: /diagnostics is also built on rclpy's timer thread, and a record that reads alive must
        # already carry this heartbeat's status and count.
        rec.status, rec.count = st, rec.count + 1
        rec.last_seen = now
        self._arm(rec)
        if restarted:
            # (when the uptime did not go down, the time since says why it counts)
            since = "" if st.uptime_s < old_uptime else f", {elapsed:.1f} s ago"
            if nid in self.devices:
                log.warning("%s restarted (uptime %d s, before %d s%s)", self.name(nid), st.uptime_s, old_uptime,
                            since)
            else:
                log.debug("node %d restarted (uptime %d s, before %d s%s)", nid, st.uptime_s, old_uptime, since)
            self._notify(nid, "restarted")
        if not rec.alive:
            rec.alive = True
            if nid in self.devices:
                log.info("%s: heartbeat back (uptime %d s, %d restarts seen)", self.name(nid), st.uptime_s,
                         rec.restarts)
            else:
                log.debug("node %d: heartbeat back", nid)
            self._notify(nid, "back")

    def _arm(self, rec: NodeRecord) -> None:
        if rec.timer is not None:
            rec.timer.cancel()
        rec.timer = None
        if self._call_later is not None:
            rec.timer = self._call_later(max(0.0, rec.last_seen + self.offline_timeout - self._clock()),
                                         lambda: self._on_timer(rec.node_id))

    def _on_timer(self, nid: int) -> None:
        rec = self.records.get(nid)
        if rec is None:
            return
        rec.timer = None
        if self._clock() - rec.last_seen < self.offline_timeout:  # a timer may fire a hair early: not yet
            self._arm(rec)
            return
        if not rec.alive:
            return
        rec.alive = False
        rec.lost_events += 1
        if nid in self.devices:
            log.warning("%s: heartbeat lost (none for %.1f s)", self.name(nid), self._clock() - rec.last_seen)
        else:
            log.debug("node %d: heartbeat gone", nid)
        self._notify(nid, "lost")

    def _notify(self, nid: int, event: str) -> None:
        device = nid in self.devices
        for handler in self._handlers:
            handler(nid, event, device)

    # -------------------------------------------------------------------------------------------- queries
    def name(self, nid: int) -> str:
        dev = self.devices.get(nid)
        return f"device {dev} (node {nid})" if dev is not None else f"node {nid}"

    def alive_since(self, nid: int) -> float | None:
        """When the node's heartbeat (re)appeared, if it is alive now; else None."""
        rec = self.records.get(nid)
        if rec is None or self._clock() - rec.last_seen >= self.offline_timeout:
            return None
        return rec.alive_since

    def uptime_of(self, nid: int) -> int | None:
        rec = self.records.get(nid)
        return None if rec is None else rec.status.uptime_s

    def entry(self, nid: int) -> dict[str, Any]:
        """The stats of one node (JSON-serialisable)."""
        rec = self.records.get(nid)
        if rec is None:
            return {"node_id": nid, "seen": False, "alive": False, "state": "never seen"}
        age = self._clock() - rec.last_seen
        alive = age < self.offline_timeout
        st = rec.status
        return {
            "node_id": nid, "seen": True, "age_s": round(age, 3), "alive": alive,
            "state": "alive" if alive else "stale", "health": st.health, "level": st.level, "mode": st.mode,
            "uptime_s": st.uptime_s, "vssc": st.vssc, "heartbeats": rec.count, "lost_events": rec.lost_events,
            "restarts": rec.restarts,
        }

    def snapshot(self) -> tuple[dict[str, Any], dict[str, Any]]:
        """(devices by name, other nodes by node id) for the stats."""
        devices = {name: self.entry(nid) for nid, name in self.devices.items()}
        known = set(self.devices) | {self.own_node_id}
        others = {str(nid): self.entry(nid) for nid in sorted(list(self.records)) if nid not in known}
        return devices, others
