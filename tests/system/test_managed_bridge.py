"""The bridge as a managed (lifecycle) node (issue 30): ``sam-codegen bridge --managed`` as a child process beside the
simulated devices (``sam-sim``), on Cyphal/UDP and on DroneCAN (layout ``dronecan``, a private loopback bus),
driven by an rclpy lifecycle client (lifecycle_msgs/srv/ChangeState and GetState) in the test process:

unconfigured (no bridge topics) -> configure (inactive: telemetry flows, commands dropped as ``inactive``) ->
activate (commands reach the bus) -> deactivate (telemetry flows on, every command after the transition's answer
is dropped and counted ``inactive``, on /diagnostics too; none reaches the bus) -> activate (commands again) ->
deactivate -> cleanup (the bridge's topics gone, the node stays) -> configure -> activate (a new bridge's commands
reach the bus) -> shutdown (the process exits 0).

Commands are /longitudinal_weight_position (one mapping on both protocols), telemetry /imu (100 Hz); what reached
the bus is the bridge's ``published`` count of the command mapping in its stats file (written every second while
a bridge exists). Every wait polls a condition with a deadline.
"""

from __future__ import annotations

import signal
import threading
import time
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("rclpy")
pytest.importorskip("dronecan")

from helpers.dronecan_support import private_iface
from helpers.ros_probe import SpunNode
from helpers.runtime_support import (
    Proc,
    child_env,
    cyphal_udp_lock,
    domain_id,
    generated_or_skip,
    poll_until,
    read_json,
    ros_prefix_for,
    runtime_cmd,
)

pytestmark = [pytest.mark.ros, pytest.mark.slow]

COMMAND_TOPIC = "/longitudinal_weight_position"
TELEMETRY_TOPIC = "/imu"
COMMANDS = 20  # sent in each phase
WAIT_S = 60.0  # a condition on a loaded machine (the configure compiles or loads the DSDL, opens the bus)

# lifecycle_msgs/msg/Transition ids and State ids
CONFIGURE, CLEANUP, ACTIVATE, DEACTIVATE, SHUTDOWN_FROM_ACTIVE = 1, 2, 3, 4, 7
UNCONFIGURED, INACTIVE, ACTIVE = 1, 2, 3


class LifecycleClient(SpunNode):
    """ChangeState/GetState clients of the bridge's node, a /imu counter, a command publisher and the latest
    /diagnostics statuses by name."""

    def __init__(self, node: str, gen: Any, tables: Any) -> None:
        from diagnostic_msgs.msg import DiagnosticArray
        from lifecycle_msgs.srv import ChangeState, GetState
        from rclpy.qos import qos_profile_sensor_data

        super().__init__("test_lifecycle_client")
        self.change = self.node.create_client(ChangeState, f"/{node}/change_state")
        self.get = self.node.create_client(GetState, f"/{node}/get_state")
        topic = next(m.topic for m in tables.MAPPINGS if m.topic.name == COMMAND_TOPIC)
        imu = next(m.topic for m in tables.MAPPINGS if m.topic.name == TELEMETRY_TOPIC)
        self.command_cls = gen.ros_class(topic)
        self.pub = self.node.create_publisher(self.command_cls, COMMAND_TOPIC, 100)
        self.lock = threading.Lock()
        self.imu = 0
        self.statuses: dict[str, dict[str, str]] = {}
        self.node.create_subscription(gen.ros_class(imu), TELEMETRY_TOPIC, self._on_imu, qos_profile_sensor_data)
        self.node.create_subscription(DiagnosticArray, "/diagnostics", self._on_diag, 100)
        self.round_trips: dict[str, float] = {}
        self.start_spinning("lifecycle-client")

    def _on_imu(self, _msg: Any) -> None:
        with self.lock:
            self.imu += 1

    def _on_diag(self, arr: Any) -> None:
        with self.lock:
            for st in arr.status:
                self.statuses[st.name] = {"message": st.message, **{kv.key: kv.value for kv in st.values}}

    def imu_count(self) -> int:
        with self.lock:
            return self.imu

    def status(self, suffix: str) -> dict[str, str] | None:
        with self.lock:
            return next((v for k, v in self.statuses.items() if k.endswith(suffix)), None)

    def _call(self, client: Any, request: Any) -> Any:
        assert client.wait_for_service(timeout_sec=WAIT_S), f"no service {client.srv_name}"
        future = client.call_async(request)
        poll_until(future.done, WAIT_S, f"the answer of {client.srv_name}", interval=0.002)
        return future.result()

    def transition(self, label: str, transition_id: int) -> bool:
        from lifecycle_msgs.srv import ChangeState

        request = ChangeState.Request()
        request.transition.id = transition_id
        started = time.monotonic()
        ok = bool(self._call(self.change, request).success)
        self.round_trips[label] = time.monotonic() - started
        return ok

    def state(self) -> int:
        from lifecycle_msgs.srv import GetState

        return int(self._call(self.get, GetState.Request()).current_state.id)

    def available_transitions(self) -> list[str]:
        from lifecycle_msgs.srv import GetAvailableTransitions

        client = self.node.create_client(GetAvailableTransitions, self.change.srv_name.replace(
            "change_state", "get_available_transitions"))
        return sorted(d.transition.label for d in self._call(client, GetAvailableTransitions.Request())
                      .available_transitions)

    def lifecycle_interface(self, node: str) -> bool:
        """Every standard lifecycle service of the node and its transition_event topic are in the graph."""
        services = {name for name, _ in self.node.get_service_names_and_types()}
        topics = {name for name, _ in self.node.get_topic_names_and_types()}
        wanted = {f"/{node}/{s}" for s in ("change_state", "get_state", "get_available_states",
                                           "get_available_transitions", "get_transition_graph")}
        return wanted <= services and f"/{node}/transition_event" in topics

    def send_commands(self, n: int, value: float) -> None:
        for _ in range(n):
            msg = self.command_cls()
            msg.percent = value
            msg.header.stamp = self.node.get_clock().now().to_msg()
            self.pub.publish(msg)


def _command_counts(path: Path, mapping: str) -> tuple[int, int] | None:
    """(published, dropped as inactive) of the command mapping in the bridge's stats file, or None."""
    s = read_json(path)
    if not s or mapping not in s.get("mappings", {}):
        return None
    m = s["mappings"][mapping]
    return int(m["published"]), int(m["dropped"].get("inactive", 0))


def _run(protocol: str, tmp: Path) -> dict[str, Any]:
    gen = generated_or_skip()
    tables = gen.tables()
    if not any(m.topic.name == COMMAND_TOPIC for m in tables.MAPPINGS):
        pytest.skip(f"the spec has no {COMMAND_TOPIC}")
    prefix = ros_prefix_for(gen)
    env = child_env(prefix, domain_id(61 if protocol == "cyphal" else 62), {"SAM_GENERATED_DIR": str(gen.root)})
    if protocol == "cyphal":
        bus = ["--transport", "udp", "--iface", "127.0.0.1"]
        mapping = next(m.name for m in tables.MAPPINGS if m.topic.name == COMMAND_TOPIC)
    else:
        bus = ["--layout", "dronecan", "--dronecan-iface", private_iface()]
        mapping = next(m.name for m in tables.DRONECAN_MAPPINGS if m.topic.name == COMMAND_TOPIC)
    stats = tmp / "bridge.json"
    bridge = Proc("bridge", runtime_cmd("bridge", "--managed", *bus, "--stats-file", str(stats)), env, tmp)
    sim = Proc("sim", runtime_cmd("sim", *bus), env, tmp)
    client = None
    out: dict[str, Any] = {"protocol": protocol}
    try:
        ready = bridge.wait_line("READY", WAIT_S)
        node = ready.split()[2]
        sim.wait_line("READY", WAIT_S)
        client = LifecycleClient(node, gen, tables)
        out["initial"] = client.state()
        out["available"] = client.available_transitions()
        out["interface"] = poll_until(lambda: client.lifecycle_interface(node), WAIT_S,
                                      "the lifecycle services and transition_event")
        out["subscribed_unconfigured"] = client.node.count_subscribers(COMMAND_TOPIC)

        # configure: the bus opened, telemetry flows, commands dropped as inactive
        out["configure"] = client.transition("configure", CONFIGURE)
        out["after_configure"] = client.state()
        poll_until(lambda: client.imu_count() > 10, WAIT_S, "telemetry after configure")
        poll_until(lambda: client.node.count_subscribers(COMMAND_TOPIC), WAIT_S, "the bridge's command subscription")

        # activate: commands reach the bus
        out["activate"] = client.transition("activate", ACTIVATE)
        out["after_activate"] = client.state()
        client.send_commands(COMMANDS, 40.0)
        first = poll_until(lambda: (c := _command_counts(stats, mapping)) and c[0] >= COMMANDS and c, WAIT_S,
                           "commands on the bus while active")

        # deactivate: commands after the answer dropped as inactive, telemetry goes on
        out["deactivate"] = client.transition("deactivate", DEACTIVATE)
        out["after_deactivate"] = client.state()
        imu_before = client.imu_count()
        client.send_commands(COMMANDS, 60.0)
        inactive = poll_until(lambda: (c := _command_counts(stats, mapping)) and c[1] >= COMMANDS and c, WAIT_S,
                              "commands dropped as inactive")
        poll_until(lambda: client.imu_count() > imu_before + 10, WAIT_S, "telemetry while inactive")
        diag = poll_until(lambda: (st := client.status(f"/mapping/{mapping}")) and int(st.get("dropped.inactive", 0))
                          >= COMMANDS and st, WAIT_S, "the inactive drops on /diagnostics")
        bridge_status = poll_until(lambda: (st := client.status(node)) and st.get("active") == "False" and st,
                                   WAIT_S, "the bridge inactive on /diagnostics")
        out["published_while_active"] = first[0]
        out["inactive_counts"] = inactive
        out["diag_mapping"] = diag
        out["diag_bridge"] = bridge_status

        # activate again: commands flow again
        out["reactivate"] = client.transition("reactivate", ACTIVATE)
        client.send_commands(COMMANDS, 50.0)
        again = poll_until(lambda: (c := _command_counts(stats, mapping)) and c[0] >= inactive[0] + COMMANDS and c,
                           WAIT_S, "commands on the bus after reactivation")
        out["published_after_reactivate"] = again[0]
        out["dropped_inactive_final"] = again[1]

        # deactivate, cleanup: the bridge's topics gone, the node still there; configure and activate a new bridge
        out["deactivate_again"] = client.transition("deactivate again", DEACTIVATE)
        out["cleanup"] = client.transition("cleanup", CLEANUP)
        out["after_cleanup"] = client.state()
        out["subscribed_after_cleanup"] = poll_until(
            lambda: client.node.count_subscribers(COMMAND_TOPIC) == 0 and client.node.count_publishers(
                TELEMETRY_TOPIC) == 0 and "gone", WAIT_S, "the bridge's topics gone after cleanup")
        out["configure_again"] = client.transition("configure again", CONFIGURE)
        out["activate_again"] = client.transition("activate again", ACTIVATE)
        poll_until(lambda: client.node.count_subscribers(COMMAND_TOPIC), WAIT_S, "the new bridge's subscription")
        client.send_commands(COMMANDS, 30.0)

        def new_bridge_published() -> int:
            s = read_json(stats)  # the new bridge's counters (the file of the closed one stays until then)
            if not s or s.get("lifecycle", {}).get("configure") != 2:
                return 0
            return int(s["mappings"][mapping]["published"]) >= COMMANDS

        out["new_bridge_published"] = bool(poll_until(new_bridge_published, WAIT_S, "commands from the new bridge"))

        # shutdown: the process exits
        out["shutdown"] = client.transition("shutdown", SHUTDOWN_FROM_ACTIVE)
        out["exit_code"] = bridge.wait(WAIT_S)
        out["round_trips_ms"] = {k: round(v * 1000, 1) for k, v in client.round_trips.items()}
        return out
    finally:
        if client is not None:
            client.close()
        sim.stop(signal.SIGTERM)
        bridge.stop(signal.SIGTERM)


@pytest.fixture(scope="module", params=["cyphal", "dronecan"])
def run(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    tmp = tmp_path_factory.mktemp(f"managed_{request.param}")
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("ROS_DOMAIN_ID", domain_id(61 if request.param == "cyphal" else 62))
        if request.param == "cyphal":
            with cyphal_udp_lock():
                return _run(request.param, tmp)
        return _run(request.param, tmp)


def test_the_managed_bridge_waits_unconfigured_then_follows_its_manager(run: dict[str, Any]) -> None:
    print(f"\n{run['protocol']}: change_state round trips (ms) {run['round_trips_ms']}; dropped as inactive "
          f"{run['dropped_inactive_final']}")
    assert run["initial"] == UNCONFIGURED and run["subscribed_unconfigured"] == 0
    assert run["interface"] and run["available"] == ["configure", "shutdown"]
    assert run["configure"] and run["after_configure"] == INACTIVE
    assert run["activate"] and run["after_activate"] == ACTIVE
    assert run["deactivate"] and run["after_deactivate"] == INACTIVE
    assert run["reactivate"] and run["shutdown"]
    assert run["deactivate_again"] and run["cleanup"] and run["after_cleanup"] == UNCONFIGURED
    assert run["configure_again"] and run["activate_again"] and run["new_bridge_published"]
    assert run["exit_code"] == 0


def test_deactivate_stops_every_command_and_counts_it_inactive(run: dict[str, Any]) -> None:
    published, dropped = run["inactive_counts"]
    assert dropped >= COMMANDS
    assert published == run["published_while_active"]  # nothing reached the bus while inactive
    assert run["published_after_reactivate"] >= published + COMMANDS
    assert run["dropped_inactive_final"] == dropped  # (none dropped once active again)


def test_diagnostics_show_the_inactive_drops_and_state(run: dict[str, Any]) -> None:
    assert int(run["diag_mapping"]["dropped.inactive"]) >= COMMANDS
    assert "inactive" in run["diag_bridge"]["message"]
