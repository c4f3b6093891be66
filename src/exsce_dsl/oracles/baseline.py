"""Baselines: the oracles of a scenario with their numbers, from its stored runs.

For each oracle the acceptance criteria plan, the value it compares with is a
fixed one (``around``, ``from``), a limit (``stays below``), or the mean of the
metric over the good stored runs of the scenario (a baseline oracle) or of the
scenario it was derived from (a metamorphic one; good runs: those that did not fail,
were not inconclusive, completed their mission and broke no safety limit, see
:mod:`exsce_dsl.oracles.good_runs`); the tolerance follows the
clause (``within 1 std``, ``within 10 %``, ``within 2 s``; one standard deviation
for ``invariant`` if none is written), or its confidence (``at 99 %``: the half-width of the
prediction interval for one new run, :func:`~exsce_dsl.oracles.intervals.prediction_half_width`).
The method's "update baseline" is writing these oracles to the store again.  Each oracle names
the topics the values it learnt from were computed from, as the store holds them
(:mod:`exsce_dsl.oracles.sources`), not the method's topics for its metric.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from exsce_dsl.errors import ExsceError, NotEnoughRuns
from exsce_dsl.model import Scenario
from exsce_dsl.model.acceptance import Acceptance, BasicRelation
from exsce_dsl.model.oracles import Oracle
from exsce_dsl.oracles.good_runs import GoodRuns, good_runs_of
from exsce_dsl.oracles.intervals import prediction_half_width
from exsce_dsl.oracles.observe import RunValues, observe, run_values
from exsce_dsl.oracles.plan import PlannedOracle, plan_oracles, tolerance_of
from exsce_dsl.oracles.sources import ValueSources, unread_topics
from exsce_dsl.store import Store

PACKAGE = "exsce.metamorphic.relationships"
"""The package the method's YAML names for the built-in relations (kept for its format)."""


@dataclass(frozen=True)
class Statistics:
    mean: float
    std: float
    """The population standard deviation (n in its denominator), the method's tolerance."""
    runs: tuple[str, ...]
    values: tuple[float, ...] = ()
    """The values, run by run, for a tolerance at a confidence."""


def baseline_oracles(
    store: Store,
    acceptance: Acceptance,
    scenario: Scenario,
    bases: dict[str, Scenario] | None = None,
    *,
    include_all: bool = False,
    runs: Sequence[str] | None = None,
) -> list[Oracle]:
    """The oracles of ``scenario`` with their numbers from its good runs in ``store`` (see
    :mod:`exsce_dsl.oracles.good_runs`; every run with ``include_all``).

    ``bases`` are the scenarios metamorphic clauses compare with (by id).  ``runs`` (uuids of
    runs of ``scenario``), when given, are the baseline's own runs instead of its good stored ones
    (bench/oracles.py builds baselines from chosen runs this way).  Raises
    :class:`NotEnoughRuns` while the scenario has fewer good runs than its criteria ask.
    """
    learnt = learn_baseline(store, acceptance, scenario, bases, include_all=include_all, runs=runs)
    return list(learnt.oracles)


@dataclass(frozen=True)
class LearntBaseline:
    """The oracles, and the runs of each scenario they learnt from (and those left out, with why)."""

    oracles: tuple[Oracle, ...]
    runs: dict[str, GoodRuns]
    """By scenario id: the scenario's own, and each base a metamorphic clause compares with."""


def learn_baseline(
    store: Store,
    acceptance: Acceptance,
    scenario: Scenario,
    bases: dict[str, Scenario] | None = None,
    *,
    include_all: bool = False,
    runs: Sequence[str] | None = None,
) -> LearntBaseline:
    """:func:`baseline_oracles`, with the runs they were built from and the runs left out."""
    planned = plan_oracles(acceptance, scenario)
    own = GoodRuns(tuple(runs)) if runs is not None else _usable_runs(store, scenario, include_all)
    needed = acceptance.baseline_runs
    learns = any(p.needs_runs and p.expectation.against is None for p in planned)
    if learns:
        own.require_some(f"scenario '{scenario.id}'")
    if len(own.used) < needed and learns:
        left = f" ({len(own.left_out)} left out: {own.reasons()})" if own.left_out else ""
        count = f"{len(own.used)} good stored run{'s' if len(own.used) != 1 else ''}"
        raise NotEnoughRuns(
            f"scenario '{scenario.id}' has {count}{left}; its baseline needs {needed} "
            "(ingest more runs, or lower 'given at least N baseline runs')"
        )
    chosen = {scenario.id: own}
    values = {scenario.id: run_values(store, list(own.used))}
    oracles = []
    sources = ValueSources(store)  # what the values learnt from were read from, not the method's topics
    for oracle in planned:
        base_id = oracle.expectation.against or scenario.id
        base = (bases or {}).get(base_id, scenario) if base_id != scenario.id else scenario
        if base_id not in values:
            base_runs = _usable_runs(store, base if base.id == base_id else base_id, include_all)
            if not base_runs.used and not base_runs.left_out:
                raise ExsceError(
                    f"scenario '{scenario.id}' is compared with '{base_id}', which has no stored runs yet"
                )
            base_runs.require_some(f"'{base_id}', which '{scenario.id}' is compared with")
            chosen[base_id] = base_runs
            values[base_id] = run_values(store, list(base_runs.used))
        stats = _statistics(oracle, list(values[base_id].values()), base)
        whole_run = oracle.window_text is None
        topics = sources.topics(stats.runs if stats else (), oracle.metric, oracle.robot, whole_run=whole_run)
        topics = topics or unread_topics(scenario, oracle.metric, oracle.robot)
        oracles.append(_numbers(oracle, stats, scenario, topics))
    return LearntBaseline(tuple(oracles), chosen)


def _usable_runs(store: Store, scenario: Scenario | str, include_all: bool = False) -> GoodRuns:
    """The good runs of a scenario (every run with ``include_all``), and those left out with why."""
    if isinstance(scenario, Scenario):
        return good_runs_of(store, scenario.id, include_all=include_all, scenario=scenario)
    return good_runs_of(store, scenario, include_all=include_all)


def _statistics(oracle: PlannedOracle, runs: Sequence[RunValues], scenario: Scenario) -> Statistics | None:
    observed: list[float] = []
    used: list[str] = []
    for values in runs:
        value, _ = observe(values, oracle.metric, oracle.robot, oracle.window, scenario)
        if value is not None:
            observed.append(value)
            used.append(values.run)
    if not observed:
        return None
    mean = math.fsum(observed) / len(observed)
    std = math.sqrt(math.fsum((v - mean) ** 2 for v in observed) / len(observed))
    return Statistics(mean, std, tuple(used), tuple(observed))


def _numbers(
    oracle: PlannedOracle, stats: Statistics | None, scenario: Scenario, topics: tuple[str, ...]
) -> Oracle:
    e = oracle.expectation
    common = {
        "metric": oracle.metric,
        "robot": oracle.robot,
        "relation": e.relation.value,
        "type": oracle.type,
        "base_scenario": e.against or scenario.id,
        "topics": topics,
        "package": PACKAGE,
        "window": oracle.window_text,
        "criterion": oracle.criterion,
    }
    if e.limit is not None:
        return Oracle(**common, limit=e.limit.value)  # type: ignore[arg-type]
    # none written: one standard deviation around the runs' mean, but exactly a fixed value
    needs_std = (
        (e.tolerance is not None and e.tolerance.unit == "std")
        or (e.tolerance is None and e.relation is BasicRelation.INVARIANT and e.value is None)
        or e.confidence is not None
    )
    if stats is None and (e.value is None or needs_std):
        where = f"'{e.against}'" if e.against else f"scenario '{scenario.id}'"
        raise ExsceError(
            f"no stored run of {where} has a value of '{oracle.metric}'"
            + (f" for robot '{oracle.robot}'" if oracle.robot else "")
            + (f" {oracle.window_text}" if oracle.window_text else "")
            + " to build the oracle from"
        )
    value = e.value.value if e.value is not None else stats.mean  # type: ignore[union-attr]
    std = stats.std if stats is not None else 0.0
    tolerance: float | None = tolerance_of(e.tolerance, value, std, e.relation)
    if e.tolerance is None and e.value is not None:
        tolerance = None
    confidence = e.confidence_level
    if confidence is not None:
        assert stats is not None  # needs_std
        tolerance = _prediction_tolerance(oracle, stats, confidence, e.against or scenario.id)
    delta = (
        e.delta.value if e.delta is not None else (0.0 if e.relation is not BasicRelation.INVARIANT else None)
    )
    sources = stats.runs if stats is not None and (e.value is None or needs_std) else ()
    return Oracle(
        **common,  # type: ignore[arg-type]
        value=value,
        delta=delta,
        tolerance=tolerance,
        sources=sources,
        confidence=confidence,
    )


def _prediction_tolerance(oracle: PlannedOracle, stats: Statistics, confidence: float, base: str) -> float:
    """The half-width of the prediction interval for one new run at ``confidence``; the spread
    of at least 2 runs is needed."""
    if len(stats.values) < 2:
        whose = f" of robot '{oracle.robot}'" if oracle.robot else ""
        raise NotEnoughRuns(
            f"'{oracle.metric}'{whose} at {confidence * 100:g} % confidence needs the values of at "
            f"least 2 runs of '{base}' to take its band from their spread, and only "
            f"{len(stats.values)} has one (ingest more runs, or write a tolerance: 'within ...')"
        )
    return prediction_half_width(stats.values, confidence)
