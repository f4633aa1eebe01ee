"""The generated ament packages build with colcon, the way a ROS user builds a workspace, not only with our own CMake
call (issue 11): this repository's generated/ros/* and a user's (the skiff spec) in one temporary workspace, against
the ROS 2 wheels of this environment; then every message of every package imports and goes through serialization
with the workspace's install on the paths."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from helpers.user_project import make_project

from sam_codegen.build import build
from sam_codegen.project.ros_install import ros_packages_in_order, ros_runtime_env

pytestmark = [pytest.mark.ros, pytest.mark.slow]

REPO = Path(__file__).resolve().parents[2]
COLCON = Path(sys.executable).parent / "colcon"
# A clean build of a package takes ~10-40 s here; this only guards against a hung build.
BUILD_TIMEOUT_S = 1200

_CHECK = textwrap.dedent("""\
    import importlib, json, sys
    from rclpy.serialization import deserialize_message, serialize_message

    done = {}
    for package, names in json.loads(sys.argv[1]).items():
        module = importlib.import_module(f"{package}.msg")
        assert module.__file__.startswith(sys.argv[2]), module.__file__
        for name in names:
            cls = getattr(module, name)
            msg = cls()
            assert deserialize_message(serialize_message(msg), cls) == msg, name
        done[package] = len(names)
    print(json.dumps(done))
    """)


@pytest.mark.skipif(not COLCON.exists(), reason="colcon is not installed: pip install -e '.[test]'")
def test_generated_packages_build_with_colcon(tmp_path: Path) -> None:
    skiff = make_project(tmp_path / "skiff")
    build(skiff / "spec" / "interfaces.yaml", skiff / "generated")
    src = tmp_path / "ws" / "src"
    packages = [*ros_packages_in_order(REPO / "generated" / "ros"),
                *ros_packages_in_order(skiff / "generated" / "ros")]
    assert {"sam_msgs", "dinghy_msgs"} <= {p.name for p in packages}
    for package in packages:
        shutil.copytree(package, src / package.name)

    venv = Path(sys.prefix)
    env = {k: v for k, v in os.environ.items() if not k.startswith(("COLCON_", "AMENT_", "CMAKE_"))}
    env.update({
        "AMENT_PREFIX_PATH": str(venv),
        "CMAKE_PREFIX_PATH": str(venv),
        "PATH": f"{venv / 'bin'}{os.pathsep}{env.get('PATH', '')}",
        "COLCON_HOME": str(tmp_path / "colcon-home"),  # no defaults of the user's own ~/.colcon
    })
    ws = tmp_path / "ws"
    proc = subprocess.run(
        [str(COLCON), "--log-base", str(ws / "log"), "build", "--merge-install", "--base-paths", str(src),
         "--build-base", str(ws / "build"), "--install-base", str(ws / "install"),
         "--cmake-args", f"-DPython3_EXECUTABLE={sys.executable}", "-DBUILD_TESTING=OFF"],
        cwd=ws, env=env, capture_output=True, text=True, timeout=BUILD_TIMEOUT_S)
    assert proc.returncode == 0, f"colcon build failed:\n{proc.stdout[-6000:]}\n{proc.stderr[-6000:]}"
    for package in packages:
        assert f"Finished <<< {package.name}" in proc.stdout + proc.stderr

    install = ws / "install"
    messages = {p.name: sorted(m.stem for m in (p / "msg").glob("*.msg")) for p in packages}
    check = subprocess.run([sys.executable, "-c", _CHECK, json.dumps(messages), str(install)],
                           env=ros_runtime_env(install), capture_output=True, text=True, timeout=120)
    assert check.returncode == 0, check.stderr[-4000:]
    assert json.loads(check.stdout) == {name: len(names) for name, names in messages.items()}
