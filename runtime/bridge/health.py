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
- a restart (the uptime went down, or the transport saw the node's transfer ids start over:
  ``DeviceStatus.ids_restarted``) is counted, logged and reported (``restarted``: its clock may have restarted).
  The second covers a quick reboot on Cyphal/UDP whose first heartbeats the transport dropped (pycyphal discards
  ids below the last one until its 2 s transfer-id timeout has passed), so that the first one heard carries an
  uptime no lower than the last one before the reboot. No rule on the time between heartbeats: a bridge held up
  for seconds would count restarts that never happened;
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

__all__ = ["OFFLINE_TIMEOUT_S", "DeviceHealth", "NodeRecord"]

OFFLINE_TIMEOUT_S = 3.0

# handler(node_id, event, is_device): event is "first" (its first heartbeat), "lost", "back" or "restarted"
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
            if nid in self.devices:  # first contact (the bridge reads the board's settings then)
                self._notify(nid, "first")
            return
        if not rec.alive or now - rec.last_seen >= self.offline_timeout:
            rec.alive_since = now  # back (possibly before its timer noticed it was gone)
        old_uptime = rec.status.uptime_s
        restarted = st.uptime_s < old_uptime or st.ids_restarted
        if restarted:
            rec.restarts += 1
            rec.alive_since = now  # a device that just booted gets its grace before it must publish
        # last_seen last: /diagnostics may also be built on rclpy's executor thread (an enable service's change),
        # and a record that reads alive must already carry this heartbeat's status and count.
        rec.status, rec.count = st, rec.count + 1
        rec.last_seen = now
        self._arm(rec)
        if restarted:
            # (when the uptime did not go down, the transport's word is why it counts)
            since = "" if st.uptime_s < old_uptime else ", its transfer ids started over"
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

    def last_heartbeat(self, nid: int) -> float | None:
        """When the node's last heartbeat arrived (the clock's time), or None when never heard."""
        rec = self.records.get(nid)
        return None if rec is None else rec.last_seen

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
