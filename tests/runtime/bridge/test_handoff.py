"""The bridge's ROS -> UAVCAN hand-off and its receive stamps (runtime/bridge/outbound.py, handoff.py).

- hand-off, without ROS or a transport: objects handed off from another thread reach the mapping's bounded
  queue in order, with one wake-up of the asyncio loop per batch, and the same drops (``queue_full``,
  ``shutdown``) as one ``call_soon_threadsafe`` per object had; nothing stays behind in a race with the drain;
  a closed loop counts what it can no longer take.
- end to end on python-can ``virtual`` CAN FD in a helper process (tests/helpers/handoff_scenario.py): ROS
  commands reach the actuator's subject in order and counted (``published`` + ``dropped.queue_full`` ==
  ``received``) in paced chunks and in one burst beyond the queue; an IMU transfer with an unknown timestamp is
  stamped with the system time, with the /clock time while use_sim_time is set at run time, and with the
  system time again once it is cleared.
"""

from __future__ import annotations

import asyncio
import json
import logging
import subprocess
import sys
import threading
import time
from typing import Any

import pytest
from helpers.runtime_support import HELPERS, child_env, domain_id, generated_or_skip, ros_prefix_for


# ============================================================================================ hand-off
def _outbound(queue_size: int) -> tuple[Any, Any]:
    """The bridge's ROS -> UAVCAN path, not started, with one mapping whose converter passes the object through
    (no ROS node, no backend)."""
    from sam_runtime.bridge.counters import MappingStats
    from sam_runtime.bridge.lifetime import Lifetime
    from sam_runtime.bridge.outbound import Outbound, OutMapping
    from sam_runtime.common.rate_log import RateLimitedLog

    gen = generated_or_skip()
    info = next((m for m in gen.tables().MAPPINGS if m.direction == "ros_to_uavcan"), None)
    if info is None:
        pytest.skip("the spec has no ROS -> UAVCAN mapping")
    lifetime = Lifetime("test", RateLimitedLog(logging.getLogger("test_bridge_handoff")))
    om = OutMapping(info, lambda msg, stats: msg, MappingStats(threading.Lock(), info.name, lifetime.rlog))
    return Outbound(lifetime, [om], lambda: True, queue_size=queue_size), om


class _CountingLoop:
    """Counts the hand-off's call_soon_threadsafe calls on a real loop (one per wake-up)."""

    def __init__(self, loop: asyncio.AbstractEventLoop) -> None:
        self.loop = loop
        self.calls = 0

    def call_soon_threadsafe(self, *args: Any) -> Any:
        self.calls += 1
        return self.loop.call_soon_threadsafe(*args)

    def is_closed(self) -> bool:
        return self.loop.is_closed()


def _drops(om: Any) -> dict[str, int]:
    return dict(om.stats.snapshot()["dropped"])


def test_handoff_batch_overflows_like_one_call_per_object() -> None:
    """300 objects handed off while the loop is busy: one wake-up, the first 8 queued in order, 292 queue_full."""
    out, om = _outbound(queue_size=8)

    async def main() -> None:
        loop = asyncio.get_running_loop()
        counting = _CountingLoop(loop)
        out.handoff.loop = counting
        om.queue = asyncio.Queue(maxsize=8)
        producer = threading.Thread(target=lambda: [out.on_ros([om], i) for i in range(300)])
        producer.start()
        producer.join()  # blocks the loop: every hand-off happens before the first drain
        assert counting.calls == 1 and len(out.handoff) == 300
        await asyncio.sleep(0.01)
        assert [om.queue.get_nowait() for _ in range(om.queue.qsize())] == list(range(8))
        assert counting.calls == 1 and not len(out.handoff) and not out.handoff.scheduled

    asyncio.run(main())
    st = om.stats.snapshot()
    assert st["received"] == 300 and _drops(om) == {"queue_full": 292}


def test_handoff_race_with_the_drain_loses_nothing() -> None:
    """A producer thread and a consuming worker race for 20,000 objects: all arrive, in order, with fewer
    wake-ups than objects, and no drop."""
    n = 20_000
    out, om = _outbound(queue_size=n)
    got: list[int] = []

    async def main() -> None:
        loop = asyncio.get_running_loop()
        counting = _CountingLoop(loop)
        out.handoff.loop = counting
        om.queue = asyncio.Queue(maxsize=n)

        async def worker() -> None:
            while len(got) < n:
                assert om.queue is not None
                got.append(await om.queue.get())

        def produce() -> None:
            for i in range(n):
                out.on_ros([om], i)
                if i % 97 == 0:
                    time.sleep(0)  # let the loop drain mid-stream

        task = asyncio.create_task(worker())
        producer = threading.Thread(target=produce)
        producer.start()
        while producer.is_alive():
            await asyncio.sleep(0.001)
        producer.join()
        await asyncio.wait_for(task, 10.0)
        assert 1 <= counting.calls < n, counting.calls

    asyncio.run(main())
    assert got == list(range(n))
    assert om.stats.snapshot()["received"] == n and _drops(om) == {}


def test_handoff_after_the_loop_closed_counts_shutdown() -> None:
    """A drain scheduled before the loop closed never runs: what it would have taken and every later hand-off
    is counted as shutdown, not left in the deque."""
    out, om = _outbound(queue_size=8)
    loop = asyncio.new_event_loop()
    out.handoff.loop = loop
    om.queue = None
    out.on_ros([om], 1)  # schedules a drain on a loop that will never run it
    out.on_ros([om], 2)
    assert out.handoff.scheduled and len(out.handoff) == 2
    loop.close()
    out.on_ros([om], 3)
    assert not len(out.handoff)
    assert om.stats.snapshot()["received"] == 3 and _drops(om) == {"shutdown": 3}


def test_a_failing_ros_callback_is_counted_and_never_raises() -> None:
    """A bug inside the hand-off (here: no loop to hand to) must not escape into the rclpy executor, where it
    would also hold back the messages it has queued: counted as handler_error, and the next message goes on."""
    out, om = _outbound(queue_size=8)
    out.handoff.loop = None  # not started: nothing to hand to
    out.on_ros([om], 1)
    assert _drops(om) == {"handler_error": 1} and out.lifetime.errors["handler_error"] == 1
    loop = asyncio.new_event_loop()
    try:
        out.handoff.loop = loop
        om.queue = asyncio.Queue(maxsize=8)
        out.on_ros([om], 2)
        loop.run_until_complete(asyncio.sleep(0))
        assert om.queue.get_nowait() == 2
    finally:
        loop.close()
    assert om.stats.snapshot()["received"] == 2


def test_a_nan_command_is_dropped_as_not_a_number() -> None:
    """Issue 29 item 5: a converter that rejects a command for NaN (``stats.reject_nan``) has its drop counted as
    ``not_a_number``, beside ``rejected.<mapping>.<field>``; any other rejection stays ``rejected``."""
    out, om = _outbound(queue_size=8)

    def convert(msg: Any, stats: Any) -> Any:
        (stats.reject_nan if msg != msg else stats.reject)("m.angle")
        return None

    om.to_uavcan = convert
    out.on_ros([om], float("nan"))
    out.on_ros([om], 1e9)
    out.on_ros([om], float("nan"))
    snapshot = om.stats.snapshot()
    assert snapshot["dropped"] == {"not_a_number": 2, "rejected": 1}
    assert snapshot["rejected_fields"] == {"m.angle": 3} and snapshot["received"] == 3


def test_handoff_drained_at_close_counts_shutdown() -> None:
    """What the rclpy thread handed off last, still in the deque when the bridge closes: shutdown."""
    out, om = _outbound(queue_size=8)

    async def main() -> None:
        out.handoff.loop = asyncio.get_running_loop()
        om.queue = asyncio.Queue(maxsize=8)
        out.on_ros([om], 1)
        out.lifetime.closed = True
        out.handoff.drain()

    asyncio.run(main())
    assert _drops(om) == {"shutdown": 1}


# ============================================================================================ end to end
@pytest.fixture(scope="module")
def scenario(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    pytest.importorskip("rclpy")
    pytest.importorskip("can")
    gen = generated_or_skip()
    if gen.tables().VEHICLE != "sam":
        pytest.skip("the scenario uses the SAM spec's /thruster_angles and /imu mappings")
    prefix = ros_prefix_for(gen)
    out = tmp_path_factory.mktemp("handoff") / "result.json"
    cmd = [sys.executable, str(HELPERS / "handoff_scenario.py"), "--iface", f"virtual:handoff{id(out)}",
           "--out", str(out)]
    env = child_env(prefix, domain_id(7), {"SAM_GENERATED_DIR": str(gen.root)})
    proc = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=180)
    assert proc.returncode == 0 and out.exists(), f"scenario failed:\n{proc.stdout[-3000:]}\n{proc.stderr[-5000:]}"
    assert "Traceback" not in proc.stderr, proc.stderr[-5000:]
    return json.loads(out.read_text())


@pytest.mark.ros
@pytest.mark.slow
def test_commands_in_order_and_counted(scenario: dict[str, Any]) -> None:
    paced, burst = scenario["paced"], scenario["burst"]
    # Paced chunks no larger than the queue: every command reaches the actuator, in order, none dropped.
    assert paced["at_actuator"] == list(range(paced["sent"])), paced
    assert paced["stats"]["received"] == paced["stats"]["published"] == paced["sent"]
    assert paced["stats"]["dropped"] == {}
    # One burst beyond the queue: what is not published is counted as queue_full, nothing else; the actuator
    # gets exactly the published ones, in order.
    st = burst["stats"]
    assert st["received"] == burst["sent"] + paced["sent"], burst
    assert set(st["dropped"]) <= {"queue_full"}, st
    assert st["published"] + st["dropped"].get("queue_full", 0) == st["received"], st
    seqs = burst["at_actuator"]
    assert len(seqs) == st["published"] - paced["sent"] and seqs == sorted(set(seqs)), burst
    assert all(paced["sent"] <= s < paced["sent"] + burst["sent"] for s in seqs)


@pytest.mark.ros
@pytest.mark.slow
def test_receive_stamps_follow_the_ros_clock(scenario: dict[str, Any]) -> None:
    stamps = scenario["stamps"]
    for phase in ("system", "system_again"):
        s = stamps[phase]
        assert s["before_ns"] <= s["stamp_ns"] <= s["after_ns"], (phase, s)
        assert s["ros_time_active"] is False
    sim = stamps["sim"]
    assert sim["ros_time_active"] is True
    assert sim["stamp_ns"] == sim["clock_ns"], sim


def test_garbage_cdr_on_a_command_topic_is_bad_cdr_not_convert_error() -> None:
    """Issue 29 item 7: on the wire path a command whose bytes are not valid CDR is bad input from the ROS side,
    counted as ``bad_cdr``; ``convert_error`` stays what it says (a converter bug), also on the wire path."""
    import importlib

    out, om = _outbound(queue_size=8)
    codec = importlib.import_module("sam_bridge.codec")
    om.raw = True
    om.to_uavcan = codec.CODECS[om.info.name][1]  # the generated CDR -> payload codec of the mapping
    for junk in (b"", b"\x00", b"\x00\x01\x00\x00", b"\xff" * 64, b"\x00\x01\x00\x00" + b"\xff" * 3):
        out.on_ros([om], junk)
    assert _drops(om) == {"bad_cdr": 5}

    def broken(msg: Any, stats: Any) -> Any:
        raise ZeroDivisionError("a bug")

    om.to_uavcan = broken
    out.on_ros([om], b"\x00\x01\x00\x00")
    assert _drops(om) == {"bad_cdr": 5, "convert_error": 1}
