"""Good runs: the stored runs that baselines, expected values and estimates learn from.

A run of a scenario is **good** unless

* its last verification gave a verdict that is ``failed`` or ``inconclusive`` (verifying a run
  again replaces its verdicts, so a run fixed by a better baseline counts again);
* its mission did not complete (``cancelled`` or ``stopped``: the recording does not cover it);
* a safety limit was violated in it, as measured when it was ingested (a ``violation_duration``
  above 0 s, or a hotspot), even if it was never verified;
* its recording does not cover it (a coverage gap found at ingest: cut short, no data, a gap,
  a thinned topic, a clock jump), even if it was never verified.

A run that went wrong is not a sample of how the scenario performs: an over-speed run in a
baseline widens its band and moves its mean, and in an estimate it teaches the fault to the
expected values of every scenario derived later.  The store finds the defects
(``run_defects.rq``); this module turns them into the runs used and, for each run left out,
why, in words.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field

from exsce_dsl.errors import NoGoodRuns
from exsce_dsl.lang import standard_metrics
from exsce_dsl.model import Scenario
from exsce_dsl.model.coverage import CoverageGap, Shortfall
from exsce_dsl.remedies import LEARN_FROM_EVERY_RUN
from exsce_dsl.store import RunDefect, Store, run_coverage, run_defects
from exsce_dsl.store import runs as stored_runs

__all__ = ["GoodRuns", "NoGoodRuns", "good_runs_of"]


@dataclass(frozen=True)
class GoodRuns:
    """The runs to learn from, and the runs left out with why (uuid → sentence)."""

    used: tuple[str, ...]
    left_out: dict[str, str] = field(default_factory=dict)

    def reasons(self, short: int = 8) -> str:
        """Each run left out, by its first ``short`` characters, with why: ``8186e306 (...); ...``."""
        return "; ".join(f"{run[:short]} ({reason})" for run, reason in self.left_out.items())

    def summary(self) -> str:
        """``built from 3 runs; left out 1: 8186e306 (max_velocity of tiago1 above its limit for 33.3 s)``."""
        text = f"built from {len(self.used)} run{'s' if len(self.used) != 1 else ''}"
        if self.left_out:
            text += f"; left out {len(self.left_out)}: {self.reasons()}"
        return text

    def require_some(self, what: str) -> GoodRuns:
        """These runs, or a :class:`NoGoodRuns` naming why each stored run was left out."""
        if self.used or not self.left_out:
            return self
        raise NoGoodRuns(
            f"no good run of {what} to learn from: every stored run was left out: {self.reasons()}",
            remedy=LEARN_FROM_EVERY_RUN,
        )


def good_runs_of(
    store: Store,
    scenario_id: str | None = None,
    *,
    include_all: bool = False,
    scenario: Scenario | None = None,
) -> GoodRuns:
    """The good runs of ``scenario_id`` (of every scenario if None), oldest first, and the
    runs left out with why; ``include_all`` keeps every run (nothing is left out).
    ``scenario`` (its metric declarations) words the direction of its own safety limits."""
    every = [run.uuid for run in stored_runs(store, scenario_id)]
    every = list(dict.fromkeys(every))
    if include_all:
        return GoodRuns(tuple(every))
    defects: dict[str, list[RunDefect]] = {}
    for defect in run_defects(store, scenario_id):
        defects.setdefault(defect.run, []).append(defect)
    bounds = _limit_bounds(scenario)
    reasons = {run: _reason(found, bounds) for run, found in defects.items()}
    for run, gaps in run_coverage(store, every).items():
        said = _coverage_reason(gaps, mission_said=any(d.kind == "mission" for d in defects.get(run, ())))
        if said:
            reasons[run] = f"{reasons[run]}; {said}" if run in reasons else said
    left_out = {run: reasons[run] for run in every if run in reasons}
    return GoodRuns(tuple(run for run in every if run not in reasons), left_out)


def _coverage_reason(gaps: Iterable[CoverageGap], mission_said: bool) -> str:
    """What a run's recording does not cover, in words (its first gap, and how many more)."""
    told = [
        g for g in gaps if not (mission_said and g.kind is Shortfall.CUT_SHORT and g.robot is None)
    ]  # the mission's status is said already
    if not told:
        return ""
    more = f" and {len(told) - 1} more gap{'s' if len(told) > 2 else ''}" if len(told) > 1 else ""
    return f"its recording does not cover it: {told[0].reason}{more}"


def _reason(defects: Iterable[RunDefect], bounds: dict[str, str]) -> str:
    """One sentence for all that is wrong with a run, the most telling first."""
    defects = list(defects)
    parts = []
    for outcome in ("failed", "inconclusive"):
        oracles = sorted({d.subject for d in defects if d.kind == outcome})
        if oracles:
            verb = "failed" if outcome == "failed" else "was inconclusive on"
            parts.append(f"{verb} {', '.join(oracles)} when verified")
    for status in sorted({d.subject for d in defects if d.kind == "mission"}):
        parts.append(f"its mission was {status}")
    violations = [d for d in defects if d.kind == "violation"]
    by_robot = {d.subject for d in violations if d.robot is not None}
    for d in sorted(violations, key=lambda d: (d.subject, d.robot is None, d.robot or "")):
        if d.robot is None and d.subject in by_robot:
            continue  # the mission's value of a robot's metric: the robots' values say it
        whose = f" of {d.robot}" if d.robot else ""
        parts.append(f"{d.subject}{whose} {_beyond(d.subject, bounds)} for {d.seconds or 0.0:.1f} s")
    said = {d.subject for d in violations}
    spots: dict[tuple[str, str], int] = {}
    for d in defects:
        if d.kind == "hotspot" and d.subject not in said:
            spots[(d.subject, d.robot or "")] = spots.get((d.subject, d.robot or ""), 0) + 1
    for (metric, robot), count in sorted(spots.items()):
        whose = f" of {robot}" if robot else ""
        parts.append(
            f"{count} hotspot{'s' if count != 1 else ''} where {metric}{whose} broke its safety limit"
        )
    return "; ".join(parts)


def _beyond(metric: str, bounds: dict[str, str]) -> str:
    """``above its limit`` for a metric safe below a limit, ``below its limit`` for one safe above."""
    bound = bounds.get(metric)
    if bound == "below":
        return "above its limit"
    if bound == "above":
        return "below its limit"
    return "beyond its safety limit"


def _limit_bounds(scenario: Scenario | None) -> dict[str, str]:
    """Each safety metric's bound (``below``, ``above``): the standard library's, then the scenario's."""
    declared = [*standard_metrics(), *(scenario.metrics if scenario is not None else ())]
    return {m.name: m.safety.bound for m in declared if m.safety is not None}
