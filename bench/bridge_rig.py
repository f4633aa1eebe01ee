"""The rig of the bridge benchmarks (bench/bridge.py for Cyphal; bench/bridge_dronecan.py builds on it): one
process holds the Bridge on the asyncio loop (its rclpy executor in its own thread), the device and receiver
nodes on the same loop (python-can's ``virtual`` bus exists only inside one process) and the raw reference
nodes; the ROS side (subscribers of the bridged topics, publisher of the commands) is a separate process
(``multiprocessing`` spawn), as ROS consumers are in a deployment: its Python executor would otherwise compete
for this process's GIL and the figures would be the probe's, not the bridge's. Counters and flow-control
credits are shared memory; commands and latency samples go through a pipe. CLOCK_MONOTONIC is system-wide,
so send and receive times of the two processes compare.
"""

from __future__ import annotations

import asyncio
import contextlib
import fcntl
import multiprocessing
import os
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from bench.common import REPO, angles_seq, log, percentile, sample_uavcan, seq_angles

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
        msg.thruster_vertical_radians, msg.thruster_horizontal_radians = seq_angles(seq)
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
            self.rx_at[angles_seq(msg.vertical_radians, msg.horizontal_radians)] = now


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
        from sam_runtime.cyphal_io.transport import make_node

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
        from sam_runtime.cyphal_io.transport import aclose

        extra, self.nodes[keep:] = self.nodes[keep:], []
        with contextlib.suppress(Exception):
            await aclose(*extra)
        await asyncio.sleep(0.2)

    async def close(self) -> None:
        from sam_runtime.cyphal_io.transport import aclose

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
        cmd.vertical_radians, cmd.horizontal_radians = seq_angles(seq)
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



def imu_payload(rig: Rig) -> bytes:
    """The IMU sample's transfer payload (classic CAN with tail array optimisation on DroneCAN)."""
    if rig.kind == "dronecan":
        from dronecan import transport

        return bytes(transport.Transfer(payload=rig.imu_sample).payload)
    import pycyphal.dsdl

    return b"".join(pycyphal.dsdl.serialize(rig.imu_sample))


