"""Each pytest process (xdist worker) runs in a network of its own (tests/helpers/isolation.py), and what the tests
start inherits it. These fail when isolation is lost; they skip only where the machine allows no namespace (the
fallback, which the run's summary line names)."""

from __future__ import annotations

import errno
import os
import socket
import subprocess
import sys
import threading

import pytest
from helpers import isolation


@pytest.fixture
def private() -> isolation.Isolation:
    state = isolation.state()
    assert state.isolated or not state.entered, f"a network namespace was made but is not private: {state.how}"
    if not state.isolated:
        pytest.skip(f"fallback, no isolation: {state.how}")
    return state


def test_tests_run_in_the_thread_that_entered_the_namespace(private: isolation.Isolation) -> None:
    # CLONE_NEWNET is per thread: the tests must run where pytest_configure entered it (xdist: the main thread).
    assert threading.current_thread() is threading.main_thread()
    assert isolation.current_namespace() == private.namespace
    # Not the network of the process that started this one (xdist's controller, or the shell).
    assert os.readlink(f"/proc/{os.getppid()}/ns/net") != private.namespace


def test_the_loopback_is_this_process_own(private: isolation.Isolation) -> None:
    """Every isolated process holds SENTINEL_PORT on 127.0.0.1 (no SO_REUSEADDR) since its start: had two workers
    shared a loopback, the second's bind would have failed (the fixture's assert). Here: it is really held."""
    assert isolation.sentinel_bound()
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s, pytest.raises(OSError) as caught:
        s.bind(("127.0.0.1", isolation.SENTINEL_PORT))
    assert caught.value.errno == errno.EADDRINUSE


def test_a_thread_started_by_a_test_shares_the_network(private: isolation.Isolation) -> None:
    # rclpy's executor, DDS and pycyphal's readers are threads started during a test.
    seen: list[str] = []
    t = threading.Thread(target=lambda: seen.append(isolation.current_namespace()))
    t.start()
    t.join(timeout=30)
    assert seen == [private.namespace]


@pytest.mark.system
def test_a_child_process_shares_the_network(private: isolation.Isolation) -> None:
    # The bridge, simulator and CMake run as children: they must be in the same private network as the test.
    code = ("import os, socket; s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM); "
            f"s.bind(('127.0.0.1', {isolation.SENTINEL_PORT})); print(os.readlink('/proc/thread-self/ns/net'))")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=False)
    # The child cannot take the port this process holds: the same loopback.
    assert proc.returncode != 0 and "Address already in use" in proc.stderr, proc.stderr
    proc = subprocess.run([sys.executable, "-c", "import os; print(os.readlink('/proc/thread-self/ns/net'))"],
                          capture_output=True, text=True, timeout=120, check=True)
    assert proc.stdout.strip() == private.namespace


def test_machine_network_goes_back_and_returns(private: isolation.Isolation) -> None:
    # pip reaching the package index (tests/system/test_install_wheel.py) steps out for that call only.
    with isolation.machine_network():
        outside = isolation.current_namespace()
    assert outside != private.namespace
    assert isolation.current_namespace() == private.namespace
