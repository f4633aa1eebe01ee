"""Profile one bridge path with cProfile, every thread (py-spy cannot attach on these machines: ptrace fails).

    python -m bench.profile_bridge [u2r_bridge|r2u_bridge|u2r_raw|r2u_raw] [udp|can|dronecan] [seconds] [experiment ...]
    python -m bench.profile_bridge ab [udp|can] [seconds] [reps] [variant ...]     (see A/B below)

Runs the flow-controlled throughput measurement of bench/bridge.py (``dronecan``: bench/bridge_dronecan.py, the
bridge on DroneCAN with plain dronecan nodes) on that path and prints, per thread, the
functions by own time and the top cumulative entries (PROFILE_FILTER=regex restricts the listing; PROFILE=0 runs
without the profiler, for the plain figure; PROFILE_WIRE=object profiles the bridge's object path instead of its
wire path). Not part of `nox -s bench`.

Experiments (monkeypatches in this process only, to size a proposed fix of runtime/bridge/ before anyone makes
it; nothing is changed on disk):
- ``events_executor``: the bridge's rclpy executor is rclpy.experimental.EventsExecutor instead of the Python
  SingleThreadedExecutor;
- ``no_qos_events``: publishers and subscriptions created without rclpy's default QoS-event handlers (each adds
  waitables that the Python executor rebuilds its wait set from on every wake-up). With the EventsExecutor the
  bridge uses, no measurable gain (3 alternating runs of the A/B below: paired ratios within the noise).

A/B of the bridge's own per-message choices, interleaved with the raw reference in ONE process (the machine is
noisy: only figures of the same run compare):

    python -m bench.profile_bridge ab [udp|can] [seconds] [reps] [variant ...]

Every rep runs u2r_raw, each variant on u2r_bridge, r2u_raw, each variant on r2u_bridge (the order rotated per
rep) and prints per variant the median msg/s, the median of the per-rep ratios to raw, and CPU ms per 1000
messages (process, asyncio thread, rclpy thread). A variant is ``new`` (runtime/bridge/ as it is) or a
``+``-joined list of what to put back as it was before, switched on the running bridge between runs:
- ``old_handoff``: one ``call_soon_threadsafe`` (one self-pipe write) per command instead of one per batch;
- ``old_clock``: receive stamps from rclpy's ``Clock.now()`` for every transfer instead of ``time.time_ns()``;
- ``old_spin``: the rclpy thread returns to Python after every callback (``spin_once``) instead of spinning
  0.1 s slices in the EventsExecutor (``spin_until_future_complete``).
Default variants: ``old_handoff+old_clock+old_spin new``.
"""

from __future__ import annotations

import asyncio
import cProfile
import io
import os
import pstats
import sys
import threading
from typing import Any

import bench.common  # noqa: F401  (loopback discovery before rclpy)

PROFILES: dict[str, cProfile.Profile] = {}
EXPERIMENTS: list[str] = []


def _experiments(names: list[str]) -> None:
    import rclpy.executors
    import rclpy.node

    if "events_executor" in names:
        from rclpy.experimental import EventsExecutor

        rclpy.executors.SingleThreadedExecutor = lambda context=None: EventsExecutor(context=context)
    if "no_qos_events" in names:
        from rclpy.event_handler import PublisherEventCallbacks, SubscriptionEventCallbacks

        orig_pub, orig_sub = rclpy.node.Node.create_publisher, rclpy.node.Node.create_subscription

        def create_publisher(self: Any, *a: Any, **kw: Any) -> Any:
            kw.setdefault("event_callbacks", PublisherEventCallbacks(use_default_callbacks=False))
            return orig_pub(self, *a, **kw)

        def create_subscription(self: Any, *a: Any, **kw: Any) -> Any:
            kw.setdefault("event_callbacks", SubscriptionEventCallbacks(use_default_callbacks=False))
            return orig_sub(self, *a, **kw)

        rclpy.node.Node.create_publisher = create_publisher
        rclpy.node.Node.create_subscription = create_subscription


# ----------------------------------------------------------------------------------------------- A/B mode
class _SpinSwitch:
    """Wraps the bridge's executor (before its thread starts) so that ``old_spin`` can be switched at run time."""

    def __init__(self, executor: Any) -> None:
        self.executor = executor
        self.old_spin = False

    def spin_until_future_complete(self, future: Any, timeout_sec: float | None = None) -> None:
        if self.old_spin:
            self.executor.spin_once(timeout_sec=timeout_sec)
        else:
            self.executor.spin_until_future_complete(future, timeout_sec=timeout_sec)

    def __getattr__(self, name: str) -> Any:
        return getattr(self.executor, name)


def _old_on_ros(self: Any, oms: list[Any], msg: Any) -> None:
    """The bridge's Outbound.on_ros before the batched hand-off (without its log lines)."""
    loop = self.handoff.loop
    for om in oms:
        st = om.stats
        st.receive()
        try:
            obj = om.to_uavcan(msg, st)
        except Exception:
            st.drop("convert_error")
            continue
        if obj is None:
            st.drop("rejected")
            continue
        try:
            loop.call_soon_threadsafe(self._enqueue, om, obj)
        except RuntimeError:
            st.drop("shutdown")


def _set_variant(bridge: Any, variant: str) -> None:
    import types

    parts = set() if variant == "new" else set(variant.split("+"))
    unknown = parts - {"old_handoff", "old_clock", "old_spin"}
    if unknown:
        raise SystemExit(f"unknown variant part(s) {sorted(unknown)}")
    if "old_handoff" in parts:
        bridge.outbound.on_ros = types.MethodType(_old_on_ros, bridge.outbound)
    else:
        bridge.outbound.__dict__.pop("on_ros", None)
    # The ROS clock is read for every stamp while ros_time_active (as under use_sim_time); the system clock is
    # ROS time here (no use_sim_time), so the stamps are the same either way.
    bridge.ros.ros_time_active = "old_clock" in parts
    bridge.ros.executor.old_spin = "old_spin" in parts


async def ab(kind: str, seconds: float, reps: int, variants: list[str]) -> None:
    from bench.bridge_blocks import PATHS
    from bench.bridge_rig import Rig
    from bench.common import generated_package, median
    from sam_runtime.bridge.ros_side import RosSide
    from sam_runtime.cyphal_io.transport import quiet_late_media_completions

    quiet_late_media_completions(asyncio.get_running_loop())
    gen = generated_package()
    gen.convert()
    open_ros = RosSide._open

    def _open_ros(self: Any) -> None:
        open_ros(self)
        self.executor = _SpinSwitch(self.executor)

    RosSide._open = _open_ros  # type: ignore[method-assign]
    pid = os.getpid()
    rig = (Rig(gen, "udp", "127.0.0.1", "127.0.0.1", None) if kind == "udp"
           else Rig(gen, "can", f"virtual:ab{pid}", f"virtual:ar{pid}", 64))
    names = ["raw", *variants]
    runs: dict[tuple[str, str], list[dict[str, Any]]] = {(d, v): [] for d in ("u2r", "r2u") for v in names}
    try:
        await rig.start({})
        for p in PATHS:
            await rig.windowed(p, 0.3, cpu=False)
        for r in range(reps):
            order = names[r % len(names):] + names[:r % len(names)]
            for d in ("u2r", "r2u"):
                for v in order:
                    if v != "raw":
                        _set_variant(rig.bridge, v)
                    res = await rig.windowed(f"{d}_{'raw' if v == 'raw' else 'bridge'}", seconds)
                    runs[(d, v)].append(res)
                    await asyncio.sleep(0.1)
        drops = {n: m["dropped"] for n, m in rig.bridge.stats()["mappings"].items() if m["dropped_total"]}
    finally:
        await rig.close()
    print(f"{kind}: {reps} reps of {seconds} s; load average now {open('/proc/loadavg').read().split()[:3]}")
    for d in ("u2r", "r2u"):
        raw = runs[(d, "raw")]
        for v in names:
            rs = runs[(d, v)]
            n = max(1, sum(x["received"] for x in rs))

            def cpu(key: str, rs: list[dict[str, Any]] = rs, n: int = n) -> float:
                return sum(x["cpu_s"].get(key, 0.0) for x in rs) / n * 1e6

            paired = median([x["msg_per_s"] / y["msg_per_s"] for x, y in zip(rs, raw, strict=True)])
            print(f"  {d} {v:32s} {median([x['msg_per_s'] for x in rs]):6.0f} msg/s  ratio to raw {paired:.3f}  "
                  f"lost {sum(x['lost'] for x in rs)}  CPU ms/1000: process {cpu('process'):.0f}, "
                  f"asyncio {cpu('main (asyncio loop)'):.0f}, rclpy {cpu('bridge rclpy thread'):.0f}  "
                  f"runs {[round(x['msg_per_s']) for x in rs]}")
    print(f"  bridge drops: {drops or 'none'}")


def _thread_hook(frame: Any, event: str, arg: Any) -> None:
    prof = cProfile.Profile()
    PROFILES[threading.current_thread().name] = prof
    sys.setprofile(None)
    prof.enable()


async def main(path_name: str, kind: str, seconds: float) -> None:
    from bench.bridge_rig import Rig
    from bench.common import generated_package

    gen = generated_package()
    gen.convert()
    _experiments(EXPERIMENTS)
    pid = os.getpid()
    if kind == "dronecan":  # bench/bridge_dronecan.py: the DroneCAN bridge and plain dronecan nodes
        from bench.bridge_dronecan import DroneCanRig, private_ifaces

        rig: Any = DroneCanRig(gen, *private_ifaces())
    else:
        rig = (Rig(gen, "udp", "127.0.0.1", "127.0.0.1", None) if kind == "udp"
               else Rig(gen, "can", f"virtual:pb{pid}", f"virtual:pr{pid}", 64))
    rig.wire = os.environ.get("PROFILE_WIRE", "codec")  # the bridge's path: codec (wire codecs) or object
    profile = os.environ.get("PROFILE", "1") != "0"
    if profile:
        threading.setprofile(_thread_hook)
    try:
        await rig.start({})
        await rig.windowed(path_name, 0.5, cpu=False)
        main_prof = cProfile.Profile()
        if profile:
            PROFILES["MainThread"] = main_prof
            main_prof.enable()
        res = await rig.windowed(path_name, seconds)
        main_prof.disable()
        print(f"{path_name} on {kind} ({rig.bridge.wire} path): {res['msg_per_s']:.0f} msg/s, lost {res['lost']}, "
              f"CPU s {res['cpu_s']}")
    finally:
        threading.setprofile(None)
        await rig.close()
    for name, prof in PROFILES.items():
        if "InputSession" in name:
            continue
        out = io.StringIO()
        st = pstats.Stats(prof, stream=out)
        if not st.stats:
            continue
        print(f"\n======== thread {name}: by own time")
        st.sort_stats("tottime").print_stats(*([os.environ["PROFILE_FILTER"]] if os.environ.get("PROFILE_FILTER")
                                               else []), 30)
        print(out.getvalue()[-9000:])
        out2 = io.StringIO()
        pstats.Stats(prof, stream=out2).sort_stats("cumulative").print_stats(25)
        print(f"======== thread {name}: cumulative")
        print(out2.getvalue()[-7000:])


if __name__ == "__main__":
    os.environ.setdefault("ROS_DOMAIN_ID", str(150 + os.getpid() % 60))
    args = sys.argv[1:]
    if args and args[0] == "ab":
        import logging

        from bench.bridge_rig import cyphal_udp_lock

        logging.getLogger("sam_runtime").setLevel(logging.ERROR)
        kind = args[1] if len(args) > 1 else "udp"
        coro = ab(kind, float(args[2]) if len(args) > 2 else 1.5, int(args[3]) if len(args) > 3 else 8,
                  args[4:] or ["old_handoff+old_clock+old_spin", "new"])
        if kind == "udp":
            with cyphal_udp_lock():
                asyncio.run(coro)
        else:
            asyncio.run(coro)
        sys.exit(0)
    EXPERIMENTS.extend(args[3:])
    asyncio.run(main(args[0] if args else "u2r_bridge", args[1] if len(args) > 1 else "udp",
                     float(args[2]) if len(args) > 2 else 3.0))
