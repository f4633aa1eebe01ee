"""The main job beside another command of its project (issue 25, "Runs beside each other"), on a user's project (the
skiff spec):

- `--duration` counts from the moment the vehicle is up (every child READY), not from the launch: judged from the
  simulator's own truth file (its vehicle clock) against the duration, and from the job's report of when the
  vehicle came up and how long it ran.
- Two real `sam-codegen ros-install` into one build folder at once (the defect: the second's CMake configure failed
  in the folder the first was building in): one compiles, the other waits, says for whom, and reuses the install.
  A `cmake` in front of the real one holds the first build in its compile step until the second is seen waiting,
  so the overlap does not depend on the machine's speed.
- A second run of the project at the same time logs to a folder of its own.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import stat
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from sam_codegen.project.lock import ProjectLock, lock_path
from sam_codegen.project.ros_install import ros_runtime_env

pytest.importorskip("pycyphal")
pytest.importorskip("rclpy")

from helpers.runtime_support import child_env, cyphal_udp_lock, domain_id, poll_until
from helpers.user_project import built_project, make_project

from sam_runtime.main_job.job import RunOptions, claim_log_dir

# Bounds on events that come, never waits that must pass: a loaded 2-core machine.
RUN_BOUND_S = 300.0
BUILD_BOUND_S = 900.0


@pytest.fixture(scope="module")
def skiff(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    return built_project(tmp_path_factory.mktemp("user") / "skiff")


@pytest.mark.ros
@pytest.mark.slow
def test_the_duration_counts_from_the_vehicle_start(skiff: tuple[Path, Path], tmp_path: Path) -> None:
    project, prefix = skiff
    env = child_env(prefix, domain_id(142))
    env.pop("SAM_GENERATED_DIR", None)
    truth = tmp_path / "truth.jsonl"
    duration = 4.0
    with cyphal_udp_lock():
        proc = subprocess.run(
            [sys.executable, "-m", "sam_runtime.cli", "run", "--no-build", "--plain", "--duration", f"{duration:g}",
             "--ros-prefix", str(prefix), "--truth-file", str(truth), "--log-dir", str(tmp_path / "logs")],
            cwd=project, env=env, capture_output=True, text=True, timeout=RUN_BOUND_S)
    out = proc.stdout + proc.stderr
    assert proc.returncode == 0, out
    up = re.search(r"sam-run: vehicle up (\d+\.\d) s after launch \(([a-z_, ]+) READY\); --duration 4 s counts "
                   r"from here", out)
    assert up, out
    assert up.group(2).split(", ")[:2] == ["sim", "bridge"]
    final = re.search(r"final \(duration\) after (\d+\.\d) s of the vehicle up", out)
    assert final and out.index(up.group(0)) < out.index(final.group(0)), out
    assert float(final.group(1)) >= duration
    # The simulator's clock started before it said READY, hence before the vehicle was up: it ran at least the
    # duration. Counted from the launch instead, the sim's start-up (seconds of imports) was cut off the run.
    samples = [json.loads(line) for line in truth.read_text().splitlines() if line.strip()]
    assert samples, out
    assert samples[-1]["t"] >= duration, (samples[0]["t"], samples[-1]["t"], out)


def _cmake_in_front(folder: Path, control: Path) -> Path:
    """A `cmake` that logs every call (with its parent: the Python process that runs it) and holds the first
    `--build` until the file `go` exists, then runs the real CMake."""
    real = shutil.which("cmake")
    assert real is not None
    folder.mkdir()
    script = folder / "cmake"
    script.write_text(textwrap.dedent(f"""\
        #!/bin/sh
        echo "$PPID $1 $2" >> "{control}/cmake.log"
        if [ "$1" = "--build" ]; then
            while [ ! -e "{control}/go" ]; do sleep 0.05; done
        fi
        exec "{real}" "$@"
        """))
    script.chmod(script.stat().st_mode | stat.S_IXUSR | stat.S_IXGRP | stat.S_IXOTH)
    return folder


@pytest.mark.ros
@pytest.mark.slow
def test_two_real_ros_installs_at_once_compile_once(tmp_path: Path) -> None:
    if shutil.which("cmake") is None:
        pytest.skip("no cmake")
    project = make_project(tmp_path / "skiff")
    subprocess.run([sys.executable, "-m", "sam_codegen.cli", "build"], cwd=project, check=True, capture_output=True,
                   timeout=BUILD_BOUND_S)
    control = tmp_path / "control"
    control.mkdir()
    front = _cmake_in_front(tmp_path / "bin", control)
    env = {**os.environ, "PATH": f"{front}{os.pathsep}{os.environ['PATH']}"}
    env.pop("SAM_GENERATED_DIR", None)
    prefix = tmp_path / "prefix"
    cmd = [sys.executable, "-m", "sam_codegen.cli", "ros-install", "--prefix", str(prefix)]
    outs = [tmp_path / "first.out", tmp_path / "second.out"]
    procs: list[subprocess.Popen[bytes]] = []
    log = control / "cmake.log"
    try:
        with open(outs[0], "w") as fh:
            procs.append(subprocess.Popen(cmd, cwd=project, env=env, stdout=fh, stderr=subprocess.STDOUT))
        # The first has configured (a real CMake configure) and holds in its compile step.
        poll_until(lambda: log.exists() and " --build " in log.read_text(), BUILD_BOUND_S, "the first compile")
        with open(outs[1], "w") as fh:
            procs.append(subprocess.Popen(cmd, cwd=project, env=env, stdout=fh, stderr=subprocess.STDOUT))
        build_root = project / ".sam-codegen-cache" / "ros-build"
        poll_until(lambda: f"sam-codegen: waiting for the ROS build folder {build_root}: pid {procs[0].pid} "
                   in outs[1].read_text(), RUN_BOUND_S, "the second to say for whom it waits")
        poll_until(lambda: "dinghy_msgs: build (" in outs[1].read_text(), RUN_BOUND_S,
                   "the first one's step, through the lock file")
        (control / "go").touch()
        codes = [p.wait(timeout=BUILD_BOUND_S) for p in procs]
    finally:
        (control / "go").touch()
        for p in procs:
            if p.poll() is None:
                p.kill()
                p.wait(timeout=60)
    first, second = (o.read_text() for o in outs)
    assert codes == [0, 0], first + second
    callers = {line.split()[0] for line in log.read_text().splitlines()}
    assert callers == {str(procs[0].pid)}, log.read_text()  # CMake ran for the first only
    assert f"sam-codegen: dinghy_msgs installed into {prefix} meanwhile by pid {procs[0].pid}: reused" in second
    assert "sam-codegen: [1/1] dinghy_msgs: configure (" in first
    assert not [line for line in second.splitlines() if line.startswith("sam-codegen: [1/")], second  # no step
    # The install works: the message package imports from the prefix.
    check = subprocess.run([sys.executable, "-c", "from dinghy_msgs.msg import Depth; print(Depth().depth)"],
                           env=ros_runtime_env(prefix), capture_output=True, text=True, timeout=120)
    assert check.returncode == 0 and check.stdout.strip() == "0.0", check.stdout + check.stderr


def test_a_second_run_logs_to_its_own_folder(tmp_path: Path) -> None:
    state = tmp_path / ".sam-codegen-cache"
    said: list[str] = []
    base = (state / "run-logs").resolve()
    with ProjectLock(lock_path("run-logs", base), "the first run's logs", command="the first run"):
        folder, lock = claim_log_dir(RunOptions(), state, said.append)
        assert lock is not None
        try:
            assert folder == base.with_name("run-logs-2")
            assert said == [f"sam-run: {base} is another run's; this run's logs go to {folder}"]
            third, third_lock = claim_log_dir(RunOptions(), state, said.append)  # a third run meanwhile
            assert third == base.with_name("run-logs-3") and third_lock is not None
            third_lock.release()
        finally:
            lock.release()
    folder, lock = claim_log_dir(RunOptions(), state, said.append)  # alone again: the usual folder
    assert folder == base and lock is not None
    lock.release()
    assert claim_log_dir(RunOptions(log_dir=tmp_path / "mine"), state, said.append) == ((tmp_path / "mine"), None)
