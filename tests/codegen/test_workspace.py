"""sam-codegen acts on the project where it runs, never on its install (issue 11, defects 1, 2, 3 and 11).

A new user's project is a copy of tests/specs/skiff.yaml at <tmp>/skiff/spec/interfaces.yaml: not SAM's spec, and
not inside this repository.
"""

from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from sam_codegen.build import MARKER
from sam_codegen.cli import main
from sam_codegen.project.cyphal_path import CyphalPathError, dsdl_lookup_roots, search_dirs
from sam_codegen.project.ros_install import RosBuildError, ros_packages_in_order
from sam_codegen.project.workspace import (
    GENERATED_MARKER,
    OutDirError,
    WorkspaceError,
    find_generated,
    find_spec,
    user_cache_dir,
    workspace_for,
)

REPO = Path(__file__).resolve().parents[2]
SKIFF = Path(__file__).parents[1] / "specs" / "skiff.yaml"
SHARED_DSDL = REPO.parent / "shared" / "dsdl" / "public_regulated_data_types"


def _tree(folder: Path) -> dict[str, str]:
    """Every file under folder with a hash of its bytes (what a build could have changed)."""
    return {p.relative_to(folder).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file() and "__pycache__" not in p.parts}


@pytest.fixture
def project(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A user's project outside this repository; the runtime's override of generated/ is not set."""
    root = tmp_path / "skiff"
    (root / "spec").mkdir(parents=True)
    shutil.copy(SKIFF, root / "spec" / "interfaces.yaml")
    (root / "src" / "pilot").mkdir(parents=True)
    monkeypatch.delenv("SAM_GENERATED_DIR", raising=False)
    return root


# ------------------------------------------------------------------------------------------- discovery (pure)


def test_spec_and_generated_are_found_from_the_working_directory(project: Path) -> None:
    spec = project / "spec" / "interfaces.yaml"
    for cwd in (project, project / "spec", project / "src" / "pilot"):
        assert find_spec(cwd) == spec
        ws = workspace_for(cwd=cwd)
        assert (ws.spec, ws.generated, ws.project) == (spec, project / "generated", project)
        assert ws.state_dir == project / ".sam-codegen-cache"
    # --spec alone: generated/ in that spec's project; a spec kept elsewhere: generated/ beside it.
    other = project / "vehicles" / "b.yaml"
    assert workspace_for(Path("vehicles/b.yaml"), cwd=project).generated == project / "vehicles" / "generated"
    assert workspace_for(other, Path("../out"), cwd=project / "src").generated == project / "out"


def test_no_spec_is_one_clear_error(tmp_path: Path) -> None:
    with pytest.raises(WorkspaceError) as ei:
        find_spec(tmp_path)
    assert str(ei.value) == f"no spec/interfaces.yaml in {tmp_path.resolve()} or any parent; pass --spec"


@pytest.mark.parametrize(("spec", "out", "why"), [
    ("gen/x.yaml", "gen", "it holds the spec"),                # defect 2: the spec inside the output folder
    ("gen/deeper/x.yaml", "gen", "it holds the spec"),
    ("spec/interfaces.yaml", ".", "it holds the spec"),         # the project itself
    ("spec/interfaces.yaml", "spec/interfaces.yaml", "it is the spec itself"),
    ("spec/interfaces.yaml", "/", "file system root"),
])
def test_out_may_not_hold_the_spec(tmp_path: Path, spec: str, out: str, why: str) -> None:
    with pytest.raises(OutDirError, match=why):
        workspace_for(Path(spec), Path(out), cwd=tmp_path)


def test_the_runtime_finds_generated_the_same_way(project: Path, tmp_path: Path) -> None:
    generated = project / "generated"
    assert find_generated(project / "src" / "pilot", environ={}) == generated
    (generated / "python").mkdir(parents=True)
    (generated / GENERATED_MARKER).write_text("")
    # Inside a generated folder (even one without a spec above it): that folder.
    assert find_generated(generated / "python", environ={}) == generated
    assert find_generated(project, environ={"SAM_GENERATED_DIR": str(tmp_path / "x")}) == tmp_path / "x"
    with pytest.raises(WorkspaceError, match="pass --generated or set SAM_GENERATED_DIR"):
        find_generated(tmp_path, environ={})
    assert GENERATED_MARKER == MARKER


def test_caches_go_to_the_user_cache_directory(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from sam_runtime.cyphal_io.dsdl_cache import default_cache_dir

    assert user_cache_dir({"XDG_CACHE_HOME": str(tmp_path)}) == tmp_path / "sam-codegen"
    assert user_cache_dir({"XDG_CACHE_HOME": "relative/ignored", "HOME": "/h"}).parts[-2:] == (".cache", "sam-codegen")
    monkeypatch.delenv("SAM_DSDL_CACHE", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    assert default_cache_dir() == tmp_path / "sam-codegen" / "dsdl"
    monkeypatch.setenv("SAM_DSDL_CACHE", str(tmp_path / "mine"))
    assert default_cache_dir() == tmp_path / "mine"


# ------------------------------------------------------------------------------------------- the CLI in a project


def test_cli_acts_on_the_project_where_it_runs(project: Path, monkeypatch: pytest.MonkeyPatch,
                                               capsys: pytest.CaptureFixture[str]) -> None:
    """Defect 1: no --spec/--out in a copy of a project builds that copy, and never this repository's generated/."""
    mine = _tree(REPO / "generated")
    monkeypatch.chdir(project / "src" / "pilot")
    assert main(["validate"]) == 0
    assert f"{project / 'spec' / 'interfaces.yaml'} is valid" in capsys.readouterr().out
    assert main(["build"]) == 0
    assert "updated" in capsys.readouterr().out
    generated = project / "generated"
    assert (generated / "ros" / "dinghy_msgs" / "package.xml").is_file()
    assert (generated / "python" / "dinghy_bridge" / "tables.py").is_file()
    assert main(["build", "--check"]) == 0

    # The user edits their spec: the check sees it, a build takes it.
    spec = project / "spec" / "interfaces.yaml"
    spec.write_text(spec.read_text().replace("rate_hz: 10}", "rate_hz: 20}"))
    capsys.readouterr()
    assert main(["build", "--check"]) == 1
    assert "python/dinghy_bridge/tables.py" in capsys.readouterr().err
    assert main(["build"]) == 0
    assert main(["build", "--check"]) == 0
    assert _tree(REPO / "generated") == mine


def test_no_project_is_one_clear_error(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                       capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.chdir(tmp_path)
    for command in (["build"], ["build", "--check"], ["validate"], ["ros-install"]):
        assert main(command) == 1
        err = capsys.readouterr().err
        assert err == f"sam-codegen: no spec/interfaces.yaml in {tmp_path.resolve()} or any parent; pass --spec\n"
    assert list(tmp_path.iterdir()) == []


def test_out_holding_the_spec_deletes_nothing(project: Path, monkeypatch: pytest.MonkeyPatch,
                                              capsys: pytest.CaptureFixture[str]) -> None:
    """Defect 2: `build --spec gen/x.yaml --out gen` over a generated gen/ deleted the spec."""
    monkeypatch.chdir(project)
    assert main(["build", "--out", "gen"]) == 0
    shutil.copy(project / "spec" / "interfaces.yaml", project / "gen" / "x.yaml")
    before = _tree(project)
    capsys.readouterr()
    for out in ("gen", "."):
        assert main(["build", "--spec", "gen/x.yaml", "--out", out]) == 1
        err = capsys.readouterr().err
        assert f"refusing --out {(project / out).resolve()}: it holds the spec {project / 'gen' / 'x.yaml'}" in err
        assert "Traceback" not in err
    assert _tree(project) == before


def test_out_dot_inside_the_generated_folder(project: Path, monkeypatch: pytest.MonkeyPatch,
                                             capsys: pytest.CaptureFixture[str]) -> None:
    """Defect 3: `build --out .` inside a generated folder raised "PosixPath('.') has an empty name"."""
    monkeypatch.chdir(project)
    assert main(["build"]) == 0
    generated = project / "generated"
    (generated / "stray.txt").write_text("not generated")
    monkeypatch.chdir(generated)
    capsys.readouterr()
    assert main(["build", "--check", "--out", "."]) == 1
    assert "not generated by the spec: stray.txt" in capsys.readouterr().err
    assert main(["build", "--out", "."]) == 0
    out = capsys.readouterr().out
    assert out.startswith("sam-codegen: . updated from ")
    assert f"a shell inside the old one needs `cd {generated}`" in out
    assert not (generated / "stray.txt").exists()
    monkeypatch.chdir(generated)  # the process's own working directory was the replaced folder
    assert main(["build", "--out", "."]) == 0
    assert "already up to date" in capsys.readouterr().out
    # `..` is the project, which holds the spec.
    assert main(["build", "--out", ".."]) == 1
    assert f"refusing --out {project}: it holds the spec" in capsys.readouterr().err
    assert sorted(p.name for p in project.iterdir()) == ["generated", "spec", "src"]


# ------------------------------------------------------------------------------------------- ros-install


def _package(folder: Path, name: str, *deps: str, tag: str = "depend") -> None:
    folder.mkdir(parents=True)
    lines = "".join(f"  <{tag}>{d}</{tag}>\n" for d in deps)
    (folder / "package.xml").write_text(f'<?xml version="1.0"?>\n<package format="3">\n  <name>{name}</name>\n'
                                        f"{lines}</package>\n")
    (folder / "msg").mkdir()
    (folder / "msg" / "Thing.msg").write_text("int32 value\n")


def test_ros_packages_are_built_in_dependency_order(tmp_path: Path) -> None:
    ros = tmp_path / "ros"
    _package(ros / "a_msgs", "a_msgs", "z_msgs", "std_msgs")  # needs a generated package named later
    _package(ros / "z_msgs", "z_msgs", "std_msgs", tag="build_depend")
    _package(ros / "m_msgs", "m_msgs", "a_msgs", tag="exec_depend")
    _package(ros / "b_msgs", "b_msgs")
    (ros / "notes").mkdir()  # not a package
    (ros / "empty_msgs").mkdir()  # a package without interfaces: nothing to build
    (ros / "empty_msgs" / "package.xml").write_text((ros / "b_msgs" / "package.xml").read_text())
    assert [p.name for p in ros_packages_in_order(ros)] == ["b_msgs", "z_msgs", "a_msgs", "m_msgs"]
    assert ros_packages_in_order(tmp_path / "none") == []
    _package(ros / "y_msgs", "y_msgs", "m_msgs")
    (ros / "z_msgs" / "package.xml").write_text((ros / "z_msgs" / "package.xml").read_text().replace(
        "<build_depend>std_msgs", "<build_depend>y_msgs"))
    with pytest.raises(RosBuildError, match="in a cycle: a_msgs, m_msgs, y_msgs, z_msgs"):
        ros_packages_in_order(ros)


def test_ros_install_builds_every_generated_package(project: Path, tmp_path: Path,
                                                    monkeypatch: pytest.MonkeyPatch,
                                                    capsys: pytest.CaptureFixture[str]) -> None:
    """Every package under generated/ros (a second, generated interface package too), dependencies first, build
    folders in the project's .sam-codegen-cache (not the install's build/)."""
    import sam_codegen.project.ros_install as ros_build

    monkeypatch.chdir(project)
    assert main(["build"]) == 0
    _package(project / "generated" / "ros" / "aa_extra_msgs", "aa_extra_msgs", "dinghy_msgs")
    built: list[tuple[str, Path, Path]] = []
    monkeypatch.setattr(ros_build, "build_ros_package",
                        lambda pkg, build, prefix, **_: built.append((Path(pkg).name, Path(build), Path(prefix))))
    assert main(["ros-install", "--prefix", str(tmp_path / "prefix")]) == 0
    state = project / ".sam-codegen-cache"
    assert built == [("dinghy_msgs", state / "ros-build" / "dinghy_msgs", tmp_path / "prefix"),
                     ("aa_extra_msgs", state / "ros-build" / "aa_extra_msgs", tmp_path / "prefix")]
    assert (state / ".gitignore").read_text().splitlines()[-1] == "*"
    assert "dinghy_msgs, aa_extra_msgs installed into" in capsys.readouterr().out


# ------------------------------------------------------------------------------------------- CYPHAL_PATH


def test_cyphal_path_then_conventional_places(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    home = tmp_path / "home"
    checkout = home / ".cyphal" / "public_regulated_data_types"
    checkout.mkdir(parents=True)
    (checkout / "uavcan").symlink_to(SHARED_DSDL / "uavcan")
    vendor = home / ".cyphal" / "vendor_dsdl" / "acme"
    vendor.mkdir(parents=True)
    (vendor / "Thing.1.0.dsdl").write_text("@sealed\n")
    roots = dsdl_lookup_roots({"HOME": str(home)})
    assert [(r.name, r.parent) for r in roots] == [("acme", vendor.parent), ("reg", SHARED_DSDL.resolve()),
                                                   ("uavcan", (SHARED_DSDL / "uavcan").resolve().parent)]
    assert search_dirs({"HOME": str(home)})[:2] == [checkout, vendor.parent]
    # CYPHAL_PATH, when set, is the whole search path.
    assert search_dirs({"HOME": str(home), "CYPHAL_PATH": str(tmp_path)}) == [tmp_path]

    # An installed wheel has no development default: with nothing conventional either, one error says what to set.
    import sam_codegen.project.cyphal_path as cyphal_path

    monkeypatch.setattr(cyphal_path, "source_checkout", lambda: None)
    with pytest.raises(CyphalPathError) as ei:
        dsdl_lookup_roots({"HOME": str(tmp_path / "empty")})
    text = str(ei.value)
    assert text.startswith("no DSDL root namespace 'uavcan' found; searched: nothing (CYPHAL_PATH is unset, so the "
                           "checkouts in ~/.cyphal/ were searched)")
    assert "`export CYPHAL_PATH=/path/to/public_regulated_data_types`" in text


def test_missing_uavcan_is_one_line_from_the_cli(project: Path, monkeypatch: pytest.MonkeyPatch,
                                                 capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.chdir(project)
    monkeypatch.setenv("CYPHAL_PATH", str(project / "nowhere"))
    for command in (["validate"], ["build"]):
        assert main(command) == 1
        err = capsys.readouterr().err
        assert err.startswith("sam-codegen: no DSDL root namespace 'uavcan' found; searched: "
                              f"{project / 'nowhere'} (missing)")
        assert err.count("\n") == 1 and "export CYPHAL_PATH=" in err
    assert not (project / "generated").exists()


# ------------------------------------------------------------------------------------------- defect 11

# Runs `sam-codegen sim` in a Python where the [runtime] extra's packages cannot be imported, and their
# distributions are unknown to importlib.metadata (as after `pip install sam-codegen` without the extra).
_WITHOUT_RUNTIME = textwrap.dedent("""\
    import importlib.abc, importlib.metadata, sys
    BLOCKED = {"pycyphal", "nunavut", "rclpy", "can"}

    class Blocker(importlib.abc.MetaPathFinder):
        def find_spec(self, name, path=None, target=None):
            if name.partition(".")[0] in BLOCKED:
                raise ModuleNotFoundError(f"No module named {name!r}", name=name)
            return None

    sys.meta_path.insert(0, Blocker())
    real_version = importlib.metadata.version

    def version(name):
        if name in BLOCKED:
            raise importlib.metadata.PackageNotFoundError(name)
        return real_version(name)

    importlib.metadata.version = version
    from sam_codegen.cli import main
    sys.exit(main(sys.argv[1:]))
    """)


@pytest.mark.system  # starts a process: not in the unit tier
@pytest.mark.parametrize("command", ["sim", "bridge", "run"])
def test_runtime_commands_without_the_runtime_extra(command: str, tmp_path: Path) -> None:
    proc = subprocess.run([sys.executable, "-c", _WITHOUT_RUNTIME, command, "--generated", str(REPO / "generated")],
                          capture_output=True, text=True, timeout=120, cwd=tmp_path,
                          env={**os.environ, "SAM_DSDL_CACHE": str(tmp_path / "cache")})
    assert proc.returncode == 1, proc.stderr
    assert "Traceback" not in proc.stderr
    missing = "pycyphal, nunavut" + (", rclpy" if command != "sim" else "")
    assert proc.stderr == (f"sam-codegen {command}: the runtime is not installed (missing: {missing}); install the "
                           "runtime extra: pip install 'sam-codegen[runtime]'\n")
    assert list(tmp_path.iterdir()) == []
