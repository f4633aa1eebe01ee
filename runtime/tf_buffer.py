"""A small TF buffer: the transforms of a frame tree, and lookups chained between any two of its frames.

No wheel provides tf2_ros here, so the nodes keep their own buffer (fed from /tf and /tf_static by
sam_runtime.node_support). Pure Python, no ROS: unit-tested on its own (tests/test_tf_buffer.py).

Conventions (as tf2):
- A transform parent->child is the pose of `child` in `parent`: a point p given in child coordinates is
  ``rotation * p + translation`` in parent coordinates. Rotations are unit quaternions (x, y, z, w).
- ``lookup(target, source)`` is the pose of `source` in `target` (tf2's lookupTransform(target_frame,
  source_frame)), chained through the tree in any direction: up from each frame to their common ancestor.
- Each frame has one parent: a transform to a child with another parent re-parents it (as tf2 does); one that
  would close a loop is refused.
- Static transforms (from /tf_static) never age. A dynamic edge keeps its samples of the last `cache_time_s`
  (measured from its newest sample; the newest is always kept), so a lookup can ask for a past time
  (``time_ns``, interpolated between samples); without it, the newest sample of each edge is used.
- A sample older than the edge's newest is kept in the history (if within the cache) but never replaces it.

Errors are ``TfError`` subclasses with what went wrong in the message: ``TfMissingEdge`` (two frames nothing
connects; ``missing`` names the pair an edge would have to join), ``TfStale`` (an edge older than ``max_age_s``;
``edge`` and ``age_s``), ``TfExtrapolation`` (``time_ns`` outside an edge's samples).
"""

from __future__ import annotations

import bisect
import math
import threading
from dataclasses import dataclass, field

from sam_codegen.model.frames import quat_from_rpy

# quat_from_rpy: the spec's rpy convention, one definition shared with the generator (sam_codegen.model.frames).
__all__ = ["TfBuffer", "TfError", "TfExtrapolation", "TfMissingEdge", "TfStale", "Transform", "quat_from_rpy"]

Vector = tuple[float, float, float]
Quaternion = tuple[float, float, float, float]  # x, y, z, w

IDENTITY: Quaternion = (0.0, 0.0, 0.0, 1.0)
# tf2 refuses quaternions whose squared norm is this far from 1; closer ones are normalised here.
_NORM_TOLERANCE = 1e-3


class TfError(Exception):
    """A transform cannot be stored or looked up."""


class TfMissingEdge(TfError):
    """Two frames are not connected: `missing` is the pair of frames (tree roots) no transform joins."""

    def __init__(self, target: str, source: str, missing: tuple[str, str], message: str) -> None:
        super().__init__(message)
        self.target, self.source, self.missing = target, source, missing


class TfStale(TfError):
    """An edge of the chain is older than allowed: `edge` (parent, child) and its `age_s`."""

    def __init__(self, edge: tuple[str, str], age_s: float, max_age_s: float) -> None:
        super().__init__(f"transform {edge[0]}->{edge[1]} is stale: {age_s:.3f} s old (at most {max_age_s:g} s)")
        self.edge, self.age_s, self.max_age_s = edge, age_s, max_age_s


class TfExtrapolation(TfError):
    """A lookup at a time outside the samples an edge holds."""


# ---- quaternion algebra ----------------------------------------------------------------------------------------


def quat_multiply(a: Quaternion, b: Quaternion) -> Quaternion:
    """The rotation b, then a (Hamilton product a*b).

    >>> quat_multiply(IDENTITY, (0.0, 0.0, 1.0, 0.0))
    (0.0, 0.0, 1.0, 0.0)
    """
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz)


def quat_rotate(q: Quaternion, v: Vector) -> Vector:
    """v rotated by the unit quaternion q.

    >>> [round(c, 12) for c in quat_rotate(quat_from_rpy(0.0, 0.0, math.pi / 2), (1.0, 0.0, 0.0))]
    [0.0, 1.0, 0.0]
    """
    x, y, z, w = q
    vx, vy, vz = v
    # v + 2w(u x v) + 2 u x (u x v), u = (x, y, z)
    cx, cy, cz = y * vz - z * vy, z * vx - x * vz, x * vy - y * vx
    return (vx + 2.0 * (w * cx + y * cz - z * cy),
            vy + 2.0 * (w * cy + z * cx - x * cz),
            vz + 2.0 * (w * cz + x * cy - y * cx))


def quat_conjugate(q: Quaternion) -> Quaternion:
    return (-q[0], -q[1], -q[2], q[3])


def quat_to_rpy(q: Quaternion) -> Vector:
    """(roll, pitch, yaw) of a unit quaternion; pitch in [-pi/2, pi/2].

    >>> [round(a, 9) for a in quat_to_rpy(quat_from_rpy(0.1, -0.2, 3.0))]
    [0.1, -0.2, 3.0]
    """
    x, y, z, w = q
    roll = math.atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))
    pitch = math.asin(max(-1.0, min(1.0, 2.0 * (w * y - z * x))))
    yaw = math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
    return roll, pitch, yaw


def quat_slerp(a: Quaternion, b: Quaternion, f: float) -> Quaternion:
    """Spherical interpolation from a (f = 0) to b (f = 1), the short way round."""
    dot = sum(p * q for p, q in zip(a, b, strict=True))
    if dot < 0.0:
        b, dot = (-b[0], -b[1], -b[2], -b[3]), -dot
    if dot > 0.9995:  # nearly equal: linear, then normalised
        out = tuple(p + f * (q - p) for p, q in zip(a, b, strict=True))
        n = math.sqrt(sum(c * c for c in out))
        return (out[0] / n, out[1] / n, out[2] / n, out[3] / n)
    theta = math.acos(dot)
    s = math.sin(theta)
    wa, wb = math.sin((1.0 - f) * theta) / s, math.sin(f * theta) / s
    return (wa * a[0] + wb * b[0], wa * a[1] + wb * b[1], wa * a[2] + wb * b[2], wa * a[3] + wb * b[3])


# ---- transforms ------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Transform:
    """The pose of `child` in `parent` at `stamp_ns` (a chained one carries the oldest stamp of its dynamic
    edges; 0 when it is made of static edges only)."""

    parent: str
    child: str
    stamp_ns: int
    translation: Vector
    rotation: Quaternion  # x, y, z, w

    @staticmethod
    def identity(frame: str, stamp_ns: int = 0) -> Transform:
        return Transform(frame, frame, stamp_ns, (0.0, 0.0, 0.0), IDENTITY)

    def compose(self, other: Transform) -> Transform:
        """parent->child composed with child->other.child: the pose of other.child in self.parent.

        >>> a = Transform("a", "b", 5, (1.0, 0.0, 0.0), quat_from_rpy(0.0, 0.0, math.pi / 2))
        >>> c = a.compose(Transform("b", "c", 7, (1.0, 0.0, 0.0), IDENTITY))
        >>> c.parent, c.child, c.stamp_ns, [round(v, 12) for v in c.translation]
        ('a', 'c', 5, [1.0, 1.0, 0.0])
        """
        if other.parent != self.child:
            raise ValueError(f"cannot compose {self.parent}->{self.child} with {other.parent}->{other.child}")
        moved = quat_rotate(self.rotation, other.translation)
        translation = (self.translation[0] + moved[0], self.translation[1] + moved[1],
                       self.translation[2] + moved[2])
        return Transform(self.parent, other.child, _older(self.stamp_ns, other.stamp_ns), translation,
                         _normalised(quat_multiply(self.rotation, other.rotation)))

    def inverse(self) -> Transform:
        """The pose of parent in child.

        >>> t = Transform("a", "b", 3, (1.0, 2.0, 3.0), quat_from_rpy(0.3, 0.2, 0.1))
        >>> back = t.compose(t.inverse())
        >>> back.parent, back.child, [round(v, 12) + 0.0 for v in back.translation]
        ('a', 'a', [0.0, 0.0, 0.0])
        """
        rotation = quat_conjugate(self.rotation)
        x, y, z = quat_rotate(rotation, self.translation)
        return Transform(self.child, self.parent, self.stamp_ns, (-x, -y, -z), rotation)

    def apply(self, point: Vector) -> Vector:
        """A point given in child coordinates, in parent coordinates."""
        x, y, z = quat_rotate(self.rotation, point)
        return (x + self.translation[0], y + self.translation[1], z + self.translation[2])

    def rpy(self) -> Vector:
        """(roll, pitch, yaw) of the rotation, radians."""
        return quat_to_rpy(self.rotation)

    def yaw(self) -> float:
        """Heading of child's x axis in parent, counter-clockwise about z from parent's x (REP-103), radians.

        >>> round(Transform("w", "b", 0, (0.0, 0.0, 0.0), quat_from_rpy(0.0, 0.4, 1.2)).yaw(), 12)
        1.2
        """
        return quat_to_rpy(self.rotation)[2]


def _older(a: int, b: int) -> int:
    """The older of two stamps; 0 (a static edge) is timeless."""
    if a == 0 or b == 0:
        return a or b
    return min(a, b)


def _normalised(q: Quaternion) -> Quaternion:
    n = math.sqrt(sum(c * c for c in q))
    return (q[0] / n, q[1] / n, q[2] / n, q[3] / n)


def _check_frame(name: object, strip: bool = False) -> str:
    """A valid frame id; a stored transform may name its frames with ROS 1's leading slash (tf2 strips it), a
    lookup may not (tf2 refuses it)."""
    if strip and isinstance(name, str):
        name = name.removeprefix("/")
    if not isinstance(name, str) or not name:
        raise TfError(f"frame id {name!r} is not a non-empty string")
    if name.startswith("/"):
        raise TfError(f"frame id {name!r} starts with '/': ROS 2 frame ids have no leading slash")
    return name


@dataclass
class _Edge:
    parent: str
    static: bool
    stamps: list[int] = field(default_factory=list)  # ascending
    samples: list[tuple[Vector, Quaternion]] = field(default_factory=list)

    @property
    def newest_ns(self) -> int:
        return self.stamps[-1]

    def at(self, child: str, time_ns: int | None) -> Transform:
        if time_ns is None or self.static:
            i = len(self.stamps) - 1
            stamp = 0 if self.static else self.stamps[i]
            return Transform(self.parent, child, stamp, *self.samples[i])
        i = bisect.bisect_left(self.stamps, time_ns)
        if i < len(self.stamps) and self.stamps[i] == time_ns:
            return Transform(self.parent, child, time_ns, *self.samples[i])
        if i == 0 or i == len(self.stamps):
            raise TfExtrapolation(
                f"transform {self.parent}->{child} is not known at {time_ns * 1e-9:.3f} s: its samples cover "
                f"{self.stamps[0] * 1e-9:.3f} .. {self.stamps[-1] * 1e-9:.3f} s")
        t0, t1 = self.stamps[i - 1], self.stamps[i]
        (p0, q0), (p1, q1) = self.samples[i - 1], self.samples[i]
        f = (time_ns - t0) / (t1 - t0)
        translation = (p0[0] + f * (p1[0] - p0[0]), p0[1] + f * (p1[1] - p0[1]), p0[2] + f * (p1[2] - p0[2]))
        return Transform(self.parent, child, time_ns, translation, quat_slerp(q0, q1, f))


class TfBuffer:
    """The transforms of one frame tree (thread-safe). See the module docstring for the conventions."""

    def __init__(self, cache_time_s: float = 10.0) -> None:
        if not cache_time_s > 0:
            raise ValueError(f"cache_time_s must be positive, not {cache_time_s!r}")
        self.cache_time_s = float(cache_time_s)
        self._edges: dict[str, _Edge] = {}  # child -> its edge from its parent
        self._lock = threading.Lock()
        self.ignored_old = 0  # samples older than an edge's cache window (dropped)
        self.reparented = 0

    # ---- input -------------------------------------------------------------------------------------------------
    def set_transform(self, parent: str, child: str, stamp_ns: int, translation: Vector, rotation: Quaternion,
                      static: bool = False) -> bool:
        """Store the pose of `child` in `parent` (a leading '/' of a frame id is dropped, as tf2 does). Returns
        False when the sample is older than the edge's cache (dropped, counted in ``ignored_old``); raises TfError
        for an empty frame id, a non-finite value, a rotation that is not a unit quaternion (within 1e-3 of
        norm 1: normalised), or an edge that would close a loop."""
        parent, child = _check_frame(parent, strip=True), _check_frame(child, strip=True)
        if parent == child:
            raise TfError(f"transform {parent}->{child} relates a frame to itself")
        values = [*translation, *rotation]
        if len(translation) != 3 or len(rotation) != 4 or not all(math.isfinite(v) for v in values):
            raise TfError(f"transform {parent}->{child} has a non-finite or malformed value: {values}")
        norm2 = sum(c * c for c in rotation)
        if abs(norm2 - 1.0) > _NORM_TOLERANCE:
            raise TfError(f"transform {parent}->{child}: rotation {tuple(rotation)} is not a unit quaternion "
                          f"(squared norm {norm2:.6g})")
        sample = ((float(translation[0]), float(translation[1]), float(translation[2])),
                  _normalised(tuple(float(c) for c in rotation)))  # type: ignore[arg-type]
        stamp_ns = int(stamp_ns)
        with self._lock:
            up = parent
            while up in self._edges:
                up = self._edges[up].parent
                if up == child:
                    raise TfError(f"transform {parent}->{child} would close a loop: {child!r} is an ancestor of "
                                  f"{parent!r}")
            edge = self._edges.get(child)
            if edge is None or edge.parent != parent or edge.static != static:
                if edge is not None:
                    self.reparented += 1
                self._edges[child] = _Edge(parent, static, [stamp_ns], [sample])
                return True
            if static:
                edge.stamps[:], edge.samples[:] = [stamp_ns], [sample]
                return True
            horizon = edge.newest_ns - int(self.cache_time_s * 1e9)
            if stamp_ns < horizon:
                self.ignored_old += 1
                return False
            i = bisect.bisect_left(edge.stamps, stamp_ns)
            if i < len(edge.stamps) and edge.stamps[i] == stamp_ns:
                edge.samples[i] = sample  # a repeated stamp: the latest value wins
            else:
                edge.stamps.insert(i, stamp_ns)
                edge.samples.insert(i, sample)
            horizon = edge.newest_ns - int(self.cache_time_s * 1e9)
            cut = bisect.bisect_left(edge.stamps, horizon)
            if cut:
                del edge.stamps[:cut], edge.samples[:cut]
            return True

    def clear(self) -> None:
        """Forget every transform (e.g. after the clock jumped back: a restarted simulation)."""
        with self._lock:
            self._edges.clear()

    # ---- queries -----------------------------------------------------------------------------------------------
    def frames(self) -> list[str]:
        with self._lock:
            return sorted({*self._edges, *(e.parent for e in self._edges.values())})

    def parent_of(self, frame: str) -> str | None:
        with self._lock:
            edge = self._edges.get(frame)
            return edge.parent if edge else None

    def can_transform(self, target_frame: str, source_frame: str) -> bool:
        try:
            self.lookup(target_frame, source_frame)
        except TfError:
            return False
        return True

    def lookup(self, target_frame: str, source_frame: str, *, now_ns: int | None = None,
               max_age_s: float | None = None, time_ns: int | None = None) -> Transform:
        """The pose of `source_frame` in `target_frame`, chained through the tree.

        With `max_age_s`, every dynamic edge of the chain must be at most that old at `now_ns` (required then)
        or TfStale names the oldest. With `time_ns`, each dynamic edge is interpolated at that time (TfExtrapolation
        outside its samples); otherwise the newest sample of each edge is used.
        """
        if max_age_s is not None and now_ns is None:
            raise ValueError("max_age_s needs now_ns (the current time on the clock the stamps use)")
        target, source = _check_frame(target_frame), _check_frame(source_frame)
        with self._lock:
            up_target, root_target = self._path_up(target)
            up_source, root_source = self._path_up(source)
            if root_target != root_source:
                raise self._missing(target, source, root_target, root_source)
            # Up from each frame to their lowest common ancestor, then down to the other.
            frames_target = [target] + [edge.parent for _, edge in up_target]
            frames_source = [source] + [edge.parent for _, edge in up_source]
            on_source_path = set(frames_source)
            common = next(frame for frame in frames_target if frame in on_source_path)
            edges_target = up_target[:frames_target.index(common)]
            edges_source = up_source[:frames_source.index(common)]
            if max_age_s is not None:
                assert now_ns is not None
                dynamic = [(c, e) for c, e in edges_target + edges_source if not e.static]
                if dynamic:
                    child, edge = min(dynamic, key=lambda ce: ce[1].newest_ns)
                    age = (now_ns - edge.newest_ns) * 1e-9
                    if age > max_age_s:
                        raise TfStale((edge.parent, child), age, max_age_s)
            common_to_target = Transform.identity(common)
            for child, edge in reversed(edges_target):
                common_to_target = common_to_target.compose(edge.at(child, time_ns))
            common_to_source = Transform.identity(common)
            for child, edge in reversed(edges_source):
                common_to_source = common_to_source.compose(edge.at(child, time_ns))
        result = common_to_target.inverse().compose(common_to_source)
        return Transform(target, source, result.stamp_ns, result.translation, result.rotation)

    # ---- internals (under the lock) ----------------------------------------------------------------------------
    def _path_up(self, frame: str) -> tuple[list[tuple[str, _Edge]], str]:
        """The edges from `frame` up to its root (child, edge), and the root."""
        path: list[tuple[str, _Edge]] = []
        while frame in self._edges:
            edge = self._edges[frame]
            path.append((frame, edge))
            frame = edge.parent
        return path, frame

    def _missing(self, target: str, source: str, root_target: str, root_source: str) -> TfMissingEdge:
        def where(frame: str, root: str) -> str:
            if frame == root and frame not in {e.parent for e in self._edges.values()}:
                return f"{frame!r} (unknown: no transform names it)"
            return f"{root!r}" + ("" if frame == root else f" (the root of {frame!r}'s tree)")

        known = sorted({*self._edges, *(e.parent for e in self._edges.values())})
        return TfMissingEdge(
            target, source, (root_target, root_source),
            f"no transform from {source!r} to {target!r}: nothing connects {where(target, root_target)} and "
            f"{where(source, root_source)}; known frames: {', '.join(known) or 'none'}")
