"""Generated ROS packages built for tests, and child processes that can use them.

Each package is compiled once per *content*: into its own prefix ``.cache/ros-pkg/<name>-<key>``, where the key
hashes the package's files, the keys of the packages it depends on, the Python version and the build type.
Packages are combined by chaining prefixes in the environment (AMENT_PREFIX_PATH, CMAKE_PREFIX_PATH to build one on
another; PYTHONPATH, LD_LIBRARY_PATH, AMENT_PREFIX_PATH to use them: :func:`chained_env`), never rebuilt per
combination. A package already installed and current in the venv (``sam-codegen ros-install`` of the tests session
puts sam_msgs and tf2_msgs there) is used as it is. Concurrent workers wait for one build (a file lock per package).

Tests need no optimised code and no C++: the build type is CMake's empty one (no -O3), about half the compile time
of the users' Release builds (codegen/project/ros_install.py), and the C++ generators and type supports are left
out (python_only.cmake beside this file: sam_msgs 30.5 -> 18.2 CPU s). A package installed outside the venv is
usable only by a process started with its environment, so tests that need the built types run their checks in a
child: :func:`run_child`.
"""

from __future__ import annotations

import contextlib
import hashlib
import importlib.util
import os
import shutil
import subprocess
import sys
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
# Not .cache/ros-prefix (one prefix per combination, the layout before): a worktree may share that folder with
# checkouts that still use it.
CACHE = ROOT / ".cache" / "ros-pkg"
BUILD_TYPE = ""  # CMake's default: no optimisation flags
PYTHON_ONLY = Path(__file__).with_name("python_only.cmake")  # the C generators, type supports and Python only
# In a prefix made here: the prefixes (one a line, dependencies first) a process needs besides this one.
CHAIN_FILE = ".sam-test-chain"


def missing_tools() -> str | None:
    """Why the packages cannot be built or used here (None: they can)."""
    if shutil.which("cmake") is None:
        return "cmake is not installed"
    if importlib.util.find_spec("rclpy") is None:
        return "rclpy is not installed (pip extra 'runtime')"
    if not (Path(sys.prefix) / "share" / "rosidl_default_generators" / "package.xml").is_file():
        return "rosidl_default_generators is not installed in this environment (pip extra 'rosbuild')"
    return None


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


def current_in_venv(package_dir: Path) -> bool:
    """Whether the venv holds this package with exactly these interfaces (what ``ensure_ros_package`` accepts)."""
    from sam_codegen.project.ros_install import is_installed, package_dependencies
    from sam_runtime.genpkg import same_interfaces

    name, _ = package_dependencies(package_dir)
    venv = Path(sys.prefix).absolute()
    return is_installed(name, venv) and same_interfaces(package_dir, venv / "share" / name)


@dataclass(frozen=True)
class Planned:
    name: str
    folder: Path
    key: str  # its content, the build type, the Python version and its dependencies' keys
    needs: frozenset[str]  # the packages of the same list it depends on, transitively


def plan(package_dirs: Sequence[Path]) -> list[Planned]:
    """The packages in order with their keys: a package's key is the same in whatever list it is (its content and
    what it depends on decide it, not what else is built)."""
    from sam_codegen.project.ros_install import package_dependencies
    from sam_runtime.genpkg import ros_package_hash

    done: dict[str, Planned] = {}
    for d in (Path(p) for p in package_dirs):
        name, depends = package_dependencies(d)
        deps = [done[n] for n in done if n in depends]
        h = hashlib.sha256(f"{sys.version_info[:2]} {BUILD_TYPE!r} {ros_package_hash(d)}".encode())
        h.update(PYTHON_ONLY.read_bytes())
        for dep in deps:
            h.update(f" {dep.name}={dep.key}".encode())
        needs = frozenset(dep.name for dep in deps).union(*(dep.needs for dep in deps))
        done[name] = Planned(name, d, h.hexdigest()[:20], needs)
    return list(done.values())


def built_prefix(package_dirs: Sequence[Path]) -> Path:
    """Every package of `package_dirs` (a later one may depend on an earlier one) built and usable together.

    Returns a prefix for :func:`chained_env` (and so for ``run_child``, ``child_env`` of runtime_support and
    spec_build): the venv when all of them are current there; the last package's own prefix when it needs every
    other one built (its chain file names them); else a folder whose chain file names them all."""
    prefixes: dict[str, Path] = {}  # package name -> where it was built (absent: current in the venv)
    planned = plan(package_dirs)
    for p in planned:
        # The venv's copy was built on the venv's dependencies: usable only when none of them had to be built.
        if not (p.needs & prefixes.keys()) and current_in_venv(p.folder):
            continue
        prefixes[p.name] = _build_once(p, [prefixes[n] for n in prefixes if n in p.needs])
    built = [p.name for p in planned if p.name in prefixes]
    if not built:
        return Path(sys.prefix).absolute()
    if set(built[:-1]) <= planned[-1].needs and built[-1] == planned[-1].name:
        return prefixes[built[-1]]
    chain = [prefixes[n] for n in built]
    view = CACHE / "chains" / hashlib.sha256("\n".join(map(str, chain)).encode()).hexdigest()[:20]
    with locked(CACHE / "chains" / f".lock-{view.name}"):
        view.mkdir(parents=True, exist_ok=True)
        (view / CHAIN_FILE).write_text("".join(f"{p}\n" for p in chain))
    return view


def _build_once(p: Planned, chain: Sequence[Path]) -> Path:
    prefix = CACHE / f"{p.name}-{p.key}"
    with locked(CACHE / f".lock-{prefix.name}"):
        if not (prefix / ".complete").is_file():
            shutil.rmtree(prefix, ignore_errors=True)
            build_dir = CACHE / "build" / prefix.name
            shutil.rmtree(build_dir, ignore_errors=True)
            cmake_build(p.folder, build_dir, prefix, chain)
            (prefix / CHAIN_FILE).write_text("".join(f"{p}\n" for p in chain))
            (prefix / ".complete").write_text("built by tests/helpers/ros_packages.py\n")
            shutil.rmtree(build_dir, ignore_errors=True)  # objects only: the prefix is what is used
    return prefix


def cmake_build(package_dir: Path, build_dir: Path, prefix: Path, chain: Sequence[Path]) -> None:
    """Configure, build and install one package on the venv's ROS and the prefixes of `chain` (its built
    dependencies), as ``sam_codegen.project.ros_install.build_ros_package`` does but with the tests' build type;
    raises its RosBuildError with CMake's output."""
    from sam_codegen.project.ros_install import RosBuildError, cmake_generator

    cmake = shutil.which("cmake")
    if cmake is None:
        raise RosBuildError("cmake was not found on PATH")
    search = [*(str(p) for p in reversed(chain)), sys.prefix]
    env = dict(os.environ)
    env["AMENT_PREFIX_PATH"] = os.pathsep.join([*search, *filter(None, [env.get("AMENT_PREFIX_PATH")])])
    env["CMAKE_PREFIX_PATH"] = os.pathsep.join([*search, *filter(None, [env.get("CMAKE_PREFIX_PATH")])])
    env["PATH"] = os.pathsep.join([str(Path(sys.executable).parent), env.get("PATH", "")])
    env.pop("COLCON_PREFIX_PATH", None)
    build_dir.mkdir(parents=True, exist_ok=True)
    steps = {
        "configure": [cmake, *cmake_generator(build_dir, env), "-S", str(package_dir.absolute()),
                      "-B", str(build_dir),
                      f"-DCMAKE_PREFIX_PATH={';'.join(search)}", f"-DCMAKE_INSTALL_PREFIX={prefix}",
                      f"-DPython3_EXECUTABLE={sys.executable}", f"-DCMAKE_BUILD_TYPE={BUILD_TYPE}",
                      "-DBUILD_TESTING=OFF", f"-DCMAKE_PROJECT_INCLUDE={PYTHON_ONLY}"],
        "build": [cmake, "--build", str(build_dir), "-j", str(os.cpu_count() or 2)],
        "install": [cmake, "--install", str(build_dir)],
    }
    for what, cmd in steps.items():
        proc = subprocess.run(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                              errors="replace", timeout=1800, check=False)
        if proc.returncode != 0:
            raise RosBuildError(f"CMake {what} of {package_dir.name} failed (exit code {proc.returncode})",
                                proc.stdout)


def _read_chain(prefix: Path) -> list[Path]:
    try:
        return [Path(line) for line in (Path(prefix) / CHAIN_FILE).read_text().splitlines() if line]
    except OSError:
        return []


def chained_env(prefix: Path, base: Mapping[str, str] | None = None) -> dict[str, str]:
    """The environment of a process that uses the packages of `prefix` (a :func:`built_prefix` result, or any
    install prefix): the prefixes its chain names, then itself, first on the paths (the last one wins a lookup)."""
    from sam_codegen.project.ros_install import ros_runtime_env

    prefix = Path(prefix).absolute()
    env = dict(os.environ if base is None else base)
    if prefix == Path(sys.prefix).absolute():
        return env
    for p in [*_read_chain(prefix), prefix]:
        env = ros_runtime_env(p, env)
    return env


def child_env(prefix: Path, domain: str, extra: Mapping[str, str] | None = None) -> dict[str, str]:
    env = chained_env(prefix)
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
