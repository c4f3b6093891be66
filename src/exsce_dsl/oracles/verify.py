"""Judging runs: each stored oracle of a run's scenario applied to the run's values."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

from exsce_dsl.errors import ExsceError, RelationError
from exsce_dsl.lang import standard_metrics
from exsce_dsl.model import Scenario
from exsce_dsl.model.acceptance import Window
from exsce_dsl.model.coverage import CoverageGap, Shortfall, TopicRate
from exsce_dsl.model.metrics import Combine
from exsce_dsl.model.oracles import Oracle
from exsce_dsl.model.verdicts import Outcome, Verdict
from exsce_dsl.oracles.coverage_check import Span, clause_gaps, judge_coverage, learned_rate_gaps
from exsce_dsl.oracles.observe import RunValues, observe, parse_window, run_values, window_segments
from exsce_dsl.oracles.relations import relation
from exsce_dsl.oracles.sources import ValueSources
from exsce_dsl.remedies import BUILD_A_BASELINE
from exsce_dsl.store import Store, StoredRun, action_times
from exsce_dsl.store import oracles as stored_oracles
from exsce_dsl.store import runs as stored_runs


def judge_runs(
    store: Store,
    runs: Sequence[str],
    scenario: Scenario,
    coverage: Mapping[str, Sequence[CoverageGap]] | None = None,
    rates: Mapping[str, Sequence[TopicRate]] | None = None,
) -> list[Verdict]:
    """The verdicts of every oracle of ``scenario`` on each of ``runs`` (uuids), run by run.

    ``coverage`` (run uuid → what its recording does not cover) and ``rates`` (run uuid → how
    densely its topics were recorded; the runs the oracles' expectations came from as well as
    those judged) make a verdict over data the recording lacks inconclusive, never passed
    (:mod:`exsce_dsl.oracles.coverage_check`).  A run whose mission did not complete (cancelled
    or stopped, as the store says) is cut short whatever ``coverage`` says: a clause it met is
    inconclusive; a limit it broke fails, for what was recorded did break it.

    Raises :class:`ExsceError` for a run the store does not hold, a run of another
    scenario, or a scenario without oracles (no baseline built yet).
    """
    known = {run.uuid: run for run in stored_runs(store)}
    for run in runs:
        if run not in known:
            raise ExsceError(f"the store holds no run {run}")
        if known[run].scenario != scenario.id:
            raise ExsceError(f"run {run} is a run of '{known[run].scenario}', not of '{scenario.id}'")
    oracles = stored_oracles(store, scenario.id)
    if not oracles:
        raise ExsceError(
            f"scenario '{scenario.id}' has no oracles in the store",
            remedy=BUILD_A_BASELINE,
            about=scenario.id,
        )
    values = run_values(store, list(runs))
    times = _action_spans(store, runs)
    baseline = [run for o in oracles if o.base_scenario == scenario.id for run in o.sources]
    verdicts = []
    sources = ValueSources(store)
    for run in runs:
        found = list((coverage or {}).get(run, ()))
        gaps = found if any(g.kind is Shortfall.CUT_SHORT for g in found) else found + _cut_short(known[run])
        for oracle in oracles:
            window = _window(oracle)
            observed, why = observe(values[run], oracle.metric, oracle.robot, window, scenario)
            topics = sources.topics((run,), oracle.metric, oracle.robot, whole_run=window is None)
            verdict = _verdict(run, scenario.id, oracle, observed, why, topics)
            span = _span(values[run], oracle, window, scenario, times)
            concerned = clause_gaps(verdict, gaps, span)
            if rates:
                declared = {g.topic for g in concerned if g.kind is Shortfall.LOW_RATE}
                learned = learned_rate_gaps(verdict, oracle.topics, rates, oracle.sources or baseline)
                concerned += [g for g in learned if g.topic not in declared]
            verdicts.append(judge_coverage(verdict, concerned, _accumulates(oracle.metric, scenario)))
    return verdicts


def _cut_short(run: StoredRun) -> list[CoverageGap]:
    """A run whose mission was cancelled or stopped, as the store says: its recording does not
    cover the whole mission (unless ingestion already said the run was cut short)."""
    if run.mission_status is None:
        return []
    reason = f"the run is incomplete (its mission was {run.mission_status}): it was not seen to the end"
    return [CoverageGap(Shortfall.CUT_SHORT, reason)]


_GROWS = {"mission_duration", "waypoints_visited", "violation_duration"}
"""Built-in metrics without a per-segment combination whose value only grows with more data."""


def _accumulates(metric: str, scenario: Scenario) -> Combine | None:
    """How ``metric``'s value changes with more data (see :func:`judge_coverage`)."""
    for definition in (*scenario.metrics, *standard_metrics()):
        if definition.name == metric and definition.combine is not None:
            return definition.combine
    return Combine.SUM if metric in _GROWS else None


def _action_spans(store: Store, runs: Sequence[str]) -> dict[str, Span]:
    """Action IRI → when it started and ended (its bounds None where the store does not say)."""
    return {t.action: Span(t.start, t.end) for t in action_times(store, list(runs))}


def _span(
    values: RunValues, oracle: Oracle, window: Window | None, scenario: Scenario, times: Mapping[str, Span]
) -> Span:
    """The part of the run a clause looks at: the time of its window's path segments (the whole
    run without a window, or where a segment's times are not known)."""
    if window is None:
        return Span()
    picked = [times.get(s.action, Span()) for s in window_segments(values, oracle.robot, window, scenario)]
    starts = [p.start for p in picked if p.start is not None]
    ends = [p.end for p in picked if p.end is not None]
    if not picked or len(starts) < len(picked) or len(ends) < len(picked):
        return Span()
    return Span(min(starts), max(ends))


def _window(oracle: Oracle) -> Window | None:
    """The oracle's window; a task's window is the oracle's robot's."""
    window = parse_window(oracle.window)
    if window is not None and window.task is not None and oracle.robot is not None:
        return Window(window.moment, oracle.robot, task=window.task)
    return window


def _verdict(
    run: str, scenario: str, oracle: Oracle, observed: float | None, why: str, topics: tuple[str, ...] = ()
) -> Verdict:
    common = {
        "run": run,
        "scenario": scenario,
        "criterion": oracle.criterion,
        "oracle": oracle.name,
        "metric": oracle.metric,
        "robot": oracle.robot,
        "relation": oracle.relation,
        "observed": observed,
        "expected": oracle.value,
        "limit": oracle.limit,
        "delta": oracle.delta,
        "tolerance": oracle.tolerance,
        "window": oracle.window,
        "sources": oracle.sources,
        "against": oracle.base_scenario if oracle.base_scenario not in (None, scenario) else None,
        "topics": topics,
    }
    if observed is None:
        return Verdict(**common, outcome=Outcome.INCONCLUSIVE, reason=why)  # type: ignore[arg-type]
    try:
        given = {
            "value": oracle.value,
            "limit": oracle.limit,
            "delta": oracle.delta,
            "tolerance": oracle.tolerance,
        }
        judged = relation(oracle.relation).judge(
            observed, **{k: v for k, v in given.items() if v is not None}
        )
    except RelationError as exc:
        return Verdict(**common, outcome=Outcome.INCONCLUSIVE, reason=str(exc))  # type: ignore[arg-type]
    outcome = Outcome.PASSED if judged.passed else Outcome.FAILED
    margin = None if math.isnan(judged.margin) else judged.margin
    reason = "" if judged.passed else f"{observed:g} is not {judged.expected}"
    return Verdict(**common, outcome=outcome, margin=margin, reason=reason)  # type: ignore[arg-type]
