"""The end-to-end run of a spec's mappings across processes: its bridge (stats in bridge.json), its simulated
devices (``sam-sim`` with a report, sim.json, and a record of every transfer, sim.jsonl), a ROS listen probe
(listen.json, and its record of every message) and, once the probe hears the devices, a ROS publish probe playing
d/plan.json (tests/helpers/ros_probe.py).

Invariants: the body of `bridge_sim_probe` runs after the plan was published in full; when the body ends normally
the devices, the probe and the bridge are stopped by SIGTERM and each must exit 0 (the simulator writes its report
at exit); whichever way it ends, every process started is stopped. Every wait has a deadline.
"""

from __future__ import annotations

import signal
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path

from helpers.ros_probe import listen_cmd, publish_cmd
from helpers.runtime_support import Proc, poll_until, read_json, runtime_cmd


@contextmanager
def bridge_sim_probe(d: Path, env: dict[str, str], generated: Path, bus: Sequence[str], protocol: str,
                     devices: str, topics: Sequence[str], record: Path,
                     heard: Callable[[dict[str, int]], bool], what: str,
                     bridge_args: Sequence[str] = ()) -> Iterator[None]:
    """`bus` the transport arguments both the bridge and the simulator take; `topics` what the probe listens to
    (recorded in `record`); `heard` when the probe's message counts show the devices are heard (`what` names
    it); `bridge_args` more arguments of the bridge (``--namespace /sam1``)."""
    bridge = Proc("bridge", runtime_cmd("bridge", *bus, "--protocol", protocol, "--stats-file",
                                        str(d / "bridge.json"), *bridge_args), env, d)
    sim = Proc("sim", runtime_cmd("sim", *bus, "--devices", devices, "--report", str(d / "sim.json"),
                                  "--record", str(d / "sim.jsonl")), env, d)
    listen = Proc("listen", listen_cmd(generated, topics, d / "listen.json", record), env, d)
    publish = None
    try:
        bridge.wait_line("READY", 120)
        sim.wait_line("READY", 120)
        listen.wait_line("READY", 60)
        poll_until(lambda: heard((read_json(d / "listen.json") or {}).get("counts", {})), 60, what)
        publish = Proc("publish", publish_cmd(generated, d / "plan.json", d / "publish.json"), env, d)
        assert publish.wait(90) == 0, publish.stderr_tail()
        yield
        assert sim.stop(signal.SIGTERM) == 0, sim.stderr_tail()  # its report, written at exit
        assert listen.stop(signal.SIGTERM) == 0, listen.stderr_tail()
        assert bridge.stop(signal.SIGTERM) == 0, bridge.stderr_tail()
    finally:
        for p in (publish, listen, sim, bridge):
            if p is not None:
                p.stop()
