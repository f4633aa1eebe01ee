"""The `sam-codegen` command line.

It acts on the project where it runs, like ruff or nox: the spec is --spec, else spec/interfaces.yaml in the working
directory or its nearest parent that has one; generated/ is --out, else generated/ in the spec's project (the folder
holding spec/, or the spec file's own folder for a spec elsewhere). Caches and logs stay in the project
(.sam-codegen-cache/) or the user's cache directory, never where sam-codegen is installed.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from sam_codegen.model.diagnostics import SpecError
from sam_codegen.project.cyphal_path import CyphalPathError
from sam_codegen.project.workspace import Workspace, WorkspaceError, ensure_state_dir, workspace_for

SPEC_HELP = "the interface spec (default: spec/interfaces.yaml in the working directory or its nearest parent)"
OUT_HELP = ("the generated folder (default: generated/ in the spec's project: beside spec/, or beside a spec file "
            "kept elsewhere); it may not be or hold the spec")


def _workspace(args: argparse.Namespace, *, need_spec: bool = True) -> Workspace:
    return workspace_for(Path(args.spec) if args.spec else None, Path(args.out) if args.out else None,
                         need_spec=need_spec)


def _shown(path: Path, cwd: Path) -> str:
    """A path as the user reads it best: relative to the working directory when it is inside it."""
    try:
        return str(path.relative_to(cwd)) or "."
    except ValueError:
        return str(path)


def _print_budget(lines: list[str]) -> None:
    """The bus budget's lines, after the build's verdict: a layout's figures on stdout, a warning
    (`file:line:col: warning: ...`) on stderr."""
    for line in lines:
        if ": warning: " in line:
            print(line, file=sys.stderr)
        else:
            print(f"sam-codegen: {line}")


def _say(line: str) -> None:
    """A progress line (a step, a wait for another process), at once: a build can take minutes."""
    print(f"sam-codegen: {line}", flush=True)


def _cmd_build(args: argparse.Namespace) -> int:
    from sam_codegen.build import build

    ws = _workspace(args)
    assert ws.spec is not None
    # Taken before the build: when it runs inside generated/ (`--out .`), the rebuild replaces the working directory.
    cwd = Path.cwd().resolve()
    out, spec = _shown(ws.generated, cwd), _shown(ws.spec, cwd)
    try:
        budget: list[str] = []
        stale = build(ws.spec, ws.generated, check=args.check, report=budget.append, say=_say,
                      wait_timeout=args.wait_timeout)
    except SpecError as exc:
        for line in exc.lines():
            print(line, file=sys.stderr)
        count = len(exc.diagnostics)
        print(f"sam-codegen: {count:,} error{'s' if count != 1 else ''} in the spec; {out} left unchanged",
              file=sys.stderr)
        return 1
    if args.check:
        if stale:
            for line in stale.lines():
                print(line, file=sys.stderr)
            print(f"sam-codegen: {out} is stale; run `sam-codegen build`", file=sys.stderr)
            return 1
        print(f"sam-codegen: {out} is up to date with {spec}")
        _print_budget(budget)
        return 0
    print(f"sam-codegen: {out} {'updated' if stale else 'already up to date'} from {spec}")
    _print_budget(budget)
    if stale and (cwd == ws.generated or ws.generated in cwd.parents):
        print(f"sam-codegen: note: {ws.generated} is a new folder now; a shell inside the old one needs `cd {cwd}`")
    return 0


def _cmd_validate(args: argparse.Namespace) -> int:
    from sam_codegen.frontend.loader import load_spec_file
    from sam_codegen.validate.resolve import validate

    ws = _workspace(args)
    assert ws.spec is not None
    try:
        validate(load_spec_file(ws.spec))
    except SpecError as exc:
        for line in exc.lines():
            print(line, file=sys.stderr)
        return 1
    print(f"sam-codegen: {_shown(ws.spec, Path.cwd().resolve())} is valid")
    return 0


def _cmd_ros_install(args: argparse.Namespace) -> int:
    from sam_codegen.project.lock import LockError
    from sam_codegen.project.ros_install import (
        RosBuildError,
        build_ros_packages,
        is_current,
        ros_build_lock,
        ros_packages_in_order,
    )

    ws = _workspace(args, need_spec=False)
    ros_dir = ws.generated / "ros"
    try:
        packages = ros_packages_in_order(ros_dir)
    except RosBuildError as exc:
        print(f"sam-codegen: {exc}", file=sys.stderr)
        return 1
    if not packages:
        if any(ros_dir.glob("*/package.xml")):  # the spec's ROS side uses upstream messages only
            print(f"sam-codegen: the ROS packages under {ros_dir} define no messages: nothing to build")
            return 0
        print(f"sam-codegen: no ROS package under {ros_dir}; run `sam-codegen build` first", file=sys.stderr)
        return 1
    prefix = Path(args.prefix or sys.prefix).absolute()
    build_root = Path(args.build_dir).absolute() if args.build_dir else ensure_state_dir(ws) / "ros-build"
    names = ", ".join(p.name for p in packages)
    try:
        # Held from here to the install: a second ros-install or run of this project waits, then reuses the result.
        with ros_build_lock(build_root, say=_say, timeout=args.wait_timeout) as lock:
            todo = packages
            if lock.contended:  # another process built meanwhile: what it installed from these sources is reused
                todo = [p for p in packages if not is_current(p, prefix)]
                reused = [p.name for p in packages if p not in todo]
                if reused:
                    holder = f" by pid {lock.held_by.pid}" if lock.held_by is not None else ""
                    _say(f"{', '.join(reused)} installed into {prefix} meanwhile{holder}: reused")

            def log(line: str) -> None:
                _say(line)
                lock.status(line)

            build_ros_packages(todo, build_root, prefix, log=log)
    except LockError as exc:
        print(f"sam-codegen: {exc}", file=sys.stderr)
        return 1
    except RosBuildError as exc:
        print(f"sam-codegen: building {exc.package or names} failed: {exc}", file=sys.stderr)
        return 1
    print(f"sam-codegen: {names} installed into {prefix}")
    return 0


def _cmd_plot(args: argparse.Namespace) -> int:
    try:  # the report needs matplotlib and mcap: the `runtime` extra
        from sam_runtime.report.plot import RecordingError, limits_from_params, plot_run
    except ImportError as exc:
        print(f"sam-codegen plot: the runtime is not installed ({exc}); install with the [runtime] extra",
              file=sys.stderr)
        return 1
    recording = Path(args.recording)
    out = Path(args.output) if args.output else recording.with_suffix(".png")
    params = Path(args.params_file) if args.params_file else None
    if params is None:  # the project's generated parameters, when the command runs in one
        try:
            found = sorted((_workspace(args, need_spec=False).generated / "params").glob("*.params.yaml"))
        except (WorkspaceError, CyphalPathError, OSError):
            found = []
        params = found[0] if found else None
    try:
        limits = limits_from_params(params) if params is not None else {}
        plot_run(recording, out, limits=limits)
    except (RecordingError, ValueError, OSError) as exc:
        print(f"sam-codegen plot: {exc}", file=sys.stderr)
        return 1
    note = f" (limits from {_shown(params.resolve(), Path.cwd().resolve())})" if params is not None else \
        " (no parameters file: no depth/altitude limits)"
    print(f"sam-codegen: {out}{note}")
    return 0


WAIT_TIMEOUT_HELP = ("when another sam-codegen process (build, ros-install, run) is writing {what} of this project, "
                     "wait at most S seconds for it, then fail (default: as long as it runs; it says what it does)")


def _wait_timeout_arg(p: argparse.ArgumentParser, what: str) -> None:
    p.add_argument("--wait-timeout", type=float, default=None, metavar="S", help=WAIT_TIMEOUT_HELP.format(what=what))


def make_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="sam-codegen", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.epilog = "Runtime commands (see `sam-codegen run --help`): bridge, sim, nodes, run, record, replay, params."
    sub = parser.add_subparsers(dest="command", required=True)

    def common(p: argparse.ArgumentParser) -> None:
        p.add_argument("--spec", default=None, help=SPEC_HELP)
        p.add_argument("--out", default=None, help=OUT_HELP)

    p = sub.add_parser("build", help="validate the spec and generate generated/")
    common(p)
    p.add_argument("--check", action="store_true", help="fail and list the stale files instead of writing")
    _wait_timeout_arg(p, "generated/")
    p.set_defaults(func=_cmd_build)
    p = sub.add_parser("validate", help="validate the spec only")
    common(p)
    p.set_defaults(func=_cmd_validate)
    p = sub.add_parser("ros-install", help="build every ROS package under generated/ros with CMake, in dependency "
                       "order, and install them")
    common(p)
    p.add_argument("--prefix", help="install prefix (default: this Python's environment)")
    p.add_argument("--build-dir", default=None,
                   help="parent of the CMake build folders (default: .sam-codegen-cache/ros-build in the project)")
    _wait_timeout_arg(p, "the build folder")
    p.set_defaults(func=_cmd_ros_install)
    p = sub.add_parser("plot", help="draw a recorded run (an MCAP) as one PNG/SVG report: track, depth, altitude, "
                       "commands, battery, abort, node states")
    common(p)
    p.add_argument("recording", help="the run's MCAP recording (sam-codegen run --record FILE.mcap)")
    p.add_argument("-o", "--output", help="the picture, .png or .svg (default: the recording's name with .png)")
    p.add_argument("--params-file", help="the parameters with the depth/altitude limits (default: "
                   "generated/params/*.params.yaml of the project)")
    p.set_defaults(func=_cmd_plot)
    return parser


RUNTIME_COMMANDS = ("bridge", "sim", "nodes", "run", "record", "replay", "params")


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if argv and argv[0] in RUNTIME_COMMANDS:
        # The runtime has its own options (transports, durations); it is an optional part of the install.
        try:
            from sam_runtime.cli import main as runtime_main
        except ImportError as exc:
            print(f"sam-codegen {argv[0]}: the runtime is not installed ({exc}); install with the [runtime] extra",
                  file=sys.stderr)
            return 1
        return int(runtime_main(argv))
    args = make_parser().parse_args(argv)
    try:
        return int(args.func(args))
    except (WorkspaceError, CyphalPathError) as exc:
        print(f"sam-codegen: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        return 130


if __name__ == "__main__":
    sys.exit(main())
