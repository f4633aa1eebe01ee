"""The main job's children (the simulated devices and the bridge) never outlive it, whatever ends it (issue 11,
defect 4's orphans): a crash, SIGKILL, or the terminal closing (SIGHUP). Left running, they doubled every rate of the
next run. On a user's project (the skiff spec), with its logs in the project's .sam-codegen-cache."""

from __future__ import annotations

import os
import re
import resource
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

pytest.importorskip("pycyphal")
pytest.importorskip("rclpy")

from helpers.runtime_support import child_env, cyphal_udp_lock, domain_id, poll_until
from helpers.user_project import built_project, start_time, wait_gone

from sam_codegen.project.workspace import STATE_DIR_NAME
from sam_runtime.cli_support import ORPHAN_GRACE_S, PARENT_ENV_VAR, PARENT_POLL_S
from sam_runtime.main_job.job import CHILD_KILL_TIMEOUT_S, CHILD_STOP_TIMEOUT_S

pytestmark = [pytest.mark.ros, pytest.mark.slow]

# An orphan ends within ORPHAN_GRACE_S of noticing (one poll); the rest is margin for a loaded machine.
ORPHAN_BOUND_S = PARENT_POLL_S + ORPHAN_GRACE_S + 10.0
# The main job's own stop of its children is bounded by these two deadlines.
STOP_BOUND_S = CHILD_STOP_TIMEOUT_S + CHILD_KILL_TIMEOUT_S + 10.0
HEADER = re.compile(r"sim pid (\d+)\s+bridge pid (\d+)")


@pytest.fixture(scope="module")
def skiff(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    return built_project(tmp_path_factory.mktemp("user") / "skiff")


def _no_core_dump() -> None:
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))


@pytest.mark.parametrize(("sig", "offset"), [(signal.SIGKILL, 41), (signal.SIGSEGV, 42), (signal.SIGHUP, 43)],
                         ids=["SIGKILL", "SIGSEGV-a-crash", "SIGHUP-terminal-closed"])
def test_children_end_with_the_main_job(skiff: tuple[Path, Path], tmp_path: Path, sig: int, offset: int) -> None:
    project, prefix = skiff
    env = child_env(prefix, domain_id(offset))
    env.pop("SAM_GENERATED_DIR", None)  # found from the working directory, like a user's run
    logs = project / STATE_DIR_NAME / "run-logs"
    out_path = tmp_path / "run.out"
    with cyphal_udp_lock(), open(out_path, "w") as out:
        for old in logs.glob("*.log"):
            old.unlink()
        run = subprocess.Popen(
            [sys.executable, "-m", "sam_runtime.cli", "run", "--no-build", "--plain", "--duration", "600",
             "--ros-prefix", str(prefix)],
            cwd=project, env=env, stdout=out, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
            start_new_session=True, preexec_fn=_no_core_dump)
        children: dict[int, int] = {}
        try:
            def output() -> str:
                return out_path.read_text(errors="replace")

            def up() -> bool:
                assert run.poll() is None, f"the main job ended early ({run.returncode}):\n{output()}"
                return all("READY" in (p.read_text(errors="replace") if p.exists() else "")
                           for p in (logs / "sim.log", logs / "bridge.log"))

            poll_until(up, 120, "the sim and the bridge to be READY")
            match = poll_until(lambda: HEADER.search(output()), 60, "the main job's table")
            children = {int(pid): start_time(int(pid)) or 0 for pid in match.groups()}
            assert all(children.values()), f"the children {list(children)} are not running"

            os.kill(run.pid, sig)
            code = run.wait(timeout=STOP_BOUND_S)
            if sig == signal.SIGHUP:  # handled: a clean stop of everything, like Ctrl-C
                assert code == 0, output()
                assert "final (SIGHUP)" in output()
                bound = 5.0  # already stopped, the last wait is for /proc to show it
            else:
                assert code == -sig
                bound = ORPHAN_BOUND_S
            left = wait_gone(children, bound)
            assert not left, f"still running {bound:.0f} s after the main job ended by {signal.Signals(sig).name}: " \
                             f"{left}"
        finally:
            for pid, started in children.items():
                if start_time(pid) == started:
                    os.kill(pid, signal.SIGKILL)
            if run.poll() is None:
                os.killpg(run.pid, signal.SIGKILL)
                run.wait(timeout=10)


# A grandchild bound to its parent, which then ignores SIGTERM (a stop that hangs): it must end anyway.
_STUBBORN = textwrap.dedent("""\
    import signal, sys, time
    from sam_runtime.cli_support import stay_with_parent
    stay_with_parent()
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    print("bound", flush=True)
    time.sleep(600)
    """)
_PARENT = textwrap.dedent("""\
    import os, subprocess, sys, time
    child = subprocess.Popen([sys.executable, "-c", sys.argv[1]], env={**os.environ, sys.argv[2]: str(os.getpid())})
    print(child.pid, flush=True)
    time.sleep(600)
    """)


def test_an_orphan_whose_stop_hangs_still_ends(tmp_path: Path) -> None:
    parent = subprocess.Popen([sys.executable, "-c", _PARENT, _STUBBORN, PARENT_ENV_VAR], stdout=subprocess.PIPE,
                              text=True, cwd=tmp_path, start_new_session=True)
    assert parent.stdout is not None
    grandchild = int(parent.stdout.readline())
    started = start_time(grandchild)
    try:
        assert parent.stdout.readline().strip() == "bound"
        parent.kill()
        parent.wait(timeout=10)
        t0 = time.monotonic()
        assert not wait_gone({grandchild: started or 0}, ORPHAN_BOUND_S)
        # It could only end through the watchdog's hard exit: it ignores SIGTERM.
        assert time.monotonic() - t0 >= ORPHAN_GRACE_S - 1.0
    finally:
        if start_time(grandchild) == started:
            os.kill(grandchild, signal.SIGKILL)
        if parent.poll() is None:
            parent.kill()


def test_a_child_whose_main_job_is_gone_does_not_start(tmp_path: Path) -> None:
    ended = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True,
                           check=True)
    gone = ended.stdout.strip()
    proc = subprocess.run([sys.executable, "-m", "sam_runtime.cli", "sim", "--generated", str(tmp_path / "none")],
                          capture_output=True, text=True, timeout=60, cwd=tmp_path,
                          env={**os.environ, PARENT_ENV_VAR: gone})
    assert proc.returncode == 1
    assert proc.stderr == f"the main job (pid {gone}) has already ended; not starting\n"
