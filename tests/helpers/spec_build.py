"""A test spec's generated package and its ROS messages, for runtime tests on specs other than SAM's.

:func:`built_spec` generates ``generated/`` for a spec into a folder cached by the spec's content
(``.cache/test-specs/<name>-<hash>``) and builds its ROS package with CMake into a prefix cached the same way
(``.cache/ros-prefix/<package>-<hash>``, ~20 s once). Concurrent test runs wait for one build (file locks).
A ROS package outside the venv is usable only by a process started with its environment
(:func:`sam_codegen.project.ros_install.ros_runtime_env`):
run the runtime in a child process (``child_env(prefix, ...)``).
"""

from __future__ import annotations

import hashlib
import shutil
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest

from helpers.ros_packages import built_prefix, locked
from helpers.runtime_support import REPO, child_env, domain_id

SPECS = Path(__file__).resolve().parents[1] / "specs"


@dataclass(frozen=True)
class BuiltSpec:
    spec: Path
    generated: Path  # the generated/ folder of the spec
    prefix: Path  # where its ROS package is installed

    def child_env(self, domain_offset: int) -> dict[str, str]:
        """The environment of a child process running this spec: its ROS package, a private ROS domain
        (runtime_support.domain_id), SAM_GENERATED_DIR its generated/ folder."""
        return child_env(self.prefix, domain_id(domain_offset), {"SAM_GENERATED_DIR": str(self.generated)})


def generated_spec(name: str) -> Path:
    """The generated/ folder of ``tests/specs/<name>.yaml`` (what needs only the DSDL and Python needs no ROS
    build)."""
    from sam_codegen.build import build

    spec = SPECS / f"{name}.yaml"
    digest = hashlib.sha256(spec.read_bytes()).hexdigest()[:16]
    cache = REPO / ".cache" / "test-specs"
    gen_dir = cache / f"{name}-{digest}" / "generated"
    with locked(cache / f".lock-{name}"):
        build(spec, gen_dir)  # rewrites only when the generator's output changed
    return gen_dir


def built_spec(name: str) -> BuiltSpec:
    """``tests/specs/<name>.yaml`` generated and its ROS package installed (skips without cmake/ROS tools)."""
    if shutil.which("cmake") is None:
        pytest.skip("cmake is not installed")
    if not (Path(sys.prefix) / "share" / "rosidl_default_generators" / "package.xml").is_file():
        pytest.skip("rosidl_default_generators is not installed (pip extra 'rosbuild')")
    from sam_runtime.genpkg import GeneratedPackage

    gen_dir = generated_spec(name)
    prefix = built_prefix([GeneratedPackage(gen_dir).ros_package_dir()])
    return BuiltSpec(SPECS / f"{name}.yaml", gen_dir, prefix)


def spec_workdir(tmp_path_factory: pytest.TempPathFactory, name: str, folder: str,
                 domain_offset: int) -> tuple[BuiltSpec, Path, dict[str, str]]:
    """The prologue of a system test's module fixture: ``tests/specs/<name>.yaml`` built (built_spec), a fresh
    folder for its processes' files, and their environment (BuiltSpec.child_env)."""
    built = built_spec(name)
    return built, tmp_path_factory.mktemp(folder), built.child_env(domain_offset)


def forget_generated(gen: Any) -> None:
    """Take a generated package (a GeneratedPackage) out of this process again: its modules and its sys.path entry.

    A test that imports a spec's package into the pytest process calls it when done, so that a later test may
    import another build of the same vehicle (a user project under tmp_path): GeneratedPackage refuses a package
    that another copy shadows."""
    python_dir = str(gen.python_dir)
    for name in [m for m in sys.modules if m.split(".")[0] == gen.package]:
        if python_dir in str(getattr(sys.modules[name], "__file__", "") or ""):
            del sys.modules[name]
    while python_dir in sys.path:
        sys.path.remove(python_dir)
