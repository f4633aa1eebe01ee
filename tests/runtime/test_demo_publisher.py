"""The monitor's demo publisher builds every command from the message's own field types (issue 11, defect 4).

`sam-codegen run` on a spec whose command message had a float32[2] field ended in a segmentation fault inside
rclpy's publish: the demo publisher had put a scalar into the array. Now every value comes from the field's
rosidl type (runtime/main_job/demo.py) and is checked by rclpy as it is set. The checks run in a child process
(tests/helpers/demo_check.py), so a segmentation fault fails the test instead of ending pytest, on the glider
spec (float32[2], int8[<=3], bool, nested messages in its commands), the rover spec and SAM's, and end to end:
`sam-codegen run` on the glider spec.
"""

from __future__ import annotations

import json
import signal
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("rclpy")

from helpers.runtime_support import (
    HELPERS,
    child_env,
    cyphal_udp_lock,
    domain_id,
    generated_or_skip,
    ros_prefix_for,
)
from helpers.spec_build import built_spec

pytestmark = [pytest.mark.ros, pytest.mark.slow]



def _spec(name: str) -> tuple[Path, Path]:
    if name == "sam":
        gen = generated_or_skip()
        return gen.root, ros_prefix_for(gen)
    b = built_spec(name)
    return b.generated, b.prefix


def _exit_text(code: int) -> str:
    return f"signal {signal.Signals(-code).name}" if code < 0 else f"exit code {code}"


@pytest.mark.parametrize("spec", ["glider", "rover", "sam"])
def test_demo_messages_are_well_formed_and_published(spec: str, tmp_path: Path) -> None:
    generated, prefix = _spec(spec)
    out = tmp_path / "demo.json"
    env = child_env(prefix, domain_id(40 + ["glider", "rover", "sam"].index(spec)))
    proc = subprocess.run([sys.executable, str(HELPERS / "demo_check.py"), "--generated", str(generated),
                           "--out", str(out)], env=env, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, f"demo check died ({_exit_text(proc.returncode)}):\n{proc.stderr[-4000:]}"
    res: dict[str, Any] = json.loads(out.read_text())
    for ros_type, r in res["classes"].items():
        assert r["problems"] == [], (ros_type, r["problems"])
        assert r["scalar_in_array_caught"] in (None, True), ros_type  # the checker sees the old defect
    mon = res["monitor"]
    assert mon["errors"] == {}
    assert mon["received"] and all(n >= 3 for n in mon["received"].values()), mon
    assert all(p == [] for p in mon["received_problems"].values()), mon["received_problems"]
    if spec == "glider":
        cmd = res["classes"]["glider_msgs/msg/FinCommand"]["shapes"]
        assert cmd["angles_rad"] == 2 and 0 < cmd["trims"] <= 3 and cmd["enable"] == "bool"
        assert set(cmd["gains"]) == {"p", "d"} and set(cmd["offset"]) == {"x", "y", "z"}
        assert res["classes"]["glider_msgs/msg/FinCommand"]["scalar_in_array_caught"] is True


def test_run_on_the_glider_spec_bridges_the_demo_commands(tmp_path: Path) -> None:
    """The issue's own reproduction: `sam-codegen run` on a spec with a float32[2] command field. It used to
    die with SIGSEGV in the monitor's demo publisher; now the demo commands go through the bridge to the
    simulated fins and pump, and the run ends cleanly."""
    b = built_spec("glider")
    env = child_env(b.prefix, domain_id(43))
    cmd = [sys.executable, "-m", "sam_runtime.cli", "run", "--spec", str(b.spec), "--generated", str(b.generated),
           "--no-build", "--ros-prefix", str(b.prefix), "--duration", "12", "--plain", "--log-dir", str(tmp_path)]
    with cyphal_udp_lock():
        proc = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=180)
    logs = {p.name: p.read_text(errors="replace") for p in tmp_path.glob("*.log")}
    assert proc.returncode == 0, (f"run ended with {_exit_text(proc.returncode)}:\n{proc.stdout[-3000:]}\n"
                                  f"{proc.stderr[-3000:]}\n{logs}")
    final = proc.stdout[proc.stdout.rindex("final ("):]
    rows = {line.split()[0]: line.split() for line in final.splitlines() if line.startswith("/")}
    # TOPIC DIR RATE NOMINAL COUNT DROPS ...: the demo published commands the bridge took without a drop, and
    # the simulated fins' state flowed back.
    for topic in ("/fins/command", "/pump/command", "/fins/state"):
        assert int(rows[topic][4]) > 0 and int(rows[topic][5]) == 0, final
    assert "Traceback" not in proc.stderr + "".join(logs.values()), logs
