"""A robot's pose from the TF tree of its bag, vectorised over time with numpy.

Real robots say where they are through TF: ``/tf`` carries the dynamic transforms, each at its own rate
(odom → base_link from the wheel odometry at 50 Hz, map → odom from AMCL or SLAM at 10-20 Hz), and
``/tf_static`` the fixed ones (base_link → laser), latched and sent once. The pose of ``base_link`` in
``map`` is the composition along the tree, map → odom → base_link, with each edge interpolated at the
query times. This module does that for whole arrays of times at once; it reads no files: the caller
hands it decoded columns, one :class:`EdgeSeries` per (parent, child) pair.

Conventions are ROS's: a transform from ``parent`` to ``child`` is the pose of ``child`` in ``parent``
(translation = the child's origin in parent coordinates; rotation = a quaternion ``x, y, z, w``), and a
pose composes as "rotate, then translate". Frame ids lose a leading ``/``, as tf2 does (ROS 1 bags often
carry ``/map`` next to ``map``).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from exsce_dsl.errors import TfError
from exsce_dsl.suggest import did_you_mean

MAX_EXTRAPOLATION = 0.5
"""Seconds a transform's first or last value is held outside its data (see :func:`pose_at`)."""

MAX_GAP = 1.0
"""Seconds between two samples of a transform beyond which it is not interpolated (a dropped stream)."""

_NLERP_ANGLE = 1e-6
"""Below this angle between two quaternions slerp's weights divide by ~0: blend linearly instead."""

_CONJUGATE = np.array([-1.0, -1.0, -1.0, 1.0])
_IDENTITY = np.array([0.0, 0.0, 0.0, 1.0])


def _frame(name: str) -> str:
    return name[1:] if name.startswith("/") else name


def _read_only(array: np.ndarray) -> np.ndarray:
    array.setflags(write=False)
    return array


@dataclass(frozen=True, eq=False)
class EdgeSeries:
    """The transforms from ``parent`` to ``child`` over a run.

    Constructing one cleans the data once, so that everything downstream may assume it: rows with a
    non-finite value or a zero quaternion are dropped, rows are sorted by time (of rows with the same
    stamp the last one given is kept), quaternions are normalised and made sign-continuous (``q`` and
    ``-q`` are the same rotation; consecutive quaternions are flipped to have a non-negative dot
    product, so interpolation takes the short way round). The arrays are read-only copies.

    A static edge (from ``/tf_static``) holds at every time; its last row is its value.
    """

    parent: str
    child: str
    times: np.ndarray
    """Seconds (float64), the transforms' header stamps, shape (n,)."""
    translation: np.ndarray
    """The child's origin in the parent frame, shape (n, 3)."""
    rotation: np.ndarray
    """Quaternions ``x, y, z, w``, shape (n, 4)."""
    static: bool = False

    def __post_init__(self) -> None:
        parent, child = _frame(self.parent), _frame(self.child)
        if not parent or not child:
            raise TfError(f"a transform with an empty frame id: parent '{self.parent}', child '{self.child}'")
        if parent == child:
            raise TfError(f"a transform from frame '{parent}' to itself")
        times = np.asarray(self.times, dtype=np.float64)
        translation = np.asarray(self.translation, dtype=np.float64)
        rotation = np.asarray(self.rotation, dtype=np.float64)
        n = len(times) if times.ndim == 1 else -1
        if n < 0 or translation.shape != (n, 3) or rotation.shape != (n, 4):
            raise TfError(
                f"transform {parent} → {child}: expected times (n,), translation (n, 3) and rotation (n, 4), "
                f"got {times.shape}, {translation.shape} and {rotation.shape}"
            )
        norm = _norm(rotation)
        keep = (
            np.isfinite(times)
            & np.isfinite(translation).all(axis=1)
            & np.isfinite(rotation).all(axis=1)
            & (norm > 1e-12)
        )
        if not keep.all():
            times, translation, rotation, norm = times[keep], translation[keep], rotation[keep], norm[keep]
        rotation = rotation / norm[:, None]
        if len(times) > 1 and not np.all(times[1:] >= times[:-1]):  # a stable sort of sorted rows keeps them
            order = np.argsort(times, kind="stable")
            times, translation, rotation = times[order], translation[order], rotation[order]
        if len(times) > 1:  # the gathers copy the caller's arrays
            last_of_stamp = np.append(times[1:] != times[:-1], True)
            times, translation = times[last_of_stamp], translation[last_of_stamp]
            rotation = rotation[last_of_stamp]
        else:
            times, translation = times.copy(), translation.copy()
        if len(rotation) > 1:
            dots = np.einsum("ij,ij->i", rotation[1:], rotation[:-1])
            rotation[1:] *= np.cumprod(np.where(dots < 0.0, -1.0, 1.0))[:, None]
        object.__setattr__(self, "parent", parent)
        object.__setattr__(self, "child", child)
        object.__setattr__(self, "times", _read_only(times))
        object.__setattr__(self, "translation", _read_only(translation))
        object.__setattr__(self, "rotation", _read_only(rotation))

    @property
    def name(self) -> str:
        """``parent → child``, for messages."""
        return f"{self.parent} → {self.child}"


@dataclass(frozen=True)
class Chain:
    """The edges that lead from frame ``fixed`` to frame ``body``.

    From ``fixed`` the chain climbs to the nearest ancestor the two frames share (``up``: each edge
    applied inverted), then descends to ``body`` (``down``). When ``fixed`` is an ancestor of ``body``,
    ``up`` is empty.
    """

    fixed: str
    body: str
    up: tuple[EdgeSeries, ...]
    """Edges from ``fixed`` up to the common ancestor, the one into ``fixed`` first; applied inverted."""
    down: tuple[EdgeSeries, ...]
    """Edges from the common ancestor down to ``body``, in order."""

    @property
    def edges(self) -> tuple[EdgeSeries, ...]:
        return self.up + self.down

    @property
    def steps(self) -> tuple[tuple[EdgeSeries, bool], ...]:
        """Each edge with whether it is applied inverted, in the order they compose."""
        return tuple((e, True) for e in self.up) + tuple((e, False) for e in self.down)


class FrameTree:
    """The TF tree of a run: each frame's parent, and the edge that links them.

    A frame with two parents, a transform given twice and a cycle are errors (tf2 has the same rule:
    each frame has one parent); all of them are reported together.
    """

    def __init__(self, edges: Iterable[EdgeSeries]) -> None:
        self._edge: dict[str, EdgeSeries] = {}
        problems: list[str] = []
        for edge in edges:
            known = self._edge.get(edge.child)
            if known is None:
                self._edge[edge.child] = edge
            elif known.parent == edge.parent:
                kinds = " and ".join(sorted({_kind(known), _kind(edge)}))
                problems.append(f"the transform {edge.name} is given twice ({kinds})")
            else:
                problems.append(
                    f"frame '{edge.child}' has two parents, '{known.parent}' and '{edge.parent}'"
                    " (in TF each frame has one parent)"
                )
        problems.extend(f"the frames {' → '.join(cycle)} form a cycle" for cycle in self._cycles())
        if problems:
            raise TfError("the TF data is not a tree: " + "; ".join(problems))
        self._children: dict[str, list[str]] = {}
        for child, edge in sorted(self._edge.items()):
            self._children.setdefault(edge.parent, []).append(child)
        self._frames = tuple(sorted(set(self._edge) | set(self._children)))

    @property
    def frames(self) -> tuple[str, ...]:
        """Every frame named by an edge, sorted."""
        return self._frames

    @property
    def edges(self) -> tuple[EdgeSeries, ...]:
        return tuple(self._edge[child] for child in sorted(self._edge))

    def parent_of(self, frame: str) -> str | None:
        """The frame's parent; None for a root."""
        frame = _frame(frame)
        self._require(frame)
        edge = self._edge.get(frame)
        return edge.parent if edge else None

    def chain(self, fixed: str, body: str) -> Chain:
        """The edges from ``fixed`` to ``body`` (see :class:`Chain`)."""
        fixed, body = _frame(fixed), _frame(body)
        self._require(fixed, body)
        from_fixed, from_body = self._ancestry(fixed), self._ancestry(body)
        shared = set(from_body)
        common = next((frame for frame in from_fixed if frame in shared), None)
        if common is None:
            raise TfError(
                f"frames '{fixed}' and '{body}' are not connected in TF: '{fixed}' is in the tree of "
                f"'{from_fixed[-1]}' and '{body}' in the tree of '{from_body[-1]}'. {self._overview()}"
            )
        up = tuple(self._edge[f] for f in from_fixed[: from_fixed.index(common)])
        down = tuple(self._edge[f] for f in reversed(from_body[: from_body.index(common)]))
        return Chain(fixed, body, up, down)

    def outline(self) -> str:
        """Each tree on one line, e.g. ``map → odom → base_link → {imu, laser}``."""
        roots = [frame for frame in self._frames if frame not in self._edge]
        return "; ".join(self._outline(root) for root in roots)

    def _outline(self, frame: str) -> str:
        children = self._children.get(frame, [])
        if not children:
            return frame
        if len(children) == 1:
            return f"{frame} → {self._outline(children[0])}"
        return f"{frame} → {{{', '.join(self._outline(c) for c in children)}}}"

    def _overview(self) -> str:
        if not self._frames:
            return "The TF data has no transforms."
        trees = self.outline()
        separate = " (separate trees)" if "; " in trees else ""
        return f"The TF data has frames {', '.join(self._frames)}, connected as{separate}: {trees}"

    def _require(self, *frames: str) -> None:
        missing = [
            f"no frame '{f}' in the TF data{did_you_mean(f, self._frames)}"
            for f in frames
            if f not in self._frames
        ]
        if missing:
            text = "; ".join(missing)
            raise TfError(f"{text}{'' if text.endswith('?') else '.'} {self._overview()}")

    def _ancestry(self, frame: str) -> list[str]:
        """``frame``, its parent, its grandparent... up to its root."""
        path = [frame]
        while path[-1] in self._edge:
            path.append(self._edge[path[-1]].parent)
        return path

    def _cycles(self) -> list[tuple[str, ...]]:
        found: set[tuple[str, ...]] = set()
        cleared: set[str] = set()  # frames whose ancestry ends at a root
        for start in self._edge:
            path: list[str] = []
            frame: str | None = start
            while frame is not None and frame not in cleared and frame not in path:
                path.append(frame)
                edge = self._edge.get(frame)
                frame = edge.parent if edge else None
            if frame is not None and frame in path:
                cycle = path[path.index(frame) :][::-1]  # walked child → parent; said parent → child
                turn = cycle.index(min(cycle))  # one spelling per cycle, wherever the walk entered it
                found.add(tuple(cycle[turn:] + cycle[:turn] + [cycle[turn]]))
                continue
            cleared.update(path)
        return sorted(found)


def _kind(edge: EdgeSeries) -> str:
    return "static" if edge.static else "dynamic"


@dataclass(frozen=True, eq=False)
class Poses:
    """A frame's pose in another frame at given times.

    Where ``valid`` is False (an edge has no data near that time) the position, quaternion and yaw
    are NaN. Quaternions are ``x, y, z, w``, normalised and sign-continuous over the valid samples,
    the first of them with ``w >= 0``.
    """

    times: np.ndarray
    position: np.ndarray
    """Shape (n, 3)."""
    yaw: np.ndarray
    """Radians in [-π, π], shape (n,)."""
    quaternion: np.ndarray
    """Shape (n, 4)."""
    valid: np.ndarray
    """Bool, shape (n,)."""


def pose_at(
    tree: FrameTree,
    fixed: str,
    body: str,
    times: ArrayLike,
    *,
    max_extrapolation: float = MAX_EXTRAPOLATION,
    max_gap: float = MAX_GAP,
) -> Poses:
    """The pose of frame ``body`` in frame ``fixed`` at each of ``times`` (seconds, the bag's stamps).

    Each edge of the chain is interpolated at the times (translation linearly, rotation by slerp along
    the shorter arc), a static edge is constant, and the edges are composed in order.

    Outside an edge's data its first or last value is held, but only for ``max_extrapolation``
    seconds; beyond that the pose is invalid. Some holding is needed because the streams do not start
    and stop together: map → odom from AMCL is published at the laser's rate and only once its first
    scan has been processed, so the first odometry samples of a run come before it, and at the end of
    a recording each stream stops at its own moment. The correction map → odom changes slowly, so half
    a second of holding costs at most half a second of its drift (centimetres), while holding longer
    would invent poses the robot never reported. Pass 0 for tf2's rule (no extrapolation at all).

    Between two samples more than ``max_gap`` seconds apart (a dropped stream) nothing is interpolated:
    the pose is invalid strictly inside such a gap; the samples on either side are valid.
    """
    _check_limits(max_extrapolation, max_gap)
    at = np.asarray(times, dtype=np.float64)
    if at.ndim != 1:
        raise TfError(f"pose times must be a 1-D array of seconds, got shape {at.shape}")
    chain = tree.chain(fixed, body)
    n = len(at)
    position = np.zeros((n, 3))
    quaternion = np.tile(_IDENTITY, (n, 1))
    valid = np.isfinite(at)
    for edge, inverted in chain.steps:
        translation, rotation, known = _sample(edge, at, max_extrapolation, max_gap)
        if inverted:
            rotation = rotation * _CONJUGATE
            translation = -_rotate(rotation, translation)
        position = position + _rotate(quaternion, translation)
        quaternion = _multiply(quaternion, rotation)
        valid &= known
    quaternion /= _norm(quaternion)[:, None]
    _make_continuous(quaternion, valid)
    position[~valid] = np.nan
    quaternion[~valid] = np.nan
    return Poses(
        times=_read_only(at.copy()),
        position=_read_only(position),
        yaw=_read_only(yaw_from_quaternion(quaternion)),
        quaternion=_read_only(quaternion),
        valid=_read_only(valid),
    )


def default_times(
    tree: FrameTree, fixed: str, body: str, *, max_extrapolation: float = MAX_EXTRAPOLATION
) -> np.ndarray:
    """The natural times to sample ``body`` in ``fixed`` at: the stamps of the chain's fastest dynamic
    edge (the shortest median interval), within the span where every edge has data (each end widened
    by ``max_extrapolation``, as :func:`pose_at` holds values that long). Gaps inside the span stay;
    :func:`pose_at` marks them invalid.
    """
    _check_limits(max_extrapolation, MAX_GAP)
    chain = tree.chain(fixed, body)
    empty = [edge.name for edge in chain.edges if len(edge.times) == 0]
    if empty:
        raise TfError(
            f"no usable transforms {', '.join(empty)} in the TF data, between '{fixed}' and '{body}'"
        )
    dynamic = [edge for edge in chain.edges if not edge.static]
    if not dynamic:
        raise TfError(
            f"every transform between '{fixed}' and '{body}' is static, so the pose never changes and has "
            "no natural sample times: give the times yourself"
        )
    start = max(float(edge.times[0]) for edge in dynamic) - max_extrapolation
    end = min(float(edge.times[-1]) for edge in dynamic) + max_extrapolation
    fastest = min(dynamic, key=_median_interval)
    found = fastest.times[(fastest.times >= start) & (fastest.times <= end)]
    if len(found) == 0:
        spans = ", ".join(f"{e.name} {e.times[0]:.3f}–{e.times[-1]:.3f} s" for e in dynamic)
        raise TfError(f"the transforms between '{fixed}' and '{body}' never overlap in time: {spans}")
    return found.copy()


def yaw_from_quaternion(quaternion: np.ndarray) -> np.ndarray:
    """The yaw (rotation about z, radians in [-π, π]) of quaternions ``x, y, z, w``, shape (n, 4)."""
    x, y, z, w = quaternion[:, 0], quaternion[:, 1], quaternion[:, 2], quaternion[:, 3]
    yaw: np.ndarray = np.arctan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
    return yaw


def _check_limits(max_extrapolation: float, max_gap: float) -> None:
    if not max_extrapolation >= 0.0:
        raise TfError(f"max_extrapolation must be 0 or more seconds, got {max_extrapolation}")
    if not max_gap > 0.0:
        raise TfError(f"max_gap must be more than 0 seconds, got {max_gap}")


def _median_interval(edge: EdgeSeries) -> float:
    return float(np.median(np.diff(edge.times))) if len(edge.times) > 1 else float("inf")


def _sample(
    edge: EdgeSeries, times: np.ndarray, max_extrapolation: float, max_gap: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The edge's translation (n, 3), rotation (n, 4) and whether it is known (n,) at ``times``."""
    n, m = len(times), len(edge.times)
    if m == 0:
        return np.zeros((n, 3)), np.tile(_IDENTITY, (n, 1)), np.zeros(n, dtype=bool)
    if edge.static:
        translation = np.broadcast_to(edge.translation[-1], (n, 3))
        return translation, np.broadcast_to(edge.rotation[-1], (n, 4)), np.ones(n, dtype=bool)
    stamps = edge.times
    after = np.searchsorted(stamps, times, side="right")  # stamps[after - 1] <= time < stamps[after]
    i0 = np.clip(after - 1, 0, m - 1)
    i1 = np.clip(after, 0, m - 1)
    t0, t1 = stamps[i0], stamps[i1]
    span = t1 - t0  # 0 outside the data: both indices at the same end
    inside = span > 0.0
    u = np.zeros(n)
    u[inside] = (times[inside] - t0[inside]) / span[inside]
    known = (
        (stamps[0] - times <= max_extrapolation)
        & (times - stamps[-1] <= max_extrapolation)
        & ~((span > max_gap) & (times > t0))
    )
    p0, p1 = np.take(edge.translation, i0, axis=0), np.take(edge.translation, i1, axis=0)
    translation = p0 + u[:, None] * (p1 - p0)
    # the angle between consecutive quaternions, per interval of the data (m - 1 of them, fewer than the
    # times as a rule); the last entry, 0, serves the times after the data, where i0 = i1
    angles = np.append(_angle_between(edge.rotation[:-1], edge.rotation[1:]), 0.0)
    q0, q1 = np.take(edge.rotation, i0, axis=0), np.take(edge.rotation, i1, axis=0)
    return translation, _slerp(q0, q1, u, np.take(angles, i0)), known


def _angle_between(q0: np.ndarray, q1: np.ndarray) -> np.ndarray:
    """The angle between unit 4-vectors, row by row: accurate also when they nearly coincide (unlike
    arccos of the dot product). For quaternions with a non-negative dot product it is half the angle
    of the rotation from one to the other."""
    angle: np.ndarray = 2.0 * np.arctan2(_norm(q1 - q0), _norm(q1 + q0))
    return angle


def _slerp(q0: np.ndarray, q1: np.ndarray, u: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """Spherical interpolation from ``q0`` (u = 0) to ``q1`` (u = 1), row by row; ``theta`` is the angle
    between them. The quaternions must have a non-negative dot product (``EdgeSeries`` makes consecutive
    ones so): the interpolation then takes the shorter arc."""
    close = theta < _NLERP_ANGLE
    sin_theta = np.where(close, 1.0, np.sin(theta))
    w0 = np.where(close, 1.0 - u, np.sin((1.0 - u) * theta) / sin_theta)
    w1 = np.where(close, u, np.sin(u * theta) / sin_theta)
    q = w0[:, None] * q0 + w1[:, None] * q1
    normalised: np.ndarray = q / _norm(q)[:, None]
    return normalised


def _norm(rows: np.ndarray) -> np.ndarray:
    norm: np.ndarray = np.sqrt(np.einsum("ij,ij->i", rows, rows))
    return norm


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    ax, ay, az = a[:, 0], a[:, 1], a[:, 2]
    bx, by, bz = b[:, 0], b[:, 1], b[:, 2]
    return np.stack([ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx], axis=1)


def _rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Vectors ``v`` (n, 3) rotated by unit quaternions ``q`` (n, 4)."""
    axis = q[:, :3]
    t = 2.0 * _cross(axis, v)
    rotated: np.ndarray = v + q[:, 3:4] * t + _cross(axis, t)
    return rotated


def _multiply(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton products ``a ⊗ b`` of quaternions ``x, y, z, w``, row by row: ``b`` applied first."""
    ax, ay, az, aw = a[:, 0], a[:, 1], a[:, 2], a[:, 3]
    bx, by, bz, bw = b[:, 0], b[:, 1], b[:, 2], b[:, 3]
    return np.stack(
        [
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz,
        ],
        axis=1,
    )


def _make_continuous(quaternion: np.ndarray, valid: np.ndarray) -> None:
    """Flip signs in place so that consecutive valid quaternions point the same way, the first w >= 0."""
    rows = np.flatnonzero(valid)
    if len(rows) == 0:
        return
    q = quaternion[rows]
    dots = np.einsum("ij,ij->i", q[1:], q[:-1])
    first = -1.0 if q[0, 3] < 0.0 else 1.0
    signs = first * np.cumprod(np.concatenate(([1.0], np.where(dots < 0.0, -1.0, 1.0))))
    quaternion[rows] = q * signs[:, None]
