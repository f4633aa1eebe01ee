"""Two sam-codegen commands started at once in one project never break each other (issue 25, "Runs beside each
other"): two `build`s of one generated/ both succeed with one valid tree; a second `build` or `ros-install` waits for
the first, says for whom, and reuses what it wrote instead of writing (or compiling) it again.

The ROS build step here is a stand-in (tests/helpers-free: the script below replaces build_ros_package) that holds
until the test lets it go, so that the second command is seen waiting whatever the machine's load; one real CMake
build of two concurrent `ros-install`s is in tests/runtime/main_job/test_run_beside.py."""

from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import sys
import textwrap
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

from sam_codegen.project.lock import ProjectLock, lock_path

SKIFF = Path(__file__).parents[1] / "specs" / "skiff.yaml"
DEADLINE_S = 120.0  # a bound on events that come (a build of the skiff spec takes ~1 s idle), never a wait

# `python -c STANDIN MODE ARGS...`: ros-install (the command) or ensure (the main job's step,
# sam_runtime.genpkg.ensure_ros_package, with run's build folder), their CMake step replaced by one that notes who
# builds, reports a step, and installs only once the file `go` exists in $STANDIN_CONTROL.
STANDIN = textwrap.dedent("""\
    import os, pathlib, sys, time
    from sam_codegen.project import ros_install
    control = pathlib.Path(os.environ["STANDIN_CONTROL"])

    def build_ros_package(package_dir, build_dir, prefix, *, python=None, jobs=2, progress=None):
        name = pathlib.Path(package_dir).name
        with open(control / "builds.log", "a") as log:
            log.write(f"{os.getpid()} {name}\\n")
        if progress is not None:
            progress("configure")
        while not (control / "go").exists():
            time.sleep(0.02)
        share = pathlib.Path(prefix) / "share" / name
        share.mkdir(parents=True, exist_ok=True)
        (share / "package.xml").write_text((pathlib.Path(package_dir) / "package.xml").read_text())

    ros_install.build_ros_package = build_ros_package  # before sam_runtime.genpkg binds the name
    mode, prefix = sys.argv[1], sys.argv[2]
    if mode == "ros-install":
        from sam_codegen.cli import main
        sys.exit(main(["ros-install", "--prefix", prefix]))
    from sam_runtime.genpkg import GeneratedPackage, ensure_ros_package
    ensure_ros_package(GeneratedPackage(pathlib.Path("generated")), pathlib.Path(prefix),
                       log=lambda line: print("sam-run:", line, flush=True),
                       build_root=pathlib.Path(".sam-codegen-cache", "ros-build"))
    print("sam-run: ROS packages ready", flush=True)
    """)


def _tree(folder: Path) -> dict[str, str]:
    return {p.relative_to(folder).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file() and "__pycache__" not in p.parts}


def _project(root: Path) -> Path:
    (root / "spec").mkdir(parents=True)
    shutil.copy(SKIFF, root / "spec" / "interfaces.yaml")
    return root


def _env(**extra: str) -> dict[str, str]:
    env = {**os.environ, **extra}
    env.pop("SAM_GENERATED_DIR", None)  # found from the working directory, like a user's command
    return env


def _poll(fn: Callable[[], object], what: str) -> None:
    deadline = time.monotonic() + DEADLINE_S
    while not fn():
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out after {DEADLINE_S:.0f} s waiting for {what}")
        time.sleep(0.02)


class Command:
    """A command in the background, its output (stdout and stderr) in a file."""

    def __init__(self, args: list[str], cwd: Path, out: Path, env: dict[str, str]) -> None:
        self.out_path = out
        self._fh = open(out, "w")
        self.proc = subprocess.Popen(args, cwd=cwd, env=env, stdout=self._fh, stderr=subprocess.STDOUT,
                                     stdin=subprocess.DEVNULL)

    def output(self) -> str:
        return self.out_path.read_text(errors="replace")

    def finish(self) -> tuple[int, str]:
        code = self.proc.wait(timeout=DEADLINE_S)
        self._fh.close()
        return code, self.output()


@pytest.fixture
def commands() -> Iterator[list[Command]]:
    started: list[Command] = []
    yield started
    for c in started:
        if c.proc.poll() is None:
            c.proc.kill()
            c.proc.wait(timeout=DEADLINE_S)
        c._fh.close()


def _build_cmd(*args: str) -> list[str]:
    return [sys.executable, "-m", "sam_codegen.cli", "build", *args]


@pytest.mark.slow
def test_two_builds_at_once_both_succeed_with_one_valid_tree(tmp_path: Path, commands: list[Command]) -> None:
    reference = _project(tmp_path / "reference")
    subprocess.run(_build_cmd(), cwd=reference, env=_env(), check=True, capture_output=True, timeout=DEADLINE_S)
    project = _project(tmp_path / "skiff")
    for k in range(2):  # started together; which one writes is up to them
        commands.append(Command(_build_cmd(), project, tmp_path / f"build{k}.out", _env()))
    results = [c.finish() for c in commands]
    assert [code for code, _ in results] == [0, 0], results
    assert "Traceback" not in "".join(out for _, out in results)
    assert _tree(project / "generated") == _tree(reference / "generated")
    check = subprocess.run(_build_cmd("--check"), cwd=project, env=_env(), capture_output=True, text=True,
                           timeout=DEADLINE_S)
    assert check.returncode == 0, check.stderr
    assert not list(project.glob(".generated-*"))  # no staging or backup folder left behind


@pytest.mark.slow
def test_a_build_waits_for_the_one_writing_and_reuses_its_tree(tmp_path: Path, commands: list[Command]) -> None:
    """The test holds generated/'s lock (as a build writing it would): both builds wait and say for whom; once it is
    free, one writes and the other, after waiting for that one too, finds the tree current."""
    project = _project(tmp_path / "skiff")
    generated = (project / "generated").resolve()
    with ProjectLock(lock_path("generated", generated), "held by the test", command="the test") as held:
        held.status("writing")
        for k in range(2):
            commands.append(Command(_build_cmd(), project, tmp_path / f"build{k}.out", _env()))
        waiting = f"sam-codegen: waiting for the generated folder {generated}: pid {os.getpid()} (`the test`)"
        _poll(lambda: all(waiting in c.output() for c in commands), "both builds to say for whom they wait")
        assert not (project / "generated").exists()
    results = [c.finish() for c in commands]
    assert [code for code, _ in results] == [0, 0], results
    said = sorted("updated from" in out for _, out in results)
    assert said == [False, True], results  # one wrote...
    assert sum("generated already up to date from" in out for _, out in results) == 1, results  # ...one reused
    check = subprocess.run(_build_cmd("--check"), cwd=project, env=_env(), capture_output=True, text=True,
                           timeout=DEADLINE_S)
    assert check.returncode == 0, check.stderr


@pytest.mark.slow
def test_a_build_gives_up_after_its_wait_timeout(tmp_path: Path) -> None:
    project = _project(tmp_path / "skiff")
    generated = (project / "generated").resolve()
    with ProjectLock(lock_path("generated", generated), "held by the test", command="the test"):
        proc = subprocess.run(_build_cmd("--wait-timeout", "0.5"), cwd=project, env=_env(), capture_output=True,
                              text=True, timeout=DEADLINE_S)
    assert proc.returncode == 1, proc.stdout + proc.stderr
    assert f"sam-codegen: gave up after 1 s waiting for the generated folder {generated}: pid {os.getpid()} " \
           "(`the test`)" in proc.stderr.replace("after 0 s", "after 1 s"), proc.stderr
    assert "Traceback" not in proc.stderr
    assert not generated.exists()


@pytest.mark.slow
@pytest.mark.parametrize(("first", "second"), [("ros-install", "ros-install"), ("ensure", "ros-install"),
                                               ("ros-install", "ensure")],
                         ids=["ros-install-beside-ros-install", "ros-install-beside-run", "run-beside-ros-install"])
def test_a_second_ros_build_waits_and_reuses_the_first(tmp_path: Path, commands: list[Command], first: str,
                                                      second: str) -> None:
    project = _project(tmp_path / "skiff")
    subprocess.run(_build_cmd(), cwd=project, env=_env(), check=True, capture_output=True, timeout=DEADLINE_S)
    control = tmp_path / "control"
    control.mkdir()
    prefix = tmp_path / "prefix"
    env = _env(STANDIN_CONTROL=str(control))
    builds = control / "builds.log"

    def standin(mode: str, k: int) -> Command:
        return Command([sys.executable, "-c", STANDIN, mode, str(prefix)], project, tmp_path / f"{k}.out", env)

    commands.append(standin(first, 0))
    _poll(lambda: builds.exists() and builds.read_text().strip(), "the first command to start its build")
    holder = commands[0].proc.pid
    commands.append(standin(second, 1))
    build_root = project / ".sam-codegen-cache" / "ros-build"
    waiting = f"waiting for the ROS build folder {build_root}: pid {holder} (`python -c ... {first} {prefix}`)"
    _poll(lambda: waiting in commands[1].output(), "the second command to say for whom it waits")
    _poll(lambda: "dinghy_msgs: configure" in commands[1].output(), "the first one's step, through the lock file")
    assert commands[1].proc.poll() is None
    (control / "go").touch()
    results = [c.finish() for c in commands]
    assert [code for code, _ in results] == [0, 0], results
    assert builds.read_text().split() == [str(holder), "dinghy_msgs"]  # built once, by the first
    reused = ("sam-codegen: dinghy_msgs installed into {prefix} meanwhile by pid {pid}: reused" if second ==
              "ros-install" else "sam-run: ROS package dinghy_msgs was installed into {prefix} meanwhile by pid "
              "{pid}: reused").format(prefix=prefix, pid=holder)
    assert reused in results[1][1], results[1][1]
    assert (prefix / "share" / "dinghy_msgs" / ".sam_codegen_source_hash").is_file()
