"""sam_runtime.cyphal_io.ports: the bridge's named ports and their registers (issue 11, defect 12), on pycyphal's own
in-memory registry. Read over the network by a Cyphal tool: tests/test_glider_bridge.py."""

from __future__ import annotations

from typing import Any

import pytest

pytest.importorskip("pycyphal")

from sam_runtime.cyphal_io.ports import PortConfigError, register_environment, register_node_id, resolve_subject


@pytest.fixture(scope="module")
def heartbeat_type() -> type:
    from sam_runtime.cyphal_io.dsdl_cache import ensure_compiled

    ensure_compiled(())  # uavcan: pycyphal.application needs it
    import uavcan.node

    return uavcan.node.Heartbeat_1_0


def _registry(env: dict[str, str]) -> Any:
    import pycyphal.application

    return pycyphal.application.make_registry(None, environment_variables=register_environment(env))



def test_default_is_the_spec_subject_and_the_type_is_exposed(heartbeat_type: type) -> None:
    reg = _registry({})
    assert resolve_subject(reg, "sub", "imu", heartbeat_type, 1100) == 1100
    assert int(reg["uavcan.sub.imu.id"]) == 1100
    assert str(reg["uavcan.sub.imu.type"]) == "uavcan.node.Heartbeat.1.0"
    assert resolve_subject(reg, "pub", "thruster_1_rpm", heartbeat_type, 1200) == 1200
    register_node_id(reg, 100)
    assert int(reg["uavcan.node.id"]) == 100
    assert sorted(reg) == ["uavcan.node.id", "uavcan.pub.thruster_1_rpm.id", "uavcan.pub.thruster_1_rpm.type",
                           "uavcan.sub.imu.id", "uavcan.sub.imu.type"]


def test_environment_overrides_the_default(heartbeat_type: type) -> None:
    reg = _registry({"UAVCAN__SUB__IMU__ID": "1234", "UAVCAN__NODE__ID": "7"})
    assert resolve_subject(reg, "sub", "imu", heartbeat_type, 1100) == 1234
    assert resolve_subject(reg, "sub", "gps", heartbeat_type, 1102) == 1102
    register_node_id(reg, 100)  # the bridge decides its node id; UAVCAN__NODE__ID is not a register override
    assert int(reg["uavcan.node.id"]) == 100


@pytest.mark.parametrize(("value", "error"), [
    ("65535", "register uavcan.sub.imu.id = 65535 is not a subject id (0..8191; 65535 = not configured): the "
              "bridge needs this port; unset UAVCAN__SUB__IMU__ID or give it a subject id"),
    ("8192", "register uavcan.sub.imu.id = 8192 is not a subject id (0..8191; 65535 = not configured): the "
             "bridge needs this port; unset UAVCAN__SUB__IMU__ID or give it a subject id"),
    ("imu", "UAVCAN__SUB__IMU__ID='imu' is not a subject id (0..8191): register uavcan.sub.imu.id"),
    ("70000", "UAVCAN__SUB__IMU__ID='70000' is not a subject id (0..8191): register uavcan.sub.imu.id"),
])
def test_unusable_override_is_a_clear_error(heartbeat_type: type, value: str, error: str) -> None:
    reg = _registry({"UAVCAN__SUB__IMU__ID": value})
    with pytest.raises(PortConfigError) as info:
        resolve_subject(reg, "sub", "imu", heartbeat_type, 1100)
    assert str(info.value) == error
