"""A Cyphal/UDP fault injector on 127.0.0.1 for tests/test_faults.py: crafts raw Cyphal/UDP datagrams (valid,
broken, spoofed, reordered, undecodable) for a subject and sends them to its multicast group. No rclpy.

python fault_injector.py --generated DIR [--subject 1100]
Reads one command per line on stdin, answers one line ``DONE {json}`` per command (``READY`` first):

    valid N [SRC] [RATE_HZ]   N valid RawIMU transfers from node SRC (default 11); RATE_HZ 0 = as fast as possible
    spoof N                   N valid transfers from node 42 (a node the spec does not allow)
    malformed                 20 garbage datagrams, 20 too short for a header, 20 with a broken header CRC (none of
                              them attributable to a node), then from node 11: 20 transfers whose payload was cut
                              (transfer CRC fails) and 10 two-frame transfers whose last frame never comes; then 1
                              valid transfer (so the bridge sees the transfer-id gap)
    undecodable N             N transfers from node 11 with a valid frame and CRC but a covariance length of 200
                              (> 36), then 1 valid transfer
    reorder                   from node 11 with transfer ids t, t+2, t+1 (late), t+1 (duplicate), t+3
    stamps                    from node 11: device stamps now +1, +3, +2 (older), +4 us; then stamp 0 (unknown);
                              then stamp 0 with rate_gyro_latest [NaN, +inf, -inf] and accelerometer_latest
                              [65504, -65504, 0] (float16 limits)
    burst N [RATE_HZ]         N valid transfers from node 11 as fast as possible (or at RATE_HZ), a 0.3 s pause,
                              then 10 more at 100 Hz (so that a loss at the end of the burst shows as a gap)
    hostile KIND N            N valid RawIMU transfers from node 11 at 100 Hz (the real device), each followed by a
                              hostile sender's datagrams of KIND (issue 29): bad_crc (3 single-frame transfers with
                              node 11's id, the next transfer ids, their CRC broken), bad_crc_multi (a 2-frame
                              transfer with node 11's id and its next transfer id, its CRC broken), header (node
                              11's next transfer with its header CRC broken), jump (a valid transfer with node 11's
                              id, its transfer id 2**40 ahead), partials (50 first frames of 2-frame transfers from
                              distinct node ids, never finished), junk (5 datagrams of random bytes, 3 short ones)
    quit
The JSON says what was sent: ``{"sent": {"11": n, ...}, "datagrams": n, "rate_hz": r, ...}``.
"""

from __future__ import annotations

import argparse
import json
import math
import socket
import sys
import time
from collections import Counter
from pathlib import Path
from typing import Any

CYPHAL_UDP_PORT = 9382
IMU_NODE = 11
SPOOF_NODE = 42


class RawSender:
    """Builds Cyphal/UDP frames with pycyphal's own frame and serializer classes, sends them with a plain socket."""

    def __init__(self, subject: int, iface: str = "127.0.0.1") -> None:
        import pycyphal.transport
        from pycyphal.transport.udp import UDPFrame
        from pycyphal.transport.udp._ip._endpoint_mapping import message_data_specifier_to_multicast_group

        self.UDPFrame = UDPFrame
        self.ds = pycyphal.transport.MessageDataSpecifier(subject)
        group = str(message_data_specifier_to_multicast_group(self.ds))
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
        self.sock.bind((iface, 0))
        self.sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF, socket.inet_aton(iface))
        self.sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 1)
        self.sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
        self.sock.connect((group, CYPHAL_UDP_PORT))
        self.next_tid: Counter[int] = Counter()
        self.datagrams = 0

    def frames(self, src: int, payload: bytes, tid: int, max_frame_payload: int = 1200) -> list[bytes]:
        import pycyphal.transport
        from pycyphal.transport.commons.high_overhead_transport import serialize_transfer

        def factory(index: int, eot: bool, data: memoryview) -> Any:
            return self.UDPFrame(priority=pycyphal.transport.Priority.NOMINAL, transfer_id=tid, index=index,
                                 end_of_transfer=eot, payload=data, source_node_id=src, destination_node_id=None,
                                 data_specifier=self.ds, user_data=0)

        out = []
        for fr in serialize_transfer([memoryview(payload)], max_frame_payload, factory):
            header, data = fr.compile_header_and_payload()
            out.append(bytes(header) + bytes(data))
        return out

    def send(self, datagram: bytes) -> None:
        self.sock.send(datagram)
        self.datagrams += 1

    def transfer(self, src: int, payload: bytes, tid: int | None = None) -> int:
        if tid is None:
            tid = self.next_tid[src]
        self.next_tid[src] = max(self.next_tid[src], tid + 1)
        for d in self.frames(src, payload, tid):
            self.send(d)
        return tid


class Injector:
    def __init__(self, generated: Path, subject: int) -> None:
        from sam_runtime.genpkg import GeneratedPackage

        gen = GeneratedPackage(generated)
        gen.compile_dsdl()
        ports = {p.subject_id: p for d in gen.tables().DEVICES for p in d.publishes}
        self.dtype = gen.dsdl_class(ports[subject])
        self.tx = RawSender(subject)

    def payload(self, stamp_us: int | None = None, gyro: list[float] | None = None,
                acc: list[float] | None = None) -> bytes:
        import pycyphal.dsdl

        obj = self.dtype()
        obj.timestamp.microsecond = time.time_ns() // 1000 if stamp_us is None else stamp_us
        obj.integration_interval = 0.01
        obj.rate_gyro_latest = gyro if gyro is not None else [0.01, 0.02, 0.03]
        obj.accelerometer_latest = acc if acc is not None else [0.0, 0.0, 9.81]
        obj.covariance = [0.0] * 6
        return b"".join(bytes(x) for x in pycyphal.dsdl.serialize(obj))

    def valid(self, n: int, src: int = IMU_NODE, rate_hz: float = 0.0, stamp_us: int | None = None
              ) -> dict[str, Any]:
        t0 = time.monotonic()
        for i in range(n):
            self.tx.transfer(src, self.payload(stamp_us=stamp_us))
            if rate_hz > 0:
                delay = t0 + (i + 1) / rate_hz - time.monotonic()
                if delay > 0:
                    time.sleep(delay)
        return {"sent": {str(src): n}}

    def malformed(self) -> dict[str, Any]:
        good = self.tx.frames(IMU_NODE, self.payload(), 0)[0]
        kinds = Counter()
        for i in range(20):  # not a Cyphal/UDP frame at all (version byte 0xFF)
            self.tx.send(bytes([0xFF]) + bytes((i * 37 + k) % 256 for k in range(40)))
            kinds["garbage"] += 1
        for _ in range(20):  # shorter than the 24-byte header
            self.tx.send(good[:12])
            kinds["short"] += 1
        for _ in range(20):  # header CRC broken (a flipped bit in the transfer id)
            bad = bytearray(good)
            bad[8] ^= 0x01
            self.tx.send(bytes(bad))
            kinds["bad_header_crc"] += 1
        for _ in range(20):  # the payload cut short: header fine, transfer CRC fails
            tid = self.tx.next_tid[IMU_NODE]
            self.tx.next_tid[IMU_NODE] += 1
            self.tx.send(self.tx.frames(IMU_NODE, self.payload(), tid)[0][:40])
            kinds["truncated_payload"] += 1
        for _ in range(10):  # a two-frame transfer whose last frame never comes
            tid = self.tx.next_tid[IMU_NODE]
            self.tx.next_tid[IMU_NODE] += 1
            frames = self.tx.frames(IMU_NODE, self.payload(), tid, max_frame_payload=32)
            assert len(frames) >= 2
            for d in frames[:-1]:
                self.tx.send(d)
            kinds["missing_last_frame"] += 1
        self.tx.transfer(IMU_NODE, self.payload())
        return {"sent": {str(IMU_NODE): 31}, "kinds": dict(kinds), "unattributable": 60, "broken_from_11": 30,
                "valid": 1}

    def undecodable(self, n: int) -> dict[str, Any]:
        import pycyphal.dsdl

        raw = bytearray(self.payload())
        # RawIMU: timestamp 7 + interval 4 + 3 float16 + 3 float32 + 3 float16 + 3 float32 = 47 bytes, then the
        # covariance length prefix (uint8, capacity 36).
        raw[47] = 200
        assert pycyphal.dsdl.deserialize(self.dtype, [memoryview(bytes(raw))]) is None
        for _ in range(n):
            self.tx.transfer(IMU_NODE, bytes(raw))
        self.tx.transfer(IMU_NODE, self.payload())
        return {"sent": {str(IMU_NODE): n + 1}, "undecodable": n, "valid": 1}

    def reorder(self) -> dict[str, Any]:
        t = self.tx.next_tid[IMU_NODE]
        order = [t, t + 2, t + 1, t + 1, t + 3]
        for tid in order:
            self.tx.transfer(IMU_NODE, self.payload(), tid=tid)
        return {"sent": {str(IMU_NODE): 4}, "datagrams_sent": len(order), "tids": order}

    def stamps(self) -> dict[str, Any]:
        base = time.time_ns() // 1000  # newer than every stamp sent before
        sent = [base + 1, base + 3, base + 2, base + 4]  # the third is older than the second
        for us in sent:
            self.tx.transfer(IMU_NODE, self.payload(stamp_us=us))
        self.tx.transfer(IMU_NODE, self.payload(stamp_us=0))  # unknown: the bridge stamps the receive time
        self.tx.transfer(IMU_NODE, self.payload(stamp_us=0, gyro=[math.nan, math.inf, -math.inf],
                                                acc=[65504.0, -65504.0, 0.0]))
        return {"sent": {str(IMU_NODE): 6}, "stamps_us": [*sent, 0, 0]}

    def burst(self, n: int, rate_hz: float = 0.0) -> dict[str, Any]:
        payload = self.payload(stamp_us=0)  # stamped by the bridge on receipt
        datagrams = [self.tx.frames(IMU_NODE, payload, self.tx.next_tid[IMU_NODE] + i)[0] for i in range(n)]
        self.tx.next_tid[IMU_NODE] += n
        t0 = time.perf_counter()
        for i, d in enumerate(datagrams):
            self.tx.send(d)
            if rate_hz > 0 and i % 20 == 19:  # paced in chunks of 20 (sleep granularity)
                delay = t0 + (i + 1) / rate_hz - time.perf_counter()
                if delay > 0:
                    time.sleep(delay)
        dt = time.perf_counter() - t0
        time.sleep(0.3)
        self.valid(10, IMU_NODE, 100.0, stamp_us=0)
        return {"sent": {str(IMU_NODE): n + 10}, "burst": n, "burst_s": round(dt, 4),
                "burst_rate_hz": round(n / dt) if dt > 0 else None, "trailer": 10}
    def hostile(self, kind: str, n: int) -> dict[str, Any]:
        import random

        rnd = random.Random(29)
        sent, hostile, partial_src = n, 0, 200
        t0 = time.monotonic()
        for i in range(n):
            self.tx.transfer(IMU_NODE, self.payload())
            nxt = self.tx.next_tid[IMU_NODE]
            bad: list[bytes] = []
            if kind == "bad_crc":
                for tid in (nxt, nxt + 1, nxt + 5):
                    d = bytearray(self.tx.frames(IMU_NODE, self.payload(), tid)[0])
                    d[-1] ^= 0x5A
                    bad.append(bytes(d))
            elif kind == "bad_crc_multi":
                frames = self.tx.frames(IMU_NODE, self.payload(), nxt, max_frame_payload=40)
                last = bytearray(frames[-1])
                last[-1] ^= 0x5A
                bad += [*frames[:-1], bytes(last)]
            elif kind == "header":
                d = bytearray(self.tx.frames(IMU_NODE, self.payload(), nxt)[0])
                d[8] ^= 0x01
                bad.append(bytes(d))
            elif kind == "jump":
                bad.append(self.tx.frames(IMU_NODE, self.payload(), nxt + 2**40)[0])
                sent += 1  # a valid transfer of node 11: the bridge counts it (transfer_id_jump)
            elif kind == "partials":
                for _ in range(50):
                    bad.append(self.tx.frames(partial_src, self.payload(), 0, max_frame_payload=40)[0])
                    partial_src += 1
            elif kind == "junk":
                bad += [rnd.randbytes(rnd.randint(24, 80)) for _ in range(5)]
                bad += [rnd.randbytes(rnd.randint(0, 21)) for _ in range(3)]
            else:
                raise ValueError(f"unknown hostile kind {kind!r}")
            for d in bad:
                self.tx.send(d)
            hostile += len(bad)
            delay = t0 + (i + 1) / 100.0 - time.monotonic()
            if delay > 0:
                time.sleep(delay)
        return {"sent": {str(IMU_NODE): sent}, "real": n, "hostile_datagrams": hostile,
                "partial_sources": partial_src - 200}


def main() -> int:
    p = argparse.ArgumentParser()
    p.add_argument("--generated", type=Path, required=True)
    p.add_argument("--subject", type=int, default=1100)
    args = p.parse_args()
    inj = Injector(args.generated, args.subject)
    print("READY", flush=True)
    for line in sys.stdin:
        parts = line.split()
        if not parts:
            continue
        op, rest = parts[0], parts[1:]
        if op == "quit":
            break
        before = inj.tx.datagrams
        if op == "valid":
            res = inj.valid(int(rest[0]), int(rest[1]) if len(rest) > 1 else IMU_NODE,
                            float(rest[2]) if len(rest) > 2 else 0.0)
        elif op == "spoof":
            res = inj.valid(int(rest[0]), SPOOF_NODE, 200.0)
        elif op == "malformed":
            res = inj.malformed()
        elif op == "undecodable":
            res = inj.undecodable(int(rest[0]))
        elif op == "reorder":
            res = inj.reorder()
        elif op == "stamps":
            res = inj.stamps()
        elif op == "hostile":
            res = inj.hostile(rest[0], int(rest[1]))
        elif op == "burst":
            res = inj.burst(int(rest[0]), float(rest[1]) if len(rest) > 1 else 0.0)
        else:
            res = {"error": f"unknown command {op!r}"}
        res["datagrams"] = inj.tx.datagrams - before
        print("DONE " + json.dumps(res), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
