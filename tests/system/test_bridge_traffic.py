"""The bridge's run-time traffic control across processes (issue 19), on tests/specs/weir.yaml: the simulated gauge
publishes its level at 50 Hz (sam-sim) to the bridge (sam-bridge), over Cyphal/UDP 127.0.0.1 and (layout dronecan)
over DroneCAN on a private ``mcast-lo:`` bus, and this test's own rclpy node (its own context and ROS domain: an
independent client) listens, calls the services and publishes commands.

- ``level`` (max_rate_hz: 4): what reaches ROS is at most what 4 Hz allows over the interval its messages span,
  judged from the DDS source timestamps the bridge's publisher put on them (the system's clock at publish time, not
  this process's receive times), and again from the bridge's own /diagnostics reports (their stamps and counters);
  the rest is counted as ``rate_limited``, and received == published + dropped (+ at most the one held message).
- ``level_raw`` (enabled: false): nothing on /level_raw while /diagnostics shows it disabled and counts
  ``dropped.disabled``; ``std_srvs/SetBool`` on ``/weir_bridge/enable_level_raw`` (the default name) from this
  process enables it, and its messages arrive.
- ``gate`` (ROS->UAVCAN, max_rate_hz: 2, deadline: 1.5, enable_service: start_stop_gate): disabled through
  ``/start_stop_gate`` its commands are dropped as ``disabled``; enabled again a burst is coalesced to the latest.

Every wait polls a condition with a generous deadline; no verdict rests on this process's timing.
"""

from __future__ import annotations

import sys
import threading
from collections.abc import Callable
from contextlib import ExitStack
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("pycyphal")
pytest.importorskip("rclpy")

from helpers.ros_probe import SpunNode
from helpers.runtime_support import Proc, child_env, cyphal_udp_lock, domain_id, runtime_cmd
from helpers.runtime_support import poll_until as wait_for
from helpers.spec_build import generated_spec

from sam_runtime.bridge.rate_limit import most_in

pytestmark = [pytest.mark.ros, pytest.mark.slow]

BRIDGE = "weir_bridge"
LEVEL_RATE_HZ = 4.0  # tests/specs/weir.yaml
START_TIMEOUT_S = 90.0
# The source timestamp is taken inside rclpy's publish, a moment after the pacer let the message out: two
# neighbours may look that much closer than the interval. One message of slack covers it.
STAMP_SLACK = 1



class TrafficProbe(SpunNode):
    """The test's rclpy node: /level and /level_raw with their DDS source timestamps, the bridge's mapping statuses
    from /diagnostics with their stamps, a /gate publisher, SetBool clients."""

    def __init__(self, domain: int) -> None:
        from diagnostic_msgs.msg import DiagnosticArray
        from std_msgs.msg import Int32, UInt8

        from sam_runtime.node_support import qos_profile

        super().__init__("traffic_probe", domain)
        n = self.node
        self.lock = threading.Lock()
        self.stamps: dict[str, list[int]] = {"/level": [], "/level_raw": []}  # DDS source timestamps, ns
        self.statuses: dict[str, list[tuple[int, dict[str, str], int, str]]] = {}  # (stamp ns, values, level, msg)
        any_publisher = qos_profile("best_effort", "volatile", 200)  # matches reliable and best-effort publishers
        for topic in self.stamps:
            n.create_subscription(Int32, topic, self._on_level(topic), any_publisher)
        n.create_subscription(DiagnosticArray, "/diagnostics", self._on_diag, qos_profile("reliable", "volatile",
                                                                                            200))
        self.gate = n.create_publisher(UInt8, "/gate", qos_profile("reliable", "volatile", 50))
        self.start_spinning("traffic-probe")

    def _on_level(self, topic: str) -> Callable[[Any, Any], None]:
        def on_message(msg: Any, info: Any) -> None:
            with self.lock:
                self.stamps[topic].append(int(info["source_timestamp"]))

        return on_message

    def _on_diag(self, arr: Any) -> None:
        stamp = arr.header.stamp.sec * 1_000_000_000 + arr.header.stamp.nanosec
        with self.lock:
            for s in arr.status:
                if s.name.startswith(f"{BRIDGE}/mapping/"):
                    level = s.level[0] if isinstance(s.level, bytes) else int(s.level)
                    self.statuses.setdefault(s.name.rsplit("/", 1)[1], []).append(
                        (stamp, {kv.key: kv.value for kv in s.values}, level, s.message))

    def received(self, topic: str) -> list[int]:
        with self.lock:
            return sorted(self.stamps[topic])

    def history(self, mapping: str) -> list[tuple[int, dict[str, str], int, str]]:
        with self.lock:
            return list(self.statuses.get(mapping, []))

    def latest(self, mapping: str) -> dict[str, str] | None:
        h = self.history(mapping)
        return h[-1][1] if h else None

    def set_bool(self, service: str, value: bool) -> Any:
        from std_srvs.srv import SetBool

        client = self.node.create_client(SetBool, service)
        wait_for(lambda: client.wait_for_service(timeout_sec=0.1), 30, f"the service {service}")
        future = client.call_async(SetBool.Request(data=value))
        wait_for(future.done, 10, f"the answer of {service}")
        return future.result()

    def close(self, join_timeout_s: float = 2.0) -> None:
        super().close(join_timeout_s)


def _count(values: dict[str, str] | None, key: str) -> int:
    return int((values or {}).get(key, "0"))


@pytest.mark.parametrize("protocol", ["cyphal", "dronecan"])
def test_rate_limit_disabled_mapping_and_setbool_across_processes(protocol: str, tmp_path: Path) -> None:
    generated = generated_spec("weir")  # its topics are std_msgs: no ROS package of its own to build
    domain = domain_id(61 if protocol == "cyphal" else 62)
    env = child_env(Path(sys.prefix).absolute(), domain)
    with ExitStack() as stack:
        if protocol == "cyphal":
            stack.enter_context(cyphal_udp_lock())
            bus = ["--transport", "udp", "--iface", "127.0.0.1"]
        else:
            pytest.importorskip("dronecan")
            from helpers.dronecan_support import private_iface

            bus = ["--layout", "dronecan", "--dronecan-iface", private_iface()]
        bridge = Proc("bridge", runtime_cmd("bridge", "--generated", str(generated), *bus), env, tmp_path)
        sim = Proc("sim", runtime_cmd("sim", "--generated", str(generated), *bus), env, tmp_path)
        probe = TrafficProbe(int(domain))
        try:
            ready = bridge.wait_line("READY", START_TIMEOUT_S)
            assert ("mcast-lo" in ready) == (protocol == "dronecan"), ready
            sim.wait_line("READY", START_TIMEOUT_S)
            _check_rate_limit(probe)
            _check_disabled_then_enabled(probe)
            _check_commands(probe)
        finally:
            probe.close()
            for p in (sim, bridge):
                p.stop()
    assert "Traceback" not in (tmp_path / "bridge.stderr").read_text()


def _check_rate_limit(probe: TrafficProbe) -> None:
    # 16 messages at 4 Hz: about 4 s of the gauge's 50 Hz stream through the limit
    stamps = wait_for(lambda: (s := probe.received("/level")) and len(s) >= 16 and s, 60, "16 messages on /level")
    span_s = (stamps[-1] - stamps[0]) / 1e9
    print(f"/level: {len(stamps)} messages over {span_s:.3f} s by their source stamps "
          f"(4 Hz allows {most_in(span_s, LEVEL_RATE_HZ)})")
    assert len(stamps) <= most_in(span_s, LEVEL_RATE_HZ) + STAMP_SLACK, (len(stamps), span_s)

    # the bridge's own reports: two of them at least 3 s apart by their stamps
    def two_reports() -> tuple[Any, Any] | None:
        h = [r for r in probe.history("level") if _count(r[1], "published") > 0]
        late = [r for r in h if h and r[0] - h[0][0] >= 3e9]
        return (h[0], late[-1]) if late else None

    first, last = wait_for(two_reports, 30, "two /diagnostics reports of mapping level 3 s apart")
    window_s = (last[0] - first[0]) / 1e9
    published = _count(last[1], "published") - _count(first[1], "published")
    limited = _count(last[1], "dropped.rate_limited") - _count(first[1], "dropped.rate_limited")
    print(f"level by /diagnostics: {published} published, {limited} rate_limited over {window_s:.3f} s")
    assert 0 < published <= most_in(window_s, LEVEL_RATE_HZ) + STAMP_SLACK, (published, window_s)
    assert limited > 0  # the gauge sends 50 Hz: the rest is thinned out, and counted
    values = last[1]
    assert values["max_rate_hz"] == "4.0" and values["enabled"] == "True"
    assert values["enable_service"] == f"/{BRIDGE}/enable_level"  # ~/enable_level, resolved by the bridge's node
    # every message that reached the bridge published or counted, but the one waiting for its slot (`lost`
    # counts transfers that never reached it)
    taken = _count(values, "dropped") - _count(values, "dropped.lost") - _count(values, "dropped.lost_link_down")
    assert _count(values, "received") - _count(values, "published") - taken in (0, 1), values
    others = [k for k, v in values.items() if k.startswith("dropped.") and k != "dropped.rate_limited" and v != "0"]
    assert last[2] == 0 or others, last  # intended drops alone never make the mapping WARN


def _check_disabled_then_enabled(probe: TrafficProbe) -> None:
    def disabled_and_dropping() -> dict[str, str] | None:
        v = probe.latest("level_raw")
        return v if v is not None and _count(v, "dropped.disabled") >= 50 else None

    values = wait_for(disabled_and_dropping, 30, "level_raw dropping as disabled")
    assert values["enabled"] == "False" and _count(values, "published") == 0
    assert probe.received("/level_raw") == []  # and nothing reached ROS meanwhile
    assert probe.history("level_raw")[-1][3].startswith(f"disabled (std_srvs/SetBool /{BRIDGE}/enable_level_raw)")

    answer = probe.set_bool(f"/{BRIDGE}/enable_level_raw", True)
    assert answer.success and answer.message == "mapping level_raw: enabled"
    wait_for(lambda: len(probe.received("/level_raw")) >= 20, 30, "messages on /level_raw once enabled")
    after = wait_for(lambda: (v := probe.latest("level_raw")) and v["enabled"] == "True" and _count(
        v, "published") > 0 and v, 10, "/diagnostics showing level_raw enabled and publishing")
    assert _count(after, "dropped.disabled") >= _count(values, "dropped.disabled")


def _check_commands(probe: TrafficProbe) -> None:
    from std_msgs.msg import UInt8

    wait_for(lambda: probe.gate.get_subscription_count() > 0, 30, "the bridge subscribing to /gate")
    answer = probe.set_bool("/start_stop_gate", False)  # the spec's name, relative: in the bridge's namespace
    assert answer.success and answer.message == "mapping gate: disabled"
    for i in range(10):
        probe.gate.publish(UInt8(data=i))
    # (a keep-last reader may lose some of a burst before the bridge takes them: only what it took counts)
    disabled = wait_for(lambda: (v := probe.latest("gate")) and _count(v, "dropped.disabled") >= 1 and v, 30,
                        "commands dropped as disabled")
    assert _count(disabled, "published") == 0
    base = probe.latest("gate") or {}
    assert probe.set_bool("/start_stop_gate", True).success
    for i in range(30):  # a burst far above 2 Hz
        probe.gate.publish(UInt8(data=50 + i))

    def burst_accounted() -> dict[str, str] | None:
        v = probe.latest("gate")
        if v is None:
            return None
        got = _count(v, "received") - _count(base, "received")
        out = sum(_count(v, k) - _count(base, k) for k in ("published", "dropped"))
        return v if got == out and _count(v, "published") - _count(base, "published") >= 2 else None

    values = wait_for(burst_accounted, 30, "the burst's commands published or counted")
    got = _count(values, "received") - _count(base, "received")
    published = _count(values, "published") - _count(base, "published")
    coalesced = _count(values, "dropped.coalesced") - _count(base, "dropped.coalesced")
    print(f"gate burst of 30: {got} taken by the bridge, {published} published, {coalesced} coalesced, "
          f"disabled before: {_count(base, 'dropped.disabled')}")
    # the first at once and the latest at its slot (more if the burst spread over slots on a loaded machine)
    late = sum(_count(values, k) - _count(base, k) for k in ("dropped.expired", "dropped.disabled"))
    # (disabled: one of the first ten the bridge took after `base` was reported, before the switch)
    assert published >= 2 and coalesced >= 1 and published + coalesced + late == got, values
    assert values["deadline_s"] == "1.5" and values["enable_service"] == "/start_stop_gate"
