"""The main job: build, start the simulated devices, the bridge and the node host, and show live what flows.

:func:`run` (``sam-run`` / ``sam-codegen run``):

1. regenerates ``generated/`` from the spec (``sam_codegen.build.build``) unless ``build=False``; the spec and
   generated/ are found from the working directory like ``sam-codegen build`` does (sam_codegen.project.workspace);
2. builds and installs the generated ROS message packages into the venv if they are missing or stale (build folders
   under the project's ``.sam-codegen-cache/ros-build``);
3. compiles the DSDL once (the children reuse the cache);
4. starts ``sam-sim`` (with the vehicle options and a truth file), ``sam-bridge`` and, when the spec has nodes with
   an implementation (sam_runtime.nodes), ``sam-nodes`` (the node host, flying the demo mission unless ``--goal`` or
   ``--mission`` says otherwise) as subprocesses on Cyphal/UDP 127.0.0.1 (own sessions, logs under the project's
   ``.sam-codegen-cache/run-logs``); they never outlive this process (sam_runtime.cli_support.stay_with_parent);
5. shows it live (:class:`LiveView`, an rclpy node in this process): the vehicle, its goal, plan and commands and
   every node's state (main_job.vehicle_view, when nodes are hosted), every bridged topic's rate over a sliding
   window and its last value, every device's heartbeat (from the bridge's /diagnostics) and the bridge's drop
   counters; a refreshing table on a terminal, plain lines every second otherwise. For a spec without node
   implementations it publishes slow demo sweeps on the command topics instead (main_job.demo), so that the
   simulated actuators move (never on a topic a hosted node publishes);
6. stops on ``--duration``, Ctrl-C, SIGTERM or SIGHUP (the terminal closed): children get SIGTERM together (SIGKILL
   after one deadline), exit 0.
   A child that dies on its own ends the run with exit code 1 and the tail of its log.
"""

from __future__ import annotations

import os

os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")

import contextlib
import importlib
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sam_codegen.build import build
from sam_codegen.model.diagnostics import SpecError
from sam_codegen.project.cyphal_path import CyphalPathError
from sam_codegen.project.lock import LockError, LockTimeout, ProjectLock, lock_path
from sam_codegen.project.ros_install import RosBuildError, ros_runtime_env
from sam_codegen.project.workspace import (
    GENERATED_ENV_VAR,
    WorkspaceError,
    ensure_state_dir,
    find_generated,
    workspace_for,
)
from sam_runtime.bridge.layout import protocols_in_use
from sam_runtime.cli_support import PARENT_ENV_VAR
from sam_runtime.cyphal_io.dsdl_cache import DsdlCompileError
from sam_runtime.genpkg import GeneratedPackage, GeneratedPackageError, ensure_ros_package
from sam_runtime.main_job.live_view import LiveView, summarize_message
from sam_runtime.nodes import implemented, unimplemented
from sam_runtime.recording.target import RecordingTargetError, check_target
from sam_runtime.report.plot import limits_from_params, plot_run

__all__ = ["LiveView", "RunOptions", "run", "summarize_message"]

CHILD_STOP_TIMEOUT_S = 8.0
# A vehicle whose processes have not all said READY by then is not coming up (a hung child): the run ends with
# exit code 1 and their logs. Generous: on a loaded machine the node host's imports alone take seconds.
VEHICLE_START_TIMEOUT_S = 300.0
CHILD_KILL_TIMEOUT_S = 5.0
# The signals that end the main job cleanly; SIGHUP is the terminal closing.
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


@dataclass
class RunOptions:
    spec: Path | None = None
    generated: Path | None = None
    package: str | None = None
    iface: str = "127.0.0.1"
    duration: float | None = None
    build: bool = True
    demo_commands: bool = True
    window: float = 2.0
    plain: bool = False
    log_dir: Path | None = None
    refresh_s: float = 0.5
    ros_prefix: Path | None = None  # where the generated ROS package is installed (default: the venv)
    argv: list[str] | None = None  # for the re-exec when ros_prefix needs a new process environment
    nodes: bool = True  # start the node host when the spec has node implementations
    node_args: list[str] | None = None  # for `sam-nodes` (--goal, --mission, --params-file)
    sim_args: list[str] | None = None  # for `sam-sim` (the vehicle options)
    truth_file: Path | None = None  # the sim's truth file (default: truth.json in the log folder)
    layout: str | None = None  # the spec's layout (which firmware each device runs); a mixed one: two bridges
    dronecan_iface: str = "mcast-lo:"
    wire: str = "codec"  # the bridges' path: the generated wire codecs, or "object" (the object converters)
    record: Path | None = None  # an MCAP file: the recorder (sam-codegen record) runs as one more child
    namespace: Any = None  # sam_runtime.common.ros_namespace.RosNamespace: the bridge's, the nodes' and the view's
    wait_timeout: float | None = None  # for another process building generated/ or the ROS packages (None: no bound)


# ============================================================================================ processes
class _Child:
    def __init__(self, name: str, cmd: list[str], env: Mapping[str, str], log: Path) -> None:
        self.name, self.log = name, log
        log.parent.mkdir(parents=True, exist_ok=True)
        self._fh = open(log, "w")
        # Own session: the terminal's Ctrl-C and hangup reach only us, and we stop the children. They end with us
        # however we end (even SIGKILL or a crash): they watch this pid (sam_runtime.cli_support.stay_with_parent).
        self.proc = subprocess.Popen(cmd, env={**env, PARENT_ENV_VAR: str(os.getpid())}, stdout=self._fh,
                                     stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL, start_new_session=True)
        self._read = 0  # bytes of the log looked through for READY
        self._ready = False

    def ready(self) -> bool:
        """Whether the child has said READY (every command of the runtime prints it, flushed, once it serves)."""
        if not self._ready:
            try:
                with open(self.log, "rb") as fh:
                    fh.seek(self._read)
                    chunk = fh.read()
            except OSError:
                return False
            whole = chunk[:chunk.rfind(b"\n") + 1]  # a line still being written is read again next time
            self._read += len(whole)
            self._ready = any(line.startswith(b"READY") for line in whole.splitlines())
        return self._ready

    def alive(self) -> bool:
        return self.proc.poll() is None

    def signal(self, sig: int) -> None:
        """Signal the child's whole process group (its session), so nothing it started stays behind."""
        if self.proc.poll() is not None:
            return
        try:
            os.killpg(self.proc.pid, sig)
        except (ProcessLookupError, PermissionError):
            with contextlib.suppress(ProcessLookupError):
                self.proc.send_signal(sig)

    def wait(self, timeout: float) -> int | None:
        try:
            return self.proc.wait(timeout=max(0.0, timeout))
        except subprocess.TimeoutExpired:
            return None

    def close_log(self) -> None:
        self._fh.close()

    def tail(self, n: int = 15) -> str:
        try:
            return "\n".join(self.log.read_text(errors="replace").splitlines()[-n:])
        except OSError:
            return ""


def _stop_children(children: list[_Child], timeout: float = CHILD_STOP_TIMEOUT_S) -> dict[str, int | None]:
    """SIGTERM to every child at once (the bridge first: it consumes), then one shared deadline, then SIGKILL to
    those still running. Bounded by timeout + CHILD_KILL_TIMEOUT_S; never raises. Returns the exit codes."""
    for c in reversed(children):
        c.signal(signal.SIGTERM)
    deadline = time.monotonic() + timeout
    for c in children:
        c.wait(deadline - time.monotonic())
    late = [c for c in children if c.alive()]
    for c in late:
        c.signal(signal.SIGKILL)
    deadline = time.monotonic() + CHILD_KILL_TIMEOUT_S
    for c in late:
        c.wait(deadline - time.monotonic())
    for c in children:
        c.close_log()
    return {c.name: c.proc.returncode for c in children}


def _workspace(opts: RunOptions) -> Any:
    """Where this run works (sam_codegen.project.workspace):
    the spec and generated/ as `sam-codegen build` finds them when it
    builds; with --no-build and no --spec, only the generated folder (--generated, $SAM_GENERATED_DIR or found from
    the working directory)."""
    env_generated = os.environ.get(GENERATED_ENV_VAR, "").strip()
    generated = opts.generated or (Path(env_generated) if env_generated and opts.spec is None else None)
    if opts.build or opts.spec is not None:
        return workspace_for(opts.spec, generated)
    return workspace_for(None, generated or find_generated(), need_spec=False)


def claim_log_dir(opts: RunOptions, state: Path, say: Any) -> tuple[Path, ProjectLock | None]:
    """The children's log folder (with the truth file): ``--log-dir``, else the project's ``run-logs``, held by this
    run (a lock) until it ends. A second run of the project at the same time gets ``run-logs-2`` (and so on)
    instead of overwriting the first one's logs, which the first one is reading."""
    if opts.log_dir is not None:
        return opts.log_dir.resolve(), None
    base = (state / "run-logs").resolve()
    for n in range(1, 100):
        folder = base if n == 1 else base.with_name(f"{base.name}-{n}")
        lock = ProjectLock(lock_path("run-logs", folder), f"the log folder {folder}", timeout=0.0)
        try:
            lock.__enter__()
        except LockTimeout:  # another run writes there
            continue
        except LockError:  # no lock files at all: as before, the one folder
            break
        if n > 1:
            say(f"sam-run: {base} is another run's; this run's logs go to {folder}")
        return folder, lock
    return base, None


def _build(spec: Path, gen_dir: Path, say: Any, opts: RunOptions, cancelled: Any) -> None:
    stale = build(spec, gen_dir, check=False, say=lambda line: say(f"sam-run: {line}"), wait_timeout=opts.wait_timeout,
                  cancelled=cancelled)
    say(f"generated {gen_dir} from {spec}: " + (f"{len(stale.lines())} file(s) updated" if stale else "up to date"))


def _say(text: str) -> None:
    print(text, flush=True)


@dataclass(frozen=True)
class _Prepared:
    """What the run starts from: generated/ up to date, its ROS package installed, its DSDL compiled."""

    gen_dir: Path
    state: Path  # the project's .sam-codegen-cache
    gen: GeneratedPackage
    prefix: Path  # where the generated ROS package is installed


def _prepare(opts: RunOptions, say: Any, cancelled: Any) -> _Prepared | int:
    """Steps 1-3 of the run (build, ROS package, DSDL); an exit code where one fails (said, never raised).

    Steps 1 and 2 hold the project's locks (sam_codegen.project.lock) while they write: a second run started at once
    waits for the first one's build, says for whom it waits, and then reuses what it built. A stop signal while
    waiting (``cancelled``) ends the run quietly (exit 0)."""
    try:
        ws = _workspace(opts)
        gen_dir = ws.generated
        if opts.build:
            _build(ws.spec, gen_dir, say, opts, cancelled)
        state = ensure_state_dir(ws)
        gen = GeneratedPackage(gen_dir, opts.package)
        prefix = ensure_ros_package(gen, opts.ros_prefix, log=lambda line: say(f"sam-run: {line}"),
                                    build_root=state / "ros-build", wait_timeout=opts.wait_timeout,
                                    cancelled=cancelled)
        importlib.invalidate_caches()  # a package installed just now into this venv
        gen.compile_dsdl()
    except SpecError as ex:
        say(f"sam-run: the spec is invalid:\n{ex}")
        return 1
    except (WorkspaceError, CyphalPathError, GeneratedPackageError, DsdlCompileError, LockError) as ex:
        if cancelled():  # stopped while waiting for another process: what was asked
            say(f"sam-run: {ex}" if isinstance(ex, LockError) else "sam-run: stopped")
            return 0
        say(f"sam-run: {ex}")
        return 1
    except RosBuildError as ex:
        say(f"sam-run: building the generated ROS packages failed: {ex}")
        return 1
    return _Prepared(gen_dir, state, gen, prefix)


def _children_env(opts: RunOptions, prefix: Path, gen_dir: Path,
                  old_handlers: Mapping[signal.Signals, Any]) -> dict[str, str]:
    """The children's environment; first, if the ROS prefix is a separate one not yet on LD_LIBRARY_PATH, this
    process continues as a new one that has it (os.execve, with the signal handlers it found put back)."""
    env = ros_runtime_env(prefix) if prefix != Path(sys.prefix).absolute() else dict(os.environ)
    ld_path = os.environ.get("LD_LIBRARY_PATH", "").split(os.pathsep)
    if str(prefix / "lib") not in ld_path and opts.argv is not None:
        # The ROS type support libraries of a separate prefix are found only through LD_LIBRARY_PATH,
        # which the loader reads at process start: continue in a process that has it (built already).
        for sig, h in old_handlers.items():
            signal.signal(sig, h)
        sys.stdout.flush()
        os.execve(sys.executable, [sys.executable, "-m", "sam_runtime.cli", "run", *opts.argv, "--no-build",
                                   "--generated", str(gen_dir)], env)
    env["ROS_AUTOMATIC_DISCOVERY_RANGE"] = env.get("ROS_AUTOMATIC_DISCOVERY_RANGE") or "LOCALHOST"
    env["PYTHONUNBUFFERED"] = "1"
    env.setdefault("SAM_GENERATED_DIR", str(gen_dir))
    return env


def _start_children(children: list[_Child], opts: RunOptions, gen_dir: Path, tables: Any, hosted: list[str],
                    env: Mapping[str, str], log_dir: Path, truth: Path) -> None:
    """Step 4: the simulator, a bridge per protocol in use, the recorder and the node host, each appended to
    `children` as soon as it runs (the caller stops whatever was started, even if a later start fails)."""
    common = ["--generated", str(gen_dir), "--transport", "udp", "--iface", opts.iface,
              "--dronecan-iface", opts.dronecan_iface, *(["--layout", opts.layout] if opts.layout else [])]
    if opts.package:
        common += ["--package", opts.package]
    py = [sys.executable, "-m", "sam_runtime.cli"]
    ns_args = opts.namespace.argv() if opts.namespace is not None else []
    children.append(_Child("sim", [*py, "sim", *common, *(opts.sim_args or []), "--truth-file", str(truth),
                                   *ns_args[:2]],
                           env, log_dir / "sim.log"))
    layout = opts.layout or tables.DEFAULT_LAYOUT
    protocols = protocols_in_use(tables, layout)
    for proto in protocols if len(protocols) > 1 else [None]:
        name = "bridge" if proto is None else f"bridge_{proto}"
        children.append(_Child(name, [*py, "bridge", *common, "--wire", opts.wire, *ns_args,
                                      *(["--protocol", proto] if proto else [])], env, log_dir / f"{name}.log"))
    if opts.record is not None:
        children.append(_Child("recorder", [*py, "record", str(opts.record), "--generated", str(gen_dir),
                                            "--iface", opts.iface, "--dronecan-iface", opts.dronecan_iface,
                                            *ns_args,  # the frame prefix too: the recording keeps both
                                            *(["--layout", opts.layout] if opts.layout else []),
                                            *(["--package", opts.package] if opts.package else [])],
                               env, log_dir / "recorder.log"))
    if hosted:
        gen_args = ["--generated", str(gen_dir)] + (["--package", opts.package] if opts.package else [])
        children.append(_Child("nodes", [*py, "nodes", *gen_args, *(opts.node_args or []), *ns_args], env,
                               log_dir / "nodes.log"))


def _vehicle_up(children: list[_Child], launched: float, opts: RunOptions, say: Any) -> float | None:
    """When every child has said READY: the moment the vehicle is up (now), said once; else None."""
    if not all(c.ready() for c in children):
        return None
    now = time.monotonic()
    say(f"sam-run: vehicle up {now - launched:.1f} s after launch ({', '.join(c.name for c in children)} READY)"
        + ("" if opts.duration is None else f"; --duration {opts.duration:g} s counts from here"))
    return now


def _show_live(live: LiveView, children: list[_Child], tables: Any, opts: RunOptions, stop_reason: list[str],
               say: Any, launched: float) -> tuple[int, float | None]:
    """Step 5 until a stop reason comes (a signal handler, --duration, a child that died or never came up: exit
    code 1). Returns the exit code and how long the vehicle ran (None if it never came up). ``launched``: when
    the first child was started (time.monotonic).

    ``--duration`` counts from the moment the vehicle is up (every child READY), not from the launch: starting the
    processes takes seconds, more on a loaded machine or beside another run's build."""
    exit_code = 0
    tty = sys.stdout.isatty() and not opts.plain
    up: float | None = None
    next_draw = time.monotonic()
    refresh = opts.refresh_s if tty else 1.0
    while not stop_reason:
        if up is None:
            up = _vehicle_up(children, launched, opts, say)
        elapsed = time.monotonic() - up if up is not None else 0.0
        if up is not None and opts.duration is not None and elapsed >= opts.duration:
            stop_reason.append("duration")
            break
        late = [c for c in children if not c.ready()] if up is None else []
        if late and time.monotonic() - launched >= VEHICLE_START_TIMEOUT_S:
            for c in late:
                say(f"sam-run: {c.name} is not READY {VEHICLE_START_TIMEOUT_S:.0f} s after launch; its log ({c.log}):"
                    f"\n{c.tail()}")
            exit_code = 1
            stop_reason.append("vehicle not up")
            break
        dead = [c for c in children if not c.alive()]
        if dead:
            for c in dead:
                say(f"sam-run: {c.name} exited with code {c.proc.returncode}; its log ({c.log}):\n{c.tail()}")
            exit_code = 1
            stop_reason.append("child exited")
            break
        live.spin_for(max(0.0, min(next_draw - time.monotonic(), 0.1)))
        if time.monotonic() >= next_draw:
            next_draw += refresh
            clock = f"t={elapsed:6.1f} s" if up is not None else "starting: waiting for " + ", ".join(
                c.name for c in late)
            header = (f"{tables.VEHICLE} bridge run  {clock}  "
                      + "  ".join(f"{c.name} pid {c.proc.pid}" for c in children)
                      + ("" if opts.duration is None else f"  (stops at {opts.duration:.0f} s)")
                      + ("  Ctrl-C to stop" if tty else ""))
            lines = live.table(header)
            if tty:
                cols = shutil.get_terminal_size((120, 40)).columns
                sys.stdout.write("\x1b[H\x1b[2J" + "\n".join(line[:cols] for line in lines) + "\n")
                sys.stdout.flush()
            else:
                say("\n".join(lines) + "\n")
    return exit_code, None if up is None else time.monotonic() - up


def _report_stopped(children: list[_Child], codes: Mapping[str, int | None], exit_code: int,
                    stop_reason: list[str], say: Any) -> None:
    """Step 6's words: a child that stopped badly (unless the run already said why it ended), and the logs."""
    with contextlib.suppress(OSError):  # the terminal may be gone (SIGHUP): reporting must not fail the stop
        for c in children:
            rc = codes[c.name]
            if rc not in (0, None, -signal.SIGTERM) and exit_code == 0 and (
                    not stop_reason or stop_reason[0] != "child exited"):
                say(f"sam-run: {c.name} stopped with exit code {rc}; log: {c.log}")
        if children:
            say("logs: " + ", ".join(str(c.log) for c in children))


def run(opts: RunOptions) -> int:
    say = _say
    stop_reason: list[str] = []

    def on_signal(signum: int, _frame: Any) -> None:
        stop_reason.append(signal.Signals(signum).name)

    if opts.record is not None:  # an unwritable recording is an error before anything starts
        try:
            opts.record = check_target(opts.record)
        except RecordingTargetError as ex:
            say(f"sam-run: {ex}")
            return 1
    old_handlers = {s: signal.signal(s, on_signal) for s in STOP_SIGNALS}
    children: list[_Child] = []
    live: LiveView | None = None
    log_lock: ProjectLock | None = None
    exit_code = 0
    try:
        prepared = _prepare(opts, say, lambda: bool(stop_reason))
        if isinstance(prepared, int):
            return prepared
        gen_dir, gen = prepared.gen_dir, prepared.gen
        if stop_reason:
            return 0
        env = _children_env(opts, prepared.prefix, gen_dir, old_handlers)
        log_dir, log_lock = claim_log_dir(opts, prepared.state, say)
        tables = gen.tables()
        hosted = implemented(tables) if opts.nodes else []
        missing = unimplemented(tables)
        if opts.nodes and missing:
            say(f"no implementation for node(s) {', '.join(missing)} of the spec"
                + (f"; hosting {', '.join(hosted)}" if hosted else "; demo commands move the actuators"))
        truth = (opts.truth_file or log_dir / "truth.json").resolve()
        launched = time.monotonic()
        _start_children(children, opts, gen_dir, tables, hosted, env, log_dir, truth)
        live = LiveView(tables, gen, window=opts.window, demo_commands=opts.demo_commands, hosted=hosted,
                        truth_file=truth, namespace=opts.namespace)
        exit_code, ran = _show_live(live, children, tables, opts, stop_reason, say, launched)
        final = live.table(f"final ({stop_reason[0] if stop_reason else 'stopped'}) after "
                           + ("the vehicle never came up" if ran is None else f"{ran:.1f} s of the vehicle up"))
        say("\n".join(final))
    finally:
        # Our handlers stay in place until the children are stopped: a second Ctrl-C must not cut the stop short.
        codes = _stop_children(children)
        for s, h in old_handlers.items():
            signal.signal(s, h)
        if log_lock is not None:
            log_lock.release()
        if live is not None:
            with contextlib.suppress(Exception):  # the children are stopped already; nothing else depends on it
                live.close()
        _report_stopped(children, codes, exit_code, stop_reason, say)
    if opts.record is not None and opts.record.is_file():  # the recorder has stopped: its file is whole
        report_picture(opts.record, gen_dir, say)
    return exit_code


def report_picture(recording: Path, gen_dir: Path, say: Any) -> Path | None:
    """The recorded run as one picture beside the recording (<name>.png), with the limits of the generated params
    file; a failure is said, never raised: the run and its recording are done."""
    params = sorted((gen_dir / "params").glob("*.params.yaml"))
    try:
        limits = limits_from_params(params[0]) if params else None
        out = plot_run(recording, recording.with_suffix(".png"), limits=limits)
    except Exception as ex:  # e.g. matplotlib missing, a recording with nothing readable
        say(f"sam-run: no report picture of {recording}: {type(ex).__name__}: {ex}")
        return None
    say(f"report: {out}")
    return out
