"""What each metric value used: its window and why, the samples of each source, the findings.

A monitor reads every sample of its sources inside a value's window; this module counts them
where the value is made, with ``numpy.searchsorted`` over the very arrays the monitor read, and
says why a value used fewer: samples outside the span where all the topics it combines have data,
samples without the array element it reads, samples without a value (NaN, or no element passing
the metric's condition).  Analysis then names the sources as the bag has them and puts the window
on the wall clock (:func:`on_wall_clock`); the run's coverage adds the findings that touch the
value (:func:`~exsce_dsl.runs.coverage.with_findings`).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import replace

import numpy as np

from exsce_dsl.model.runs import Accounting, MetricValue, SourceCount
from exsce_dsl.monitor_kit import monitor_core as core
from exsce_dsl.wording import counted

GOALS_SPAN = "the recorded goals' span (first goal active to last goal done)"
MISSION_SPAN = "the mission's span (the first start to the last end of its robots' windows)"


def segment_reason(allocation: int, subtask: int, waypoint: int) -> str:
    """Why a segment value's window is what it is: its path segment."""
    return f"path segment to waypoint {waypoint} of subtask {subtask} of task {allocation}"


class SampleCounter:
    """Counts, per window, the samples of a monitor's sources and those its aggregates used.

    Whether an aggregate's values are one per sample of a source is decided once per pair (its
    times are the source's, or a subset of them) and kept: a run has many windows."""

    def __init__(self, topics: Mapping[str, core.Topic]) -> None:
        self.topics = topics
        self._based: dict[tuple[int, str], tuple[core.Prepared, bool]] = {}

    def accounting(
        self,
        prepared: Sequence[core.Prepared],
        sources: Sequence[str],
        window: tuple[float, float],
        reason: str,
        held: bool = False,
    ) -> Accounting:
        """The accounting of a value over ``window`` (the run's timeline) from ``prepared``;
        ``held``: the value sums how long samples hold (a duration, a violation duration)."""
        start, end = window
        counts = [c for name in sources if (c := self.count(prepared, name, window, held)) is not None]
        return Accounting(start, end, reason, tuple(counts))

    def count(
        self, prepared: Sequence[core.Prepared], name: str, window: tuple[float, float], held: bool = False
    ) -> SourceCount | None:
        """Samples of source ``name`` in the window and those used (None: not a series read)."""
        start, end = window
        topic = self.topics.get(name)
        if topic is None or not len(topic):
            return None
        w = core.window(topic.t, start, end)
        n = w.stop - w.start
        best: tuple[int, list[str]] | None = None
        notes: list[str] = []
        for p in prepared:
            if not self._based_on(p, name, topic):
                continue
            used, why = _used(p, topic.t[w], start, end)
            if best is None or used > best[0]:
                best = (used, why)
            notes += _held(p, start, end) if held or p.func == "duration" else []
        used, why = best if best is not None else (n, [])
        said = "; ".join(dict.fromkeys(why + notes)) or None
        return SourceCount((name,), used, n, said)

    def _based_on(self, p: core.Prepared, name: str, topic: core.Topic) -> bool:
        """Whether ``p`` has one value per sample of ``topic`` (all of them, or some)."""
        key = (id(p.t), name)
        known = self._based.get(key)
        if known is None or known[0] is not p:
            known = self._based[key] = (p, _subset(p.t, topic.t))
        return known[1]


def _subset(t: np.ndarray, of: np.ndarray) -> bool:
    if t is of:
        return True
    if len(t) == 0 or len(t) > len(of):
        return False
    if len(t) == len(of):
        return bool(np.array_equal(t, of))
    at = np.searchsorted(of, t)
    return bool(at[-1] < len(of) and np.array_equal(of[np.minimum(at, len(of) - 1)], t))


def _used(p: core.Prepared, inside: np.ndarray, start: float, end: float) -> tuple[int, list[str]]:
    """How many of the source's samples ``inside`` the window ``p`` used, and why not the others."""
    pw = core.window(p.t, start, end)
    kept = pw.stop - pw.start
    valid = _valid(p, pw)
    why: list[str] = []
    if kept < len(inside):
        outside = 0 if kept == 0 else int((inside < p.t[pw.start]).sum() + (inside > p.t[pw.stop - 1]).sum())
        outside = len(inside) if kept == 0 else outside
        if outside:
            why.append(
                f"{counted(outside, 'sample')} outside the span where every topic it combines "
                "has data (values of several topics are combined only there)"
            )
        if len(inside) - kept - outside > 0:
            why.append(
                f"{counted(len(inside) - kept - outside, 'sample')} without the array element it reads"
            )
    if valid < kept:
        why.append(
            f"{counted(kept - valid, 'sample')} without a value (NaN, or no element meeting its condition)"
        )
    return valid, why


def _valid(p: core.Prepared, pw: slice) -> int:
    """The samples of ``p`` in ``pw`` that have a value."""
    if p.func in ("duration", "count"):
        return int(pw.stop - pw.start)
    if p.count is not None:
        return int(np.count_nonzero(p.count[pw]))
    with np.errstate(invalid="ignore"):
        ok = (
            ~np.isnan(p.v[pw]) if np.issubdtype(p.v.dtype, np.floating) else np.ones(pw.stop - pw.start, bool)
        )
        if ok.ndim > 1:
            ok = ok.any(axis=1)
        for more in p.extra:
            ok = ok & ~np.isnan(more[pw])
    return int(np.count_nonzero(ok))


def _held(p: core.Prepared, start: float, end: float) -> list[str]:
    """A duration's note: samples before a gap hold two median periods, not the whole gap."""
    t = p.t[core.window(p.t, start, end)]
    if len(t) < 3:
        return []
    gaps = np.diff(t)
    cut = int(np.count_nonzero(gaps > 2 * float(np.median(gaps))))
    if not cut:
        return []
    return [f"{counted(cut, 'sample')} before a gap held for two median periods, not the whole gap"]


def on_wall_clock(
    values: Sequence[MetricValue],
    wall: Callable[[np.ndarray], np.ndarray],
    real: Mapping[str, tuple[str, ...]],
    chains: Mapping[str, str] | None = None,
) -> list[MetricValue]:
    """``values`` with their accountings' windows on the wall clock (``wall``: the run's timeline
    → the recorder's wall clock, called once for every window) and their sources named as the bag
    has them (``real``: a series the monitors read → the bag topics it came from; ``chains``: a
    series composed from TF → the transforms composed).  The coverage findings that touch a value
    are added once the run's coverage is known (:func:`~exsce_dsl.runs.coverage.with_findings`)."""
    windows = [(a.start, a.end) for v in values if (a := v.accounting) is not None]
    walled = iter(wall(np.array(windows, dtype=np.float64).reshape(-1)).tolist() if windows else [])
    chains = chains or {}
    found = []
    for value in values:
        if value.accounting is None:
            found.append(value)
            continue
        sources = tuple(
            replace(
                c,
                topics=tuple(dict.fromkeys(r for t in c.topics for r in real.get(t, (t,)))),
                tf_chain=next((chains[t] for t in c.topics if t in chains), c.tf_chain),
            )
            for c in value.accounting.sources
        )
        start, end = next(walled), next(walled)
        walled_accounting = replace(value.accounting, start=start, end=end, sources=sources)
        found.append(replace(value, accounting=walled_accounting))
    return found
