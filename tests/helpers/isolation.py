"""A network of its own for each pytest process (every xdist worker, or the one process of a plain run).

Cyphal/UDP subjects are multicast groups, DroneCAN's ``mcast-lo:`` bus is a multicast group and DDS discovers over
loopback: on the machine's shared network two workers (or a ``sam-codegen run`` flown beside the suite) would see
each other's devices and nodes. :func:`enter_private_network` moves the calling thread into a new Linux network
namespace with only ``lo``, up. CLONE_NEWNET applies to the calling thread; every thread it starts afterwards
(rclpy's executor, DDS, pycyphal's socket readers) and every child process inherit it, so it must be called in the
thread that runs the tests, before any test opens a socket or starts a thread: pytest_configure in the main thread
(xdist runs a worker's tests in its main thread; tests/test_isolation.py checks both).

As root it is a plain ``unshare(CLONE_NEWNET)``; otherwise a user namespace mapping the caller to root is tried
first (allowed where unprivileged user namespaces are, and only in a single-threaded process). Where neither works
the run falls back to what it did before: Cyphal/UDP tests take a machine-wide lock file and ROS domain ids are
derived from the pid (``helpers.runtime_support``), and the pytest header says so once.
"""

from __future__ import annotations

import contextlib
import ctypes
import errno
import fcntl
import os
import socket
import struct
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

CLONE_NEWNET = 0x40000000
CLONE_NEWUSER = 0x10000000
_SIOCGIFFLAGS = 0x8913
_SIOCSIFFLAGS = 0x8914
_IFF_UP = 0x1
# Set in the environment by the process that entered a namespace, read by helpers.runtime_support (children see it
# too: they inherit the namespace with it).
ENV = "SAM_TEST_NETNS"
# Every isolated process binds this loopback port at start and holds it: two processes that share a loopback cannot
# both hold it, so a lost isolation shows as a failed bind (tests/test_isolation.py), not as cross-talk in a bridge.
SENTINEL_PORT = 47_919


@dataclass(frozen=True)
class Isolation:
    isolated: bool
    entered: bool  # a namespace was made (isolated is False then only when it turned out shared: a defect)
    how: str  # how the namespace was made, or why none could be
    namespace: str  # the network namespace the tests run in (readlink of /proc/thread-self/ns/net)


_state: Isolation | None = None
_sentinel: socket.socket | None = None
_machine_ns: int | None = None  # an fd of the network this process started in (machine_network goes back to it)


def current_namespace() -> str:
    """The network namespace of the calling thread, e.g. ``net:[4026532281]`` ('' where /proc has none)."""
    try:
        return os.readlink("/proc/thread-self/ns/net")
    except OSError:
        return ""


def _unshare(flags: int) -> None:
    libc = ctypes.CDLL(None, use_errno=True)
    if libc.unshare(ctypes.c_int(flags)) != 0:
        err = ctypes.get_errno()
        raise OSError(err, os.strerror(err))


def _map_to_root(uid: int, gid: int) -> None:
    """Inside a fresh user namespace: the caller is root there (may configure its network)."""
    Path("/proc/self/setgroups").write_text("deny")
    Path("/proc/self/uid_map").write_text(f"0 {uid} 1")
    Path("/proc/self/gid_map").write_text(f"0 {gid} 1")


def _loopback_up() -> None:
    """``ip link set lo up`` without the ip tool: SIOCSIFFLAGS on a socket of the new namespace."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        req = struct.pack("16sh", b"lo", 0)
        flags = struct.unpack("16sh", fcntl.ioctl(s.fileno(), _SIOCGIFFLAGS, req))[1]
        fcntl.ioctl(s.fileno(), _SIOCSIFFLAGS, struct.pack("16sh", b"lo", flags | _IFF_UP))


# Set to 1: make no namespace (to see the fallback, or to debug with the machine's network).
OFF_ENV = "SAM_TEST_NO_NETNS"


def _try_enter() -> str:
    """Enter a new network namespace; returns how, raises OSError with the reason when it cannot."""
    if os.environ.get(OFF_ENV) == "1":
        raise OSError(errno.EPERM, f"{OFF_ENV}=1")
    if not os.path.exists("/proc/self/ns/net"):
        raise OSError(errno.ENOSYS, "no Linux network namespaces here")
    if os.geteuid() == 0:
        _unshare(CLONE_NEWNET)
        return "unshare(CLONE_NEWNET) as root"
    uid, gid = os.getuid(), os.getgid()
    # CLONE_NEWUSER is refused (EINVAL) in a process with more than one thread (an xdist worker has execnet's).
    _unshare(CLONE_NEWUSER | CLONE_NEWNET)
    _map_to_root(uid, gid)
    return "unshare(CLONE_NEWUSER|CLONE_NEWNET), unprivileged"


def workers_can_isolate() -> str | None:
    """Whether xdist workers will be able to enter namespaces of their own (None) or why not. Asked before the
    workers start, in a forked child so that this process stays where it is. Only root can: a worker has more
    than one thread (execnet's), and CLONE_NEWUSER refuses a multi-threaded process."""
    if os.environ.get(OFF_ENV) == "1":
        return f"{OFF_ENV}=1"
    if not os.path.exists("/proc/self/ns/net"):
        return "no Linux network namespaces here"
    if os.geteuid() != 0:
        return "not root (an unprivileged namespace cannot be made in a multi-threaded xdist worker)"
    pid = os.fork()
    if pid == 0:  # the child: try, report by exit code, never return into pytest
        try:
            _unshare(CLONE_NEWNET)
            _loopback_up()
            os._exit(0)
        except BaseException:
            os._exit(1)
    _, status = os.waitpid(pid, 0)
    return None if os.waitstatus_to_exitcode(status) == 0 else "unshare(CLONE_NEWNET) refused"


def enter_private_network() -> Isolation:
    """Move the calling thread (and what it starts later) into a private network with loopback up; once per
    process. Never raises: where it cannot, the result says why and the tests serialise as before."""
    global _state, _sentinel, _machine_ns
    if _state is not None:
        return _state
    os.environ.pop(ENV, None)
    try:
        machine = os.open("/proc/thread-self/ns/net", os.O_RDONLY | os.O_CLOEXEC)
    except OSError:
        machine = None
    try:
        how = _try_enter()
    except OSError as ex:
        _state = Isolation(False, False, f"no private network namespace ({ex.strerror or ex})", current_namespace())
        return _state
    try:
        _loopback_up()
        sentinel = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        sentinel.bind(("127.0.0.1", SENTINEL_PORT))
    except OSError as ex:
        _state = Isolation(False, True, f"a namespace was made ({how}) but its loopback is not private: {ex}",
                           current_namespace())
        return _state
    _sentinel = sentinel
    _machine_ns = machine
    _state = Isolation(True, True, how, current_namespace())
    os.environ[ENV] = _state.namespace
    return _state


def _setns(fd: int) -> None:
    libc = ctypes.CDLL(None, use_errno=True)
    if libc.setns(ctypes.c_int(fd), ctypes.c_int(CLONE_NEWNET)) != 0:
        err = ctypes.get_errno()
        raise OSError(err, os.strerror(err))


@contextlib.contextmanager
def machine_network() -> Iterator[None]:
    """The calling thread (and the processes it starts meanwhile) back in the machine's network for a step that
    needs more than loopback, e.g. pip reaching the package index; the private one again after. Where the
    process is not isolated, or cannot go back (a user namespace), it stays where it is."""
    if _machine_ns is None or not isolated():
        yield
        return
    private = os.open("/proc/thread-self/ns/net", os.O_RDONLY | os.O_CLOEXEC)
    try:
        try:
            _setns(_machine_ns)
        except OSError:
            yield
            return
        try:
            yield
        finally:
            _setns(private)
    finally:
        os.close(private)


def state() -> Isolation:
    """This process's isolation (entered by the conftest at start; a process without it is not isolated)."""
    if _state is not None:
        return _state
    inherited = bool(os.environ.get(ENV)) and os.environ.get(ENV) == current_namespace()
    return Isolation(inherited, False, "inherited from the parent process" if inherited else "not entered",
                     current_namespace())


def isolated() -> bool:
    """Whether this process runs in a private network: no machine-wide lock or pid-derived ids needed."""
    return state().isolated


def sentinel_bound() -> bool:
    """Whether this process holds SENTINEL_PORT on its loopback (it does when it entered its namespace)."""
    return _sentinel is not None
