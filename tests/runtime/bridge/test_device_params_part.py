"""The bridge's ROS parameter sets of the boards' settings (sam_runtime.bridge.device_params), without ROS or a bus:
a fake bus access in a real asyncio loop thread. A set is refused by the spec without bus traffic; a board that keeps
another value, or does not answer, fails the set with the reason; a real confirmed through float32 succeeds."""

from __future__ import annotations

import asyncio
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
        self.silent: set[int] = set()
        self.requests: list[tuple[int, str, Any]] = []

    async def __call__(self, nid: int, name: str, kind: str, value: Any, timeout: float) -> Any:
        self.requests.append((nid, name, value))
        if nid in self.silent:
            raise ParamIOError(f"node {nid} did not answer within {timeout:g} s")
        if value is not None and name not in self.refuse:
            # a real comes back as float32
            self.values[name] = float(f"{value:.7g}") + 1e-9 if kind == "real" else value
        return self.values[name]


@pytest.fixture
def setup() -> Iterator[tuple[DeviceParams, FakeBoard]]:
    loop = asyncio.new_event_loop()
    thread = threading.Thread(target=loop.run_forever, daemon=True)
    thread.start()
    board = FakeBoard()
    params = DeviceParams(SimpleNamespace(closed=False), None, {21: "thruster_1", 23: "thrust_vector"},
                          (POLES, DIRECTION, LIMIT), "dronecan", board, timeout=0.5)
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
