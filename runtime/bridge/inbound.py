"""The UAVCAN -> ROS path, on the asyncio loop: every transfer of a subscribed port is checked against each of the
port's mappings' accepted source node ids, its transfer-id gaps are counted (:mod:`.loss`), and it is converted
(``<mapping>_to_ros``, receive time from the ROS clock) and published to ROS at once (rclpy's publish is
thread-safe).

Several mappings may share one port (one subscription): each gets every transfer and counts it. Drops per mapping:
``unknown_source``, ``lost`` / ``lost_link_down`` (counted when the next transfer of the source arrives),
``transfer_id_jump`` (a transfer id further ahead than the time since the source's last transfer allows: a restart
or a spoof, see :mod:`.loss`; the transfer is not published),
``convert_error``, ``rejected``, ``publish_error``, ``handler_error`` (a bug in this path; never raised into the
backend's receive loop), ``unselected`` (DroneCAN: a broadcast from an accepted device that no mapping of the port
selects, e.g. an esc.Status with an ESC index no mapping reads; counted on the first mapping accepting the device).
A transfer from a device that another mapping of the shared port accepts is that mapping's alone.

A mapping with ``any_node`` (the spec's ``source_node_ids: any``) accepts every source node id: it is routed only
by what the message says (DroneCAN's ``select`` and the items it reads), so it gives up the source filter's
protection against spoofing; its port then never counts ``unknown_source``.

Stamps: a device stamp of 0 (unknown) becomes the receive time; an empty frame id the mapping's; a stamp older than
the previous one of the same source on the same mapping is published anyway, in arrival order, and counted as
``out_of_order``. A source that restarted (:meth:`Inbound.forget_stamps`) may have restarted its clock: its next
stamp is compared with nothing.

Two paths, one accounting: the object path gets the protocol library's message object and converts it with
``<mapping>_to_ros`` into a ROS message; the wire path (``InMapping.raw``) gets the transfer's payload bytes and the
generated codec (``<mapping>_wire_to_ros``) turns them straight into the ROS message's CDR, published raw. A payload
the codec refuses (``ValueError``: what the protocol library's deserializer would have refused) is counted below the
bridge by the inlet (``Inlet.malformed``) and goes no further, as the library's own refusals do on the object path.

Traffic control (issue 19): a disabled mapping (:mod:`.switches`) drops a transfer before converting it
(``disabled``); a mapping with ``max_rate_hz`` publishes through a :class:`~.rate_limit.Pacer` on the loop's timers:
the latest converted message at most that often, trailing edge, a held one replaced by a newer one counted as
``rate_limited`` (its stamp was checked when it arrived); what is held when the bridge closes counts as ``shutdown``.
"""

from __future__ import annotations

import functools
import logging
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

from sam_runtime.bridge.backend import Backend, Inlet
from sam_runtime.bridge.counters import MappingStats, count_handler_error, count_superseded
from sam_runtime.bridge.lifetime import Lifetime
from sam_runtime.bridge.loss import JUMP, TransferLoss
from sam_runtime.bridge.rate_limit import Pacer
from sam_runtime.bridge.switches import MappingSwitch

__all__ = ["InMapping", "Inbound", "PortGroup", "accepts"]


def accepts(info: Any, src: int | None) -> bool:
    """Whether the mapping ``info`` takes a transfer from node ``src`` (its source node ids, or any node)."""
    return src in info.source_node_ids or (src is not None and getattr(info, "any_node", False))

_DISABLED = object()  # a conversion result: the mapping was disabled, nothing converted


@dataclass
class InMapping:
    """A UAVCAN -> ROS mapping at run time."""

    info: Any
    to_ros: Callable[..., Any]
    stats: MappingStats
    ros_cls: Any = None  # the topic's ROS message class
    ros_publisher: Any = None
    has_header: bool = False
    # DroneCAN: whether a message is this mapping's (its `select` values, the broadcast-array elements it reads);
    # None: every message of the port from an accepted source is
    matches: Callable[[Any], bool] | None = None
    # the wire path: to_ros / matches take payload bytes, to_ros returns (CDR bytes, header stamp ns or -1) or None
    raw: bool = False
    last_stamp_ns: dict[int, int] = field(default_factory=dict)  # per source: stamp of the last published message
    switch: MappingSwitch = field(default_factory=lambda: MappingSwitch(""))  # enabled unless told (composition)
    pacer: Pacer | None = None  # with max_rate_hz (Inbound makes it)


@dataclass
class PortGroup:
    """The mappings of one subscribed port."""

    port_id: int  # the spec's
    port_name: str  # for registers and reports (its first mapping's name)
    dtype: Any
    mappings: list[InMapping]
    loss: TransferLoss
    accepted_sources: frozenset[int] = frozenset()
    inlet: Inlet | None = None
    any_source: bool = False  # a mapping of the port accepts every node id (``any_node``)

    # the port's only mapping when it takes every transfer of an accepted source (no select / elements to match):
    # the one-mapping fast path (Inbound sets it)
    single: InMapping | None = None

    @property
    def raw(self) -> bool:
        """Whether the port's transfers come as payload bytes (every mapping of a port takes the same path)."""
        return any(im.raw for im in self.mappings)


class Inbound:
    """:param ros: gives the ROS publishers (``ros.publisher(topic, cls)``) and the receive time (``ros.receive_ns()``:
        nanoseconds of the node's clock) once the bridge starts.
    :param backend: subscribes each group's port when the bridge starts."""

    def __init__(self, lifetime: Lifetime, groups: Sequence[PortGroup], ros: Any, backend: Backend) -> None:
        self.lifetime = lifetime
        self._ros, self._backend = ros, backend
        self.groups = {g.port_id: g for g in groups}
        self.frame_prefix = ""  # before every frame id written (sam_runtime.common.ros_namespace); object path only
        # (the wire codecs write it themselves: the bridge takes a codec module bound to it)
        for g in groups:
            g.accepted_sources = frozenset(n for im in g.mappings for n in im.info.source_node_ids)
            g.any_source = any(getattr(im.info, "any_node", False) for im in g.mappings)
            g.single = g.mappings[0] if len(g.mappings) == 1 and g.mappings[0].matches is None else None
        self._receive_ns: Callable[[], int] = ros.receive_ns
        # (mapping, source, stamp ns, receive ns) of every published message with a header: the time-sync watch
        self.on_stamp: Callable[[str, int, int, int], None] | None = None
        self._group_of = {im.info.name: g for g in groups for im in g.mappings}
        for g in groups:
            for im in g.mappings:
                rate = getattr(im.info, "max_rate_hz", None)
                if rate is not None and im.pacer is None:
                    im.pacer = Pacer(rate, functools.partial(self._deliver, im),
                                     functools.partial(count_superseded, im.stats, "rate_limited"))

    def attach(self) -> None:
        """The ROS publishers and the backend's subscriptions when the bridge starts (before the backend opens)."""
        self.lifetime.add_hooks("UAVCAN -> ROS", start=self._start, close=self._close)

    def _close(self) -> None:
        for group in self.groups.values():
            for im in group.mappings:
                if im.pacer is not None and im.pacer.close() is not None:
                    im.stats.drop("shutdown")

    def _start(self) -> None:
        for group in self.groups.values():
            for im in group.mappings:
                im.ros_publisher = self._ros.publisher(im.info.topic, im.ros_cls)
                if im.pacer is not None:
                    im.pacer.loop = self.lifetime.loop
            group.inlet = self._backend.subscribe(group.port_name, group.port_id, group.dtype, self.handler(group),
                                                  raw=group.raw)

    def group_of(self, mapping: str) -> PortGroup | None:
        return self._group_of.get(mapping)

    def handler(self, group: PortGroup) -> Callable[[Any, int | None, int, float], None]:
        """The backend's transfer handler of ``group``'s port."""

        def on_transfer(msg: Any, src: int | None, transfer_id: int, monotonic_s: float) -> None:
            try:
                self._bridge_transfer(group, msg, src, transfer_id, monotonic_s)
            except Exception as ex:  # a bug: counted and logged, the receive loop goes on
                count_handler_error([im.stats for im in group.mappings], f"subject {group.port_id}", ex,
                                    self.lifetime.errors, self.lifetime.rlog)

        return on_transfer

    def forget_stamps(self, nid: int) -> None:
        """``nid`` restarted: its next stamps are compared with nothing."""
        for group in self.groups.values():
            for im in group.mappings:
                im.last_stamp_ns.pop(nid, None)

    def last_message(self, mapping: str, nid: int) -> float | None:
        """When the last transfer of ``nid`` arrived on the port of ``mapping`` (monotonic s)."""
        group = self._group_of.get(mapping)
        return None if group is None else group.loss.last_message(nid)

    def _takers(self, group: PortGroup, msg: Any, src: int) -> list[InMapping] | None:
        """The mappings a transfer from the accepted source ``src`` is for (None: a payload the codec refuses,
        counted below the bridge)."""
        try:
            return [im for im in group.mappings
                    if accepts(im.info, src) and (im.matches is None or im.matches(msg))]
        except ValueError as ex:  # only the wire path's matches parse bytes
            if not group.raw:
                raise
            self._malformed(group, src, ex)
            return None

    def _malformed(self, group: PortGroup, src: int | None, ex: Exception) -> None:
        if group.inlet is not None:
            group.inlet.malformed(src, f"{type(ex).__name__}: {ex}")

    def _bridge_transfer(self, group: PortGroup, msg: Any, src: int | None, tid: int, now: float) -> None:
        known = src in group.accepted_sources or (group.any_source and src is not None)
        if not known:
            rlog = self.lifetime.rlog
            for im in group.mappings:  # no mapping's device: each mapping of the port counts it
                im.stats.receive()
                im.stats.drop("unknown_source")
                rlog.note((im.info.name, "unknown_source"), logging.WARNING,
                          "dropped a transfer from node %s (accepted: %s)", src, sorted(im.info.source_node_ids))
            return
        assert src is not None
        single = group.single
        if single is not None:  # the port's one mapping accepts src (known) and takes everything: no lists
            self._one(group, single, msg, src, tid, now)
            return
        takers = self._takers(group, msg, src)
        if takers is None:
            return
        receive_ns = self._receive_ns() if takers else 0
        results: list[tuple[InMapping, Any, Exception | None]] = []
        for im in takers:
            if not im.switch.enabled:
                results.append((im, _DISABLED, None))
                continue
            try:
                results.append((im, im.to_ros(msg, receive_ns, im.stats), None))
            except ValueError as ex:
                if not im.raw:
                    results.append((im, None, ex))
                    continue
                self._malformed(group, src, ex)  # the whole payload is refused, before any counter moved
                return
            except Exception as ex:
                results.append((im, None, ex))
        lost, lost_est = group.loss.track(src, tid, now)
        for im, out, error in results:
            self._account(im, src, tid, lost, lost_est, receive_ns, out, error)
        if not takers:  # from an accepted device, but what no mapping selects: never a silent loss
            im = next(im for im in group.mappings if accepts(im.info, src))
            im.stats.receive()
            im.stats.drop("unselected")
            self.lifetime.rlog.note((im.info.name, "unselected"), logging.WARNING,
                                    "node %s sent a message no mapping of port %d selects (select / elements)", src,
                                    group.port_id)

    def _one(self, group: PortGroup, im: InMapping, msg: Any, src: int, tid: int, now: float) -> None:
        """:meth:`_bridge_transfer` for a port whose one mapping takes the transfer (the same steps, without the
        takers' and results' lists: the usual case, per message)."""
        receive_ns = self._receive_ns()
        error: Exception | None = None
        if not im.switch.enabled:
            out: Any = _DISABLED
        else:
            try:
                out = im.to_ros(msg, receive_ns, im.stats)
            except ValueError as ex:
                if im.raw:
                    self._malformed(group, src, ex)  # the whole payload is refused, before any counter moved
                    return
                out, error = None, ex
            except Exception as ex:
                out, error = None, ex
        lost, lost_est = group.loss.track(src, tid, now)
        self._account(im, src, tid, lost, lost_est, receive_ns, out, error)

    def _account(self, im: InMapping, src: int, tid: int, lost: int, lost_est: int, receive_ns: int, out: Any,
                 error: Exception | None) -> None:
        """Count, check the stamp of and publish one mapping's conversion of one transfer."""
        st = im.stats
        if lost or lost_est or error is not None or out is None or out is _DISABLED:
            self._account_drops(im, src, tid, lost, lost_est, out, error)
            if error is not None or out is None or out is _DISABLED or lost == JUMP:
                return
            received = True  # (counted with the drops)
        else:
            received = False  # counted with the publication (one lock: MappingStats.bridged)
        if im.raw:
            out, stamp = out  # the codec resolved the frame id and an unknown stamp already
        elif im.has_header:
            hdr = out.header
            if not hdr.frame_id and im.info.frame_id:
                hdr.frame_id = im.info.frame_id
            if self.frame_prefix and hdr.frame_id:
                hdr.frame_id = self.frame_prefix + hdr.frame_id
            if hdr.stamp.sec == 0 and hdr.stamp.nanosec == 0:
                hdr.stamp.sec, hdr.stamp.nanosec = divmod(receive_ns, 1_000_000_000)
            stamp = hdr.stamp.sec * 1_000_000_000 + hdr.stamp.nanosec
        else:
            stamp = -1
        if stamp >= 0 and im.has_header:
            last_stamps = im.last_stamp_ns
            last = last_stamps.get(src)
            last_stamps[src] = stamp
            if last is not None and stamp < last:  # published anyway, in arrival order (see the docstring)
                st.reorder()
                self.lifetime.rlog.note((im.info.name, "out_of_order"), logging.WARNING,
                                        "node %s: stamp %.6f s is older than the previous one (%.6f s); published",
                                        src, stamp * 1e-9, last * 1e-9)
            if self.on_stamp is not None:
                self.on_stamp(im.info.name, src, stamp, receive_ns)
        if im.pacer is not None:
            if not received:
                st.receive()
            im.pacer.offer(out)  # now, or when its slot comes (see the docstring)
        else:
            self._deliver(im, out, received)

    def _account_drops(self, im: InMapping, src: int, tid: int, lost: int, lost_est: int, out: Any,
                       error: Exception | None) -> None:
        """The transfer's receipt and what did not become a publication: losses before it, and it when disabled,
        failed or rejected."""
        rlog, st, name = self.lifetime.rlog, im.stats, im.info.name
        st.receive()
        if lost == JUMP:  # a restart with another counter, or a spoof: not published, and no loss (see .loss)
            st.drop("transfer_id_jump")
            rlog.note((name, "transfer_id_jump"), logging.WARNING, "node %s: transfer id %d is further ahead than "
                      "the time since its previous transfer allows (a restart or a spoof): dropped", src, tid)
            return
        if lost:
            st.drop("lost", lost)
            rlog.note((name, "lost"), logging.WARNING, "%d transfers from node %s never arrived "
                      "(transfer id gap before %d)", lost, src, tid, count=lost)
        if lost_est:
            st.drop("lost_link_down", lost_est)
            rlog.note((name, "lost_link_down"), logging.WARNING, "about %d transfers from node %s missed "
                      "while the link was down (estimated from the nominal rate)", lost_est, src, count=lost_est)
        if out is _DISABLED:
            st.drop(im.switch.drop_reason)
            return
        if error is not None:
            st.drop("convert_error")
            rlog.note((name, "convert_error"), logging.ERROR, "conversion failed: %s: %s", type(error).__name__,
                      error)
            return
        if out is None:
            st.drop("rejected")

    def _deliver(self, im: InMapping, out: Any, received: bool = True) -> None:
        """Publish one converted message (at once, or from the pacer's timer; ``received``: its receipt is counted
        already, else it is counted here). Never raises."""
        st = im.stats
        if not im.switch.enabled:  # held for its rate slot while the mapping was disabled
            if not received:
                st.receive()
            st.drop(im.switch.drop_reason)
            return
        try:
            im.ros_publisher.publish(out)  # CDR bytes on the wire path: rclpy publishes them raw
        except Exception as ex:
            if not received:
                st.receive()
            st.drop("publish_error")
            self.lifetime.rlog.note((im.info.name, "publish_error"), logging.ERROR, "ROS publish failed: %s: %s",
                                    type(ex).__name__, ex)
            return
        if received:
            st.publish()
        else:
            st.bridged()
