"""UAVCAN -> ROS mappings that get nothing from a device whose heartbeat is alive (rules: bridge.liveness),
checked once a second (the graces are 3 s or more: a finding comes within a second of its grace, and the
check shares the bridge's one housekeeping wake-up a second); a mapping going silent, and the end of it, is
logged once and handed to the handlers (the bridge publishes /diagnostics at once)."""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable, Mapping
from typing import Any

from sam_runtime.bridge.counters import log
from sam_runtime.bridge.lifetime import Lifetime
from sam_runtime.bridge.liveness import LivenessCheck, Silence

__all__ = ["CHECK_PERIOD_S", "SilenceWatch"]

CHECK_PERIOD_S = 1.0


class SilenceWatch:
    """:param mappings: (name, nominal rate [Hz], accepted source node ids) per UAVCAN -> ROS mapping.
    :param alive_since: a node's heartbeat (re)appeared at (monotonic s), None if it is not alive.
    :param last_message: (mapping, node id) -> when its last transfer arrived (monotonic s), or None.
    :param listening_since: since when the bridge listens (its link last opened; monotonic s).
    :param last_heartbeat: when a node's last heartbeat arrived (monotonic s), None if never heard."""

    def __init__(self, mappings: Iterable[tuple[str, float, Iterable[int]]], device_names: Mapping[int, str], *,
                 alive_since: Callable[[int], float | None], last_message: Callable[[str, int], float | None],
                 listening_since: Callable[[], float], last_heartbeat: Callable[[int], float | None] | None = None
                 ) -> None:
        self.liveness = LivenessCheck(mappings, device_names)
        self._alive_since, self._last_message, self._listening_since = alive_since, last_message, listening_since
        self._last_heartbeat = last_heartbeat
        self._handlers: list[Callable[[], None]] = []

    def attach(self, lifetime: Lifetime) -> None:
        lifetime.every(CHECK_PERIOD_S, "silence", self.check)

    def add_handler(self, handler: Callable[[], None]) -> None:
        self._handlers.append(handler)

    @property
    def findings(self) -> dict[str, Silence | None]:
        return self.liveness.findings

    def check(self) -> None:
        changes = self.liveness.update(time.monotonic(), alive_since=self._alive_since,
                                      last_message=self._last_message, listening_since=self._listening_since(),
                                      last_heartbeat=self._last_heartbeat)
        for name, before, found in changes:
            if found is not None:
                log.warning("%s: %s", name, found.message())
            elif before is not None:
                why = ("messages again from" if self._alive_since(before.node_id) is not None
                       else "no longer watched: no heartbeat from")
                log.info("%s: %s device %s (node %d)", name, why, before.device, before.node_id)
        if changes:
            for handler in self._handlers:
                handler()

    def entry(self, mapping: str) -> dict[str, Any]:
        """The mapping's liveness for the stats."""
        silence = self.liveness.findings.get(mapping)
        if silence is None:
            return {"state": "ok"}
        return {"state": silence.state, "message": silence.message(), "node_id": silence.node_id,
                "silent_s": round(silence.silent_s, 3), "grace_s": silence.grace_s,
                "nominal_rate_hz": silence.rate_hz}
