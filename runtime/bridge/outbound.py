"""The ROS -> UAVCAN path: a ROS message of a command topic, converted in the rclpy executor thread by each of the
topic's mappings (``<mapping>_to_uavcan``; on the wire path the generated codec, from the CDR bytes of a raw
subscription to the payload bytes the backend sends as they are), handed to the asyncio loop (:mod:`.handoff`),
queued per mapping in a bounded queue, and published in order by one worker task per mapping on its backend port.

Every message that is not published is counted once per mapping: ``convert_error``, ``rejected``, ``queue_full``
(the bounded queue), ``link_down`` (the backend's link is being reopened), ``publish_error`` (the send raised),
``not_sent`` (not every frame within the port's send timeout), ``shutdown`` (the bridge was closing),
``handler_error`` (a bug in this path). Nothing raises into the rclpy executor: an exception out of a callback
would also leave the EventsExecutor's queued messages waiting for the next one.

Traffic control (issue 19): a disabled mapping (:mod:`.switches`) drops a command before converting it, and one
that was queued or held when it was disabled, as ``disabled``. With ``max_rate_hz`` the converted commands pass a
:class:`~.rate_limit.Pacer` on the loop before the queue: the latest at most that often, a held one replaced by a
newer one counted as ``coalesced``. With ``deadline_s`` each command carries the monotonic time the rclpy callback
took it, and the worker drops it as ``expired`` when it is older than the deadline at the moment it would be sent
(after waiting in the hand-off, the pacer or the queue). What is held when the bridge closes counts as ``shutdown``.

A managed bridge that is not active (:mod:`.managed`: configured but not activated, or deactivated) drops every
command as ``inactive`` (:attr:`Outbound.active`: one bool read per command, in the rclpy thread and again by the
worker before it sends, so nothing queued or held at the deactivation reaches the bus after it).
"""

from __future__ import annotations

import asyncio
import functools
import logging
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

from sam_runtime.bridge.backend import Backend, LinkDownError, Outlet
from sam_runtime.bridge.counters import MappingStats, count_handler_error, count_superseded, log
from sam_runtime.bridge.handoff import Handoff
from sam_runtime.bridge.layout import port_id_of
from sam_runtime.bridge.lifetime import Lifetime
from sam_runtime.bridge.rate_limit import Pacer, expired
from sam_runtime.bridge.switches import MappingSwitch
from sam_runtime.common.tasks import cancel_and_wait

__all__ = ["DEFAULT_QUEUE_SIZE", "OutMapping", "Outbound"]

DEFAULT_QUEUE_SIZE = 256


@dataclass
class OutMapping:
    """A ROS -> UAVCAN mapping at run time."""

    info: Any
    to_uavcan: Callable[..., Any]
    stats: MappingStats
    ros_cls: Any = None  # the topic's ROS message class
    dtype: Any = None  # the port's DSDL class
    outlet: Outlet | None = None
    queue: asyncio.Queue[Any] | None = None
    worker: asyncio.Task[None] | None = None
    # the wire path: to_uavcan is the generated codec (CDR bytes of a raw subscription -> UAVCAN payload bytes)
    raw: bool = False
    switch: MappingSwitch = field(default_factory=lambda: MappingSwitch(""))  # enabled unless told (composition)
    pacer: Pacer | None = None  # with max_rate_hz (Outbound makes it)
    deadline_s: float | None = None  # from the tables (Outbound sets it): queued items are (obj, received_s)


class Outbound:
    """:param link_up: whether the backend's link is up now.
    :param ros: subscribes the command topics when the bridge starts (``ros.subscribe(topic, cls, callback)``).
    :param backend: advertises each mapping's port when the bridge starts; its ``label`` names it in log lines.

    Without ``ros`` and ``backend`` (tests), set ``handoff.loop``, the queues and the outlets yourself."""

    def __init__(self, lifetime: Lifetime, mappings: Sequence[OutMapping], link_up: Callable[[], bool], *,
                 queue_size: int = DEFAULT_QUEUE_SIZE, ros: Any = None, backend: Backend | None = None) -> None:
        self.lifetime = lifetime
        self.mappings = {om.info.name: om for om in mappings}
        self.by_topic: dict[str, list[OutMapping]] = {}
        for om in mappings:
            self.by_topic.setdefault(om.info.topic.name, []).append(om)
        self._link_up = link_up
        self.queue_size = int(queue_size)
        self._ros, self._backend = ros, backend
        self.label = backend.label if backend is not None else "UAVCAN"
        self.handoff: Handoff[OutMapping] = Handoff(self._enqueue, lambda om, _obj: om.stats.drop("shutdown"))
        for om in mappings:
            om.deadline_s = getattr(om.info, "deadline_s", None)
            rate = getattr(om.info, "max_rate_hz", None)
            if rate is not None and om.pacer is None:
                om.pacer = Pacer(rate, functools.partial(self._put, om),
                                 functools.partial(count_superseded, om.stats, "coalesced"))
        self._timed = {topic: any(om.deadline_s is not None for om in oms) for topic, oms in self.by_topic.items()}
        self.clock: Callable[[], float] = time.monotonic  # of the deadline check (tests may set their own)
        # False while a managed bridge is not active (sam_runtime.bridge.managed): every command is dropped as
        # ``inactive``, at the subscription and again before sending (what was queued or held when it was deactivated)
        self.active = True

    def attach(self) -> None:
        """Subscribe the command topics, advertise the ports, start the workers when the bridge starts (before the
        backend opens); hand nothing on once it closes."""
        self.lifetime.add_hooks("ROS -> UAVCAN", start=self._start, close=self._close)

    def _start(self) -> None:
        if self._backend is not None:
            for om in self.mappings.values():
                om.outlet = self._backend.advertise(om.info.name, port_id_of(om.info), om.dtype, raw=om.raw)
        if self._ros is not None:
            for oms in self.by_topic.values():
                self._ros.subscribe(oms[0].info.topic, oms[0].ros_cls, lambda msg, oms=oms: self.on_ros(oms, msg),
                                    raw=all(om.raw for om in oms))
        self.handoff.loop = self.lifetime.loop
        for om in self.mappings.values():
            if om.pacer is not None:
                om.pacer.loop = self.lifetime.loop
            om.queue = asyncio.Queue(maxsize=self.queue_size)
            om.worker = asyncio.create_task(self._worker(om), name=f"bridge-out-{om.info.name}")

    async def _close(self) -> None:
        self.handoff.drain()  # what the rclpy thread handed off last: counted as shutdown (see _enqueue)
        for om in self.mappings.values():
            if om.pacer is not None and om.pacer.close() is not None:
                om.stats.drop("shutdown")
        stuck = await cancel_and_wait([om.worker for om in self.mappings.values() if om.worker is not None])
        if stuck:
            log.warning("%d bridge tasks did not stop", len(stuck))

    # -------------------------------------------------------------------------------------------- rclpy thread
    def on_ros(self, oms: Sequence[OutMapping], msg: Any) -> None:
        """Every message of a command topic (``oms``: the topic's mappings). Never raises."""
        try:
            self._convert_and_hand_off(oms, msg)
        except Exception as ex:  # a bug: counted and logged, the executor goes on
            count_handler_error([om.stats for om in oms], f"topic {oms[0].info.topic.name if oms else '?'}", ex,
                                self.lifetime.errors, self.lifetime.rlog)

    def _convert_and_hand_off(self, oms: Sequence[OutMapping], msg: Any) -> None:
        rlog = self.lifetime.rlog
        # the command's age counts from here, on the worker's clock (time.monotonic: thread-safe)
        received = self.clock() if oms and self._timed.get(oms[0].info.topic.name) else 0.0
        for om in oms:
            st = om.stats
            st.receive()
            if not self.active:
                st.drop("inactive")
                continue
            if not om.switch.enabled:
                st.drop(om.switch.drop_reason)
                continue
            try:
                obj = om.to_uavcan(msg, st)
            except ValueError as ex:
                if not om.raw:
                    st.drop("convert_error")
                    rlog.note((om.info.name, "convert_error"), logging.ERROR, "conversion failed: %s: %s",
                              type(ex).__name__, ex)
                    continue
                # the wire codec refused the CDR bytes (a WireError: truncated, not plain CDR, a bound exceeded):
                # bad input from the ROS side, not a bug (issue 29)
                st.drop("bad_cdr")
                rlog.note((om.info.name, "bad_cdr"), logging.WARNING, "a command that is not valid CDR: %s", ex)
                continue
            except Exception as ex:
                st.drop("convert_error")
                rlog.note((om.info.name, "convert_error"), logging.ERROR, "conversion failed: %s: %s",
                          type(ex).__name__, ex)
                continue
            if obj is None:
                st.drop("rejected")
                continue
            self.handoff.put(om, obj if om.deadline_s is None else (obj, received))

    # -------------------------------------------------------------------------------------------- asyncio loop
    def _enqueue(self, om: OutMapping, obj: Any) -> None:
        """Queue for the mapping's worker (keeps the order, bounds the backlog), through its pacer if it has one."""
        if om.queue is None or self.lifetime.closed:
            om.stats.drop("shutdown")
            return
        if om.pacer is not None:
            om.pacer.offer(obj)
        else:
            self._put(om, obj)

    def _put(self, om: OutMapping, obj: Any) -> None:
        if om.queue is None or self.lifetime.closed:
            om.stats.drop("shutdown")
            return
        try:
            om.queue.put_nowait(obj)
        except asyncio.QueueFull:
            om.stats.drop("queue_full")
            self.lifetime.rlog.note((om.info.name, "queue_full"), logging.WARNING,
                                    "%s publish queue full (%d): dropping", self.label, self.queue_size)

    async def _worker(self, om: OutMapping) -> None:
        assert om.queue is not None
        name, rlog, lifetime = om.info.name, self.lifetime.rlog, self.lifetime
        while not lifetime.closed:
            obj = await om.queue.get()
            if om.deadline_s is not None:
                obj, received = obj
                if expired(received, self.clock(), om.deadline_s):
                    om.stats.drop("expired")
                    rlog.note((name, "expired"), logging.WARNING, "a command older than its deadline (%.3f s) was "
                              "not sent", om.deadline_s)
                    continue
            if not self.active:  # queued or held before the bridge was deactivated
                om.stats.drop("inactive")
                continue
            if not om.switch.enabled:  # queued before the mapping was disabled
                om.stats.drop(om.switch.drop_reason)
                continue
            outlet = om.outlet
            if outlet is None or not outlet.ready or not self._link_up():
                om.stats.drop("link_down")
                rlog.note((name, "link_down"), logging.WARNING, "the %s transport is being reopened", self.label)
                continue
            try:
                ok = await outlet.publish(obj)
            except asyncio.CancelledError:
                om.stats.drop("shutdown")
                raise
            except LinkDownError:
                om.stats.drop("shutdown" if lifetime.closed else "link_down")
                continue
            except Exception as ex:
                if lifetime.closed:
                    om.stats.drop("shutdown")
                    continue
                om.stats.drop("publish_error")
                rlog.note((name, "publish_error"), logging.WARNING, "%s publish failed: %s: %s", self.label,
                          type(ex).__name__, ex)
                continue
            if ok:
                om.stats.publish()
            else:
                om.stats.drop("not_sent")
                rlog.note((name, "not_sent"), logging.WARNING, "%s publish: not every frame sent within %.1f s",
                          self.label, outlet.send_timeout)
