"""Fault-injection scenarios for tests/test_faults.py (issue 4). Each runs in this helper process so that rclpy,
pycyphal and python-can never outlive the test; the result (figures per phase) is written as JSON.

python fault_scenario.py udp --out OUT.json
    The bridge (Cyphal/UDP on 127.0.0.1) and an rclpy probe here; tests/helpers/fault_injector.py in a child
    process plays the IMU (node 11) and a spoofer (node 42) with raw datagrams: valid, spoofed, malformed,
    truncated, undecodable, reordered/duplicated, out-of-order stamps, float16 limits, and two bursts of 5000.
python fault_scenario.py can --iface virtual:NAME --out OUT.json
    The bridge, every simulated device and the probe on one python-can virtual CAN FD bus in this process;
    the bridge's CAN media goes through a fault-injecting wrapper of its python-can bus. Phases: out-of-range
    commands, a slow ROS subscriber (tests/helpers/slow_subscriber.py, own process), transient bus errors,
    the interface going down and coming back, a device whose heartbeat stops and resumes, /diagnostics content.
"""

from __future__ import annotations

import os

os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")

import argparse
import asyncio
import errno
import json
import math
import statistics
import subprocess
import sys
import threading
import time
from collections import Counter, defaultdict
from collections.abc import Callable
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))
from ros_probe import ThreadedProbe
from settling import until_stable

HERE = Path(__file__).resolve().parent
BRIDGE = "uavcan_ros_bridge"


async def wait_for(cond: Callable[[], Any], timeout: float, what: str, interval: float = 0.02) -> Any:
    """Poll ``cond``; ``timeout`` is a hang guard (the phases' timing is judged from what the system reports and
    the measured loop stalls, not from how long a wait took: a loaded machine may stall the loop for seconds)."""
    deadline = time.monotonic() + timeout
    while True:
        value = cond()
        if value:
            return value
        if time.monotonic() > deadline:
            raise TimeoutError(f"timed out after {timeout} s waiting for {what}")
        await asyncio.sleep(interval)


async def try_wait_for(cond: Callable[[], Any], timeout: float, what: str) -> bool:
    try:
        await wait_for(cond, timeout, what)
        return True
    except TimeoutError as ex:
        print(f"NOTE {ex}", flush=True)
        return False


def _level(st: Any) -> int:
    return st.level[0] if isinstance(st.level, bytes | bytearray) else int(st.level)


class Probe(ThreadedProbe):
    """Counts the bridged topics (optionally records /imu), keeps the latest /diagnostics status per name and
    every level change, publishes commands."""

    node_name = "test_fault_probe"

    def setup(self) -> None:
        from diagnostic_msgs.msg import DiagnosticArray

        self.counts: Counter[str] = Counter()
        self.recording = False
        self.records: list[dict[str, Any]] = []
        self.latency_ms: list[float] | None = None
        self.diag_latest: dict[str, dict[str, Any]] = {}
        # level changes: {"t": monotonic, "name", "level", "message", "values"}
        self.diag_events: list[dict[str, Any]] = []
        self.diag_messages = 0
        self.node.create_subscription(DiagnosticArray, "/diagnostics", self._on_diag, 50)

    def on_message(self, topic: str, msg: Any) -> None:
        self._on_msg(topic, msg)

    def _on_msg(self, topic: str, msg: Any) -> None:
        self.counts[topic] += 1
        if topic == "/imu":
            stamp = msg.header.stamp.sec * 10**9 + msg.header.stamp.nanosec
            now = time.time_ns()
            if self.latency_ms is not None:
                self.latency_ms.append((now - stamp) / 1e6)
            if self.recording:
                av, la = msg.angular_velocity, msg.linear_acceleration
                self.records.append({"stamp_ns": stamp, "recv_wall_ns": now, "gyro": [av.x, av.y, av.z],
                                     "acc": [la.x, la.y, la.z], "frame_id": msg.header.frame_id})

    def _on_diag(self, arr: Any) -> None:
        self.diag_messages += 1
        now = time.monotonic()
        for st in arr.status:
            level = _level(st)
            values = {kv.key: kv.value for kv in st.values}
            prev = self.diag_latest.get(st.name)
            if prev is None or prev["level"] != level:
                self.diag_events.append({"t": now, "name": st.name, "level": level, "message": st.message,
                                         "values": values})
            self.diag_latest[st.name] = {"level": level, "message": st.message, "t": now, "values": values}

    def level(self, name: str) -> int | None:
        d = self.diag_latest.get(name)
        return None if d is None else d["level"]



def delta(before: dict[str, Any], after: dict[str, Any]) -> dict[str, Any]:
    """after - before for the counters of a mapping's stats entry (nested dicts of ints)."""
    out: dict[str, Any] = {}
    for k, v in after.items():
        b = before.get(k)
        if isinstance(v, bool) or v is None or k.endswith("_age_s"):
            continue
        if isinstance(v, int | float):
            if isinstance(b, int | float) and not isinstance(b, bool):
                d = v - b
                if d:
                    out[k] = d
            elif b is None and v:
                out[k] = v
        elif isinstance(v, dict):
            d = delta(b if isinstance(b, dict) else {}, v)
            if d:
                out[k] = d
    return out


def clean(o: Any) -> Any:
    if isinstance(o, float) and not math.isfinite(o):
        return repr(o)
    if isinstance(o, dict):
        return {str(k): clean(v) for k, v in o.items()}
    if isinstance(o, list | tuple):
        return [clean(x) for x in o]
    return o


def log_lines(bridge: Any) -> dict[str, int]:
    return {f"{k[0]}|{k[1]}": v for k, v in sorted(bridge.log.lines.items())}


# ============================================================================================ UDP
class InjectorProc:
    def __init__(self, generated: Path) -> None:
        self.proc = subprocess.Popen([sys.executable, str(HERE / "fault_injector.py"), "--generated", str(generated)],
                                     stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)

    def expect(self, prefix: str) -> str:
        assert self.proc.stdout is not None
        while True:
            line = self.proc.stdout.readline()
            if not line:
                raise RuntimeError(f"the injector exited (code {self.proc.poll()}) before {prefix!r}")
            if line.startswith(prefix):
                return line[len(prefix):].strip()

    def command(self, cmd: str) -> dict[str, Any]:
        assert self.proc.stdin is not None
        self.proc.stdin.write(cmd + "\n")
        self.proc.stdin.flush()
        return json.loads(self.expect("DONE "))

    def close(self) -> None:
        try:
            if self.proc.poll() is None and self.proc.stdin is not None:
                self.proc.stdin.write("quit\n")
                self.proc.stdin.flush()
            self.proc.wait(timeout=10)
        except (OSError, subprocess.TimeoutExpired):
            self.proc.kill()
            self.proc.wait(timeout=5)


async def udp_phase(bridge: Any, probe: Probe, inj: InjectorProc, cmd: str) -> dict[str, Any]:
    loop = asyncio.get_running_loop()
    before = bridge.stats()["mappings"]["imu"]
    ros_before = probe.counts["/imu"]
    t0 = time.monotonic()
    res = await loop.run_in_executor(None, inj.command, cmd)
    sent_total = sum(res["sent"].values())

    def accounted() -> bool:
        d = delta(before, bridge.stats()["mappings"]["imu"])
        return d.get("published", 0) + d.get("dropped_total", 0) >= sent_total

    settled = await try_wait_for(accounted, 60, f"{cmd}: every transfer published or counted")
    after = bridge.stats()["mappings"]["imu"]
    d = delta(before, after)
    await try_wait_for(lambda: probe.counts["/imu"] - ros_before >= d.get("published", 0), 15,
                       f"{cmd}: the probe's copies")
    return {
        "command": cmd, "injector": res, "settled": settled, "seconds": round(time.monotonic() - t0, 3),
        "sent": res["sent"], "sent_total": sent_total,
        "received": d.get("received", 0), "published": d.get("published", 0),
        "dropped": d.get("dropped", {}), "dropped_total": d.get("dropped_total", 0),
        "out_of_order": d.get("out_of_order", 0), "cyphal": d.get("cyphal", {}),
        "ros_received": probe.counts["/imu"] - ros_before,
    }


async def main_udp(args: argparse.Namespace) -> dict[str, Any]:
    from sam_runtime.bridge import Bridge, TransportConfig
    from sam_runtime.genpkg import GeneratedPackage

    gen = GeneratedPackage()
    gen.compile_dsdl()
    bridge = Bridge(gen, transport=TransportConfig("udp", "127.0.0.1"), log_interval=args.log_interval)
    await bridge.start()
    probe = Probe(gen, ["/imu"], [], depth=20000)
    inj = InjectorProc(gen.root)
    result: dict[str, Any] = {"transport": bridge.transport_config.describe(), "log_interval": args.log_interval}
    try:
        await wait_for(lambda: probe.node.count_publishers("/imu") > 0
                       and (bridge.stats()["mappings"]["imu"]["ros_subscribers"] or 0) > 0, 20, "ROS discovery")
        await asyncio.get_running_loop().run_in_executor(None, inj.expect, "READY")
        phases: dict[str, Any] = {}
        for name, cmd in (("warmup", "valid 20 11 200"), ("spoof", "spoof 50"), ("malformed", "malformed"),
                          ("undecodable", "undecodable 20"), ("reorder", "reorder")):
            phases[name] = await udp_phase(bridge, probe, inj, cmd)
        probe.records.clear()
        probe.recording = True
        wall0 = time.time_ns()
        phases["stamps"] = await udp_phase(bridge, probe, inj, "stamps")
        probe.recording = False
        phases["stamps"]["records"] = list(probe.records)
        phases["stamps"]["wall_window_ns"] = [wall0, time.time_ns()]
        for name, cmd in (("burst_max", "burst 5000"), ("burst_paced", "burst 5000 3000")):
            phases[name] = await udp_phase(bridge, probe, inj, cmd)
        result["phases"] = phases
        # /diagnostics of the latest period, after everything above.
        n0 = probe.diag_messages
        await try_wait_for(lambda: probe.diag_messages >= n0 + 2, 5, "two more /diagnostics messages")
        result["diagnostics"] = probe.diag_latest
        result["bridge"] = bridge.stats()
        result["log_lines"] = log_lines(bridge)
    finally:
        inj.close()
        probe.close()
        await bridge.close()
    return result


def _rss_kb() -> int:
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1])
    return 0


def _imu_port(bridge: Any) -> Any:
    rx = bridge.backend._loop_rx  # the bridge's Cyphal/UDP receiver (a test reads its counters)
    return next(p for p in rx.ports if p.subject_id == 1100)


def _port_counts(port: Any) -> dict[str, Any]:
    # (getattr: the same scenario measures the receiver before issue 29, which had no refusals or slots to count)
    return {"frames": port.frames, "own_frames": getattr(port, "own_frames", 0),
            "refused": dict(getattr(port, "refused", {})), "errors": port.errors,
            "partial_transfers": getattr(port, "partial_transfers", len(getattr(port, "_sources", ())))}


async def main_udp_hostile(args: argparse.Namespace) -> dict[str, Any]:
    """Issue 29: a hostile sender beside the real IMU (node 11, 100 Hz), one junk kind per phase."""
    from sam_runtime.bridge import Bridge, TransportConfig
    from sam_runtime.genpkg import GeneratedPackage

    gen = GeneratedPackage()
    gen.compile_dsdl()
    bridge = Bridge(gen, transport=TransportConfig("udp", "127.0.0.1"), log_interval=args.log_interval)
    await bridge.start()
    probe = Probe(gen, ["/imu"], [], depth=20000)
    inj = InjectorProc(gen.root)
    result: dict[str, Any] = {}
    try:
        await wait_for(lambda: probe.node.count_publishers("/imu") > 0
                       and (bridge.stats()["mappings"]["imu"]["ros_subscribers"] or 0) > 0, 20, "ROS discovery")
        await asyncio.get_running_loop().run_in_executor(None, inj.expect, "READY")
        await udp_phase(bridge, probe, inj, "valid 20 11 200")
        st0 = bridge.stats()
        phases: dict[str, Any] = {}
        for kind in args.kinds.split(","):
            port = _imu_port(bridge)
            before, rss0 = _port_counts(port), _rss_kb()
            errors0 = dict(bridge.stats()["bridge"]["errors"])
            ph = await udp_phase(bridge, probe, inj, f"hostile {kind} {args.steps}")
            ph["port_before"], ph["port_after"] = before, _port_counts(port)
            ph["rss_kb"] = [rss0, _rss_kb()]
            errors1 = bridge.stats()["bridge"]["errors"]
            ph["bridge_errors"] = {k: v - errors0.get(k, 0) for k, v in errors1.items() if v != errors0.get(k, 0)}
            phases[kind] = ph
        result["phases"] = phases
        st1 = bridge.stats()
        result["commands_published"] = {
            name: st1["mappings"][name]["published"] - st0["mappings"][name]["published"]
            for name, m in st1["mappings"].items() if m["direction"] != "uavcan_to_ros"}
        result["bridge"] = st1
    finally:
        inj.close()
        probe.close()
        await bridge.close()
    return result


# ============================================================================================ CAN
class FaultPlan:
    """What the bridge's CAN interface does now: ``transient`` (send raises ENOBUFS, receive raises a python-can
    CanOperationError: the media survive) or ``down`` (ENETDOWN everywhere, opening fails: the media die)."""

    def __init__(self) -> None:
        self.mode: str | None = None
        self.counts: Counter[str] = Counter()
        self.times: defaultdict[str, list[float]] = defaultdict(list)  # when each was injected (monotonic)
        self.lock = threading.Lock()

    def _count(self, key: str) -> None:
        with self.lock:
            self.counts[key] += 1
            self.times[key].append(time.monotonic())

    def first(self, keys: tuple[str, ...], since: float) -> float | None:
        """When the first of ``keys`` happened at or after ``since``."""
        with self.lock:
            return min((t for k in keys for t in self.times[k] if t >= since), default=None)

    def send_error(self) -> BaseException | None:
        if self.mode == "transient":
            self._count("send_ENOBUFS")
            return OSError(errno.ENOBUFS, "No buffer space available (injected CAN fault)")
        if self.mode == "down":
            self._count("send_ENETDOWN")
            return OSError(errno.ENETDOWN, "Network is down (injected CAN fault)")
        return None

    def recv_error(self) -> BaseException | None:
        import can

        if self.mode == "transient":
            self._count("recv_CanOperationError")
            return can.CanOperationError("bus error (injected CAN fault)")
        if self.mode == "down":
            self._count("recv_ENETDOWN")
            return OSError(errno.ENETDOWN, "Network is down (injected CAN fault)")
        return None

    def open_error(self) -> BaseException | None:
        if self.mode == "down":
            self._count("open_ENETDOWN")
            return OSError(errno.ENETDOWN, "Network is down (injected CAN fault)")
        return None


class FaultyBus:
    """Wraps the python-can bus inside pycyphal's PythonCANMedia: recv/send raise while the plan says so."""

    def __init__(self, bus: Any, plan: FaultPlan) -> None:
        self._bus = bus
        self._plan = plan

    def recv(self, timeout: float | None = None) -> Any:
        err = self._plan.recv_error()
        if err is not None:
            time.sleep(min(timeout or 0.0, 0.05))
            raise err
        return self._bus.recv(timeout)

    def send(self, msg: Any, timeout: float | None = None) -> Any:
        err = self._plan.send_error()
        if err is not None:
            raise err
        return self._bus.send(msg, timeout)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._bus, name)


def faulty_can_factory(iface: str, mtu: int, plan: FaultPlan) -> Callable[[int], Any]:
    def faulty_can(node_id: int) -> Any:
        from pycyphal.transport.can import CANTransport
        from pycyphal.transport.can.media.pythoncan import PythonCANMedia

        plan._count("open_attempt")
        err = plan.open_error()
        if err is not None:
            raise err
        media = PythonCANMedia(iface, (1_000_000, 4_000_000) if mtu > 8 else 1_000_000, mtu)
        media._bus = FaultyBus(media._bus, plan)  # the media's own threads read/write through the wrapper
        plan._count("opened")
        return CANTransport(media, node_id)

    return faulty_can


def sim_sent(sim: Any, subject: int) -> int:
    return sum(pp.sent for d in sim.devices for pp in d.pubs if pp.port.subject_id == subject)


def sim_accepted(sim: Any, subject: int) -> int:
    return sum(sp.accepted for d in sim.devices for sp in d.subs if sp.port.subject_id == subject)


def sim_last(sim: Any, subject: int) -> Any:
    return next((sp.last for d in sim.devices for sp in d.subs if sp.port.subject_id == subject), None)


IN_SUBJECTS = {"imu": 1100, "magnetic_field": 1101, "gps_fix": 1102, "pressure": 1103, "battery_state": 1104,
               "battery_info": 1104, "thruster_1_feedback": 1300, "thruster_2_feedback": 1301,
               "thrust_vector_feedback": 1302, "longitudinal_weight_feedback": 1304,
               "buoyancy_piston_feedback": 1305}


class LoopLag:
    """Measures how late the asyncio loop runs a 10 ms timer (stalls of the loop the bridge shares): the largest per
    phase (``take``), and every stall of more than STALL_S with the time it ended (``stalls``, monotonic), so that a
    report can be set against the stalls around it."""

    STALL_S = 0.02

    def __init__(self) -> None:
        self.max_ms = 0.0
        self.over_50ms = 0
        self.stalls: list[tuple[float, float]] = []  # (monotonic time the late timer ran, how late [s])
        self._task = asyncio.create_task(self._run())

    async def _run(self) -> None:
        while True:
            t = time.monotonic()
            await asyncio.sleep(0.01)
            now = time.monotonic()
            lag = now - t - 0.01
            self.max_ms = max(self.max_ms, lag * 1000)
            self.over_50ms += lag > 0.05
            if lag > self.STALL_S:
                self.stalls.append((round(now, 4), round(lag, 4)))

    def take(self) -> dict[str, Any]:
        out = {"loop_lag_max_ms": round(self.max_ms, 1), "loop_stalls_over_50ms": self.over_50ms}
        self.max_ms, self.over_50ms = 0.0, 0
        return out

    def stop(self) -> None:
        self._task.cancel()


class HeartbeatSends:
    """When each simulated device sent its heartbeats (monotonic, as the device's own heartbeat publisher calls
    its pre-heartbeat handlers): what the device really sent, to set a bridge's "heartbeat lost" against."""

    def __init__(self) -> None:
        self.times: defaultdict[str, list[float]] = defaultdict(list)
        self._watched: list[Any] = []  # the nodes hooked (kept: a new node is never mistaken for an old one)

    def watch(self, sim: Any) -> None:
        """Hook every powered device's current node (again after a power cycle: a new node)."""
        for dev in sim.devices:
            node = dev.node
            if node is None or any(n is node for n in self._watched):
                continue
            self._watched.append(node)
            times = self.times[dev.info.name]
            node.heartbeat_publisher.add_pre_heartbeat_handler(lambda times=times: times.append(time.monotonic()))

    def count(self, name: str) -> int:
        return len(self.times[name])


def sim_late(sim: Any, subject: int | None = None) -> int:
    """Ticks the simulated devices skipped because the shared event loop was late (they did not send then)."""
    return sum(pp.late for d in sim.devices for pp in d.pubs if subject is None or pp.port.subject_id == subject)


async def settle(bridge: Any, probe: Probe | None, stable_s: float = 0.3, timeout: float = 5.0) -> None:
    """Wait (deadline) until the bridge's and the probe's counters stop moving: every transfer in flight handled."""
    def snap() -> tuple[Any, ...]:
        st = bridge.stats()["mappings"]
        return (tuple((m["received"], m["published"], m["dropped_total"]) for m in st.values()),
                tuple(sorted(probe.counts.items())) if probe is not None else ())

    await until_stable(snap, stable_s, timeout)


async def sensor_window(bridge: Any, sim: Any, probe: Probe | None, body: Callable[[], Any]) -> dict[str, Any]:
    """Run ``body`` (a coroutine function) between two quiet points (the simulated devices paused, nothing in
    flight) and report, per UAVCAN->ROS mapping, what the devices sent, what the bridge received, published and
    dropped (by reason), and what stays unaccounted (sent - published - dropped)."""
    await sim.pause()
    await settle(bridge, probe)
    sent0 = {m: sim_sent(sim, s) for m, s in IN_SUBJECTS.items()}
    late0 = sim_late(sim)
    late_by0 = {m: sim_late(sim, s) for m, s in IN_SUBJECTS.items()}
    st0 = bridge.stats()["mappings"]
    ros0 = dict(probe.counts) if probe is not None else {}
    sim.resume()
    extra = await body()
    await sim.pause()
    await settle(bridge, probe)
    st1 = bridge.stats()["mappings"]
    per = {}
    for m in IN_SUBJECTS:
        d = delta(st0[m], st1[m])
        sent = sim_sent(sim, IN_SUBJECTS[m]) - sent0[m]
        per[m] = {"sent": sent, "received": d.get("received", 0), "published": d.get("published", 0),
                  "dropped": d.get("dropped", {}),
                  "unaccounted": sent - d.get("published", 0) - d.get("dropped_total", 0),
                  "sim_late_ticks": sim_late(sim, IN_SUBJECTS[m]) - late_by0[m]}
        if d.get("cyphal", {}).get("errors"):
            per[m]["cyphal_errors"] = d["cyphal"]["errors"]
    out: dict[str, Any] = {"mappings": per, "sim_late_ticks": sim_late(sim) - late0}
    if probe is not None:
        out["ros_received"] = {t: probe.counts[t] - ros0.get(t, 0) for t in probe.counts}
    sim.resume()
    if extra:
        out.update(extra)
    return out


async def main_can(args: argparse.Namespace) -> dict[str, Any]:
    from sam_runtime.bridge import Bridge, TransportConfig
    from sam_runtime.genpkg import GeneratedPackage
    from sam_runtime.sim.simulator import SimConfig, Simulator

    gen = GeneratedPackage()
    gen.compile_dsdl()
    tables = gen.tables()
    plan = FaultPlan()
    bridge = Bridge(gen, transport=TransportConfig("custom", factory=faulty_can_factory(args.iface, args.mtu, plan)),
                    log_interval=args.log_interval)
    await bridge.start()
    sim = Simulator(gen, SimConfig("can", args.iface, args.mtu))
    await sim.start()
    heartbeats = HeartbeatSends()
    heartbeats.watch(sim)
    lag = LoopLag()  # from here on: the stalls of the loop the devices and the bridge share, start-up included
    in_topics = sorted({m.topic.name for m in tables.MAPPINGS if m.direction == "uavcan_to_ros"})
    out_topics = sorted({m.topic.name for m in tables.MAPPINGS if m.direction == "ros_to_uavcan"})
    probe = Probe(gen, in_topics, out_topics)
    slow: SlowSubscriber | None = None
    result: dict[str, Any] = {"iface": args.iface, "mtu": args.mtu, "transport": bridge.transport_config.describe()}
    try:
        in_maps = [m for m in tables.MAPPINGS if m.direction == "uavcan_to_ros"]
        await wait_for(lambda: all(probe.node.count_publishers(t) > 0 for t in in_topics)
                       and all((bridge.stats()["mappings"][m.name]["ros_subscribers"] or 0) > 0 for m in in_maps)
                       and all(p.get_subscription_count() > 0 for p in probe.pubs.values()), 20, "ROS discovery")
        await wait_for(lambda: all(d["alive"] for d in bridge.stats()["devices"].values()), 10, "heartbeats")
        # (The bridge reports every second; a start-up stall of the shared loop may show a device lost first.)
        await wait_for(lambda: all(probe.level(f"{BRIDGE}/device/{d.name}") == 0 for d in tables.DEVICES), 30,
                       "every device OK on /diagnostics")
        # The baseline of the phases: every device OK on /diagnostics. What the probe saw before it depends on
        # when its subscription matched: a /diagnostics message published before a device's first heartbeat
        # reached the bridge rightly shows that device STALE (never heard).
        result["diag_events_baseline"] = len(probe.diag_events)
        sim.start_publishing()
        lag.take()
        phases: dict[str, Any] = {}
        phases["commands"] = await can_commands(bridge, sim, probe)
        phases["commands"].update(lag.take())
        slow, phases["slow_subscriber"] = await can_slow_subscriber(bridge, sim, probe, args)
        phases["slow_subscriber"].update(lag.take())
        phases["bus_errors_transient"] = await can_transient(bridge, sim, probe, plan)
        phases["bus_errors_transient"].update(lag.take())
        phases["interface_down"] = await can_down(bridge, sim, probe, plan)
        phases["interface_down"].update(lag.take())
        phases["heartbeat"] = await can_heartbeat(bridge, sim, probe, heartbeats)
        phases["heartbeat"].update(lag.take())
        result["final"] = await final_report(bridge, probe, heartbeats, [d.name for d in tables.DEVICES])
        result["final"].update(lag.take())
        lag.stop()
        result["phases"] = phases
        result["diagnostics"] = result["final"].pop("diagnostics")
        result["diag_events"] = probe.diag_events
        result["heartbeat_sends"] = dict(heartbeats.times)
        result["loop_stalls"] = lag.stalls
        result["bridge"] = bridge.stats()
        result["sim"] = sim.report()
        result["plan"] = dict(plan.counts)
        result["log_lines"] = log_lines(bridge)
    finally:
        if slow is not None:
            slow.stop()
        probe.close()
        await sim.close()
        await bridge.close()
    return result


async def final_report(bridge: Any, probe: Probe, heartbeats: HeartbeatSends, devices: list[str],
                       enough: int = 5) -> dict[str, Any]:
    """The /diagnostics the test reads at the end: a report in which every device carries a heartbeat the bridge
    handled after the phases (its ``heartbeats`` value beyond the count now) and is OK. A device whose report is not
    OK then was not heard for 3 s: the shared loop stalled, or the device was starved. The wait for a better report
    is bounded by the devices' own heartbeats (``enough`` sent by each since now), not by a clock."""
    names = {d: f"{BRIDGE}/device/{d}" for d in devices}
    handled0 = {d: bridge.stats()["devices"][d]["heartbeats"] for d in devices}
    sent0 = {d: heartbeats.count(d) for d in devices}

    def reported_ok(d: str, latest: dict[str, Any] | None = None) -> bool:
        st = (probe.diag_latest if latest is None else latest).get(names[d]) or {}
        return st.get("level") == 0 and int(st.get("values", {}).get("heartbeats", 0)) > handled0[d]

    def enough_heard() -> bool:
        return all(heartbeats.count(d) - sent0[d] >= enough for d in devices)

    t0 = time.monotonic()
    n0 = probe.diag_messages
    # (A hang guard only: each device sends a heartbeat a second while this loop runs.)
    await try_wait_for(lambda: (all(reported_ok(d) for d in devices) and probe.diag_messages > n0)
                       or enough_heard(), 120, "every device OK on /diagnostics with a heartbeat after the phases")
    latest = dict(probe.diag_latest)  # the probe's thread replaces entries: one consistent copy, judged as is
    return {"diagnostics": latest, "all_ok": all(reported_ok(d, latest) for d in devices),
            "waited_s": round(time.monotonic() - t0, 3),
            "heartbeats_sent": {d: heartbeats.count(d) - sent0[d] for d in devices}}


async def can_commands(bridge: Any, sim: Any, probe: Probe) -> dict[str, Any]:
    """ROS -> UAVCAN values out of range, through the running bridge."""
    subjects = {"thruster_1_rpm": 1200, "thruster_2_rpm": 1201, "thrust_vector": 1202, "ballast": 1203,
                "longitudinal_weight": 1204, "buoyancy_piston": 1205}
    acc0 = {m: sim_accepted(sim, s) for m, s in subjects.items()}
    st0 = bridge.stats()["mappings"]
    sent = [
        ("/thruster_rpms", {"thruster_1_rpm": 200_000, "thruster_2_rpm": -200_000}),
        ("/thruster_angles", {"thruster_vertical_radians": math.inf, "thruster_horizontal_radians": -math.inf}),
        # NaN is no setpoint: this one is dropped (not_a_number, issue 29); the next one's 1e6 saturates to the limit
        ("/ballast_angles", {"weight_1_offset_radians": math.nan, "weight_2_offset_radians": 0.0}),
        ("/ballast_angles", {"weight_1_offset_radians": 0.5, "weight_2_offset_radians": 1e6}),
        ("/longitudinal_weight_position", {"percent": math.nan}),
        ("/buoyancy_piston_position", {"percent": 150.0}),
    ]
    for topic, values in sent:
        probe.publish(topic, values)
    want = {"thruster_1_rpm": 1, "thruster_2_rpm": 1, "thrust_vector": 1, "ballast": 1, "buoyancy_piston": 1}
    await try_wait_for(lambda: all(sim_accepted(sim, subjects[m]) - acc0[m] >= n for m, n in want.items())
                       and bridge.stats()["mappings"]["longitudinal_weight"]["received"]
                       > st0["longitudinal_weight"]["received"], 10, "the commands at the actuators")
    last = {m: sim_last(sim, s) for m, s in subjects.items()}
    # The mapping that rejected NaN still works: a valid value goes through.
    probe.publish("/longitudinal_weight_position", {"percent": 42.0})
    await try_wait_for(lambda: sim_accepted(sim, 1204) - acc0["longitudinal_weight"] >= 1, 10,
                       "the valid percent command")
    st1 = bridge.stats()["mappings"]
    await try_wait_for(lambda: all(
        probe.diag_latest.get(f"{BRIDGE}/mapping/{m}", {}).get("values", {}).get("received")
        == str(st1[m]["received"]) for m in subjects), 30, "the counters on /diagnostics")
    return {
        "sent": [{"topic": t, "values": v} for t, v in sent] + [
            {"topic": "/longitudinal_weight_position", "values": {"percent": 42.0}}],
        "at_actuators": {m: sim_accepted(sim, s) - acc0[m] for m, s in subjects.items()},
        "last_at_actuator": last, "last_longitudinal_weight": sim_last(sim, 1204),
        "bridge": {m: delta(st0[m], st1[m]) for m in subjects},
        "diagnostics": {m: probe.diag_latest.get(f"{BRIDGE}/mapping/{m}") for m in subjects},
    }


class SlowSubscriber:
    """tests/helpers/slow_subscriber.py in its own process; its COUNT lines are read by a thread."""

    def __init__(self, out: Path, sleep: float, depth: int) -> None:
        self.proc = subprocess.Popen([sys.executable, str(HERE / "slow_subscriber.py"), "--topic", "/imu", "--sleep",
                                      str(sleep), "--depth", str(depth), "--out", str(out)], stdout=subprocess.PIPE,
                                     text=True)
        self.count = -1
        self.ready = threading.Event()
        self._t = threading.Thread(target=self._read, daemon=True)
        self._t.start()

    def _read(self) -> None:
        assert self.proc.stdout is not None
        for line in self.proc.stdout:
            if line.startswith("READY"):
                self.ready.set()
            elif line.startswith("COUNT "):
                self.count = int(line.split()[1])

    def stop(self) -> None:
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait(timeout=5)


async def can_slow_subscriber(bridge: Any, sim: Any, probe: Probe, args: argparse.Namespace
                              ) -> tuple[SlowSubscriber, dict[str, Any]]:
    """A ROS subscriber that sleeps 0.1 s in every /imu callback (keep-last 10) runs while the devices publish at
    their nominal rates: the bridge must go on publishing everything."""
    slow = SlowSubscriber(Path(args.out).with_suffix(".slow.json"), args.slow_sleep, 10)
    await wait_for(slow.ready.is_set, 30, "the slow subscriber's READY")
    await wait_for(lambda: (bridge.stats()["mappings"]["imu"]["ros_subscribers"] or 0) >= 2, 20,
                   "the bridge matching the slow subscriber")
    await wait_for(lambda: slow.count > 0, 10, "the slow subscriber receiving")
    probe.latency_ms = []
    info: dict[str, Any] = {}

    async def window() -> dict[str, Any]:
        info["slow_count0"] = slow.count
        await asyncio.sleep(args.window)  # the measurement window itself (data flows at the nominal rates)
        return {}

    res = await sensor_window(bridge, sim, probe, window)
    lat = probe.latency_ms or [0.0]
    probe.latency_ms = None
    res.update({
        "window_s": args.window, "slow_sleep_s": args.slow_sleep, "slow_depth": 10,
        "slow_received": slow.count - info["slow_count0"],
        "fast_probe_latency_ms": {"median": round(statistics.median(lat), 3), "max": round(max(lat), 3),
                                  "p99": round(statistics.quantiles(lat, n=100)[98], 3) if len(lat) > 2 else None},
    })
    return slow, res


async def can_transient(bridge: Any, sim: Any, probe: Probe, plan: FaultPlan) -> dict[str, Any]:
    """Bus errors for 1 s: sends raise ENOBUFS, receives raise CanOperationError; then they stop."""
    st0 = bridge.stats()
    acc0 = sim_accepted(sim, 1200)
    plan0 = Counter(plan.counts)

    async def body() -> dict[str, Any]:
        plan.mode = "transient"
        t0 = time.monotonic()
        for i in range(5):  # commands during the fault
            probe.publish("/thruster_rpms", {"thruster_1_rpm": 1000 + i, "thruster_2_rpm": 0})
            await asyncio.sleep(max(0.0, t0 + 0.1 * (i + 1) - time.monotonic()))
        await wait_for(lambda: bridge.stats()["mappings"]["thruster_1_rpm"]["received"]
                       >= st0["mappings"]["thruster_1_rpm"]["received"] + 5, 5, "the commands at the bridge")
        await wait_for(lambda: bridge.stats()["mappings"]["thruster_1_rpm"]["queued"] == 0
                       and bridge.stats()["mappings"]["thruster_1_rpm"]["published"]
                       + bridge.stats()["mappings"]["thruster_1_rpm"]["dropped_total"]
                       >= st0["mappings"]["thruster_1_rpm"]["published"]
                       + st0["mappings"]["thruster_1_rpm"]["dropped_total"] + 5, 5, "the commands handled")
        await asyncio.sleep(max(0.0, t0 + 1.0 - time.monotonic()))  # the fault lasts 1 s
        plan.mode = None
        fault_s = time.monotonic() - t0
        for i in range(5):  # commands after it
            probe.publish("/thruster_rpms", {"thruster_1_rpm": 2000 + i, "thruster_2_rpm": 0})
            await asyncio.sleep(0.1)
        await wait_for(lambda: sim_accepted(sim, 1200) >= acc0 + 5, 10, "the commands after the fault")
        return {"fault_s": round(fault_s, 3)}

    res = await sensor_window(bridge, sim, probe, body)
    st1 = bridge.stats()
    res.update({
        "injected": dict(Counter(plan.counts) - plan0),
        "commands": {"sent": 10, "during_fault": 5, "after_fault": 5, "at_actuator": sim_accepted(sim, 1200) - acc0,
                     "last_at_actuator": sim_last(sim, 1200),
                     "bridge": delta(st0["mappings"]["thruster_1_rpm"], st1["mappings"]["thruster_1_rpm"])},
        "link": st1["bridge"]["link"], "bridge_errors": delta(st0["bridge"]["errors"], st1["bridge"]["errors"]),
    })
    return res


async def can_down(bridge: Any, sim: Any, probe: Probe, plan: FaultPlan) -> dict[str, Any]:
    """The interface goes down for 2 s (ENETDOWN: pycyphal's media thread dies and the media closes itself;
    opening fails meanwhile), then comes back: the bridge must reopen its transport."""
    st0 = bridge.stats()
    acc0 = sim_accepted(sim, 1200)
    plan0 = Counter(plan.counts)
    info: dict[str, Any] = {}

    async def body() -> dict[str, Any]:
        plan.mode = "down"
        t0 = time.monotonic()
        await wait_for(lambda: not bridge.stats()["bridge"]["link"]["up"], 30, "the bridge noticing the link down")
        t_seen = time.monotonic()
        info["detected_after_s"] = round(t_seen - t0, 3)
        first = plan.first(("recv_ENETDOWN", "send_ENETDOWN"), t0)  # when pycyphal's media met the fault
        info["detected_after_media_died_s"] = None if first is None else round(t_seen - first, 3)
        await try_wait_for(lambda: probe.level(BRIDGE) == 2, 30, "the bridge at ERROR on /diagnostics")
        info["diag_bridge_level_while_down"] = probe.level(BRIDGE)
        info["diag_bridge_message_while_down"] = (probe.diag_latest.get(BRIDGE) or {}).get("message")
        for i in range(5):  # commands while the interface is down
            probe.publish("/thruster_rpms", {"thruster_1_rpm": 3000 + i, "thruster_2_rpm": 0})
            await asyncio.sleep(0.1)
        await asyncio.sleep(max(0.0, t0 + 2.0 - time.monotonic()))  # down for 2 s
        plan.mode = None
        t_up = time.monotonic()
        await wait_for(lambda: bridge.stats()["bridge"]["link"]["up"], 15, "the bridge reopening its transport")
        info["reopened_after_up_s"] = round(time.monotonic() - t_up, 3)
        with plan.lock:
            after_up = [t for t in plan.times["open_attempt"] if t >= t_up]
        info["open_attempts_after_up"] = len(after_up)
        info["first_attempt_after_up_s"] = round(after_up[0] - t_up, 3) if after_up else None
        pub0 = bridge.stats()["mappings"]["imu"]["published"]
        every0 = {m: x["published"] for m, x in bridge.stats()["mappings"].items() if m in IN_SUBJECTS}
        await wait_for(lambda: bridge.stats()["mappings"]["imu"]["published"] > pub0 + 10, 10, "IMU data again")
        info["data_again_after_up_s"] = round(time.monotonic() - t_up, 3)
        # Every stream once more, the 1 Hz ones too: what the bridge missed while down is counted (from the transfer
        # ids) only when a source's next transfer arrives, which on a loaded machine may be after a short window.
        await wait_for(lambda: all(bridge.stats()["mappings"][m]["published"] > n for m, n in every0.items()), 15,
                       "every sensor's data again")
        await try_wait_for(lambda: probe.level(BRIDGE) == 0, 30, "the bridge OK on /diagnostics")
        info["diag_bridge_level_after"] = probe.level(BRIDGE)
        for i in range(5):  # commands after it
            probe.publish("/thruster_rpms", {"thruster_1_rpm": 4000 + i, "thruster_2_rpm": 0})
            await asyncio.sleep(0.1)
        await wait_for(lambda: sim_accepted(sim, 1200) >= acc0 + 5, 10, "the commands after the outage")
        return {}

    res = await sensor_window(bridge, sim, probe, body)
    st1 = bridge.stats()
    res.update(info)
    res.update({
        "injected": dict(Counter(plan.counts) - plan0),
        "commands": {"sent": 10, "while_down": 5, "after": 5, "at_actuator": sim_accepted(sim, 1200) - acc0,
                     "last_at_actuator": sim_last(sim, 1200),
                     "bridge": delta(st0["mappings"]["thruster_1_rpm"], st1["mappings"]["thruster_1_rpm"])},
        "link": st1["bridge"]["link"], "bridge_errors": delta(st0["bridge"]["errors"], st1["bridge"]["errors"]),
    })
    return res


async def can_heartbeat(bridge: Any, sim: Any, probe: Probe, heartbeats: HeartbeatSends) -> dict[str, Any]:
    """The GPS stops (power off): its heartbeat times out; then it comes back (a reboot)."""
    name = f"{BRIDGE}/device/gps"
    t_off = time.monotonic()  # before the age is read: the last heartbeat came at t_off - age or later
    st0 = bridge.stats()
    last_hb_age = st0["devices"]["gps"]["age_s"]
    await sim.power_off("gps")
    n_events = len(probe.diag_events)
    await wait_for(lambda: probe.level(name) == 2, 30, "the GPS at ERROR on /diagnostics")
    t_err = time.monotonic()
    err = next(e for e in probe.diag_events[n_events:] if e["name"] == name and e["level"] == 2)
    pub_off = bridge.stats()["mappings"]["gps_fix"]["published"]
    t_on = time.monotonic()
    n_events = len(probe.diag_events)
    await sim.power_on("gps")
    heartbeats.watch(sim)  # the rebooted GPS is a new node
    await wait_for(lambda: probe.level(name) == 0, 30, "the GPS OK again on /diagnostics")
    t_ok = time.monotonic()
    ok = next(e for e in probe.diag_events[n_events:] if e["name"] == name and e["level"] == 0)
    await wait_for(lambda: bridge.stats()["mappings"]["gps_fix"]["published"] > pub_off, 30, "GPS fixes again")
    st1 = bridge.stats()
    return {
        "heartbeat_age_at_power_off_s": last_hb_age,
        "error_after_power_off_s": round(t_err - t_off, 3),
        # What the bridge's own report said (the report's values, not a later reading).
        "heartbeat_age_when_reported_s": float(err["values"]["age_s"]),
        "heartbeats_when_lost": int(err["values"]["heartbeats"]),
        "message_when_lost": err["message"],
        "ok_after_power_on_s": round(t_ok - t_on, 3),
        "when_ok": {k: int(ok["values"][k]) for k in ("heartbeats", "restarts", "uptime_s")},
        "device": st1["devices"]["gps"],
        "gps_fix": delta(st0["mappings"]["gps_fix"], st1["mappings"]["gps_fix"]),
        "events": [e for e in probe.diag_events if e["name"] == name],
    }


def main() -> int:
    p = argparse.ArgumentParser()
    sub = p.add_subparsers(dest="mode", required=True)
    u = sub.add_parser("udp")
    u.add_argument("--out", type=Path, required=True)
    u.add_argument("--log-interval", type=float, default=2.0)
    h = sub.add_parser("udp-hostile")
    h.add_argument("--out", type=Path, required=True)
    h.add_argument("--log-interval", type=float, default=2.0)
    h.add_argument("--kinds", default="bad_crc,bad_crc_multi,header,jump,partials,junk")
    h.add_argument("--steps", type=int, default=100)
    c = sub.add_parser("can")
    c.add_argument("--iface", required=True)
    c.add_argument("--mtu", type=int, default=64)
    c.add_argument("--window", type=float, default=3.0)
    c.add_argument("--slow-sleep", type=float, default=0.1)
    c.add_argument("--log-interval", type=float, default=2.0)
    c.add_argument("--out", type=Path, required=True)
    args = p.parse_args()
    res = asyncio.run(main_udp(args) if args.mode == "udp" else main_udp_hostile(args) if args.mode == "udp-hostile"
                      else main_can(args))
    args.out.write_text(json.dumps(clean(res), default=str))
    print("DONE", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
