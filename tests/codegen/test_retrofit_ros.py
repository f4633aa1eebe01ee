"""tests/specs/retrofit.yaml's ROS packages built (CMake, rosidl) and used by rclpy (issue 27, class 3): the srv of
another package (`external_services`: uavcan_ros_msgs/UavcanGetNodeInfo) and the spec's own srv, both with
constants, import with the declared constants and fields, and their messages serialize. A system test (CMake, a
child process)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from helpers.ros_packages import built_prefix, missing_tools, run_child
from helpers.runtime_support import domain_id

from sam_codegen.frontend.loader import load_spec_file
from sam_codegen.targets import ros as emit_ros
from sam_codegen.validate.resolve import validate

pytestmark = [pytest.mark.ros, pytest.mark.slow]

SPEC = Path(__file__).resolve().parents[1] / "specs" / "retrofit.yaml"

_CHILD = """
import json
from rclpy.serialization import deserialize_message, serialize_message
from retrofit_msgs.srv import Calibrate
from uavcan_ros_msgs.srv import UavcanGetNodeInfo

response = UavcanGetNodeInfo.Response(success=True, name="esc", uptime_sec=42, health=1)
again = deserialize_message(serialize_message(response), UavcanGetNodeInfo.Response)
print(json.dumps({
    "constants": [UavcanGetNodeInfo.Request.HEALTH_OK, UavcanGetNodeInfo.Request.HEALTH_WARNING,
                  Calibrate.Request.MODE_ZERO, Calibrate.Request.MODE_SPAN],
    "response": sorted(UavcanGetNodeInfo.Response.get_fields_and_field_types()),
    "again": [again.name, again.uptime_sec, again.health, again.vendor_note],
}))
"""


def test_the_external_and_own_srvs_build_and_import(tmp_path: Path) -> None:
    why = missing_tools()
    if why:
        pytest.skip(why)
    resolved = validate(load_spec_file(SPEC))
    for path, text in emit_ros.emit(resolved).items():
        target = tmp_path / path
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text(text, encoding="utf-8")
    prefix = built_prefix([tmp_path / "ros" / name for name in emit_ros.build_order(resolved)])
    proc = run_child(["-c", _CHILD], prefix, domain_id(41), timeout=300)
    assert proc.returncode == 0, proc.stderr[-3000:]
    found = json.loads(proc.stdout.strip().splitlines()[-1])
    assert found["constants"] == [0, 1, 1, 2]
    assert found["response"] == sorted(["success", "message", "name", "uptime_sec", "health", "mode",
                                        "vendor_specific_status_code", "vendor_note"])
    assert found["again"] == ["esc", 42, 1, ""]
