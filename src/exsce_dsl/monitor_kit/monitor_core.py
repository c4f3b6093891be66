"""The metric core that generated monitors call: numpy over whole topics, then per window.

This module imports nothing of exsce: ``exscec generate ros1-monitor`` and
``ros2-monitor`` copy it as it is into the node packages, so the offline
monitors (bags) and the runtime ones (live topics) compute metrics with the
same code.  It runs on Python 3.8 and numpy 1.17 (ROS Noetic) as well: no
``X | Y`` or ``list[...]`` outside annotations.

A topic is its receive times and its decoded fields (dotted paths of the
message definition: ``linear.x``, ``ranges``).  Expressions combine fields
element-wise; a field of another topic is interpolated at the left operand's
times, where both topics have data.  An aggregate is *prepared* once per run
(its per-message values), then reduced over each window: the whole run, a
robot's part of it, each path segment.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Callable, Optional, Tuple, Union

import numpy as np

Number = Union[float, int]  # typing's spelling: this module also runs on ROS Noetic's Python 3.8
PRESENT = "#present"
"""Suffix of the key of a field path's mask: which messages have the array element it picks."""


def expand_topic(pattern: str, namespace: str) -> str:
    """``pattern`` with ``{ns}`` replaced by a robot's namespace; a robot at the root (no
    namespace) leaves no empty level: ``/{ns}/odom`` is then ``/odom``."""
    name = pattern.replace("{ns}", namespace.strip("/"))
    while "//" in name:
        name = name.replace("//", "/")
    return name


@dataclass(frozen=True)
class Signal:
    """Values per message (``v``: n numbers, or n × k for arrays) at sorted times ``t``."""

    t: np.ndarray
    v: np.ndarray


@dataclass(frozen=True)
class Topic:
    """One topic of a run: receive times (seconds, sorted) and fields by dotted path."""

    name: str
    t: np.ndarray
    fields: Mapping[str, np.ndarray] = field(default_factory=dict)

    def __len__(self) -> int:
        return len(self.t)

    def field(self, key: str) -> Signal:
        """The values of a field path (its key); a path that picks array elements has values
        only in the messages that have the element (``KEY#present``)."""
        values = self.fields[key]
        present = self.fields.get(key + PRESENT)
        if present is None or values.ndim > 1:  # rows of arrays keep their place: NaN is no value
            return Signal(self.t, values)
        return Signal(self.t[present], values[present])

    def rows(self, part: slice) -> Topic:
        """The messages ``part`` of the topic (views, no copies)."""
        return Topic(self.name, self.t[part], {k: v[part] for k, v in self.fields.items()})


Operand = Union[Signal, float, int]


# numpy 2 renamed trapz to trapezoid; the ROS distributions ship numpy 1
_trapezoid: Any = getattr(np, "trapezoid", None) or getattr(np, "trapz", None)


def window(t: np.ndarray, start: float, end: float) -> slice:
    """The samples of ``t`` in ``[start, end]``."""
    return slice(int(np.searchsorted(t, start, "left")), int(np.searchsorted(t, end, "right")))


def hold(t: np.ndarray) -> np.ndarray:
    """How long each sample holds: until the next one (the last one, one median period; at most
    two periods, so that a gap in the recording does not count as time spent).  The period is
    the median of the steps that move: samples sharing a time (a burst logged at once, coarse
    stamps) would make the median 0, and every sample hold for no time at all."""
    if len(t) < 2:
        return np.zeros(len(t))
    gaps = np.diff(t)
    moving = gaps[gaps > 0]
    period = float(np.median(moving)) if len(moving) else 0.0
    held: np.ndarray = np.minimum(np.append(gaps, period), 2 * period)
    return held


def _same_clock(a: np.ndarray, b: np.ndarray) -> bool:
    return a is b or (a.shape == b.shape and bool(np.array_equal(a, b)))


def _columns(v: np.ndarray, width: int | None) -> np.ndarray:
    """``v`` shaped to broadcast against arrays of ``width`` elements per message (None: no
    arrays): a number per message as a column, a narrower array widened (see ``widened``)."""
    if width is None:
        return v
    if v.ndim == 1:
        return v[:, None]
    return widened(v, width)


def widened(v: np.ndarray, width: int) -> np.ndarray:
    """An array per message (n × k) as ``width`` elements: cut, or filled with what a message
    lacks, NaN (False for a condition), as rows of different lengths are; two array fields of
    one message need not have the same length (a scan's ranges and its empty intensities)."""
    if v.shape[1] >= width:
        return v[:, :width]
    if v.dtype == np.bool_:
        return np.pad(v, ((0, 0), (0, width - v.shape[1])), constant_values=False)
    wide = v if np.issubdtype(v.dtype, np.floating) else v.astype(np.float64)
    return np.pad(wide, ((0, 0), (0, width - v.shape[1])), constant_values=np.nan)


def combine(func: Callable[..., np.ndarray], *operands: Operand) -> Signal:
    """``func`` element-wise over signals and numbers; signals of other topics are aligned in time
    to the first signal's (linear interpolation, only where both have data)."""
    signals = [o for o in operands if isinstance(o, Signal)]
    base = signals[0]
    t, keep = base.t, slice(None)
    for other in signals[1:]:
        if not _same_clock(base.t, other.t):
            if len(other.t) == 0:
                t = t[:0]
                break
            inside = window(t, float(other.t[0]), float(other.t[-1]))
            t = t[inside]
            offset = keep.start or 0
            keep = slice(offset + inside.start, offset + inside.stop)
    values: list[np.ndarray | Number] = []
    for o in operands:
        if not isinstance(o, Signal):
            values.append(o)
        elif _same_clock(o.t, base.t):
            values.append(o.v[keep])
        else:
            values.append(np.interp(t, o.t, o.v))
    widths = [v.shape[1] for v in values if isinstance(v, np.ndarray) and v.ndim == 2]
    width = max(widths) if widths else None
    shaped = [_columns(v, width) if isinstance(v, np.ndarray) else v for v in values]
    with np.errstate(divide="ignore", invalid="ignore"):
        return Signal(t, np.asarray(func(*shaped)))


def norm(*operands: Operand) -> Signal:
    """The Euclidean norm of the operands, element-wise (``hypot`` for two, as precise as it gets)."""
    if len(operands) == 2:
        return combine(np.hypot, *operands)
    return combine(lambda *vs: np.sqrt(sum(np.square(v) for v in vs)), *operands)


BASELINE = 0.5
"""Seconds over which ``speed`` and ``derivative`` take their differences.  A position with noise
of σ gives speeds off by about σ·√2 / BASELINE (3 cm/s at σ = 1 cm), where differences between
messages 20 ms apart would be off by 0.7 m/s; a turn shortens the chord by (ωB)²/24 of the arc
(under 1 % below 1 rad/s)."""


def _changes(t: np.ndarray, columns: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each time of ``t``: how much each column of ``columns`` (n × k) changes from
    ``BASELINE / 2`` before to ``BASELINE / 2`` after it (values interpolated linearly between
    messages; both ends held within the series), and how long that is."""
    if len(t) == 0:
        return np.zeros(0), np.zeros((0, columns.shape[1]))
    before = np.maximum(t - BASELINE / 2, t[0])
    after = np.minimum(t + BASELINE / 2, t[-1])
    with np.errstate(invalid="ignore"):  # inf - inf: no value
        steps = [np.interp(after, t, c) - np.interp(before, t, c) for c in columns.T]
    return after - before, np.stack(steps, axis=-1)


def speed(*coordinates: Operand) -> Signal:
    """Speed along a path (x, y[, z]) at each message's time: the straight distance between the
    positions ``BASELINE / 2`` before and after, over that time (see ``BASELINE``); no value where
    the series has a single time."""
    path = combine(lambda *vs: np.stack(vs, axis=-1), *coordinates)
    span, steps = _changes(path.t, path.v)
    with np.errstate(divide="ignore", invalid="ignore"):
        moved = np.sqrt(np.square(steps).sum(axis=1))
        return Signal(path.t, np.where(span > 0, moved / np.where(span > 0, span, 1.0), np.nan))


def derivative(values: Signal) -> Signal:
    """d/dt of a number at each message's time, over ``BASELINE`` as ``speed`` is (an angle is
    not unwrapped: a yaw through ±π jumps)."""
    span, steps = _changes(values.t, values.v.reshape(-1, 1))
    with np.errstate(divide="ignore", invalid="ignore"):
        return Signal(values.t, np.where(span > 0, steps[:, 0] / np.where(span > 0, span, 1.0), np.nan))


def constant_norm(*values: float) -> float:
    return math.sqrt(sum(v * v for v in values))


@dataclass(frozen=True)
class Prepared:
    """An aggregate's per-message values over a whole run: NaN where a message has none.

    For an array aggregated by ``mean``, ``count`` holds how many elements each
    message contributed (``v`` their sum); ``extra`` holds the further
    coordinates of ``path_length``.
    """

    func: str
    t: np.ndarray
    v: np.ndarray
    count: np.ndarray | None = None
    extra: tuple[np.ndarray, ...] = ()


def prepare(func: str, values: Signal | None, where: Signal | None = None, *more: Signal) -> Prepared:
    """Per-message values of aggregate ``func`` (for ``duration``/``count``: ``where`` alone)."""
    if func in ("duration", "count"):
        assert where is not None
        return Prepared(func, where.t, where.v.astype(bool))
    assert values is not None
    v = values.v
    if where is not None:
        mask = where.v if where.v.ndim == 1 else widened(where.v.astype(bool), v.shape[1])
        v = np.where(mask if mask.ndim == v.ndim else mask[:, None], v, np.nan)
    if v.ndim == 2:
        if v.shape[1] == 0:  # arrays empty in every message (a scan without intensities): no values
            v = np.full((len(v), 1), np.nan)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # messages with no valid element: NaN
            if func == "min":
                return Prepared(func, values.t, np.nanmin(v, axis=1))
            if func == "max":
                return Prepared(func, values.t, np.nanmax(v, axis=1))
            valid = ~np.isnan(v)
            total = np.where(valid, v, 0.0).sum(axis=1)
            counted = valid.sum(axis=1)
            if func == "sum":
                return Prepared(func, values.t, np.where(counted > 0, total, np.nan))
            return Prepared(func, values.t, total, counted)
    return Prepared(func, values.t, v.astype(np.float64, copy=False), None, tuple(m.v for m in more))


BLOCK = 2048
"""Messages per block when an aggregate over arrays (laser ranges) is prepared: the element-wise
temporaries of a block stay small, whatever the length of the run."""


def prepare_blocks(
    func: str, topic: Topic, compute: Callable[[Topic], tuple[Signal, Signal | None]]
) -> Prepared:
    """``prepare`` of an aggregate over an array field, ``BLOCK`` messages at a time.

    ``compute`` gives the values (and the ``where`` condition) for some of the
    topic's messages; arrays never mix topics, so blocks of one topic suffice.
    """
    parts = []
    for first in range(0, max(len(topic), 1), BLOCK):
        values, where = compute(topic.rows(slice(first, first + BLOCK)))
        parts.append(prepare(func, values, where))
    counts = [p.count for p in parts if p.count is not None]
    return Prepared(
        func,
        topic.t,
        np.concatenate([p.v for p in parts]),
        np.concatenate(counts) if counts else None,
    )


Compute = Callable[[Topic], Tuple[Signal, Optional[Signal]]]


def reduced(func: str, topic: Topic, key: str, compute: Compute) -> Prepared:
    """The aggregate over arrays, from per-message values reduced while the bag was read
    (field ``key``, see :func:`reducer`), else computed now, a block at a time."""
    if key in topic.fields:
        return Prepared(func, topic.t, topic.fields[key], topic.fields.get(f"{key}#count"))
    return prepare_blocks(func, topic, compute)


def reducer(
    entries: Sequence[tuple[str, str, Compute]],
) -> Callable[[dict[str, np.ndarray]], dict[str, np.ndarray]]:
    """A function from decoded fields of some messages to the same fields plus, for each entry
    (key, aggregate, compute), the per-message values of that aggregate."""

    def reduce(fields: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        n = len(next(iter(fields.values()))) if fields else 0
        block = Topic("", np.arange(n, dtype=np.float64), fields)
        out = dict(fields)
        for key, func, compute in entries:
            values, where = compute(block)
            p = prepare(func, values, where)
            out[key] = p.v
            if p.count is not None:
                out[f"{key}#count"] = p.count
        return out

    return reduce


def overlaps(t: np.ndarray, start: float, end: float) -> bool:
    """Whether the window ``[start, end]`` meets the span of times ``t`` (sorted)."""
    return len(t) > 0 and start <= float(t[-1]) and end >= float(t[0])


def value_in(p: Prepared, start: float, end: float) -> float | None:
    """The aggregate over ``[start, end]``; None when the window has nothing to aggregate, and
    when it does not overlap the series at all (a sum, count or path length there is not 0:
    the series says nothing of that time)."""
    if not overlaps(p.t, start, end):
        return None
    w = window(p.t, start, end)
    v = p.v[w]
    if p.func == "duration":
        return float(hold(p.t[w])[v].sum())
    if p.func == "count":
        return float(np.count_nonzero(v))
    if p.func == "change":
        ends = np.interp([start, end], p.t, p.v)
        return float(ends[1] - ends[0])
    if p.func == "path_length":
        with np.errstate(invalid="ignore"):
            steps = [np.diff(c[w]) for c in (p.v, *p.extra)]
        return float(np.sqrt(sum(np.square(s) for s in steps)).sum()) if len(v) > 1 else 0.0
    if p.func == "integral":
        t = p.t[w]
        keep = ~np.isnan(v)
        return float(_trapezoid(v[keep], t[keep])) if keep.sum() > 1 else 0.0
    if p.func == "mean" and p.count is not None:
        n = int(p.count[w].sum())
        return float(p.v[w].sum() / n) if n else None
    valid = v[~np.isnan(v)]
    if p.func == "sum":
        return float(valid.sum())
    if len(valid) == 0:
        return None
    if p.func == "min":
        return float(valid.min())
    if p.func == "max":
        return float(valid.max())
    if p.func == "mean":
        return float(valid.mean())
    if p.func == "first":
        return float(valid[0])
    if p.func == "last":
        return float(valid[-1])
    raise ValueError(f"unknown aggregate {p.func!r}")


def value_sqrt(a: float) -> float:
    return math.sqrt(a) if a >= 0 else math.nan


def divide(a: float, b: float) -> float:
    return a / b if b != 0 else math.nan


def finite(value: float | None) -> float | None:
    """A metric's value, or None when there is none (missing data, a division by zero)."""
    return value if value is not None and math.isfinite(value) else None
