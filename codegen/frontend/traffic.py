"""A mapping's run-time traffic keys (issue 19): `max_rate_hz`, `deadline`, `enabled`, `enable_service`.

- `max_rate_hz` (number > 0, either direction): the bridge passes on the latest message at most this often
  (UAVCAN->ROS: published to ROS; ROS->UAVCAN: commands coalesced, the latest sent), trailing edge: a message held
  back is passed on when its slot comes unless a newer one replaced it, so the last value of a stream that stops is
  never lost. Absent: every message.
- `deadline` (seconds > 0, ros_to_uavcan only): a command older than this when it would be sent is not sent; its age
  counts from when the bridge's ROS subscription took it (the bridge's monotonic clock), not from its header stamp
  (the stamp is the publisher's clock, maybe sim time or another machine's, and many command types have none). A
  UAVCAN->ROS message has no "too late" for the bridge to judge, so the key is an error there. With `max_rate_hz`
  the deadline must be longer than the interval 1 / max_rate_hz: the command held for its slot waits up to that.
- `enabled` (bool, default true): the initial state of the mapping's switch; `enable_service` (a ROS name, default
  `~/enable_<mapping>`, under the bridge node's name) is the std_srvs/SetBool service that flips it at run time.
  SAM's current bridge calls its switches `start_stop_<topic>`: set `enable_service: start_stop_thruster1_cmd` to
  keep that name. Two mappings of one protocol may not share a service.

Invariant: every error is a file:line:col diagnostic; the values returned are None/defaults after an error.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass

from sam_codegen.frontend.reading import Reader, number
from sam_codegen.model.diagnostics import Diagnostics, Pos
from sam_codegen.model.protocols.registry import protocol as protocol_of
from sam_codegen.model.spec import UAVCAN_TO_ROS, Mapping

__all__ = ["TRAFFIC_KEYS", "Traffic", "check_enable_services", "parse_traffic"]

TRAFFIC_KEYS = ("max_rate_hz", "deadline", "enabled", "enable_service")
# absolute (/a/b), relative (a/b) or private (~/a) ROS name; segments as ROS topic names
SERVICE_NAME = re.compile(r"(~/|/)?[A-Za-z_][A-Za-z0-9_]*(/[A-Za-z_][A-Za-z0-9_]*)*")


@dataclass(frozen=True)
class Traffic:
    max_rate_hz: float | None = None
    deadline_s: float | None = None
    enabled: bool = True
    enable_service: str = ""


def _positive(r: Reader, key: str, what: str, unit: str, diag: Diagnostics) -> float | None:
    value = number(r.node(key), f"{key!r} of {what}", diag)
    if value is not None and value <= 0:
        diag.error(r.key_pos(key), f"{key} of {what} must be positive, found {value}", unit)
        return None
    return None if value is None else float(value)


def parse_traffic(r: Reader, what: str, direction: str | None, diag: Diagnostics) -> Traffic:
    """The traffic keys of a mapping's Reader (``r.what`` is e.g. "mapping 'level'")."""
    rate = _positive(r, "max_rate_hz", what, "a rate in Hz above 0", diag)
    deadline = _positive(r, "deadline", what, "seconds above 0", diag)
    if r.node("deadline") is not None and direction == UAVCAN_TO_ROS:
        diag.error(r.key_pos("deadline"), f"{what} goes UAVCAN->ROS: a deadline applies to commands (ros_to_uavcan) "
                   "only", "max_rate_hz to thin a stream, or no deadline")
        deadline = None
    if rate is not None and deadline is not None and deadline <= 1.0 / rate:
        diag.error(r.key_pos("deadline"), f"deadline of {what} ({deadline:g} s) is not longer than the interval of its "
                   f"max_rate_hz ({1.0 / rate:g} s): a command held for its slot could expire every time",
                   f"a deadline above {1.0 / rate:g} s")
        deadline = None
    enabled = r.get("enabled", bool, True)
    service = r.get("enable_service", str, "")
    if service and not SERVICE_NAME.fullmatch(service):
        diag.error(r.node("enable_service").pos,  # type: ignore[union-attr]
                   f"enable_service {service!r} of {what} is not a valid ROS service name",
                   "/name, name or ~/name, each segment a letter or underscore then letters, digits, underscores")
        service = ""
    elif r.node("enable_service") is not None and service == "":
        diag.error(r.key_pos("enable_service"), f"enable_service of {what} is empty", "a ROS service name")
    return Traffic(rate, deadline, enabled if isinstance(enabled, bool) else True,
                   service if isinstance(service, str) else "")


def check_enable_services(mappings: Sequence[Mapping], protocol: str, diag: Diagnostics) -> None:
    """No two mappings of one protocol (one bridge node) share an enable service."""
    seen: dict[str, tuple[str, Pos]] = {}
    for m in mappings:
        name = m.enable_service_name
        if name in seen:
            first, pos = seen[name]
            what = protocol_of(protocol).mapping_noun
            diag.error(m.pos, f"enable_service {name!r} of {what} {m.name!r} is also that of {first!r} (line "
                       f"{pos.line})", "one service per mapping")
        else:
            seen[name] = (m.name, m.pos)
