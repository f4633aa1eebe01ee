"""The bridge's ROS parameter sets of the boards' settings (sam_runtime.bridge.device_params), without ROS or a bus:
a fake bus access in a real asyncio loop thread. A set is refused by the spec without bus traffic; a board that keeps
another value, or does not answer, fails the set with the reason; a real confirmed through float32 succeeds. A store
answers None only on the board's OK, else the reason; an override (--params-file) is written after the board's first
read when it differs, once, and a refusal is logged and counted."""

from __future__ import annotations

import asyncio
import logging
import threading
from collections.abc import Iterator
from types import SimpleNamespace
from typing import Any

import pytest

from sam_codegen.contracts.table_types import DeviceParameterInfo
from sam_runtime.bridge.backends.param_access import ParamIOError
from sam_runtime.bridge.device_params import DeviceParams

POLES = DeviceParameterInfo("thruster_1", "motor.pole_count", "integer", 14, "", 2, 48, "", (), None, True,
                            (("cyphal", "motor.pole_count"), ("dronecan", "MOTOR_POLE_COUNT")))
DIRECTION = DeviceParameterInfo("thruster_1", "motor.direction", "enum", "forward", "", None, None, "",
                                (("forward", 1), ("reverse", -1)), None, False,
                                (("cyphal", "motor.direction"), ("dronecan", "MOTOR_DIRECTION")))
LIMIT = DeviceParameterInfo("thrust_vector", "servo.limit", "real", 0.12, "", 0.02, 0.2, "rad", (), None, False,
                            (("cyphal", "servo.limit"), ("dronecan", "SERVO_LIMIT")))


class FakeBoard:
    """Answers like a board: keeps `keep` (refuses) for one name, never answers for another."""

    def __init__(self) -> None:
        self.values: dict[str, Any] = {"MOTOR_POLE_COUNT": 14, "MOTOR_DIRECTION": 1, "SERVO_LIMIT": 0.12}
        self.refuse: set[str] = set()
        self.accept_once: set[str] = set()  # the first write taken, every later one refused
        self.silent: set[int] = set()
        self.requests: list[tuple[int, str, Any]] = []
        self.stores: list[int] = []
        self.refuse_store: set[int] = set()

    async def __call__(self, nid: int, name: str, kind: str, value: Any, timeout: float) -> Any:
        self.requests.append((nid, name, value))
        if nid in self.silent:
            raise ParamIOError(f"node {nid} did not answer within {timeout:g} s")
        if value is not None and name not in self.refuse:
            # a real comes back as float32
            self.values[name] = float(f"{value:.7g}") + 1e-9 if kind == "real" else value
            if name in self.accept_once:
                self.refuse.add(name)
        return self.values[name]

    async def store(self, nid: int, timeout: float) -> None:
        self.stores.append(nid)
        if nid in self.silent:
            raise ParamIOError(f"node {nid} did not answer within {timeout:g} s")
        if nid in self.refuse_store:
            raise ParamIOError(f"node {nid} refused to store its settings: status 1 (FAILURE)")


@pytest.fixture
def setup() -> Iterator[tuple[DeviceParams, FakeBoard]]:
    loop = asyncio.new_event_loop()
    thread = threading.Thread(target=loop.run_forever, daemon=True)
    thread.start()
    board = FakeBoard()
    params = DeviceParams(SimpleNamespace(closed=False), SimpleNamespace(node=None),
                          {21: "thruster_1", 23: "thrust_vector"}, (POLES, DIRECTION, LIMIT), "dronecan", board,
                          timeout=0.5)
    params._loop = loop  # (what _start sets, without a ROS node)
    try:
        yield params, board
    finally:
        loop.call_soon_threadsafe(loop.stop)
        thread.join(5)
        loop.close()


def test_a_value_the_spec_refuses_never_reaches_the_board(setup: tuple[DeviceParams, FakeBoard]) -> None:
    params, board = setup
    assert params._set_one("thruster_1.motor.direction", "sideways") == (
        "refused by the spec: 'sideways' is none of ['forward', 'reverse']")
    assert params._set_one("thruster_1.motor.pole_count", 2.5) is not None
    assert board.requests == [] and params.counts["refused_by_spec"] == 2


def test_a_confirmed_set_and_an_enum_written_as_its_integer(setup: tuple[DeviceParams, FakeBoard]) -> None:
    params, board = setup
    assert params._set_one("thruster_1.motor.direction", "reverse") is None
    assert params._set_one("thrust_vector.servo.limit", 0.15) is None  # confirmed through float32
    assert board.requests == [(21, "MOTOR_DIRECTION", -1), (23, "SERVO_LIMIT", 0.15)]
    assert params.differing_by_device()["thruster_1"] == "motor.direction reverse (spec forward)"


def test_a_board_that_keeps_its_value_fails_the_set(setup: tuple[DeviceParams, FakeBoard]) -> None:
    params, board = setup
    board.refuse.add("MOTOR_POLE_COUNT")
    assert params._set_one("thruster_1.motor.pole_count", 20) == "refused by thruster_1 (node 21): it keeps 14"
    assert params.counts["refused_by_board"] == 1


def test_a_board_that_does_not_answer_fails_the_set(setup: tuple[DeviceParams, FakeBoard]) -> None:
    params, board = setup
    board.silent.add(23)
    assert params._set_one("thrust_vector.servo.limit", 0.1) == "thrust_vector: node 23 did not answer within 0.5 s"
    assert params.counts["timeouts"] == 1


def test_only_the_devices_of_the_bridge_are_parameters() -> None:
    params = DeviceParams(SimpleNamespace(closed=False), None, {21: "thruster_1"}, (POLES, LIMIT), "cyphal",
                          FakeBoard())
    assert list(params.settings) == ["thruster_1.motor.pole_count"]
    assert params.settings["thruster_1.motor.pole_count"].bus_name == "motor.pole_count"


def test_a_store_succeeds_only_on_the_boards_ok(setup: tuple[DeviceParams, FakeBoard]) -> None:
    params, board = setup
    board.refuse_store.add(21)
    board.silent.add(23)
    assert params.store("thruster_1") == "thruster_1: node 21 refused to store its settings: status 1 (FAILURE)"
    assert params.store("thrust_vector") == "thrust_vector: node 23 did not answer within 3 s"
    assert params.store("nobody") == "nobody is no board with settings of this bridge"
    board.refuse_store.clear()
    assert params.store("thruster_1") is None
    assert board.stores == [21, 23, 21]
    assert params.counts["stores"] == 4 and params.counts["store_failures"] == 3


def _read(params: DeviceParams, nid: int) -> None:
    assert params._loop is not None
    asyncio.run_coroutine_threadsafe(params._read_board(nid), params._loop).result(5)


def test_an_override_is_written_after_the_first_read_when_it_differs(setup: tuple[DeviceParams, FakeBoard],
                                                                     caplog: pytest.LogCaptureFixture) -> None:
    params, board = setup
    caplog.set_level(logging.INFO)
    poles, direction = "thruster_1.motor.pole_count", "thruster_1.motor.direction"
    assert params._override(poles, params.settings[poles], 20) == 20
    assert params._override(direction, params.settings[direction], "forward") == "forward"  # the board's already
    _read(params, 21)
    assert [r for r in board.requests if r[2] is not None] == [(21, "MOTOR_POLE_COUNT", 20)]
    assert "thruster_1.motor.pole_count: 14 -> 20" in caplog.messages[-1]
    assert params.counts["overrides_applied"] == 1 and params.pending_overrides == {}
    _read(params, 21)  # a later read (the board restarted): written once per start only
    assert len([r for r in board.requests if r[2] is not None]) == 1


def test_a_refused_override_is_logged_and_counted(setup: tuple[DeviceParams, FakeBoard],
                                                  caplog: pytest.LogCaptureFixture) -> None:
    params, board = setup
    poles, limit = "thruster_1.motor.pole_count", "thrust_vector.servo.limit"
    # the spec refuses it: the default is declared, nothing is written
    assert params._override(poles, params.settings[poles], 60) == 14 and poles not in params.pending_overrides
    assert "the override 60 is refused by the spec: 60 is outside 2..48" in caplog.messages[-1]
    assert params._override(poles, params.settings[poles], 30) == 30
    board.refuse.add("MOTOR_POLE_COUNT")
    _read(params, 21)
    assert caplog.messages[-1] == "thruster_1.motor.pole_count: 14 -> 30 REFUSED: thruster_1 (node 21) keeps 14"
    assert params.counts["overrides_refused"] == 2
    # a board that does not answer the read: the override waits for its next read
    assert params._override(limit, params.settings[limit], 0.1) == 0.1
    board.silent.add(23)
    _read(params, 23)
    assert params.pending_overrides == {limit: 0.1} and params.counts["read_failures"] == 1


def _atomic(params: DeviceParams, **values: Any) -> Any:
    """The on-set callback as rclpy calls it for set_parameters_atomically: every parameter at once."""
    return params._on_set([SimpleNamespace(name=n.replace("__", "."), value=v) for n, v in values.items()])


def test_an_atomic_set_is_checked_whole_before_anything_is_written(setup: tuple[DeviceParams, FakeBoard]) -> None:
    params, board = setup
    result = _atomic(params, thruster_1__motor__pole_count=20, thrust_vector__servo__limit=0.5)
    assert not result.successful and result.reason.startswith("thrust_vector.servo.limit: refused by the spec")
    assert board.requests == []


def test_an_atomic_set_that_a_board_fails_is_written_back(setup: tuple[DeviceParams, FakeBoard]) -> None:
    params, board = setup
    for nid in (21, 23):
        _read(params, nid)  # what the boards hold: known from their first read
    board.requests.clear()
    board.refuse.add("SERVO_LIMIT")
    result = _atomic(params, thruster_1__motor__pole_count=20, thruster_1__motor__direction="reverse",
                     thrust_vector__servo__limit=0.15)
    assert not result.successful
    assert result.reason == ("thrust_vector.servo.limit: refused by thrust_vector (node 23): it keeps 0.12; "
                             "written back: thruster_1.motor.direction, thruster_1.motor.pole_count"), result.reason
    assert board.values["MOTOR_POLE_COUNT"] == 14 and board.values["MOTOR_DIRECTION"] == 1
    assert board.requests == [(21, "MOTOR_POLE_COUNT", 20), (21, "MOTOR_DIRECTION", -1), (23, "SERVO_LIMIT", 0.15),
                              (21, "MOTOR_DIRECTION", 1), (21, "MOTOR_POLE_COUNT", 14)]
    assert params.counts["rollbacks"] == 2 and params.counts["rollback_failures"] == 0


def test_a_rollback_that_fails_is_named(setup: tuple[DeviceParams, FakeBoard]) -> None:
    params, board = setup
    _read(params, 21)
    board.silent.add(23)
    board.accept_once.add("MOTOR_POLE_COUNT")  # takes 20, then keeps it
    result = _atomic(params, thruster_1__motor__pole_count=20, thruster_1__motor__direction="reverse",
                     thrust_vector__servo__limit=0.15)
    assert result.reason == ("thrust_vector.servo.limit: thrust_vector: node 23 did not answer within 0.5 s; "
                             "written back: thruster_1.motor.direction; NOT written back: "
                             "thruster_1.motor.pole_count (it keeps 20)"), result.reason
    assert board.values["MOTOR_POLE_COUNT"] == 20 and params.counts["rollback_failures"] == 1
    # shown as it is: the parameter's value follows what the board answered
    assert params.board_values["thruster_1.motor.pole_count"] == 20
