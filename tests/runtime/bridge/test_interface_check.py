"""The interface check (sam_runtime.bridge.interface_check, issue 28 part 4), on a fake clock and a fake request:
asked on first contact and after a restart or a return, never per heartbeat; match / mismatch / unknown (0) /
no answer; a mismatch counted and shown on the device's /diagnostics status (WARN, or ERROR with `stop`); `stop`
holds the board's own mappings off with drops counted as `interface_mismatch`, and a match releases them; the
enable service cannot re-enable a held mapping. Also the DroneCAN answer's flag rule (dronecan's own types)."""

from __future__ import annotations

from collections.abc import Callable
from types import SimpleNamespace as NS

import pytest

from sam_runtime.bridge.backend import DeviceStatus
from sam_runtime.bridge.diagnostics import Naming, statuses
from sam_runtime.bridge.interface_check import MISMATCH_DROP, RETRY_S, InterfaceCheck, board_switches
from sam_runtime.bridge.switches import MappingSwitch

WANT = 0x1111_2222_3333_4444
OTHER = 0x9999_8888_7777_6666


class FakeAsk:
    """Records requests; the test answers them."""

    def __init__(self) -> None:
        self.pending: list[tuple[int, Callable[[int | None, str], None]]] = []
        self.asked: list[int] = []

    def __call__(self, nid: int, done: Callable[[int | None, str], None]) -> None:
        self.asked.append(nid)
        self.pending.append((nid, done))

    def answer(self, got: int | None, failure: str = "") -> None:
        _, done = self.pending.pop(0)
        done(got, failure)


def beat(nid: int, uptime: int = 5) -> DeviceStatus:
    return DeviceStatus(nid, "NOMINAL", 0, "OPERATIONAL", uptime, 0)


def make(on_mismatch: str = "warn") -> tuple[InterfaceCheck, FakeAsk, dict[str, MappingSwitch], list[float], list[int]]:
    now = [100.0]
    verdicts: list[int] = []
    ask = FakeAsk()
    switches = {"imu": MappingSwitch("imu"), "rpm": MappingSwitch("rpm"), "both": MappingSwitch("both")}
    mappings = [NS(name="imu", direction="uavcan_to_ros", source_node_ids=frozenset({11})),
                NS(name="rpm", direction="ros_to_uavcan", destination_node_id=11),
                NS(name="both", direction="uavcan_to_ros", source_node_ids=frozenset({11, 12}))]
    check = InterfaceCheck({11: ("imu", WANT), 12: ("gps", WANT)}, ask, on_mismatch=on_mismatch,
                           switches=board_switches(mappings, switches), on_verdict=lambda: verdicts.append(1),
                           clock=lambda: now[0])
    return check, ask, switches, now, verdicts


def test_first_contact_once_then_restart_and_return() -> None:
    check, ask, _, now, verdicts = make()
    check.on_status(beat(11))
    check.on_status(beat(11))  # the second heartbeat: no second request
    assert ask.asked == [11]
    now[0] += 0.004
    ask.answer(WANT)
    assert check.boards[11].verdict == "match" and check.boards[11].answered_after_s == pytest.approx(0.004)
    assert verdicts == [1]
    for _ in range(3):
        check.on_status(beat(11))
    assert ask.asked == [11]
    check.on_health(11, "restarted", True)
    check.on_health(11, "back", True)
    check.on_health(11, "lost", True)
    check.on_health(77, "restarted", False)  # no device of the spec
    assert ask.asked == [11, 11, 11]


def test_mismatch_warn_counts_and_shows_on_diagnostics() -> None:
    check, ask, switches, _, _ = make("warn")
    check.on_status(beat(11))
    ask.answer(OTHER)
    board = check.boards[11]
    assert board.verdict == "mismatch" and board.counts["mismatches"] == 1
    assert all(s.enabled for s in switches.values())  # warn: traffic goes on
    entry = check.device_entries()["imu"]
    assert entry["interface"] == "mismatch" and entry["interface_got"] == f"{OTHER:016x}"
    device = {"seen": True, "alive": True, "level": 0, "health": "NOMINAL", "mode": "OPERATIONAL", "node_id": 11,
              "age_s": 0.1, **entry}
    snap = {"bridge": {"name": "b", "node_id": 127, "transport": "udp", "uptime_s": 1.0, "errors": {},
                       "link": {"up": True, "state": "up", "outages": 0, "down_s": 0.0}, "log_lines": 0},
            "mappings": {}, "devices": {"imu": device}, "other_nodes": {}}
    by_name = {name: (level, msg) for level, name, msg, *_ in statuses(snap, Naming("b", "cyphal", "Cyphal",
                                                                                     "pycyphal"))}
    level, msg = by_name["b/device/imu"]
    assert level == 1 and f"firmware interface {OTHER:016x} != spec {WANT:016x}" in msg


def test_stop_holds_the_boards_own_mappings_until_a_match() -> None:
    check, ask, switches, _, _ = make("stop")
    check.on_status(beat(11))
    ask.answer(OTHER)
    assert not switches["imu"].enabled and not switches["rpm"].enabled
    assert switches["imu"].drop_reason == MISMATCH_DROP
    assert switches["both"].enabled  # another board's traffic too: keeps running
    assert check.stopped(11) and check.status("imu") is not None and check.status("imu")[0] == "ERROR"
    assert "held off" in switches["imu"].set(True) and not switches["imu"].enabled  # the service cannot override
    check.on_health(11, "restarted", True)  # reflashed
    ask.answer(WANT)
    assert switches["imu"].enabled and switches["rpm"].enabled and switches["imu"].drop_reason == "disabled"
    switches["imu"].set(False)
    assert not switches["imu"].enabled and switches["imu"].drop_reason == "disabled"


def test_unknown_and_no_answer_are_no_mismatch() -> None:
    check, ask, switches, now, _ = make("stop")
    check.on_status(beat(11))
    check.on_status(beat(12))
    ask.answer(0)
    ask.answer(None, "no answer within 1 s")
    assert check.boards[11].verdict == "unknown" and check.boards[12].verdict == "no_answer"
    assert all(s.enabled for s in switches.values())
    assert check.status("imu") == ("OK", "firmware interface unknown (the board reports no hash)")
    assert check.snapshot()["boards"]["gps"]["verdict"] == "no_answer"
    now[0] += RETRY_S - 0.1
    check.on_status(beat(12))
    check.on_status(beat(11))  # unknown: asked again only at a restart
    assert ask.asked == [11, 12]
    now[0] += 0.1
    check.on_status(beat(12))  # no answer, RETRY_S ago: asked again
    assert ask.asked == [11, 12, 12]
    ask.answer(WANT)
    assert check.boards[12].verdict == "match"


def test_a_failing_request_is_counted_not_raised() -> None:
    def broken(nid: int, done: Callable[[int | None, str], None]) -> None:
        raise RuntimeError("boom")

    check = InterfaceCheck({11: ("imu", WANT)}, broken)
    check.on_status(beat(11))
    assert check.errors == 1 and check.boards[11].verdict == "no_answer"


def test_on_mismatch_is_checked() -> None:
    with pytest.raises(ValueError, match="warn, stop"):
        InterfaceCheck({}, FakeAsk(), on_mismatch="halt")


@pytest.mark.parametrize(("flag", "crc", "expected"), [(True, OTHER, OTHER), (False, OTHER, 0), (True, 0, 0)])
def test_dronecan_reads_image_crc_only_under_its_flag(flag: bool, crc: int, expected: int) -> None:
    dronecan = pytest.importorskip("dronecan")
    from sam_runtime.bridge.backends.interface_ask import dronecan_ask

    response = dronecan.TYPENAMES["uavcan.protocol.GetNodeInfo"].Response()
    response.software_version.image_crc = crc
    if flag:
        response.software_version.optional_field_flags = response.software_version.OPTIONAL_FIELD_FLAG_IMAGE_CRC
    requests: list[tuple[int, float]] = []

    class Node:
        def request(self, request: object, nid: int, callback: Callable[[object], None], timeout: float) -> None:
            requests.append((nid, timeout))
            callback(NS(response=response))

    got: list[tuple[int | None, str]] = []
    dronecan_ask(NS(node=Node(), node_loop=None))(11, lambda value, failure: got.append((value, failure)))
    assert requests == [(11, 1.0)] and got == [(expected, "")]


def test_dronecan_no_answer_and_link_down() -> None:
    pytest.importorskip("dronecan")
    from sam_runtime.bridge.backends.interface_ask import dronecan_ask

    class Node:
        def request(self, request: object, nid: int, callback: Callable[[object], None], timeout: float) -> None:
            callback(None)  # dronecan's callback at the timeout

    got: list[tuple[int | None, str]] = []
    dronecan_ask(NS(node=Node(), node_loop=None))(11, lambda value, failure: got.append((value, failure)))
    dronecan_ask(NS(node=None))(11, lambda value, failure: got.append((value, failure)))
    assert got == [(None, "no answer within 1 s"), (None, "the DroneCAN link is down")]
