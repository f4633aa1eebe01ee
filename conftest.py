"""pytest collects the doctests of codegen/ and runtime/ as well as tests/ (pyproject's testpaths).

pytest names a module it collects by its folder (``runtime.nav.mission``); the installed package is
``sam_runtime`` (``sam_codegen`` for codegen/). :class:`_SourceFolderAlias` makes the folder names aliases of the
packages, so a doctest runs in the one module the code imports (exceptions print as ``sam_runtime....Error``, module
state is not duplicated).

The ROS node implementations import the generated node bases (``sam_nodes``), which only a run or a test that
built them puts on the path; they hold no doctests (their logic, with its doctests, is in sam_runtime.nav).
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import json
import os
import sys
import time
from types import ModuleType
from typing import ClassVar

import pytest
from helpers import durations, isolation, tiers

collect_ignore = [f"runtime/nodes/{name}.py" for name in
                  ("controller", "dead_reckoning", "mission", "motion_planner", "performance_monitor", "slam")]


class _SourceFolderAlias(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    PACKAGES: ClassVar[dict[str, str]] = {"codegen": "sam_codegen", "runtime": "sam_runtime"}

    def find_spec(self, name: str, path: object = None, target: object = None) -> importlib.machinery.ModuleSpec | None:
        return importlib.util.spec_from_loader(name, self) if name.partition(".")[0] in self.PACKAGES else None

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> ModuleType:
        top, dot, rest = spec.name.partition(".")
        return importlib.import_module(self.PACKAGES[top] + dot + rest)

    def exec_module(self, module: ModuleType) -> None:
        """The real module is executed by its own import."""


sys.meta_path.insert(0, _SourceFolderAlias())


# --- Isolation and tiers (tests/helpers/isolation.py, tests/helpers/tiers.py) ------------------------------------
# Here, not in tests/conftest.py: this file is loaded by every run (also one of codegen/ or runtime/ doctests alone),
# and pytest_configure of the rootdir's conftest runs in each process's main thread before any test: the moment to
# enter a private network. pyproject's `pythonpath = ["tests"]` is applied before this file is imported.

_GUARD = pytest.StashKey["tiers.ChildProcessGuard"]()
_CPU = pytest.StashKey[float]()
_START = pytest.StashKey[float]()
_WORKER_ISOLATION: list[dict[str, object]] = []  # what each xdist worker reported (the controller's summary)
_SERIAL_FALLBACK: list[str] = []  # why the run was made serial, if it was


def pytest_addoption(parser: pytest.Parser) -> None:
    parser.addoption("--unit-tier", action="store_true", default=False,
                     help="run the unit tier only (no system test) and fail a test that starts a process")


@pytest.hookimpl(tryfirst=True)
def pytest_cmdline_main(config: pytest.Config) -> None:
    """Before xdist starts workers: where they could not each have a network of their own, run serially (the
    machine-wide lock and pid-derived domain ids of runtime_support then keep concurrent runs apart, as before)."""
    if getattr(config.option, "numprocesses", None) and not hasattr(config, "workerinput"):
        why = isolation.workers_can_isolate()
        if why is not None:
            _SERIAL_FALLBACK.append(why)
            config.option.numprocesses = 0


def _xdist_controller(config: pytest.Config) -> bool:
    return (not hasattr(config, "workerinput") and getattr(config.option, "dist", "no") != "no"
            and bool(getattr(config.option, "tx", None)) and not config.getoption("collectonly"))


@pytest.hookimpl(trylast=True)
def pytest_configure(config: pytest.Config) -> None:
    # Last: a plugin may connect to the xdist controller here (pytest-rerunfailures does, over 127.0.0.1); a socket
    # made before keeps working in the new namespace. The controller of an xdist run runs no test and stays where it
    # is, so that its workers, started from it, can reach it before they leave.
    if not _xdist_controller(config):
        isolation.enter_private_network()
    if config.getoption("--unit-tier"):
        tiers.warm_up()


def pytest_report_header(config: pytest.Config) -> str:
    return _isolation_line(config)


def _isolation_line(config: pytest.Config) -> str:
    mine = isolation.state()
    states = _WORKER_ISOLATION or [{"isolated": mine.isolated, "how": mine.how}]
    if all(s["isolated"] for s in states):
        who = f"each of {len(states)} workers" if _WORKER_ISOLATION else "this process"
        serial = f"; one test at a time: workers could not have one each ({_SERIAL_FALLBACK[0]})" \
            if _SERIAL_FALLBACK else ""
        return f"network isolation: {who} in a private network namespace ({states[0]['how']}){serial}"
    why = "; ".join(sorted({str(s["how"]) for s in states if not s["isolated"]} | set(_SERIAL_FALLBACK)))
    serial = ", one test at a time instead of in parallel" if _SERIAL_FALLBACK else ""
    return (f"network isolation: NONE ({why}): Cyphal/UDP tests serialise on {isolation_lock_name()}, "
            f"ROS domain ids are derived from the pid{serial}")


def isolation_lock_name() -> str:
    """The fallback's lock file (helpers.runtime_support)."""
    from helpers.runtime_support import UDP_LOCK

    return str(UDP_LOCK)


def pytest_xdist_make_scheduler(config: pytest.Config, log: object) -> object:
    return tiers.spread_scheduler(config, log)


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    tiers.mark_system(items)
    tiers.system_first(items)
    if config.getoption("--unit-tier"):
        keep = [item for item in items if item.get_closest_marker("system") is None]
        dropped = [item for item in items if item.get_closest_marker("system") is not None]
        if dropped:
            config.hook.pytest_deselected(items=dropped)
        items[:] = keep


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item: pytest.Item, nextitem: pytest.Item | None) -> object:
    item.stash[_CPU] = durations.cpu_seconds()
    item.stash[_START] = time.time()
    if not item.config.getoption("--unit-tier"):
        yield
        return
    with tiers.ChildProcessGuard() as guard:
        item.stash[_GUARD] = guard
        yield


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item: pytest.Item, call: pytest.CallInfo[None]) -> object:
    if call.when == "teardown" and _CPU in item.stash:
        # Before the report is made: junit writes the teardown report's properties (.nox/tests/junit.xml), so the
        # work a test cost (this process and the children it reaped) can be tabled beside its wall time.
        item.user_properties.append((durations.CPU_PROPERTY, round(durations.cpu_seconds() - item.stash[_CPU], 3)))
        now = time.time()
        item.user_properties += [(durations.WORKER_PROPERTY, os.environ.get("PYTEST_XDIST_WORKER", "")),
                                 (durations.END_PROPERTY, round(now, 3)),
                                 (durations.BUSY_PROPERTY, round(now - item.stash[_START], 3))]
    outcome = yield
    guard = item.stash.get(_GUARD, None)
    if guard is not None:
        tiers.fail_if_guarded(item, outcome.get_result(), guard)


def pytest_sessionfinish(session: pytest.Session) -> None:
    workeroutput = getattr(session.config, "workeroutput", None)
    if workeroutput is not None:  # an xdist worker tells the controller how it was isolated
        mine = isolation.state()
        workeroutput["isolation"] = json.dumps({"isolated": mine.isolated, "how": mine.how})


@pytest.hookimpl(optionalhook=True)
def pytest_testnodedown(node: object, error: object) -> None:
    output = getattr(node, "workeroutput", {}) or {}
    if "isolation" in output:
        _WORKER_ISOLATION.append(json.loads(output["isolation"]))


def pytest_terminal_summary(terminalreporter: pytest.TerminalReporter, exitstatus: int,
                            config: pytest.Config) -> None:
    terminalreporter.write_line(_isolation_line(config))
