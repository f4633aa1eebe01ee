"""Enable and disable a mapping at run time (issue 19): one ``std_srvs/SetBool`` service per mapping on the bridge's
ROS node, named by the tables' ``enable_service`` (default ``~/enable_<mapping>``: under the node's own name, so
``/uavcan_ros_bridge/enable_imu``, and under its namespace when it has one); the initial state is the tables'
``enabled``.

A disabled mapping drops every message it gets and counts it as ``disabled`` (UAVCAN->ROS before conversion;
ROS->UAVCAN before conversion, and also a command that was queued or held for its rate slot when the mapping was
disabled: nothing goes out after the service answered). Its transfer-loss and liveness bookkeeping go on, so a
re-enabled mapping reports as before. /diagnostics shows ``enabled`` and the service of every mapping (its full name,
as the node resolved it), and a change is published at once.

Threads: the services run on the rclpy executor thread, the paths read :attr:`MappingSwitch.enabled` on either
thread (one attribute, assigned atomically).
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from sam_runtime.bridge.counters import log
from sam_runtime.bridge.lifetime import Lifetime

__all__ = ["EnableServices", "MappingSwitch", "switches_of"]


@dataclass
class MappingSwitch:
    """One mapping's switch: its state, its service name, how often the service changed it.

    ``enabled`` is what the paths read: the service's wish (``wanted``) unless the bridge holds the mapping off
    (:meth:`hold`: the interface check's ``stop`` of a board whose firmware is from another spec), and
    ``drop_reason`` the counter a dropped message goes to (``disabled``, or the hold's reason)."""

    name: str
    service: str = ""
    enabled: bool = True
    changes: int = 0
    requests: int = 0
    resolved: str = ""  # the service's full name once the node created it (namespace, ~ expanded)
    wanted: bool = field(default=True, init=False)  # the service's (or the tables') state
    held: str = field(default="", init=False)  # why the bridge holds it off ("" : not held)
    drop_reason: str = field(default="disabled", init=False)

    def __post_init__(self) -> None:
        self.wanted = self.enabled

    def set(self, value: bool) -> str:
        """Set the state; the answer for the caller."""
        self.requests += 1
        was, self.wanted = self.wanted, bool(value)
        self._apply()
        state = "enabled" if self.wanted else "disabled"
        held = f" (held off: {self.held})" if self.held and self.wanted else ""
        if was == self.wanted:
            return f"mapping {self.name}: already {state}{held}"
        self.changes += 1
        return f"mapping {self.name}: {state}{held}"

    def hold(self, reason: str) -> None:
        """Hold the mapping off for ``reason`` (its drops are counted under it), or release it (``""``)."""
        self.held = reason
        self._apply()

    def _apply(self) -> None:
        # drop_reason first: a path that sees enabled False already counts under the right reason
        self.drop_reason = self.held if self.held else "disabled"
        self.enabled = self.wanted and not self.held

    def snapshot(self) -> dict[str, Any]:
        out: dict[str, Any] = {"enabled": self.enabled, "enable_service": self.resolved or self.service,
                               "enable_changes": self.changes}
        if self.held:
            out["held"] = self.held
        return out


def switches_of(mappings: Any) -> dict[str, MappingSwitch]:
    """A switch per mapping of the tables, in its initial state (tables without the fields: enabled,
    ``~/enable_<name>``)."""
    return {m.name: MappingSwitch(m.name, getattr(m, "enable_service", "") or f"~/enable_{m.name}",
                                  bool(getattr(m, "enabled", True))) for m in mappings}


class EnableServices:
    """The SetBool services, created on the bridge's ROS node when it starts.

    :param on_change: called (on the rclpy thread) after a switch changed, e.g. to publish /diagnostics at once."""

    def __init__(self, lifetime: Lifetime, ros: Any, switches: Mapping[str, MappingSwitch],
                 on_change: Callable[[], None] | None = None) -> None:
        self.lifetime, self.ros, self.switches = lifetime, ros, dict(switches)
        self._on_change = on_change
        self.services: dict[str, Any] = {}

    def attach(self) -> None:
        """After the ROS node (the services are its own)."""
        self.lifetime.add_hooks("enable services", start=self._start)

    def _start(self) -> None:
        from std_srvs.srv import SetBool

        for sw in self.switches.values():
            self.services[sw.name] = self.ros.node.create_service(SetBool, sw.service, self._callback(sw))
            sw.resolved = self.resolved(sw.name)
            if not sw.enabled:
                log.info("mapping %s starts disabled (enable it with std_srvs/SetBool %s)", sw.name,
                         self.resolved(sw.name))

    def resolved(self, mapping: str) -> str:
        """The service's full name as the node resolves it (its namespace, its name for ``~``, remappings)."""
        name = self.switches[mapping].service
        try:
            return str(self.ros.node.resolve_service_name(name))
        except Exception:  # no node (yet): the name as the spec gave it
            return name

    def _callback(self, sw: MappingSwitch) -> Callable[[Any, Any], Any]:
        def on_request(request: Any, response: Any) -> Any:
            try:
                before = sw.enabled
                response.message = sw.set(bool(request.data))
                response.success = True
                if before != sw.enabled:
                    log.info("%s (std_srvs/SetBool %s)", response.message, self.resolved(sw.name))
                    if self._on_change is not None:
                        self._on_change()
            except Exception as ex:  # a bug: answered and counted, never raised into the executor
                self.lifetime.errors["enable_service_error"] += 1
                self.lifetime.rlog.note(("enable", sw.name), logging.ERROR, "enable service: %s: %s",
                                        type(ex).__name__, ex)
                response.success, response.message = False, f"{type(ex).__name__}: {ex}"
            return response

        return on_request
