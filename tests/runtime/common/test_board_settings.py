"""A board's settings: the rules both the bridge and a simulated board apply, a board's saved values across a
reboot, and the values in each protocol's wire form (GetSet's union, a register)."""

from __future__ import annotations

from types import SimpleNamespace

import pytest
from helpers.runtime_support import generated_or_skip

from sam_codegen.contracts.table_types import DeviceParameterInfo
from sam_runtime.common.board_settings import BoardSettings, from_stored, ros_problem, stored_problem, to_stored

POLES = DeviceParameterInfo("thruster_1", "motor.pole_count", "integer", 14, "", 2, 48, "", (), None, True,
                            (("cyphal", "motor.pole_count"), ("dronecan", "MOTOR_POLE_COUNT")))
DIRECTION = DeviceParameterInfo("thruster_1", "motor.direction", "enum", "forward", "", None, None, "",
                                (("forward", 1), ("reverse", -1)), None, False,
                                (("cyphal", "motor.direction"), ("dronecan", "MOTOR_DIRECTION")))
TRIM = DeviceParameterInfo("thrust_vector", "servo.trim", "real", 0.0, "", -0.1, 0.1, "rad", (), None, False,
                           (("cyphal", "servo.trim"), ("dronecan", "SERVO_TRIM")))
LABEL = DeviceParameterInfo("imu", "label", "string", "a", "", None, None, "", (), 4, False,
                            (("cyphal", "label"), ("dronecan", "LABEL")))


@pytest.mark.parametrize(("p", "value", "problem"), [
    (POLES, 14, None), (POLES, 49, "49 is outside 2..48"), (POLES, 1.5, "motor.pole_count is an integer, not float"),
    (POLES, True, "motor.pole_count is an integer, not bool"),
    (DIRECTION, "reverse", None), (DIRECTION, "sideways", "'sideways' is none of ['forward', 'reverse']"),
    (TRIM, 0.1, None), (TRIM, -0.1, None), (TRIM, 0, None), (TRIM, 0.1001, "0.1001 is outside -0.1..0.1 rad"),
    (TRIM, float("nan"), "nan is not a finite float32"), (LABEL, "abcd", None),
    (LABEL, "abcde", "'abcde' is longer than 4 bytes"),
])
def test_the_bridge_refuses_what_a_board_would(p: DeviceParameterInfo, value: object, problem: str | None) -> None:
    found = ros_problem(p, value)
    assert found == problem if problem is None else found is not None and found.startswith(problem)


def test_an_enum_is_stored_as_its_integer_and_shown_by_name() -> None:
    assert to_stored(DIRECTION, "reverse") == -1
    assert from_stored(DIRECTION, -1) == "reverse"
    assert from_stored(DIRECTION, 7) == "7"  # a value the spec does not name: shown, never hidden
    assert stored_problem(DIRECTION, 7) == "7 is none of [-1, 1]"


def test_a_reboot_keeps_what_was_saved_and_erase_brings_the_defaults_back() -> None:
    board = BoardSettings((POLES, DIRECTION), "dronecan")
    assert board.write("MOTOR_POLE_COUNT", 60) is not None and board.values["MOTOR_POLE_COUNT"] == 14
    assert board.refused == 1
    assert board.write("MOTOR_POLE_COUNT", 12) is None
    board.reboot()
    assert board.values["MOTOR_POLE_COUNT"] == 14  # not saved: lost
    board.write("MOTOR_POLE_COUNT", 12)
    board.save()
    board.reboot()
    assert board.values["MOTOR_POLE_COUNT"] == 12
    board.erase()
    board.reboot()
    assert board.values == {"MOTOR_POLE_COUNT": 14, "MOTOR_DIRECTION": 1}


def test_a_dronecan_board_answers_getset_by_name_and_index_and_refuses_out_of_range() -> None:
    import dronecan

    from sam_runtime.dronecan_io.params import fill_value, read_value
    from sam_runtime.sim.params_dronecan import PARAM_GETSET, param_getset_handler

    board = BoardSettings((POLES, DIRECTION), "dronecan")
    handler = param_getset_handler("thruster_1", board)
    getset = dronecan.TYPENAMES[PARAM_GETSET]

    def ask(name: str = "", index: int = 0, value: int | None = None) -> object:
        req = getset.Request(index=index, name=name)
        fill_value(req.value, "integer", value)
        return handler(SimpleNamespace(request=req))

    resp = ask(index=1)
    assert bytes(resp.name).decode() == "MOTOR_DIRECTION" and read_value(resp.value, "enum") == 1
    resp = ask("MOTOR_POLE_COUNT", value=16)
    assert read_value(resp.value, "integer") == 16 and read_value(resp.max_value, "integer") == 48
    resp = ask("MOTOR_POLE_COUNT", value=50)
    assert read_value(resp.value, "integer") == 16 and board.refused == 1
    assert bytes(ask("NO_SUCH").name) == b"" and bytes(ask(index=2).name) == b""


@pytest.mark.parametrize(("p", "value"), [(POLES, 20), (DIRECTION, -1), (TRIM, 0.0625), (LABEL, "ab")])
def test_a_register_value_reads_back(p: DeviceParameterInfo, value: object) -> None:
    generated_or_skip().compile_dsdl()  # pycyphal's uavcan package
    from sam_runtime.cyphal_io.registers import register_stored, register_value

    assert register_stored(p.type, register_value(p.type, value)) == value  # type: ignore[arg-type]
