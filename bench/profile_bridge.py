"""Profile one bridge path with cProfile, every thread (py-spy cannot attach on these machines: ptrace fails).

    python -m bench.profile_bridge [u2r_bridge|r2u_bridge|u2r_raw|r2u_raw] [udp|can] [seconds] [experiment ...]

Runs the flow-controlled throughput measurement of bench/bridge.py on that path and prints, per thread, the
functions by own time and the top cumulative entries (PROFILE_FILTER=regex restricts the listing; PROFILE=0 runs
without the profiler, for the plain figure). Not part of `nox -s bench`.

Experiments (monkeypatches in this process only, to size a proposed fix of runtime/bridge.py before anyone makes
it; nothing is changed on disk):
- ``events_executor``: the bridge's rclpy executor is rclpy.experimental.EventsExecutor instead of the Python
  SingleThreadedExecutor;
- ``no_qos_events``: publishers and subscriptions created without rclpy's default QoS-event handlers (each adds
  waitables that the Python executor rebuilds its wait set from on every wake-up).
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


def _thread_hook(frame: Any, event: str, arg: Any) -> None:
    prof = cProfile.Profile()
    PROFILES[threading.current_thread().name] = prof
    sys.setprofile(None)
    prof.enable()


async def main(path_name: str, kind: str, seconds: float) -> None:
    from bench.bridge import Rig
    from bench.common import generated_package

    gen = generated_package()
    gen.convert()
    _experiments(EXPERIMENTS)
    pid = os.getpid()
    rig = (Rig(gen, "udp", "127.0.0.1", "127.0.0.1", None) if kind == "udp"
           else Rig(gen, "can", f"virtual:pb{pid}", f"virtual:pr{pid}", 64))
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
        print(f"{path_name} on {kind}: {res['msg_per_s']:.0f} msg/s, lost {res['lost']}, CPU s {res['cpu_s']}")
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
    EXPERIMENTS.extend(args[3:])
    asyncio.run(main(args[0] if args else "u2r_bridge", args[1] if len(args) > 1 else "udp",
                     float(args[2]) if len(args) > 2 else 3.0))
