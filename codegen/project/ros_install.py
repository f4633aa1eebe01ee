"""Build and install a generated ROS 2 interface package with plain CMake.

The ROS 2 Jazzy pip wheels install an ament prefix inside the virtual environment; there is no
colcon workspace or ``setup.bash`` here, so the handful of variables a sourced workspace would set
are passed explicitly (see shared/notes/ros2-jazzy-wheels.md).
"""

from __future__ import annotations

import hashlib
import os
import re
import shutil
import subprocess
import sys
import time
import xml.etree.ElementTree as ET
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

from sam_codegen.project.lock import ProjectLock, lock_path
from sam_codegen.project.progress import TerminalProgress

__all__ = [
    "HASH_STAMP",
    "RosBuildError",
    "build_ros_package",
    "build_ros_packages",
    "is_current",
    "is_installed",
    "package_dependencies",
    "ros_build_lock",
    "ros_package_hash",
    "ros_packages_in_order",
    "ros_runtime_env",
    "same_interfaces",
    "stamp_install",
]

# Written beside an installed package.xml: the hash of the sources it was built from (ros_package_hash).
HASH_STAMP = ".sam_codegen_source_hash"

# Lines of CMake output kept in an error: enough to include rosidl's message and CMake's call stack.
_TAIL_LINES = 40
# A clean build takes ~10 s on two cores; this only guards against a hung compiler or generator.
_STEP_TIMEOUT_S = 1800.0


# Lines that name the actual problem: CMake's own errors, rosidl_adapter's, the compiler's.
_ERROR_LINE = re.compile(r"CMake Error|Error processing|\berror:|\bError:")


class RosBuildError(Exception):
    """A CMake step failed; the message ends with the tail of that step's output."""

    def __init__(self, message: str, output: str = "", package: str | None = None) -> None:
        self.output = output
        self.package = package  # the package whose build failed, when several were built
        lines = output.splitlines()
        self.tail = "\n".join(lines[-_TAIL_LINES:])
        # A long Python traceback from a generator can push the real cause out of the tail,
        # so the first few errors are repeated up front.
        parts = [message, *_error_summaries(lines)]
        if self.tail:
            parts += ["--- last lines of output ---", self.tail]
        super().__init__("\n".join(parts))


def _error_summaries(lines: Sequence[str], limit: int = 3) -> list[str]:
    """The first ``limit`` error paragraphs, each on one line.

    CMake wraps a message over several indented lines up to a blank one; the first line alone
    ("CMake Error in CMakeLists.txt:") names no cause.
    """
    found: list[str] = []
    for i, line in enumerate(lines):
        if len(found) == limit:
            break
        if not _ERROR_LINE.search(line):
            continue
        paragraph = [line.strip()]
        for follow in lines[i + 1 : i + 6]:
            if not follow.strip() or _ERROR_LINE.search(follow):
                break
            paragraph.append(follow.strip())
        found.append(" ".join(paragraph))
    return found


def _join_paths(*parts: str | None, sep: str = os.pathsep) -> str:
    """Join path lists, dropping empty entries and later duplicates (earlier entries win lookups)."""
    seen: list[str] = []
    for part in parts:
        for entry in (part or "").split(sep):
            if entry and entry not in seen:
                seen.append(entry)
    return sep.join(seen)


def _python_prefix(python: Path) -> Path:
    """sys.prefix of another interpreter.

    Asked rather than derived from the path: a venv's bin/python is a symlink to the base
    interpreter, so resolving it would point outside the venv that holds the ROS wheels.
    """
    try:
        proc = subprocess.run(
            [str(python), "-c", "import sys; print(sys.prefix)"],
            capture_output=True,
            text=True,
            timeout=60,
            check=False,
        )
    except (OSError, subprocess.TimeoutExpired) as exc:
        raise RosBuildError(f"cannot run Python interpreter {python}: {exc}") from None
    if proc.returncode != 0 or not proc.stdout.strip():
        raise RosBuildError(f"cannot query sys.prefix of {python}", proc.stdout + proc.stderr)
    return Path(proc.stdout.strip().splitlines()[-1])


def _run_step(what: str, cmd: Sequence[str], env: Mapping[str, str]) -> None:
    try:
        proc = subprocess.run(
            list(cmd),
            env=dict(env),
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,  # interleaved, so the tail shows errors next to their context
            text=True,
            errors="replace",
            timeout=_STEP_TIMEOUT_S,
            check=False,
        )
    except subprocess.TimeoutExpired as exc:
        out = exc.output.decode(errors="replace") if isinstance(exc.output, bytes) else exc.output or ""
        raise RosBuildError(f"CMake {what} timed out after {_STEP_TIMEOUT_S:.0f} s", out) from None
    except OSError as exc:
        raise RosBuildError(f"cannot run CMake {what}: {exc}") from None
    if proc.returncode != 0:
        raise RosBuildError(f"CMake {what} failed (exit code {proc.returncode})", proc.stdout)


def build_ros_package(
    package_dir: Path,
    build_dir: Path,
    install_prefix: Path,
    *,
    python: Path | None = None,
    jobs: int = 2,
    progress: Callable[[str], None] | None = None,
) -> None:
    """Configure, build and install the ament package in ``package_dir`` into ``install_prefix``.

    ``python`` is the interpreter whose environment holds the ROS wheels (default: the running one);
    its prefix is the ROS prefix CMake searches. ``progress`` is told each step ("configure", "build",
    "install") as it starts. Raises RosBuildError on any failure.
    """
    def step(what: str, cmd: Sequence[str], env: Mapping[str, str]) -> None:
        if progress is not None:
            progress(what)
        # a build step runs 5-40 s without a word: a line with the elapsed time on a terminal (issue 30)
        with TerminalProgress(f"ROS package {Path(package_dir).name}: CMake {what}"):
            _run_step(what, cmd, env)

    cmake = shutil.which("cmake")
    if cmake is None:
        raise RosBuildError("cmake was not found on PATH; install CMake (>= 3.8) to build ROS packages")

    package_dir = Path(package_dir).absolute()
    build_dir = Path(build_dir).absolute()
    install_prefix = Path(install_prefix).absolute()
    if not (package_dir / "CMakeLists.txt").is_file():
        raise RosBuildError(f"{package_dir} has no CMakeLists.txt")

    if python is None:
        # Not sys.executable's resolved path: keep the venv's own bin/python so it finds the wheels.
        interpreter = Path(sys.executable)
        ros_prefix = Path(sys.prefix)
    else:
        interpreter = Path(python).absolute()
        ros_prefix = _python_prefix(interpreter)

    env = dict(os.environ)
    # Without the ROS prefix in AMENT_PREFIX_PATH rosidl finds no type support ("No
    # 'rosidl_typesupport_c' found"); install_prefix lets one generated package use another.
    env["AMENT_PREFIX_PATH"] = _join_paths(str(install_prefix), str(ros_prefix), env.get("AMENT_PREFIX_PATH"))
    env["CMAKE_PREFIX_PATH"] = _join_paths(str(install_prefix), str(ros_prefix), env.get("CMAKE_PREFIX_PATH"))
    # Whatever ament runs by name (its tools, python3) must come from the ROS environment, not the system.
    env["PATH"] = _join_paths(str(interpreter.parent), env.get("PATH"))
    # A stale setting from the caller's shell would override the prefix variables above.
    env.pop("COLCON_PREFIX_PATH", None)

    _forget_build_of_other_source(build_dir, package_dir)
    generator = cmake_generator(build_dir, env)
    build_dir.mkdir(parents=True, exist_ok=True)
    cmake_prefix_path = ";".join(env["CMAKE_PREFIX_PATH"].split(os.pathsep))
    base = [
        cmake,
        *generator,
        "-S",
        str(package_dir),
        "-B",
        str(build_dir),
        f"-DCMAKE_PREFIX_PATH={cmake_prefix_path}",
        f"-DCMAKE_INSTALL_PREFIX={install_prefix}",
        f"-DPython3_EXECUTABLE={interpreter}",
        "-DCMAKE_BUILD_TYPE=Release",
        # The generated package has no tests; skipping ament's lint/test hooks saves configure time.
        "-DBUILD_TESTING=OFF",
    ]
    step("configure", [*base, f"-D{UNITY_OPTION}=ON"], env)
    build = [cmake, "--build", str(build_dir), "-j", str(max(1, jobs))]
    try:
        step("build", build, env)
    except RosBuildError:
        # The generated CMakeLists.txt compiles the type supports as unity files (see there); one that a future
        # rosidl cannot compile must not cost the user the package: file by file.
        step("configure without unity files", [*base, f"-D{UNITY_OPTION}=OFF"], env)
        step("build", build, env)
    step("install", [cmake, "--install", str(build_dir)], env)


def cmake_generator(build_dir: Path, env: Mapping[str, str]) -> list[str]:
    """CMake's ``-G`` for a new build folder: Ninja where it is installed (rosidl's generators and the type
    supports cost ~20 % less CPU than under Makefiles: one process schedules the whole graph, no recursive make
    re-reading dependency files); none for a folder CMake already configured (it keeps its generator, and refuses
    another) or when the caller chose one (CMAKE_GENERATOR)."""
    if env.get("CMAKE_GENERATOR") or (Path(build_dir) / "CMakeCache.txt").is_file():
        return []
    ninja = shutil.which("ninja", path=env.get("PATH"))
    return ["-G", "Ninja", f"-DCMAKE_MAKE_PROGRAM={ninja}"] if ninja else []


# The generated CMakeLists.txt's option (templates/ros/CMakeLists.txt.j2) that compiles in unity batches.
UNITY_OPTION = "SAM_CODEGEN_UNITY_BUILD"


def _forget_build_of_other_source(build_dir: Path, package_dir: Path) -> None:
    """Empty a build folder that CMake configured for another source folder (a moved or copied project): CMake
    refuses to reuse it ("CMakeCache.txt directory ... is different")."""
    cache = build_dir / "CMakeCache.txt"
    try:
        text = cache.read_text(errors="replace")
    except OSError:
        return
    match = re.search(r"^CMAKE_HOME_DIRECTORY:INTERNAL=(.*)$", text, re.MULTILINE)
    if match is None or Path(match.group(1)).resolve() != package_dir.resolve():
        shutil.rmtree(build_dir, ignore_errors=True)


# The package.xml tags that order a build: what is needed to build, or to use, a package (tests and docs are not).
_ORDERING_TAGS = ("depend", "build_depend", "buildtool_depend", "build_export_depend", "exec_depend")


def package_dependencies(package_dir: Path) -> tuple[str, set[str]]:
    """(name, the names it depends on) from a package.xml; raises RosBuildError when it is unreadable."""
    manifest = Path(package_dir) / "package.xml"
    try:
        root = ET.parse(manifest).getroot()
    except (OSError, ET.ParseError) as exc:
        raise RosBuildError(f"cannot read {manifest}: {exc}") from None
    name = (root.findtext("name") or "").strip()
    if not name:
        raise RosBuildError(f"{manifest} has no <name>")
    deps = {(e.text or "").strip() for tag in _ORDERING_TAGS for e in root.iter(tag)}
    return name, deps - {"", name}


def has_interfaces(package_dir: Path) -> bool:
    """Whether a package folder defines any interface (msg, srv or action file): rosidl refuses to build a package
    without one, and a spec whose ROS side uses upstream messages only generates its own package empty."""
    return any(any((Path(package_dir) / kind).glob(f"*.{kind}")) for kind in ("msg", "srv", "action"))


def ros_packages_in_order(ros_dir: Path) -> list[Path]:
    """The package folders under ``ros_dir`` (each holding a package.xml and at least one interface: an empty one has
    nothing to build), every package after the ones of the same folder it depends on; otherwise by name. Raises
    RosBuildError on a dependency cycle or a repeated name."""
    ros_dir = Path(ros_dir)
    if not ros_dir.is_dir():
        return []
    folders: dict[str, Path] = {}
    needs: dict[str, set[str]] = {}
    for folder in sorted(p for p in ros_dir.iterdir() if (p / "package.xml").is_file() and has_interfaces(p)):
        name, deps = package_dependencies(folder)
        if name in folders:
            raise RosBuildError(f"two packages named {name} under {ros_dir}: {folders[name].name}, {folder.name}")
        folders[name], needs[name] = folder, deps
    local = {name: deps & folders.keys() for name, deps in needs.items()}
    ordered: list[str] = []
    while len(ordered) < len(local):
        ready = sorted(n for n, deps in local.items() if n not in ordered and deps <= set(ordered))
        if not ready:
            cycle = sorted(set(local) - set(ordered))
            raise RosBuildError(f"the ROS packages under {ros_dir} depend on each other in a cycle: {', '.join(cycle)}")
        ordered.extend(ready)
    return [folders[n] for n in ordered]


def build_ros_packages(
    package_dirs: Sequence[Path],
    build_root: Path,
    install_prefix: Path,
    *,
    python: Path | None = None,
    jobs: int = 2,
    log: Callable[[str], None] | None = None,
    clock: Callable[[], float] = time.monotonic,
) -> None:
    """Build and install several packages in the given order (see :func:`ros_packages_in_order`), each in its own
    folder ``build_root/<name>``; a later one finds the earlier ones in ``install_prefix``. A failure stops there and
    names the package (``RosBuildError.package``).

    ``log`` gets one line per step of each package and one when it is installed, numbered and with the time since
    the package began (a build takes 10-40 s: silence that long reads as a hang)::

        [1/1] sam_msgs: configure (0.0 s)
        [1/1] sam_msgs: build (4.1 s)
        [1/1] sam_msgs: install (21.7 s)
        [1/1] sam_msgs: installed in 22.0 s
    """
    total = len(package_dirs)
    for index, package_dir in enumerate(package_dirs, 1):
        name = Path(package_dir).name
        started = clock()

        def progress(what: str, name: str = name, index: int = index, started: float = started) -> None:
            if log is not None:
                log(f"[{index}/{total}] {name}: {what} ({clock() - started:.1f} s)")

        try:
            build_ros_package(package_dir, Path(build_root) / name, install_prefix, python=python, jobs=jobs,
                              progress=progress)
        except RosBuildError as exc:
            exc.package = name
            raise
        stamp_install(package_dir, install_prefix)
        if log is not None:
            log(f"[{index}/{total}] {name}: installed in {clock() - started:.1f} s")


def ros_runtime_env(install_prefix: Path, base: Mapping[str, str] | None = None) -> dict[str, str]:
    """Environment in which a subprocess can import and use a package installed in ``install_prefix``.

    Only needed when ``install_prefix`` is not the venv itself. The new entries come first so a
    freshly built package shadows an older copy elsewhere on the paths.
    """
    env = dict(os.environ if base is None else base)
    prefix = Path(install_prefix).absolute()
    py_version = f"python{sys.version_info.major}.{sys.version_info.minor}"
    site_packages = prefix / "lib" / py_version / "site-packages"
    env["PYTHONPATH"] = _join_paths(str(site_packages), env.get("PYTHONPATH"))
    # The type-support libraries are dlopen()ed by name; the loader reads this only at process start.
    env["LD_LIBRARY_PATH"] = _join_paths(str(prefix / "lib"), env.get("LD_LIBRARY_PATH"))
    # The venv prefix stays behind the overlay: when AMENT_PREFIX_PATH names only the overlay,
    # ament_index no longer finds the wheels' packages (std_msgs, rclpy's resources).
    env["AMENT_PREFIX_PATH"] = _join_paths(str(prefix), env.get("AMENT_PREFIX_PATH"), sys.prefix)
    # Fast DDS otherwise sends discovery multicast off the machine, which is not allowed here.
    env.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
    return env


def is_installed(package: str, prefix: Path) -> bool:
    """Whether an ament package is installed in ``prefix`` (its package.xml is where ament puts it)."""
    return (Path(prefix) / "share" / package / "package.xml").is_file()


def ros_package_hash(package_dir: Path) -> str:
    """Hash of every file of a ROS package source tree (to tell whether an install is current)."""
    h = hashlib.sha256()
    for p in sorted(Path(package_dir).rglob("*")):
        if p.is_file():
            h.update(p.relative_to(package_dir).as_posix().encode() + b"\0" + p.read_bytes() + b"\0")
    return h.hexdigest()[:24]


def same_interfaces(src: Path, installed: Path) -> bool:
    """Whether an install (e.g. by an older ``sam-codegen ros-install``) holds exactly the source's interface
    files."""
    def files(root: Path) -> dict[str, bytes]:
        return {p.relative_to(root).as_posix(): p.read_bytes()
                for sub in ("msg", "srv") for p in sorted((root / sub).glob("*.*")) if p.suffix in (".msg", ".srv")}

    try:
        mine = files(src)
        return bool(mine) and mine == files(installed)
    except OSError:
        return False


def is_current(package_dir: Path, prefix: Path, digest: str | None = None) -> bool:
    """Whether the package in ``package_dir`` is installed in ``prefix`` from these very sources: its stamp holds
    their hash (``digest``, computed when not given), or the install has exactly its interface files."""
    name = Path(package_dir).name
    if not is_installed(name, prefix):
        return False
    share = Path(prefix) / "share" / name
    try:
        stamped = (share / HASH_STAMP).read_text().strip()
    except OSError:
        stamped = ""
    return stamped == (digest or ros_package_hash(package_dir)) or same_interfaces(package_dir, share)


def ros_build_lock(build_root: Path, *, say: Callable[[str], None] | None = None, timeout: float | None = None,
                   cancelled: Callable[[], bool] | None = None) -> ProjectLock:
    """The lock of a ROS build folder (``build_root``, the parent of the packages' CMake folders) and of what is
    built in it into an install prefix: held across the is-it-current check, the CMake steps and the install, so
    that a second build meanwhile waits and then finds the packages current (see sam_codegen.project.lock)."""
    build_root = Path(build_root).absolute()
    return ProjectLock(lock_path("ros-build", build_root), f"the ROS build folder {build_root}", say=say,
                       timeout=timeout, cancelled=cancelled)


def stamp_install(package_dir: Path, prefix: Path, digest: str | None = None) -> None:
    """Record beside the installed package.xml the hash of the sources just installed (see is_current)."""
    stamp = Path(prefix) / "share" / Path(package_dir).name / HASH_STAMP
    stamp.parent.mkdir(parents=True, exist_ok=True)
    stamp.write_text((digest or ros_package_hash(package_dir)) + "\n")
