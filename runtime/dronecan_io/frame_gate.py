"""A driver wrapper that lets only whole UAVCAN v0 transfers through to a dronecan Node, and counts the rest.

dronecan's Node silently ignores some frames (11-bit ids, empty frames, a frame whose transfer never started) and
keeps a multi-frame transfer whose last frame never comes for ever (its ``remove_inactive_transfers`` is never
called, and fails when it has something to remove). A Cyphal v1 first frame (toggle bit set) makes its ``spin()``
raise a toggle error. :class:`FrameGate` sits between the CAN driver and the node:

- frames dronecan would ignore, and Cyphal v1 frames, are counted under their :class:`~.drops.DropReason` and not
  passed on;
- the frames of a multi-frame v0 transfer are held until its last frame arrives and then passed on together, so
  dronecan never holds a partial transfer; one that does not end within ``transfer_timeout`` (or is restarted by a
  new first frame with the same CAN id and transfer id after :data:`RESTART_AFTER_S` without a frame) is counted as
  ``incomplete_transfer``. A frame that cannot be the transfer's next one (its toggle bit, or a first frame while
  the transfer is live) is counted and dropped alone: frames with a device's node id from another sender must not
  spoil the device's transfer (issue 29);
- completed transfers of the data types in :attr:`taps` (the bridge's wire path, :mod:`.wire`) go to their
  handlers as payload bytes instead of to the node;
- :meth:`limit_batch` bounds how many frames one ``node.spin(0)`` takes, so an event loop stays responsive under a
  flood, and :attr:`last_frame` tells which frame a ``spin()`` exception came from.

Toggle, CRC and data type errors of the transfers that are passed on are dronecan's to find (it raises
``TransferError``; :class:`~.node_loop.NodeLoop` counts them).
"""

from __future__ import annotations

import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass

from dronecan.driver.common import AbstractDriver, CANFrame

from sam_runtime.dronecan_io.can_id import TAIL_EOT, TAIL_SOT, TAIL_TID, TAIL_TOGGLE, V0Id
from sam_runtime.dronecan_io.drops import DropCounter, DropReason
from sam_runtime.dronecan_io.wire import TransferTaps

__all__ = ["FrameGate"]

# The largest v0 transfer dronecan can decode is a few hundred bytes (about 50 classic frames); far more than that
# under one key is a broken sender, not a transfer.
MAX_FRAMES_PER_TRANSFER = 512
# A multi-frame transfer whose next frame has not come for this long is abandoned by its sender (its frames are sent
# back to back), so that a new first frame under its key starts a new transfer; a younger one is kept.
RESTART_AFTER_S = 0.1


@dataclass
class _Partial:
    frames: list[CANFrame]
    last_seen: float


class FrameGate(AbstractDriver):
    """Wraps the dronecan driver ``inner``: ``Node(FrameGate(driver), node_id=...)``.

    Drops are counted in ``drops`` (by default the inner driver's own counter if it has one, so that one snapshot
    has both). ``max_partial_transfers`` bounds the memory a sender of endless first frames can take.
    """

    def __init__(self, inner: AbstractDriver, *, drops: DropCounter | None = None, transfer_timeout: float = 2.0,
                 max_partial_transfers: int = 4096, clock: Callable[[], float] = time.monotonic) -> None:
        super().__init__()
        self.inner = inner
        inner_drops = getattr(inner, "drops", None)
        if drops is None:
            drops = inner_drops if isinstance(inner_drops, DropCounter) else DropCounter()
        self.drops: DropCounter = drops
        self.transfer_timeout = transfer_timeout
        self._max_partial = max_partial_transfers
        self._clock = clock
        self._ready: deque[CANFrame] = deque()
        self._partial: dict[tuple[int, int], _Partial] = {}
        self._v1: dict[tuple[int, int], float] = {}
        self._budget: int | None = None
        self.last_frame: CANFrame | None = None
        # The last receive() found the driver empty (not just a batch limit): held transfers are really waiting.
        self.drained = False
        # The wire path: completed transfers of the tapped data types go to their handlers, not to dronecan.
        self.taps: TransferTaps | None = None
        # Frames read and not passed on: every one counted under a drop reason (a whole incomplete transfer is one
        # drop of its reason but all its frames here).
        self.frames_dropped = 0

    def __repr__(self) -> str:
        return f"FrameGate({self.inner!r})"

    # -- the dronecan driver interface --------------------------------------------------------------------------

    def add_io_hook(self, hook):  # dronecan's signature
        return self.inner.add_io_hook(hook)

    def send_frame(self, frame: CANFrame) -> None:
        self.inner.send_frame(frame)

    def close(self) -> None:
        self.inner.close()

    def receive(self, timeout: float | None = None) -> CANFrame | None:
        # receive(0), dronecan's spin(0) from a NodeLoop, per frame of the bus: no clock reading for a deadline
        drain = timeout is not None and timeout <= 0
        deadline = None if timeout is None or drain else self._clock() + timeout
        inner, ready = self.inner, self._ready
        while True:
            if self._budget is not None and self._budget <= 0:
                self.last_frame = None
                return None
            if ready:
                frame: CANFrame | None = ready.popleft()
            else:
                left = 0.0 if drain else None if deadline is None else max(0.0, deadline - self._clock())
                raw = inner.receive(left)
                if raw is None:
                    self.last_frame = None
                    self.drained = True
                    return None
                self.drained = False
                if self._budget is not None:
                    self._budget -= 1
                frame = self._admit(raw)
                if frame is None:
                    continue
            self.last_frame = frame
            return frame

    # -- for the event loop -------------------------------------------------------------------------------------

    def limit_batch(self, frames: int | None) -> None:
        """From now on :meth:`receive` takes at most ``frames`` frames from the driver and then returns None
        (``None``: no limit)."""
        self._budget = frames

    def has_ready_frames(self) -> bool:
        """Frames of completed transfers are waiting: call ``spin(0)`` again even if the driver's fd is quiet."""
        return bool(self._ready)

    def sweep(self) -> None:
        """Count and forget multi-frame transfers whose next frame is overdue. Call it when :attr:`drained`: a
        frame still in the driver is not overdue, however long this process was kept from reading it."""
        now = self._clock()
        stale = [k for k, p in self._partial.items() if now - p.last_seen > self.transfer_timeout]
        for key in stale:
            self._drop_partial(key, f"no frame for {now - self._partial[key].last_seen:.1f} s")
        for key in [k for k, t in self._v1.items() if now - t > self.transfer_timeout]:
            del self._v1[key]

    @property
    def partial_transfers(self) -> int:
        return len(self._partial)

    # -- classification -----------------------------------------------------------------------------------------

    def _admit(self, frame: CANFrame) -> CANFrame | None:
        """The frame to pass on now, or None (held as part of a transfer, or counted as a drop)."""
        if not frame.extended:
            self.frames_dropped += 1
            self.drops.add(DropReason.NOT_EXTENDED_ID, detail=f"11-bit frame 0x{frame.id:03x}")
            return None
        data = frame.data
        if not data:
            self._drop(DropReason.EMPTY_FRAME, frame, "frame without a tail byte")
            return None
        tail = data[-1]  # (the bits of can_id.Tail, read inline: this runs for every frame of the bus)
        end = tail & TAIL_EOT
        key = (frame.id, tail & TAIL_TID)
        if tail & TAIL_SOT:
            if end and not tail & TAIL_TOGGLE and not self._partial:  # a single-frame v0 transfer, nothing held
                return None if self.taps is not None and self.taps.take([frame]) else frame
            now = self._clock()
            if tail & TAIL_TOGGLE:
                self._drop(DropReason.CYPHAL_V1_FRAME, frame, "first frame with the toggle bit set (Cyphal v1)")
                if not end:
                    self._v1[key] = now
                return None
            held = self._partial.get(key)
            if held is not None:
                if now - held.last_seen <= RESTART_AFTER_S:
                    # A transfer's frames come back to back: a first frame under the key of a live transfer is
                    # not the device's (a hostile sender's, issue 29), and must not end the real one.
                    self._drop(DropReason.FRAME_SEQUENCE_ERROR, frame, "first frame under the key of a live transfer")
                    return None
                self._drop_partial(key, "restarted by a new first frame")
            if end:
                return None if self.taps is not None and self.taps.take([frame]) else frame
            if len(self._partial) >= self._max_partial:
                self._drop_partial(next(iter(self._partial)), "too many unfinished transfers")
            self._partial[key] = _Partial([frame], now)
            return None
        now = self._clock()
        partial = self._partial.get(key)
        if partial is not None:
            if bool(tail & TAIL_TOGGLE) != (len(partial.frames) & 1 == 1):
                # Not the next frame of the transfer (its toggle bit alternates from 0): a repeat, or another
                # sender's; dropped alone, so that the transfer's own frames still make it whole (issue 29).
                self._drop(DropReason.TOGGLE_ERROR, frame, "frame with the wrong toggle bit for its transfer")
                return None
            partial.frames.append(frame)
            partial.last_seen = now
            if end:
                del self._partial[key]
                if self.taps is not None and self.taps.take(partial.frames):
                    return None
                self._ready.extend(partial.frames[1:])
                return partial.frames[0]
            if len(partial.frames) > MAX_FRAMES_PER_TRANSFER:
                self._drop_partial(key, f"more than {MAX_FRAMES_PER_TRANSFER} frames")
            return None
        if key in self._v1:
            self._drop(DropReason.CYPHAL_V1_FRAME, frame, "frame of a Cyphal v1 transfer")
            if end:
                del self._v1[key]
            else:
                self._v1[key] = now
            return None
        self._drop(DropReason.ORPHAN_FRAME, frame, "frame of a transfer whose first frame was not seen")
        return None

    def _drop(self, reason: DropReason, frame: CANFrame, detail: str) -> None:
        self.frames_dropped += 1
        ident = V0Id.parse(frame.id)
        self.drops.add(reason, data_type_id=ident.data_type_id, source_node_id=ident.source_node_id,
                       detail=f"{detail}: id 0x{frame.id:08x} data {bytes(frame.data).hex()}")

    def _drop_partial(self, key: tuple[int, int], why: str) -> None:
        partial = self._partial.pop(key)
        self.frames_dropped += len(partial.frames) - 1  # (_drop counts one)
        self._drop(DropReason.INCOMPLETE_TRANSFER, partial.frames[0],
                   f"multi-frame transfer {why} after {len(partial.frames)} frames")
