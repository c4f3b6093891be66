"""How far apart two scenarios are, by the method's distances d1–d6 (DESIGN §1, similarity).

* d1 = |#r1 − #r2|, the fleet sizes; d2 = Σ over base types of the difference in how
  many robots have it; d3 the same for torso yes/no.  Each is divided by the largest
  fleet among the scenarios compared.
* d4 = Σ f(x) over the path segments x of both scenarios, f = 0 if the other
  scenario has x too, 0.5 if it has a segment between the same areas, 1 otherwise;
  divided by twice the larger segment count (so 0 ≤ d4 ≤ 1).
* metrics: for each metric both have, |m1 − m2| divided by the largest value stored
  among the scenarios compared (waypoints visited as a share of the planned ones);
  the mean over metrics.
* d5 = |t1 − t2|, the mean violation duration of their runs, and d6 = |h1 − h2|, the
  mean hotspot count, each divided by the largest among the scenarios compared.

Distances that need runs are None for a scenario without any; the combined distance
is the weighted mean of those that are known.
"""

from __future__ import annotations

import re
from collections import Counter
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

DISTANCES = ("d1", "d2", "d3", "d4", "metrics", "d5", "d6")
_HEADING = re.compile(r"-R-?[\d.]+_P-?[\d.]+_Y-?[\d.]+$")


@dataclass(frozen=True)
class ScenarioFacts:
    """What the distances look at in one scenario (from the store: see ``facts.py``)."""

    id: str
    bases: tuple[str | None, ...]
    """The base type of each robot."""
    torsos: tuple[bool | None, ...]
    """Whether each robot has a torso."""
    segments: tuple[tuple[str, str], ...]
    """Each path segment as (start pose id, goal pose id), headings left out."""
    metrics: Mapping[str, float] = field(default_factory=dict)
    """Metric → the mean of its runs' values (empty without runs)."""
    violation: float | None = None
    """Mean over runs of the seconds any safety limit was violated."""
    hotspots: float | None = None
    """Mean over runs of the number of violation hotspots."""

    @property
    def fleet(self) -> int:
        return len(self.bases)


@dataclass(frozen=True)
class Norms:
    """The largest values among the scenarios compared, which the distances are divided by."""

    fleet: int
    metrics: Mapping[str, float]
    violation: float
    hotspots: float

    @classmethod
    def of(cls, scenarios: Sequence[ScenarioFacts]) -> Norms:
        metrics: dict[str, float] = {}
        for s in scenarios:
            for name, value in s.metrics.items():
                metrics[name] = max(metrics.get(name, 0.0), abs(value))
        return cls(
            max((s.fleet for s in scenarios), default=0),
            metrics,
            max((s.violation or 0.0 for s in scenarios), default=0.0),
            max((s.hotspots or 0.0 for s in scenarios), default=0.0),
        )


@dataclass(frozen=True)
class Distances:
    d1: float
    d2: float
    d3: float
    d4: float
    metrics: float | None
    d5: float | None
    d6: float | None

    def combined(self, weights: Mapping[str, float] | None = None) -> float:
        """The weighted mean of the known distances (every weight 1 unless given)."""
        weights = weights or {}
        known = [(getattr(self, n), weights.get(n, 1.0)) for n in DISTANCES if getattr(self, n) is not None]
        total = sum(w for _, w in known)
        return sum(v * w for v, w in known) / total if total else 0.0

    def as_dict(self) -> dict[str, float | None]:
        return {n: getattr(self, n) for n in DISTANCES}


def pose_id(name: str) -> str:
    """A pose's id without the heading the store adds to its name (``-R0.00_P0.00_Y2.269``)."""
    return _HEADING.sub("", name)


def area_of(pose: str) -> str:
    """The area of a pose: its id before the first hyphen (``classroom_c025-w001``)."""
    return pose.split("-", 1)[0]


def _ratio(difference: float, norm: float) -> float:
    return difference / norm if norm > 0 else 0.0


def robot_distances(a: ScenarioFacts, b: ScenarioFacts, fleet: int) -> tuple[float, float, float]:
    """d1, d2, d3: fleet size, base types and torsos, each divided by the largest fleet."""
    d1 = abs(a.fleet - b.fleet)
    bases_a, bases_b = Counter(a.bases), Counter(b.bases)
    d2 = sum(abs(bases_a[k] - bases_b[k]) for k in bases_a.keys() | bases_b.keys())
    torsos_a, torsos_b = Counter(a.torsos), Counter(b.torsos)
    d3 = sum(abs(torsos_a[k] - torsos_b[k]) for k in torsos_a.keys() | torsos_b.keys())
    return _ratio(d1, fleet), _ratio(d2, fleet), _ratio(d3, fleet)


def segment_distance(a: Sequence[tuple[str, str]], b: Sequence[tuple[str, str]]) -> float:
    """d4: each segment of either scenario costs 0 (the other has it), 0.5 (the other has one
    between the same areas) or 1; divided by twice the larger segment count."""
    if not a and not b:
        return 0.0

    def cost(x: tuple[str, str], other: Sequence[tuple[str, str]], areas: set[tuple[str, str]]) -> float:
        if x in other:
            return 0.0
        return 0.5 if (area_of(x[0]), area_of(x[1])) in areas else 1.0

    areas_a = {(area_of(s), area_of(g)) for s, g in a}
    areas_b = {(area_of(s), area_of(g)) for s, g in b}
    total = sum(cost(x, b, areas_b) for x in a) + sum(cost(x, a, areas_a) for x in b)
    return total / (2 * max(len(a), len(b)))


def metric_distance(a: ScenarioFacts, b: ScenarioFacts, norms: Norms) -> float | None:
    """The mean over the metrics both scenarios have of |m1 − m2| / the largest stored value."""
    shared = sorted(a.metrics.keys() & b.metrics.keys())
    if not shared:
        return None
    ratios = [_ratio(abs(a.metrics[m] - b.metrics[m]), norms.metrics.get(m, 0.0)) for m in shared]
    return sum(ratios) / len(ratios)


def distances(a: ScenarioFacts, b: ScenarioFacts, norms: Norms) -> Distances:
    d1, d2, d3 = robot_distances(a, b, norms.fleet)
    d4 = segment_distance(a.segments, b.segments)
    d5 = _known(a.violation, b.violation, norms.violation)
    d6 = _known(a.hotspots, b.hotspots, norms.hotspots)
    return Distances(d1, d2, d3, d4, metric_distance(a, b, norms), d5, d6)


def _known(a: float | None, b: float | None, norm: float) -> float | None:
    return None if a is None or b is None else _ratio(abs(a - b), norm)
