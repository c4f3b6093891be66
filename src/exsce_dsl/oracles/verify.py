"""Judging runs: each stored oracle of a run's scenario applied to the run's values."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace

from exsce_dsl.errors import ExsceError
from exsce_dsl.model import Scenario
from exsce_dsl.model.acceptance import Window
from exsce_dsl.model.oracles import Oracle
from exsce_dsl.model.verdicts import Outcome, Verdict
from exsce_dsl.oracles.observe import observe, parse_window, run_values
from exsce_dsl.oracles.relations import RelationError, relation
from exsce_dsl.store.base import Store
from exsce_dsl.store.queries import oracles as stored_oracles
from exsce_dsl.store.queries import runs as stored_runs


def judge_runs(store: Store, runs: Sequence[str], scenario: Scenario) -> list[Verdict]:
    """The verdicts of every oracle of ``scenario`` on each of ``runs`` (uuids), run by run.

    A run whose mission did not complete (cancelled or stopped: its recording does not cover the
    whole mission) is never passed: a clause it met is inconclusive, saying so; one it broke fails,
    for what was recorded did break it.

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
            f"scenario '{scenario.id}' has no oracles in the store: build its baseline first "
            f"(exscec baseline <spec> --scenario-id {scenario.id})"
        )
    values = run_values(store, list(runs))
    verdicts = []
    for run in runs:
        for oracle in oracles:
            observed, why = observe(values[run], oracle.metric, oracle.robot, _window(oracle), scenario)
            verdict = _verdict(run, scenario.id, oracle, observed, why)
            incomplete = known[run].mission_status
            if incomplete and verdict.outcome is Outcome.PASSED:
                reason = f"the run is incomplete (its mission was {incomplete}): it was not seen to the end"
                verdict = replace(verdict, outcome=Outcome.INCONCLUSIVE, reason=reason, margin=None)
            verdicts.append(verdict)
    return verdicts


def _window(oracle: Oracle) -> Window | None:
    """The oracle's window; a task's window is the oracle's robot's."""
    window = parse_window(oracle.window)
    if window is not None and window.task is not None and oracle.robot is not None:
        return Window(window.moment, oracle.robot, task=window.task)
    return window


def _verdict(run: str, scenario: str, oracle: Oracle, observed: float | None, why: str) -> Verdict:
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
