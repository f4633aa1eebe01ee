"""The project lock (sam_codegen.project.lock, issue 25 "Runs beside each other"): a second process waits for the one
holding a resource, says once for whom (pid and command line, from the lock file) and then what the holder does at a
bounded rate, and gets the lock when the holder is done, or dies: the kernel releases a dead holder's flock.

The holder is a real process (so that its pid and command line are another process's), held on a file the test
creates: no verdict rests on how long anything takes."""

from __future__ import annotations

import itertools
import re
import signal
import subprocess
import sys
import textwrap
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

from sam_codegen.project import lock as lock_module
from sam_codegen.project.lock import LockTimeout, LockWaitCancelled, ProjectLock, command_line, lock_path

# Generous bounds for a loaded machine: each is a deadline on an event that comes, never a wait that must pass.
DEADLINE_S = 60.0

# Takes the lock, says so, reports a step when told to (file "step"), lets go when told to (file "go").
_HOLDER = textwrap.dedent("""\
    import pathlib, sys, time
    from sam_codegen.project.lock import ProjectLock
    lock_file, control = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
    with ProjectLock(lock_file, "the test resource") as lock:
        print("held", flush=True)
        while not (control / "step").exists():
            time.sleep(0.02)
        lock.status("[1/1] thing: build (1.0 s)")
        print("step", flush=True)
        while not (control / "go").exists():
            time.sleep(0.02)
    print("released", flush=True)
    """)


def _poll(fn: Callable[[], object], what: str, timeout: float = DEADLINE_S) -> None:
    deadline = time.monotonic() + timeout
    while not fn():
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out after {timeout:.0f} s waiting for {what}")
        time.sleep(0.02)


class Holder:
    def __init__(self, lock_file: Path, control: Path) -> None:
        self.control = control
        control.mkdir(exist_ok=True)
        self.proc = subprocess.Popen([sys.executable, "-c", _HOLDER, str(lock_file), str(control), "--marker"],
                                     stdout=subprocess.PIPE, text=True)
        self.expect("held")

    def expect(self, line: str) -> None:
        assert self.proc.stdout is not None
        got = self.proc.stdout.readline().strip()  # the holder prints these lines at once, or has ended
        assert got == line, f"the holder said {got!r} (exit {self.proc.poll()}), expected {line!r}"

    def tell(self, what: str) -> None:
        (self.control / what).touch()


@pytest.fixture
def holder(tmp_path: Path) -> Iterator[Holder]:
    h = Holder(tmp_path / "resource.lock", tmp_path / "control")
    try:
        yield h
    finally:
        if h.proc.poll() is None:
            h.proc.kill()
        h.proc.wait(timeout=DEADLINE_S)


class Waiter(threading.Thread):
    """ProjectLock entered in a thread, its lines collected."""

    def __init__(self, lock: ProjectLock) -> None:
        super().__init__(daemon=True)
        self.lock, self.lines, self.error = lock, [], None  # type: ignore[var-annotated]
        self.lock._say = self.lines.append  # type: ignore[assignment]
        self.got = threading.Event()
        self.done = threading.Event()

    def run(self) -> None:
        try:
            with self.lock:
                self.got.set()
                self.done.wait(DEADLINE_S)
        except BaseException as exc:
            self.error = exc  # type: ignore[assignment]


@pytest.mark.system  # the holder / the publisher is another process
def test_a_waiter_says_for_whom_it_waits_then_what_the_holder_does(tmp_path: Path, holder: Holder,
                                                                   monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(lock_module, "MIN_LINE_S", 0.0)  # the bounded rate is tested below, with a fake clock
    waiter = Waiter(ProjectLock(tmp_path / "resource.lock", "the test resource"))
    waiter.start()
    _poll(lambda: waiter.lines, "the waiting line")
    assert not waiter.got.is_set()
    first = waiter.lines[0]
    assert first.startswith(f"waiting for the test resource: pid {holder.proc.pid} (`python -c ... ")
    assert "/control --marker`) has held it for " in first, first  # the holder's own command line
    holder.tell("step")
    holder.expect("step")
    _poll(lambda: any("[1/1] thing: build" in line for line in waiter.lines), "the holder's step")
    assert next(line for line in waiter.lines if "thing: build" in line).startswith("still waiting (")
    assert not waiter.got.is_set()
    holder.tell("go")
    holder.expect("released")
    assert waiter.got.wait(DEADLINE_S), waiter.error
    waiter.done.set()
    waiter.join(DEADLINE_S)
    assert waiter.error is None
    assert waiter.lock.contended and waiter.lock.held_by is not None and waiter.lock.held_by.pid == holder.proc.pid
    assert waiter.lines[-1].startswith("the test resource is free after ")


@pytest.mark.system  # the holder / the publisher is another process
def test_a_dead_holder_leaves_no_stale_lock(tmp_path: Path, holder: Holder) -> None:
    waiter = Waiter(ProjectLock(tmp_path / "resource.lock", "the test resource"))
    waiter.start()
    _poll(lambda: waiter.lines, "the waiting line")
    holder.proc.send_signal(signal.SIGKILL)  # no clean-up of its own: the kernel releases the flock
    holder.proc.wait(DEADLINE_S)
    assert waiter.got.wait(DEADLINE_S), waiter.error
    waiter.done.set()
    waiter.join(DEADLINE_S)
    assert waiter.error is None and waiter.lock.contended
    with ProjectLock(tmp_path / "resource.lock", "the test resource") as again:  # free once the waiter let go
        assert not again.contended


@pytest.mark.system  # the holder / the publisher is another process
def test_a_wait_timeout_names_the_holder(tmp_path: Path, holder: Holder) -> None:
    with pytest.raises(LockTimeout) as info:
        with ProjectLock(tmp_path / "resource.lock", "the test resource", timeout=0.3):
            pass
    text = str(info.value)
    assert text.startswith("gave up after 0 s waiting for the test resource: pid "
                           f"{holder.proc.pid} (`python -c ... "), text
    assert str(tmp_path / "resource.lock") in text
    assert holder.proc.poll() is None  # the holder goes on


@pytest.mark.system  # the holder / the publisher is another process
def test_a_stop_while_waiting_ends_the_wait(tmp_path: Path, holder: Holder) -> None:
    asked = []

    def cancelled() -> bool:
        asked.append(1)
        return len(asked) > 2

    with pytest.raises(LockWaitCancelled, match="stopped while waiting for the test resource"):
        with ProjectLock(tmp_path / "resource.lock", "the test resource", cancelled=cancelled):
            pass


def test_the_waiting_lines_come_at_a_bounded_rate(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A holder that changes its step at every poll, a waiter on a fake clock: at most one line per MIN_LINE_S,
    and one at least every QUIET_S when the holder says nothing new."""
    path = tmp_path / "resource.lock"
    now = [0.0]
    lines: list[tuple[float, str]] = []
    with ProjectLock(path, "the test resource", command="holder") as held:
        steps = iter(range(10_000))

        def sleep(_s: float) -> None:
            now[0] += lock_module.POLL_S
            if now[0] < 30.0:
                held.status(f"step {next(steps)}")  # a new step every poll for 30 s, then silence
            if now[0] >= 80.0:
                held.release()

        monkeypatch.setattr(lock_module.time, "sleep", sleep)
        waiter = ProjectLock(path, "the test resource", say=lambda line: lines.append((now[0], line)),
                             clock=lambda: now[0])
        with waiter:
            pass
    times = [t for t, _ in lines]
    assert lines[0][1].startswith("waiting for the test resource: pid ") and "`holder`" in lines[0][1]
    gaps = [b - a for a, b in itertools.pairwise(times[:-1])]  # the last line comes when the holder lets go
    assert min(gaps) >= lock_module.MIN_LINE_S - 1e-9 and max(gaps) <= lock_module.QUIET_S + lock_module.POLL_S
    assert sum(1 for t in times if t < 30.0) <= 30.0 / lock_module.MIN_LINE_S + 1
    assert any("still waiting for the test resource (" in line for t, line in lines if t > 30.0)
    assert re.fullmatch(r"the test resource is free after 80\.\d s of waiting", lines[-1][1]), lines[-1]


def test_lock_files_are_named_after_the_resolved_resource(tmp_path: Path) -> None:
    (tmp_path / "project" / "generated").mkdir(parents=True)
    link = tmp_path / "link"
    link.symlink_to(tmp_path / "project")
    one = lock_path("generated", tmp_path / "project" / "generated", tmp_path / "locks")
    assert one == lock_path("generated", link / "generated", tmp_path / "locks")
    assert one.name.startswith("generated-generated-") and one.parent == tmp_path / "locks"
    assert one != lock_path("generated", tmp_path / "other" / "generated", tmp_path / "locks")


def test_the_command_line_is_the_users(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(sys, "orig_argv", ["/venv/bin/python", "/venv/bin/sam-codegen", "run", "--duration", "30"])
    assert command_line() == "sam-codegen run --duration 30"
    monkeypatch.setattr(sys, "orig_argv", ["/venv/bin/python3", "-m", "sam_runtime.cli", "run", "--namespace", "/a b"])
    assert command_line() == "python -m sam_runtime.cli run --namespace '/a b'"
    monkeypatch.setattr(sys, "orig_argv", ["python3", "-c", "import x\nx.main()", "build"])
    assert command_line() == "python -c ... build"
