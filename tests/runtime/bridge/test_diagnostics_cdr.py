"""/diagnostics as the bridge publishes it (issue 26): serialized straight to CDR by
:func:`~sam_runtime.bridge.diagnostics.diagnostic_array_cdr`, published raw from the housekeeping round on the loop.

- the bytes are rclpy's serialize_message of the message :func:`diagnostic_array` builds from the same snapshot
  (alignment after each level byte and string, UTF-8 text, empty values, many statuses), on fixed snapshots and on
  generated ones: the same length, the same bytes but the alignment padding (zero here; the DDS serializer leaves
  whatever its buffer held there), and they deserialize to the same message;
- the Reporter publishes those bytes (a subscriber deserializes the very message ``diagnostics_message`` gives) and
  its period is a job of the bridge's lifetime (no rclpy timer): at 1 s, in the one housekeeping round.
"""

from __future__ import annotations

import logging
import threading
from types import SimpleNamespace as NS
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as hs

from sam_runtime.bridge.counters import MappingStats
from sam_runtime.bridge.lifetime import Lifetime
from sam_runtime.common.rate_log import RateLimitedLog

pytest.importorskip("diagnostic_msgs")
from builtin_interfaces.msg import Time
from rclpy.serialization import deserialize_message, serialize_message

from sam_runtime.bridge.diagnostics import Naming, diagnostic_array, diagnostic_array_cdr

NAMING = Naming("/sam/uavcan_ros_bridge", "dronecan", "DroneCAN", "dronecan")


def _mapping(**over: Any) -> dict[str, Any]:
    m = {"direction": "uavcan_to_ros", "topic": "/imu", "data_type_id": 1120, "port": "uavcan.sub.imu",
         "received": 10, "published": 7, "dropped": {"lost": 2, "unknown_source": 1}, "dropped_total": 3,
         "saturated": {}, "saturated_total": 0, "rejected_fields": {}, "out_of_order": 0, "last_drop_age_s": 1.5,
         "enabled": True, "enable_service": "/sam/uavcan_ros_bridge/enable/imu", "max_rate_hz": None,
         "deadline_s": None, "source_node_ids": [11],
         "dronecan": {"transfers": 12, "errors": 1, "error_kinds": {"crc.node11": 1}, "last_problem_age_s": 0.4},
         "liveness": {"state": "ok"}}
    m.update(over)
    return m


def _snapshot() -> dict[str, Any]:
    dev = {"node_id": 11, "seen": True, "alive": True, "age_s": 0.2, "state": "alive", "mode": "OPERATIONAL",
           "uptime_s": 9, "vssc": 0, "heartbeats": 9, "lost_events": 0, "restarts": 0}
    return {
        "bridge": {"node_id": 100, "transport": "dronecan:mcast-lo:", "uptime_s": 9.25,
                   "errors": {"transport_down": 1}, "link": {"up": False, "state": "down: ENETDOWN", "outages": 1,
                                                             "down_s": 0.5}},
        "mappings": {
            "imu": _mapping(),
            "gps": _mapping(topic="/gps/fix", dropped={}, dropped_total=0, saturated={"gps.alt": 4}, saturated_total=4,
                            rejected_fields={"gps.lat": 1}, last_drop_age_s=None, max_rate_hz=5.0, enabled=False,
                            source_node_ids="any", dronecan={},
                            liveness={"state": "stopped", "message": "no message for 5 s while device gps (node 13) "
                                      "is alive; nominal 5 Hz; the last one 64 s ago", "silent_s": 5.1,
                                      "grace_s": 3.0, "nominal_rate_hz": 5.0}),
            "thruster_1_rpm": {k: v for k, v in _mapping(direction="ros_to_uavcan", topic="/rpm", dropped={},
                                                         dropped_total=0, deadline_s=0.25).items()
                               if k not in ("liveness", "dronecan", "source_node_ids")},
        },
        "devices": {"imu": dev | {"health": "OK", "level": 0}, "gps": dev | {"health": "WARNING", "level": 1},
                    "dvl": {"node_id": 14, "seen": False, "alive": False, "state": "never seen"},
                    "ctd": dev | {"health": "OK", "level": 0, "alive": False, "age_s": 3.2, "state": "stale"}},
        "time_sync": {"master": {"last_sent_age_s": 0.3, "period_s": 0.5, "message": "GlobalTimeSync", "sent": 18,
                                 "failed": 0, "imprecise": 1, "tx_time": {"driver": 17}},
                      "devices": {"imu": {"synchronised": True, "stamps_known": 5, "stamps_unknown": 0,
                                          "stamps_off": 0, "error_ms": {"median": 0.25}},
                                  "gps": {"synchronised": False, "stamps_known": 0, "stamps_unknown": 3,
                                          "stamps_off": 0}}},
    }


def _same_as_rclpys(snap: dict[str, Any], stamp_ns: int) -> None:
    from diagnostic_msgs.msg import DiagnosticArray

    sec, nanosec = divmod(stamp_ns, 1_000_000_000)
    msg = diagnostic_array(snap, NAMING, Time(sec=sec, nanosec=nanosec))
    theirs = bytes(serialize_message(msg))
    ours = diagnostic_array_cdr(snap, NAMING, stamp_ns)
    assert len(ours) == len(theirs)
    differ = [i for i in range(len(ours)) if ours[i] != theirs[i]]
    assert all(ours[i] == 0 and i % 4 for i in differ), differ[:8]  # padding only (never a length's first byte)
    assert deserialize_message(ours, DiagnosticArray) == msg


@pytest.mark.parametrize("stamp_ns", [0, 1_764_284_400_123_456_789, 999_999_999])
def test_cdr_is_rclpys_serialization(stamp_ns: int) -> None:
    snap = _snapshot()
    _same_as_rclpys(snap, stamp_ns)
    snap["mappings"] = {}
    snap["devices"] = {}
    del snap["time_sync"]
    _same_as_rclpys(snap, stamp_ns)


_text = hs.text(hs.characters(blacklist_categories=("Cs",), blacklist_characters="\0"), max_size=9)


@settings(max_examples=150, deadline=None)
@given(transport=_text, errors=hs.dictionaries(_text, hs.integers(0, 2**40), max_size=4),
       names=hs.lists(_text, max_size=5, unique=True), received=hs.integers(0, 2**31), up=hs.booleans(),
       stamp_ns=hs.integers(0, 2**31 * 10**9 - 1))
def test_cdr_is_rclpys_serialization_for_any_text(transport: str, errors: dict[str, int], names: list[str],
                                                  received: int, up: bool, stamp_ns: int) -> None:
    snap = _snapshot()
    snap["bridge"].update(transport=transport, errors=errors)
    snap["bridge"]["link"]["up"] = up
    snap["mappings"] = {n: _mapping(topic=n, received=received, port=n * 3) for n in names}
    snap["devices"] = {n: snap["devices"]["imu"] | {"mode": n} for n in names}
    _same_as_rclpys(snap, stamp_ns)


def test_reporter_publishes_the_cdr_on_the_lifetimes_round() -> None:
    from diagnostic_msgs.msg import DiagnosticArray

    from sam_runtime.bridge.reporting import Reporter

    snap = _snapshot()
    lt = Lifetime("t", RateLimitedLog(logging.getLogger("test_diagnostics_cdr")))
    published: list[Any] = []
    stamp_ns = 1_764_284_400_500_000_000
    ros = NS(clock=NS(now=lambda: NS(nanoseconds=stamp_ns, to_msg=lambda: Time(sec=1_764_284_400,
                                                                                 nanosec=500_000_000))),
             node=NS(create_publisher=lambda *a: NS(publish=published.append)))
    backend = NS(protocol="dronecan", label="DroneCAN", stack="dronecan")
    rep = Reporter(lt, NAMING.bridge, [], {"imu": MappingStats(threading.Lock())}, backend=backend,  # type: ignore[arg-type]
                   health=None, link=None, inbound=None, outbound=None, silence=None, ros=ros, period=1.0)  # type: ignore[arg-type]
    rep.snapshot = lambda: snap  # type: ignore[method-assign]
    rep.attach()
    assert lt.schedule == {1.0: ["diagnostics"]}  # a job of the lifetime's round, not an rclpy timer
    rep._start()
    rep.publish_now()
    assert len(published) == 1 and isinstance(published[0], bytes)  # published raw
    got = deserialize_message(published[0], DiagnosticArray)
    assert got == rep.diagnostics_message()
    assert got.status[0].name == NAMING.bridge and got.header.stamp.nanosec == 500_000_000

    off = Reporter(Lifetime("t", lt.rlog), "b", [], {}, backend=backend, health=None, link=None,  # type: ignore[arg-type]
                   inbound=None, outbound=None, silence=None, ros=ros, period=0.0)  # type: ignore[arg-type]
    off.attach()
    assert off.lifetime.schedule == {}  # /diagnostics off: no job


def test_cdr_with_the_string_cache_cleared_between_messages(monkeypatch: pytest.MonkeyPatch) -> None:
    from sam_runtime.bridge import diagnostics

    monkeypatch.setattr(diagnostics, "_ENCODED_MAX", 5)  # cleared before every message, refilled within it
    snap = _snapshot()
    first = diagnostic_array_cdr(snap, NAMING, 7)
    assert diagnostic_array_cdr(snap, NAMING, 7) == first
    _same_as_rclpys(snap, 7)
