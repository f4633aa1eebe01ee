"""A test spec's generated package and its ROS messages, for runtime tests on specs other than SAM's.

:func:`built_spec` generates ``generated/`` for a spec into a folder cached by the spec's content
(``.cache/test-specs/<name>-<hash>``) and builds its ROS package with CMake into a prefix cached the same way
(``.cache/ros-prefix/<package>-<hash>``, ~20 s once). Concurrent test runs wait for one build (file locks).
A ROS package outside the venv is usable only by a process started with its environment
(:func:`sam_codegen.ros_build.ros_runtime_env`): run the runtime in a child process (``child_env(prefix, ...)``).
"""

from __future__ import annotations

import contextlib
import fcntl
import hashlib
import shutil
import sys
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest

from helpers.runtime_support import REPO

SPECS = Path(__file__).resolve().parents[1] / "specs"


@dataclass(frozen=True)
class BuiltSpec:
    spec: Path
    generated: Path  # the generated/ folder of the spec
    prefix: Path  # where its ROS package is installed


@contextlib.contextmanager
def _locked(path: Path) -> Iterator[None]:
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "a+b") as fh:
        fcntl.flock(fh.fileno(), fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(fh.fileno(), fcntl.LOCK_UN)


def _tree_hash(folder: Path) -> str:
    h = hashlib.sha256(f"{sys.version_info[:2]}".encode())
    for p in sorted(folder.rglob("*")):
        if p.is_file():
            h.update(p.relative_to(folder).as_posix().encode() + b"\0" + p.read_bytes() + b"\0")
    return h.hexdigest()[:20]


def generated_spec(name: str) -> Path:
    """The generated/ folder of ``tests/specs/<name>.yaml`` (what needs only the DSDL and Python needs no ROS
    build)."""
    from sam_codegen.build import build

    spec = SPECS / f"{name}.yaml"
    digest = hashlib.sha256(spec.read_bytes()).hexdigest()[:16]
    cache = REPO / ".cache" / "test-specs"
    gen_dir = cache / f"{name}-{digest}" / "generated"
    with _locked(cache / f".lock-{name}"):
        build(spec, gen_dir)  # rewrites only when the generator's output changed
    return gen_dir


def built_spec(name: str) -> BuiltSpec:
    """``tests/specs/<name>.yaml`` generated and its ROS package installed (skips without cmake/ROS tools)."""
    if shutil.which("cmake") is None:
        pytest.skip("cmake is not installed")
    if not (Path(sys.prefix) / "share" / "rosidl_default_generators" / "package.xml").is_file():
        pytest.skip("rosidl_default_generators is not installed (pip extra 'rosbuild')")
    from sam_codegen.ros_build import build_ros_package
    from sam_runtime.genpkg import GeneratedPackage

    gen_dir = generated_spec(name)
    pkg_dir = GeneratedPackage(gen_dir).ros_package_dir()
    prefixes = REPO / ".cache" / "ros-prefix"
    prefix = prefixes / f"{pkg_dir.name}-{_tree_hash(pkg_dir)}"
    with _locked(prefixes / f".lock-{prefix.name}"):
        if not (prefix / ".complete").is_file():
            shutil.rmtree(prefix, ignore_errors=True)
            build_ros_package(pkg_dir, gen_dir.parent / "ros-build", prefix)
            (prefix / ".complete").write_text("built by tests/helpers/spec_build.py\n")
    return BuiltSpec(SPECS / f"{name}.yaml", gen_dir, prefix)
