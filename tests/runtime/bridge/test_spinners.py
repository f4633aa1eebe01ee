"""The bridge's ROS executors do not poll (issue 26: an idle bridge's cost), in one process, a private ROS domain:

- the bridge's executor (RosSide) runs every callback of its nodes, the bridge's and another part's added with
  ``add_node`` (the DroneCAN duties' Panic node: no thread of its own), on its one thread, and does not return to
  Python while nothing happens; stopping wakes it at once (its wait has no short timeout);
- the service mappings' executor thread (SpinThread) waits for work without a timeout: idle, it does not go round;
  ``close()`` wakes and ends it at once.
"""

from __future__ import annotations

import asyncio
import logging
import threading
import time
from typing import Any

import pytest

pytest.importorskip("rclpy")

from helpers.dronecan_support import until
from helpers.runtime_support import domain_id

from sam_runtime.bridge.backends.spin_thread import SpinThread, WaitingCalls
from sam_runtime.bridge.lifetime import Lifetime
from sam_runtime.bridge.ros_side import RosSide
from sam_runtime.common.rate_log import RateLimitedLog

pytestmark = [pytest.mark.ros]

IDLE_S = 1.0  # a 10 Hz poll would go round ~10 times in it; an executor that waits goes round at most once


class _Counting:
    """An executor seen through a proxy that counts the calls that return to Python."""

    def __init__(self, inner: Any) -> None:
        self.inner = inner
        self.calls = 0

    def spin_until_future_complete(self, *args: Any, **kwargs: Any) -> Any:
        self.calls += 1
        return self.inner.spin_until_future_complete(*args, **kwargs)

    def spin_once(self, *args: Any, **kwargs: Any) -> Any:
        self.calls += 1
        return self.inner.spin_once(*args, **kwargs)

    def __getattr__(self, name: str) -> Any:
        return getattr(self.inner, name)


@pytest.fixture
def private_domain(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ROS_DOMAIN_ID", domain_id(143))


def _lifetime() -> Lifetime:
    return Lifetime("t", RateLimitedLog(logging.getLogger("test_spinners"), 10.0))


def test_the_bridge_executor_runs_other_nodes_on_its_thread_and_sleeps_when_idle(private_domain: None) -> None:
    asyncio.run(_bridge_executor_scenario())


async def _bridge_executor_scenario() -> None:
    from std_msgs.msg import String

    lt = _lifetime()
    ros = RosSide(lt, "spin_test")
    ros.attach()
    seen: list[str] = []
    counting: dict[str, _Counting] = {}

    def add_part() -> None:  # as the DroneCAN duties do: their own node on the bridge's executor
        from rclpy.node import Node

        node = Node("spin_test_part", context=ros.context)
        node.create_subscription(String, "/spin_test/ping", lambda m: seen.append(threading.current_thread().name),
                                 10)
        ros.add_node(node)
        counting["executor"] = ros.executor = _Counting(ros.executor)

    lt.add_hooks("a part", start=add_part)
    ros.attach_spinner()
    await lt.start()
    try:
        pub = ros.node.create_publisher(String, "/spin_test/ping", 10)
        await until(lambda: pub.get_subscription_count() > 0, 10, "the part's subscription")
        pub.publish(String(data="ping"))
        await until(lambda: seen, 10, "the part's callback")
        assert seen == ["spin_test-rclpy"]  # the bridge's executor thread, no thread of the part's own
        calls = counting["executor"].calls
        await asyncio.sleep(IDLE_S)
        assert counting["executor"].calls - calls <= 1
        assert [t.name for t in threading.enumerate() if t.name.startswith("spin_test")] == ["spin_test-rclpy"]
    finally:
        started = time.monotonic()
        await lt.close()
    assert not any(t.name == "spin_test-rclpy" for t in threading.enumerate())
    assert time.monotonic() - started < 4.0  # woken, not left to its hour-long wait (the join gives up at 5 s)
    assert lt.errors == {}


def test_the_service_thread_waits_without_polling_and_close_ends_it(private_domain: None) -> None:
    import rclpy
    from rclpy.executors import MultiThreadedExecutor, SingleThreadedExecutor
    from rclpy.node import Node
    from std_srvs.srv import Trigger

    context = rclpy.Context()
    rclpy.init(context=context)
    try:
        lt = _lifetime()
        node = Node("spin_test_services", context=context)
        node.create_service(Trigger, "/spin_test/trigger",
                            lambda req, resp: setattr(resp, "message", threading.current_thread().name) or resp)
        class CountingExecutor(MultiThreadedExecutor):
            """Counts its rounds: each wait for work (that returns work, times out or is woken)."""

            calls = 0

            def wait_for_ready_callbacks(self, *args: Any, **kwargs: Any) -> Any:
                CountingExecutor.calls += 1
                return super().wait_for_ready_callbacks(*args, **kwargs)

        executor = CountingExecutor(num_threads=2, context=context)
        spinner = SpinThread(lt, context, executor, node, "spin-test-services", "service_executor_error", "test")
        spinner.start()
        client_node = Node("spin_test_client", context=context)
        client = client_node.create_client(Trigger, "/spin_test/trigger")
        assert client.wait_for_service(timeout_sec=10.0)
        future = client.call_async(Trigger.Request())
        client_executor = SingleThreadedExecutor(context=context)
        client_executor.add_node(client_node)
        client_executor.spin_until_future_complete(future, timeout_sec=10.0)
        assert future.done() and future.result() is not None  # served while the thread waits without a timeout
        calls = executor.calls
        time.sleep(IDLE_S)
        assert executor.calls - calls <= 2  # (one more round may finish the call that just ended)
        started = time.monotonic()
        spinner.close()
        assert not spinner.thread.is_alive() and time.monotonic() - started < 1.9
        assert lt.errors == {}
        client_executor.shutdown()
        client_node.destroy_node()
    finally:
        context.shutdown()


def test_the_parts_that_wait_for_devices_share_one_thread(private_domain: None) -> None:
    """WaitingCalls: the service mappings' and the store services' nodes on one executor thread, which starts with
    the first node and ends with the last (a managed bridge's cleanup leaves none); both nodes are served."""
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.node import Node
    from std_srvs.srv import Trigger

    def threads() -> list[str]:
        return [t.name for t in threading.enumerate() if t.name == "wait_test-calls"]

    context = rclpy.Context()
    rclpy.init(context=context)
    try:
        lt = _lifetime()
        calls = WaitingCalls(lt, "wait_test-calls")
        nodes = [Node(f"wait_test_{k}", context=context) for k in ("services", "settings")]
        for k, node in enumerate(nodes):
            node.create_service(Trigger, f"/wait_test/trigger_{k}",
                                lambda req, resp: setattr(resp, "message", threading.current_thread().name) or resp)
            calls.add(context, node)
        assert threads() == ["wait_test-calls"] and set(calls.nodes) == set(nodes)  # (rclpy keeps a set)
        client_node = Node("wait_test_client", context=context)
        client_executor = SingleThreadedExecutor(context=context)
        client_executor.add_node(client_node)
        for k in range(2):  # both served (the second node was added while the thread was spinning)
            client = client_node.create_client(Trigger, f"/wait_test/trigger_{k}")
            assert client.wait_for_service(timeout_sec=10.0)
            future = client.call_async(Trigger.Request())
            client_executor.spin_until_future_complete(future, timeout_sec=10.0)
            assert future.done() and future.result() is not None, k
        calls.remove(nodes[0])
        assert threads() == ["wait_test-calls"] and calls.nodes == [nodes[1]]
        calls.remove(nodes[1])
        assert threads() == [] and calls.nodes == []
        assert lt.errors == {}
        client_executor.shutdown()
        client_node.destroy_node()
    finally:
        context.shutdown()
