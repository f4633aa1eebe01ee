"""Part `codec` (issue 12): every generated wire codec alone against the object pipeline it replaces, per mapping of
the spec, Cyphal (``<pkg>.codec``) and DroneCAN (``<pkg>.codec_v0``), both directions.

- UAVCAN->ROS, object pipeline: the protocol library's deserializer (``pycyphal.dsdl.deserialize`` / dronecan's
  ``_unpack`` of the payload bits, as ``Transfer.from_frames`` does it) + the generated ``<m>_to_ros`` +
  ``rclpy.serialization.serialize_message``; codec: ``<m>_wire_to_ros(payload, receive_ns, stats)``.
- ROS->UAVCAN, object pipeline: ``deserialize_message`` + the generated ``<m>_to_uavcan`` + the library's serializer
  (``pycyphal.dsdl.serialize`` / dronecan's ``_pack`` with tail array optimisation, as ``Transfer`` packs it on
  classic CAN); codec: ``<m>_ros_to_wire(cdr, stats)``.

Inputs: the simulator's values for the mapping's type (as bench.common.sample_uavcan: generic values, then the SAM
physics; for DroneCAN also the mapping's ``select`` values and the broadcast elements it reads), as received
(encoded and decoded once); the ROS->UAVCAN input is the CDR of the object path's ROS message of it. Before timing,
both must agree: the codec's CDR deserialized by rclpy equals the object pipeline's message, its payload decoded by
the library equals the object converter's UAVCAN object (NaN-aware), same stamp, same counters; whether the bytes
are identical too is recorded.

Method as bench/converters.py: batches of K calls (K such that the object pipeline's batch takes ~``batch_s`` and
the codec's at least 0.25 ms) timed with perf_counter_ns for each in turn, ``rounds`` rounds in alternating order,
the garbage collector paused in a batch (and run once before each mapping's direction); the figure is the best
round (other processes only add time), medians kept.

    python -m bench.run --parts codec [--quick]        python -m bench.codec   (table on stdout)
"""

from __future__ import annotations

import gc
import math
import random
import time
from collections.abc import Callable
from typing import Any

from bench.common import log, median, plain, ratio, same, sample_uavcan

TARGET = 5.0  # issue 12: the codec alone >= 5x the object pipeline, every mapping
RECEIVE_NS = 1_795_000_000_123_456_789
IMPLS = ("codec", "object")


def _batch_ns(fn: Callable[..., Any], args: tuple[Any, ...], k: int) -> float:
    # GC paused in the batch; collected once per mapping and direction (time_pair), not per batch: a full
    # collection with rclpy, pycyphal and dronecan loaded takes tens of ms, and neither side leaves cycles
    gc.disable()
    try:
        t0 = time.perf_counter_ns()
        for _ in range(k):
            fn(*args)
        return (time.perf_counter_ns() - t0) / k
    finally:
        gc.enable()


def _ns_per_call(fn: Callable[..., Any], args: tuple[Any, ...]) -> float:
    k = 20
    while True:
        per = _batch_ns(fn, args, k)
        if per * k >= 2e6 or k >= 1_000_000:
            return max(per, 1.0)
        k *= 4


def batch_size(object_ns: float, codec_ns: float, batch_s: float) -> int:
    """Calls per batch: the object pipeline's batch ~batch_s, the codec's at least 0.25 ms (a timer read costs
    ~0.1 us: the codec's batch is timed to better than 0.1 %).

    >>> batch_size(50_000, 5_000, 0.005)
    100
    >>> batch_size(100_000, 1_000, 0.005)
    250
    """
    return max(20, int(batch_s * 1e9 / object_ns), int(2.5e5 / codec_ns))


def _put(obj: Any, path: str, value: Any) -> None:
    *head, last = path.split(".")
    for part in head:
        obj = getattr(obj, part)
    setattr(obj, last, value)


# ----------------------------------------------------------------------------------------------- the protocols
class CyphalSide:
    """Cyphal: pycyphal's (de)serializer, the mapping's DSDL class, bench.common.sample_uavcan."""

    protocol, label = "cyphal", "Cyphal"

    def __init__(self, gen: Any) -> None:
        import pycyphal.dsdl

        self.gen, self._dsdl = gen, pycyphal.dsdl
        self.convert = gen.convert()
        self.mappings = list(gen.tables().MAPPINGS)

    def sample(self, m: Any) -> Any:
        return sample_uavcan(self.gen, m.port)

    def decoder(self, m: Any) -> Callable[[Any], Any]:
        deserialize, cls = self._dsdl.deserialize, self.gen.dsdl_class(m.port)

        def decode(payload: Any) -> Any:
            return deserialize(cls, [memoryview(payload)])

        return decode

    def encoder(self, m: Any) -> Callable[[Any], bytes]:
        serialize = self._dsdl.serialize

        def encode(obj: Any) -> bytes:
            return b"".join(serialize(obj))

        return encode

    def builtin(self, obj: Any) -> Any:
        return None if obj is None else self._dsdl.to_builtin(obj)


class DroneCanSide:
    """DroneCAN: dronecan's bit-level (de)serializer on classic CAN (tail array optimisation), the simulator's v0
    values (generic values, physics, then the mapping's ``select`` values and array elements)."""

    protocol, label = "dronecan", "DroneCAN"

    def __init__(self, gen: Any) -> None:
        import dronecan
        from dronecan import transport

        self.gen, self._dronecan, self._transport = gen, dronecan, transport
        self.convert = gen.convert_v0()  # the spec's own v0 types loaded beside dronecan's
        self.mappings = list(gen.tables().DRONECAN_MAPPINGS)

    def sample(self, m: Any, seed: int = 0, t: float = 12.5) -> Any:
        from sam_runtime.sim.devices import DeviceState, VehicleState
        from sam_runtime.sim.devices_dronecan import ensure_element, generic_fill_v0, parse_element, physics_v0

        dt = m.data_type
        veh = VehicleState(rng=random.Random(seed))
        now_us = veh.now_us()
        obj = generic_fill_v0(self._dronecan.TYPENAMES[dt.name](), t, now_us, seed=dt.data_type_id)
        physics = physics_v0(dt.name, dt.custom)
        if physics is not None:
            physics(obj, DeviceState("bench", 0), veh, t, 0.01, veh.rng)
        for path, value in m.select:
            _put(obj, path, value)
        elements = [parse_element(e) for e in m.elements]
        claimed = {el.value for el in elements if el.key is not None}
        for el in elements:
            ensure_element(obj, el, claimed, t, now_us)
        return self.decoder(m)(self.encoder(m)(obj))  # as received

    def decoder(self, m: Any) -> Callable[[Any], Any]:
        cls, bits = self._dronecan.TYPENAMES[m.data_type.name], self._transport.bits_from_bytes

        def decode(payload: Any) -> Any:
            msg = cls()
            msg._unpack(bits(bytearray(payload)), True)  # what Transfer.from_frames does on classic CAN
            return msg

        return decode

    def encoder(self, m: Any) -> Callable[[Any], bytes]:
        transfer = self._transport.Transfer

        def encode(obj: Any) -> bytes:
            return bytes(transfer(payload=obj).payload)  # _pack(tao=True), padded to whole bytes

        return encode

    def builtin(self, obj: Any) -> Any:
        from sam_runtime.sim.devices_dronecan import to_builtin_v0

        return None if obj is None else to_builtin_v0(obj)


# ----------------------------------------------------------------------------------------------- one mapping
def _fill_header(msg: Any, frame_id: str | None, receive_ns: int) -> int:
    """What the bridge's object path does after ``<m>_to_ros`` (runtime/bridge/inbound.py): the mapping's frame id
    for an empty one, the receive time for a zero stamp; the stamp in ns, -1 without a header."""
    hdr = getattr(msg, "header", None)
    if hdr is None:
        return -1
    if not hdr.frame_id and frame_id:
        hdr.frame_id = frame_id
    if hdr.stamp.sec == 0 and hdr.stamp.nanosec == 0:
        hdr.stamp.sec, hdr.stamp.nanosec = divmod(receive_ns, 1_000_000_000)
    return hdr.stamp.sec * 1_000_000_000 + hdr.stamp.nanosec


def same_bytes(codec: bytes, reference: bytes) -> bool | str:
    """True when identical; "padding" when they differ only where the codec wrote zeros (CDR alignment padding:
    rclpy's serializer leaves those bytes as its buffer held them); else False.

    >>> same_bytes(b"ab", b"ab"), same_bytes(b"a\\0b", b"a?b"), same_bytes(b"ab", b"ac")
    (True, 'padding', False)
    """
    if codec == reference:
        return True
    if len(codec) == len(reference) and all(x == 0 for x, y in zip(codec, reference, strict=True) if x != y):
        return "padding"
    return False


def _counters(stats: Any) -> dict[str, dict[str, int]]:
    return {"saturated": dict(stats.saturated), "rejected": dict(stats.rejected)}


def pipelines(side: Any, codec: Any, m: Any) -> dict[str, Any]:
    """The two implementations of both directions of mapping ``m`` with their inputs, checked to agree."""
    from rclpy.serialization import deserialize_message, serialize_message

    convert = side.convert
    to_ros, to_uavcan = convert.CONVERTERS[m.name]
    wire_to_ros, ros_to_wire = codec.CODECS[m.name]
    ros_cls = side.gen.ros_class(m.topic)
    decode, encode = side.decoder(m), side.encoder(m)
    src = side.sample(m)
    payload = encode(src)
    so, sc = convert.ConversionStats(), convert.ConversionStats()

    def object_to_ros(payload: Any, receive_ns: int, stats: Any) -> Any:
        msg = to_ros(decode(payload), receive_ns, stats)
        return None if msg is None else serialize_message(msg)

    def object_to_uavcan(cdr: Any, stats: Any) -> Any:
        obj = to_uavcan(deserialize_message(cdr, ros_cls), stats)
        return None if obj is None else encode(obj)

    problems: list[str] = []
    # UAVCAN->ROS
    ros_msg = to_ros(decode(payload), RECEIVE_NS, so)
    stamp_o = _fill_header(ros_msg, m.frame_id, RECEIVE_NS) if ros_msg is not None else None
    out = wire_to_ros(payload, RECEIVE_NS, sc)
    if (ros_msg is None) != (out is None):
        problems.append(f"to_ros: object {'drops' if ros_msg is None else 'converts'}, codec "
                        f"{'drops' if out is None else 'converts'}")
    cdr_identical = None
    if ros_msg is not None and out is not None:
        cdr, stamp_c = out
        cdr_o = serialize_message(ros_msg)  # the object pipeline's output (float32 fields rounded only here)
        if not same(plain(deserialize_message(bytes(cdr), ros_cls)), plain(deserialize_message(cdr_o, ros_cls)), 0.0):
            problems.append("to_ros: the codec's CDR decodes to other values")
        if stamp_c != (stamp_o if stamp_o is not None else -1):
            problems.append(f"to_ros: stamp {stamp_c} != {stamp_o}")
        cdr_identical = same_bytes(bytes(cdr), cdr_o)
    if _counters(so) != _counters(sc):
        problems.append(f"to_ros counters: object {_counters(so)}, codec {_counters(sc)}")
    sample_counters = {"to_ros": _counters(so)}
    matches = getattr(convert, "MATCHES", {}).get(m.name)
    wire_matches = getattr(codec, "WIRE_MATCHES", {}).get(m.name)
    if wire_matches is not None and matches is not None and wire_matches(payload) != matches(decode(payload)):
        problems.append("WIRE_MATCHES and MATCHES disagree")
    # ROS->UAVCAN, from the CDR of the object path's message
    if ros_msg is None:
        ros_msg = ros_cls()
    cdr_in = serialize_message(ros_msg)
    so, sc = convert.ConversionStats(), convert.ConversionStats()
    uav = to_uavcan(deserialize_message(cdr_in, ros_cls), so)
    wire = ros_to_wire(cdr_in, sc)
    payload_identical = None
    if (uav is None) != (wire is None):
        problems.append(f"to_uavcan: object {'drops' if uav is None else 'converts'}, codec "
                        f"{'drops' if wire is None else 'converts'}")
    elif uav is not None:
        decoded, payload_o = decode(wire), encode(uav)
        if decoded is None or not same(side.builtin(decoded), side.builtin(decode(payload_o)), 0.0):
            problems.append("to_uavcan: the codec's payload decodes to other values")
        payload_identical = bytes(wire) == payload_o
    if _counters(so) != _counters(sc):
        problems.append(f"to_uavcan counters: object {_counters(so)}, codec {_counters(sc)}")
    sample_counters["to_uavcan"] = _counters(so)
    stats = convert.ConversionStats()
    return {
        "to_ros": {"codec": (wire_to_ros, (payload, RECEIVE_NS, stats)),
                   "object": (object_to_ros, (payload, RECEIVE_NS, stats))},
        "to_uavcan": {"codec": (ros_to_wire, (cdr_in, stats)), "object": (object_to_uavcan, (cdr_in, stats))},
        "problems": problems, "cdr_identical": cdr_identical, "payload_identical": payload_identical,
        "payload_bytes": len(payload), "cdr_bytes": len(cdr_in), "sample_counters": sample_counters,
    }


def time_pair(impls: dict[str, tuple[Callable[..., Any], tuple[Any, ...]]], rounds: int, batch_s: float
              ) -> dict[str, list[float]]:
    """ns per call of each implementation, one sample per round (interleaved, alternating order)."""
    gc.collect()
    per = {name: _ns_per_call(*impls[name]) for name in IMPLS}
    k = batch_size(per["object"], per["codec"], batch_s)
    samples: dict[str, list[float]] = {name: [] for name in IMPLS}
    for r in range(rounds):
        for name in (IMPLS if r % 2 == 0 else IMPLS[::-1]):
            fn, args = impls[name]
            samples[name].append(_batch_ns(fn, args, k))
    return samples


def run_protocol(side: Any, codec: Any, rounds: int, batch_s: float) -> list[dict[str, Any]]:
    rows: list[dict[str, Any]] = []
    for m in side.mappings:
        if m.name not in codec.CODECS:
            rows.append({"protocol": side.protocol, "mapping": m.name, "missing": True})
            continue
        p = pipelines(side, codec, m)
        if p["problems"]:
            log(f"  codec {side.protocol} {m.name}: DISAGREES with the object pipeline: {'; '.join(p['problems'])}")
        for direction in ("to_ros", "to_uavcan"):
            samples = time_pair(p[direction], rounds, batch_s)
            ns = {n: min(v) for n, v in samples.items()}
            rows.append({
                "protocol": side.protocol, "mapping": m.name, "direction": direction,
                "bridge_runs_it": (direction == "to_ros") == (m.direction == "uavcan_to_ros"),
                "agree": not p["problems"], "problems": p["problems"],
                "bytes_identical": p["cdr_identical"] if direction == "to_ros" else p["payload_identical"],
                "payload_bytes": p["payload_bytes"], "cdr_bytes": p["cdr_bytes"],
                "sample_counters": p["sample_counters"][direction],
                "ns_per_msg": {n: round(v, 1) for n, v in ns.items()},
                "median_ns_per_msg": {n: round(median(v), 1) for n, v in samples.items()},
                "ratio": round(ratio(ns["object"], ns["codec"]), 2),
                "spread_pct": {n: round(100 * (max(v) - min(v)) / median(v), 1) for n, v in samples.items()},
            })
    return rows


def geomean(xs: list[float]) -> float:
    """The geometric mean.

    >>> round(geomean([2.0, 8.0]), 6)
    4.0
    """
    return math.exp(sum(math.log(x) for x in xs) / len(xs)) if xs else math.nan


def summarize(rows: list[dict[str, Any]]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for proto in sorted({r["protocol"] for r in rows}):
        for direction in ("to_ros", "to_uavcan", "all"):
            sel = [r for r in rows if r["protocol"] == proto and not r.get("missing")
                   and direction in ("all", r["direction"])]
            if not sel:
                continue
            out[f"{proto} {direction}"] = {
                "codecs": len(sel), "geomean": round(geomean([r["ratio"] for r in sel]), 2),
                "min": min(r["ratio"] for r in sel), "max": max(r["ratio"] for r in sel),
                "meet_target": sum(r["ratio"] >= TARGET for r in sel), "agree": sum(r["agree"] for r in sel),
                "missing": sum(1 for r in rows if r["protocol"] == proto and r.get("missing")),
            }
    return out


def run(gen: Any, *, rounds: int = 15, batch_s: float = 0.005,
        protocols: tuple[str, ...] = ("cyphal", "dronecan")) -> dict[str, Any]:
    t0 = time.monotonic()
    rows: list[dict[str, Any]] = []
    modules: dict[str, str] = {}
    for proto in protocols:
        codec = gen.codec(proto)
        if codec is None:
            log(f"codec: the generated package has no {proto} codecs (codec{'_v0' if proto == 'dronecan' else ''}"
                ".py): skipped")
            continue
        modules[proto] = getattr(codec, "__file__", None) or type(codec).__name__
        side = CyphalSide(gen) if proto == "cyphal" else DroneCanSide(gen)
        rows += run_protocol(side, codec, rounds, batch_s)
    log(f"codec: {sum(not r.get('missing') for r in rows)} timed in {time.monotonic() - t0:.1f} s")
    return {
        "method": {"rounds": rounds, "batch_s": batch_s, "statistic": "best (minimum) ns/msg over interleaved rounds"},
        "target": TARGET, "modules": modules, "rows": rows, "summary": summarize(rows),
    }


def run_namespaced(gen: Any, *, prefix: str = "sam1/", rounds: int = 15, batch_s: float = 0.005,
                   protocols: tuple[str, ...] = ("cyphal", "dronecan")) -> dict[str, Any]:
    """The namespaced variant (issue 26): a run with a frame prefix (``--namespace /sam1``) stays on the codec path,
    the codec module bound to the prefix at start (sam_runtime.genpkg.bound_codec), against the object pipeline with
    the prefix (the path a namespaced bridge took before: the frame id prefixed after ``<m>_to_ros``, as
    runtime/bridge/inbound.py does) and the unbound codec; the UAVCAN->ROS mappings whose message has a header (where
    the prefix is written). Checked first: the bound codec's CDR decodes to the object pipeline's message."""
    from rclpy.serialization import deserialize_message, serialize_message

    rows: list[dict[str, Any]] = []
    for proto in protocols:
        codec, bound = gen.codec(proto), gen.codec(proto, prefix)
        if codec is None or bound is None:
            log(f"codec (namespaced): the generated package has no {proto} codecs that take a frame prefix: skipped")
            continue
        side = CyphalSide(gen) if proto == "cyphal" else DroneCanSide(gen)
        for m in side.mappings:
            ros_cls = gen.ros_class(m.topic)
            if m.direction != "uavcan_to_ros" or m.name not in bound.CODECS or not hasattr(ros_cls(), "header"):
                continue
            to_ros, decode = side.convert.CONVERTERS[m.name][0], side.decoder(m)

            def object_to_ros(payload: Any, receive_ns: int, stats: Any, to_ros: Any = to_ros,
                              decode: Any = decode) -> Any:
                msg = to_ros(decode(payload), receive_ns, stats)
                if msg is None:
                    return None
                if msg.header.frame_id:
                    msg.header.frame_id = prefix + msg.header.frame_id
                return serialize_message(msg)

            args = (side.encoder(m)(side.sample(m)), RECEIVE_NS, side.convert.ConversionStats())
            ref, out = object_to_ros(*args), bound.CODECS[m.name][0](*args)
            agree = (ref is None) == (out is None) and (ref is None or same(
                plain(deserialize_message(bytes(out[0]), ros_cls)), plain(deserialize_message(ref, ros_cls)), 0.0))
            if not agree:
                log(f"  codec {proto} {m.name} with prefix {prefix!r}: DISAGREES with the object pipeline")
            vs_object = time_pair({"codec": (bound.CODECS[m.name][0], args), "object": (object_to_ros, args)},
                                  rounds, batch_s)
            vs_unbound = time_pair({"codec": (bound.CODECS[m.name][0], args),
                                    "object": (codec.CODECS[m.name][0], args)}, rounds, batch_s)
            # each ratio from its own interleaved pair (the same number of rounds on both sides)
            ns = {"codec": min(vs_unbound["codec"]), "object": min(vs_object["object"]),
                  "codec_no_prefix": min(vs_unbound["object"])}
            rows.append({"protocol": proto, "mapping": m.name, "agree": agree,
                         "ns_per_msg": {k: round(v, 1) for k, v in ns.items()},
                         "per_s": {k: round(1e9 / v) for k, v in ns.items()},
                         "ratio": round(ratio(min(vs_object["object"]), min(vs_object["codec"])), 2),
                         "vs_no_prefix": round(ratio(ns["codec_no_prefix"], ns["codec"]), 3)})
    summary = {}
    for proto in sorted({r["protocol"] for r in rows}):
        sel = [r for r in rows if r["protocol"] == proto]
        summary[proto] = {"mappings": len(sel), "agree": sum(r["agree"] for r in sel),
                          "geomean": round(geomean([r["ratio"] for r in sel]), 2), "min": min(r["ratio"] for r in sel),
                          "vs_no_prefix": round(geomean([r["vs_no_prefix"] for r in sel]), 3),
                          "per_s": {k: round(geomean([r["per_s"][k] for r in sel]))
                                    for k in ("codec", "object", "codec_no_prefix")}}
    return {"prefix": prefix, "rows": rows, "summary": summary}


if __name__ == "__main__":
    import json
    import sys

    import bench.common  # noqa: F401  (loopback discovery before rclpy)
    from bench.common import generated_package

    res = run(generated_package(), rounds=5 if "quick" in sys.argv[1:] else 15)
    for r in res["rows"]:
        if r.get("missing"):
            print(f"{r['protocol']:8s} {r['mapping']:30s} no codec")
            continue
        print(f"{r['protocol']:8s} {r['mapping']:30s} {r['direction']:9s} codec {r['ns_per_msg']['codec']:>9,.0f} ns"
              f"  object {r['ns_per_msg']['object']:>9,.0f} ns  x{r['ratio']:.2f}  agree {r['agree']}"
              f"  bytes identical {r['bytes_identical']}")
    print(json.dumps(res["summary"], indent=1))
    print(json.dumps(run_namespaced(generated_package(), rounds=5 if "quick" in sys.argv[1:] else 15)["summary"],
                     indent=1))
