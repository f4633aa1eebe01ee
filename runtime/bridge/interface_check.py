"""The interface check (issue 28 part 4): does each board run firmware built from the bridge's spec?

A board reports its interface version (sam_codegen.validate.interface_version, 64 bits): Cyphal in GetInfo's
``software_vcs_revision_id``, DroneCAN in GetNodeInfo's ``software_version.image_crc`` with the optional field flag
set. The bridge asks each device of its spec on first contact (its first heartbeat) and again after every restart
the device tracker sees (uptime back, or transfer ids started over) and when its heartbeat comes back after a loss (a
board swapped meanwhile), and compares with the tables' hash of that board. Verdicts:

- ``match``: the same hash;
- ``mismatch``: another one: logged (WARNING), counted (``mismatches``), the device's /diagnostics status ERROR
  (``stop``) or WARN (``warn``) "firmware interface <got> != spec <want>";
- ``unknown``: the board reports none (0, or DroneCAN's flag unset): firmware that predates the hash; not a
  mismatch, said in the device's status message only;
- ``no_answer``: it did not answer the request (counted); asked again at a heartbeat :data:`RETRY_S` later, or at
  its next restart or return.

With the spec's ``bridge.interface_check.on_mismatch: stop`` (the default is ``warn``), a mismatched board's
mappings stop: the :class:`~.switches.MappingSwitch` of every mapping whose only devices are mismatched boards
is held off, so their messages are dropped and counted as ``dropped.interface_mismatch`` (by the paths' existing
disabled branch: nothing new per message); a later ``match`` releases them. Requests and verdicts happen only at
those events, never per message.

Threads: everything here runs on the loop's thread (heartbeats, the requests' callbacks); /diagnostics reads the
verdicts there too, or a consistent copy (:meth:`snapshot` builds new dicts).
"""

from __future__ import annotations

import collections
import time
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any

from sam_runtime.bridge.backend import DeviceStatus
from sam_runtime.bridge.counters import log

__all__ = ["MISMATCH_DROP", "RETRY_S", "Ask", "BoardVerdict", "InterfaceCheck", "board_switches", "hex_hash"]

MISMATCH_DROP = "interface_mismatch"  # the drop reason of a stopped board's mappings
RETRY_S = 10.0  # a board that did not answer is asked again at its first heartbeat this much later
ON_MISMATCH = ("warn", "stop")

# ask(node_id, done): request the board's interface hash; done(hash, "") with 0 for "reports none", or
# done(None, reason) when it could not be asked or did not answer. Called on the loop's thread.
Ask = Callable[[int, Callable[[int | None, str], None]], None]


def hex_hash(value: int) -> str:
    return f"{value:016x}"


@dataclass
class BoardVerdict:
    """One board's state: what it should report, what it reported last and when."""

    device: str
    want: int
    verdict: str = "unchecked"  # unchecked | asking | match | mismatch | unknown | no_answer
    got: int | None = None
    asked_at: float | None = None
    answered_after_s: float | None = None  # time from the request (first contact or restart) to the verdict
    checks: int = 0
    counts: collections.Counter[str] = field(default_factory=collections.Counter)

    def status(self, on_mismatch: str) -> tuple[str, str] | None:
        """(level, text) for its /diagnostics status when the check has something to say; else None."""
        if self.verdict == "mismatch" and self.got is not None:
            level = "ERROR" if on_mismatch == "stop" else "WARN"
            stopped = ": its mappings are stopped" if on_mismatch == "stop" else ""
            return level, f"firmware interface {hex_hash(self.got)} != spec {hex_hash(self.want)}{stopped}"
        if self.verdict == "unknown":
            return "OK", "firmware interface unknown (the board reports no hash)"
        return None


class InterfaceCheck:
    """:param boards: node id -> (device name, the tables' interface hash of that board).
    :param ask: the protocol's request (see :data:`Ask`).
    :param on_mismatch: ``warn`` or ``stop``.
    :param switches: node id -> the switches of the mappings that carry only that board's traffic (``stop``
        holds them off while it mismatches).
    :param on_verdict: called after a verdict changed (the reporter publishes /diagnostics at once).
    """

    def __init__(self, boards: Mapping[int, tuple[str, int]], ask: Ask, *, on_mismatch: str = "warn",
                 switches: Mapping[int, Iterable[Any]] | None = None,
                 on_verdict: Callable[[], None] | None = None, clock: Callable[[], float] = time.monotonic) -> None:
        if on_mismatch not in ON_MISMATCH:
            raise ValueError(f"interface_check.on_mismatch is one of {', '.join(ON_MISMATCH)}, not {on_mismatch!r}")
        self.boards = {nid: BoardVerdict(name, want) for nid, (name, want) in boards.items()}
        self.on_mismatch = on_mismatch
        self._ask = ask
        self._switches = {nid: list(s) for nid, s in (switches or {}).items()}
        self._on_verdict = on_verdict
        self._clock = clock
        self.errors = 0  # a request that raised (a bug in the protocol's ask): counted, never out of a callback

    # ------------------------------------------------------------------------------------------------ events in
    def on_status(self, st: DeviceStatus) -> None:
        """Every heartbeat: a board never checked is asked now (first contact), one that did not answer again after
        :data:`RETRY_S`. A dict lookup per heartbeat."""
        board = self.boards.get(st.node_id)
        if board is None:
            return
        if board.verdict == "unchecked" or (board.verdict == "no_answer" and board.asked_at is not None
                                            and self._clock() - board.asked_at >= RETRY_S):
            self.check(st.node_id)

    def on_health(self, nid: int, event: str, device: bool) -> None:
        """The device tracker's events: a restart, or a return after a loss, may be another firmware."""
        if device and event in ("restarted", "back") and nid in self.boards:
            self.check(nid)

    def check(self, nid: int) -> None:
        board = self.boards[nid]
        board.verdict, board.asked_at, board.checks = "asking", self._clock(), board.checks + 1
        try:
            self._ask(nid, lambda got, failure: self._answer(nid, got, failure))
        except Exception as ex:  # the protocol's request failed to start: counted and logged, asked again later
            self.errors += 1
            self._answer(nid, None, f"{type(ex).__name__}: {ex}")

    def _answer(self, nid: int, got: int | None, failure: str) -> None:
        board = self.boards[nid]
        before = board.verdict
        board.got = got
        if board.asked_at is not None:
            board.answered_after_s = self._clock() - board.asked_at
        if got is None:
            board.verdict = "no_answer"
            log.warning("%s (node %d) did not report its firmware interface: %s", board.device, nid, failure)
        elif got == 0:
            board.verdict = "unknown"
            log.info("%s (node %d): firmware interface unknown (it reports no hash)", board.device, nid)
        elif got == board.want:
            board.verdict = "match"
            log.info("%s (node %d): firmware interface %s matches the spec", board.device, nid, hex_hash(got))
        else:
            board.verdict = "mismatch"
            board.counts["mismatches"] += 1
            log.warning("%s (node %d): firmware interface %s != spec %s%s", board.device, nid, hex_hash(got),
                        hex_hash(board.want), ": its mappings stop" if self.on_mismatch == "stop" else "")
        board.counts[board.verdict] += 1
        self._hold(nid, board.verdict == "mismatch" and self.on_mismatch == "stop")
        if board.verdict != before and self._on_verdict is not None:
            self._on_verdict()

    def _hold(self, nid: int, held: bool) -> None:
        for switch in self._switches.get(nid, ()):
            switch.hold(MISMATCH_DROP if held else "")

    # ------------------------------------------------------------------------------------------------ queries
    def stopped(self, nid: int) -> bool:
        board = self.boards.get(nid)
        return board is not None and board.verdict == "mismatch" and self.on_mismatch == "stop"

    def status(self, device: str) -> tuple[str, str] | None:
        """The check's word for a device's /diagnostics status (see :meth:`BoardVerdict.status`)."""
        for board in self.boards.values():
            if board.device == device:
                return board.status(self.on_mismatch)
        return None

    def device_entries(self) -> dict[str, dict[str, Any]]:
        """Per device the keys its /diagnostics status and the stats show (``interface``: the verdict)."""
        return {b.device: {"interface": b.verdict, "interface_want": hex_hash(b.want),
                           "interface_got": "" if b.got is None else hex_hash(b.got),
                           "interface_on_mismatch": self.on_mismatch,
                           "interface_mismatches": b.counts["mismatches"],
                           **({"interface_verdict_s": round(b.answered_after_s, 4)}
                              if b.answered_after_s is not None else {})}
                for b in self.boards.values()}

    def snapshot(self) -> dict[str, Any]:
        """JSON-serialisable: per device its verdict, hashes, time to the verdict and counts."""
        return {"on_mismatch": self.on_mismatch, "errors": self.errors, "boards": {
            b.device: {"node_id": nid, "verdict": b.verdict, "want": hex_hash(b.want),
                       "got": None if b.got is None else hex_hash(b.got), "checks": b.checks,
                       "verdict_after_s": None if b.answered_after_s is None else round(b.answered_after_s, 4),
                       **dict(b.counts)}
            for nid, b in self.boards.items()}}


def board_switches(mappings: Iterable[Any], switches: Mapping[str, Any]) -> dict[int, list[Any]]:
    """Node id -> the switches of the mappings that carry one board's traffic alone: UAVCAN->ROS from that node only,
    ROS->UAVCAN to that node only (a mapping of several boards, or of any node, keeps running: the others' traffic
    is fine)."""
    out: dict[int, list[Any]] = {}
    for m in mappings:
        if getattr(m, "any_node", False) or m.name not in switches:
            continue
        if m.direction == "uavcan_to_ros":
            nodes = set(m.source_node_ids)
        elif hasattr(m, "destination_node_ids"):  # DroneCAN
            nodes = set(m.destination_node_ids)
        else:
            nodes = {m.destination_node_id} if m.destination_node_id is not None else set()
        if len(nodes) == 1:
            out.setdefault(next(iter(nodes)), []).append(switches[m.name])
    return out
