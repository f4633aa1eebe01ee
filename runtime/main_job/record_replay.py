"""The ``record`` and ``replay`` commands (``sam-codegen record|replay``, ``sam-record``, ``sam-replay``).

``record FILE.mcap``: the recorder (sam_runtime.recording.recorder) until Ctrl-C, SIGTERM or ``--duration``; as a
child of the main job (``run --record``) it ends with it like the other children. The path is checked before
anything starts (exit 1 with one line); a write that fails later stops the recording, never the process.

``replay FILE.mcap``: the recorded bus through the bridge's inbound path offline (sam_runtime.bridge.offline: this
top-layer module hands the bridge's part to sam_runtime.recording.replay, which does not know the bridge) of the
project's generated package, or of ``--spec OTHER`` built into a temporary folder; prints the per-topic report,
writes ``--out`` and ``--report``; exit 0 when the topics are the same as recorded (up to receive-time fields), 3
when they differ.
"""

from __future__ import annotations

import argparse
import asyncio
import json
import sys
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from sam_codegen.build import build
from sam_codegen.model.diagnostics import SpecError
from sam_runtime.bridge.backend import BridgeConfigError
from sam_runtime.bridge.offline import OfflineBridge
from sam_runtime.cli_support import (
    EXIT_ERROR,
    EXIT_OK,
    EXIT_USAGE,
    add_generated_args,
    generated_package,
    require_runtime,
    serve,
    setup_logging,
    stay_with_parent,
    wait_for_stop,
    write_json_atomic,
)
from sam_runtime.common.ros_namespace import ros_namespace
from sam_runtime.common.run_names import run_names
from sam_runtime.cyphal_io.dsdl_cache import DsdlCompileError
from sam_runtime.genpkg import GeneratedPackage, GeneratedPackageError
from sam_runtime.recording.reading import Recording, read_recording, recording_file_problem, rosbag2_folder
from sam_runtime.recording.recorder import METADATA_NAME, Recorder, RecorderConfig
from sam_runtime.recording.replay import SPEEDS, replay
from sam_runtime.recording.schemas import TRANSFER_TYPE
from sam_runtime.recording.target import RecordingTargetError, bag_target, check_target

__all__ = ["EXIT_DIFFERENT", "record_main", "replay_main"]

EXIT_DIFFERENT = 3
_TICK_S = 0.2


def _record_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="sam-record", description="Record every ROS topic of the spec and the raw "
                                "UAVCAN bus of a running vehicle into one MCAP file (Ctrl-C stops).")
    p.add_argument("file", type=Path, help="the MCAP file to write (with --rosbag2: the bag folder)")
    p.add_argument("--rosbag2", action="store_true",
                   help="write a rosbag2 folder: FILE is a new folder, holding FILE_0.mcap and, once the recording "
                        "ends, its metadata.yaml (what ros2 bag info/play and other rosbag2 readers open)")
    add_generated_args(p)
    p.add_argument("--layout", default=None, metavar="NAME", help="the spec's layout (default: its default layout)")
    p.add_argument("--iface", default="127.0.0.1", help="Cyphal/UDP interface to listen on (default 127.0.0.1)")
    p.add_argument("--dronecan-iface", default="mcast-lo:", metavar="URI",
                   help="DroneCAN bus to listen on: mcast-lo:[BUS[:PORT]] (default mcast-lo:)")
    p.add_argument("--no-bus", dest="bus", action="store_false", help="record the ROS topics only")
    p.add_argument("--duration", type=float, default=None, help="stop after S seconds (default: until signal)")
    p.add_argument("--log-level", default="INFO")
    p.add_argument("--namespace", default=None, metavar="NS",
                   help="the vehicle's ROS namespace: the spec's relative topics are recorded under it (channels are "
                        "named as the run resolves them; default /)")
    p.add_argument("--frame-prefix", default=None, metavar="PREFIX",
                   help="the run's frame prefix, kept in the recording for plot and replay (default: from the "
                        "namespace, sam1/ for /sam1)")
    return p


def record_main(argv: Sequence[str] | None = None) -> int:
    args = _record_parser().parse_args(argv)
    require_runtime("run")
    try:
        # before anything starts
        target = bag_target(args.file) if args.rosbag2 else check_target(args.file)
        names = ros_namespace(args.namespace, frame_prefix=args.frame_prefix)
    except (RecordingTargetError, ValueError) as ex:
        print(f"sam-record: {ex}", file=sys.stderr)
        return EXIT_ERROR
    stay_with_parent()
    setup_logging(args.log_level)

    async def run(stop: asyncio.Event) -> int:
        rec = Recorder(generated_package(args), RecorderConfig(target, layout=args.layout, iface=args.iface,
                                                               dronecan_iface=args.dronecan_iface, bus=args.bus,
                                                               namespace=names.node_namespace,
                                                               frame_prefix=names.frame_prefix))
        summary: dict[str, Any] = {}
        try:
            await rec.start()
            print(f"READY recorder {target} topics={len(rec.writer.channels)} protocols="
                  f"{','.join(rec.protocols) if args.bus else 'none'}", flush=True)
            deadline = None if args.duration is None else time.monotonic() + args.duration
            while not stop.is_set():
                left = None if deadline is None else deadline - time.monotonic()
                if left is not None and left <= 0:
                    break
                await wait_for_stop(stop, _TICK_S if left is None else min(_TICK_S, left))
                rec.tick()
        finally:
            summary = await rec.close()
            if args.rosbag2:  # the bag's metadata.yaml beside the finished file (a cut one recovered in place)
                try:
                    summary["rosbag2"] = str(await asyncio.to_thread(rosbag2_folder, target, target.parent))
                except Exception as ex:  # the MCAP stays; only the folder's metadata is missing: said, not raised
                    summary["rosbag2_error"] = f"{type(ex).__name__}: {ex}"
                    print(f"sam-record: no metadata.yaml for {target.parent}: {ex}", file=sys.stderr)
        print("DONE recorder " + json.dumps(summary, sort_keys=True), flush=True)
        return EXIT_OK

    # one line, no traceback: what the generated package, the DSDL cache or the bus refuse at start
    return serve("sam-record", run, (GeneratedPackageError, DsdlCompileError, RecordingTargetError, ValueError,
                                     OSError))


def _replay_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="sam-replay", description="Replay a recording's raw UAVCAN bus through a "
                                "spec's bridge conversion, offline, and compare with the recorded ROS topics.")
    p.add_argument("file", type=Path, help="the recording (MCAP)")
    add_generated_args(p)
    p.add_argument("--spec", type=Path, default=None,
                   help="replay through this spec instead (built into a temporary folder)")
    p.add_argument("--layout", default=None, metavar="NAME", help="the layout (default: the recording's)")
    p.add_argument("--out", type=Path, default=None, help="write the replayed topics and the bus to this MCAP")
    p.add_argument("--speed", choices=SPEEDS, default="max", help="recorded: at the recorded pace; max (default)")
    p.add_argument("--report", type=Path, default=None, help="write the report as JSON here")
    p.add_argument("--log-level", default="WARNING")
    return p


def _why_no_transfers(rec: Recording) -> str:
    """Why a recording gives the replay nothing to feed, as the end of `<file> ...`: the cause it can name."""
    raw = [c for c in rec.channels.values() if rec.schemas.get(c.schema_id) is not None
           and rec.schemas[c.schema_id].name == TRANSFER_TYPE]
    if raw:
        lost = f"; {rec.damage()} could not be read" if rec.damaged else ""
        cut = f"; it is cut short ({rec.stopped_by})" if rec.stopped_by and not rec.complete else ""
        return f"has a bus channel but no UAVCAN transfer in it{lost}{cut}"
    if rec.damaged or (rec.stopped_by and not rec.messages):
        parts = [f"{rec.damage()} could not be read" if rec.damaged else "",
                 f"it is cut short ({rec.stopped_by})" if rec.stopped_by and not rec.complete else ""]
        return f"holds no readable UAVCAN transfers: {'; '.join(p for p in parts if p)}"
    return "holds no UAVCAN transfers (recorded with --no-bus?)"


def replay_main(argv: Sequence[str] | None = None) -> int:
    args = _replay_parser().parse_args(argv)
    require_runtime("run")
    setup_logging(args.log_level)
    problem = recording_file_problem(args.file)
    if problem is not None:
        print(f"sam-replay: {args.file}: {problem}", file=sys.stderr)
        return EXIT_USAGE
    if args.out is not None:
        try:
            check_target(args.out)
        except RecordingTargetError as ex:
            print(f"sam-replay: {ex}", file=sys.stderr)
            return EXIT_ERROR
    with tempfile.TemporaryDirectory(prefix="sam-replay-") as tmp:
        try:
            if args.spec is not None:
                build(args.spec, Path(tmp) / "generated")
                gen = GeneratedPackage(Path(tmp) / "generated", args.package)
            else:
                gen = generated_package(args)
            rec = read_recording(args.file)
            if rec.damaged:  # skipped, counted, said: what could be read is replayed
                print(f"note: {args.file} has damaged records, skipped: {rec.damage()}", file=sys.stderr)
            if not rec.transfers():
                print(f"sam-replay: {args.file} {_why_no_transfers(rec)}", file=sys.stderr)
                return EXIT_ERROR
            meta = rec.metadata.get(METADATA_NAME, {})
            layout = args.layout or meta.get("layout") or None
            recorded = [p for p in meta.get("protocols", "cyphal").split(",") if p]
            names = run_names(meta)  # a namespaced run's topics and frame ids, as it wrote them
            converters = []
            for proto in recorded:
                try:
                    converters.append(OfflineBridge(gen, layout=layout, protocol=proto if len(recorded) > 1 else None,
                                                    namespace=names))
                except BridgeConfigError as ex:
                    print(f"sam-replay: {proto}: {ex}", file=sys.stderr)
            if not converters:
                return EXIT_ERROR
            report = replay(args.file, converters, out=args.out, speed=args.speed, recording=rec)
        except SpecError as ex:
            print(f"sam-replay: the spec is invalid:\n{ex}", file=sys.stderr)
            return EXIT_ERROR
        except (GeneratedPackageError, BridgeConfigError, DsdlCompileError, OSError, ValueError) as ex:
            print(f"sam-replay: {ex}", file=sys.stderr)
            return EXIT_ERROR
    if not rec.complete:
        print(f"note: {args.file} was cut short ({rec.stopped_by}); replayed what it holds")
    print("\n".join(report.lines()))
    if args.report is not None:
        write_json_atomic(args.report, report.as_dict())
    return EXIT_OK if report.same else EXIT_DIFFERENT
