"""The bridge's stats snapshot as diagnostic_msgs/DiagnosticArray: one status for the bridge (ERROR while its link
is down), one per mapping (received, published, dropped and dropped.<reason>, saturated and saturated.<field>,
rejected.<field>, out_of_order, the protocol stack's counters, the traffic control (enabled, enable_service,
max_rate_hz, deadline_s); WARN while it dropped within the last 10 s, or while
it gets nothing from a device whose heartbeat is alive for longer than its grace: sam_runtime.bridge.liveness), one per
device (OK while its heartbeat is alive and its health means OK, WARN or ERROR as its health says, ERROR when the
heartbeat is lost, STALE when never seen), and one for the bus's time (:func:`time_sync_status`)."""

from __future__ import annotations

import struct
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

__all__ = ["RECENT_DROP_WINDOW_S", "Naming", "Status", "diagnostic_array", "diagnostic_array_cdr", "statuses",
           "statuses_cdr", "time_sync_fields", "time_sync_status", "traffic_values"]

RECENT_DROP_WINDOW_S = 10.0  # a mapping's diagnostics level is WARN while it dropped within this window
_PROBLEMS = ("errors", "deserialization_failures", "overruns", "drops")


@dataclass(frozen=True)
class Naming:
    """How the statuses are named: ``bridge`` (the bridge's status name), ``protocol`` (the key of the stack's
    counters: ``cyphal``), ``label`` (``Cyphal``), ``stack`` (``pycyphal``)."""

    bridge: str
    protocol: str
    label: str
    stack: str


def _port(m: Mapping[str, Any]) -> dict[str, Any]:
    """A mapping's port: its Cyphal subject id, or its DroneCAN data type id."""
    return {k: m[k] for k in ("subject_id", "data_type_id") if k in m}


def traffic_values(m: Mapping[str, Any]) -> dict[str, Any]:
    """A mapping's traffic control as diagnostic values: ``enabled``, ``enable_service``, and ``max_rate_hz`` /
    ``deadline_s`` when it has them (its drops are under ``dropped.rate_limited``, ``.coalesced``, ``.expired``,
    ``.disabled``)."""
    out: dict[str, Any] = {"enabled": m.get("enabled", True), "enable_service": m.get("enable_service", "")}
    for key in ("max_rate_hz", "deadline_s"):
        if m.get(key) is not None:
            out[key] = m[key]
    return out


# One status before it becomes a message: (level 0-3, name, message, hardware_id, values).
Status = tuple[int, str, str, str, dict[str, Any]]


def diagnostic_array(snap: Mapping[str, Any], naming: Naming, stamp: Any) -> Any:
    """The snapshot as a diagnostic_msgs/DiagnosticArray (``stamp``: a builtin_interfaces/Time, or None)."""
    from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue

    arr = DiagnosticArray()
    if stamp is not None:
        arr.header.stamp = stamp
    arr.status = [DiagnosticStatus(level=bytes([level]), name=name, message=msg, hardware_id=hw,
                                   values=[KeyValue(key=str(k), value=str(v)) for k, v in values.items()])
                  for level, name, msg, hw, values in statuses(snap, naming)]
    return arr


def diagnostic_array_cdr(snap: Mapping[str, Any], naming: Naming, stamp_ns: int) -> bytes:
    """The same message as :func:`diagnostic_array` (stamped ``stamp_ns``), serialized (CDR, little endian) for a
    raw publish: the bridge publishes /diagnostics once a second with several hundred strings, and building them as
    rclpy message objects (each KeyValue's checked constructor, then rclpy's conversion to C) was most of its idle
    CPU. rclpy's serialize_message gives the same bytes but the alignment padding (zero here), which deserialize to
    the same message (tests/runtime/bridge/test_diagnostics_cdr.py). Most strings repeat from one message to the
    next (names, keys, small values): their encoding is kept (:data:`_ENCODED`)."""
    return statuses_cdr(statuses(snap, naming), stamp_ns)


def statuses_cdr(sts: list[Status], stamp_ns: int) -> bytes:
    """A DiagnosticArray of these statuses (stamped ``stamp_ns``), serialized as :func:`diagnostic_array_cdr`
    serializes the bridge's (the service mappings publish theirs so too)."""
    sec, nanosec = divmod(int(stamp_ns), 1_000_000_000)
    out = bytearray(_CDR_LE)
    out += _U32.pack(sec & 0xFFFFFFFF) + _U32.pack(nanosec) + _EMPTY_STRING + _U32.pack(len(sts))
    encoded = _ENCODED
    if len(encoded) > _ENCODED_MAX:  # (values that never repeat, such as ages and uptimes, are kept too: bounded)
        encoded.clear()
    for level, name, msg, hw, values in sts:
        out.append(level)
        strings = [name, msg, hw]
        for k, v in values.items():
            strings.append(k if type(k) is str else str(k))
            strings.append(v if type(v) is str else str(v))
        for i, text in enumerate(strings):
            if i == 3:  # the values' count, after hardware_id
                out += _PADS[-len(out) & 3] + _U32.pack(len(values))
            enc = encoded.get(text)
            if enc is None:
                raw = text.encode()
                enc = encoded[text] = _U32.pack(len(raw) + 1) + raw + b"\0"
            out += _PADS[-len(out) & 3]
            out += enc
        if len(strings) == 3:
            out += _PADS[-len(out) & 3] + _U32.pack(0)
    return bytes(out)


_CDR_LE = b"\x00\x01\x00\x00"  # the encapsulation header: plain CDR, little endian
_U32 = struct.Struct("<I")
_EMPTY_STRING = _U32.pack(1) + b"\0\0\0\0"  # header.frame_id "" (length 1: its NUL), padded to 4
# CDR strings are 4-byte aligned; the offsets count from after the 4-byte encapsulation header, so the buffer's own
# offsets align the same
_PADS = (b"", b"\0", b"\0\0", b"\0\0\0")
# text -> its CDR string (length with the NUL, UTF-8 bytes, NUL); cleared when it outgrows the bound
_ENCODED: dict[str, bytes] = {}
_ENCODED_MAX = 20_000


def statuses(snap: Mapping[str, Any], naming: Naming) -> list[Status]:
    """The statuses of the snapshot, in order: the bridge, each mapping, each device, the bus's time."""
    out: list[Status] = []
    ok, warn, err, stale = 0, 1, 2, 3
    proto = naming.protocol

    b = snap["bridge"]
    link = b["link"]
    total_drop = sum(m["dropped_total"] for m in snap["mappings"].values())
    bmsg = f"{len(snap['mappings'])} mappings, {total_drop} dropped"
    if not link["up"]:
        bmsg = f"{naming.label} link {link['state']}; " + bmsg
    if not b.get("active", True):  # a managed bridge its manager has not activated: commands are dropped
        bmsg = "inactive (lifecycle): commands dropped; " + bmsg
    out.append((ok if link["up"] else err, naming.bridge, bmsg, f"{proto} node {b['node_id']}",
                {"node_id": b["node_id"], "transport": b["transport"], "uptime_s": b["uptime_s"],
                 "dropped_total": total_drop, "link_up": link["up"], "link_state": link["state"],
                 "link_outages": link["outages"], "link_down_s": link["down_s"],
                 "active": b.get("active", True),
                 **{f"error.{k}": v for k, v in sorted(b["errors"].items())}}))
    for name, m in snap["mappings"].items():
        values: dict[str, Any] = {
            "direction": m["direction"], "topic": m["topic"], **_port(m), "port": m["port"],
            "received": m["received"], "published": m["published"], "dropped": m["dropped_total"],
        }
        for key in ("source_node_ids", "destination_node_ids"):
            if m.get(key) == "any":  # the spec's explicit choice, visible: no node id filter (no spoofing check)
                values[key] = "any"
        values.update({f"dropped.{k}": v for k, v in sorted(m["dropped"].items())})
        values["saturated"] = m["saturated_total"]
        values.update({f"saturated.{k}": v for k, v in sorted(m["saturated"].items())})
        values.update({f"rejected.{k}": v for k, v in sorted(m["rejected_fields"].items())})
        values["out_of_order"] = m["out_of_order"]
        values.update(traffic_values(m))
        below = dict(m.get(proto) or {})
        kinds = below.pop("error_kinds", {})
        problem_age = below.pop("last_problem_age_s", None)
        values.update({f"{proto}.{k}": v for k, v in below.items()})
        values.update({f"{proto}.error.{k}": v for k, v in sorted(kinds.items())})
        recent = any(age is not None and age < RECENT_DROP_WINDOW_S for age in (m["last_drop_age_s"], problem_age))
        level = warn if recent else ok
        if m["dropped_total"]:
            parts = ", ".join(f"{k} {v}" for k, v in sorted(m["dropped"].items()))
            msg = f"{m['dropped_total']} dropped ({parts})" + (
                f", the last {m['last_drop_age_s']:.0f} s ago" if m["last_drop_age_s"] is not None else "")
        else:
            msg = "ok"
        if m["saturated_total"]:
            msg += f", {m['saturated_total']} values saturated"
        bad = sum(int(below.get(k, 0)) for k in _PROBLEMS)
        if bad:
            msg += f", {bad} frames/transfers discarded by {naming.stack}"
        if not m.get("enabled", True):  # drops it was told to make: OK unless something else is wrong
            msg = f"disabled (std_srvs/SetBool {m.get('enable_service', '')}); " + msg
        live = m.get("liveness")
        if live is not None:
            values["liveness"] = live["state"]
            if live["state"] != "ok":  # silent while its device is alive (sam_runtime.bridge.liveness)
                level = warn
                msg = live["message"] + ("" if msg == "ok" else f"; {msg}")
                values.update(silent_s=live["silent_s"], grace_s=live["grace_s"],
                              nominal_rate_hz=live["nominal_rate_hz"])
        out.append((level, f"{naming.bridge}/mapping/{name}", msg,
                    " ".join(f"{k.replace('_id', '').replace('_', ' ')} {v}" for k, v in _port(m).items()), values))
    for name, d in snap["devices"].items():
        if not d["seen"]:
            level, msg = stale, "no heartbeat yet"
        elif not d["alive"]:
            level, msg = err, f"heartbeat lost: none for {d['age_s']:.1f} s"
            if not link["up"]:
                msg += f" (the bridge's {naming.label} link is down)"
        else:
            level = (ok, warn, err)[min(max(int(d["level"]), 0), 2)]
            msg = f"{d['health']} {d['mode']}"
        if d.get("interface") == "mismatch":  # firmware from another spec (issue 28: bridge.interface_check)
            level = err if d.get("interface_on_mismatch") == "stop" or level == err else warn
            msg += f"; firmware interface {d['interface_got']} != spec {d['interface_want']}"
            if d.get("interface_on_mismatch") == "stop":
                msg += ": its mappings are stopped"
        out.append((level, f"{naming.bridge}/device/{name}", msg, f"{proto} node {d['node_id']}",
                    {k: v for k, v in d.items() if k not in ("seen", "level")}))
    ts = snap.get("time_sync")
    if ts is not None:
        out.append(time_sync_fields(ts, naming))
    return out


def time_sync_status(ts: Mapping[str, Any], naming: Naming, status_cls: Any, kv: Any) -> Any:
    """:func:`time_sync_fields` as ``status_cls(...)`` with ``kv(values)``."""
    level, name, msg, hw, values = time_sync_fields(ts, naming)
    return status_cls(level=bytes([level]), name=name, hardware_id=hw, message=msg, values=kv(values))


def time_sync_fields(ts: Mapping[str, Any], naming: Naming) -> Status:
    """``<bridge>/time_sync``: the master (running: messages sent within 3 periods) and, per device, whether its
    stamps are synchronised, their counts and the median error receive time - stamp. OK while the master sends and
    every device's last stamp was synchronised; WARN otherwise (not yet, or not following); ERROR when the
    master's sends fail."""
    master = ts.get("master")
    values: dict[str, Any] = {}
    problems: list[str] = []
    level = 0
    if master is None:
        values["master"] = "off"
    else:
        age = master["last_sent_age_s"]
        running = age is not None and age <= 3 * master["period_s"]
        values.update({"master": "running" if running else "not sending", "master.message": master["message"],
                       "master.period_s": master["period_s"], "master.sent": master["sent"],
                       "master.failed": master["failed"], "master.imprecise": master["imprecise"]})
        if master.get("tx_time"):  # where its transmission times came from (sam_runtime.bridge.time_sync)
            values["master.tx_time"] = ", ".join(f"{k}={v}" for k, v in master["tx_time"].items())
        if not running:
            level = 2
            problems.append("the master is not sending")
    unsynced = []
    for name, d in ts["devices"].items():
        values[f"{name}.synchronised"] = d["synchronised"]
        values.update({f"{name}.{k}": d[k] for k in ("stamps_known", "stamps_unknown", "stamps_off")})
        if "error_ms" in d:
            values[f"{name}.error_ms.median"] = d["error_ms"]["median"]
        if not d["synchronised"]:
            unsynced.append(name)
    if unsynced:
        level = max(level, 1)
        problems.append("not synchronised: " + ", ".join(unsynced))
    msg = "; ".join(problems) or (f"{len(ts['devices'])} devices synchronised" if master is not None else
                                  f"master off; {len(ts['devices'])} devices synchronised")
    return level, f"{naming.bridge}/time_sync", msg, "time sync", values
