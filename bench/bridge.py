"""Part 3: the bridge (runtime/bridge.py, through its public API) against the raw pycyphal transport.

The rig (bench/bridge_rig.py): the process under test holds what the bridge's own process holds in a deployment
plus the devices; the ROS side of the measurement is a separate process, as ROS consumers are in a deployment.

Per transport (Cyphal/UDP on 127.0.0.1; Cyphal/CAN FD on python-can ``virtual``):

- throughput, flow-controlled: at most WINDOW messages in flight (sent - received) for ``window_s`` seconds;
  msg/s = received / (last receipt - first send); nothing may be lost. Bridge UAVCAN->ROS: RawIMU (120 B with its
  covariance) from node 11 on subject 1100 -> bridge -> /imu -> ROS process. Bridge ROS->UAVCAN: the ROS process
  publishes sam_msgs/ThrusterAngles on /thruster_angles -> bridge -> subject 1202 -> pycyphal subscriber.
  Raw reference: the same DSDL types, pycyphal publisher -> pycyphal subscriber in this process, no bridge (own
  subjects on UDP, own virtual bus on CAN), measured in the same run and interleaved with the bridge runs.
- latency, paced at ``latency_hz``: UAVCAN publish -> ROS callback (the send time travels in the RawIMU
  timestamp, which the converter turns into header.stamp) and ROS publish -> UAVCAN receive (a sequence number
  travels in the two float16 angles, inside their limits: bench.common.seq_angles; the ROS process returns its
  send times).
- CPU time of this process (os.times: all its threads) per 1000 messages of the throughput runs, split by thread
  (main = asyncio loop: the device publisher + pycyphal + the bridge's UAVCAN half; the bridge's rclpy thread;
  other = DDS and transport I/O threads); the ROS process's CPU beside it; resident memory (VmRSS) before and
  after the bridge starts and after all bridged messages.
- the SAM sensor mix: every UAVCAN->ROS port of the spec from its device's node id at k x its nominal rate for
  ``mix_s`` seconds; sustained = every message at ROS (counted per topic), none dropped by the bridge, the
  publishers on schedule (never 0.25 s behind) and the backlog drained within ``drain_s``. k doubles from 1 until
  a trial fails, then is bisected twice.
"""

from __future__ import annotations

import asyncio
import heapq
import os
import time
from collections.abc import Callable
from typing import Any

from bench.bridge_blocks import codec_vs_object, object_block, run_block, summarize_latency, summarize_throughput
from bench.bridge_rig import ACT_NODE, IMU_TOPIC, WINDOW, Rig, cyphal_udp_lock, imu_payload, now_us, rss_kib
from bench.common import log, percentile, sample_uavcan


# ----------------------------------------------------------------------------------------------- sensor mix
async def sensor_mix_trial(rig: Rig, devices: dict[int, Any], k: float, seconds: float, drain_s: float
                           ) -> dict[str, Any]:
    """Every UAVCAN->ROS port at k x nominal from its device; sustained = nothing lost, on schedule, drained."""
    gen, ros = rig.gen, rig.ros
    assert ros is not None
    ports: dict[int, Any] = {}
    for m in rig.in_maps:
        ports.setdefault(m.port.subject_id, (m, next(iter(m.source_node_ids))))
    pubs = []
    for sid, (m, nid) in sorted(ports.items()):
        pub = devices[nid]["pubs"].get(sid)
        if pub is None:
            pub = devices[nid]["node"].make_publisher(gen.dsdl_class(m.port), sid)
            devices[nid]["pubs"][sid] = pub
        pubs.append((sid, pub, sample_uavcan(gen, m.port, seed=sid), float(m.port.rate_hz) * k))
    nominal = sum(float(m.port.rate_hz) for m, _ in ports.values())
    before = {t: ros.count(t) for t in rig.in_topics}
    before_stats = rig.bridge.stats()["mappings"]
    sent = {sid: 0 for sid, *_ in pubs}
    heap = [(i / (17.0 * rate), sid, rate, pub, sample) for i, (sid, pub, sample, rate) in enumerate(pubs)]
    heapq.heapify(heap)
    await ros.request("lat_on")
    t0 = time.monotonic()
    end = t0 + seconds
    late_max = 0.0
    behind = False
    while heap:
        due, sid, rate, pub, sample = heap[0]
        at = t0 + due
        now = time.monotonic()
        if at >= end or now >= end:
            break
        if at > now:
            await asyncio.sleep(at - now)
        elif now - at > 0.25:  # a quarter second behind schedule: this rate is not sustained
            behind = True
            late_max = max(late_max, now - at)
            break
        else:
            late_max = max(late_max, now - at)
        heapq.heapreplace(heap, (due + 1.0 / rate, sid, rate, pub, sample))
        if hasattr(sample, "timestamp"):
            sample.timestamp.microsecond = now_us()
        if await pub.publish(sample):
            sent[sid] += 1
    t_sent = time.monotonic()
    expected = {t: sum(sent[m.port.subject_id] for m in rig.in_maps if m.topic.name == t) for t in rig.in_topics}

    def got() -> dict[str, int]:
        return {t: ros.count(t) - before[t] for t in rig.in_topics}

    while any(got()[t] < expected[t] for t in rig.in_topics) and time.monotonic() < t_sent + drain_s:
        await asyncio.sleep(0.005)
    drained_in = time.monotonic() - t_sent
    await asyncio.sleep(0.05)
    received = got()
    lat = (await ros.request("lat_off"))[1]
    after_stats = rig.bridge.stats()["mappings"]
    dropped = sum(after_stats[m.name]["dropped_total"] - before_stats[m.name]["dropped_total"] for m in rig.in_maps)
    elapsed = max(1e-9, t_sent - t0)
    total = sum(sent.values())
    on_schedule = not behind and total >= 0.97 * nominal * k * seconds
    lost = sum(max(0, expected[t] - received[t]) for t in rig.in_topics)
    return {
        "k": k, "target_msg_per_s": round(nominal * k, 1), "offered_msg_per_s": round(total / elapsed, 1),
        "ros_msgs_expected": sum(expected.values()), "ros_msgs_received": sum(received.values()), "lost": lost,
        "bridge_dropped": dropped, "on_schedule": on_schedule, "publisher_late_max_ms": round(late_max * 1e3, 1),
        "drained_in_s": round(drained_in, 3),
        "imu_latency_p50_ms": round(percentile(lat, 50) / 1e3, 2) if lat else None,
        "imu_latency_p99_ms": round(percentile(lat, 99) / 1e3, 2) if lat else None,
        "sustained": lost == 0 and dropped == 0 and on_schedule and drained_in < drain_s,
    }


async def sensor_mix(rig: Rig, seconds: float, drain_s: float, k_max: float = 512.0, bisect: int = 2
                     ) -> dict[str, Any]:
    ids = sorted({next(iter(m.source_node_ids)) for m in rig.in_maps})
    existing = {next(iter(rig.imu_map.source_node_ids)): rig.imu_node, ACT_NODE: rig.act_node}  # one node per id
    devices = {nid: {"node": existing.get(nid) or rig.node(f"dev{nid}", nid), "pubs": {}} for nid in ids}
    nominal = sum(float(p.rate_hz) for p in {m.port.subject_id: m.port for m in rig.in_maps}.values())
    trials: list[dict[str, Any]] = []
    good, bad = 0.0, None

    async def trial(k: float) -> bool:
        r = await sensor_mix_trial(rig, devices, k, seconds, drain_s)
        trials.append(r)
        log(f"  mix x{k:g} ({r['target_msg_per_s']:.0f} msg/s): {'sustained' if r['sustained'] else 'NOT sustained'}"
            f" - {r['ros_msgs_received']}/{r['ros_msgs_expected']} at ROS, offered {r['offered_msg_per_s']}/s, "
            f"late {r['publisher_late_max_ms']} ms, drained in {r['drained_in_s']} s")
        await asyncio.sleep(0.3 if r["sustained"] else 1.5)  # let a backlog clear before the next trial
        return bool(r["sustained"])

    k = 1.0
    while k <= k_max:
        if await trial(k):
            good, k = k, k * 2
        else:
            bad = k
            break
    if bad is not None and good > 0:
        for _ in range(bisect):
            k = round((good + bad) / 2, 2)
            if await trial(k):
                good = k
            else:
                bad = k
    return {"nominal_msg_per_s": nominal, "nominal_ros_msg_per_s": sum(float(m.rate_hz) for m in rig.in_maps),
            "max_sustained_k": good, "max_sustained_msg_per_s": round(good * nominal, 1), "first_failing_k": bad,
            "device_nodes": len(devices), "nodes_on_bus": len(rig.nodes) - (3 if rig.kind == "can" else 2) + 1,
            "trials": trials}


def per_message_costs(rig: Rig, n: int = 2000) -> dict[str, float]:
    """Microseconds per call of the steps of one bridged IMU message, each alone in a loop (best of 3), on the
    running bridge (its /imu publisher has the ROS process as subscriber)."""
    import timeit

    import pycyphal.dsdl

    conv = rig.gen.convert()
    src = rig.imu_sample
    stats = conv.ConversionStats()
    msg = conv.imu_to_ros(src, 1, stats)
    raw = list(pycyphal.dsdl.serialize(src))
    pub = getattr(rig.bridge.ros, "_publishers", {}).get(IMU_TOPIC)
    clock = getattr(rig.bridge.ros, "clock", None)

    def t(fn: Any) -> float:
        return round(min(timeit.repeat(fn, number=n, repeat=3)) / n * 1e6, 2)

    out = {
        "pycyphal serialize RawIMU (device side)": t(lambda: list(pycyphal.dsdl.serialize(src))),
        "pycyphal deserialize RawIMU (receive side, raw too)": t(lambda: pycyphal.dsdl.deserialize(type(src), raw)),
        "generated imu_to_ros": t(lambda: conv.imu_to_ros(src, 1, stats)),
        "  for comparison: sensor_msgs/Imu() (the class; the converter builds with its own constructor)": t(type(msg)),
    }
    receive_ns = getattr(rig.bridge.ros, "receive_ns", None)
    if receive_ns is not None:
        out["bridge: receive stamp per message (system clock unless use_sim_time)"] = t(receive_ns)
    if clock is not None:
        out["  for comparison: rclpy Clock.now() (read only under use_sim_time)"] = t(
            lambda: clock.now().nanoseconds)
    if pub is not None:
        out["rclpy publish of the Imu (1 subscriber)"] = t(lambda: pub.publish(msg))
    out.update(wire_steps(rig, pub, t))
    return out


def wire_steps(rig: Rig, pub: Any, t: Callable[[Any], float]) -> dict[str, float]:
    """The wire path's steps of the same IMU message and of a command (what replaces the steps above)."""
    from rclpy.serialization import serialize_message

    codec = rig.gen.codec("dronecan" if rig.kind == "dronecan" else "cyphal")
    if codec is None:
        return {}
    conv = rig.gen.convert_v0() if rig.kind == "dronecan" else rig.gen.convert()
    stats = conv.ConversionStats()
    w2r = codec.CODECS[rig.imu_map.name][0]
    r2w = codec.CODECS[rig.cmd_map.name][1]
    payload = imu_payload(rig)
    cdr, _ = w2r(payload, 1, stats)
    angles = rig.gen.ros_class(rig.cmd_map.topic)(thruster_vertical_radians=0.0625, thruster_horizontal_radians=-0.0625)
    cmd_cdr = serialize_message(angles)
    out = {f"wire path: generated {rig.imu_map.name}_wire_to_ros (payload {len(payload)} B -> CDR {len(cdr)} B)":
           t(lambda: w2r(payload, 1, stats))}
    if pub is not None:
        out["wire path: rclpy publish of the Imu's CDR bytes (raw, 1 subscriber)"] = t(lambda: pub.publish(cdr))
    out[f"wire path: generated {rig.cmd_map.name}_ros_to_wire (CDR -> payload)"] = t(lambda: r2w(cmd_cdr, stats))
    return out



async def measure_transport(gen: Any, kind: str, *, reps: int, window_s: float, latency_hz: float,
                            latency_s: float, mix_s: float, drain_s: float, mix: bool = True,
                            object_reps: int = 3, object_latency_reps: int = 1) -> dict[str, Any]:
    from sam_runtime.cyphal_io.transport import quiet_late_media_completions

    quiet_late_media_completions(asyncio.get_running_loop())
    pid = os.getpid()
    if kind == "udp":
        rig = Rig(gen, "udp", "127.0.0.1", "127.0.0.1", None)
        label = "Cyphal/UDP on 127.0.0.1"
    else:
        rig = Rig(gen, "can", f"virtual:sbb{pid}", f"virtual:sbr{pid}", 64)
        label = "Cyphal/CAN FD on python-can virtual"
    rss: dict[str, int] = {}
    out: dict[str, Any] = {"transport": label, "kind": kind}
    try:
        await rig.start(rss)
        out["wire"] = rig.bridge.wire  # "object" when the generated package has no codecs (the bridge warns)
        if out["wire"] != "codec":
            log(f"WARNING: the bridge took the {out['wire']} path, not the codec one (no generated codec module?)")
        tp, lat, bridged = await run_block(rig, reps=reps, window_s=window_s, latency_reps=max(1, reps - 2),
                                           latency_hz=latency_hz, latency_s=latency_s)
        rss["after_bridged_kib"] = rss_kib()
        out["bridged_messages"] = bridged
        out["throughput"] = summarize_throughput(tp)
        out["latency"] = summarize_latency(lat, latency_hz, latency_s)
        out["rss"] = dict(rss)
        out["rss"]["bridge_footprint_mib"] = round((rss["after_bridge_start_kib"] - rss["before_bridge_kib"]) / 1024, 1)
        out["rss"]["growth_kib_per_1000_bridged"] = round(
            (rss["after_bridged_kib"] - rss["after_bridge_start_kib"]) / max(1, bridged) * 1000, 2)
        out["per_message_us"] = per_message_costs(rig)
        await asyncio.sleep(1.0)  # let the ROS process take those before the sensor mix counts
        if mix:
            n0 = len(rig.nodes)
            out["sensor_mix"] = await sensor_mix(rig, mix_s, drain_s)
            await rig.drop_nodes(n0)  # the mix's device nodes: on python-can's virtual bus each costs every frame
        st = rig.bridge.stats()
        out["bridge_errors"] = st["bridge"]["errors"]
        out["bridge_dropped"] = {n: m["dropped"] for n, m in st["mappings"].items() if m["dropped_total"]}
        if object_reps and out["wire"] == "codec":
            out["object"] = await object_block(rig, reps=object_reps, window_s=window_s,
                                               latency_reps=object_latency_reps, latency_hz=latency_hz,
                                               latency_s=latency_s)
            out["codec_vs_object"] = codec_vs_object(out["throughput"], out["object"]["throughput"])
    finally:
        await rig.close()
    return out


def run(gen: Any, transports: tuple[str, ...] = ("udp", "can"), *, reps: int = 3, window_s: float = 3.0,
        latency_hz: float = 200.0, latency_s: float = 2.5, mix_s: float = 3.0, drain_s: float = 0.5,
        mix: bool = True, object_reps: int = 3, object_latency_reps: int = 1) -> dict[str, Any]:
    """Per transport: the bridge on its wire path (codec) against raw, then on the object path against raw
    (``object_reps`` throughput and ``object_latency_reps`` latency repetitions; 0: not measured)."""
    import logging

    os.environ.setdefault("ROS_DOMAIN_ID", str(150 + os.getpid() % 60))  # private to this run (tests use 1..101)
    # The bridge warns when an overloaded loop delays a heartbeat past 3 s; its counters tell the rest.
    logging.getLogger("sam_runtime").setLevel(logging.ERROR)
    gen.convert()  # DSDL compiled and the converters importable before anything else
    results: dict[str, Any] = {"method": {
        "window_in_flight": WINDOW, "window_s": window_s, "reps": reps, "latency_hz": latency_hz,
        "latency_s": latency_s, "mix_s": mix_s, "drain_s": drain_s, "ros_domain_id": os.environ["ROS_DOMAIN_ID"],
        "latency_reps": max(1, reps - 2), "object_reps": object_reps, "object_latency_reps": object_latency_reps,
    }}
    for kind in transports:
        t0 = time.monotonic()
        kw = dict(reps=reps, window_s=window_s, latency_hz=latency_hz, latency_s=latency_s, mix_s=mix_s,
                  drain_s=drain_s, mix=mix, object_reps=object_reps, object_latency_reps=object_latency_reps)
        if kind == "udp":
            with cyphal_udp_lock() as locked:
                res = asyncio.run(measure_transport(gen, kind, **kw))
                res["udp_lock_held"] = locked
        else:
            res = asyncio.run(measure_transport(gen, kind, **kw))
        res["wall_s"] = round(time.monotonic() - t0, 1)
        log(f"bridge {kind}: done in {res['wall_s']} s")
        results[kind] = res
    return results


if __name__ == "__main__":
    import json
    import sys

    from bench.common import generated_package

    args = sys.argv[1:]
    kinds = tuple(a for a in args if a in ("udp", "can")) or ("udp", "can")
    print(json.dumps(run(generated_package(), kinds, reps=2, window_s=2.0, mix="nomix" not in args,
                         object_reps=0 if "noobject" in args else 2), indent=1, default=str))
