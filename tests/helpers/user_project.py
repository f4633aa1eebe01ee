"""A new user's project for the workspace tests: tests/specs/skiff.yaml as <root>/spec/interfaces.yaml, outside this
repository; and processes judged alive or gone by /proc (they may be grandchildren, reaped by someone else)."""

from __future__ import annotations

import shutil
import time
from pathlib import Path

from helpers.ros_packages import built_prefix
from helpers.runtime_support import REPO

SKIFF_SPEC = REPO / "tests" / "specs" / "skiff.yaml"


def make_project(root: Path) -> Path:
    """``root``/spec/interfaces.yaml = the skiff spec; returns root."""
    (root / "spec").mkdir(parents=True)
    shutil.copy(SKIFF_SPEC, root / "spec" / "interfaces.yaml")
    return root


def built_project(root: Path) -> tuple[Path, Path]:
    """A skiff project with generated/ built and dinghy_msgs installed: (project, ROS prefix)."""
    from sam_codegen.build import build
    from sam_codegen.project.ros_install import ros_packages_in_order
    from sam_runtime.genpkg import GeneratedPackage

    project = make_project(root)
    build(project / "spec" / "interfaces.yaml", project / "generated")
    gen = GeneratedPackage(project / "generated")
    # dinghy_msgs is built once per content (helpers.ros_packages), wherever the project's folder is. Its folder is
    # found without importing the project's tables: another module's skiff project on the same worker may have
    # imported its own copy of the package already (GeneratedPackage refuses a shadowing copy).
    prefix = built_prefix(ros_packages_in_order(gen.root / "ros"))
    gen.compile_dsdl()  # once here, so that the processes of a test start in seconds
    return project, prefix


def start_time(pid: int) -> int | None:
    """The process's start time in clock ticks since boot (None once it is gone): with the pid it names one process,
    even if the pid is reused later."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return None
    fields = stat[stat.rindex(")") + 2:].split()
    if fields[0] in ("Z", "X"):  # a zombie has ended; whoever reaps it does not matter here
        return None
    return int(fields[19])


def wait_gone(processes: dict[int, int], timeout: float) -> list[int]:
    """Poll until every (pid, start time) has ended or the deadline passes; returns those still running."""
    deadline = time.monotonic() + timeout
    while True:
        alive = [pid for pid, started in processes.items() if start_time(pid) == started]
        if not alive or time.monotonic() > deadline:
            return alive
        time.sleep(0.05)
