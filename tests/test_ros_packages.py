"""tests/helpers/ros_packages.py: a generated ROS package is built once per content and combined with others by
chaining prefixes in the environment."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest
from helpers import ros_packages

MSG = "float64 x\n"


def _package(root: Path, name: str, depends: tuple[str, ...] = (), msg: str = MSG) -> Path:
    folder = root / name
    (folder / "msg").mkdir(parents=True)
    deps = "".join(f"  <depend>{d}</depend>\n" for d in depends)
    (folder / "package.xml").write_text(f'<?xml version="1.0"?>\n<package format="3">\n  <name>{name}</name>\n'
                                        f"{deps}</package>\n")
    (folder / "msg" / "Thing.msg").write_text(msg)
    (folder / "CMakeLists.txt").write_text(f"project({name})\n")
    return folder


def test_a_package_key_is_its_content_and_its_dependencies_not_its_company(tmp_path: Path) -> None:
    a = _package(tmp_path / "one", "a_msgs")
    b = _package(tmp_path / "one", "b_msgs", depends=("a_msgs",))
    other = _package(tmp_path / "one", "other_msgs")
    alone = {p.name: p for p in ros_packages.plan([a])}
    together = {p.name: p for p in ros_packages.plan([other, a, b])}
    assert alone["a_msgs"].key == together["a_msgs"].key  # one build, whatever it is combined with
    assert together["b_msgs"].needs == {"a_msgs"} and together["other_msgs"].needs == set()
    # The same package in another folder (a user project under tmp_path) is the same build.
    assert ros_packages.plan([_package(tmp_path / "two", "a_msgs")])[0].key == alone["a_msgs"].key
    # A changed dependency is another build of the package that uses it.
    a2 = _package(tmp_path / "three", "a_msgs", msg="float32 x\n")
    b2 = _package(tmp_path / "three", "b_msgs", depends=("a_msgs",))
    changed = {p.name: p for p in ros_packages.plan([a2, b2])}
    assert changed["a_msgs"].key != alone["a_msgs"].key
    assert changed["b_msgs"].key != together["b_msgs"].key


def test_chained_env_puts_the_package_first_then_the_prefixes_it_needs(tmp_path: Path) -> None:
    dep, top = tmp_path / "dep", tmp_path / "top"
    top.mkdir()
    (top / ros_packages.CHAIN_FILE).write_text(f"{dep}\n")
    env = ros_packages.chained_env(top, {"PATH": os.environ.get("PATH", "")})
    py = f"python{sys.version_info.major}.{sys.version_info.minor}"
    assert env["PYTHONPATH"].split(os.pathsep)[:2] == [f"{top}/lib/{py}/site-packages", f"{dep}/lib/{py}/site-packages"]
    assert env["LD_LIBRARY_PATH"].split(os.pathsep)[:2] == [f"{top}/lib", f"{dep}/lib"]
    ament = env["AMENT_PREFIX_PATH"].split(os.pathsep)
    assert ament[:2] == [str(top), str(dep)] and sys.prefix in ament  # the wheels' packages stay found
    # The venv itself needs nothing added.
    assert ros_packages.chained_env(Path(sys.prefix), {"A": "1"}) == {"A": "1"}


@pytest.mark.ros
def test_packages_current_in_the_venv_are_used_as_they_are() -> None:
    from sam_codegen.project.ros_install import ros_packages_in_order

    packages = ros_packages_in_order(ros_packages.ROOT / "generated" / "ros")
    if not all(ros_packages.current_in_venv(p) for p in packages):
        pytest.skip("generated/ros is not installed in this venv (`sam-codegen ros-install`; nox's tests session)")
    assert ros_packages.built_prefix(packages) == Path(sys.prefix).absolute()


@pytest.mark.ros
@pytest.mark.slow
def test_the_tests_builds_hold_the_c_and_python_type_supports_and_no_cpp() -> None:
    """python_only.cmake leaves the C++ generators out of the tests' builds (the users' builds keep them)."""
    from helpers.spec_build import built_spec

    if ros_packages.missing_tools() is not None:
        pytest.skip(str(ros_packages.missing_tools()))
    built = built_spec("glider")  # built by other tests anyway: cached by content
    libs = sorted(p.name for p in (built.prefix / "lib").glob("lib*.so"))
    kinds = {lib.split("__", 1)[1].removesuffix(".so") for lib in libs}
    assert kinds == {"rosidl_generator_c", "rosidl_generator_py", "rosidl_typesupport_c",
                     "rosidl_typesupport_fastrtps_c", "rosidl_typesupport_introspection_c"}, libs
    assert not list((built.prefix / "include").rglob("*.hpp")), "C++ headers generated"
