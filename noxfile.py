"""Sessions: tests (the CI gate), lint, build, run (the main job on simulated devices), bench."""

from __future__ import annotations

import os

import nox

nox.options.default_venv_backend = "venv"
nox.options.sessions = ["lint", "tests"]
nox.options.reuse_existing_virtualenvs = True

# Every process that starts rclpy keeps DDS discovery on loopback (these machines may only talk to 127/8).
LOOPBACK = {"ROS_AUTOMATIC_DISCOVERY_RANGE": os.environ.get("ROS_AUTOMATIC_DISCOVERY_RANGE") or "LOCALHOST"}


def _install(session: nox.Session, extras: str) -> None:
    session.install("-e", f".[{extras}]")


def _ros_install(session: nox.Session) -> None:
    """Build the generated sam_msgs package with CMake into this session's environment."""
    session.run("sam-codegen", "ros-install", "--build-dir", f"{session.virtualenv.location}/ros-build",
                env=LOOPBACK)


@nox.session(python="3.11")
def tests(session: nox.Session) -> None:
    """Everything: generated/ is current, sam_msgs builds, then unit, golden, conformance and end-to-end tests."""
    _install(session, "runtime,rosbuild,test")
    session.run("ruff", "check", "codegen", "runtime", "tests", "bench", "noxfile.py")
    session.run("sam-codegen", "build", "--check")
    _ros_install(session)
    session.run("pytest", *(session.posargs or ["-q"]), env=LOOPBACK)


@nox.session(python="3.11")
def lint(session: nox.Session) -> None:
    session.install("ruff>=0.6")
    session.run("ruff", "check", "codegen", "runtime", "tests", "bench", "noxfile.py")


@nox.session(python="3.11")
def build(session: nox.Session) -> None:
    """Regenerate generated/ from spec/interfaces.yaml."""
    _install(session, "test")
    session.run("sam-codegen", "build", *session.posargs)


@nox.session(python="3.11")
def run(session: nox.Session) -> None:
    """The main job: simulated devices -> Cyphal/UDP on 127.0.0.1 -> bridge -> ROS 2, shown live until Ctrl-C."""
    _install(session, "runtime,rosbuild")
    # `run` regenerates generated/ and (re)builds sam_msgs into this environment when they are stale.
    session.run("sam-codegen", "run", *session.posargs, env=LOOPBACK)


@nox.session(python="3.11")
def bench(session: nox.Session) -> None:
    """Benchmarks (not part of the tests): bench/results/results.md, results.json and scaling.png."""
    _install(session, "runtime,rosbuild,bench")
    session.run("sam-codegen", "build", "--check")
    _ros_install(session)
    session.run("python", "-m", "bench.run", *session.posargs, env=LOOPBACK)
