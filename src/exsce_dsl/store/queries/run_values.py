"""What the store holds of runs: the runs, their metric values and where each came from."""

from __future__ import annotations

import datetime
from collections.abc import Sequence
from dataclasses import dataclass

from exsce_dsl.errors import ExsceError
from exsce_dsl.prov.identifiers import DEFAULT_NAMESPACE, topic_of_name, unescape_name
from exsce_dsl.store.base import Rows, Store
from exsce_dsl.store.queries.segment_stats import ValueStats, stats_of
from exsce_dsl.store.queries.terms import (
    datetime_of,
    float_of,
    run_query,
    text_of,
)


@dataclass(frozen=True)
class StoredRun:
    """A run as the store knows it."""

    uuid: str
    scenario: str
    start: datetime.datetime | None
    end: datetime.datetime | None
    bag: str | None
    """The bag file's name."""
    path: str | None = None
    """Where the bag file was when it was ingested."""
    mission_status: str | None = None
    """``cancelled`` or ``stopped`` when the run's mission did not complete (its recording does not
    cover the whole mission); None when it completed."""


def runs(store: Store, scenario: str | None = None, namespace: str = DEFAULT_NAMESPACE) -> list[StoredRun]:
    """The runs of ``scenario`` (of every scenario if None), oldest first."""
    given = {} if scenario is None else {"scenario": scenario}
    found = []
    for row in run_query(store, "runs", given, namespace):
        found.append(
            StoredRun(
                uuid=text_of(row["run"]) or "",
                scenario=text_of(row["scenario_id"]) or "",
                start=datetime_of(row["start"]),
                end=datetime_of(row["end"]),
                bag=text_of(row["bag"]) or None,
                path=text_of(row["path"]),
                mission_status=text_of(row["mission_status"]),
            )
        )
    return found


def run_scenarios(
    store: Store, runs: Sequence[str], namespace: str = DEFAULT_NAMESPACE
) -> dict[str, tuple[str, ...]]:
    """The scenario (by id) of each of ``runs`` (uuids) the store holds; runs it lacks are left out."""
    if not runs:
        return {}
    found: dict[str, tuple[str, ...]] = {}
    for row in run_query(store, "run_scenarios", {"run": list(dict.fromkeys(runs))}, namespace):
        run, scenario = text_of(row["run"]), text_of(row["scenario_id"])
        if run is not None and scenario:
            found[run] = (*found.get(run, ()), scenario)
    return found


def run_metric(
    store: Store, run: str, metric: str, robot: str, namespace: str = DEFAULT_NAMESPACE
) -> float | None:
    """The value of ``metric`` for ``robot`` over the whole of ``run`` (None if not recorded)."""
    rows = run_query(store, "run_metric", {"run": run, "metric": metric, "robot": robot}, namespace)
    return _single_value(rows, f"'{metric}' of robot '{robot}' in run {run}")


def mission_metric(store: Store, run: str, metric: str, namespace: str = DEFAULT_NAMESPACE) -> float | None:
    """The mission value of ``metric`` in ``run`` (None if not recorded)."""
    rows = run_query(store, "run_mission_metric", {"run": run, "metric": metric}, namespace)
    return _single_value(rows, f"mission metric '{metric}' in run {run}")


def _single_value(rows: Rows, what: str) -> float | None:
    values = {float_of(row["value"]) for row in rows}
    if len(values) > 1:
        raise ExsceError(f"the store holds {len(values)} values of {what}: {sorted(v or 0 for v in values)}")
    return next(iter(values), None)


@dataclass(frozen=True)
class MetricSource:
    """Where one value of a metric came from: the run's bag and the topics it read."""

    robot: str | None
    """None for a mission value."""
    segment: str | None
    """The action (``tiago1-task_01-subtask_001-w_001``) for a segment value."""
    value: float
    topics: tuple[str, ...]
    bag: str
    """The bag file's name."""


def metric_sources(
    store: Store, run: str, metric: str, namespace: str = DEFAULT_NAMESPACE
) -> list[MetricSource]:
    """Each value of ``metric`` in ``run``, with the topics and the bag it was computed from."""
    grouped: dict[tuple[str | None, str | None, float, str], list[str]] = {}
    for row in run_query(store, "metric_sources", {"run": run, "metric": metric}, namespace):
        value, bag = float_of(row["value"]) or 0.0, unescape_name(text_of(row["bag"]) or "")
        key = (text_of(row["robot"]), text_of(row["segment"]), value, bag)
        grouped.setdefault(key, []).append(topic_of_name(text_of(row["topic_id"]) or ""))
    return [
        MetricSource(robot, segment, value, tuple(sorted(set(topics))), bag)
        for (robot, segment, value, bag), topics in grouped.items()
    ]


# -- safety -----------------------------------------------------------------------------


@dataclass(frozen=True)
class ViolationDuration:
    """How long a safety metric's limit was violated in one run, by one robot (None: the mission)."""

    run: str
    robot: str | None
    seconds: float


def violation_durations(
    store: Store, scenario: str, metric: str, namespace: str = DEFAULT_NAMESPACE
) -> list[ViolationDuration]:
    """The violation durations of safety ``metric`` (e.g. ``max_velocity``) in each run of ``scenario``."""
    rows = run_query(store, "violation_durations", {"scenario": scenario, "metric": metric}, namespace)
    return [
        ViolationDuration(text_of(row["run"]) or "", text_of(row["robot"]), float_of(row["seconds"]) or 0.0)
        for row in rows
    ]


def violation_duration(
    store: Store, scenario: str, metric: str, namespace: str = DEFAULT_NAMESPACE
) -> dict[str | None, ValueStats]:
    """The mean (and deviation) over the runs of ``scenario`` of the violation duration of
    ``metric``, per robot (key None: the mission's)."""
    rows = run_query(store, "violation_duration_stats", {"scenario": scenario, "metric": metric}, namespace)
    found: dict[str | None, ValueStats] = {}
    for row in rows:
        aggregate = stats_of(Rows(rows.variables, (tuple(row.values()),)))
        if aggregate is not None:
            found[text_of(row["robot"])] = aggregate
    return found


@dataclass(frozen=True)
class MetricReading:
    """One metric value of a run: a whole-run value (``action`` None), or one action's
    (``action`` its IRI, ``start`` and ``goal`` the names of the poses it went between, with
    their headings)."""

    run: str
    metric: str
    robot: str | None
    value: float
    action: str | None = None
    goal: str | None = None
    safety: str | None = None
    """For a ``violation_duration``: the safety metric whose limit was violated."""
    unit: str | None = None
    """The value's unit (None for a count)."""
    start: str | None = None
    """For an action's value: the pose it started from."""


def run_metric_values(
    store: Store, runs: Sequence[str], namespace: str = DEFAULT_NAMESPACE
) -> list[MetricReading]:
    """Every whole-run metric value of ``runs``: each robot's and the mission's."""
    if not runs:
        return []
    found = []
    for row in run_query(store, "run_metric_values", {"run": list(runs)}, namespace):
        run, metric, value = text_of(row["run"]), text_of(row["metric"]), float_of(row["value"])
        if run is not None and metric is not None and value is not None:
            reading = MetricReading(
                run,
                metric,
                text_of(row["robot"]),
                value,
                safety=text_of(row["safety"]),
                unit=text_of(row["unit"]),
            )
            found.append(reading)
    return found


def run_segment_values(
    store: Store, runs: Sequence[str], namespace: str = DEFAULT_NAMESPACE
) -> list[MetricReading]:
    """Every path-segment metric value of ``runs``, by action, from the segment index."""
    if not runs:
        return []
    found = []
    for row in run_query(store, "run_segment_values", {"run": list(runs)}, namespace):
        run, metric, value = text_of(row["run"]), text_of(row["metric"]), float_of(row["value"])
        action, goal, start = text_of(row["action"]), text_of(row["goal"]), text_of(row["start"])
        if None not in (run, metric, value, action, goal):
            assert run is not None and metric is not None and value is not None and goal is not None
            reading = MetricReading(
                run,
                metric,
                text_of(row["robot"]),
                value,
                action,
                goal.rsplit("/", 1)[-1],
                unit=text_of(row["unit"]),
                start=start.rsplit("/", 1)[-1] if start is not None else None,
            )
            found.append(reading)
    return found


@dataclass(frozen=True)
class RunDefect:
    """One thing that makes a stored run unfit to learn from (see ``run_defects.rq``)."""

    run: str
    kind: str
    """``failed``, ``inconclusive`` (a verdict of its last verification), ``mission`` (not
    completed), ``violation`` (a safety limit violated), ``hotspot`` (where one was)."""
    subject: str
    """The oracle, the mission's end (``cancelled``...), or the safety metric."""
    robot: str | None = None
    seconds: float | None = None
    """For a violation: how long the limit was violated."""


def run_defects(
    store: Store, scenario: str | None = None, namespace: str = DEFAULT_NAMESPACE
) -> list[RunDefect]:
    """The defects of the runs of ``scenario`` (of every run without one), by run."""
    given = {} if scenario is None else {"scenario": scenario}
    found = []
    for row in run_query(store, "run_defects", given, namespace):
        run, kind, subject = text_of(row["run"]), text_of(row["kind"]), text_of(row["subject"])
        if run and kind and subject is not None:
            kind = "inconclusive" if kind == "unjudged" else kind  # as older stores say
            found.append(RunDefect(run, kind, subject, text_of(row["robot"]), float_of(row["seconds"])))
    return found


@dataclass(frozen=True)
class ActionTimes:
    """When one action of a run started and ended (None where its PROV does not say)."""

    run: str
    action: str
    """The action's IRI, as :func:`run_segment_values` names it."""
    start: datetime.datetime | None
    end: datetime.datetime | None


def action_times(store: Store, runs: Sequence[str], namespace: str = DEFAULT_NAMESPACE) -> list[ActionTimes]:
    """When each action of ``runs`` (uuids) started and ended: the time a windowed clause covers."""
    if not runs:
        return []
    found = []
    for row in run_query(store, "action_times", {"run": list(runs)}, namespace):
        run, action = text_of(row["run"]), text_of(row["action"])
        if run is not None and action is not None:
            found.append(ActionTimes(run, action, datetime_of(row["start"]), datetime_of(row["end"])))
    return found
