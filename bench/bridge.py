"""Part 3: the bridge (runtime/bridge.py, through its public API) against the raw pycyphal transport.

The process under test holds what the bridge's own process holds in a deployment plus the devices: the Bridge
on the asyncio loop (its rclpy executor in its own thread) and pycyphal device/receiver nodes on the same loop
(python-can's ``virtual`` bus exists only inside one process, as in tests/helpers/can_scenario.py). The ROS side
of the measurement (the subscribers of the bridged topics, the publisher of the commands) is a separate process
(``multiprocessing`` spawn), as ROS consumers are in a deployment: its Python executor would otherwise compete
for this process's GIL and the figures would be the probe's, not the bridge's. Counters and flow-control
credits are shared memory; commands and latency samples go through a pipe. CLOCK_MONOTONIC is system-wide,
so send and receive times of the two processes compare.

Per transport (Cyphal/UDP on 127.0.0.1; Cyphal/CAN FD on python-can ``virtual``):

- throughput, flow-controlled: at most WINDOW messages in flight (sent - received) for ``window_s`` seconds;
  msg/s = received / (last receipt - first send); nothing may be lost. Bridge UAVCAN->ROS: RawIMU (120 B with its
  covariance) from node 11 on subject 1100 -> bridge -> /imu -> ROS process. Bridge ROS->UAVCAN: the ROS process
  publishes sam_msgs/ThrusterAngles on /thruster_angles -> bridge -> subject 1202 -> pycyphal subscriber.
  Raw reference: the same DSDL types, pycyphal publisher -> pycyphal subscriber in this process, no bridge (own
  subjects on UDP, own virtual bus on CAN), measured in the same run and interleaved with the bridge runs.
- latency, paced at ``latency_hz``: UAVCAN publish -> ROS callback (the send time travels in the RawIMU
  timestamp, which the converter turns into header.stamp) and ROS publish -> UAVCAN receive (a sequence number
  travels in the two float16 angles, exact below 2048; the ROS process returns its send times).
- CPU time of this process (os.times: all its threads) per 1000 messages of the throughput runs, split by thread
  (main = asyncio loop: the device publisher + pycyphal + the bridge's UAVCAN half; the bridge's rclpy thread;
  other = DDS and transport I/O threads); the ROS process's CPU beside it; resident memory (VmRSS) before and
  after the bridge starts and after all bridged messages.
- the SAM sensor mix: every UAVCAN->ROS port of the spec from its device's node id at k x its nominal rate for
  ``mix_s`` seconds; sustained = every message at ROS (counted per topic), none dropped by the bridge, the
  publishers on schedule (never 0.25 s behind) and the backlog drained within ``drain_s``. k doubles from 1 until
  a trial fails, then is bisected twice.
"""

from __future__ import annotations

import asyncio
import contextlib
import fcntl
import heapq
import multiprocessing
import os
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

from bench.common import REPO, log, median, percentile, ratio, sample_uavcan

WINDOW = 32
# The bridge's ROS history depth as `sam-bridge` deploys it (its --qos-depth default): a burst of WINDOW commands fits
# (with the spec's keep-last 10 on /thruster_angles, DDS overwrote the burst's tail before the bridge took it).
QOS_DEPTH = 100
UDP_LOCK = Path("/tmp") / "sam-runtime-tests-cyphal-udp.lock"  # the tests' machine-wide Cyphal/UDP lock
RAW_SUBJECT_U2R = 4001
RAW_SUBJECT_R2U = 4002
RAW_PUB_NODE, RAW_SUB_NODE, ACT_NODE = 91, 92, 23
IMU_TOPIC, CMD_TOPIC = "/imu", "/thruster_angles"
CLK_TCK = os.sysconf("SC_CLK_TCK")


# ----------------------------------------------------------------------------------------------- helpers
@contextlib.contextmanager
def cyphal_udp_lock(timeout: float = 120.0) -> Iterator[bool]:
    """Cyphal/UDP subjects are machine-wide multicast groups: serialize with the runtime tests (same lock file)
    so neither sees the other's traffic. Yields whether the lock was obtained."""
    with open(UDP_LOCK, "a+") as fh:
        deadline = time.monotonic() + timeout
        got = False
        while True:
            try:
                fcntl.flock(fh.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
                got = True
                break
            except BlockingIOError:
                if time.monotonic() > deadline:
                    log(f"WARNING: {UDP_LOCK} still held after {timeout:.0f} s; measuring anyway")
                    break
                time.sleep(0.2)
        try:
            yield got
        finally:
            if got:
                fcntl.flock(fh.fileno(), fcntl.LOCK_UN)


def rss_kib() -> int:
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1])
    return 0


def thread_cpu() -> dict[int, float]:
    """CPU seconds (user+system) of every thread of this process, by native thread id."""
    out: dict[int, float] = {}
    for task in Path("/proc/self/task").iterdir():
        try:
            fields = (task / "stat").read_text().rsplit(")", 1)[1].split()
            out[int(task.name)] = (int(fields[11]) + int(fields[12])) / CLK_TCK
        except (OSError, ValueError, IndexError):
            continue
    return out


def process_cpu() -> float:
    t = os.times()
    return t.user + t.system


def now_us() -> int:
    return int(time.monotonic() * 1e6)


# ----------------------------------------------------------------------------------------------- ROS process
def _ros_process(conn: Any, generated: str, in_topics: list[str], out_topic: str, counts: Any, last_rx: Any,
                 credit: Any) -> None:
    """The ROS side: subscribers of the bridged topics (counting, /imu latency), publisher of the commands."""
    import rclpy
    from rclpy.event_handler import PublisherEventCallbacks, SubscriptionEventCallbacks
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.node import Node
    from rclpy.signals import SignalHandlerOptions

    import bench.common  # noqa: F401  (loopback discovery before rclpy)
    from sam_runtime.genpkg import GeneratedPackage
    from sam_runtime.node_support import qos_profile

    gen = GeneratedPackage(Path(generated))
    topic_info = {m.topic.name: m.topic for m in gen.tables().MAPPINGS}
    ctx = rclpy.Context()
    rclpy.init(args=[], context=ctx, signal_handler_options=SignalHandlerOptions.NO)
    node = Node("sam_bench_ros_side", context=ctx)

    def qos(topic: str) -> Any:  # the spec's reliability and durability (the bridge's), a deep history
        q = topic_info[topic].qos
        return qos_profile(q.reliability, q.durability, 1000)

    state: dict[str, Any] = {"lat": None}

    def counter(i: int) -> Any:
        def cb(msg: Any) -> None:
            counts[i] += 1
            last_rx[i] = time.monotonic_ns()
        return cb

    imu_i = in_topics.index(IMU_TOPIC)

    def on_imu(msg: Any) -> None:
        now = time.monotonic_ns()
        counts[imu_i] += 1
        last_rx[imu_i] = now
        lat = state["lat"]
        if lat is not None:
            st = msg.header.stamp
            lat.append(now // 1000 - (st.sec * 1_000_000 + st.nanosec // 1000))

    # The cheapest consumer rclpy offers, so that the figures are the bridge's: no QoS-event waitables, and the
    # C++ events executor where this rclpy has it (the Python executor costs ~0.3 ms per message here).
    for i, t in enumerate(in_topics):
        node.create_subscription(gen.ros_class(topic_info[t]), t, on_imu if i == imu_i else counter(i), qos(t),
                                 event_callbacks=SubscriptionEventCallbacks(use_default_callbacks=False))
    cmd_cls = gen.ros_class(topic_info[out_topic])
    pub = node.create_publisher(cmd_cls, out_topic, qos(out_topic),
                                event_callbacks=PublisherEventCallbacks(use_default_callbacks=False))
    try:
        from rclpy.experimental import EventsExecutor

        executor = EventsExecutor(context=ctx)
    except ImportError:
        executor = SingleThreadedExecutor(context=ctx)
    executor.add_node(node)
    stop = threading.Event()

    def spin() -> None:
        while not stop.is_set():
            executor.spin_once(timeout_sec=0.05)

    thread = threading.Thread(target=spin, daemon=True)
    thread.start()

    def publish(seq: int) -> None:
        msg = cmd_cls()
        msg.thruster_vertical_radians = float(seq // 2048)
        msg.thruster_horizontal_radians = float(seq % 2048)
        pub.publish(msg)

    deadline = time.monotonic() + 30.0
    while time.monotonic() < deadline:
        if all(node.count_publishers(t) > 0 for t in in_topics) and pub.get_subscription_count() > 0:
            break
        time.sleep(0.05)
    conn.send(("ready", all(node.count_publishers(t) > 0 for t in in_topics) and pub.get_subscription_count() > 0))
    try:
        while True:
            cmd = conn.recv()
            what = cmd[0]
            if what == "quit":
                break
            if what == "lat_on":
                state["lat"] = []
                conn.send(("ok",))
            elif what == "lat_off":
                lat, state["lat"] = state["lat"] or [], None
                conn.send(("lat", lat))
            elif what == "cpu":
                t = os.times()
                conn.send(("cpu", t.user + t.system))
            elif what == "windowed":  # publish while seq < credit (set by the receiving side), for `seconds`
                seconds = cmd[1]
                seq = 0
                end = time.monotonic() + seconds
                t0 = time.monotonic()
                while time.monotonic() < end:
                    if seq < credit.value:
                        publish(seq)
                        seq += 1
                    else:
                        time.sleep(0.0002)
                conn.send(("done", seq, t0))
            elif what == "paced":  # n commands at hz; returns the send times
                hz, n = cmd[1], cmd[2]
                times = []
                t0 = time.monotonic()
                for i in range(n):
                    delay = t0 + i / hz - time.monotonic()
                    if delay > 0:
                        time.sleep(delay)
                    times.append(time.monotonic())
                    publish(i)
                conn.send(("done", n, times))
    finally:
        stop.set()
        thread.join(timeout=5)
        with contextlib.suppress(Exception):
            executor.shutdown(timeout_sec=1.0)
        with contextlib.suppress(Exception):
            node.destroy_node()
        with contextlib.suppress(Exception):
            ctx.shutdown()


class RosSide:
    """Handle of the ROS process."""

    def __init__(self, in_topics: list[str]) -> None:
        ctx = multiprocessing.get_context("spawn")
        self.in_topics = in_topics
        self.counts = ctx.RawArray("q", len(in_topics))
        self.last_rx = ctx.RawArray("q", len(in_topics))
        self.credit = ctx.RawValue("q", 0)
        self.conn, child = ctx.Pipe()
        self.proc = ctx.Process(target=_ros_process, name="sam-bench-ros", daemon=True, args=(
            child, str(REPO / "generated"), in_topics, CMD_TOPIC, self.counts, self.last_rx, self.credit))
        self.proc.start()
        self.ready: bool | None = None

    def count(self, topic: str) -> int:
        return int(self.counts[self.in_topics.index(topic)])

    def last(self, topic: str) -> float:
        return self.last_rx[self.in_topics.index(topic)] / 1e9

    async def request(self, *cmd: Any, timeout: float = 30.0) -> Any:
        self.conn.send(cmd)
        return await self.reply(timeout)

    async def reply(self, timeout: float = 30.0) -> Any:
        deadline = time.monotonic() + timeout
        while not self.conn.poll():
            if time.monotonic() > deadline or not self.proc.is_alive():
                raise TimeoutError(f"the ROS process did not answer (alive: {self.proc.is_alive()})")
            await asyncio.sleep(0.005)
        return self.conn.recv()

    async def wait_ready(self, timeout: float = 60.0) -> None:
        msg = await self.reply(timeout)
        self.ready = bool(msg[1])
        if not self.ready:
            raise TimeoutError("the ROS process did not discover the bridge")

    def close(self) -> None:
        with contextlib.suppress(Exception):
            self.conn.send(("quit",))
        self.proc.join(timeout=10)
        if self.proc.is_alive():
            self.proc.terminate()
            self.proc.join(timeout=5)


class CyphalReceiver:
    """A pycyphal subscriber that counts, records receive times while recording, and may grant credits."""

    def __init__(self, node: Any, dtype: type, subject: int, kind: str) -> None:
        self.count = 0
        self.last_rx = 0.0
        self.kind = kind  # "imu": send time in the timestamp; "seq": sequence number in the angles
        self.latencies_us: list[int] | None = None
        self.rx_at: dict[int, float] | None = None
        self.credit: Any = None  # shared RawValue: count - credit_base + WINDOW
        self.credit_base = 0
        self.sub = node.make_subscriber(dtype, subject)
        self.sub.receive_in_background(self._on)

    def _on(self, msg: Any, transfer: Any) -> None:
        now = time.monotonic()
        self.count += 1
        self.last_rx = now
        if self.credit is not None:
            self.credit.value = self.count - self.credit_base + WINDOW
        if self.latencies_us is not None:
            self.latencies_us.append(int(now * 1e6) - msg.timestamp.microsecond)
        elif self.rx_at is not None:
            self.rx_at[int(msg.vertical_radians) * 2048 + int(msg.horizontal_radians)] = now


# ----------------------------------------------------------------------------------------------- rig
class Rig:
    """The bridge, the ROS process and the pycyphal nodes of one transport."""

    def __init__(self, gen: Any, kind: str, iface_bridge: str, iface_raw: str, mtu: int | None,
                 wire: str = "codec") -> None:
        self.gen, self.kind, self.iface_b, self.iface_r, self.mtu = gen, kind, iface_bridge, iface_raw, mtu
        self.wire = wire  # the bridge's path asked for: codec (generated wire codecs) or object (converters)
        self.nodes: list[Any] = []
        self.bridge: Any = None
        self.ros: RosSide | None = None

    def node(self, name: str, node_id: int, raw: bool = False) -> Any:
        from sam_runtime.transport import make_node

        n = make_node(f"org.sam.bench.{name}", node_id, self.kind, iface=self.iface_r if raw else self.iface_b,
                      mtu=self.mtu)
        self.nodes.append(n)
        return n

    async def start(self, rss: dict[str, int]) -> None:
        tables = self.gen.tables()
        self.imu_map = next(m for m in tables.MAPPINGS if m.topic.name == IMU_TOPIC)
        self.cmd_map = next(m for m in tables.MAPPINGS if m.topic.name == CMD_TOPIC)
        self.in_maps = [m for m in tables.MAPPINGS if m.direction == "uavcan_to_ros"]
        self.in_topics = sorted({m.topic.name for m in self.in_maps})
        imu_cls = self.gen.dsdl_class(self.imu_map.port)
        cmd_cls = self.gen.dsdl_class(self.cmd_map.port)
        self.ros = RosSide(self.in_topics)
        # Raw reference: publisher and receiver nodes, no bridge on their subjects / bus.
        raw_pub = self.node("rawpub", RAW_PUB_NODE, raw=True)
        raw_sub = self.node("rawsub", RAW_SUB_NODE, raw=True)
        if self.kind == "can":  # python-can's virtual bus hands every frame to every node: three on each bus
            self.node("bystander", RAW_SUB_NODE + 1, raw=True)
        self.raw_u2r_pub = raw_pub.make_publisher(imu_cls, RAW_SUBJECT_U2R)
        self.raw_r2u_pub = raw_pub.make_publisher(cmd_cls, RAW_SUBJECT_R2U)
        self.raw_u2r_rx = CyphalReceiver(raw_sub, imu_cls, RAW_SUBJECT_U2R, "imu")
        self.raw_r2u_rx = CyphalReceiver(raw_sub, cmd_cls, RAW_SUBJECT_R2U, "seq")
        # Bridge side: the IMU device (its spec node id) and the thrust vector actuator's subscriber.
        self.imu_node = self.node("imu", next(iter(self.imu_map.source_node_ids)))
        self.imu_pub = self.imu_node.make_publisher(imu_cls, self.imu_map.port.subject_id)
        self.act_node = act = self.node("actuator", ACT_NODE)  # the thrust vector device's node id
        self.cmd_rx = CyphalReceiver(act, cmd_cls, self.cmd_map.port.subject_id, "seq")
        self.imu_sample = sample_uavcan(self.gen, self.imu_map.port)
        self.cmd_sample = cmd_cls()
        await asyncio.sleep(0.2)
        rss["before_bridge_kib"] = rss_kib()
        await self.start_bridge()
        rss["after_bridge_start_kib"] = rss_kib()
        await self.ros.wait_ready()
        await self.discovered()

    def make_bridge(self) -> Any:
        from sam_runtime.bridge import Bridge, TransportConfig

        tc = TransportConfig("can", self.iface_b, self.mtu) if self.kind == "can" else TransportConfig(
            "udp", self.iface_b)
        return Bridge(self.gen, transport=tc, wire=self.wire, qos_depth=QOS_DEPTH)

    async def start_bridge(self) -> None:
        self.bridge = self.make_bridge()
        await self.bridge.start()

    async def discovered(self) -> None:
        """Until the bridge's ROS endpoints and the ROS process's have matched."""
        deadline = time.monotonic() + 20.0
        while True:
            s = self.bridge.stats()["mappings"]
            if (all((s[m.name].get("ros_subscribers") or 0) > 0 for m in self.in_maps)
                    and (s[self.cmd_map.name].get("ros_publishers") or 0) > 0):
                break
            if time.monotonic() > deadline:
                raise TimeoutError("the bridge did not discover the ROS process")
            await asyncio.sleep(0.05)

    async def swap_bridge(self, wire: str) -> None:
        """Close the bridge and start another on ``wire`` (same process, nodes and ROS process)."""
        await self.bridge.close()
        self.bridge = None
        self.wire = wire
        await self.start_bridge()
        await self.discovered()
        await asyncio.sleep(0.3)  # the new endpoints settle before anything is timed

    def cpu_start(self) -> dict[str, Any]:
        return {"process": process_cpu(), "threads": thread_cpu()}

    def cpu_stop(self, t0: dict[str, Any]) -> dict[str, float]:
        p1, t1 = process_cpu(), thread_cpu()
        delta = {tid: v - t0["threads"].get(tid, 0.0) for tid, v in t1.items()}
        main_tid = threading.main_thread().native_id
        spin = getattr(getattr(self.bridge.ros, "_spin_thread", None), "native_id", None)
        return {
            "process": p1 - t0["process"],
            "main (asyncio loop)": delta.get(main_tid, 0.0),
            "bridge rclpy thread": delta.get(spin, 0.0) if spin is not None else 0.0,
            "other threads": sum(v for tid, v in delta.items() if tid not in (main_tid, spin)),
        }

    async def drop_nodes(self, keep: int) -> None:
        """Close the nodes made after the first ``keep``."""
        from sam_runtime.transport import aclose

        extra, self.nodes[keep:] = self.nodes[keep:], []
        with contextlib.suppress(Exception):
            await aclose(*extra)
        await asyncio.sleep(0.2)

    async def close(self) -> None:
        from sam_runtime.transport import aclose

        try:
            if self.bridge is not None:
                await self.bridge.close()
        finally:
            if self.ros is not None:
                self.ros.close()
            with contextlib.suppress(Exception):
                await aclose(*self.nodes)

    # ------------------------------------------------------------------------------------- measured paths
    async def _send_imu(self, pub: Any) -> None:
        self.imu_sample.timestamp.microsecond = now_us()
        await pub.publish(self.imu_sample)

    async def _send_cmd_raw(self, seq: int) -> None:
        cmd = self.cmd_sample
        cmd.vertical_radians = float(seq // 2048)
        cmd.horizontal_radians = float(seq % 2048)
        await self.raw_r2u_pub.publish(cmd)

    def _counter(self, path: str) -> Any:
        assert self.ros is not None
        ros = self.ros
        return {
            "u2r_raw": (lambda: self.raw_u2r_rx.count, lambda: self.raw_u2r_rx.last_rx),
            "u2r_bridge": (lambda: ros.count(IMU_TOPIC), lambda: ros.last(IMU_TOPIC)),
            "r2u_raw": (lambda: self.raw_r2u_rx.count, lambda: self.raw_r2u_rx.last_rx),
            "r2u_bridge": (lambda: self.cmd_rx.count, lambda: self.cmd_rx.last_rx),
        }[path]

    async def windowed(self, path: str, seconds: float, cpu: bool = True) -> dict[str, Any]:
        """Max throughput with at most WINDOW in flight."""
        assert self.ros is not None
        received, last_rx = self._counter(path)
        base = received()
        sent = 0
        c0 = self.cpu_start() if cpu else None
        r0 = (await self.ros.request("cpu"))[1] if cpu else 0.0
        t0 = time.monotonic()
        if path == "r2u_bridge":  # the ROS process publishes, paced by credits from the receiver
            self.cmd_rx.credit_base = base
            self.ros.credit.value = WINDOW
            self.cmd_rx.credit = self.ros.credit
            self.ros.conn.send(("windowed", seconds))
            msg = await self.ros.reply(seconds + 30)
            sent, t0 = msg[1], msg[2]
            self.cmd_rx.credit = None
        else:
            pub = {"u2r_raw": self.raw_u2r_pub, "u2r_bridge": self.imu_pub}.get(path)
            deadline = t0 + seconds
            while time.monotonic() < deadline:
                if sent - (received() - base) < WINDOW:
                    if pub is not None:
                        await self._send_imu(pub)
                    else:
                        await self._send_cmd_raw(sent)
                    sent += 1
                    if sent % 8 == 0:
                        await asyncio.sleep(0)
                else:
                    await asyncio.sleep(0.0005)
        drain = time.monotonic() + 2.0
        while received() - base < sent and time.monotonic() < drain:
            await asyncio.sleep(0.002)
        cpu_s = self.cpu_stop(c0) if c0 else {}
        if cpu:
            cpu_s["ROS process"] = (await self.ros.request("cpu"))[1] - r0
        got = received() - base
        elapsed = max(1e-9, last_rx() - t0)
        return {"sent": sent, "received": got, "lost": sent - got, "seconds": round(elapsed, 3),
                "msg_per_s": got / elapsed, "cpu_s": cpu_s}

    async def paced(self, path: str, hz: float, seconds: float) -> dict[str, Any]:
        """Latency at a fixed rate (absolute schedule)."""
        assert self.ros is not None
        received, _ = self._counter(path)
        base = received()
        n = int(hz * seconds)
        lat: list[int] = []
        if path == "r2u_bridge":
            self.cmd_rx.rx_at = {}
            self.ros.conn.send(("paced", hz, n))
            msg = await self.ros.reply(seconds + 30)
            sent_at = msg[2]
            drain = time.monotonic() + 2.0
            while received() - base < n and time.monotonic() < drain:
                await asyncio.sleep(0.002)
            rx_at, self.cmd_rx.rx_at = self.cmd_rx.rx_at, None
            lat = [int((t - sent_at[s]) * 1e6) for s, t in rx_at.items() if s < len(sent_at)]
        else:
            rx = {"u2r_raw": self.raw_u2r_rx, "r2u_raw": self.raw_r2u_rx}.get(path)
            if path == "u2r_bridge":
                await self.ros.request("lat_on")
            elif rx is not None and rx.kind == "imu":
                rx.latencies_us = []
            elif rx is not None:
                rx.rx_at = {}
            sent_at: list[float] = []
            t0 = time.monotonic()
            for i in range(n):
                delay = t0 + i / hz - time.monotonic()
                if delay > 0:
                    await asyncio.sleep(delay)
                if path in ("u2r_raw", "u2r_bridge"):
                    await self._send_imu(self.raw_u2r_pub if path == "u2r_raw" else self.imu_pub)
                else:
                    sent_at.append(time.monotonic())
                    await self._send_cmd_raw(i)
            drain = time.monotonic() + 2.0
            while received() - base < n and time.monotonic() < drain:
                await asyncio.sleep(0.002)
            if path == "u2r_bridge":
                lat = (await self.ros.request("lat_off"))[1]
            elif rx is not None and rx.kind == "imu":
                lat, rx.latencies_us = rx.latencies_us or [], None
            elif rx is not None:
                rx_at, rx.rx_at = rx.rx_at or {}, None
                lat = [int((t - sent_at[s]) * 1e6) for s, t in rx_at.items() if s < len(sent_at)]
        got = received() - base
        return {"sent": n, "received": got, "lost": n - got, "samples": len(lat),
                "p50_us": percentile(lat, 50), "p99_us": percentile(lat, 99), "max_us": max(lat) if lat else None}


# ----------------------------------------------------------------------------------------------- sensor mix
async def sensor_mix_trial(rig: Rig, devices: dict[int, Any], k: float, seconds: float, drain_s: float
                           ) -> dict[str, Any]:
    """Every UAVCAN->ROS port at k x nominal from its device; sustained = nothing lost, on schedule, drained."""
    gen, ros = rig.gen, rig.ros
    assert ros is not None
    ports: dict[int, Any] = {}
    for m in rig.in_maps:
        ports.setdefault(m.port.subject_id, (m, next(iter(m.source_node_ids))))
    pubs = []
    for sid, (m, nid) in sorted(ports.items()):
        pub = devices[nid]["pubs"].get(sid)
        if pub is None:
            pub = devices[nid]["node"].make_publisher(gen.dsdl_class(m.port), sid)
            devices[nid]["pubs"][sid] = pub
        pubs.append((sid, pub, sample_uavcan(gen, m.port, seed=sid), float(m.port.rate_hz) * k))
    nominal = sum(float(m.port.rate_hz) for m, _ in ports.values())
    before = {t: ros.count(t) for t in rig.in_topics}
    before_stats = rig.bridge.stats()["mappings"]
    sent = {sid: 0 for sid, *_ in pubs}
    heap = [(i / (17.0 * rate), sid, rate, pub, sample) for i, (sid, pub, sample, rate) in enumerate(pubs)]
    heapq.heapify(heap)
    await ros.request("lat_on")
    t0 = time.monotonic()
    end = t0 + seconds
    late_max = 0.0
    behind = False
    while heap:
        due, sid, rate, pub, sample = heap[0]
        at = t0 + due
        now = time.monotonic()
        if at >= end or now >= end:
            break
        if at > now:
            await asyncio.sleep(at - now)
        elif now - at > 0.25:  # a quarter second behind schedule: this rate is not sustained
            behind = True
            late_max = max(late_max, now - at)
            break
        else:
            late_max = max(late_max, now - at)
        heapq.heapreplace(heap, (due + 1.0 / rate, sid, rate, pub, sample))
        if hasattr(sample, "timestamp"):
            sample.timestamp.microsecond = now_us()
        if await pub.publish(sample):
            sent[sid] += 1
    t_sent = time.monotonic()
    expected = {t: sum(sent[m.port.subject_id] for m in rig.in_maps if m.topic.name == t) for t in rig.in_topics}

    def got() -> dict[str, int]:
        return {t: ros.count(t) - before[t] for t in rig.in_topics}

    while any(got()[t] < expected[t] for t in rig.in_topics) and time.monotonic() < t_sent + drain_s:
        await asyncio.sleep(0.005)
    drained_in = time.monotonic() - t_sent
    await asyncio.sleep(0.05)
    received = got()
    lat = (await ros.request("lat_off"))[1]
    after_stats = rig.bridge.stats()["mappings"]
    dropped = sum(after_stats[m.name]["dropped_total"] - before_stats[m.name]["dropped_total"] for m in rig.in_maps)
    elapsed = max(1e-9, t_sent - t0)
    total = sum(sent.values())
    on_schedule = not behind and total >= 0.97 * nominal * k * seconds
    lost = sum(max(0, expected[t] - received[t]) for t in rig.in_topics)
    return {
        "k": k, "target_msg_per_s": round(nominal * k, 1), "offered_msg_per_s": round(total / elapsed, 1),
        "ros_msgs_expected": sum(expected.values()), "ros_msgs_received": sum(received.values()), "lost": lost,
        "bridge_dropped": dropped, "on_schedule": on_schedule, "publisher_late_max_ms": round(late_max * 1e3, 1),
        "drained_in_s": round(drained_in, 3),
        "imu_latency_p50_ms": round(percentile(lat, 50) / 1e3, 2) if lat else None,
        "imu_latency_p99_ms": round(percentile(lat, 99) / 1e3, 2) if lat else None,
        "sustained": lost == 0 and dropped == 0 and on_schedule and drained_in < drain_s,
    }


async def sensor_mix(rig: Rig, seconds: float, drain_s: float, k_max: float = 512.0, bisect: int = 2
                     ) -> dict[str, Any]:
    ids = sorted({next(iter(m.source_node_ids)) for m in rig.in_maps})
    existing = {next(iter(rig.imu_map.source_node_ids)): rig.imu_node, ACT_NODE: rig.act_node}  # one node per id
    devices = {nid: {"node": existing.get(nid) or rig.node(f"dev{nid}", nid), "pubs": {}} for nid in ids}
    nominal = sum(float(p.rate_hz) for p in {m.port.subject_id: m.port for m in rig.in_maps}.values())
    trials: list[dict[str, Any]] = []
    good, bad = 0.0, None

    async def trial(k: float) -> bool:
        r = await sensor_mix_trial(rig, devices, k, seconds, drain_s)
        trials.append(r)
        log(f"  mix x{k:g} ({r['target_msg_per_s']:.0f} msg/s): {'sustained' if r['sustained'] else 'NOT sustained'}"
            f" - {r['ros_msgs_received']}/{r['ros_msgs_expected']} at ROS, offered {r['offered_msg_per_s']}/s, "
            f"late {r['publisher_late_max_ms']} ms, drained in {r['drained_in_s']} s")
        await asyncio.sleep(0.3 if r["sustained"] else 1.5)  # let a backlog clear before the next trial
        return bool(r["sustained"])

    k = 1.0
    while k <= k_max:
        if await trial(k):
            good, k = k, k * 2
        else:
            bad = k
            break
    if bad is not None and good > 0:
        for _ in range(bisect):
            k = round((good + bad) / 2, 2)
            if await trial(k):
                good = k
            else:
                bad = k
    return {"nominal_msg_per_s": nominal, "nominal_ros_msg_per_s": sum(float(m.rate_hz) for m in rig.in_maps),
            "max_sustained_k": good, "max_sustained_msg_per_s": round(good * nominal, 1), "first_failing_k": bad,
            "device_nodes": len(devices), "nodes_on_bus": len(rig.nodes) - (3 if rig.kind == "can" else 2) + 1,
            "trials": trials}


def per_message_costs(rig: Rig, n: int = 2000) -> dict[str, float]:
    """Microseconds per call of the steps of one bridged IMU message, each alone in a loop (best of 3), on the
    running bridge (its /imu publisher has the ROS process as subscriber)."""
    import timeit

    import pycyphal.dsdl

    conv = rig.gen.convert()
    src = rig.imu_sample
    stats = conv.ConversionStats()
    msg = conv.imu_to_ros(src, 1, stats)
    raw = list(pycyphal.dsdl.serialize(src))
    pub = getattr(rig.bridge.ros, "_publishers", {}).get(IMU_TOPIC)
    clock = getattr(rig.bridge.ros, "clock", None)

    def t(fn: Any) -> float:
        return round(min(timeit.repeat(fn, number=n, repeat=3)) / n * 1e6, 2)

    out = {
        "pycyphal serialize RawIMU (device side)": t(lambda: list(pycyphal.dsdl.serialize(src))),
        "pycyphal deserialize RawIMU (receive side, raw too)": t(lambda: pycyphal.dsdl.deserialize(type(src), raw)),
        "generated imu_to_ros": t(lambda: conv.imu_to_ros(src, 1, stats)),
        "  for comparison: sensor_msgs/Imu() (the class; the converter builds with its own constructor)": t(type(msg)),
    }
    receive_ns = getattr(rig.bridge.ros, "receive_ns", None)
    if receive_ns is not None:
        out["bridge: receive stamp per message (system clock unless use_sim_time)"] = t(receive_ns)
    if clock is not None:
        out["  for comparison: rclpy Clock.now() (read only under use_sim_time)"] = t(
            lambda: clock.now().nanoseconds)
    if pub is not None:
        out["rclpy publish of the Imu (1 subscriber)"] = t(lambda: pub.publish(msg))
    out.update(wire_steps(rig, pub, t))
    return out


def wire_steps(rig: Rig, pub: Any, t: Callable[[Any], float]) -> dict[str, float]:
    """The wire path's steps of the same IMU message and of a command (what replaces the steps above)."""
    from rclpy.serialization import serialize_message

    codec = rig.gen.codec("dronecan" if rig.kind == "dronecan" else "cyphal")
    if codec is None:
        return {}
    conv = rig.gen.convert_v0() if rig.kind == "dronecan" else rig.gen.convert()
    stats = conv.ConversionStats()
    w2r = codec.CODECS[rig.imu_map.name][0]
    r2w = codec.CODECS[rig.cmd_map.name][1]
    payload = imu_payload(rig)
    cdr, _ = w2r(payload, 1, stats)
    angles = rig.gen.ros_class(rig.cmd_map.topic)(thruster_vertical_radians=0.25, thruster_horizontal_radians=-0.5)
    cmd_cdr = serialize_message(angles)
    out = {f"wire path: generated {rig.imu_map.name}_wire_to_ros (payload {len(payload)} B -> CDR {len(cdr)} B)":
           t(lambda: w2r(payload, 1, stats))}
    if pub is not None:
        out["wire path: rclpy publish of the Imu's CDR bytes (raw, 1 subscriber)"] = t(lambda: pub.publish(cdr))
    out[f"wire path: generated {rig.cmd_map.name}_ros_to_wire (CDR -> payload)"] = t(lambda: r2w(cmd_cdr, stats))
    return out


def imu_payload(rig: Rig) -> bytes:
    """The IMU sample's transfer payload (classic CAN with tail array optimisation on DroneCAN)."""
    if rig.kind == "dronecan":
        from dronecan import transport

        return bytes(transport.Transfer(payload=rig.imu_sample).payload)
    import pycyphal.dsdl

    return b"".join(pycyphal.dsdl.serialize(rig.imu_sample))


# ----------------------------------------------------------------------------------------------- driver
PATHS = ("u2r_raw", "u2r_bridge", "r2u_raw", "r2u_bridge")


async def run_block(rig: Rig, *, reps: int, window_s: float, latency_reps: int, latency_hz: float, latency_s: float,
                    paths: tuple[str, ...] = PATHS) -> tuple[dict[str, list[Any]], dict[str, list[Any]], int]:
    """Throughput (``reps`` repetitions) then latency (``latency_reps``) of the four paths on the running bridge;
    raw and bridge back to back in alternating order. Returns the runs by path and the messages bridged."""
    paced = getattr(rig, "paced_cpu", rig.paced)
    for p in paths:  # warm-up
        await rig.windowed(p, 0.3, cpu=False)
    tp: dict[str, list[dict[str, Any]]] = {p: [] for p in PATHS}
    bridged = 0
    for r in range(reps):
        for direction in ("u2r", "r2u"):
            for which in (("raw", "bridge") if r % 2 == 0 else ("bridge", "raw")):
                res = await rig.windowed(f"{direction}_{which}", window_s)
                tp[f"{direction}_{which}"].append(res)
                bridged += res["received"] if which == "bridge" else 0
                await asyncio.sleep(0.1)
    log(f"  {rig.kind} ({rig.bridge.wire} path): throughput " + ", ".join(
        f"{k} {median([x['msg_per_s'] for x in v]):.0f}/s" for k, v in tp.items()))
    lat: dict[str, list[dict[str, Any]]] = {p: [] for p in PATHS}
    for r in range(latency_reps):
        for direction in ("u2r", "r2u"):
            for which in (("raw", "bridge") if r % 2 == 0 else ("bridge", "raw")):
                lat[f"{direction}_{which}"].append(await paced(f"{direction}_{which}", latency_hz, latency_s))
                bridged += lat[f"{direction}_{which}"][-1]["received"] if which == "bridge" else 0
                await asyncio.sleep(0.1)
    return tp, lat, bridged


async def object_block(rig: Rig, *, reps: int, window_s: float, latency_reps: int, latency_hz: float,
                       latency_s: float) -> dict[str, Any]:
    """The same measurement with the bridge on the object path (``wire="object"``), against raw again."""
    t0 = time.monotonic()
    await rig.swap_bridge("object")
    tp, lat, bridged = await run_block(rig, reps=reps, window_s=window_s, latency_reps=latency_reps,
                                       latency_hz=latency_hz, latency_s=latency_s, paths=("u2r_bridge", "r2u_bridge"))
    return {"wire": rig.bridge.wire, "reps": reps, "latency_reps": latency_reps, "bridged_messages": bridged,
            "throughput": _summarize_tp(tp), "latency": _summarize_lat(lat, latency_hz, latency_s),
            "wall_s": round(time.monotonic() - t0, 1)}


def codec_vs_object(codec: dict[str, Any], obj: dict[str, Any]) -> dict[str, float]:
    """Bridge msg/s of the codec path over the object path's, each normalised by the raw runs of its own block
    (the blocks run one after the other: the machine's load may differ).

    >>> codec_vs_object({"u2r_ratio": 1.2, "r2u_ratio": 0.9}, {"u2r_ratio": 0.6, "r2u_ratio": 0.6})
    {'u2r': 2.0, 'r2u': 1.5}
    """
    return {d: round(ratio(codec[f"{d}_ratio"], obj[f"{d}_ratio"]), 2) for d in ("u2r", "r2u")}


async def measure_transport(gen: Any, kind: str, *, reps: int, window_s: float, latency_hz: float,
                            latency_s: float, mix_s: float, drain_s: float, mix: bool = True,
                            object_reps: int = 3, object_latency_reps: int = 1) -> dict[str, Any]:
    from sam_runtime.bridge import quiet_late_media_completions

    quiet_late_media_completions(asyncio.get_running_loop())
    pid = os.getpid()
    if kind == "udp":
        rig = Rig(gen, "udp", "127.0.0.1", "127.0.0.1", None)
        label = "Cyphal/UDP on 127.0.0.1"
    else:
        rig = Rig(gen, "can", f"virtual:sbb{pid}", f"virtual:sbr{pid}", 64)
        label = "Cyphal/CAN FD on python-can virtual"
    rss: dict[str, int] = {}
    out: dict[str, Any] = {"transport": label, "kind": kind}
    try:
        await rig.start(rss)
        out["wire"] = rig.bridge.wire  # "object" when the generated package has no codecs (the bridge warns)
        if out["wire"] != "codec":
            log(f"WARNING: the bridge took the {out['wire']} path, not the codec one (no generated codec module?)")
        tp, lat, bridged = await run_block(rig, reps=reps, window_s=window_s, latency_reps=max(1, reps - 2),
                                           latency_hz=latency_hz, latency_s=latency_s)
        rss["after_bridged_kib"] = rss_kib()
        out["bridged_messages"] = bridged
        out["throughput"] = _summarize_tp(tp)
        out["latency"] = _summarize_lat(lat, latency_hz, latency_s)
        out["rss"] = dict(rss)
        out["rss"]["bridge_footprint_mib"] = round((rss["after_bridge_start_kib"] - rss["before_bridge_kib"]) / 1024, 1)
        out["rss"]["growth_kib_per_1000_bridged"] = round(
            (rss["after_bridged_kib"] - rss["after_bridge_start_kib"]) / max(1, bridged) * 1000, 2)
        out["per_message_us"] = per_message_costs(rig)
        await asyncio.sleep(1.0)  # let the ROS process take those before the sensor mix counts
        if mix:
            n0 = len(rig.nodes)
            out["sensor_mix"] = await sensor_mix(rig, mix_s, drain_s)
            await rig.drop_nodes(n0)  # the mix's device nodes: on python-can's virtual bus each costs every frame
        st = rig.bridge.stats()
        out["bridge_errors"] = st["bridge"]["errors"]
        out["bridge_dropped"] = {n: m["dropped"] for n, m in st["mappings"].items() if m["dropped_total"]}
        if object_reps and out["wire"] == "codec":
            out["object"] = await object_block(rig, reps=object_reps, window_s=window_s,
                                               latency_reps=object_latency_reps, latency_hz=latency_hz,
                                               latency_s=latency_s)
            out["codec_vs_object"] = codec_vs_object(out["throughput"], out["object"]["throughput"])
    finally:
        await rig.close()
    return out


def _summarize_tp(tp: dict[str, list[dict[str, Any]]]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for name, runs in tp.items():
        n = sum(r["received"] for r in runs)
        keys = list(runs[0]["cpu_s"]) if runs and runs[0]["cpu_s"] else []
        out[name] = {
            "msg_per_s": round(median([r["msg_per_s"] for r in runs])),
            "runs_msg_per_s": [round(r["msg_per_s"]) for r in runs],
            "lost": sum(r["lost"] for r in runs),
            "messages": n,
            "cpu_ms_per_1000": {k: round(sum(r["cpu_s"][k] for r in runs) / max(1, n) * 1e6, 1) for k in keys},
        }
    for d in ("u2r", "r2u"):
        b, r = out[f"{d}_bridge"], out[f"{d}_raw"]
        # Each repetition runs bridge and raw back to back: the ratio of a pair is taken under the same load, and
        # the median over the pairs is the figure (the machine's load drifts between repetitions).
        pairs = [ratio(x["msg_per_s"], y["msg_per_s"]) for x, y in zip(tp[f"{d}_bridge"], tp[f"{d}_raw"], strict=True)]
        out[f"{d}_ratio"] = round(median(pairs), 3)
        out[f"{d}_ratio_runs"] = [round(x, 3) for x in pairs]
        out[f"{d}_cpu_ratio"] = round(ratio(b["cpu_ms_per_1000"].get("process", 0),
                                            r["cpu_ms_per_1000"].get("process", 0)), 2)
    return out


def _summarize_lat(lat: dict[str, list[dict[str, Any]]], hz: float, seconds: float) -> dict[str, Any]:
    out: dict[str, Any] = {"rate_hz": hz, "seconds": seconds}
    for name, runs in lat.items():
        out[name] = {
            "p50_us": round(median([r["p50_us"] for r in runs])),
            "p99_us": round(median([r["p99_us"] for r in runs])),
            "max_us": round(max(r["max_us"] or 0 for r in runs)),
            "samples": sum(r["samples"] for r in runs),
            "lost": sum(r["lost"] for r in runs),
        }
        for key in ("cpu_ms_per_1000", "cpu_percent"):  # paced runs that measured the CPU (bench.bridge_dronecan)
            if runs and key in runs[0]:
                out[name][key] = {k: round(median([x[key][k] for x in runs]), 1) for k in runs[0][key]}
    return out


def run(gen: Any, transports: tuple[str, ...] = ("udp", "can"), *, reps: int = 3, window_s: float = 3.0,
        latency_hz: float = 200.0, latency_s: float = 2.5, mix_s: float = 3.0, drain_s: float = 0.5,
        mix: bool = True, object_reps: int = 3, object_latency_reps: int = 1) -> dict[str, Any]:
    """Per transport: the bridge on its wire path (codec) against raw, then on the object path against raw
    (``object_reps`` throughput and ``object_latency_reps`` latency repetitions; 0: not measured)."""
    import logging

    os.environ.setdefault("ROS_DOMAIN_ID", str(150 + os.getpid() % 60))  # private to this run (tests use 1..101)
    # The bridge warns when an overloaded loop delays a heartbeat past 3 s; its counters tell the rest.
    logging.getLogger("sam_runtime").setLevel(logging.ERROR)
    gen.convert()  # DSDL compiled and the converters importable before anything else
    results: dict[str, Any] = {"method": {
        "window_in_flight": WINDOW, "window_s": window_s, "reps": reps, "latency_hz": latency_hz,
        "latency_s": latency_s, "mix_s": mix_s, "drain_s": drain_s, "ros_domain_id": os.environ["ROS_DOMAIN_ID"],
        "latency_reps": max(1, reps - 2), "object_reps": object_reps, "object_latency_reps": object_latency_reps,
    }}
    for kind in transports:
        t0 = time.monotonic()
        kw = dict(reps=reps, window_s=window_s, latency_hz=latency_hz, latency_s=latency_s, mix_s=mix_s,
                  drain_s=drain_s, mix=mix, object_reps=object_reps, object_latency_reps=object_latency_reps)
        if kind == "udp":
            with cyphal_udp_lock() as locked:
                res = asyncio.run(measure_transport(gen, kind, **kw))
                res["udp_lock_held"] = locked
        else:
            res = asyncio.run(measure_transport(gen, kind, **kw))
        res["wall_s"] = round(time.monotonic() - t0, 1)
        log(f"bridge {kind}: done in {res['wall_s']} s")
        results[kind] = res
    return results


if __name__ == "__main__":
    import json
    import sys

    from bench.common import generated_package

    args = sys.argv[1:]
    kinds = tuple(a for a in args if a in ("udp", "can")) or ("udp", "can")
    print(json.dumps(run(generated_package(), kinds, reps=2, window_s=2.0, mix="nomix" not in args,
                         object_reps=0 if "noobject" in args else 2), indent=1, default=str))
