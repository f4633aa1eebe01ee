"""A DroneCAN node in its own process, written against the plain dronecan API (no sam_runtime receive path).

python dronecan_peer.py --iface mcast-lo:<bus>:<port> | slcan:/dev/pts/N  --node-id 42
    [--wait-for 10]                      wait until node 10's NodeStatus is seen before publishing
    [--publish-imu 600 --rate 200]       broadcast RawIMU number 0..599 at 200 Hz (values: raw_imu_message)
    [--listen-imu-from 10]               record RawIMU from node 10 (sequence, values checked, latency)
    [--expect-imu 600]                   print RECEIVED 600 when the 600th has come
    [--query-info-of 10]                 GetNodeInfo request to node 10 once it is seen
    [--max-life 120]

On ``mcast-lo:`` the node is ``dronecan.node.Node(LoopbackMulticastDriver(bus, port), node_id=...)`` with
dronecan's own blocking ``spin()``; on ``slcan:`` it is ``dronecan.make_node(uri, node_id=..., bitrate=1000000)``.
Prints ``READY {...}`` when the node is up, ``PUBLISHED n`` when done publishing, and ``SUMMARY {...}`` when
stdin closes (the test's way to stop it) or ``--max-life`` runs out, then exits 0.
"""

from __future__ import annotations

import argparse
import json
import logging
import sys
import threading
import time
from typing import Any

IMU_DTID = 1003


def raw_imu_fields(seq: int, stamp_us: int = 0) -> dict[str, Any]:
    """RawIMU values for message number ``seq``: all exact in float16/float32, the covariance length varies."""
    return {
        "timestamp": stamp_us,
        "integration_interval": 0.25,
        "rate_gyro_latest": [(seq % 256) * 0.125 - 16.0, -(seq % 100) * 0.5, 1.5],
        "rate_gyro_integral": [float(seq), seq * 0.5, -seq * 0.25],
        "accelerometer_latest": [9.75, -(seq % 64) * 0.25, (seq % 32) * 2.0],
        "accelerometer_integral": [seq / 1024.0, -1.0, 1e6 + seq],
        "covariance": [0.5 * i for i in range(seq % 4)],
    }


def raw_imu_message(seq: int, stamp_us: int) -> Any:
    import dronecan

    f = raw_imu_fields(seq, stamp_us)
    msg = dronecan.uavcan.equipment.ahrs.RawIMU()
    msg.timestamp.usec = f["timestamp"]
    msg.integration_interval = f["integration_interval"]
    for name in ("rate_gyro_latest", "rate_gyro_integral", "accelerometer_latest", "accelerometer_integral"):
        arr = getattr(msg, name)
        for i, v in enumerate(f[name]):
            arr[i] = v
    for v in f["covariance"]:
        msg.covariance.append(v)
    return msg


def read_raw_imu(msg: Any) -> dict[str, Any]:
    """The fields of a received RawIMU, in raw_imu_fields' shape."""
    return {
        "timestamp": int(msg.timestamp.usec),
        "integration_interval": float(msg.integration_interval),
        **{name: [float(v) for v in getattr(msg, name)] for name in (
            "rate_gyro_latest", "rate_gyro_integral", "accelerometer_latest", "accelerometer_integral",
            "covariance")},
    }


def imu_seq(msg: Any) -> int:
    return int(msg.rate_gyro_integral[0])


def _make_node(iface: str, node_id: int, name: str) -> Any:
    import dronecan

    info = dronecan.uavcan.protocol.GetNodeInfo.Response()
    info.name = name
    info.software_version.major = 1
    info.software_version.minor = 27
    info.hardware_version.unique_id = bytes(range(16))
    if iface.startswith("mcast-lo:"):
        from sam_runtime.dronecan_io import LoopbackMulticastDriver, parse_iface

        spec = parse_iface(iface)
        return dronecan.node.Node(LoopbackMulticastDriver(spec.bus, spec.port), node_id=node_id, node_info=info,
                                  node_status_interval=0.5, mode=0)
    return dronecan.make_node(iface, node_id=node_id, bitrate=1_000_000, node_info=info, node_status_interval=0.5,
                              mode=0)


def main() -> int:
    p = argparse.ArgumentParser()
    p.add_argument("--iface", required=True)
    p.add_argument("--node-id", type=int, required=True)
    p.add_argument("--name", default="org.sam.test.peer")
    p.add_argument("--wait-for", type=int)
    p.add_argument("--publish-imu", type=int, default=0)
    p.add_argument("--rate", type=float, default=200.0)
    p.add_argument("--listen-imu-from", type=int)
    p.add_argument("--expect-imu", type=int, default=0, help="print RECEIVED n when n RawIMU have come")
    p.add_argument("--query-info-of", type=int)
    p.add_argument("--max-life", type=float, default=120.0)
    args = p.parse_args()

    # dronecan's drivers log what goes wrong at INFO and above (the SLCAN one from its IO process): keep it.
    logging.basicConfig(level=logging.INFO, format="%(asctime)s %(name)s %(levelname)s %(message)s")
    import dronecan

    node = _make_node(args.iface, args.node_id, args.name)  # before any thread: dronecan's SLCAN driver forks
    stop = threading.Event()

    def watch_stdin() -> None:
        for _ in sys.stdin:
            pass
        stop.set()

    threading.Thread(target=watch_stdin, daemon=True).start()

    seen: dict[int, float] = {}
    received: list[int] = []
    mismatched: list[int] = []
    latencies_us: list[int] = []
    info_reply: dict[str, Any] = {}
    published = [0]

    def on_status(e: Any) -> None:
        seen.setdefault(e.transfer.source_node_id, time.monotonic())

    def on_imu(e: Any) -> None:
        if e.transfer.source_node_id != args.listen_imu_from:
            return
        now_us = time.monotonic_ns() // 1000
        got = read_raw_imu(e.message)
        seq = imu_seq(e.message)
        received.append(seq)
        latencies_us.append(now_us - got["timestamp"])
        if got != raw_imu_fields(seq, got["timestamp"]):
            mismatched.append(seq)
        if len(received) == args.expect_imu:
            print(f"RECEIVED {len(received)}", flush=True)

    def on_info(e: Any) -> None:
        if e is None:
            info_reply["timeout"] = True
            return
        r = e.response
        info_reply.update(name=r.name.decode(), source=e.transfer.source_node_id, uptime=r.status.uptime_sec,
                          health=r.status.health, mode=r.status.mode)

    node.add_handler(dronecan.uavcan.protocol.NodeStatus, on_status)
    if args.listen_imu_from is not None:
        node.add_handler(dronecan.uavcan.equipment.ahrs.RawIMU, on_imu)
    print("READY " + json.dumps({"node_id": args.node_id}), flush=True)

    def publish() -> None:
        if published[0] >= args.publish_imu:
            return
        node.broadcast(raw_imu_message(published[0], time.monotonic_ns() // 1000))
        published[0] += 1
        if published[0] == args.publish_imu:
            print(f"PUBLISHED {published[0]}", flush=True)

    started = False
    queried = False
    end = time.monotonic() + args.max_life
    try:
        while not stop.is_set() and time.monotonic() < end:
            node.spin(0.05)
            ready = args.wait_for is None or args.wait_for in seen
            if ready and not started and args.publish_imu:
                started = True
                print("STARTED", flush=True)
                node.periodic(1.0 / args.rate, publish)  # dronecan's scheduler: no phase drift
            if args.query_info_of is not None and args.query_info_of in seen and not queried:
                queried = True
                node.request(dronecan.uavcan.protocol.GetNodeInfo.Request(), args.query_info_of, on_info,
                             timeout=5.0)
    finally:
        summary = {"published": published[0], "received": received, "mismatched": mismatched,
                   "latencies_us": latencies_us, "seen": sorted(seen), "info": info_reply}
        node.close()
    print("SUMMARY " + json.dumps(summary), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
