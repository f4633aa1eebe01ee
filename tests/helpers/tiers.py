"""The two tiers of the suite: the gate (everything, ``nox -s tests``) and the unit tier (``nox -s unit``).

A test is a *system* test when it starts processes, builds with CMake or needs the ROS packages built: it is in
tests/system/, or marked ``system``, ``ros`` or ``slow`` (explicitly, usually by a module's ``pytestmark``).
``--unit-tier`` deselects the system tests and runs the others under a guard: a test that starts a child process
(subprocess, os.fork/spawn/system: CMake and the runtime's processes are started so) fails with a message that
asks for the marker. So a new system test cannot land in the unit tier unnoticed: it fails there.
"""

from __future__ import annotations

import _posixsubprocess
import os
import platform
import subprocess
import traceback
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

SYSTEM_MARKERS = ("system", "ros", "slow")
SYSTEM_FOLDER = Path(__file__).resolve().parents[1] / "system"


def is_system(item: pytest.Item) -> bool:
    if any(item.get_closest_marker(name) is not None for name in SYSTEM_MARKERS):
        return True
    return SYSTEM_FOLDER in Path(str(item.path)).resolve().parents


def mark_system(items: list[pytest.Item]) -> None:
    """Give every system test the ``system`` marker, so ``-m "not system"`` selects the unit tier by hand too."""
    for item in items:
        if is_system(item) and item.get_closest_marker("system") is None:
            item.add_marker(pytest.mark.system)


def warm_up() -> None:
    """Run once, before the guard, what libraries start a process for the first time they are asked and cache
    (a test must not fail for being the first in its worker to ask): platform.uname()'s processor runs `uname -p`
    (pycyphal and matplotlib ask)."""
    platform.processor()


# The modules whose tests are independent and long (property tests per spec, each building and running its own
# children; scenarios that each fly a stack): xdist gives them out test by test (SpreadLongModules).
SPREAD_MODULES = frozenset({
    "tests/codegen/test_codec.py",
    "tests/codegen/test_codec_v0.py",
    "tests/codegen/test_converters.py",
    "tests/codegen/test_converters_v0.py",
    "tests/codegen/test_element_mappings.py",
    "tests/system/test_nodes_scenarios.py",
})


def scope_of(nodeid: str) -> str:
    """The unit of distribution a test belongs to: its module, or itself in a :data:`SPREAD_MODULES` module.

    >>> scope_of("tests/codegen/test_codec.py::test_x[sam]"), scope_of("tests/test_layers.py::test_y")
    ('tests/codegen/test_codec.py::test_x[sam]', 'tests/test_layers.py')
    """
    module = nodeid.split("::", 1)[0]
    return nodeid if module in SPREAD_MODULES else module


def spread_scheduler(config: pytest.Config, log: Any) -> Any:
    """xdist's distribution by file (a module's tests on one worker: its module fixtures, a built spec or a running
    stack, are set up once), except for :data:`SPREAD_MODULES`: their tests go one by one to whichever worker is
    free, so a long module does not leave one core alone at the end. (Not ``--dist loadgroup`` with marks: with
    pytest 9 xdist 3.8 can no longer add the group to the test ids it schedules by.)"""
    from xdist.scheduler import LoadFileScheduling

    class SpreadLongModules(LoadFileScheduling):
        def _split_scope(self, nodeid: str) -> str:
            return scope_of(nodeid)

    return SpreadLongModules(config, log)


def system_first(items: list[pytest.Item]) -> None:
    """System tests (the long ones: processes, CMake) first, each group in its own order: with xdist's
    distribution by file, a long module started last would leave one core alone at the end. Test order must not
    matter (each test sets up what it needs), so this changes only the wall time."""
    items.sort(key=lambda item: item.get_closest_marker("system") is None)


class ChildProcessGuard:
    """While active, every way of starting a process records the attempt and raises: the unit tier's proof that its
    tests stay in the pytest process. The attempt is recorded because code under test may catch the exception."""

    # (module, attribute): the calls that create a process. subprocess ends in its own alias of fork_exec (or in
    # os.posix_spawn), multiprocessing in _posixsubprocess.fork_exec or os.fork.
    TARGETS = ((subprocess, "_fork_exec"), (_posixsubprocess, "fork_exec"), (os, "fork"), (os, "forkpty"),
               (os, "posix_spawn"), (os, "posix_spawnp"), (os, "system"), (os, "execv"), (os, "execve"))

    def __init__(self) -> None:
        self.attempts: list[str] = []
        self._saved: list[tuple[Any, str, Any]] = []

    def _refuse(self, what: str) -> Callable[..., Any]:
        def refused(*args: Any, **kwargs: Any) -> Any:
            # Where: the innermost frame outside the standard library's process modules (the code that asked).
            frames = [f for f in traceback.extract_stack()[:-1]
                      if Path(f.filename).name not in ("subprocess.py", "popen_fork.py", "popen_spawn_posix.py",
                                                       "util.py", "context.py", "process.py")]
            where = f" at {frames[-1].filename}:{frames[-1].lineno}" if frames else ""
            self.attempts.append(what + where)
            raise OSError(f"the unit tier starts no process ({what}); mark the test `system` "
                          "(pytestmark = pytest.mark.system) or move it to tests/system/")
        return refused

    def __enter__(self) -> ChildProcessGuard:
        self.attempts = []
        for module, name in self.TARGETS:
            if hasattr(module, name):
                self._saved.append((module, name, getattr(module, name)))
                setattr(module, name, self._refuse(f"{module.__name__}.{name}"))
        return self

    def __exit__(self, *exc: object) -> None:
        for module, name, original in reversed(self._saved):
            setattr(module, name, original)
        self._saved.clear()


def fail_if_guarded(item: pytest.Item, report: pytest.TestReport, guard: ChildProcessGuard) -> None:
    """Turn a phase that tried to start a process into a failure, whatever the test did with the exception."""
    if guard.attempts and report.outcome != "failed":
        report.outcome = "failed"
        report.longrepr = (f"{item.nodeid} tried to start a process in the unit tier ({', '.join(guard.attempts)}):"
                           " mark it `system` (pytestmark = pytest.mark.system) or move it to tests/system/")
    guard.attempts.clear()
