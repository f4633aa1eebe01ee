"""`sam-codegen ros-install` reports progress: a line per step of each package with the time since it began, and
one when it is installed (a build takes 10-40 s)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from sam_codegen.project import ros_install


def test_a_line_per_step_and_package_with_elapsed_time(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    now = [0.0]
    built: list[str] = []

    def fake_build(package_dir: Path, build_dir: Path, prefix: Path, *, python: Path | None = None, jobs: int = 2,
                   progress: Callable[[str], None] | None = None) -> None:
        assert progress is not None
        for step, seconds in (("configure", 2.0), ("build", 9.5), ("install", 0.5)):
            progress(step)
            now[0] += seconds
        built.append(package_dir.name)

    monkeypatch.setattr(ros_install, "build_ros_package", fake_build)
    lines: list[str] = []
    ros_install.build_ros_packages([tmp_path / "tf2_msgs", tmp_path / "sam_msgs"], tmp_path / "b", tmp_path / "i",
                                   log=lines.append, clock=lambda: now[0])
    assert built == ["tf2_msgs", "sam_msgs"]
    assert lines == ["[1/2] tf2_msgs: configure (0.0 s)", "[1/2] tf2_msgs: build (2.0 s)",
                     "[1/2] tf2_msgs: install (11.5 s)", "[1/2] tf2_msgs: installed in 12.0 s",
                     "[2/2] sam_msgs: configure (0.0 s)", "[2/2] sam_msgs: build (2.0 s)",
                     "[2/2] sam_msgs: install (11.5 s)", "[2/2] sam_msgs: installed in 12.0 s"]


def test_a_failure_names_its_package(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    def failing(package_dir: Path, *args: object, progress: Callable[[str], None] | None = None,
                **kwargs: object) -> None:
        assert progress is not None
        progress("configure")
        raise ros_install.RosBuildError("CMake configure failed (exit code 1)")

    monkeypatch.setattr(ros_install, "build_ros_package", failing)
    lines: list[str] = []
    with pytest.raises(ros_install.RosBuildError) as info:
        ros_install.build_ros_packages([tmp_path / "sam_msgs"], tmp_path / "b", tmp_path / "i", log=lines.append)
    assert info.value.package == "sam_msgs" and lines == ["[1/1] sam_msgs: configure (0.0 s)"]


def test_a_new_build_folder_uses_ninja_where_it_is_found(tmp_path: Path) -> None:
    """Ninja for a new build folder when it is on the build's PATH; nothing for a folder CMake configured (it keeps
    its generator and refuses another) or when the user chose one; Makefiles (no -G) without Ninja."""
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    ninja = bin_dir / "ninja"
    ninja.write_text("#!/bin/sh\n")
    ninja.chmod(0o755)
    env = {"PATH": str(bin_dir)}
    assert ros_install.cmake_generator(tmp_path / "new", env) == ["-G", "Ninja", f"-DCMAKE_MAKE_PROGRAM={ninja}"]
    assert ros_install.cmake_generator(tmp_path / "new", {**env, "CMAKE_GENERATOR": "Unix Makefiles"}) == []
    assert ros_install.cmake_generator(tmp_path / "new", {"PATH": str(tmp_path / "empty")}) == []
    configured = tmp_path / "old"
    configured.mkdir()
    (configured / "CMakeCache.txt").write_text("CMAKE_GENERATOR:INTERNAL=Unix Makefiles\n")
    assert ros_install.cmake_generator(configured, env) == []
