"""Command line of the runtime: ``bridge``, ``sim``, ``nodes`` (the node host), ``run`` (the main job), ``record``
and ``replay`` (sam_runtime.main_job.record_replay), ``params`` (save and restore the boards' settings:
sam_runtime.main_job.params_file).

Console scripts: ``sam-bridge`` = :func:`bridge_main`, ``sam-sim`` = :func:`sim_main`, ``sam-nodes`` =
:func:`nodes_main`, ``sam-run`` = :func:`run_main`, ``sam-record`` = :func:`record_main`, ``sam-replay`` =
:func:`replay_main`; ``sam-codegen bridge|sim|nodes|run|record|replay ...`` dispatches to :func:`main`. Also
``python -m sam_runtime.cli {bridge,sim,nodes,run,record,replay} ...``.

Where: ``--generated``, else ``$SAM_GENERATED_DIR``, else the generated folder of the project the working directory
is in (see sam_codegen.project.workspace); ``run`` also finds the spec the way ``sam-codegen build`` does.

Transport selection (bridge and sim): ``--transport udp|can|loopback|env``; without it, the standard
Cyphal register environment variables are used when one of UAVCAN__UDP__IFACE, UAVCAN__CAN__IFACE,
UAVCAN__LOOPBACK or UAVCAN__SERIAL__IFACE is set, else Cyphal/UDP on 127.0.0.1.
"""

from __future__ import annotations

import os

# Every process of the runtime may start rclpy: loopback-only discovery, before anything imports it.
os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")

import argparse
import asyncio
import json
import signal
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from sam_runtime.cli_support import (
    EXIT_ERROR,
    EXIT_OK,
    EXIT_USAGE,
    add_generated_args,
    add_namespace_args,
    add_transport_args,
    generated_package,
    namespace_of,
    parse_params,
    require_runtime,
    serve,
    setup_logging,
    stay_with_parent,
    transport_kind,
    wait_for_stop,
    write_json_atomic,
)

__all__ = ["bridge_main", "main", "nodes_main", "run_main", "sim_main"]


# ============================================================================================ bridge
def _add_layout_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--layout", default=None, metavar="NAME",
                   help="the spec's layout: which firmware (cyphal, dronecan) each device runs (default: the "
                        "spec's default layout, every device on its own protocol)")
    p.add_argument("--dronecan-iface", default="mcast-lo:", metavar="URI",
                   help="DroneCAN interface: mcast-lo:[BUS[:PORT]] (127.0.0.1 only), socketcan:IFNAME, "
                        "slcan:DEVICE (default mcast-lo:)")


def _add_wire_arg(p: argparse.ArgumentParser) -> None:
    p.add_argument("--wire", choices=("codec", "object"), default="codec",
                   help="the bridge's path: codec (default), the generated wire codecs from UAVCAN payload bytes to "
                        "ROS CDR and back; object, the object converters (the protocol library's messages <-> ROS "
                        "messages)")


def _bridge_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="sam-bridge", description="The UAVCAN (Cyphal) <-> ROS 2 bridge of the spec.")
    add_generated_args(p)
    add_transport_args(p)
    p.add_argument("--node-id", type=int, default=None,
                   help="Cyphal node id (default: UAVCAN__NODE__ID with --transport env, else the spec's)")
    p.add_argument("--param", action="append", default=[], metavar="NAME=VALUE",
                   help="initial value of a spec parameter (range and rules are checked), or of a board's setting "
                        "<device>.<setting> (written to the board after its first read when it differs)")
    p.add_argument("--qos-depth", type=int, default=100)
    p.add_argument("--command-qos", choices=("reliable", "best_effort"), default="reliable")
    p.add_argument("--rx-queue-size", type=int, default=None,
                   help="bound of each subject's Cyphal receive queue; beyond it transfers are dropped and counted "
                        "(default 1000; 0 = unbounded)")
    p.add_argument("--log-interval", type=float, default=None,
                   help="seconds between two log lines of one mapping and drop reason (default 10)")
    p.add_argument("--duration", type=float, default=None, help="stop after S seconds (default: until signal)")
    p.add_argument("--stats-file", type=Path, default=None,
                   help="write the counters as JSON here every second and at exit")
    _add_layout_args(p)
    p.add_argument("--protocol", choices=("cyphal", "dronecan"), default=None,
                   help="the half of a mixed layout this bridge serves (one bridge per protocol; default: the "
                        "layout's only protocol)")
    p.add_argument("--time-sync", action=argparse.BooleanOptionalAction, default=None,
                   help="be (or not) the bus's time-sync master (Cyphal uavcan.time.Synchronization, DroneCAN "
                        "GlobalTimeSync); default: the spec's bridge.time_sync, on unless it says otherwise")
    p.add_argument("--dna-server", action="store_true",
                   help="DroneCAN: run a dynamic node id allocation server (dronecan's CentralizedServer)")
    _add_wire_arg(p)
    p.add_argument("--managed", action="store_true",
                   help="a ROS 2 managed (lifecycle) node: start unconfigured and wait for a lifecycle manager "
                        "(lifecycle_msgs change_state: configure opens the bus, activate bridges commands, "
                        "deactivate drops them as 'inactive' while telemetry goes on, cleanup, shutdown exits); "
                        "default: the same lifecycle node, configured and activated by itself at start (bridging "
                        "from the start, and a manager may still deactivate it)")
    add_namespace_args(p)
    p.add_argument("--ros-args", nargs=argparse.REMAINDER, default=[], help="ROS arguments for the node")
    return p


def _namespace_or_exit(prog: str, args: argparse.Namespace) -> Any:
    """The RosNamespace of the command line, or None after printing why it is not valid."""
    try:
        return namespace_of(args)
    except ValueError as ex:
        print(f"{prog}: {ex}", file=sys.stderr)
        return None


def bridge_main(argv: Sequence[str] | None = None) -> int:
    args = _bridge_parser().parse_args(argv)
    if (namespace := _namespace_or_exit("sam-bridge", args)) is None:
        return EXIT_USAGE
    require_runtime("bridge")
    stay_with_parent()
    setup_logging(args.log_level)
    from sam_runtime.bridge import Bridge, BridgeConfigError, TransportConfig
    from sam_runtime.cyphal_io.transport import TransportConfigError
    from sam_runtime.genpkg import GeneratedPackageError

    def make(host: Any = None) -> Any:
        return Bridge(
            generated_package(args),
            node_id=args.node_id,
            transport=TransportConfig(transport_kind(args), args.iface, args.mtu),
            ros_args=args.ros_args,
            parameter_overrides=parse_params(args.param),
            qos_depth=args.qos_depth,
            command_reliability=args.command_qos,
            **({} if args.rx_queue_size is None else {"rx_queue_size": args.rx_queue_size}),
            **({} if args.log_interval is None else {"log_interval": args.log_interval}),
            layout=args.layout,
            protocol=args.protocol,
            dronecan_iface=args.dronecan_iface,
            dronecan_options={"dna_server": args.dna_server},
            wire=args.wire,
            namespace=namespace,
            time_sync=args.time_sync,
            ros_host=host,
        )

    async def run(stop: asyncio.Event) -> int:
        return await _run_managed(args, make, namespace, stop)

    return serve("sam-bridge", run, (BridgeConfigError, GeneratedPackageError, TransportConfigError))


async def _run_managed(args: argparse.Namespace, make: Any, namespace: Any, stop: asyncio.Event) -> int:
    """The bridge's lifecycle node until a manager shuts it down (or a signal, or ``--duration``); the bridge exists
    between configure and cleanup (sam_runtime.bridge.managed). Without ``--managed`` the node configures and
    activates itself first (a configure that fails ends the process with its error, as before lifecycles)."""
    from sam_runtime.bridge.managed import ManagedBridge

    loop = asyncio.get_running_loop()
    probe = make()  # the arguments checked and the node's name known before any manager calls (nothing opened)
    managed = ManagedBridge(probe.name, make, loop, stop.set, namespace=namespace.node_namespace,
                            ros_args=args.ros_args, autostart=not args.managed)
    del probe
    managed.host.open()
    snapshot = None
    try:
        if args.managed:
            print(f"READY bridge {managed.host.name} managed: unconfigured, waiting for a lifecycle manager "
                  f"namespace={namespace.namespace}", flush=True)
        else:
            await managed.start_active()
            bridge = managed.bridge
            print(f"READY bridge {bridge.name} node_id={bridge.node_id} transport={bridge.backend.describe()} "
                  f"wire={bridge.wire} namespace={namespace.namespace}", flush=True)
        deadline = None if args.duration is None else time.monotonic() + args.duration
        while not stop.is_set():
            left = None if deadline is None else deadline - time.monotonic()
            if left is not None and left <= 0:
                break
            await wait_for_stop(stop, 1.0 if left is None else min(1.0, left))
            bridge = managed.bridge
            if args.stats_file and bridge is not None and bridge.reporter is not None:
                write_json_atomic(args.stats_file, {**bridge.stats(), "lifecycle": managed.transitions})
    finally:
        # no transition from here on (off the loop: a transition in progress waits for the loop)
        await asyncio.get_running_loop().run_in_executor(None, managed.host.stop_spinning)
        bridge = managed.bridge
        if bridge is not None:
            snapshot = {**bridge.stats(), "lifecycle": managed.transitions}
            managed.bridge = None
            await bridge.close()
        managed.host.close()
        if args.stats_file and snapshot is not None:
            write_json_atomic(args.stats_file, snapshot)
    return EXIT_OK


# ============================================================================================ sim
def _sim_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="sam-sim", description="Simulated devices of the spec, one node each (Cyphal or "
                                "DroneCAN, as the layout says).")
    add_generated_args(p)
    add_transport_args(p)
    p.add_argument("--layout", default="default", metavar="NAME",
                   help="the spec's layout: which firmware (cyphal, dronecan) each device runs (default: default, "
                        "every device on its own protocol)")
    p.add_argument("--dronecan-iface", default="mcast-lo:", metavar="URI",
                   help="the DroneCAN devices' bus: mcast-lo:[BUS[:PORT]] (127.0.0.1 only), socketcan:IFNAME, "
                        "slcan:DEVICE (default mcast-lo:)")
    p.add_argument("--devices", default=None, help="comma-separated subset of device names (default: all)")
    p.add_argument("--rate-scale", type=float, default=1.0, help="multiply every nominal rate (default 1)")
    p.add_argument("--bridge-node-id", type=int, default=None,
                   help="accept commands only from this node (default: the spec's bridge)")
    p.add_argument("--duration", type=float, default=None,
                   help="publish for S seconds, then write the report and exit (default: until signal)")
    p.add_argument("--start-file", type=Path, default=None,
                   help="heartbeats at once, but publish only once this file exists (for scripted tests)")
    p.add_argument("--record", type=Path, default=None, help="JSON lines of every message sent and received")
    p.add_argument("--report", type=Path, default=None, help="write the counters as JSON here at exit")
    p.add_argument("--namespace", default=None, metavar="NS",
                   help="the vehicle's ROS namespace, as the main job gives every child; the devices have no ROS "
                        "side, so it only labels the READY line (their bus is --dronecan-iface / the transport)")
    p.add_argument("--device-clocks", action=argparse.BooleanOptionalAction, default=True,
                   help="each device its own clock, 5..120 s off, following the bus's time-sync master and stamping "
                        "0 (unknown) until synchronised (default); --no-device-clocks: one shared stamp clock")
    _add_vehicle_args(p)
    return p


def _add_vehicle_args(p: argparse.ArgumentParser, *, main_job: bool = False) -> None:
    """The simulated vehicle's options (``sim``; ``run`` forwards them to its sim, except --time-scale: the nodes
    run on the wall clock): the flags of SimConfig's fields (sam_runtime.physics.vehicle.VehicleOptions)."""
    from sam_runtime.common.cli_fields import add_flags
    from sam_runtime.sim.config import SimConfig

    v = p.add_argument_group("simulated vehicle (frames: ENU metres around --gps-origin, yaw counter-clockwise "
                             "from east, depth positive down)")
    add_flags(v, SimConfig, main_job=main_job)


def _vehicle_options(args: argparse.Namespace) -> dict[str, Any]:
    """SimConfig's vehicle options from the sim's command line (ValueError: one clear line)."""
    from sam_runtime.common.cli_fields import options_from
    from sam_runtime.sim.config import SimConfig

    return options_from(SimConfig, args)


def sim_main(argv: Sequence[str] | None = None) -> int:
    args = _sim_parser().parse_args(argv)
    args.frame_prefix = None
    if (namespace := _namespace_or_exit("sam-sim", args)) is None:
        return EXIT_USAGE
    require_runtime("sim")
    stay_with_parent()
    setup_logging(args.log_level)
    from sam_runtime.cyphal_io.transport import TransportConfigError
    from sam_runtime.genpkg import GeneratedPackageError
    from sam_runtime.sim.simulator import SimConfig, Simulator

    async def run(stop: asyncio.Event) -> int:
        kind = transport_kind(args)
        cfg = SimConfig(
            kind=kind, iface=args.iface, mtu=args.mtu, environ=dict(os.environ) if kind == "env" else None,
            bridge_node_id=args.bridge_node_id,
            devices=None if not args.devices else [d.strip() for d in args.devices.split(",") if d.strip()],
            rate_scale=args.rate_scale, record=args.record, layout=args.layout, dronecan_iface=args.dronecan_iface,
            device_clocks=args.device_clocks, **_vehicle_options(args),
        )
        sim = Simulator(generated_package(args), cfg)
        await sim.start()
        print(f"READY sim devices={len(sim.devices)} transport={kind} namespace={namespace.namespace}", flush=True)
        synchronised = asyncio.ensure_future(_say_when_synchronised(sim, stop))
        try:
            if args.start_file is not None:
                while not args.start_file.exists() and not stop.is_set():
                    await wait_for_stop(stop, 0.01)
            if not stop.is_set():
                sim.start_publishing(duration=args.duration)
                print("PUBLISHING", flush=True)
                if args.duration is None:
                    await stop.wait()
                else:
                    done = asyncio.ensure_future(sim.wait_publishing_done())
                    stopper = asyncio.ensure_future(stop.wait())
                    await asyncio.wait({done, stopper}, return_when=asyncio.FIRST_COMPLETED)
                    stopper.cancel()
                    if not done.done():
                        done.cancel()
        finally:
            synchronised.cancel()
            report = sim.report()
            await sim.close()
            if args.report:
                write_json_atomic(args.report, report)
        print("DONE " + json.dumps({k: v["published"] for k, v in report["devices"].items()}), flush=True)
        return EXIT_OK

    return serve("sam-sim", run, (GeneratedPackageError, TransportConfigError, ValueError))


async def _say_when_synchronised(sim: Any, stop: asyncio.Event) -> None:
    """Print SYNCHRONISED once every device's clock follows the bus's time-sync master (for scripts and tests that
    want only synchronised stamps: they open the start gate after it)."""
    while not sim.synchronised and not stop.is_set():
        await asyncio.sleep(0.05)
    if not stop.is_set():
        print("SYNCHRONISED", flush=True)


# ============================================================================================ nodes
def _add_mission_args(p: argparse.ArgumentParser) -> None:
    m = p.add_mutually_exclusive_group()
    m.add_argument("--goal", nargs=3, type=float, default=None, metavar=("X", "Y", "Z"),
                   help="one pose goal in world (ENU metres around the first GPS fix; z < 0 a depth, z > 0 an "
                        "altitude above the sea floor, 0 the surface) instead of the demo mission")
    m.add_argument("--mission", type=Path, default=None, metavar="FILE",
                   help="a mission file (YAML: a list of pose/heading goals with arrival tolerances, see "
                        "sam_runtime.nav.mission) instead of the demo mission")


def _mission_goals(args: argparse.Namespace) -> Any:
    """The mission's goals from --goal/--mission (None: the demo mission); MissionError for a bad file or goal."""
    from sam_runtime.nav.mission import load_mission, single_goal

    if args.goal is not None:
        return single_goal(*args.goal)
    if args.mission is not None:
        return load_mission(args.mission)
    return None


def _nodes_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="sam-nodes", description="The node host: the spec's nodes that have an implementation, in one process "
                                      "(one rclpy context and executor, each node its own ROS node).")
    add_generated_args(p)
    p.add_argument("--params-file", type=Path, default=None,
                   help="ROS 2 parameters file (default: the generated params/<vehicle>.params.yaml)")
    p.add_argument("--only", default=None, metavar="A,B",
                   help="run only these nodes (comma-separated names of the spec's nodes)")
    _add_mission_args(p)
    p.add_argument("--duration", type=float, default=None, help="stop after S seconds (default: until signal)")
    p.add_argument("--log-level", default="INFO")
    add_namespace_args(p, ros_args=True)
    return p


def nodes_main(argv: Sequence[str] | None = None) -> int:
    args = _nodes_parser().parse_args(argv)
    if (namespace := _namespace_or_exit("sam-nodes", args)) is None:
        return EXIT_USAGE
    require_runtime("nodes")
    stay_with_parent()
    setup_logging(args.log_level)
    from sam_runtime.genpkg import GeneratedPackageError
    from sam_runtime.nav.mission import MissionError
    from sam_runtime.nodes.host import HostConfigError, NodeHost, plan_host

    try:
        goals = _mission_goals(args)
        gen = generated_package(args)
        only = None if args.only is None else [n.strip() for n in args.only.split(",") if n.strip()]
        plan = plan_host(gen.tables(), only)
    except (GeneratedPackageError, HostConfigError, MissionError) as ex:
        print(f"sam-nodes: {ex}", file=sys.stderr)
        return EXIT_ERROR if not isinstance(ex, HostConfigError) else EXIT_USAGE
    if plan.missing:
        print(f"sam-nodes: no implementation for node(s) {', '.join(plan.missing)} of the spec; "
              + (f"running {', '.join(plan.run)}" if plan.run else "nothing to run"), flush=True)
    if not plan.run:
        return EXIT_OK
    if "mission" not in plan.run and goals is not None:
        print("sam-nodes: --goal/--mission need the mission node, which is not run", file=sys.stderr)
        return EXIT_USAGE
    try:
        host = NodeHost(gen, plan, params_file=args.params_file, goals=goals, namespace=namespace,
                        ros_args=args.ros_args)
    except HostConfigError as ex:
        print(f"sam-nodes: {ex}", file=sys.stderr)
        return EXIT_ERROR
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, lambda *_: host.stop())
    print(f"READY nodes {','.join(plan.run)} params={host.params_file} namespace={namespace.namespace}", flush=True)
    try:
        host.spin(args.duration)
    finally:
        host.close()
    print(f"DONE nodes errors={host.errors}", flush=True)
    return EXIT_OK


# ============================================================================================ run
def _run_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="sam-run",
        description="Build, start the simulated devices and the bridge, and show live what flows (Ctrl-C stops).")
    p.add_argument("--spec", type=Path, default=None,
                   help="the spec (default: spec/interfaces.yaml in the working directory or its nearest parent)")
    add_generated_args(p, "the generated folder (default: generated/ in the project of --spec when it is given, "
                           "else $SAM_GENERATED_DIR, else generated/ of the project the working directory is in)")
    p.add_argument("--iface", default="127.0.0.1", help="Cyphal/UDP interface of sim and bridge (default 127.0.0.1)")
    _add_layout_args(p)
    _add_wire_arg(p)
    p.add_argument("--duration", type=float, default=None,
                   help="stop S seconds after the vehicle is up (the sim, the bridge and the nodes READY; default: "
                        "until Ctrl-C)")
    p.add_argument("--no-build", action="store_true", help="use generated/ as it is")
    p.add_argument("--wait-timeout", type=float, default=None, metavar="S",
                   help="when another sam-codegen process (run, build, ros-install) is building generated/ or the "
                        "ROS packages of this project, wait at most S seconds for it, then fail (default: as long "
                        "as it runs; this run then reuses what it built)")
    p.add_argument("--no-demo-commands", dest="demo_commands", action="store_false",
                   help="specs without node implementations: do not publish demo actuator commands (by default "
                        "slow sweeps move the actuators)")
    p.add_argument("--no-nodes", dest="nodes", action="store_false",
                   help="do not start the node host (the simulated devices and the bridge only)")
    p.add_argument("--params-file", type=Path, default=None,
                   help="the node host's ROS 2 parameters file (default: the generated params/<vehicle>.params.yaml)")
    _add_mission_args(p)
    p.add_argument("--record", type=Path, default=None, metavar="FILE.mcap",
                   help="record every ROS topic of the spec and the raw UAVCAN bus into this MCAP file (a child "
                        "like the others: sam-codegen record)")
    p.add_argument("--window", type=float, default=2.0, help="rate window [s] (default 2)")
    p.add_argument("--plain", action="store_true", help="plain lines every second even on a terminal")
    p.add_argument("--log-dir", type=Path, default=None,
                   help="children's logs (default: .sam-codegen-cache/run-logs in the project)")
    p.add_argument("--ros-prefix", type=Path, default=None,
                   help="install prefix of the generated ROS package (default: the running venv)")
    p.add_argument("--log-level", default="WARNING")
    add_namespace_args(p)
    _add_vehicle_args(p, main_job=True)
    return p


def _sim_vehicle_argv(args: argparse.Namespace) -> list[str]:
    """The vehicle options the main job forwards to its sim (checked here first: ValueError, one clear line)."""
    from sam_runtime.common.cli_fields import forwarded_argv
    from sam_runtime.sim.config import SimConfig

    _vehicle_options(args)
    return forwarded_argv(SimConfig, args)


def run_main(argv: Sequence[str] | None = None) -> int:
    args = _run_parser().parse_args(argv)
    require_runtime("run")
    setup_logging(args.log_level)
    from sam_runtime.main_job.job import RunOptions, run
    from sam_runtime.nav.mission import MissionError

    try:
        _mission_goals(args)  # a bad mission file stops here, before anything starts
        sim_args = _sim_vehicle_argv(args)
        namespace = namespace_of(args)
    except (MissionError, ValueError) as ex:
        print(f"sam-run: {ex}", file=sys.stderr)
        return EXIT_USAGE
    node_args = [] if args.params_file is None else ["--params-file", str(args.params_file.resolve())]
    if args.goal is not None:
        node_args += ["--goal", *(repr(v) for v in args.goal)]
    elif args.mission is not None:
        node_args += ["--mission", str(args.mission.resolve())]
    return run(RunOptions(
        spec=args.spec, generated=args.generated, package=args.package, iface=args.iface,
        duration=args.duration, build=not args.no_build, demo_commands=args.demo_commands,
        window=args.window, plain=args.plain, log_dir=args.log_dir, ros_prefix=args.ros_prefix,
        argv=list(sys.argv[1:] if argv is None else argv), nodes=args.nodes, node_args=node_args,
        sim_args=sim_args, truth_file=args.truth_file, layout=args.layout, dronecan_iface=args.dronecan_iface,
        wire=args.wire, record=args.record, namespace=namespace, wait_timeout=args.wait_timeout,
    ))


# ============================================================================================ record, replay
def record_main(argv: Sequence[str] | None = None) -> int:
    """``sam-record`` / ``sam-codegen record``: sam_runtime.main_job.record_replay."""
    from sam_runtime.main_job.record_replay import record_main as main

    return main(argv)


def replay_main(argv: Sequence[str] | None = None) -> int:
    """``sam-replay`` / ``sam-codegen replay``: sam_runtime.main_job.record_replay."""
    from sam_runtime.main_job.record_replay import replay_main as main

    return main(argv)


def params_main(argv: Sequence[str] | None = None) -> int:
    """``sam-codegen params save|restore FILE``: sam_runtime.main_job.params_file."""
    from sam_runtime.main_job.params_file import params_main as main

    return main(argv)


# ============================================================================================ dispatch
_COMMANDS = {"bridge": bridge_main, "sim": sim_main, "nodes": nodes_main, "run": run_main, "record": record_main,
             "replay": replay_main, "params": params_main}


def main(argv: Sequence[str] | None = None) -> int:
    """``main(["bridge", ...])`` etc.: the entry ``sam-codegen bridge|sim|nodes|run`` dispatches to."""
    argv = list(sys.argv[1:] if argv is None else argv)
    if not argv or argv[0] not in _COMMANDS:
        print(f"usage: {Path(sys.argv[0]).name} {{{','.join(_COMMANDS)}}} [options]  (--help per command)",
              file=sys.stderr)
        return EXIT_USAGE
    return _COMMANDS[argv[0]](argv[1:])


if __name__ == "__main__":
    sys.exit(main())
