"""Sessions: tests (the CI gate), unit (its fast tier), lint, build, run (the main job on simulated devices), bench."""

from __future__ import annotations

import os
from pathlib import Path

import nox

nox.options.default_venv_backend = "venv"
nox.options.sessions = ["lint", "tests"]
nox.options.reuse_existing_virtualenvs = True

# Every process that starts rclpy keeps DDS discovery on loopback (these machines may only talk to 127/8).
LOOPBACK = {"ROS_AUTOMATIC_DISCOVERY_RANGE": os.environ.get("ROS_AUTOMATIC_DISCOVERY_RANGE") or "LOCALHOST"}


REPO = Path(__file__).resolve().parent
# The import names of the source folders (pyproject's package-dir): mypy needs folders named after the packages.
PACKAGE_DIRS = {"sam_codegen": "codegen", "sam_runtime": "runtime"}
RUFF_PATHS = ("codegen", "runtime", "tests", "bench", "noxfile.py", "conftest.py")


def _static_checks(session: nox.Session) -> None:
    """ruff, mypy over both packages, and the import layers (tests/test_layers.py)."""
    session.run("ruff", "check", *RUFF_PATHS)
    # Not session.create_tmp(): it sets TMPDIR for the session, which would put the tests' tmp_path inside this
    # project, where the workspace tests would find its spec.
    links = Path(session.virtualenv.location) / "mypy-path"
    links.mkdir(exist_ok=True)
    for package, folder in PACKAGE_DIRS.items():
        link = links / package
        if not link.is_symlink():
            link.symlink_to(REPO / folder, target_is_directory=True)
    session.run("mypy", "-p", "sam_codegen", "-p", "sam_runtime", env={"MYPYPATH": str(links)})
    session.run("pytest", "-q", "-p", "no:cacheprovider", "--noconftest", "tests/test_layers.py")


def _install(session: nox.Session, extras: str) -> None:
    session.install("-e", f".[{extras}]")


def _ros_install(session: nox.Session) -> None:
    """Build the generated sam_msgs package with CMake into this session's environment."""
    session.run("sam-codegen", "ros-install", "--build-dir", f"{session.virtualenv.location}/ros-build",
                env=LOOPBACK)


def _yakut(session: nox.Session) -> dict[str, str]:
    """yakut, the Cyphal command-line tool, in a virtual environment of its own (its pycyphal is its own business):
    the tests that call it (register access on a simulated board, GetInfo of the bridge's loop transport) find it by
    SAM_YAKUT (tests/helpers/yakut_tool.py)."""
    venv = Path(session.virtualenv.location) / "yakut"
    exe = venv / "bin" / "yakut"
    if not exe.exists():
        session.run("python", "-m", "venv", str(venv))
        session.run(str(venv / "bin" / "python"), "-m", "pip", "install", "-q", "yakut~=0.14.2", external=True)
    return {"SAM_YAKUT": str(exe)}


# pytest-xdist: one worker per core and two more, each in a private network (tests/helpers/isolation.py). The system
# tests fly simulated vehicles in real time and wait for discovery, so a worker per core left the CPU idle part of the
# time: 2 workers used 157 % of 200 %, 3 workers 170 % (fresh clone: 1,333 CPU s in a 784 s pytest stage,
# 2026-11-28), 4 workers 183 % (fresh clone: 1,478 CPU s in 809 s; with the test ROS packages already built 1,165 CPU s
# in 645 s). The workers end within ~20 s of each other: the stage is CPU-bound, a fifth worker has nothing to fill
# (`python tests/helpers/durations.py --workers .nox/tests/junit.xml`). A module's tests stay on one worker (by file):
# their module fixtures (a built spec, a running stack) are set up once; the long modules of independent tests go test
# by test (tests/helpers/tiers.py, SPREAD_MODULES). In the order of the collection (system tests first:
# tiers.system_first), not xdist's default of the scopes with most tests first, which left the long single-test scopes
# (a colcon build, each spread property test) for the end.
PARALLEL = ["-n", str((os.cpu_count() or 1) + 2), "--dist", "loadfile", "--no-loadscope-reorder"]


@nox.session(python="3.11")
def tests(session: nox.Session) -> None:
    """Everything: ruff, mypy and the import layers, generated/ is current, sam_msgs builds, then unit, golden,
    conformance and end-to-end tests, on every core."""
    _install(session, "runtime,rosbuild,test")
    _static_checks(session)
    session.run("sam-codegen", "build", "--check")
    _ros_install(session)
    tools = _yakut(session)
    # The per-test times land in .nox/tests/junit.xml: `python tests/helpers/durations.py` tables them per folder.
    report = f"--junitxml={session.virtualenv.location}/junit.xml"
    session.run("pytest", *(session.posargs or ["-q", *PARALLEL, report]), env={**LOOPBACK, **tools})


@nox.session(python="3.11")
def unit(session: nox.Session) -> None:
    """The fast tier for the edit-test loop: the tests that start no process, build nothing with CMake and need no
    built ROS package (tests/helpers/tiers.py; one that starts a process fails here). `nox -s tests` is the gate."""
    _install(session, "runtime,test")
    session.run("pytest", *(session.posargs or ["-q", "-n", "auto"]), "--unit-tier", env=LOOPBACK)


@nox.session(python="3.11")
def lint(session: nox.Session) -> None:
    """The static checks alone: ruff, mypy, the import layers."""
    session.install("ruff>=0.6", "mypy>=1.11", "pytest>=8")
    _static_checks(session)


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
