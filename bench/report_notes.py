"""The closing notes of bench/run.py's report: what limits each figure, from the run's numbers and the profiles
(bench/profile_bridge.py)."""

from __future__ import annotations

import math
from typing import Any

from bench.report_fmt import num as _f
from bench.report_fmt import span as _range
from bench.report_wire import DIRECTIONS, TARGET_CYPHAL, TARGET_DRONECAN, codec_notes, cpu, step


def notes(res: dict[str, Any]) -> list[str]:
    """The closing note: what limits each figure, from this run's numbers and the profiles (bench/profile_bridge.py)."""
    out: list[str] = []
    gen = res.get("generator")
    if gen and gen.get("stages_at_largest", {}).get("seconds"):
        st = gen["stages_at_largest"]["seconds"]
        top = sorted(st.items(), key=lambda kv: -kv[1])[:3]
        growth = gen["growth"]["sam-codegen build"]
        out.append(
            f"- **Generator.** Fitted exponent {growth['fitted_exponent']} (local "
            f"{', '.join(f'{k}: {_f(e)}' for k, e in growth['local_exponents'].items())}); pycyphal's own compile "
            f"{gen['growth']['pycyphal compile']['fitted_exponent']}. At {gen['stages_at_largest']['types']} types "
            f"the largest stages are {', '.join(f'{k.strip()} ({v:.2f} s)' for k, v in top)}. pydsdl's namespace "
            "checks are quadratic (pairwise fixed-port-id check, a scan of every definition per type read), so the "
            "generator has pydsdl read the emitted DSDL in batches of bounded size (codegen/build.py DSDL_BATCH); "
            "pycyphal's compile has pydsdl read the whole namespace in one call.")
    conv = res.get("converters")
    if conv:
        s = conv["summary"]
        imu = next((r for r in conv["rows"] if r["mapping"] == "imu" and r["direction"] == "to_ros"), None)
        imu_txt = (f"`sensor_msgs/Imu()` alone takes {imu['ctor_ns'] / 1e3:.1f} us, convert.py's constructor "
                   f"{_f(imu.get('generated_ctor_ns'), 0)} ns, the whole generated imu_to_ros "
                   f"{imu['ns_per_call']['generated'] / 1e3:.1f} us" if imu else "see the ctor columns")
        out.append(
            f"- **Converters.** Generated vs hand-written: geomean {s['all']['geomean_vs_handwritten']:.2f}x (min "
            f"{s['all']['min_vs_handwritten']:.2f}x); vs the generic copier: geomean "
            f"{s['all']['geomean_vs_generic']:.2f}x (min {s['all']['min_vs_generic']:.2f}x; to ROS "
            f"{s['to_ros']['geomean_vs_generic']:.2f}x, to UAVCAN {s['to_uavcan']['geomean_vs_generic']:.2f}x). "
            "The destination's class constructor used to be most of every converter's time: a rosidl class's "
            "`__init__` builds every default sub-message even when one is passed, and a pycyphal class's checks "
            "and copies every array again. The generated converters now compute every value first (every check "
            "and drop before anything is built), then call convert.py's own constructors, which set the classes' "
            f"attributes directly ({imu_txt}). convert.py proves at import that each of its constructors builds "
            "what the class builds (`FAST_CONSTRUCTORS`; with ROS_PYTHON_CHECK_FIELDS=1 or another "
            "rosidl/nunavut layout it uses the classes), and tests/test_converters.py checks both paths give the "
            "same messages. What is left is reading numpy arrays (`.tolist()`) and building numpy arrays for the "
            "fixed-size fields.")
    codec = res.get("codec")
    if codec:
        out += codec_notes(codec)
    br = res.get("bridge") or {}
    udp = br.get("udp") or {}
    profiled = False
    for kind in ("udp", "can"):
        b = br.get(kind) or {}
        if b.get("throughput"):
            out.append(cyphal_bridge_note(b))
            profiled = profiled or any(round(b["throughput"][f"{d}_ratio"], 2) < TARGET_CYPHAL for d in ("u2r", "r2u"))
            if b["throughput"]["r2u_bridge"]["lost"]:
                out.append(burst_loss_note(b["transport"], b["throughput"]["r2u_bridge"]["lost"], br["method"],
                                           b["latency"]["r2u_bridge"]))
    if profiled and br.get("udp", {}).get("wire") == "codec":
        out.append(cyphal_profile_note())
    can = br.get("can") or {}
    mixes = [b["sensor_mix"] for b in (udp, can) if b.get("sensor_mix")]
    if mixes:
        trials = [t for m in mixes for t in m["trials"]]
        failed = [t for t in trials if not t["sustained"]]
        why = sorted({("publishers behind schedule" if not t["on_schedule"] else "")
                      + (", messages lost" if t["lost"] else "") + (", bridge drops" if t["bridge_dropped"] else "")
                      for t in failed} - {""})
        can_nodes = (can.get("sensor_mix") or {}).get("nodes_on_bus")
        out.append(
            f"- **Sensor mix.** The simulated devices ({mixes[0]['device_nodes']} nodes) publish from the bridge's "
            "own process and asyncio loop, so the rate at which that loop falls 0.25 s behind its schedule bounds the "
            f"figure; the failing trials failed by: {'; '.join(why) or 'nothing'} "
            f"({sum(t['lost'] for t in trials)} messages lost and {sum(t['bridge_dropped'] for t in trials)} bridge "
            "drops over all trials). On python-can's virtual bus every frame is handed, in Python, to every other "
            f"node on the bus ({can_nodes} there): that fan-out, not the bridge, bounds the CAN figure; a real CAN "
            "bus filters in hardware. Both figures are lower bounds for the bridge alone.")
    dc = res.get("dronecan") or {}
    if dc.get("throughput"):
        out += dronecan_notes(dc)
    out.append(
        "- **Method limits.** 2 cores shared by the publisher, the bridge, DDS threads and the ROS process, and by "
        "whatever else runs on the machine (see the load average); raw and bridge runs alternate so drifts hit both. "
        "py-spy cannot attach here (ptrace is refused), so profiles are cProfile of every thread "
        "(`python -m bench.profile_bridge`).")
    return out


def _extra(tp: dict[str, Any], d: str) -> str:
    """Where a bridge run's CPU per message goes beyond its raw run's, by thread."""
    b, r = f"{d}_bridge", f"{d}_raw"

    def diff(key: str) -> str:
        return f"{round(cpu(tp, b, key) - cpu(tp, r, key)):+d}"

    return (f"this process {cpu(tp, b):.0f} us per message against {cpu(tp, r):.0f} us raw (asyncio loop "
            f"{diff('main (asyncio loop)')}, the bridge's rclpy thread {cpu(tp, b, 'bridge rclpy thread'):.0f}, "
            f"DDS and I/O threads {diff('other threads')}), and {cpu(tp, b, 'ROS process'):.0f} us in the ROS "
            "process")


def cyphal_bridge_note(b: dict[str, Any]) -> str:
    """The bridge on Cyphal: both paths against raw, where the wire path's time goes, what bounds it."""
    tp, pm = b["throughput"], b.get("per_message_us") or {}
    ob = (b.get("object") or {}).get("throughput")
    cvo = b.get("codec_vs_object") or {}
    missed = [label for d, label in (("u2r", "UAVCAN->ROS"), ("r2u", "ROS->UAVCAN"))
              if round(tp[f"{d}_ratio"], 2) < TARGET_CYPHAL]
    text = (f"- **Bridge, {b['transport']}** ({path(b)} {tp['u2r_ratio']:.2f}x raw UAVCAN->ROS, "
            f"{tp['r2u_ratio']:.2f}x ROS->UAVCAN"
            + (f"; object path {ob['u2r_ratio']:.2f}x and {ob['r2u_ratio']:.2f}x, so the wire path moves "
               f"{cvo.get('u2r', math.nan):.2f}x and {cvo.get('r2u', math.nan):.2f}x the object path's messages"
               if ob else "") + "). "
            "The runs are CPU-bound: this process (the device or sender, pycyphal's transport, the bridge, DDS's "
            "threads) needs about a core, the ROS process the other. "
            f"UAVCAN->ROS: {_extra(tp, 'u2r')}. ROS->UAVCAN: {_extra(tp, 'r2u')}. ")
    w2r, pub_raw = step(pm, "wire path: generated imu_wire_to_ros"), step(pm, "wire path: rclpy publish")
    deser, conv, pub = (step(pm, "pycyphal deserialize"), step(pm, "generated imu_to_ros"),
                        step(pm, "rclpy publish of the Imu"))
    if not math.isnan(w2r):
        text += (f"Per IMU message, measured alone: the wire path's codec {w2r:.1f} us and raw publish of its CDR "
                 f"{pub_raw:.1f} us replace the object path's pycyphal deserialize {deser:.1f} us, imu_to_ros "
                 f"{conv:.1f} us and rclpy publish of the message {pub:.1f} us (rclpy serializes it in C), and the "
                 f"command's ros_to_wire is {step(pm, 'wire path: generated thrust_vector_ros_to_wire'):.1f} us. ")
    if ob:
        text += (f"The object path's runs cost {cpu(ob, 'u2r_bridge'):.0f} us (UAVCAN->ROS) and "
                 f"{cpu(ob, 'r2u_bridge'):.0f} us (ROS->UAVCAN) per message in this process against "
                 f"{cpu(ob, 'u2r_raw'):.0f} and {cpu(ob, 'r2u_raw'):.0f} us raw beside them. ")
    text += ("Raw's CPU per message in this process over the bridge run's: "
             + " and ".join(f"{cpu(tp, f'{d}_raw') / cpu(tp, f'{d}_bridge'):.2f}x {label} (msg/s measured "
                            f"{tp[f'{d}_ratio']:.2f}x)" for d, label in DIRECTIONS)
             + ": msg/s follows this process's CPU, the ROS process having most of the other core. ")
    if missed:
        text += (f"**{' and '.join(missed)} below {TARGET_CYPHAL:g}x**: see the profile of the wire path below.")
    else:
        text += f"Both directions at or above the {TARGET_CYPHAL:g}x target."
    return text


def cyphal_profile_note() -> str:
    """What a cProfile of every thread of the wire path showed (bench/profile_bridge.py; one run, cProfile inflates
    Python against C, so the shares matter more than the us)."""
    return (
        "- **Profile of the wire path** (`python -m bench.profile_bridge u2r_bridge udp 3`, `... r2u_bridge udp 3`, "
        "`... r2u_raw udp 3`: cProfile of every thread, 2026-11-24, load average ~1). UAVCAN->ROS: the asyncio loop "
        "never waits (epoll 3 % of its time); per message the device's side (pycyphal serialize, the datagram "
        "send, which on loopback multicast delivers to every joined socket inside the call: ~115 us under the "
        "profiler), pycyphal's transport on both sides (CRC-32C in Python, ~29 us per datagram each way) and the "
        "receive task dominate, as in the raw run; the bridge's whole inbound handler (codec, checks, counters, "
        "`publish_raw` 24 us) is ~62 us, less than raw's pycyphal deserialize (~104 us under the profiler). So the "
        "bridge's asyncio loop costs what raw's does, and what is left is the work of DDS's own threads in this "
        "process for each publication (and the ROS consumer process, on the other core). ROS->UAVCAN: the asyncio "
        "loop is idle ~40 % of the time, "
        "waiting for commands; the bridge's rclpy thread takes each command's CDR and converts it "
        "(thrust_vector_ros_to_wire ~8 us under the profiler), then hands it to the loop with one "
        "`call_soon_threadsafe` (a self-pipe write) per batch, and batches are mostly single commands (4,646 "
        "wake-ups for 5,373 commands), each write ~110 us under the profiler, the GIL hand-over to the loop's "
        "thread included. The bound there is that hand-off and the DDS delivery from the ROS process's Python "
        "publisher, not the codec. Sending the payload from the rclpy thread, or batching the wake-ups by time, "
        "would be the next runtime change to try (runtime/bridge/handoff.py).")


def burst_loss_note(where: str, lost: int, meth: dict[str, Any], paced: dict[str, Any]) -> str:
    """Commands lost before the bridge saw them: a throughput run's opening burst overflowing the subscription's
    history (keep last 10) while the bridge's rclpy thread takes the first ones."""
    window = meth["window_in_flight"]
    per = lost / max(1, meth["reps"])
    return (f"- **{where} ROS->UAVCAN losses** ({lost} commands over {meth['reps']} throughput runs, {per:g} a run; "
            f"{paced.get('lost') or 'none'} in the paced runs). Each throughput run starts with a burst of {window} "
            "commands (the flow-control window); /thruster_angles is `reliable`, keep last 10 (the spec's "
            "profile), and while the bridge's rclpy thread takes the first ones, the rest of the burst overflows "
            f"the subscription's history in the DDS reader ({window} - 10 = {window - 10} a run at most) before the "
            "bridge sees them, so the bridge's counters cannot show them (with a window of 8, <= the depth, "
            "nothing is lost). The same would happen to a controller's burst of more than 10 commands.")


def path(b: dict[str, Any]) -> str:
    return "wire path" if b.get("wire") == "codec" else f"{b.get('wire', '?')} path"


def dronecan_notes(dc: dict[str, Any]) -> list[str]:
    """What limits the DroneCAN figures, from this run's numbers."""
    tp, pm, meth = dc["throughput"], dc.get("per_message_us") or {}, dc["method"]
    ob = (dc.get("object") or {}).get("throughput")
    cvo = dc.get("codec_vs_object") or {}
    enc_imu, dec_imu = step(pm, "dronecan encode RawIMU"), step(pm, "dronecan decode RawIMU")
    reads = step(pm, "of which: reading the fields")
    enc_cmd, dec_cmd = step(pm, "dronecan encode ArrayCommand"), step(pm, "dronecan decode ArrayCommand")
    raw_u, raw_r = cpu(tp, "u2r_raw"), cpu(tp, "r2u_raw")
    # With a bridge that cost nothing, a bridge run would still cost what its raw run costs but the receiver's
    # decode and reads (UAVCAN->ROS: the device's encode and the frames' I/O stay) or the sender's encode
    # (ROS->UAVCAN: the actuator's decode and the I/O stay): the highest ratio this measurement can show.
    ceil_u = raw_u / max(1e-9, raw_u - dec_imu - reads)
    ceil_r = raw_r / max(1e-9, raw_r - enc_cmd)
    missed = [label for d, label in (("u2r", "UAVCAN->ROS"), ("r2u", "ROS->UAVCAN"))
              if round(tp[f"{d}_ratio"], 2) < TARGET_DRONECAN]
    out = [
        f"- **Bridge on DroneCAN** ({path(dc)} {tp['u2r_ratio']:.2f}x raw dronecan UAVCAN->ROS, "
        f"{tp['r2u_ratio']:.2f}x ROS->UAVCAN"
        + (f"; object path {ob['u2r_ratio']:.2f}x and {ob['r2u_ratio']:.2f}x: the wire path moves "
           f"{cvo.get('u2r', math.nan):.2f}x and {cvo.get('r2u', math.nan):.2f}x its messages" if ob else "")
        + "). Both runs are bound by this process's one Python thread at a time (the GIL): the device or sender, "
        "the receiver and the bridge's node all run on the asyncio loop, so msg/s follows 1 / (CPU per message in "
        f"this process). UAVCAN->ROS: {_extra(tp, 'u2r')}. ROS->UAVCAN: {_extra(tp, 'r2u')}. On the wire path the "
        "bridge never runs dronecan's coder: FrameGate reassembles the frames "
        f"({step(pm, 'sam_runtime FrameGate'):.0f} us a RawIMU), TransferTaps checks the CRC and hands the payload "
        f"to imu_wire_to_ros ({step(pm, 'wire path: generated imu_wire_to_ros'):.1f} us), the CDR is published raw "
        f"({step(pm, 'wire path: rclpy publish'):.1f} us); the inbound handler in place costs "
        f"{step(pm, 'the bridge'):.0f} us. Commands: thrust_vector_ros_to_wire "
        f"{step(pm, 'wire path: generated thrust_vector_ros_to_wire'):.1f} us and the framing of the payload. "
        "What both runs keep is the devices' side in this same process: UAVCAN->ROS, the IMU node's dronecan "
        f"encode ({enc_imu:.0f} us) and 7 datagrams out and in, the bridge saving only the receiver's decode "
        f"({dec_imu:.0f} us) and reads ({reads:.0f} us); ROS->UAVCAN, the actuator node's dronecan decode "
        f"({dec_cmd:.0f} us) and the frames' I/O, the bridge saving only the sender's encode of an ArrayCommand "
        f"({enc_cmd:.0f} us). Even a bridge that "
        f"cost nothing would show at most {ceil_u:.1f}x UAVCAN->ROS and {ceil_r:.1f}x ROS->UAVCAN here (raw's CPU "
        "per message over raw's without the decode and reads it replaces, resp. without the encode it replaces)"
        + (f": **the {TARGET_DRONECAN:g}x target ({' and '.join(missed)}) is out of reach of this measurement, "
           "whose device ends are dronecan in Python in the bridge's process** (on a real bus they are firmware; "
           "the zero-loss figure below uses a pre-encoded device for that reason)." if missed else ".")]
    lost = tp["r2u_bridge"]["lost"]
    if lost:
        out.append(burst_loss_note("DroneCAN", lost, meth, (dc.get("latency") or {}).get("r2u_bridge", {})))
    z = dc.get("zero_loss")
    if z:
        failed = [t for t in z["trials"] if not t["sustained"]]
        why = sorted({("device behind schedule" if not t["on_schedule"] else "")
                      + (", messages lost" if t["lost"] else "") + (", bridge drops" if t["bridge_dropped"] else "")
                      + (", not drained in time" if t["drained_in_s"] >= meth["drain_s"] else "")
                      for t in failed} - {""})
        out.append(
            f"- **DroneCAN zero loss.** {_f(z['max_sustained_msg_per_s'], 0)} RawIMU/s = "
            f"{_f(z['max_sustained_frames_per_s'])} frames/s, {z['share_of_bus_nominal']:.2f}x what a saturated "
            f"1 Mbit/s classic CAN bus carries ({z['share_of_bus_worst_case']:.2f}x with worst-case stuffing): on "
            "a real bus the bus, not the bridge, is the limit for RawIMU. The failing trials failed by: "
            f"{'; '.join(why) or 'nothing'} ({sum(t['lost'] for t in z['trials'])} messages lost and "
            f"{sum(t['bridge_dropped'] for t in z['trials'])} bridge drops over all trials): this process's one "
            "Python thread (the bridge's receive, convert and publish, and the device's pre-encoded sends) falls "
            "behind first"
            + (f", at {_range([t['cpu_percent']['process'] for t in failed])} % of a core in the failing "
               "trials" if failed else "")
            + ". The bisection's last step bounds the figure from below; it moves by a few hundred msg/s between "
            "runs on this shared machine.")
    return out


