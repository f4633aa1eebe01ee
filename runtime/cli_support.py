"""What the runtime's commands share (sam_runtime.cli): the extras check, staying with the main job's process,
logging, the common arguments (generated folder, transport), the asyncio runner with signal handling, JSON files
written atomically, parameter overrides."""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import ctypes
import importlib.util
import json
import logging
import os
import signal
import sys
import threading
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

_ENV_TRANSPORT_KEYS = ("UAVCAN__UDP__IFACE", "UAVCAN__CAN__IFACE", "UAVCAN__LOOPBACK", "UAVCAN__SERIAL__IFACE")
EXIT_OK, EXIT_ERROR, EXIT_USAGE = 0, 1, 2

# What each command imports beyond the base install: the [runtime] extra.
_RUNTIME_MODULES = {
    "bridge": ("pycyphal", "nunavut", "rclpy"),
    "sim": ("pycyphal", "nunavut"),
    "nodes": ("rclpy",),
    "run": ("pycyphal", "nunavut", "rclpy"),
}
# Set by the main job (`run`) in its children's environment: the pid they must not outlive.
PARENT_ENV_VAR = "SAM_RUN_PARENT_PID"
_PR_SET_PDEATHSIG = 1  # <linux/prctl.h>
PARENT_POLL_S = 0.25
# An orphan gets this long to stop cleanly after its SIGTERM, then it exits at once.
ORPHAN_GRACE_S = 5.0


def _missing_runtime(command: str) -> list[str]:
    """The modules of the runtime extra that the command needs and this environment lacks."""
    missing = []
    for name in _RUNTIME_MODULES[command]:
        try:
            found = importlib.util.find_spec(name) is not None
        except (ImportError, ValueError):
            found = False
        if not found:
            missing.append(name)
    return missing


def require_runtime(command: str) -> None:
    """Exit with one clear line when the [runtime] extra is not installed (instead of an ImportError's traceback)."""
    missing = _missing_runtime(command)
    if missing:
        print(f"sam-codegen {command}: the runtime is not installed (missing: {', '.join(missing)}); install the "
              "runtime extra: pip install 'sam-codegen[runtime]'", file=sys.stderr)
        raise SystemExit(EXIT_ERROR)


def stay_with_parent() -> None:
    """A child of the main job ends when the main job ends, however it ends (a crash, SIGKILL, a closed terminal):
    left running, a second run would find two of every device and the rates doubled.

    Linux delivers SIGTERM at the parent's death (PR_SET_PDEATHSIG), which starts the usual clean stop. A thread also
    watches the parent (other systems, and a parent that died before the prctl call) and, once it is gone, sends that
    SIGTERM itself and ends the process ORPHAN_GRACE_S later whatever state the clean stop is in.
    """
    raw = os.environ.get(PARENT_ENV_VAR, "").strip()
    if not raw.isdigit():
        return
    parent = int(raw)
    if sys.platform.startswith("linux"):
        with contextlib.suppress(OSError, AttributeError):
            ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, int(signal.SIGTERM), 0, 0, 0)
    if os.getppid() != parent:
        print(f"the main job (pid {parent}) has already ended; not starting", file=sys.stderr)
        raise SystemExit(EXIT_ERROR)
    threading.Thread(target=_watch_parent, args=(parent,), name="parent-watch", daemon=True).start()


def _watch_parent(parent: int) -> None:
    while os.getppid() == parent:
        time.sleep(PARENT_POLL_S)
    with contextlib.suppress(OSError):
        os.kill(os.getpid(), signal.SIGTERM)
    time.sleep(ORPHAN_GRACE_S)
    os._exit(EXIT_ERROR)


def setup_logging(level: str) -> None:
    logging.basicConfig(
        level=getattr(logging, level.upper(), logging.INFO),
        format="%(asctime)s %(levelname)s %(name)s: %(message)s",
        stream=sys.stderr,
    )
    for noisy in ("pydsdl", "nunavut", "pycyphal", "can"):
        logging.getLogger(noisy).setLevel(max(logging.WARNING, logging.getLogger().level))


_GENERATED_HELP = ("the generated folder (default: $SAM_GENERATED_DIR, else generated/ of the project the working "
                   "directory is in)")


def add_generated_args(p: argparse.ArgumentParser, generated_help: str = _GENERATED_HELP) -> None:
    p.add_argument("--generated", type=Path, default=None, help=generated_help)
    p.add_argument("--package", default=None, help="python package name under generated/python (default: the "
                   "only *_bridge package)")


def add_transport_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--transport", choices=("udp", "can", "loopback", "env"), default=None,
                   help="Cyphal transport (default: env if UAVCAN__*__IFACE is set, else udp)")
    p.add_argument("--iface", default=None,
                   help="UDP: local IP (default 127.0.0.1); CAN: e.g. virtual:bus0 or socketcan:can0")
    p.add_argument("--mtu", type=int, default=None, help="CAN: 8 = Classic CAN, 64 = CAN FD (default 64)")
    p.add_argument("--log-level", default="INFO")


def add_namespace_args(p: argparse.ArgumentParser, ros_args: bool = False) -> None:
    """``--namespace`` and ``--frame-prefix`` (sam_runtime.common.ros_namespace); ``ros_args`` adds ``--ros-args``
    (whose ``-r __ns:=NS`` sets the namespace too)."""
    p.add_argument("--namespace", default=None, metavar="NS",
                   help="the vehicle's ROS namespace (e.g. /sam1): the spec's relative topics resolve under it, "
                        "absolute ones (and /tf, /tf_static, /diagnostics) stay global; also --ros-args -r "
                        "__ns:=NS (default /)")
    p.add_argument("--frame-prefix", default=None, metavar="PREFIX",
                   help="before every frame id (tf2 convention: sam1/base_link); default: the namespace without "
                        "its leading '/' plus '/' ('' for none)")
    if ros_args:
        p.add_argument("--ros-args", nargs=argparse.REMAINDER, default=[], help="ROS arguments for the nodes")


def namespace_of(args: argparse.Namespace) -> Any:
    """The RosNamespace of ``add_namespace_args`` options (ValueError: one line)."""
    from sam_runtime.common.ros_namespace import ros_namespace

    return ros_namespace(args.namespace, getattr(args, "ros_args", None) or (), args.frame_prefix)


def transport_kind(args: argparse.Namespace) -> str:
    if args.transport:
        return str(args.transport)
    if args.iface:
        return "can" if ":" in args.iface else "udp"
    if any(str(os.environ.get(k, "")).strip() for k in _ENV_TRANSPORT_KEYS):
        return "env"
    return "udp"


def generated_package(args: argparse.Namespace) -> Any:
    from sam_runtime.genpkg import GeneratedPackage, default_generated_dir

    return GeneratedPackage(args.generated or default_generated_dir(), args.package)


def _install_stop_handlers(loop: asyncio.AbstractEventLoop, stop: asyncio.Event) -> None:
    for sig in (signal.SIGINT, signal.SIGTERM):
        with contextlib.suppress(NotImplementedError, RuntimeError):
            loop.add_signal_handler(sig, stop.set)


def write_json_atomic(path: Path, data: Any) -> None:
    tmp = path.with_name(path.name + f".tmp{os.getpid()}")
    tmp.write_text(json.dumps(data, indent=1, sort_keys=True, default=str))
    os.replace(tmp, path)


async def wait_for_stop(stop: asyncio.Event, seconds: float | None) -> None:
    if seconds is None:
        await stop.wait()
    else:
        with contextlib.suppress(TimeoutError):
            await asyncio.wait_for(stop.wait(), timeout=max(0.0, seconds))


async def _drain_tasks(timeout: float) -> list[str]:
    """Cancel every task still running, repeatedly (a cancellation that lands inside ``wait_for`` can be lost
    on Python 3.11, see sam_runtime.cyphal_io.transport.aclose), until all are done or the deadline passes. Returns the
    names of the tasks that refused to end."""
    me = asyncio.current_task()
    loop = asyncio.get_running_loop()
    deadline = loop.time() + timeout
    while True:
        pending = [t for t in asyncio.all_tasks() if t is not me and not t.done()]
        if not pending:
            return []
        if loop.time() >= deadline:
            return [t.get_name() for t in pending]
        for t in pending:
            t.cancel()
        await asyncio.wait(pending, timeout=min(0.1, max(0.0, deadline - loop.time())))


def _run_async(main: Any, drain_timeout: float = 3.0) -> int:
    """Like asyncio.run(main()), but the shutdown is bounded: leftover tasks are cancelled with a deadline
    instead of awaited forever (asyncio.run would hang on a task that lost its cancellation)."""
    loop = asyncio.new_event_loop()
    asyncio.set_event_loop(loop)
    try:
        return int(loop.run_until_complete(main()))
    finally:
        try:
            stuck = loop.run_until_complete(_drain_tasks(drain_timeout))
            if stuck:
                logging.getLogger("sam_runtime").warning("tasks still running at exit: %s", ", ".join(stuck))
            loop.run_until_complete(loop.shutdown_asyncgens())
            with contextlib.suppress(TimeoutError):
                loop.run_until_complete(asyncio.wait_for(loop.shutdown_default_executor(), drain_timeout))
        finally:
            asyncio.set_event_loop(None)
            loop.close()


def parse_params(items: Sequence[str]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for item in items:
        if "=" not in item:
            raise SystemExit(f"--param expects NAME=VALUE, got {item!r}")
        k, v = item.split("=", 1)
        val: Any = v
        for conv in (int, float):
            try:
                val = conv(v)
                break
            except ValueError:
                continue
        if v.lower() in ("true", "false"):
            val = v.lower() == "true"
        out[k.strip()] = val
    return out


def serve(prog: str, body: Any, errors: tuple[type[BaseException], ...]) -> int:
    """Run ``body(stop)`` on a fresh loop, `stop` set by SIGINT/SIGTERM; `errors` become one line and exit 1."""

    async def run() -> int:
        stop = asyncio.Event()
        _install_stop_handlers(asyncio.get_running_loop(), stop)
        return int(await body(stop))

    try:
        return _run_async(run)
    except errors as ex:
        print(f"{prog}: {ex}", file=sys.stderr)
        return EXIT_ERROR
    except KeyboardInterrupt:
        return EXIT_OK
