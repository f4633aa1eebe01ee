"""The `sam-codegen` command line."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .diagnostics import SpecError

REPO_ROOT = Path(__file__).resolve().parents[1]
DEFAULT_SPEC = REPO_ROOT / "spec" / "interfaces.yaml"
DEFAULT_OUT = REPO_ROOT / "generated"


def _cmd_build(args: argparse.Namespace) -> int:
    from .build import OutputError, build

    try:
        stale = build(Path(args.spec), Path(args.out), check=args.check)
    except OutputError as exc:
        print(f"sam-codegen: {exc}", file=sys.stderr)
        return 1
    except SpecError as exc:
        for diagnostic in exc.diagnostics:
            print(diagnostic, file=sys.stderr)
        count = len(exc.diagnostics)
        print(f"sam-codegen: {count} error{'s' if count != 1 else ''} in the spec; {args.out} left unchanged",
              file=sys.stderr)
        return 1
    if args.check:
        if stale:
            for line in stale.lines():
                print(line, file=sys.stderr)
            print(f"sam-codegen: {args.out} is stale; run `sam-codegen build`", file=sys.stderr)
            return 1
        print(f"sam-codegen: {args.out} is up to date")
        return 0
    print(f"sam-codegen: {args.out} {'updated' if stale else 'already up to date'}")
    return 0


def _cmd_validate(args: argparse.Namespace) -> int:
    from .spec_loader import load_spec_file
    from .validate import validate

    try:
        validate(load_spec_file(Path(args.spec)))
    except SpecError as exc:
        for diagnostic in exc.diagnostics:
            print(diagnostic, file=sys.stderr)
        return 1
    print(f"sam-codegen: {args.spec} is valid")
    return 0


def _cmd_ros_install(args: argparse.Namespace) -> int:
    from .ros_build import RosBuildError, build_ros_package
    from .spec_loader import load_spec_file

    try:
        package = load_spec_file(Path(args.spec)).ros.name
    except SpecError as exc:
        print(exc, file=sys.stderr)
        return 1
    prefix = Path(args.prefix or sys.prefix)
    try:
        build_ros_package(Path(args.out) / "ros" / package, Path(args.build_dir) / package, prefix)
    except RosBuildError as exc:
        print(f"sam-codegen: building {package} failed: {exc}", file=sys.stderr)
        return 1
    print(f"sam-codegen: {package} installed into {prefix}")
    return 0


def make_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="sam-codegen", description=__doc__)
    parser.epilog = "Runtime commands (see `sam-codegen run --help`): bridge, sim, run."
    sub = parser.add_subparsers(dest="command", required=True)

    def common(p: argparse.ArgumentParser) -> None:
        p.add_argument("--spec", default=str(DEFAULT_SPEC), help="the interface spec (default: %(default)s)")
        p.add_argument("--out", default=str(DEFAULT_OUT), help="the generated folder (default: %(default)s)")

    p = sub.add_parser("build", help="validate the spec and generate generated/")
    common(p)
    p.add_argument("--check", action="store_true", help="fail and list the stale files instead of writing")
    p.set_defaults(func=_cmd_build)
    p = sub.add_parser("validate", help="validate the spec only")
    common(p)
    p.set_defaults(func=_cmd_validate)
    p = sub.add_parser("ros-install", help="build the generated ROS package with CMake and install it")
    common(p)
    p.add_argument("--prefix", help="install prefix (default: this Python's environment)")
    p.add_argument("--build-dir", default=str(REPO_ROOT / "build" / "ros"), help="CMake build folder")
    p.set_defaults(func=_cmd_ros_install)
    return parser


RUNTIME_COMMANDS = ("bridge", "sim", "run")


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
    except KeyboardInterrupt:
        return 130


if __name__ == "__main__":
    sys.exit(main())
