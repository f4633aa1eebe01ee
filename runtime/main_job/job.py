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

import collections
import contextlib
import importlib
import math
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from sam_codegen.build import build
from sam_codegen.model.diagnostics import SpecError
from sam_codegen.model.spec import ROS_TO_UAVCAN, UAVCAN_TO_ROS
from sam_codegen.project.cyphal_path import CyphalPathError
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
from sam_runtime.common.ros_namespace import RosNamespace
from sam_runtime.cyphal_io.dsdl_cache import DsdlCompileError
from sam_runtime.genpkg import GeneratedPackage, GeneratedPackageError, ensure_ros_package
from sam_runtime.main_job.demo import demo_message
from sam_runtime.main_job.diag_view import bridge_lines, status_key
from sam_runtime.main_job.vehicle_view import VehicleView
from sam_runtime.nodes import implemented, unimplemented
from sam_runtime.recording.target import RecordingTargetError, check_target
from sam_runtime.report.plot import limits_from_params, plot_run

if TYPE_CHECKING:
    from sam_codegen.targets.python.tables_api import TablesModule

__all__ = ["LiveView", "RunOptions", "run", "summarize_message"]

CHILD_STOP_TIMEOUT_S = 8.0
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


# ============================================================================================ formatting
def _fmt_num(v: Any) -> str:
    if isinstance(v, bool):
        return "T" if v else "F"
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        return f"{v:.4g}"
    return str(v)


def _flatten(msg: Any, prefix: str = "") -> list[tuple[str, Any]]:
    out: list[tuple[str, Any]] = []
    fields = getattr(msg, "get_fields_and_field_types", None)
    if fields is None:
        return out
    for name in fields():
        if name == "header" or "covariance" in name:
            continue
        v = getattr(msg, name)
        if hasattr(v, "get_fields_and_field_types"):
            try:
                if v == type(v)():
                    continue  # a nested message left at its default (e.g. an orientation not provided)
            except Exception:  # pragma: no cover - a type without a default constructor
                pass
            sub = _flatten(v, "")
            if sub and len(sub) <= 4 and all(isinstance(x, int | float) for _, x in sub):
                out.append((prefix + name, "(" + ",".join(_fmt_num(x) for _, x in sub) + ")"))
            else:
                out.extend((f"{prefix}{name}.{k}", x) for k, x in sub)
        elif isinstance(v, str):
            if v:
                out.append((prefix + name, v))
        elif hasattr(v, "__len__") and not isinstance(v, bytes | bytearray):
            seq = list(v)
            if seq and not hasattr(seq[0], "get_fields_and_field_types"):
                shown = ",".join(_fmt_num(x.item() if hasattr(x, "item") else x) for x in seq[:3])
                out.append((prefix + name, f"[{shown}{',...' if len(seq) > 3 else ''}]"))
        else:
            out.append((prefix + name, v.item() if hasattr(v, "item") else v))
    return out


def summarize_message(msg: Any, width: int = 70) -> str:
    """A short one-line view of any ROS message: header and covariances left out, nested vectors as tuples."""
    parts: list[str] = []
    used = 0
    for k, v in _flatten(msg):
        text = f"{k}={_fmt_num(v) if not isinstance(v, str) else v}"
        if used + len(text) + 1 > width:
            parts.append("…")
            break
        parts.append(text)
        used += len(text) + 1
    return " ".join(parts)


# ============================================================================================ live view node
class _TopicState:
    def __init__(self, name: str, direction: str, nominal: float) -> None:
        self.name, self.direction, self.nominal = name, direction, nominal
        self.count = 0
        self.arrivals: collections.deque[float] = collections.deque()
        self.first: float | None = None
        self.last: Any = None

    def on_msg(self, msg: Any) -> None:
        now = time.monotonic()
        self.count += 1
        self.arrivals.append(now)
        if self.first is None:
            self.first = now
        self.last = msg

    def rate(self, window: float) -> float:
        now = time.monotonic()
        while self.arrivals and self.arrivals[0] < now - window:
            self.arrivals.popleft()
        if self.first is None:
            return 0.0
        span = min(window, now - self.first)
        return len(self.arrivals) / span if span > 0.2 else 0.0


class LiveView:
    """An rclpy node subscribing to every bridged topic and to /diagnostics (own context): what the run shows.
    Its ROS node is ``<bridge>_monitor`` (the name it always had)."""

    def __init__(self, tables: TablesModule, gen: Any, *, window: float = 2.0, demo_commands: bool = False,
                 hosted: list[str] | None = None, truth_file: Path | None = None, namespace: Any = None) -> None:
        import rclpy
        from diagnostic_msgs.msg import DiagnosticArray
        from rclpy.node import Node
        from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy
        from rclpy.signals import SignalHandlerOptions

        self.tables, self.window = tables, window
        self.ctx = rclpy.Context()
        rclpy.init(args=[], context=self.ctx, signal_handler_options=SignalHandlerOptions.NO)
        self.namespace = namespace or RosNamespace()
        self.node = Node(f"{tables.BRIDGE_NAME}_monitor", namespace=self.namespace.node_namespace, context=self.ctx)
        best_effort = QoSProfile(depth=50, history=HistoryPolicy.KEEP_LAST, reliability=ReliabilityPolicy.BEST_EFFORT)
        self.topics: dict[str, _TopicState] = {}
        for m in tables.MAPPINGS:
            st = self.topics.get(m.topic.name)
            if st is None:
                st = _TopicState(m.topic.name, "in" if m.direction == UAVCAN_TO_ROS else "out", m.rate_hz)
                self.topics[m.topic.name] = st
                self.node.create_subscription(gen.ros_class(m.topic), m.topic.name, st.on_msg, best_effort)
        self.diagnostics: dict[str, Any] = {}
        self.node.create_subscription(DiagnosticArray, "/diagnostics", self._on_diag, 10)
        self._demo: list[tuple[Any, type, float, str]] = []
        self.demo_published: collections.Counter[str] = collections.Counter()
        self.demo_errors: collections.Counter[str] = collections.Counter()
        self._demo_t0 = time.monotonic()
        hosted = list(hosted or ())
        # The hosted nodes command the actuators: no demo sweep may compete with them on a topic.
        seen = {ep.topic for n in tables.NODES if n.name in hosted for ep in n.publishes}
        self.view = None
        if hosted:
            self.view = VehicleView(self.node, tables, topics=self.topics, diagnostics=self.diagnostics,
                                    hosted=hosted, truth_file=truth_file, frame_prefix=self.namespace.frame_prefix)
        if demo_commands:
            for m in tables.MAPPINGS:
                if m.direction == ROS_TO_UAVCAN and m.topic.name not in seen:
                    seen.add(m.topic.name)
                    cls = gen.ros_class(m.topic)
                    pub = self.node.create_publisher(cls, m.topic.name, 10)
                    rate = m.rate_hz if m.rate_hz and m.rate_hz > 0 else 10.0
                    self._demo.append((pub, cls, rate, m.topic.name))
            for i, (_pub, _cls, rate, _name) in enumerate(self._demo):
                self.node.create_timer(1.0 / rate, lambda i=i: self._publish_demo(i))
        from rclpy.executors import SingleThreadedExecutor

        self.executor = SingleThreadedExecutor(context=self.ctx)
        self.executor.add_node(self.node)

    def _on_diag(self, arr: Any) -> None:
        bridge = str(self.tables.BRIDGE_NAME)
        own = self.namespace.status_name("")  # "" or "sam1/": another vehicle's statuses are not this view's
        for s in arr.status:
            if not s.name.startswith(own):
                continue
            self.diagnostics[status_key(s.name[len(own):], bridge)] = {
                "level": int(s.level[0]) if isinstance(s.level, bytes | bytearray) else int(s.level),
                "message": s.message, "hardware_id": s.hardware_id,
                "values": {kv.key: kv.value for kv in s.values}, "at": time.monotonic(),
            }

    def _publish_demo(self, i: int) -> None:
        """One demo command on topic i: every field from its own rosidl type (sam_runtime.main_job.demo), checked by
        rclpy as it is set. A message that cannot be built is counted and logged once, never published."""
        import logging

        pub, cls, _rate, name = self._demo[i]
        try:
            pub.publish(demo_message(cls, time.monotonic() - self._demo_t0, self.node.get_clock().now().to_msg()))
        except Exception as ex:  # a value rclpy refuses (a bug of main_job.demo) or a closing context: never a crash
            self.demo_errors[name] += 1
            if self.demo_errors[name] == 1:
                logging.getLogger("sam_runtime.main_job.job").error("demo command on %s not published: %s: %s", name,
                                                               type(ex).__name__, ex)
            return
        self.demo_published[name] += 1

    def spin_for(self, seconds: float) -> None:
        deadline = time.monotonic() + seconds
        while True:
            left = deadline - time.monotonic()
            if left <= 0:
                return
            self.executor.spin_once(timeout_sec=min(left, 0.05))

    def close(self) -> None:
        try:
            self.executor.shutdown(timeout_sec=1.0)
            self.node.destroy_node()
        finally:
            if self.ctx.ok():
                self.ctx.shutdown()

    # ---------------------------------------------------------------------------------- table
    def table(self, header: str) -> list[str]:
        bridge = self.tables.BRIDGE_NAME or ""
        drops_by_topic: dict[str, int] = collections.Counter()
        for name, d in self.diagnostics.items():
            if name.startswith(f"{bridge}/mapping/"):
                v = d["values"]
                drops_by_topic[v.get("topic", "?")] += int(v.get("dropped", "0") or 0)
        lines = [header, ""]
        if self.view is not None:
            lines += [*self.view.lines(), ""]
        lines.append(f"{'TOPIC':32} {'DIR':3} {'RATE Hz':>8} {'NOMINAL':>7} {'COUNT':>7} {'DROPS':>5}  LAST VALUE")
        for st in self.topics.values():
            last = summarize_message(st.last, 60) if st.last is not None else "-"
            lines.append(f"{st.name:32} {st.direction:3} {st.rate(self.window):8.1f} {st.nominal:7.0f} "
                         f"{st.count:7d} {drops_by_topic.get(st.name, 0):5d}  {last}")
        lines.append("")
        lines.append(f"{'DEVICE':22} {'NODE':>4} {'HEARTBEAT':>10} {'HEALTH':9} {'MODE':12} STATUS")
        now = time.monotonic()
        for d in self.tables.DEVICES:
            diag = self.diagnostics.get(f"{bridge}/device/{d.name}")
            if diag is None:
                lines.append(f"{d.name:22} {d.node_id:4d} {'-':>10} {'-':9} {'-':12} waiting for the bridge")
                continue
            v = diag["values"]
            age = v.get("age_s")
            age_txt = f"{float(age) + (now - diag['at']):.1f} s" if age not in (None, "") else "never"
            status = "ok" if diag["level"] == 0 else diag["message"]
            lines.append(f"{d.name:22} {d.node_id:4d} {age_txt:>10} {v.get('health', '-'):9} "
                         f"{v.get('mode', '-'):12} {status}")
        warnings = []  # mappings not OK: recent drops, or silent while their device is alive
        for n, d in sorted(self.diagnostics.items()):
            if n.startswith(f"{bridge}/mapping/") and d["level"] != 0:
                why = ", ".join(f"{k}={x}" for k, x in d["values"].items() if k.startswith("dropped."))
                warnings.append(f"{n.split('/')[-1]}: {d['message']}" + (f" ({why})" if why else ""))
        lines.append("")
        lines.extend(bridge_lines(self.diagnostics, bridge))
        lines.extend("  warn " + x for x in warnings)
        return lines


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


def _build(spec: Path, gen_dir: Path, say: Any) -> None:
    stale = build(spec, gen_dir, check=False)
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


def _prepare(opts: RunOptions, say: Any) -> _Prepared | int:
    """Steps 1-3 of the run (build, ROS package, DSDL); an exit code where one fails (said, never raised)."""
    try:
        ws = _workspace(opts)
        gen_dir = ws.generated
        if opts.build:
            _build(ws.spec, gen_dir, say)
        state = ensure_state_dir(ws)
        gen = GeneratedPackage(gen_dir, opts.package)
        prefix = ensure_ros_package(gen, opts.ros_prefix, log=say, build_root=state / "ros-build")
        importlib.invalidate_caches()  # a package installed just now into this venv
        gen.compile_dsdl()
    except SpecError as ex:
        say(f"sam-run: the spec is invalid:\n{ex}")
        return 1
    except (WorkspaceError, CyphalPathError, GeneratedPackageError, DsdlCompileError) as ex:
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
                                            *ns_args[:2],
                                            *(["--layout", opts.layout] if opts.layout else []),
                                            *(["--package", opts.package] if opts.package else [])],
                               env, log_dir / "recorder.log"))
    if hosted:
        gen_args = ["--generated", str(gen_dir)] + (["--package", opts.package] if opts.package else [])
        children.append(_Child("nodes", [*py, "nodes", *gen_args, *(opts.node_args or []), *ns_args], env,
                               log_dir / "nodes.log"))


def _show_live(live: LiveView, children: list[_Child], tables: Any, opts: RunOptions, stop_reason: list[str],
               say: Any) -> int:
    """Step 5 until a stop reason comes (a signal handler, --duration, a child that died: exit code 1).
    Returns the exit code."""
    exit_code = 0
    tty = sys.stdout.isatty() and not opts.plain
    started = time.monotonic()
    next_draw = started
    refresh = opts.refresh_s if tty else 1.0
    while not stop_reason:
        elapsed = time.monotonic() - started
        if opts.duration is not None and elapsed >= opts.duration:
            stop_reason.append("duration")
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
            header = (f"{tables.VEHICLE} bridge run  t={elapsed:6.1f} s  "
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
    return exit_code


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
    exit_code = 0
    try:
        prepared = _prepare(opts, say)
        if isinstance(prepared, int):
            return prepared
        gen_dir, gen = prepared.gen_dir, prepared.gen
        if stop_reason:
            return 0
        env = _children_env(opts, prepared.prefix, gen_dir, old_handlers)
        log_dir = (opts.log_dir or prepared.state / "run-logs").resolve()
        tables = gen.tables()
        hosted = implemented(tables) if opts.nodes else []
        missing = unimplemented(tables)
        if opts.nodes and missing:
            say(f"no implementation for node(s) {', '.join(missing)} of the spec"
                + (f"; hosting {', '.join(hosted)}" if hosted else "; demo commands move the actuators"))
        truth = (opts.truth_file or log_dir / "truth.json").resolve()
        _start_children(children, opts, gen_dir, tables, hosted, env, log_dir, truth)
        live = LiveView(tables, gen, window=opts.window, demo_commands=opts.demo_commands, hosted=hosted,
                        truth_file=truth, namespace=opts.namespace)
        started = time.monotonic()
        exit_code = _show_live(live, children, tables, opts, stop_reason, say)
        final = live.table(f"final ({stop_reason[0] if stop_reason else 'stopped'}) after "
                           f"{time.monotonic() - started:.1f} s")
        say("\n".join(final))
    finally:
        # Our handlers stay in place until the children are stopped: a second Ctrl-C must not cut the stop short.
        codes = _stop_children(children)
        for s, h in old_handlers.items():
            signal.signal(s, h)
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
