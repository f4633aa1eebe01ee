"""One process at a time on a project's resource (generated/, a ROS build folder and its install): an advisory file
lock (``fcntl.flock``) per resource, held across check-and-build.

Two commands started at once in one project (two ``sam-codegen run``, a ``run`` beside a ``ros-install`` or a
``build``) would otherwise race: the second's CMake configure failed in a build folder the first was building in,
and two builds swap generated/ under each other. With the lock, one builds; the other waits, says once who it waits
for (the holder writes its pid, command line and current step into the lock file), then the holder's progress or
its own wait time at a bounded rate; once it has the lock it checks again, finds the result current and reuses it.

The kernel releases a flock when its holder ends, however it ends (a crash, SIGKILL): there are no stale locks to
clean up, and a waiter whose holder died simply gets the lock and finds out itself what is left to do.

The lock files live in the user's cache directory (``locks/``), one per resource, named after the resource's
resolved path: two commands meaning the same folder meet at one lock whichever way they named it, and a command
leaves nothing in the project beyond what it writes anyway. Pure standard library (the project layer).
"""

from __future__ import annotations

import contextlib
import fcntl
import hashlib
import json
import os
import shlex
import sys
import tempfile
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from types import TracebackType

from sam_codegen.project.workspace import user_cache_dir

__all__ = [
    "LockError",
    "LockHolder",
    "LockTimeout",
    "LockWaitCancelled",
    "ProjectLock",
    "command_line",
    "lock_path",
    "locks_dir",
    "optional_lock",
]

# How often a waiter tries the lock again: a tenth of a second costs nothing beside a build of seconds.
POLL_S = 0.1
# A waiter says something at least this often (its wait time when the holder reports nothing new)...
QUIET_S = 15.0
# ...and never more often than this (the holder's steps can follow each other quickly).
MIN_LINE_S = 2.0
# The holder writes who it is right after it takes the lock; the first line waits this long for it.
IDENTIFY_S = 1.0


class LockError(Exception):
    """The lock file cannot be created or opened (an unwritable cache directory)."""


class LockTimeout(LockError):
    """The lock stayed held longer than the waiter's timeout; ``str()`` says who held it."""


class LockWaitCancelled(LockError):
    """The waiter was asked to stop (a signal) while it waited."""


@dataclass(frozen=True)
class LockHolder:
    """What the process holding a lock wrote into it."""

    pid: int
    command: str
    since: float  # time.time() when it took the lock
    status: str = ""  # its current step, e.g. "[1/1] sam_msgs: build (4.1 s)"

    def describe(self, now: float) -> str:
        return f"pid {self.pid} (`{self.command}`) has held it for {max(0.0, now - self.since):.0f} s"


def command_line() -> str:
    """This process's command line as its user typed it, for the lock file: ``sam-codegen run --duration 30``, not
    ``/venv/bin/python /venv/bin/sam-codegen ...``."""
    argv = list(getattr(sys, "orig_argv", None) or sys.argv)
    if len(argv) >= 3 and argv[1] == "-m":
        words = ["python", *argv[1:]]
    elif len(argv) >= 3 and argv[1] == "-c":  # the program itself would fill the line
        words = ["python", "-c", "...", *argv[3:]]
    elif len(argv) >= 2 and not argv[1].startswith("-"):
        words = [Path(argv[1]).name, *argv[2:]]  # a console script run by its interpreter
    else:
        words = [Path(argv[0]).name if argv else "?", *argv[1:]]
    text = shlex.join(words)
    return text if len(text) <= 200 else text[:197] + "..."


def locks_dir() -> Path:
    """``locks/`` in the user's cache directory; when that cannot be created (a read-only home), one under the
    temporary folder. Raises LockError when neither can."""
    candidates = [user_cache_dir() / "locks", Path(tempfile.gettempdir()) / f"sam-codegen-{os.getuid()}" / "locks"]
    problems = []
    for folder in candidates:
        try:
            folder.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            problems.append(f"{folder}: {exc.strerror or exc}")
            continue
        if os.access(folder, os.W_OK | os.X_OK):
            return folder
        problems.append(f"{folder}: not writable")
    raise LockError("no folder for lock files: " + "; ".join(problems))


def lock_path(kind: str, resource: Path, folder: Path | None = None) -> Path:
    """The lock file of a resource folder: ``<locks>/<kind>-<name>-<hash of its resolved path>.lock``.

    >>> lock_path("ros-build", Path("/p/x/ros-build"), Path("/c")).name.startswith("ros-build-ros-build-")
    True
    """
    resolved = Path(resource).expanduser().resolve()
    digest = hashlib.sha256(str(resolved).encode()).hexdigest()[:12]
    return (folder if folder is not None else locks_dir()) / f"{kind}-{resolved.name or 'root'}-{digest}.lock"


def _read_holder(fd: int) -> LockHolder | None:
    """The holder's line, or None while it is not (completely) written yet: the holder rewrites the file in place,
    so a read may see a half-written line; the next poll reads it again."""
    try:
        raw = os.pread(fd, 4096, 0)
        data = json.loads(raw.split(b"\n", 1)[0])
        return LockHolder(int(data["pid"]), str(data["command"]), float(data["since"]), str(data.get("status", "")))
    except (OSError, ValueError, KeyError, TypeError):
        return None


class ProjectLock:
    """``with ProjectLock(path, what, say=print): ...`` holds the lock of one resource for the block.

    ``what`` names the resource for the waiting lines ("the ROS build folder /p/.sam-codegen-cache/ros-build").
    ``say`` gets the waiting lines. ``timeout`` (seconds, None: as long as the holder runs) bounds the wait
    (LockTimeout); ``cancelled`` is asked at every poll and ends the wait with LockWaitCancelled (a signal handler
    that only records the signal). After entering, ``contended`` says whether another process held it first (then
    the caller checks again what is left to do), ``waited`` is the seconds spent waiting and ``held_by`` whom the
    waiter waited for.
    """

    def __init__(self, path: Path, what: str, *, say: Callable[[str], None] | None = None,
                 timeout: float | None = None, cancelled: Callable[[], bool] | None = None,
                 command: str | None = None, clock: Callable[[], float] = time.monotonic) -> None:
        self.path, self.what = Path(path), what
        self._say = say or (lambda _line: None)
        self._timeout, self._cancelled, self._clock = timeout, cancelled, clock
        self._command = command or command_line()
        self._fd: int | None = None
        self._since = 0.0
        self.waited = 0.0
        self.contended = False
        self.held_by: LockHolder | None = None

    # ------------------------------------------------------------------------------------------------- holding
    def __enter__(self) -> ProjectLock:
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            fd = os.open(self.path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o666)
        except OSError as exc:
            raise LockError(f"cannot open the lock file {self.path}: {exc.strerror or exc}") from None
        try:
            self._wait(fd)
        except BaseException:
            os.close(fd)
            raise
        self._fd = fd
        self._since = time.time()
        self.status("")
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.release()

    def release(self) -> None:
        """Emptied first (a waiter then reads "not known yet", never a holder that has gone), then unlocked."""
        if self._fd is None:
            return
        fd, self._fd = self._fd, None
        with contextlib.suppress(OSError):
            os.ftruncate(fd, 0)
        with contextlib.suppress(OSError):
            fcntl.flock(fd, fcntl.LOCK_UN)
        os.close(fd)

    def status(self, text: str) -> None:
        """Tell the waiters what the holder is doing now (one line, e.g. a build step)."""
        if self._fd is None:
            return
        line = json.dumps({"pid": os.getpid(), "command": self._command, "since": self._since,
                           "status": " ".join(text.split())[:300], "resource": self.what}) + "\n"
        data = line.encode()
        # In place, then cut to length: a waiter reads up to the first newline, so it never takes the tail of an
        # older, longer line for part of this one.
        with contextlib.suppress(OSError):
            os.pwrite(self._fd, data, 0)
            os.ftruncate(self._fd, len(data))

    # ------------------------------------------------------------------------------------------------- waiting
    def _try(self, fd: int) -> bool:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            return False
        except OSError as exc:
            raise LockError(f"cannot lock {self.path}: {exc.strerror or exc}") from None
        return True

    def _wait(self, fd: int) -> None:
        start = self._clock()
        said_at: float | None = None  # when the last line was said
        told: tuple[int, str] | None = None  # the holder's (pid, status) last said
        while not self._try(fd):
            self.contended = True
            now = self._clock()
            waited = now - start
            holder = _read_holder(fd) or self.held_by
            self.held_by = holder
            if self._cancelled is not None and self._cancelled():
                raise LockWaitCancelled(f"stopped while waiting for {self.what}")
            who = holder.describe(time.time()) if holder is not None else "another process holds it"
            if self._timeout is not None and waited >= self._timeout:
                raise LockTimeout(f"gave up after {waited:.0f} s waiting for {self.what}: {who} (lock file "
                                  f"{self.path})")
            key = (holder.pid, holder.status) if holder is not None else None
            if said_at is None:
                if holder is not None or waited >= IDENTIFY_S:  # a moment for the holder to say who it is
                    self._say(f"waiting for {self.what}: {who}"
                              + (f"; now: {holder.status}" if holder is not None and holder.status else ""))
                    said_at, told = now, key
            elif now - said_at >= MIN_LINE_S and holder is not None and key != told:
                if told is not None and holder.pid != told[0]:  # the first holder is done; another one got it first
                    self._say(f"still waiting for {self.what} ({waited:.0f} s): now {who}")
                else:
                    self._say(f"still waiting ({waited:.0f} s): pid {holder.pid}: {holder.status or 'working'}")
                said_at, told = now, key
            elif now - said_at >= QUIET_S:
                self._say(f"still waiting for {self.what} ({waited:.0f} s)")
                said_at = now
            time.sleep(POLL_S)
        self.waited = self._clock() - start
        if said_at is not None:
            self._say(f"{self.what} is free after {self.waited:.1f} s of waiting")


@contextlib.contextmanager
def optional_lock(lock: ProjectLock | None) -> Iterator[ProjectLock | None]:
    """``with optional_lock(lock_or_none) as held:``: the lock's block, or a plain one when there is no lock."""
    if lock is None:
        yield None
        return
    with lock as held:
        yield held
