"""Which project a command acts on, and where it may write: found from the working directory, like ruff or nox.

- The spec: ``--spec``, else ``spec/interfaces.yaml`` in the working directory or the nearest parent that has one.
- Its project: the folder that holds ``spec/`` for a spec at ``<project>/spec/<file>.yaml``; for a spec file
  anywhere else, the folder of that file.
- generated/: ``--out``, else ``<project>/generated``. It may never be, or contain, the spec: a rebuild replaces the
  whole folder.
- The project's own state (ROS build folders, the main job's logs): ``<project>/.sam-codegen-cache/``, which
  ignores itself for git. What is shared by every project (the compiled Cyphal DSDL, content-addressed) goes to the
  user's cache directory, ``$XDG_CACHE_HOME/sam-codegen`` (default ``~/.cache/sam-codegen``). Nothing is ever
  written where the tool is installed.

Pure path logic (no imports beyond the standard library), so that every command can use it first.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

__all__ = [
    "GENERATED_ENV_VAR",
    "GENERATED_MARKER",
    "SPEC_RELPATH",
    "STATE_DIR_NAME",
    "OutDirError",
    "Workspace",
    "WorkspaceError",
    "check_out_dir",
    "ensure_state_dir",
    "find_generated",
    "find_spec",
    "generated_for",
    "project_of",
    "user_cache_dir",
    "workspace_for",
]

SPEC_RELPATH = Path("spec", "interfaces.yaml")
GENERATED_DIR_NAME = "generated"
STATE_DIR_NAME = ".sam-codegen-cache"
# The file `sam-codegen build` puts into every generated folder (sam_codegen.build.MARKER).
GENERATED_MARKER = ".sam-codegen"
# The runtime's override of the generated folder (bridge, sim, run).
GENERATED_ENV_VAR = "SAM_GENERATED_DIR"


class WorkspaceError(Exception):
    """No project where the command runs, or paths that would make it destroy one; ``str()`` says what to do."""


class OutDirError(WorkspaceError):
    """An output folder that a rebuild must not replace (it is, or holds, the spec; it is no folder at all)."""


def _absolute(path: Path, cwd: Path | None = None) -> Path:
    """``path`` made absolute against ``cwd`` and normalised (``.``, ``..``, symbolic links).

    >>> _absolute(Path("."), Path("/a/b")) == Path("/a/b").resolve()
    True
    """
    path = Path(os.path.expanduser(path))
    if not path.is_absolute():
        path = (cwd if cwd is not None else Path.cwd()) / path
    return path.resolve()


def find_spec(start: Path | None = None) -> Path:
    """``spec/interfaces.yaml`` in ``start`` (default: the working directory) or its nearest parent that has one."""
    start = _absolute(start or Path.cwd())
    for folder in (start, *start.parents):
        candidate = folder / SPEC_RELPATH
        if candidate.is_file():
            return candidate
    raise WorkspaceError(f"no {SPEC_RELPATH.as_posix()} in {start} or any parent; pass --spec")


def project_of(spec: Path) -> Path:
    """The project a spec belongs to: the parent of its ``spec/`` folder, else the spec's own folder.

    >>> project_of(Path("/home/u/glider/spec/interfaces.yaml"))
    PosixPath('/home/u/glider')
    >>> project_of(Path("/home/u/specs/glider.yaml"))
    PosixPath('/home/u/specs')
    """
    folder = spec.parent
    return folder.parent if folder.name == SPEC_RELPATH.parent.name else folder


def generated_for(spec: Path) -> Path:
    """The default generated folder of a spec: ``generated/`` in its project.

    >>> generated_for(Path("/home/u/glider/spec/interfaces.yaml"))
    PosixPath('/home/u/glider/generated')
    """
    return project_of(spec) / GENERATED_DIR_NAME


def check_out_dir(spec: Path, out: Path) -> None:
    """Refuse an output folder that a rebuild cannot replace without destroying the spec.

    A rebuild swaps the whole folder, so ``out`` may be neither the spec file, nor the folder holding it, nor any
    folder above it; nor the file system root. Both paths must be absolute and resolved (see :func:`workspace_for`).

    >>> check_out_dir(Path("/p/spec/interfaces.yaml"), Path("/p/generated"))
    >>> try:
    ...     check_out_dir(Path("/p/gen/x.yaml"), Path("/p/gen"))
    ... except OutDirError as refused:
    ...     print(str(refused).split(",")[0])
    refusing --out /p/gen: it holds the spec /p/gen/x.yaml
    """
    if not out.name:
        raise OutDirError(f"refusing --out {out}: a build replaces the whole output folder, and this is the file "
                          "system root")
    if out == spec:
        raise OutDirError(f"refusing --out {out}: it is the spec itself")
    if out in spec.parents:
        raise OutDirError(f"refusing --out {out}: it holds the spec {spec}, and a build replaces the whole folder; "
                          "choose a folder outside the spec's (default: generated/ beside the spec's project)")


@dataclass(frozen=True)
class Workspace:
    """The project a command acts on: every path absolute."""

    project: Path
    generated: Path
    spec: Path | None = None  # None when the command needs only generated/ (ros-install --out, the runtime)

    @property
    def state_dir(self) -> Path:
        """The project's own caches and logs (see :func:`ensure_state_dir`)."""
        return self.project / STATE_DIR_NAME

    @property
    def ros_build_dir(self) -> Path:
        return self.state_dir / "ros-build"

    @property
    def log_dir(self) -> Path:
        return self.state_dir / "run-logs"


def workspace_for(spec: Path | None = None, out: Path | None = None, *, cwd: Path | None = None,
                  need_spec: bool = True) -> Workspace:
    """The workspace of a command given its ``--spec`` and ``--out`` (either may be None: found as documented above).

    With ``need_spec=False`` (commands that read only generated/), an ``out`` alone is enough: its parent is then the
    project. Raises :class:`WorkspaceError` when no spec is found, :class:`OutDirError` for an ``out`` that holds the
    spec.
    """
    out_path = _absolute(out, cwd) if out is not None else None
    if spec is None and out_path is not None and not need_spec:
        return Workspace(project=out_path.parent, generated=out_path)
    spec_path = _absolute(spec, cwd) if spec is not None else find_spec(cwd)
    generated = out_path if out_path is not None else generated_for(spec_path)
    check_out_dir(spec_path, generated)
    return Workspace(project=project_of(spec_path), generated=generated, spec=spec_path)


def find_generated(start: Path | None = None, environ: Mapping[str, str] | None = None) -> Path:
    """The generated folder the runtime uses: ``$SAM_GENERATED_DIR``; else, from ``start`` (default: the working
    directory) upward, the generated folder it is in, or ``generated/`` of the first project found."""
    env = os.environ if environ is None else environ
    override = env.get(GENERATED_ENV_VAR, "").strip()
    if override:
        return _absolute(Path(override))
    start = _absolute(start or Path.cwd())
    for folder in (start, *start.parents):
        if (folder / GENERATED_MARKER).is_file():
            return folder
        if (folder / SPEC_RELPATH).is_file():
            return folder / GENERATED_DIR_NAME
    raise WorkspaceError(f"no generated folder found: no {SPEC_RELPATH.as_posix()} in {start} or any parent; "
                         f"pass --generated or set {GENERATED_ENV_VAR}")


def user_cache_dir(environ: Mapping[str, str] | None = None) -> Path:
    """The user's cache directory of sam-codegen: ``$XDG_CACHE_HOME/sam-codegen``, default ``~/.cache/sam-codegen``.

    >>> user_cache_dir({"XDG_CACHE_HOME": "/c"})
    PosixPath('/c/sam-codegen')
    """
    env = os.environ if environ is None else environ
    base = env.get("XDG_CACHE_HOME", "").strip()
    if base and os.path.isabs(base):  # the XDG rule: a relative value is invalid and ignored
        return Path(base) / "sam-codegen"
    try:
        return Path.home() / ".cache" / "sam-codegen"
    except RuntimeError:  # no home directory (a service account): a private folder under the temporary one
        return Path(tempfile.gettempdir()) / f"sam-codegen-{os.getuid()}"


def ensure_state_dir(workspace: Workspace) -> Path:
    """Create the project's state folder; like ruff's cache it holds a ``.gitignore`` of ``*``, so it never shows up
    in the project's version control."""
    state = workspace.state_dir
    state.mkdir(parents=True, exist_ok=True)
    ignore = state / ".gitignore"
    if not ignore.exists():
        ignore.write_text("# Created by sam-codegen: caches and logs of this project.\n*\n", encoding="utf-8")
    return state
