"""sam-codegen installed the way a user installs it (issue 11): a wheel built from this source, `pip install`ed (not
editable) into a fresh virtual environment, used in a project of the user's own (the skiff spec) outside this
repository. build, validate, ros-install, sim, bridge and run work there; what they write lands in that project or
the user's cache directory, never in the install; without the [runtime] extra or without the Cyphal standard types
each runtime command ends with one clear line.

About 3-4 minutes: the two installs come from pip's cache, ros-install builds dinghy_msgs with CMake.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import re
import shutil
import signal
import subprocess
import sys
import zipfile
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import pytest

pytest.importorskip("pycyphal")
pytest.importorskip("rclpy")

from helpers.isolation import machine_network
from helpers.runtime_support import cyphal_udp_lock, domain_id, poll_until, read_json
from helpers.user_project import make_project

from sam_codegen.project.cyphal_path import default_search_dirs

pytestmark = [pytest.mark.ros, pytest.mark.slow]

REPO = Path(__file__).resolve().parents[2]
INSTALL_TIMEOUT_S = 900
STEP_TIMEOUT_S = 600
# What `pip wheel` needs: the project's metadata and the package folders (package-dir in pyproject.toml).
SOURCE = ("pyproject.toml", "README.md", "codegen", "runtime", "templates")
# Where the old defaults wrote, relative to site-packages (the install's "repository root"): generated/, the DSDL
# cache, ROS build folders and logs under .cache/, ros-install's build/ros. (site-packages/build is pypa's `build`.)
INSTALL_LOCATION_WRITES = ("generated", ".cache", "build/ros", ".sam-codegen-cache")


def _run(cmd: Sequence[str | Path], *, cwd: Path, env: dict[str, str], timeout: float = STEP_TIMEOUT_S,
         ok: bool = True) -> subprocess.CompletedProcess[str]:
    # pip may need the package index: the machine's network, not the test's private loopback (helpers.isolation).
    with machine_network() if [str(c) for c in cmd[1:3]] == ["-m", "pip"] else contextlib.nullcontext():
        proc = subprocess.run([str(c) for c in cmd], cwd=cwd, env=env, capture_output=True, text=True,
                              timeout=timeout)
    if ok:
        assert proc.returncode == 0, f"{cmd} failed ({proc.returncode}):\n{proc.stdout[-4000:]}\n{proc.stderr[-4000:]}"
    return proc


def _tree(folder: Path) -> dict[str, str]:
    return {p.relative_to(folder).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file() and "__pycache__" not in p.parts}


@dataclass
class Wheel:
    path: Path
    root: Path


@pytest.fixture(scope="module")
def wheel(tmp_path_factory: pytest.TempPathFactory) -> Wheel:
    """The wheel, built by pip from a copy of the source (the checkout itself stays untouched)."""
    root = tmp_path_factory.mktemp("wheel")
    src = root / "src"
    src.mkdir()
    for name in SOURCE:
        if (REPO / name).is_dir():
            shutil.copytree(REPO / name, src / name, ignore=shutil.ignore_patterns("__pycache__"))
        else:
            shutil.copy(REPO / name, src / name)
    _run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "-w", root / "dist", src], cwd=root,
         env=dict(os.environ), timeout=INSTALL_TIMEOUT_S)
    (path,) = (root / "dist").glob("sam_codegen-*.whl")
    return Wheel(path, root)


def test_the_wheel_ships_the_packages_and_templates(wheel: Wheel) -> None:
    names = set(zipfile.ZipFile(wheel.path).namelist())
    templates = {p.relative_to(REPO / "templates").as_posix() for p in (REPO / "templates").rglob("*.j2")}
    assert templates and {f"sam_codegen/templates/{t}" for t in templates} <= names
    # Every module of both packages (an explicit package list in pyproject.toml that misses a subpackage fails here).
    modules = {f"sam_codegen/{p.relative_to(REPO / 'codegen').as_posix()}" for p in (REPO / "codegen").rglob("*.py")}
    modules |= {f"sam_runtime/{p.relative_to(REPO / 'runtime').as_posix()}" for p in (REPO / "runtime").rglob("*.py")}
    assert len(modules) > 100 and modules <= names, sorted(modules - names)
    assert not [n for n in names if n.startswith(("tests/", "generated/", "spec/", "bench/"))]


def _pip_cache_dir() -> str | None:
    proc = subprocess.run([sys.executable, "-m", "pip", "cache", "dir"], capture_output=True, text=True, timeout=60)
    return (proc.stdout.strip() or None) if proc.returncode == 0 else None


def _user_env(root: Path, venv: Path) -> dict[str, str]:
    """A user's shell with the venv first on PATH: nothing of this checkout or its venv, an empty home, and the
    Cyphal standard types named the conventional way (CYPHAL_PATH)."""
    # _ROS_WHEELS_BOOTSTRAP_COMPLETE: the ROS wheels' start-up hook of this process's venv ran, and set
    # LD_LIBRARY_PATH for it; the new venv's hook must run for its own.
    dropped = ("UAVCAN__", "SAM_", "AMENT_", "CMAKE_", "COLCON_", "PYTHON", "LD_LIBRARY_PATH", "VIRTUAL_ENV",
               "XDG_", "ROS_", "_ROS_WHEELS_BOOTSTRAP")
    env = {k: v for k, v in os.environ.items() if not k.startswith(dropped)}
    pip_cache = _pip_cache_dir()  # the user's warm pip cache, though HOME is a new one
    env.update({
        "HOME": str(root / "home"),
        "XDG_CACHE_HOME": str(root / "xdg-cache"),
        "PATH": f"{venv / 'bin'}{os.pathsep}{os.environ.get('PATH', '')}",
        "CYPHAL_PATH": str(default_search_dirs()[0]),
        "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST",
        "ROS_DOMAIN_ID": domain_id(50),
        **({"PIP_CACHE_DIR": pip_cache} if pip_cache else {}),
    })
    (root / "home").mkdir(exist_ok=True)
    return env


def _wait_for_line(path: Path, proc: subprocess.Popen[str], prefix: str, timeout: float) -> str:
    def found() -> str | None:
        assert proc.poll() is None or prefix in path.read_text(errors="replace"), \
            f"exited ({proc.returncode}) before {prefix!r}:\n{path.read_text(errors='replace')[-3000:]}"
        return next((line for line in path.read_text(errors="replace").splitlines() if line.startswith(prefix)),
                    None)

    return poll_until(found, timeout, f"{prefix!r} in {path.name}")


def _final_counts(output: str) -> dict[str, int]:
    """COUNT per topic of the main job's final table."""
    final = output[output.rindex("final ("):]
    return {m.group(1): int(m.group(2)) for m in re.finditer(r"^(/\S+)\s+(?:in|out)\s+[\d.]+\s+\d+\s+(\d+)", final,
                                                             re.MULTILINE)}


def test_installed_wheel_in_a_user_project(wheel: Wheel) -> None:
    root = wheel.root
    venv = root / "venv"
    _run([sys.executable, "-m", "venv", venv], cwd=root, env=dict(os.environ))
    env = _user_env(root, venv)
    python, sam = venv / "bin" / "python", venv / "bin" / "sam-codegen"
    project = make_project(root / "skiff")
    work = project / "src" / "pilot"  # the user works somewhere inside their project
    work.mkdir(parents=True)

    # ---- the base install: the generator only
    _run([python, "-m", "pip", "install", "-q", wheel.path], cwd=root, env=env, timeout=INSTALL_TIMEOUT_S)
    site = Path(_run([python, "-c", "import sam_codegen, pathlib; print(pathlib.Path(sam_codegen.__file__).parent"
                                    ".parent)"], cwd=root, env=env).stdout.strip())
    assert site.is_relative_to(venv) and (site / "sam_codegen" / "templates" / "ros" / "package.xml.j2").is_file()
    installed = {pkg: _tree(site / pkg) for pkg in ("sam_codegen", "sam_runtime")}

    assert "spec/interfaces.yaml is valid" in _run([sam, "validate"], cwd=work, env=env).stdout
    assert _run([sam, "build"], cwd=work, env=env).stdout.startswith(f"sam-codegen: {project / 'generated'} updated")
    assert (project / "generated" / "ros" / "dinghy_msgs" / "package.xml").is_file()
    _run([sam, "build", "--check"], cwd=work, env=env)

    # No Cyphal standard types anywhere (an installed wheel has no development default): one clear error.
    no_types = {k: v for k, v in env.items() if k != "CYPHAL_PATH"}
    proc = _run([sam, "validate"], cwd=work, env=no_types, ok=False)
    assert proc.returncode == 1 and "Traceback" not in proc.stderr, proc.stderr
    assert proc.stderr.startswith("sam-codegen: no DSDL root namespace 'uavcan' found; searched: nothing (CYPHAL_PATH "
                                  "is unset, so the checkouts in ~/.cyphal/ were searched)")
    assert proc.stderr.count("\n") == 1 and "export CYPHAL_PATH=" in proc.stderr

    # Defect 11: the runtime commands without the runtime extra.
    for command in ("sim", "bridge", "run"):
        proc = _run([sam, command, "--duration", "1"], cwd=work, env=env, ok=False)
        assert proc.returncode == 1 and "Traceback" not in proc.stderr, proc.stderr
        assert "the runtime is not installed (missing: pycyphal" in proc.stderr
        assert proc.stderr.endswith("install the runtime extra: pip install 'sam-codegen[runtime]'\n")

    # ---- with the runtime and the ROS build tools
    _run([python, "-m", "pip", "install", "-q", f"{wheel.path}[runtime,rosbuild]"], cwd=root, env=env,
         timeout=INSTALL_TIMEOUT_S)
    out = _run([sam, "ros-install"], cwd=work, env=env, timeout=STEP_TIMEOUT_S).stdout
    assert f"dinghy_msgs installed into {venv}" in out
    assert (venv / "share" / "dinghy_msgs" / "package.xml").is_file()
    assert (project / ".sam-codegen-cache" / "ros-build" / "dinghy_msgs" / "CMakeCache.txt").is_file()

    with cyphal_udp_lock():
        # The bridge and the devices, each found its generated/ from the working directory.
        stats, report = root / "bridge-stats.json", root / "sim-report.json"
        bridge_out = root / "bridge.out"
        with open(bridge_out, "w") as fh:
            bridge = subprocess.Popen([str(sam), "bridge", "--duration", "300", "--stats-file", str(stats)],
                                      cwd=work, env=env, stdout=fh, stderr=subprocess.STDOUT, text=True,
                                      start_new_session=True)
        try:
            _wait_for_line(bridge_out, bridge, "READY bridge dinghy_bridge", 180)
            sim = _run([sam, "sim", "--duration", "3", "--report", report], cwd=work, env=env, timeout=180)
            assert "READY sim devices=2" in sim.stdout
            published = {name: sum(d["published"].values()) for name, d in read_json(report)["devices"].items()}
            assert published["pressure"] > 0 and published["pump"] > 0, published

            def received() -> bool:
                mappings = (read_json(stats) or {}).get("mappings", {})
                return all(mappings.get(m, {}).get("published", 0) > 0 for m in ("depth", "pump_volume"))

            poll_until(received, 30, "the bridge to publish what the devices sent")
            bridge.send_signal(signal.SIGTERM)
            assert bridge.wait(timeout=60) == 0
        finally:
            if bridge.poll() is None:
                os.killpg(bridge.pid, signal.SIGKILL)
                bridge.wait(timeout=10)

        # The main job: build (up to date), the installed dinghy_msgs, sim and bridge, and what flows.
        proc = _run([sam, "run", "--duration", "8", "--plain"], cwd=work, env=env, timeout=STEP_TIMEOUT_S)
        counts = _final_counts(proc.stdout)
        assert counts["/depth"] > 0 and counts["/pump/volume"] > 0, proc.stdout[-3000:]
    logs = project / ".sam-codegen-cache" / "run-logs"
    assert "READY" in (logs / "sim.log").read_text() and "READY" in (logs / "bridge.log").read_text()
    assert f"logs: {logs / 'sim.log'}" in proc.stdout

    # What was written went to the project or the user's cache, never into the install.
    assert list((root / "xdg-cache" / "sam-codegen" / "dsdl").glob("*/.complete"))
    assert {pkg: _tree(site / pkg) for pkg in installed} == installed
    assert not [name for name in INSTALL_LOCATION_WRITES if (site / name).exists() or (venv / name).exists()]
    assert sorted(p.name for p in project.iterdir()) == [".sam-codegen-cache", "generated", "spec", "src"]
