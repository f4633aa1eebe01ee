"""The generated node bases work in rclpy: parameters with ranges and rules, the spec's QoS on every endpoint,
delivery to an overriding on_<topic>, transforms through the TF buffer, health on /diagnostics.

The ROS packages (tf2_msgs and the spec's own) are built into a prefix cached by content
(tests/helpers/ros_packages.py); a package installed outside the venv is usable only by a process started with
its library path, so the checks run in a child pytest of this same file (worker mode, like test_converters):
once for the SAM spec (generated/) and once for tests/specs/boat.yaml (generated into a temporary folder).
"""

from __future__ import annotations

import json
import os
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

ROOT = Path(__file__).resolve().parents[3]
WORKER_ENV = "SAM_NODE_BASE_WORKER"
WORKER = os.environ.get(WORKER_ENV)
SPECS = {"sam": ROOT / "spec" / "interfaces.yaml", "boat": ROOT / "tests" / "specs" / "boat.yaml"}


# ============================================================================================ parent

if not WORKER:
    from helpers.ros_packages import built_prefix, missing_tools, run_child
    from helpers.runtime_support import domain_id

    def _generated(spec: str, tmp: Path) -> Path:
        """generated/ for SAM (the committed tree), a fresh build for another spec."""
        if spec == "sam":
            return ROOT / "generated"
        from sam_codegen.build import build

        out = tmp / "generated"
        build(SPECS[spec], out)
        return out

    @pytest.mark.ros
    @pytest.mark.slow
    @pytest.mark.skipif(missing_tools() is not None, reason=str(missing_tools()))
    @pytest.mark.parametrize("spec", ["sam", "boat"])
    def test_generated_bases_in_rclpy(spec: str, tmp_path: Path) -> None:
        from sam_codegen.frontend.loader import load_spec_file
        from sam_codegen.targets.ros import build_order
        from sam_codegen.validate.resolve import validate

        generated = _generated(spec, tmp_path)
        order = build_order(validate(load_spec_file(SPECS[spec])))  # as the tables' ROS_PACKAGES
        prefix = built_prefix([generated / "ros" / name for name in order])
        config = {"spec": spec, "generated": str(generated)}
        proc = run_child(["-m", "pytest", __file__, "-v", "-p", "no:cacheprovider", "--rootdir", str(ROOT)],
                         prefix, domain_id(50 + len(spec)), {WORKER_ENV: json.dumps(config)}, timeout=900)
        report = proc.stdout[-12000:] + proc.stderr[-4000:]
        assert proc.returncode == 0, f"worker tests for {spec} failed:\n{report}"
        assert " passed" in proc.stdout and " skipped" not in proc.stdout, report
        assert f"::test_{spec}_" in proc.stdout and "::test_every_base_has_the_spec_endpoints_and_qos PASSED" in \
            proc.stdout, report


# ============================================================================================ worker

if WORKER:
    import importlib

    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.parameter import Parameter
    from rclpy.qos import DurabilityPolicy, ReliabilityPolicy

    from sam_codegen.validate.nodes import RCLPY_NODE_ATTRIBUTES
    from sam_runtime import node_support
    from sam_runtime.node_support import Level, ParameterConfigError
    from sam_runtime.tf_buffer import TfMissingEdge, TfStale

    CONFIG = json.loads(WORKER)
    GENERATED = Path(CONFIG["generated"])
    sys.path.insert(0, str(GENERATED / "python"))
    SPEC = CONFIG["spec"]
    TABLES = importlib.import_module(f"{SPEC}_bridge.tables")
    NODES_PACKAGE = importlib.import_module(TABLES.NODES_PACKAGE)
    TOPICS = {t.name: t for t in TABLES.TOPICS}
    DEADLINE_S = 10.0  # discovery and delivery on a loaded machine; polled, never slept
    RCLPY_OWN_PARAMETERS = {"use_sim_time", "start_type_description_service"}  # every rclpy node has them

    def base(name: str) -> type:
        module, cls = NODES_PACKAGE.NODES[name]
        return getattr(importlib.import_module(module), cls)

    class Session:
        """One rclpy context with an executor; nodes made here are spun by `spin_until`."""

        def __init__(self, args: list[str]) -> None:
            self.ctx = rclpy.Context()
            rclpy.init(args=args, context=self.ctx)
            self.executor = SingleThreadedExecutor(context=self.ctx)
            self.nodes: list[Any] = []

        def add(self, node: Any) -> Any:
            self.nodes.append(node)
            self.executor.add_node(node)
            return node

        def make(self, cls: type, **kwargs: Any) -> Any:
            return self.add(cls(context=self.ctx, **kwargs))

        def spin_until(self, done: Callable[[], Any], what: str, timeout: float = DEADLINE_S) -> Any:
            deadline = time.monotonic() + timeout
            while True:
                value = done()
                if value:
                    return value
                if time.monotonic() > deadline:
                    pytest.fail(f"not within {timeout} s: {what}")
                self.executor.spin_once(timeout_sec=0.02)

        def close(self) -> None:
            for node in self.nodes:
                self.executor.remove_node(node)
                node.destroy_node()
            self.executor.shutdown(timeout_sec=1.0)
            self.ctx.shutdown()

    @pytest.fixture
    def session() -> Iterator[Session]:
        s = Session([])
        yield s
        s.close()

    def set_until_mirrored(s: Session, node: Any, name: str, value: Any, watcher: Any) -> None:
        """Set `name` on `node` until `watcher` mirrors the value: /parameter_events is volatile, so a change made
        before the two nodes' endpoints matched is not seen; setting it again announces it again."""
        last = [0.0]

        def mirrored() -> bool:
            if time.monotonic() - last[0] > 0.2:
                last[0] = time.monotonic()
                assert node.set_parameters([Parameter(name, value=value)])[0].successful
            return watcher._gen_parameters.partner_values.get(name) == value

        s.spin_until(mirrored, f"{watcher.get_name()} mirroring {name} = {value}")

    def diagnostics_listener(s: Session) -> dict[str, list[Any]]:
        from diagnostic_msgs.msg import DiagnosticArray
        from rclpy.node import Node

        seen: dict[str, list[Any]] = {}
        node = s.add(Node("diagnostics_listener", context=s.ctx))

        def on_array(array: Any) -> None:
            for status in array.status:
                seen.setdefault(status.name, []).append(status)

        node.create_subscription(DiagnosticArray, "/diagnostics", on_array, 50)
        return seen

    def qos_names(profile: Any) -> tuple[str, str]:
        reliability = {ReliabilityPolicy.RELIABLE: "reliable", ReliabilityPolicy.BEST_EFFORT: "best_effort"}
        durability = {DurabilityPolicy.VOLATILE: "volatile", DurabilityPolicy.TRANSIENT_LOCAL: "transient_local"}
        return reliability.get(profile.reliability, str(profile.reliability)), durability.get(
            profile.durability, str(profile.durability))

    # ---------------------------------------------------------------------------------------- every spec

    def test_every_base_has_the_spec_endpoints_and_qos(session: Session) -> None:
        """Every node of the spec: its publishers and subscriptions exist with the spec's names, types and QoS
        (as the ROS graph reports them: get_publishers_info_by_topic / get_subscriptions_info_by_topic)."""
        for info in TABLES.NODES:
            session.make(base(info.name))
        for info in TABLES.NODES:
            fq = f"/{info.name}"
            for kind, endpoints, getter in (("publisher", info.publishes, "get_publishers_info_by_topic"),
                                            ("subscription", info.subscribes, "get_subscriptions_info_by_topic")):
                for ep in endpoints:
                    def mine(ep: Any = ep, getter: str = getter, fq: str = fq) -> list[Any]:
                        return [e for e in getattr(session.nodes[0], getter)(ep.topic)
                                if f"{e.node_namespace.rstrip('/')}/{e.node_name}" == fq]

                    found = session.spin_until(mine, f"the {kind} of {fq} on {ep.topic}")
                    assert len(found) == 1, (fq, ep.topic, found)
                    assert found[0].topic_type == TOPICS[ep.topic].ros_type
                    assert qos_names(found[0].qos_profile) == (ep.qos.reliability, ep.qos.durability), (fq, ep)

    def test_tf_endpoints(session: Session) -> None:
        """A node that publishes transforms publishes /tf with the tf QoS; one that reads them subscribes to /tf
        and /tf_static (transient local, so it gets the static frames published before it started)."""
        for info in TABLES.NODES:
            node = session.make(base(info.name))
            assert (node.tf is not None) == bool(info.reads_transforms)
        node = session.nodes[0]
        tf = TOPICS["/tf"].qos
        for info in TABLES.NODES:
            if info.transforms:
                pubs = session.spin_until(lambda n=info.name: [e for e in node.get_publishers_info_by_topic("/tf")
                                                               if e.node_name == n], f"{info.name} on /tf")
                assert qos_names(pubs[0].qos_profile) == (tf.reliability, tf.durability)
            if info.reads_transforms:
                for topic in ("/tf", "/tf_static"):
                    subs = session.spin_until(
                        lambda n=info.name, t=topic: [e for e in node.get_subscriptions_info_by_topic(t)
                                                      if e.node_name == n], f"{info.name} subscribing {topic}")
                    q = TOPICS[topic].subscriber_qos  # the subscribers' side of the topic's QoS
                    assert qos_names(subs[0].qos_profile) == (q.reliability, q.durability)

    def test_parameters_are_declared_with_ranges(session: Session) -> None:
        from rcl_interfaces.msg import ParameterType

        kinds = {"double": ParameterType.PARAMETER_DOUBLE, "integer": ParameterType.PARAMETER_INTEGER,
                 "bool": ParameterType.PARAMETER_BOOL, "string": ParameterType.PARAMETER_STRING}
        params = {p.name: p for p in TABLES.PARAMETERS}
        checked = 0
        for info in TABLES.NODES:
            node = session.make(base(info.name))
            declared = set(node.list_parameters([], 0).names) - RCLPY_OWN_PARAMETERS
            assert declared == {node_support.ros_parameter_name(n) for n in info.parameters}, info.name
            for spec_name in info.parameters:
                p, name = params[spec_name], node_support.ros_parameter_name(spec_name)
                desc = node.describe_parameter(name)
                assert desc.type == kinds[p.type] and p.description in desc.description
                assert (f"[{p.unit}]" in desc.description) == bool(p.unit)
                value = getattr(node, name.replace(".", "_"))  # the generated property
                assert value == p.default and type(value) is type(p.default)
                if p.type == "double" and p.minimum is not None:
                    assert (desc.floating_point_range[0].from_value, desc.floating_point_range[0].to_value) == (
                        p.minimum, p.maximum)
                    too_big = node.set_parameters([Parameter(name, value=p.maximum + 1.0)])[0]
                    assert not too_big.successful and getattr(node, name.replace(".", "_")) == p.default
                if p.type == "integer" and p.minimum is not None:
                    assert (desc.integer_range[0].from_value, desc.integer_range[0].to_value) == (
                        p.minimum, p.maximum)
                    assert not node.set_parameters([Parameter(name, value=int(p.maximum) + 1)])[0].successful
                checked += 1
        assert checked == sum(len(i.parameters) for i in TABLES.NODES) > 0

    def test_params_file_gives_the_values(tmp_path: Path) -> None:
        """The generated parameters file loads with --params-file for every node; a value changed in a copy of it
        reaches the node that reads it (and an unknown value for another node's parameter does no harm)."""
        params_file = GENERATED / TABLES.PARAMS_FILE
        first = next(p for p in TABLES.PARAMETERS if p.type == "double" and p.maximum is not None)
        text = params_file.read_text()
        old = f"    {node_support.ros_parameter_name(first.name)}: {first.default!r}"
        assert old in text
        new_value = (first.default + first.maximum) / 2 if first.maximum > first.default else first.default / 2
        for path, expected in ((params_file, first.default), (tmp_path / "changed.yaml", new_value)):
            path.write_text(text.replace(old, old.replace(repr(first.default), repr(new_value)))) \
                if path != params_file else None
            s = Session(["--ros-args", "--params-file", str(path)])
            try:
                nodes = [s.make(base(info.name)) for info in TABLES.NODES]
                reader = next(n for n, i in zip(nodes, TABLES.NODES, strict=True) if first.name in i.parameters)
                assert getattr(reader, node_support.ros_parameter_name(first.name).replace(".", "_")) == \
                    pytest.approx(expected)
            except ParameterConfigError as ex:  # the changed value may break a rule: then that is the error
                assert path != params_file and "breaks parameter rule" in str(ex)
            finally:
                s.close()

    def test_default_handler_counts_and_the_status_shows_it(session: Session) -> None:
        """A message on a topic whose on_<topic> is not overridden is counted (unhandled.<topic>), and the node's
        status on /diagnostics carries the count."""
        seen = diagnostics_listener(session)
        published = {e.topic: i.name for i in TABLES.NODES for e in i.publishes}
        reader, topic = next((i.name, e.topic) for i in TABLES.NODES for e in i.subscribes
                             if published.get(e.topic) not in (None, i.name))
        node = session.make(base(reader))
        source = session.make(base(published[topic]))
        cls = getattr(importlib.import_module(TOPICS[topic].ros_module), TOPICS[topic].ros_class)
        ident = topic.strip("/").replace("/", "_")

        def unhandled() -> bool:
            getattr(source, f"publish_{ident}")(cls())
            node._gen_support.publish()
            return any(kv.key == f"unhandled.{topic}" for st in seen.get(reader, []) for kv in st.values)

        session.spin_until(unhandled, f"unhandled.{topic} of {reader} on /diagnostics")

    # ---------------------------------------------------------------------------------------- SAM

    if SPEC == "sam":
        from geometry_msgs.msg import PoseStamped
        from sam_msgs.msg import Abort, HeadingStamped

        def test_sam_rclpy_attribute_list_is_current() -> None:
            """The validator's list of rclpy Node attributes (a parameter may not shadow them) is complete."""
            from rclpy.node import Node

            public = {a for a in dir(Node) if not a.startswith("_")}
            assert public <= RCLPY_NODE_ATTRIBUTES, sorted(public - RCLPY_NODE_ATTRIBUTES)

        def test_sam_rule_refused_with_its_name(session: Session) -> None:
            monitor = session.make(base("performance_monitor"))
            assert monitor.critical_depth == 60.0
            result = monitor.set_parameters([Parameter("critical_depth", value=40.0)])[0]
            assert not result.successful
            assert "critical_depth > safe_depth" in result.reason and "critical_depth = 40.0" in result.reason
            assert "safe_depth = 50.0" in result.reason and monitor.critical_depth == 60.0
            assert monitor.set_parameters([Parameter("critical_depth", value=70.0)])[0].successful
            assert monitor.critical_depth == 70.0
            # An unrelated parameter is never refused because of the rules.
            assert monitor.set_parameters([Parameter("use_sim_time", value=True)])[0].successful
            desc = monitor.describe_parameter("critical_depth")
            assert "critical_depth > safe_depth" in desc.additional_constraints

        def test_sam_rule_follows_the_other_nodes_values(session: Session) -> None:
            """safe_depth is the planner's, critical_depth the monitor's: each mirrors the other's value from
            /parameter_events, so the rule holds across the two nodes."""
            planner = session.make(base("motion_planner"))
            monitor = session.make(base("performance_monitor"))
            set_until_mirrored(session, monitor, "critical_depth", 90.0, planner)
            set_until_mirrored(session, planner, "safe_depth", 80.0, monitor)
            refused = monitor.set_parameters([Parameter("critical_depth", value=70.0)])[0]
            assert not refused.successful and "safe_depth = 80.0 (as set on /motion_planner)" in refused.reason
            assert not planner.set_parameters([Parameter("safe_depth", value=95.0)])[0].successful

        def test_sam_bad_initial_parameters_are_clear_errors(session: Session) -> None:
            cls = base("motion_planner")
            with pytest.raises(ParameterConfigError, match="breaks parameter rule 'critical_depth > safe_depth'"):
                cls(context=session.ctx, node_name="planner_a", parameter_overrides={"/safe_depth": 70.0})
            with pytest.raises(ParameterConfigError, match="unknown parameter"):
                cls(context=session.ctx, node_name="planner_b", parameter_overrides={"safe_dpeth": 10.0})
            with pytest.raises(ParameterConfigError, match="safe_depth"):
                cls(context=session.ctx, node_name="planner_c", parameter_overrides={"safe_depth": 500.0})
            ok = session.add(cls(context=session.ctx, node_name="planner_d",
                                 parameter_overrides={"safe_depth": 20, "critical_depth": 30.0}))
            assert ok.safe_depth == 20.0 and ok.get_name() == "planner_d"
            assert ok._gen_parameters.partner_values["critical_depth"] == 30.0

        def test_sam_delivery_to_overrides_and_latched_abort(session: Session) -> None:
            """The mission's goal reaches an overriding on_nav_goal; an abort published before the controller
            existed still reaches its on_abort (/abort is latched)."""
            got: dict[str, list[Any]] = {"goal": [], "abort": [], "heading": []}

            class Planner(base("motion_planner")):  # type: ignore[misc]
                def on_nav_goal(self, msg: PoseStamped) -> None:
                    got["goal"].append(msg)

                def on_nav_heading(self, msg: HeadingStamped) -> None:
                    got["heading"].append(msg)
                    raise ValueError("a bug in the node")

            class Controller(base("controller")):  # type: ignore[misc]
                def on_abort(self, msg: Abort) -> None:
                    got["abort"].append(msg)

            seen = diagnostics_listener(session)
            monitor = session.make(base("performance_monitor"))
            monitor.publish_abort(Abort(active=True, reason="depth beyond critical_depth"))
            mission = session.make(base("mission"))
            planner = session.make(Planner)
            session.make(Controller)
            session.spin_until(lambda: got["abort"], "the latched abort at a late controller")
            assert got["abort"][0].active and got["abort"][0].reason == "depth beyond critical_depth"
            session.spin_until(lambda: mission._gen_pub_nav_goal.get_subscription_count() > 0 and
                               mission._gen_pub_nav_heading.get_subscription_count() > 0, "the planner matched")
            goal = PoseStamped()
            goal.header.frame_id = "world"
            goal.pose.position.z = -5.0
            mission.publish_nav_goal(goal)
            session.spin_until(lambda: got["goal"], "the goal at on_nav_goal")
            assert got["goal"][0].pose.position.z == -5.0 and got["goal"][0].header.frame_id == "world"
            # A raising override: counted, shown as ERROR, and the node goes on receiving.
            mission.publish_nav_heading(HeadingStamped(heading=1.0, z=-3.0))
            session.spin_until(lambda: got["heading"], "the heading at on_nav_heading")
            planner._gen_support.publish()
            status = session.spin_until(lambda: [s for s in seen.get("motion_planner", [])
                                                 if any(kv.key == "errors.on_nav_heading" for kv in s.values)],
                                        "the error count on /diagnostics")[-1]
            assert status.level == bytes([Level.ERROR]) and "ValueError: a bug in the node" in status.message
            mission.publish_nav_goal(goal)
            session.spin_until(lambda: len(got["goal"]) == 2, "a second goal after the error")

        def test_sam_report_status(session: Session) -> None:
            seen = diagnostics_listener(session)
            monitor = session.make(base("performance_monitor"))
            session.spin_until(lambda: monitor.count_subscribers("/diagnostics") > 0, "the listener")
            monitor.report_status(Level.WARN, "battery low", battery_percent=18.5, state="nominal")
            first = session.spin_until(lambda: [s for s in seen.get("performance_monitor", [])
                                                if s.message == "battery low"], "the reported status")[0]
            assert first.level == bytes([Level.WARN]) and first.hardware_id == "/performance_monitor"
            values = {kv.key: kv.value for kv in first.values}
            assert values["battery_percent"] == "18.5" and values["state"] == "nominal"
            # Repeated at 1 Hz without another report.
            session.spin_until(lambda: len([s for s in seen["performance_monitor"] if s.message == "battery low"])
                               >= 2, "the periodic repetition", timeout=5.0)
            with pytest.raises(ValueError):
                monitor.report_status(7, "no such level")

        def test_sam_transforms_chain_through_the_buffer(session: Session) -> None:
            """DR publishes odom->base_link, SLAM world->odom, the host the static frames: the controller looks
            up world->base_link and the planner world->altimeter_link (through a static frame); a stale edge and
            a missing one are clear errors."""
            from rclpy.node import Node

            dr = session.make(base("dead_reckoning"))
            slam = session.make(base("slam"))
            controller = session.make(base("controller"))
            planner = session.make(base("motion_planner"))
            host = session.add(Node("node_host", context=session.ctx))
            static_pub = NODES_PACKAGE.publish_static_transforms(host)
            assert static_pub is not None
            with pytest.raises(TfMissingEdge, match="world"):
                controller.lookup_world_to_base_link()
            now = dr.get_clock().now()

            def chained() -> Any:
                # /tf is volatile: published until the readers, matched by now, have it (the same stamp each time).
                dr.publish_odom_to_base_link(now, (1.0, 2.0, -3.0), (0.0, 0.0, 0.0, 1.0))
                slam.publish_world_to_odom(now.to_msg(), (10.0, 0.0, 0.0), (0.0, 0.0, 0.7071067811865476,
                                                                             0.7071067811865476))
                try:
                    return controller.lookup_world_to_base_link(max_age_s=5.0)
                except TfMissingEdge:
                    return None

            t = session.spin_until(chained, "world->base_link at the controller")
            # world->odom turns by 90 degrees: odom's (1, 2, -3) is world's (10 - 2, 1, -3).
            assert t.translation == pytest.approx((8.0, 1.0, -3.0)) and t.yaw() == pytest.approx(1.5707963, abs=1e-6)
            assert t.stamp_ns == now.nanoseconds
            t2 = session.spin_until(lambda: planner.tf.can_transform("world", "altimeter_link") and
                                    planner.tf.lookup("world", "altimeter_link"), "through the static frame")
            assert t2.translation == pytest.approx((8.0, 1.35, -3.08))
            with pytest.raises(TfStale, match=r"odom->base_link|world->odom"):
                controller.tf.lookup("world", "base_link", now_ns=now.nanoseconds + 2_000_000_000, max_age_s=1.0)
            with pytest.raises(ValueError):
                dr.publish_odom_to_base_link(now, (float("nan"), 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))

    # ---------------------------------------------------------------------------------------- the boat

    if SPEC == "boat":
        from nav_msgs.msg import Path as PathMsg
        from std_msgs.msg import Bool

        def test_boat_own_qos_of_a_subscription(session: Session) -> None:
            """The localizer's /gnss/fix subscription has its own QoS (best effort, depth 20); the helm's /route
            is the topic's spelled-out transient local."""
            localizer = session.make(base("localizer"))
            session.make(base("helm"))
            subs = session.spin_until(lambda: localizer.get_subscriptions_info_by_topic("/gnss/fix"), "fix sub")
            assert qos_names(subs[0].qos_profile) == ("best_effort", "volatile")
            route = session.spin_until(lambda: localizer.get_subscriptions_info_by_topic("/route"), "route sub")
            assert qos_names(route[0].qos_profile) == ("reliable", "transient_local")

        def test_boat_parameter_types_and_the_cross_node_rule(session: Session) -> None:
            helm = session.make(base("helm"))
            navigator = session.make(base("navigator"))
            assert (helm.max_speed, helm.rudder_limit_deg, helm.enabled) == (3.0, 30, True)
            assert navigator.station == 'harbour "A"' and navigator.cruise_speed == 1.5
            assert not helm.set_parameters([Parameter("rudder_limit_deg", value=60)])[0].successful
            assert helm.set_parameters([Parameter("enabled", value=False)])[0].successful and not helm.enabled
            refused = navigator.set_parameters([Parameter("cruise_speed", value=4.0)])[0]
            assert not refused.successful and "cruise_speed <= max_speed" in refused.reason
            set_until_mirrored(session, helm, "max_speed", 5.0, navigator)
            assert navigator.set_parameters([Parameter("cruise_speed", value=4.0)])[0].successful

        def test_boat_route_and_latched_stop_reach_the_helm(session: Session) -> None:
            got: dict[str, list[Any]] = {"route": [], "stop": []}

            class Helm(base("helm")):  # type: ignore[misc]
                def on_route(self, msg: PathMsg) -> None:
                    got["route"].append(msg)

                def on_stop(self, msg: Bool) -> None:
                    got["stop"].append(msg)

            navigator = session.make(base("navigator"))
            operator = session.make(base("operator"))
            route = PathMsg()
            route.header.frame_id = "map"
            navigator.publish_route(route)  # before the helm exists: the topic keeps the last two
            operator.publish_stop(Bool(data=True))
            session.make(Helm)
            session.spin_until(lambda: got["route"] and got["stop"], "the latched route and stop")
            assert got["route"][0].header.frame_id == "map" and got["stop"][0].data is True

        def test_boat_lookup_through_a_static_frame(session: Session) -> None:
            """map->gnss_antenna = map->base_link (the localizer) then base_link->gnss_antenna (static, turned
            180 degrees about z)."""
            from rclpy.node import Node

            localizer = session.make(base("localizer"))
            navigator = session.make(base("navigator"))
            host = session.add(Node("node_host", context=session.ctx))
            NODES_PACKAGE.publish_static_transforms(host)
            stamp = localizer.get_clock().now().nanoseconds

            def looked_up() -> Any:
                localizer.publish_map_to_base_link(stamp, (5.0, 5.0, 0.0), (0.0, 0.0, 0.0, 1.0))
                try:
                    return navigator.lookup_map_to_gnss_antenna(max_age_s=5.0)
                except TfMissingEdge:
                    return None

            t = session.spin_until(looked_up, "map->gnss_antenna")
            assert t.translation == pytest.approx((4.5, 5.0, 1.2)) and abs(t.yaw()) == pytest.approx(3.14159265)
