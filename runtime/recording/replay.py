"""Replay: the raw bus of a recording through a spec's bridge conversion, without a simulator or a bus, into a new
MCAP, with a per-topic difference report against the ROS topics the recording holds.

The conversion is given (:class:`Converter`, e.g. ``sam_runtime.bridge.offline.OfflineBridge``, one per protocol):
this module reads, paces, writes and compares, and knows nothing of the bridge.

Invariants:

- Transfers are fed in the recording's file order (the order the listener received them), each with its recorded
  receive time as the bridge's receive time; ``speed="recorded"`` paces them by their log times, ``"max"`` not.
- The new file has every topic the converters publish, as the recording's ROS channels are written (ros2msg
  schemas, CDR as a subscriber receives it: padded to a multiple of 4 bytes, log_time = publish_time = the
  transfer's receive time), plus the recording's raw bus channels, its
  attachments and metadata, so it is itself a recording.
- The report matches the recorded and the replayed messages of each topic in order, from the replayed message
  that corresponds to the first recorded one (the bus side of a recording starts earlier and ends later than its
  ROS side: the replayed messages outside it are counted apart, ``outside``); after a pair that differs, a gap of
  up to :data:`_RESYNC_WINDOW` messages on either side is skipped when the pairs after it agree again.
  ``identical``: the same CDR bytes; ``receive_time``: they differ only in fields that depend on the receive time
  (those that change when the same transfer is converted at a later receive time: the bridge stamps a message
  whose device stamp is 0 with its own receive time, which the listener's cannot equal); ``differing``: other
  fields differ (named, each with its count and the first differing recorded and replayed values);
  ``missing``: recorded, not replayed; ``extra``: replayed, not recorded.
- Commands, the other direction (issue 30): a converter that offers ``command`` (the offline bridge) turns each
  recorded ROS command into the payloads the bridge sends, compared per port with the transfers the recording holds
  from the bridge's node id, matched in order as the topics are (the offset where most payloads agree, the one
  nearest the first transfer after the first recorded command on a tie: a controller repeats one command), gaps
  skipped and counted the same way. ``recorded`` counts the bridge's transfers, ``replayed`` the converted
  commands, ``missing`` a transfer no recorded command gives, ``extra`` a command whose payload the bus did not
  carry, ``outside`` the transfers before the first recorded command, the commands before the first one the
  bridge sent (its subscription may match a publisher after the recorder's does) and those after its last
  transfer (the bus side of a recording starts before its ROS side; the bridge may stop before the recorder); the
  values shown are the recorded transfer's payload and the replayed one (hex). Only a differing payload makes the
  commands differ: a gap is what a live run has (a transfer the listener lost under load, or a command coalesced
  or expired by ``max_rate_hz`` / ``deadline``, which are not applied offline, shows as ``extra``; a transfer
  whose command the recorder lacks as ``missing``), counted and shown.
"""

from __future__ import annotations

import bisect
import time
from collections import Counter
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol

from sam_runtime.recording.reading import Recording, read_recording
from sam_runtime.recording.schemas import KIND_MESSAGE, ROS_LOST_METADATA, TRANSFER_TYPE, qos_yaml
from sam_runtime.recording.writer import RecordingWriter

__all__ = ["Converter", "ReplayReport", "TopicDiff", "field_differences", "replay"]

SPEEDS = ("recorded", "max")
_MAX_EXAMPLES = 5


class Converter(Protocol):
    """One protocol's UAVCAN -> ROS conversion (what ``sam_runtime.bridge.offline.OfflineBridge`` offers)."""

    protocol: str

    @property
    def topics(self) -> dict[str, str]: ...

    def feed(self, port_id: int, payload: bytes, source_node_id: int | None, transfer_id: int, monotonic_s: float,
             receive_ns: int) -> Sequence[Any]:
        """The publications (``.topic``, ``.ros_type``, ``.cdr``, ``.cdr_later``) for one transfer."""
        ...

    def stats(self) -> dict[str, Any]: ...


@dataclass
class TopicDiff:
    topic: str
    recorded: int = 0
    replayed: int = 0
    identical: int = 0
    receive_time: int = 0
    differing: int = 0
    missing: int = 0
    extra: int = 0
    before: int = 0  # replayed from transfers before the ROS side of the recording began (not compared)
    after: int = 0  # ... after it ended
    fields: Counter[str] = field(default_factory=Counter)  # field path -> messages where it differs
    # field path -> (index, recorded value, replayed value) of the first message where it differs (short reprs)
    first_values: dict[str, tuple[int, str, str]] = field(default_factory=dict)
    receive_time_fields: Counter[str] = field(default_factory=Counter)
    examples: list[dict[str, Any]] = field(default_factory=list)
    # commands: a gap is what a live run has (a transfer the listener lost under load, a command rate-limited),
    # counted and shown, but only a differing payload makes the replay differ
    gaps_allowed: bool = False
    # messages of the topic the recorder knows it never got (the recording's ROS_LOST_METADATA): that many extra
    # replayed messages are the recording's loss, shown but no difference
    lost_by_recorder: int = 0

    @property
    def same(self) -> bool:
        """Nothing but receive-time fields differs, and nothing is missing or extra (unless gaps are allowed), beyond
        what the recorder lost."""
        return not (self.differing or (not self.gaps_allowed and (self.missing or self.extra > self.lost_by_recorder)))

    def as_dict(self) -> dict[str, Any]:
        return {"recorded": self.recorded, "replayed": self.replayed, "identical": self.identical,
                "receive_time_only": self.receive_time, "differing": self.differing, "missing": self.missing,
                "extra": self.extra, "lost_by_recorder": self.lost_by_recorder,
                "outside_ros_recording": self.before + self.after,
                "differing_fields": dict(self.fields),
                "first_differing_values": {k: {"index": i, "recorded": old, "replayed": new}
                                           for k, (i, old, new) in sorted(self.first_values.items())},
                "receive_time_fields": dict(self.receive_time_fields), "examples": self.examples}


@dataclass
class ReplayReport:
    input: str
    output: str | None
    transfers: int
    recorded_span_s: float
    replay_s: float
    topics: dict[str, TopicDiff]
    bridge: dict[str, Any]
    # "<protocol> <port id> (<mappings>)" -> the bridge's recorded transfers against the replayed commands
    commands: dict[str, TopicDiff] = field(default_factory=dict)

    @property
    def same(self) -> bool:
        return all(d.same for d in (*self.topics.values(), *self.commands.values()))

    def as_dict(self) -> dict[str, Any]:
        return {"input": self.input, "output": self.output, "transfers": self.transfers,
                "recorded_span_s": round(self.recorded_span_s, 3), "replay_s": round(self.replay_s, 3),
                "same": self.same, "topics": {t: d.as_dict() for t, d in sorted(self.topics.items())},
                "commands": {p: d.as_dict() for p, d in sorted(self.commands.items())}, "bridge": self.bridge}

    def lines(self) -> list[str]:
        out = [f"replayed {self.transfers} transfers ({self.recorded_span_s:.1f} s recorded) in {self.replay_s:.2f} s"
               + (f" -> {self.output}" if self.output else ""),
               f"{'TOPIC':32} {'RECORDED':>8} {'REPLAYED':>8} {'SAME':>6} {'RX-TIME':>7} {'DIFFER':>6} "
               f"{'MISSING':>7} {'EXTRA':>5} {'OUTSIDE':>7}  FIELDS"]
        rows = sorted(self.topics.items())
        if self.commands:
            rows += [(f"-> {p}", d) for p, d in sorted(self.commands.items())]
        for t, d in rows:
            fields = ", ".join(f"{k} ({n})" for k, n in d.fields.most_common(6))
            out.append(f"{t:32} {d.recorded:8d} {d.replayed:8d} {d.identical:6d} {d.receive_time:7d} "
                       f"{d.differing:6d} {d.missing:7d} {d.extra:5d} {d.before + d.after:7d}  {fields}")
        for t, d in rows:  # what differs, by example: the first differing values of each field
            for k, n in d.fields.most_common(6):
                if k in d.first_values:
                    i, old, new = d.first_values[k]
                    out.append(f"  {t} {k}: {n} differ; first at message {i}: recorded {old}, replayed {new}")
        rt = sorted({k for d in self.topics.values() for k in d.receive_time_fields})
        if rt:
            out.append(f"receive-time fields (differ only because the recorder's receive time is not the bridge's): "
                       f"{', '.join(rt)}")
        lost = [f"{t} {d.lost_by_recorder}" for t, d in sorted(self.topics.items()) if d.lost_by_recorder]
        if lost:
            out.append(f"lost by the recorder (gaps in the publisher's sequence numbers; as many EXTRA are no "
                       f"difference): {', '.join(lost)}")
        for proto, st in sorted(self.bridge.items()):  # the offline bridge's own counters, as the live one reports
            maps = st.get("mappings", {}).values()
            drops: Counter[str] = Counter()
            for m in maps:
                drops.update(m.get("dropped", {}))
            saturated = sum(m.get("saturated_total", 0) for m in maps)
            out.append(f"bridge ({proto}): {sum(m.get('published', 0) for m in maps)} published, "
                       + (", ".join(f"{k} {n}" for k, n in sorted(drops.items())) or "nothing dropped")
                       + (f", {saturated} values saturated" if saturated else "")
                       + "".join(f"; port {p} refused below the bridge: {b}"
                                 for p, b in sorted(st.get("below_bridge", {}).items())))
        out.append("same as recorded" if self.same else "DIFFERENT from the recording")
        return out


# ============================================================================================ field comparison
def _flatten(obj: Any, prefix: str, out: dict[str, Any]) -> None:
    if hasattr(obj, "__slots__") or (hasattr(obj, "__dict__") and not isinstance(obj, type)):
        names = getattr(obj, "__slots__", None) or list(vars(obj))
        for n in names:
            if not n.startswith("_"):
                _flatten(getattr(obj, n), f"{prefix}.{n}" if prefix else n, out)
    elif isinstance(obj, list | tuple):
        if all(isinstance(x, int | float | bool | str) for x in obj):
            out[prefix] = list(obj)
        else:
            out[f"{prefix}.length"] = len(obj)
            for i, x in enumerate(obj):
                _flatten(x, f"{prefix}[{i}]", out)
    elif isinstance(obj, bytes | bytearray | memoryview):
        out[prefix] = bytes(obj)
    else:
        out[prefix] = obj


def _same_value(a: Any, b: Any) -> bool:
    if isinstance(a, float) and isinstance(b, float) and a != a and b != b:  # NaN == NaN here
        return True
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(_same_value(x, y) for x, y in zip(a, b, strict=True))
    return bool(a == b)


def field_differences(decode_a: Any, a: bytes, decode_b: Any, b: bytes) -> list[str]:
    """The field paths whose values differ between two CDR messages (decoded by ``decode_a`` / ``decode_b``);
    ``["<undecodable>"]`` when either does not decode."""
    try:
        fa: dict[str, Any] = {}
        fb: dict[str, Any] = {}
        _flatten(decode_a(a), "", fa)
        _flatten(decode_b(b), "", fb)
    except Exception:
        return ["<undecodable>"]
    return sorted(k for k in fa.keys() | fb.keys() if k not in fa or k not in fb or not _same_value(fa[k], fb[k]))


class _Decoders:
    """CDR decoders per schema, built from the schema text (mcap-ros2-support), cached."""

    def __init__(self) -> None:
        from mcap_ros2.decoder import DecoderFactory

        self._factory = DecoderFactory()
        self._cache: dict[tuple[str, bytes], Any] = {}

    def get(self, schema: Any) -> Any:
        key = (schema.name, bytes(schema.data))
        if key not in self._cache:
            self._cache[key] = self._factory.decoder_for("cdr", schema)
        return self._cache[key]


# ============================================================================================ replay
_ALIGN_WINDOW = 40  # replayed messages before the time-based guess that may be the first recorded one
_ALIGN_PROBE = 30  # pairs compared to score an alignment
_RESYNC_WINDOW = 8  # messages one side may lack before the sequences are matched again
_RESYNC_CONFIRM = 3  # pairs that must agree after such a gap


@dataclass(frozen=True)
class _Out:
    cdr: bytes
    cdr_later: bytes
    log_time: int  # the transfer's receive time


class _Matcher:
    """Classifies a (recorded, replayed) pair: "identical", "receive_time" or the differing fields."""

    def __init__(self, schema_rec: Any, schema_new: Any, decoders: _Decoders) -> None:
        self.dec_rec = decoders.get(schema_rec) if schema_rec is not None else None
        self.dec_new = decoders.get(schema_new) if schema_new is not None else self.dec_rec

    @staticmethod
    def fields(decode: Any, data: bytes) -> dict[str, Any]:
        """The message's leaf fields by path ({} when it does not decode)."""
        out: dict[str, Any] = {}
        if decode is not None:
            try:
                _flatten(decode(data), "", out)
            except Exception:
                return {}
        return out

    def values(self, old: bytes, out: _Out) -> dict[str, tuple[Any, Any]]:
        """field path -> (recorded value, replayed value) of the pair (``<missing>`` for a field one side lacks)."""
        fa, fb = self.fields(self.dec_rec, old), self.fields(self.dec_new, out.cdr)
        return {k: (fa.get(k, "<missing>"), fb.get(k, "<missing>")) for k in fa.keys() | fb.keys()}

    def classify(self, old: bytes, out: _Out) -> tuple[str, list[str], set[str]]:
        # the trailing alignment padding is no content: a recorder may receive a payload padded or not (seen both
        # ways; a namespaced run's frame prefix changes the lengths)
        if old == out.cdr or _as_delivered(old) == out.cdr:
            return "identical", [], set()
        if self.dec_rec is None:
            return "differing", ["<no schema>"], set()
        diff = field_differences(self.dec_rec, old, self.dec_new, out.cdr)
        rt = set(field_differences(self.dec_new, out.cdr, self.dec_new, out.cdr_later)) if out.cdr_later != out.cdr \
            else set()
        if diff and set(diff) <= rt:
            return "receive_time", diff, rt
        return "differing", [f for f in diff if f not in rt], rt


def _short(value: Any) -> str:
    """A value for the report, at most 60 characters."""
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _align(recorded: Sequence[Any], replayed: Sequence[_Out], matcher: _Matcher, follows: bool = False
           ) -> tuple[int, int]:
    """(i, j): the recorded message i and the replayed message j that correspond, where the comparison begins.

    The ROS side of a recording starts when the recorder's subscriptions have matched the bridge's publishers, its
    bus side before: the bus holds transfers whose publications the recording does not. The bridge publishes a
    transfer after the listener received it, so a recorded message comes from one of the last transfers received
    before it (by the listener's clock, which may lag the bridge's by some milliseconds): of the offsets within
    :data:`_ALIGN_WINDOW` of that guess (:func:`_guess`), the one after which most pairs are the same (identical or
    receive-time only) wins, the nearest on a tie; when none is (a changed conversion), the one whose pairs have the
    most equal fields. A negative offset means the first recorded messages have no transfer (a recording whose bus
    side began later)."""
    if not recorded or not replayed:
        return 0, 0
    guess = _guess(recorded, replayed, follows)
    best, best_score = guess, 0
    for off in sorted(range(guess - _ALIGN_WINDOW, guess + _ALIGN_WINDOW + 1), key=lambda o: abs(o - guess)):
        i0, j0 = max(0, -off), max(0, off)
        if j0 >= len(replayed) or i0 >= len(recorded):
            continue
        score = sum(1 for old, out in zip(recorded[i0:i0 + _ALIGN_PROBE], replayed[j0:j0 + _ALIGN_PROBE],
                                          strict=False) if matcher.classify(old.data, out)[0] != "differing")
        if score > best_score:
            best, best_score = off, score
    if best_score == 0:  # no pair is the same anywhere (a changed conversion): the offset where most fields agree
        best = _align_by_fields(recorded, replayed, matcher, guess)
    return max(0, -best), max(0, best)


_GUESS_SPAN = 100  # recorded messages whose receive times estimate the offset


def _guess(recorded: Sequence[Any], replayed: Sequence[_Out], follows: bool) -> int:
    """The offset (replayed index - recorded index) the receive times say: for each of the first
    :data:`_GUESS_SPAN` recorded messages, the replayed messages received before it (``follows``: the replayed side
    comes after the recorded one, a command's transfer after the command: those received before it) less its index;
    the least of them. A recorded message's log time is when the recorder's callback ran, which a loaded machine
    delays by up to seconds at the start (its first messages then arrive in one burst, each one's guess too high
    by the messages received meanwhile: a run guessed 42 past the offset, beyond the window); a delay only ever
    raises a guess, so the least is the one the delay spared."""
    times = sorted(o.log_time for o in replayed)
    if follows:
        return min(bisect.bisect_left(times, m.log_time) - i for i, m in enumerate(recorded[:_GUESS_SPAN]))
    return min(bisect.bisect_right(times, m.log_time) - 1 - i for i, m in enumerate(recorded[:_GUESS_SPAN]))


def _align_by_fields(recorded: Sequence[Any], replayed: Sequence[_Out], matcher: _Matcher, guess: int) -> int:
    """The offset (replayed index - recorded index) within :data:`_ALIGN_WINDOW` of ``guess`` whose pairs have the
    most equal fields (a changed mapping changes some fields, the others still tell the messages apart)."""
    fields_rec = [matcher.fields(matcher.dec_rec, m.data) for m in recorded[:_ALIGN_PROBE]]
    lo, hi = max(0, guess - _ALIGN_WINDOW), min(len(replayed), guess + _ALIGN_WINDOW + _ALIGN_PROBE)
    fields_new = {j: matcher.fields(matcher.dec_new, replayed[j].cdr) for j in range(lo, hi)}
    best, best_score = guess, -1
    for off in sorted(range(guess - _ALIGN_WINDOW, guess + _ALIGN_WINDOW + 1), key=lambda o: abs(o - guess)):
        score = 0
        for i, a in enumerate(fields_rec):
            b = fields_new.get(i + off)
            if b is not None and i + off >= 0:
                score += sum(1 for k, v in a.items() if k in b and _same_value(v, b[k]))
        if score > best_score:
            best, best_score = off, score
    return best


def _diff_topic(topic: str, recorded: Sequence[Any], replayed: Sequence[_Out], matcher: _Matcher,
                follows: bool = False, start: tuple[int, int] | None = None) -> TopicDiff:
    d = TopicDiff(topic, len(recorded), len(replayed))
    i0, k = start if start is not None else _align(recorded, replayed, matcher, follows)
    d.before = k
    d.missing = i0  # recorded before the bus side began: no transfer to replay
    # after the ROS side stopped recording (a command's transfer follows it: by up to _COMMAND_LATE_NS)
    last = (recorded[-1].log_time if recorded else 0) + (_COMMAND_LATE_NS if follows else 0)
    window = list(replayed[k:])
    while len(window) > len(recorded) and window[-1].log_time > last:  # after the ROS side stopped recording
        window.pop()
        d.after += 1
    cache: dict[tuple[int, int], tuple[str, list[str], set[str]]] = {}

    def classify(i: int, j: int) -> tuple[str, list[str], set[str]]:
        if (i, j) not in cache:
            cache[(i, j)] = matcher.classify(recorded[i].data, window[j])
        return cache[(i, j)]

    def agrees(i: int, j: int) -> bool:
        """Pairs from (i, j) on are the same for :data:`_RESYNC_CONFIRM` steps (or to the end)."""
        n = min(_RESYNC_CONFIRM, len(recorded) - i, len(window) - j)
        return n > 0 and all(classify(i + s, j + s)[0] != "differing" for s in range(n))

    i, j = i0, 0
    while i < len(recorded) and j < len(window):
        kind, fields, _ = classify(i, j)
        if kind == "differing":
            # a transfer the listener lost (recorded, not replayed) or the bridge never published (replayed, not
            # recorded): skip it when the pairs after the gap agree again; else the pair differs
            skip = next(((0, g) for g in range(1, _RESYNC_WINDOW + 1) if agrees(i, j + g)), None) or \
                next(((g, 0) for g in range(1, _RESYNC_WINDOW + 1) if agrees(i + g, j)), None)
            if skip is not None:
                d.missing += skip[0]
                d.extra += skip[1]
                i, j = i + skip[0], j + skip[1]
                continue
        if kind == "identical":
            d.identical += 1
        elif kind == "receive_time":
            d.receive_time += 1
            d.receive_time_fields.update(fields)
        else:
            d.differing += 1
            d.fields.update(fields)
            if any(f not in d.first_values for f in fields):
                values = matcher.values(recorded[i].data, window[j])
                for f in fields:
                    if f not in d.first_values and f in values:
                        old, new = values[f]
                        d.first_values[f] = (i, _short(old), _short(new))
            if len(d.examples) < _MAX_EXAMPLES:
                d.examples.append({"index": i, "fields": fields})
        i, j = i + 1, j + 1
    d.missing += len(recorded) - i
    d.extra += len(window) - j
    return d


def _as_delivered(cdr: bytes) -> bytes:
    """The CDR as a ROS subscriber (the recorder) receives it: Fast DDS pads every serialized payload with zeros to
    a multiple of 4 bytes (the encapsulation options left 0), so the live bridge's publication of the codec's bytes
    arrives padded.

    >>> _as_delivered(bytes([0, 1, 0, 0, 7])).hex()
    '0001000007000000'
    """
    return cdr + bytes(-len(cdr) % 4)


def replay(path: Path, converters: Iterable[Converter], *, out: Path | None = None, speed: str = "max",
           recording: Recording | None = None) -> ReplayReport:
    """Replay ``path`` through ``converters`` (one per protocol); write ``out`` when given; the report."""
    if speed not in SPEEDS:
        raise ValueError(f"speed {speed!r}: expected one of {', '.join(SPEEDS)}")
    rec = recording if recording is not None else read_recording(path)
    by_protocol = {c.protocol: c for c in converters}
    topics: dict[str, str] = {}
    for c in by_protocol.values():
        topics.update(c.topics)
    writer = RecordingWriter(out) if out is not None else None
    schema_new: dict[str, Any] = {}
    if writer is not None:
        for topic, ros_type in topics.items():
            old = rec.schema_of(topic)
            if old is None or old.name != ros_type:
                continue  # a type the recording does not define: written by the caller's tools, not here
            writer.add_channel(topic, ros_type, "ros2msg", old.data,
                               metadata={"offered_qos_profiles": qos_yaml("reliable", "volatile", 1000)})
        for ch in rec.channels.values():
            s = rec.schemas.get(ch.schema_id)
            if s is not None and s.name == TRANSFER_TYPE:
                writer.add_channel(ch.topic, s.name, s.encoding, s.data, ch.message_encoding, dict(ch.metadata))
        for name, data in rec.attachments.items():
            writer.add_attachment(name, data)
        for name, meta in rec.metadata.items():
            writer.add_metadata(name, {**meta, "replayed_from": str(path)})
    for topic, ros_type in topics.items():
        old = rec.schema_of(topic)
        schema_new[topic] = old if old is not None and old.name == ros_type else None
    replayed: dict[str, list[_Out]] = {t: [] for t in topics}
    transfers = rec.transfers()
    t0_wall = time.monotonic()
    first_log = transfers[0][0].log_time if transfers else 0
    for msg, tr in transfers:
        if writer is not None:  # the bus goes into the new file too: it is a recording in its turn
            writer.write(msg.topic, msg.data, msg.log_time, msg.publish_time)
        conv = by_protocol.get(tr.protocol)
        if conv is None or tr.kind != KIND_MESSAGE:
            continue
        if speed == "recorded":
            wait = (msg.log_time - first_log) * 1e-9 - (time.monotonic() - t0_wall)
            if wait > 0:
                time.sleep(wait)
        for pub in conv.feed(tr.port_id, tr.payload, tr.source_node_id, tr.transfer_id, tr.timestamp_ns * 1e-9,
                             tr.timestamp_ns):
            cdr = _as_delivered(pub.cdr)
            replayed.setdefault(pub.topic, []).append(_Out(cdr, _as_delivered(pub.cdr_later), msg.log_time))
            if writer is not None:
                writer.write(pub.topic, cdr, msg.log_time, msg.log_time)
    last_log = transfers[-1][0].log_time if transfers else 0
    for conv in by_protocol.values():  # what a converter still holds (a rate-limited mapping's last message)
        finish = getattr(conv, "finish", None)
        for pub in finish() if finish is not None else ():
            cdr = _as_delivered(pub.cdr)
            replayed.setdefault(pub.topic, []).append(_Out(cdr, _as_delivered(pub.cdr_later), last_log))
            if writer is not None:
                writer.write(pub.topic, cdr, last_log, last_log)
    elapsed = time.monotonic() - t0_wall
    if writer is not None:
        writer.close()
    recorded = rec.by_topic()
    decoders = _Decoders()
    diffs = {t: _diff_topic(t, recorded.get(t, []), replayed.get(t, []),
                            _Matcher(rec.schema_of(t), schema_new.get(t) or rec.schema_of(t), decoders))
             for t in topics}
    for t, n in rec.metadata.get(ROS_LOST_METADATA, {}).items():
        if t in diffs and n.isdigit():
            diffs[t].lost_by_recorder = int(n)
    commands = _compare_commands(by_protocol.values(), recorded, transfers)
    span = (transfers[-1][0].log_time - first_log) * 1e-9 if transfers else 0.0
    return ReplayReport(str(path), None if out is None else str(out), len(transfers), span, elapsed, diffs,
                        {c.protocol: c.stats() for c in by_protocol.values()}, commands)


class _PayloadMatcher(_Matcher):
    """The command direction: payloads compared as bytes (the field ``payload``; the values in hex). Called with the
    commands as the recorded side and the transfers as the replayed one (see :func:`_diff_commands`)."""

    def __init__(self) -> None:
        self.dec_rec = self.dec_new = None

    def classify(self, old: bytes, out: _Out) -> tuple[str, list[str], set[str]]:
        return ("identical", [], set()) if old == out.cdr else ("differing", ["payload"], set())

    def values(self, old: bytes, out: _Out) -> dict[str, tuple[Any, Any]]:
        return {"payload": (out.cdr.hex(), old.hex())}  # (the recorded transfer, the replayed payload)


def _align_commands(sent: Sequence[_Sent], bus: Sequence[_Out]) -> tuple[int, int]:
    """(i, j): the first command and the transfer that carried it. A controller repeats one command, so many offsets
    give equal payloads: of those within :data:`_ALIGN_WINDOW` of the receive times' guess (:func:`_guess`), the
    one with the most equal payloads wins, on a tie the one with the most transfers not before their commands
    (by more than :data:`_COMMAND_EARLY_NS`), then the one whose transfers are nearest their commands (the median
    delay). The times only break ties: the recorder's callbacks run late on a loaded machine, which puts a
    command's log time after its transfer's by up to seconds at the start (a run had every varying payload of two
    ports differ when such offsets were excluded)."""
    if not sent or not bus:
        return 0, 0
    guess = _guess(sent, bus, follows=True)
    best, best_key = (0, max(0, guess)), (-1, -1, 0.0)
    for off in range(guess - _ALIGN_WINDOW, guess + _ALIGN_WINDOW + 1):
        i0, j0 = max(0, -off), max(0, off)
        pairs = list(zip(sent[i0:i0 + _ALIGN_PROBE], bus[j0:j0 + _ALIGN_PROBE], strict=False))
        if not pairs:
            continue
        delays = sorted(b.log_time - c.log_time for c, b in pairs)
        key = (sum(1 for c, b in pairs if c.data == b.cdr), sum(1 for x in delays if x >= -_COMMAND_EARLY_NS),
               -abs(float(delays[len(delays) // 2])))
        if key > best_key:
            best, best_key = (i0, j0), key
    return best


_COMMAND_EARLY_NS = 50_000_000  # the listener's stamp may precede the recorder's of the same command this much
_COMMAND_LATE_NS = 1_000_000_000  # and follow it by at most this much (the bridge's queue on a loaded machine)


def _diff_commands(key: str, bus: Sequence[_Out], sent: Sequence[_Sent]) -> TopicDiff:
    """The bridge's recorded transfers on one port against the replayed commands (the module docstring): matched
    as the topics are, the commands standing where the transfers stand for them (a command's transfer follows it);
    the commands the recorder got after the bus's last transfer from the bridge (it had stopped) are outside."""
    last = bus[-1].log_time if bus else 0
    inside = [c for c in sent if c.log_time <= last]
    matcher = _PayloadMatcher()
    # the commands before the first one the bridge sent: its subscription matched the publisher after the
    # recorder's did (discovery), so it never had them
    first, k = _align_commands(inside, bus)
    d = _diff_topic(key, inside[first:], bus, matcher, follows=True, start=(0, k))
    # the roles back: recorded = the bridge's transfers, replayed = the commands
    d.recorded, d.replayed = len(bus), len(sent)
    d.missing, d.extra = d.extra, d.missing
    d.after += len(sent) - len(inside) + first
    d.gaps_allowed = True
    return d


@dataclass(frozen=True)
class _Sent:
    """A replayed command payload, where a recorded message stands in _diff_topic (``data``, ``log_time``)."""

    data: bytes
    log_time: int  # the recorded ROS command's receive time


def _compare_commands(converters: Iterable[Any], recorded: dict[str, list[Any]], transfers: Sequence[Any]
                      ) -> dict[str, TopicDiff]:
    """Per command port of each converter that converts commands: the recorded ROS commands, converted, against
    the transfers the recording holds from the bridge's node id on that port (the module docstring)."""
    out: dict[str, TopicDiff] = {}
    for conv in converters:
        command = getattr(conv, "command", None)
        if command is None:
            continue
        ports: dict[int, str] = conv.command_ports
        sent: dict[int, list[_Sent]] = {p: [] for p in ports}
        ros = sorted((m for t in conv.command_topics for m in recorded.get(t, [])), key=lambda m: m.log_time)
        for m in ros:
            for c in command(m.topic, m.data):
                sent.setdefault(c.port_id, []).append(_Sent(c.payload, m.log_time))
        bus: dict[int, list[_Out]] = {p: [] for p in ports}
        for msg, tr in transfers:
            if (tr.protocol == conv.protocol and tr.kind == KIND_MESSAGE and tr.port_id in bus
                    and tr.source_node_id == conv.node_id):
                bus[tr.port_id].append(_Out(tr.payload, tr.payload, msg.log_time))
        for port, label in sorted(ports.items()):
            if not sent[port] and not bus[port]:
                continue  # a command nobody gave in this recording
            key = f"{conv.protocol} {port} ({label})"
            out[key] = _diff_commands(key, bus[port], sent[port])
    return out
