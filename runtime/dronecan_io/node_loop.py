"""Run a dronecan Node inside an asyncio event loop, in the loop's own thread.

dronecan's Node is single-threaded: ``spin(timeout)`` blocks, reads frames, calls handlers and runs its scheduler
(NodeStatus broadcasts, request timeouts, ``node.periodic``/``node.defer`` callbacks). :class:`NodeLoop` calls
``spin(0)`` (handle what is there, run what is due, return) from

- ``loop.add_reader`` on the driver's socket: as soon as a frame arrives, at most ``max_frames_per_wakeup`` frames
  per call so the loop stays responsive under a flood;
- a timer at the scheduler's next deadline (capped at ``max_idle``, so work that other code adds between calls is
  never late by more than that; :meth:`NodeLoop.wake` runs it at once).

Every exception out of ``spin()`` is caught, counted under a :class:`~.drops.DropReason` with the data type and
source node of the frame it came from, logged with a rate limit, and the next frame is handled: a ``spin(0)`` that
raised has consumed exactly the frame that failed.

Handlers: use :meth:`NodeLoop.add_handler`, which marks a handler's exception as ``handler_error`` and makes sure
dronecan does not log a traceback per message; :func:`~.iface.make_node` creates nodes with dronecan's
``catch_handler_exceptions=False`` so that such errors reach the counters.
"""

from __future__ import annotations

import asyncio
import logging
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from sam_runtime.dronecan_io.can_id import V0Id
from sam_runtime.dronecan_io.drops import DropCounter, DropKey, DropLog, DropReason
from sam_runtime.dronecan_io.frame_gate import FrameGate

__all__ = ["HandlerError", "LoopStats", "NodeLoop", "classify_spin_error", "watchable_fd"]

_log = logging.getLogger(__name__)
_DETAIL_MAX = 240

# What dronecan 1.0.27 raises out of Transfer.from_frames for a bad transfer: (exception type, message start).
_TRANSFER_ERRORS: tuple[tuple[str, str, DropReason], ...] = (
    ("TransferError", "Unrecognised ", DropReason.UNKNOWN_DATA_TYPE),
    ("TransferError", "CRC mismatch", DropReason.CRC_MISMATCH),
    ("TransferError", "Toggle bit", DropReason.TOGGLE_ERROR),
    ("TransferError", "Start of transmission", DropReason.FRAME_SEQUENCE_ERROR),
    ("TransferError", "End of transmission", DropReason.FRAME_SEQUENCE_ERROR),
    ("TransferError", "Transfer ID", DropReason.TRANSFER_ID_MISMATCH),
    ("TransferError", "", DropReason.TRANSFER_ERROR),
    ("ValueError", "Not enough bits", DropReason.MALFORMED_PAYLOAD),
)


class HandlerError(Exception):
    """A handler registered with :meth:`NodeLoop.add_handler` raised (the original is the ``__cause__``)."""


class _CountedHandlerErrors(logging.Filter):
    """dronecan logs every handler exception with its traceback before re-raising it; a HandlerError is counted and
    logged (rate-limited) by the NodeLoop instead."""

    def filter(self, record: logging.LogRecord) -> bool:
        return not (record.exc_info and isinstance(record.exc_info[1], HandlerError))


_handler_error_filter = _CountedHandlerErrors()


def classify_spin_error(ex: BaseException, during_frame: bool) -> DropReason:
    """Why ``spin()`` raised: a handler, a bad transfer (by dronecan's message), or something else.

    >>> from dronecan.transport import TransferError
    >>> classify_spin_error(TransferError("Unrecognised message type ID 4242"), True).value
    'unknown_data_type'
    >>> classify_spin_error(TransferError("Toggle bit value 32 incorrect on frame 0"), True).value
    'toggle_error'
    >>> classify_spin_error(ValueError("Not enough bits; need 56 but got 24"), True).value
    'malformed_payload'
    >>> classify_spin_error(KeyError("x"), True).value, classify_spin_error(KeyError("x"), False).value
    ('frame_exception', 'scheduled_callback_error')
    """
    if isinstance(ex, HandlerError):
        return DropReason.HANDLER_ERROR
    if not during_frame:
        return DropReason.SCHEDULED_CALLBACK_ERROR
    name, message = type(ex).__name__, str(ex)
    for type_name, prefix, reason in _TRANSFER_ERRORS:
        if name == type_name and message.startswith(prefix):
            return reason
    return DropReason.FRAME_EXCEPTION


def watchable_fd(driver: Any) -> int | None:
    """A file descriptor that is readable when ``driver.receive(0)`` has a frame, or None (poll instead).

    The loopback driver has ``fileno()``; dronecan's SocketCAN has its socket. dronecan's SLCAN and ``mcast:``
    drivers read in a forked process and hand frames over a multiprocessing queue: no fd to watch.
    """
    inner = driver.inner if isinstance(driver, FrameGate) else driver
    fileno = getattr(inner, "fileno", None)
    if callable(fileno):
        return int(fileno())
    sock = getattr(inner, "socket", None)
    if sock is not None and callable(getattr(sock, "fileno", None)):
        return int(sock.fileno())
    return None


@dataclass
class LoopStats:
    wakeups: int = 0
    frames: int = 0
    spin_errors: int = 0


class NodeLoop:
    """Drives ``node`` (whose driver is a :class:`FrameGate`) from the running asyncio loop.

    ``async with NodeLoop(node) as nl: ...`` or ``nl.start()`` / ``nl.stop()``, both from inside the loop. The node
    is not closed by :meth:`stop`. ``drops`` (the gate's counter) has the counts; :meth:`snapshot` returns them.
    """

    def __init__(self, node: Any, *, max_frames_per_wakeup: int = 128, max_idle: float = 0.1,
                 poll_interval: float = 0.002, log_interval: float = 10.0, logger: logging.Logger | None = None
                 ) -> None:
        gate = node.can_driver
        if not isinstance(gate, FrameGate):
            raise TypeError(f"NodeLoop needs a node whose driver is a FrameGate, got {type(gate).__name__}: create "
                            f"it with sam_runtime.dronecan_io.make_node() or Node(FrameGate(driver), ...)")
        self.node = node
        self.gate = gate
        self.drops: DropCounter = gate.drops
        self.stats = LoopStats()
        self._batch = max_frames_per_wakeup
        self._max_idle = max_idle
        self._poll_interval = poll_interval
        self._log = DropLog(log_interval, logger=logger or _log)
        self._loop: asyncio.AbstractEventLoop | None = None
        self._fd: int | None = None
        self._timer: asyncio.TimerHandle | None = None
        self._timer_when = 0.0
        self._soon: asyncio.Handle | None = None

    # -- lifetime -----------------------------------------------------------------------------------------------

    def start(self) -> None:
        if self._loop is not None:
            raise RuntimeError("NodeLoop already started")
        logging.getLogger("dronecan.node").addFilter(_handler_error_filter)  # idempotent
        self._loop = asyncio.get_running_loop()
        self.drops.add_listener(self._on_drop)
        self._fd = watchable_fd(self.gate)
        if self._fd is not None:
            self._loop.add_reader(self._fd, self._service)
        else:
            self._max_idle = min(self._max_idle, self._poll_interval)
        self.wake()

    def stop(self) -> None:
        if self._loop is None:
            return
        if self._fd is not None:
            self._loop.remove_reader(self._fd)
        for handle in (self._timer, self._soon):
            if handle is not None:
                handle.cancel()
        self._timer = self._soon = None
        self.drops.remove_listener(self._on_drop)
        self._log.flush(force=True)
        self._loop = None

    async def __aenter__(self) -> NodeLoop:
        self.start()
        return self

    async def __aexit__(self, *_exc: object) -> None:
        self.stop()

    @property
    def running(self) -> bool:
        return self._loop is not None

    def wake(self) -> None:
        """Run the node soon (after code outside a handler has called ``node.request``, ``defer``, ...)."""
        if self._loop is not None and self._soon is None:
            self._soon = self._loop.call_soon(self._service)

    def snapshot(self) -> dict[str, int]:
        """Drop counts by reason (see :class:`~.drops.DropReason`)."""
        return self.drops.snapshot()

    # -- handlers -----------------------------------------------------------------------------------------------

    def add_handler(self, dronecan_type: Any, handler: Callable[..., Any], **kwargs: Any) -> Any:
        """``node.add_handler`` whose exceptions are counted as ``handler_error`` (returns dronecan's remover).

        A message handler's return value is ignored (dronecan raises if it is not None); a service handler
        returns the response as with dronecan.
        """
        name = getattr(handler, "__qualname__", repr(handler))
        is_service = dronecan_type.kind == dronecan_type.KIND_SERVICE

        def guarded(event: Any, **kw: Any) -> Any:
            try:
                result = handler(event, **kw)
            except Exception as ex:
                raise HandlerError(f"{name}: {type(ex).__name__}: {ex}") from ex
            return result if is_service else None

        return self.node.add_handler(dronecan_type, guarded, **kwargs)

    # -- the work -----------------------------------------------------------------------------------------------

    def _service(self) -> None:
        self._soon = None
        if self._loop is None:
            return
        self.stats.wakeups += 1
        self.gate.limit_batch(self._batch)
        try:
            # A spin(0) that raises has consumed the failing frame (or run the failing callback); the next call
            # goes on from there. Bounded: every failing call took a frame out of the batch or ran a due event.
            for _ in range(self._batch + 8):
                try:
                    self.stats.frames += self._spin()
                    break
                except Exception as ex:
                    self._count_spin_error(ex)
        finally:
            self.gate.limit_batch(None)
        if self.gate.has_ready_frames():
            self.wake()
        self._arm_timer()

    def _spin(self) -> int:
        """``node.spin(0)``: every frame there is, then the scheduler's due events, but the scheduler only when an
        event is due. dronecan's spin(0) runs its scheduler (the stdlib's, a lock and a clock reading) at every
        call: at every wake-up of the loop, hundreds a second under traffic, for a NodeStatus a second. The frames
        go to dronecan's own per-frame entry (its private ``_recv_frame``, what spin(0) calls); a node without it
        is spun as before."""
        node = self.node
        recv_frame = getattr(node, "_recv_frame", None)
        if recv_frame is None:
            return int(node.spin(0))
        receive, count = self.gate.receive, 0
        while True:
            frame = receive(0)
            if not frame:
                break
            recv_frame(frame)
            count += 1
        due = self._next_scheduler_deadline()
        if due is None or due <= time.monotonic():  # (None: no readable queue, let dronecan look)
            node._poll_scheduler_and_get_next_deadline()
        return count

    def _on_timer(self) -> None:
        self._timer = None
        self._service()
        if self.gate.drained:
            self.gate.sweep()
        self._log.flush()

    def _arm_timer(self) -> None:
        assert self._loop is not None
        now = time.monotonic()
        when = now + self._max_idle
        deadline = self._next_scheduler_deadline()
        if deadline is not None:
            when = min(when, deadline)
        if self._timer is not None:
            if self._timer_when <= when + 1e-4:
                return
            self._timer.cancel()
        self._timer_when = when
        self._timer = self._loop.call_later(max(0.0, when - now), self._on_timer)

    def _next_scheduler_deadline(self) -> float | None:
        # dronecan's Node is a Scheduler around a stdlib sched.scheduler (clock: time.monotonic) that it keeps in
        # the private `_scheduler`; it has no public "next deadline". Without it the timer falls back to max_idle.
        sched = getattr(self.node, "_scheduler", None)
        # Its heap (the stdlib scheduler's `_queue`): the earliest event first. Read at every wake-up of the loop,
        # where `queue` (a sorted copy of the heap, of named tuples) cost more than the rest of the timer's work.
        heap = getattr(sched, "_queue", None)
        if isinstance(heap, list):
            try:
                return float(heap[0].time) if heap else None
            except (IndexError, AttributeError):  # emptied by another thread meanwhile; another layout
                pass
        try:
            queue = sched.queue  # type: ignore[union-attr]
        except AttributeError:
            return None
        return float(queue[0].time) if queue else None

    def _count_spin_error(self, ex: Exception) -> None:
        self.stats.spin_errors += 1
        frame = self.gate.last_frame
        reason = classify_spin_error(ex, frame is not None)
        ident = V0Id.parse(frame.id) if frame is not None else None
        self.drops.add(reason, data_type_id=ident.data_type_id if ident else None,
                       source_node_id=ident.source_node_id if ident else None, detail=f"{type(ex).__name__}: {ex}")

    def _on_drop(self, key: DropKey, detail: str) -> None:
        self._log.report(key, detail if len(detail) <= _DETAIL_MAX else detail[:_DETAIL_MAX] + "...")


def close_node(loop: NodeLoop | None, node: Any, logger: logging.Logger, what: str) -> None:
    """Stop a node's NodeLoop, then close the node; never raises (a dead driver may refuse to close cleanly: logged
    as ``<what>: ...``)."""
    try:
        if loop is not None:
            loop.stop()
        if node is not None:
            node.close()
    except Exception as ex:
        logger.warning("%s: %s: %s", what, type(ex).__name__, ex)
