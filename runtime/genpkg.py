"""Locate and load the generated package a spec produced (``generated/`` by default).

Layout (written by ``sam-codegen build``)::

    <generated>/dsdl/<root namespace>/...       Cyphal DSDL of the vehicle's own types
    <generated>/ros/<ros package>/              the ament package of the custom ROS messages
    <generated>/ros/<external package>/         one per package of the external_messages and known ones (tf2_msgs)
    <generated>/python/<vehicle>_bridge/        tables.py (stdlib only) and convert.py (converters)

Nothing here is SAM-specific: the Python package is found by scanning ``<generated>/python`` for a
``*_bridge`` package holding ``tables.py``. Import order matters and is enforced here:
:meth:`GeneratedPackage.tables` imports nothing but the standard library; :meth:`GeneratedPackage.convert`
first compiles the DSDL (once per process, before ``uavcan``/``pycyphal.application`` are imported) and
needs the ROS message package importable.
"""

from __future__ import annotations

import hashlib
import importlib
import importlib.util
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from types import ModuleType
from typing import Any, cast

from sam_codegen.contracts.tables_api import TablesModule
from sam_codegen.model.protocols.registry import protocol as protocol_of
from sam_codegen.project.ros_install import (
    RosBuildError,
    build_ros_package,
    is_current,
    ros_build_lock,
    ros_package_hash,
    ros_packages_in_order,
    same_interfaces,
    stamp_install,
)
from sam_codegen.project.workspace import GENERATED_ENV_VAR, WorkspaceError, find_generated, user_cache_dir
from sam_runtime.cyphal_io.dsdl_cache import ensure_compiled

__all__ = [
    "GENERATED_ENV_VAR",
    "GeneratedPackage",
    "GeneratedPackageError",
    "bound_codec",
    "default_generated_dir",
    "ensure_ros_package",
    "ros_package_hash",
    "same_interfaces",
]

class GeneratedPackageError(Exception):
    """The generated package is missing or incomplete; ``str()`` says what to run."""


def default_generated_dir() -> Path:
    """``$SAM_GENERATED_DIR``, else the generated folder of the project the working directory is in (the folder
    itself when the working directory is inside it; see sam_codegen.project.workspace)."""
    try:
        return find_generated()
    except WorkspaceError as ex:
        raise GeneratedPackageError(str(ex)) from None


def _find_python_package(python_dir: Path, name: str | None) -> str:
    if name:
        if not (python_dir / name / "tables.py").is_file():
            raise GeneratedPackageError(f"{python_dir / name}/tables.py does not exist")
        return name
    found = sorted(
        p.name for p in python_dir.glob("*_bridge") if p.is_dir() and (p / "tables.py").is_file()
    ) if python_dir.is_dir() else []
    if not found:
        raise GeneratedPackageError(
            f"no generated bridge package (<vehicle>_bridge/tables.py) under {python_dir}; "
            "run `sam-codegen build` first"
        )
    if len(found) > 1:
        raise GeneratedPackageError(
            f"several generated bridge packages under {python_dir}: {', '.join(found)}; pick one explicitly"
        )
    return found[0]


@dataclass
class GeneratedPackage:
    """One generated package; modules are imported lazily and cached."""
    root: Path = field(default_factory=default_generated_dir)
    package: str | None = None  # python package name, e.g. "sam_bridge"; default: the only *_bridge found

    def __post_init__(self) -> None:
        self.root = Path(self.root).expanduser().resolve()
        self.package = _find_python_package(self.python_dir, self.package)
        self._tables: TablesModule | None = None
        self._convert: ModuleType | None = None
        self._convert_v0: ModuleType | None = None
        self._codecs: dict[tuple[str, str], ModuleType | None] = {}  # (module, frame prefix) -> module

    # -------------------------------------------------------------------- locations
    @property
    def python_dir(self) -> Path:
        return self.root / "python"

    @property
    def dsdl_dirs(self) -> list[Path]:
        """The root namespace directories under ``<generated>/dsdl`` (usually one)."""
        base = self.root / "dsdl"
        if not base.is_dir():
            return []
        return sorted(p for p in base.iterdir() if p.is_dir() and any(p.rglob("*.dsdl")))

    def ros_package_dir(self) -> Path:
        return self.root / "ros" / self.tables().ROS_PACKAGE

    # -------------------------------------------------------------------- modules
    def _import(self, sub: str) -> ModuleType:
        path = str(self.python_dir)
        if path not in sys.path:
            sys.path.insert(0, path)
            importlib.invalidate_caches()
        name = f"{self.package}.{sub}"
        mod = importlib.import_module(name)
        origin = Path(getattr(mod, "__file__", "") or "").resolve()
        if self.python_dir not in origin.parents:
            raise GeneratedPackageError(
                f"{name} was imported from {origin}, not from {self.python_dir}: another copy shadows it"
            )
        return mod

    def tables(self) -> TablesModule:
        """``<pkg>.tables`` (standard library only: safe to import anywhere, anytime)."""
        if self._tables is None:
            module = self._import("tables")
            # The runtime reads every member the contract names, without fallbacks: tables of an older build are
            # rebuilt, not half-read.
            missing = [name for name in TablesModule.__annotations__ if not hasattr(module, name)]
            if missing:
                raise GeneratedPackageError(f"{module.__file__} lacks {', '.join(missing)}: it was built by an older "
                                            f"sam-codegen; run `sam-codegen build`")
            self._tables = cast("TablesModule", module)
        return self._tables

    def compile_dsdl(self) -> Path:
        """Compile the generated DSDL + ``uavcan`` (cached) and put it on sys.path. Call before importing
        ``uavcan`` or ``pycyphal.application`` anywhere in the process."""

        dirs = self.dsdl_dirs
        if not dirs:
            raise GeneratedPackageError(f"no DSDL under {self.root / 'dsdl'}; run `sam-codegen build` first")
        return ensure_compiled(dirs)

    def convert(self) -> ModuleType:
        """``<pkg>.convert``: compiles the DSDL first; the ROS message package must be importable."""
        if self._convert is None:
            self.compile_dsdl()
            try:
                self._convert = self._import("convert")
            except ModuleNotFoundError as ex:
                ros_pkg = self.tables().ROS_PACKAGE
                if ex.name and ex.name.split(".")[0] == ros_pkg:
                    raise GeneratedPackageError(
                        f"the ROS message package {ros_pkg!r} is not importable: build it "
                        f"(sam_runtime.genpkg.ensure_ros_package) and use its environment"
                    ) from ex
                raise
        return self._convert

    def convert_v0(self) -> ModuleType:
        """``<pkg>.convert_v0`` (the DroneCAN converters), with the spec's own v0 types added to dronecan
        (sam_runtime.dronecan_io.types: beside the loaded ones, never reloading them) and every type checked against
        the generated converters (data type id and signature)."""
        if self._convert_v0 is None:
            try:
                mod = self._import("convert_v0")
            except ModuleNotFoundError as ex:
                if ex.name and ex.name.split(".")[-1] == "convert_v0":
                    raise GeneratedPackageError(f"{self.root} has no DroneCAN converters (the spec declares no "
                                                f"dronecan mappings)") from None
                raise
            from sam_runtime.dronecan_io.types import ensure_types  # needs dronecan (the runtime extra)

            try:  # beside the types loaded already (dronecan.load_dsdl would replace them all: see that module)
                ensure_types(self)
                problems = mod.check_types()
            except Exception as ex:  # a broken or stale dsdl_v0 folder, or another dronecan version
                problems = [f"{type(ex).__name__}: {ex}"]
            if problems:
                raise GeneratedPackageError(f"the DroneCAN types of {self.root}: {'; '.join(problems)}")
            self._convert_v0 = mod
        return self._convert_v0

    def services(self) -> ModuleType | None:
        """``<pkg>.services`` (the bridge's service mappings as data, standard library only); None when the spec
        has none."""
        try:
            return self._import("services")
        except ModuleNotFoundError as ex:
            if ex.name and ex.name.split(".")[-1] == "services":
                return None
            raise

    def codec(self, protocol: str = "cyphal", frame_prefix: str = "") -> ModuleType | None:
        """The generated wire codecs of ``protocol``: ``<pkg>.codec`` (Cyphal) or ``<pkg>.codec_v0`` (DroneCAN),
        standard library only, writing ``frame_prefix`` before every frame id (see :func:`bound_codec`); None
        when the package has none, or none that takes a frame prefix (built by an older sam-codegen)."""
        sub = protocol_of(protocol).codec_package
        if (sub, "") not in self._codecs:
            try:
                self._codecs[sub, ""] = self._import(sub)
            except ModuleNotFoundError as ex:
                if not ex.name or ex.name.split(".")[-1] != sub:
                    raise
                self._codecs[sub, ""] = None
        if (sub, frame_prefix) not in self._codecs:
            module = self._codecs[sub, ""]
            self._codecs[sub, frame_prefix] = None if module is None else bound_codec(module, frame_prefix)
        return self._codecs[sub, frame_prefix]

    # -------------------------------------------------------------------- types
    @staticmethod
    def dsdl_class(port: Any) -> type:
        """The compiled pycyphal class of a PortInfo (``port.dsdl_module``/``port.dsdl_class``)."""
        return getattr(importlib.import_module(port.dsdl_module), port.dsdl_class)

    @staticmethod
    def ros_class(topic: Any) -> type:
        """The ROS message class of a TopicInfo (``topic.ros_module``/``topic.ros_class``)."""
        return getattr(importlib.import_module(topic.ros_module), topic.ros_class)


def bound_codec(module: ModuleType, frame_prefix: str) -> ModuleType | None:
    """A generated codec module that writes ``frame_prefix`` before every frame id: `module` itself for none, else a
    copy of it (its own module object, not in sys.modules) bound to the prefix. The codecs read the constants that
    depend on the prefix (the frame ids' CDR strings, the structs whose padding follows them) as module globals,
    which ``bind`` sets once: per message this costs nothing, and runs with other prefixes in the same process (two
    vehicles) each have their copy. None when `module` predates ``bind`` (an older generated package)."""
    if not frame_prefix:
        return module
    spec = module.__spec__
    if not callable(getattr(module, "bind", None)) or spec is None or spec.loader is None:
        return None
    copy = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(copy)
    copy.bind(frame_prefix)
    return copy


def ensure_ros_package(gen: GeneratedPackage, prefix: Path | None = None, *, log: Any = None,
                       build_root: Path | None = None, wait_timeout: float | None = None,
                       cancelled: Callable[[], bool] | None = None) -> Path:
    """Build and install every ROS package under ``<generated>/ros`` (the spec's own and any other it generates, in
    dependency order) into ``prefix`` (default: ``sys.prefix``, the venv), each unless an install of the same sources
    is already there or in the venv. Returns the prefix.

    The build folders are ``<build_root>/<package>-<hash>`` (default build_root: ``ros-build`` in the user's cache
    directory); an install is stamped with its sources' hash, so a changed spec triggers a rebuild and an unchanged
    one costs a few ms. A build holds the build root's lock (sam_codegen.project.ros_install.ros_build_lock) from
    its check to its install: a second process meanwhile waits (``log`` gets its waiting lines; ``wait_timeout``
    and ``cancelled``: see sam_codegen.project.lock.ProjectLock, whose LockError it raises), then finds the packages
    current and reuses them.
    """

    prefix = Path(prefix if prefix is not None else sys.prefix).absolute()
    own = gen.ros_package_dir()
    if not (own / "package.xml").is_file():
        raise GeneratedPackageError(f"{own} has no package.xml; run `sam-codegen build` first")
    try:
        packages = ros_packages_in_order(own.parent)
    except RosBuildError as ex:
        raise GeneratedPackageError(str(ex)) from None
    venv = Path(sys.prefix).absolute()

    def current(pkg_dir: Path, digest: str | None = None) -> bool:
        # A package current in the venv serves a run with another prefix too: the children's environment has the
        # venv behind the prefix (sam_codegen.project.ros_install.ros_runtime_env), so it is not built again there.
        return is_current(pkg_dir, prefix, digest) or (prefix != venv and is_current(pkg_dir, venv, digest))

    stale = [p for p in packages if not current(p)]
    if not stale:  # the usual case, without touching the lock
        return prefix
    root = Path(build_root) if build_root is not None else user_cache_dir() / "ros-build"
    with ros_build_lock(root, say=log, timeout=wait_timeout, cancelled=cancelled) as lock:
        for pkg_dir in packages:  # again, under the lock: another process may have installed them meanwhile
            name = pkg_dir.name
            digest = ros_package_hash(pkg_dir)
            if current(pkg_dir, digest):
                if pkg_dir in stale and log is not None:
                    holder = f" by pid {lock.held_by.pid}" if lock.held_by is not None else ""
                    log(f"ROS package {name} was installed into {prefix} meanwhile{holder}: reused")
                continue
            if log is not None:
                log(f"building ROS package {name} into {prefix} (about 30 s)...")
            lock.status(f"building ROS package {name} into {prefix}")
            # The source folder is part of the name: a CMake build folder belongs to one source folder.
            where = hashlib.sha256(str(pkg_dir.resolve()).encode()).hexdigest()[:8]

            def progress(step: str, name: str = name, started: float = time.monotonic()) -> None:
                lock.status(f"building ROS package {name}: {step} ({time.monotonic() - started:.1f} s)")

            build_ros_package(pkg_dir, root / f"{name}-{digest}-{where}", prefix, progress=progress)
            stamp_install(pkg_dir, prefix, digest)
    return prefix
