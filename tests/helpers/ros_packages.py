"""Generated ROS packages built for tests, and child processes that can use them.

``built_prefix(dirs)`` installs the packages (in the given order, e.g. tf2_msgs then sam_msgs) into one prefix
cached by their content under ``.cache/ros-prefix/`` (built once, ~30-60 s per package; concurrent runs wait for
one build). A package installed outside the venv is usable only by a process started with its LD_LIBRARY_PATH
(``ros_runtime_env``), so tests that need the built types run their checks in a child: ``run_child``.
"""

from __future__ import annotations

import contextlib
import hashlib
import importlib.util
import shutil
import subprocess
import sys
from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
CACHE = ROOT / ".cache" / "ros-prefix"


def missing_tools() -> str | None:
    """Why the packages cannot be built or used here (None: they can)."""
    if shutil.which("cmake") is None:
        return "cmake is not installed"
    if importlib.util.find_spec("rclpy") is None:
        return "rclpy is not installed (pip extra 'runtime')"
    if not (Path(sys.prefix) / "share" / "rosidl_default_generators" / "package.xml").is_file():
        return "rosidl_default_generators is not installed in this environment (pip extra 'rosbuild')"
    return None


def _tree_hash(folders: Sequence[Path]) -> str:
    h = hashlib.sha256(f"{sys.version_info[:2]}".encode())
    for folder in folders:
        h.update(folder.name.encode() + b"\0")
        for p in sorted(folder.rglob("*")):
            if p.is_file():
                h.update(p.relative_to(folder).as_posix().encode() + b"\0" + p.read_bytes() + b"\0")
    return h.hexdigest()[:20]


@contextlib.contextmanager
def locked(path: Path) -> Iterator[None]:
    """Held by one process at a time (concurrent test runs wait for one build)."""
    import fcntl

    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "a+b") as fh:
        fcntl.flock(fh.fileno(), fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(fh.fileno(), fcntl.LOCK_UN)


def built_prefix(package_dirs: Sequence[Path]) -> Path:
    """One prefix with every package of `package_dirs` installed, in order (a later one may use an earlier)."""
    from sam_codegen.project.ros_install import build_ros_package

    dirs = [Path(d) for d in package_dirs]
    prefix = CACHE / f"{'+'.join(d.name for d in dirs)}-{_tree_hash(dirs)}"
    with locked(CACHE / f".lock-{prefix.name}"):
        if not (prefix / ".complete").is_file():
            shutil.rmtree(prefix, ignore_errors=True)
            for d in dirs:
                build_ros_package(d, CACHE / "build" / f"{prefix.name}-{d.name}", prefix)
            (prefix / ".complete").write_text("built by tests/helpers/ros_packages.py\n")
    return prefix


def child_env(prefix: Path, domain: str, extra: Mapping[str, str] | None = None) -> dict[str, str]:
    from sam_codegen.project.ros_install import ros_runtime_env

    env = ros_runtime_env(prefix)
    env["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    env["ROS_DOMAIN_ID"] = domain
    env["PYTHONUNBUFFERED"] = "1"
    env.pop("PYTEST_ADDOPTS", None)
    env.update(extra or {})
    return env


def run_child(args: Sequence[str], prefix: Path, domain: str, extra: Mapping[str, str] | None = None,
              timeout: float = 600.0) -> subprocess.CompletedProcess[str]:
    """Run `python <args>` with the prefix's packages usable; returns the finished process (output captured)."""
    return subprocess.run([sys.executable, *args], cwd=ROOT, env=child_env(prefix, domain, extra),
                          capture_output=True, text=True, timeout=timeout, check=False)
