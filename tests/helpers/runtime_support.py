"""Shared plumbing of the runtime tests: the generated package, child processes, deadlines."""

from __future__ import annotations

import contextlib
import fcntl
import json
import os
import queue
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any, TypeVar

import pytest

from helpers.isolation import isolated
from helpers.ros_packages import chained_env

REPO = Path(__file__).resolve().parents[2]
HELPERS = Path(__file__).resolve().parent
T = TypeVar("T")


UDP_LOCK = Path("/tmp") / "sam-runtime-tests-cyphal-udp.lock"


@contextlib.contextmanager
def cyphal_udp_lock(timeout: float = 600.0) -> Iterator[None]:
    """Cyphal/UDP subjects are multicast groups shared by everything on one network (ROS_DOMAIN_ID does not
    separate them). In a private network namespace (helpers.isolation: the normal case) nothing else shares it and
    this is a no-op; where none could be made, two runs of these tests at once would see each other's devices:
    serialize them machine-wide."""
    if isolated():
        yield
        return
    with open(UDP_LOCK, "a+") as fh:
        deadline = time.monotonic() + timeout
        while True:
            try:
                fcntl.flock(fh.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
                break
            except BlockingIOError:
                if time.monotonic() > deadline:
                    pytest.fail(f"another run held {UDP_LOCK} for {timeout:.0f} s")
                time.sleep(0.2)
        try:
            yield
        finally:
            fcntl.flock(fh.fileno(), fcntl.LOCK_UN)


def generated_or_skip() -> Any:
    """The generated package (``$SAM_GENERATED_DIR`` or <repo>/generated), or skip when it is not there."""
    from sam_runtime.genpkg import GeneratedPackage, GeneratedPackageError

    try:
        gen = GeneratedPackage()
        gen.tables()
    except GeneratedPackageError as ex:
        pytest.skip(f"no generated package: {ex}")
    return gen


def ros_prefix_for(gen: Any) -> Path:
    """Where the generated ROS packages are usable (a prefix for child_env): the venv when they are current there
    (nox's tests session and `sam-codegen ros-install` put them there), else prefixes built for the tests
    (helpers.ros_packages: once per package content, ~30 s)."""
    from helpers.ros_packages import built_prefix
    from sam_codegen.project.ros_install import ros_packages_in_order

    try:
        return built_prefix(ros_packages_in_order(gen.ros_package_dir().parent))
    except Exception as ex:  # a build problem is the ROS build tests' business; here it is a skip reason
        pytest.skip(f"cannot build the generated ROS package: {type(ex).__name__}: {ex}")


def domain_id(offset: int) -> str:
    """The ROS_DOMAIN_ID of a test (1..101 by its offset, so the tests of one process never share one). In a private
    network namespace no other run can see it; without one (helpers.isolation's fallback) the pid is mixed in so that
    parallel runs on the machine do not cross-talk (they may still collide: 101 ids)."""
    salt = 0 if isolated() else os.getpid() * 7
    return str(1 + (salt + offset * 13) % 101)


def child_env(prefix: Path, domain: str, extra: Mapping[str, str] | None = None) -> dict[str, str]:
    base = dict(os.environ)
    # Never inherit a Cyphal transport from the caller's shell: the tests choose it explicitly.
    for k in list(base):
        if k.startswith("UAVCAN__"):
            del base[k]
    env = chained_env(prefix, base)
    env["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    env["ROS_DOMAIN_ID"] = domain
    env["PYTHONUNBUFFERED"] = "1"
    env.update(extra or {})
    return env


def poll_until(fn: Callable[[], T], timeout: float, what: str, interval: float = 0.05) -> T:
    """Call fn until it returns something truthy; fail with `what` at the deadline."""
    deadline = time.monotonic() + timeout
    while True:
        value = fn()
        if value:
            return value
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out after {timeout:.0f} s waiting for {what}")
        time.sleep(interval)


def read_json(path: Path) -> Any:
    try:
        return json.loads(path.read_text())
    except (OSError, ValueError):
        return None


class Proc:
    """A child process whose stdout lines are collected by a thread; stderr goes to a log file."""

    def __init__(self, name: str, cmd: Sequence[str], env: Mapping[str, str], log_dir: Path) -> None:
        self.name = name
        self.log = log_dir / f"{name}.stderr"
        self._err = open(self.log, "w")
        self.proc = subprocess.Popen(list(cmd), env=dict(env), stdout=subprocess.PIPE, stderr=self._err,
                                     stdin=subprocess.DEVNULL, text=True, start_new_session=True)
        self.lines: list[str] = []
        self._q: queue.Queue[str] = queue.Queue()
        self._t = threading.Thread(target=self._read, daemon=True)
        self._t.start()

    def _read(self) -> None:
        assert self.proc.stdout is not None
        for line in self.proc.stdout:
            line = line.rstrip("\n")
            self.lines.append(line)
            self._q.put(line)

    def wait_line(self, prefix: str, timeout: float) -> str:
        deadline = time.monotonic() + timeout
        for line in self.lines:
            if line.startswith(prefix):
                return line
        while True:
            left = deadline - time.monotonic()
            if left <= 0 or (self.proc.poll() is not None and self._q.empty()):
                raise AssertionError(
                    f"{self.name}: no line starting with {prefix!r} within {timeout:.0f} s "
                    f"(exit code {self.proc.poll()}); stdout: {self.lines[-10:]}; stderr: {self.stderr_tail()}")
            try:
                line = self._q.get(timeout=min(left, 0.1))
            except queue.Empty:
                continue
            if line.startswith(prefix):
                return line

    def stderr_tail(self, n: int = 20) -> str:
        try:
            return "\n".join(self.log.read_text(errors="replace").splitlines()[-n:])
        except OSError:
            return ""

    def wait(self, timeout: float) -> int:
        try:
            return self.proc.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            raise AssertionError(
                f"{self.name} did not exit within {timeout:.0f} s; stderr: {self.stderr_tail()}") from None

    def stop(self, sig: int = signal.SIGTERM, timeout: float = 10.0) -> int | None:
        """Signal, wait (deadline), kill if needed; returns the exit code."""
        if self.proc.poll() is None:
            try:
                self.proc.send_signal(sig)
                self.proc.wait(timeout=timeout)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait(timeout=5)
        self._t.join(timeout=2)
        if not self._err.closed:
            self._err.close()
        return self.proc.returncode


def runtime_cmd(*args: str) -> list[str]:
    return [sys.executable, "-m", "sam_runtime.cli", *args]


def helper_cmd(script: str, *args: str) -> list[str]:
    return [sys.executable, str(HELPERS / script), *args]


def load_records(path: Path) -> list[dict[str, Any]]:
    if not path.exists():
        return []
    out = []
    for line in path.read_text().splitlines():
        try:
            out.append(json.loads(line))
        except ValueError:  # a line being written
            pass
    return out


def command_plan(tables: Any, n: int) -> dict[str, list[dict[str, Any]]]:
    """SAM's command topics with known values; the last of some are out of range (saturate)."""
    plan: dict[str, list[dict[str, Any]]] = {}
    topics = {m.topic.name for m in tables.MAPPINGS if m.direction == "ros_to_uavcan"}
    for t in sorted(topics):
        items = []
        for i in range(n):
            if t == "/thruster_rpms":
                items.append({"thruster_1_rpm": 100 * i - 500, "thruster_2_rpm": -50 * i})
            elif t == "/thruster_angles":
                # (inside the nozzle's +-0.12 rad for any n; the ballast's +-1.5708)
                items.append({"thruster_vertical_radians": 0.01 * (i % 12),
                              "thruster_horizontal_radians": -0.01 * (i % 12)})
            elif t == "/ballast_angles":
                items.append({"weight_1_offset_radians": 0.1 + 0.01 * (i % 100),
                              "weight_2_offset_radians": -0.05 * (i % 30)})
            elif t == "/longitudinal_weight_position":
                items.append({"percent": float(5 * i)})
            elif t == "/buoyancy_piston_position":
                items.append({"percent": float(100 - 5 * i)})
        if items:
            if t == "/thruster_rpms":
                items[-1] = {"thruster_1_rpm": 1_000_000, "thruster_2_rpm": -1_000_000}
            elif t == "/thruster_angles":  # beyond the spec's limits
                items[-1] = {"thruster_vertical_radians": 0.5, "thruster_horizontal_radians": -1e6}
            elif t == "/ballast_angles":
                items[-1] = {"weight_1_offset_radians": 2.0, "weight_2_offset_radians": -1e6}
            elif t == "/longitudinal_weight_position":
                items[-1] = {"percent": 150.0}
            elif t == "/buoyancy_piston_position":
                items[-1] = {"percent": -20.0}
            plan[t] = items
    return plan
