"""Statistics of metric values over stored runs: per path segment, per robot, per mission.

The store computes means, variances and counts; only the square root of a variance is taken here
(SPARQL 1.1 has none)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from exsce_dsl.errors import ExsceError
from exsce_dsl.model.geometry import Pose
from exsce_dsl.prov.identifiers import DEFAULT_NAMESPACE, point_name
from exsce_dsl.store.base import Rows, Store
from exsce_dsl.store.queries.terms import (
    float_of,
    int_of,
    pose_local_name,
    run_query,
)


@dataclass(frozen=True)
class ValueStats:
    """The mean and (population) standard deviation of ``count`` values."""

    mean: float
    std: float
    count: int


def stats_of(rows: Rows) -> ValueStats | None:
    """The statistics of the first row of an aggregate query (count, mean, variance); None for no values."""
    for row in rows:
        count = int_of(row["count"])
        mean, variance = float_of(row["mean"]), float_of(row["variance"])
        if count == 0 or mean is None:
            return None
        return ValueStats(mean, math.sqrt(max(0.0, variance or 0.0)), count)
    return None


def segment_metric(
    store: Store,
    metric: str,
    start: Pose | str,
    goal: Pose | str,
    *,
    runs: Sequence[str] | None = None,
    scenario: str | None = None,
    namespace: str = DEFAULT_NAMESPACE,
) -> ValueStats | None:
    """``metric`` over the path segment ``start`` → ``goal`` (that direction), in ``runs`` or in
    every run of ``scenario`` (give one of the two); None when no run went that way."""
    given: dict[str, str | Sequence[str]] = {
        "metric": metric,
        "start": pose_local_name(start),
        "goal": pose_local_name(goal),
    }
    if (runs is None) == (scenario is None):
        raise ExsceError("segment_metric needs either runs or a scenario")
    if runs is not None:
        if not runs:
            return None
        return stats_of(run_query(store, "segment_metric", {**given, "run": list(runs)}, namespace))
    assert scenario is not None
    given["scenario"] = scenario
    return stats_of(run_query(store, "segment_metric_of_scenario", given, namespace))


def segment_metric_any(
    store: Store, metric: str, start: Pose | str, goal: Pose | str, namespace: str = DEFAULT_NAMESPACE
) -> ValueStats | None:
    """``metric`` over the segment ``start`` → ``goal`` in every stored run of any scenario."""
    given = {"metric": metric, "start": pose_local_name(start), "goal": pose_local_name(goal)}
    return stats_of(run_query(store, "segment_metric_any", given, namespace))


def segment_metric_between(
    store: Store,
    metric: str,
    start: Pose,
    goal: Pose,
    namespace: str = DEFAULT_NAMESPACE,
    *,
    runs: Sequence[str] | None = None,
) -> ValueStats | None:
    """``metric`` over every stored drive from ``start``'s position to ``goal``'s, whatever the
    headings, in ``runs`` (of any scenario; every stored run if None)."""
    given: dict[str, str | Sequence[str]] = {
        "metric": metric,
        "from": point_name(start),
        "to": point_name(goal),
    }
    if runs is not None:
        if not runs:
            return None
        given["run"] = list(runs)
    return stats_of(run_query(store, "segment_metric_between", given, namespace))


def robot_metric_over_runs(
    store: Store, metric: str, robot: str, runs: Sequence[str], namespace: str = DEFAULT_NAMESPACE
) -> ValueStats | None:
    """A robot's whole-run values of ``metric`` over ``runs``."""
    if not runs:
        return None
    given = {"metric": metric, "robot": robot, "run": list(runs)}
    return stats_of(run_query(store, "robot_metric_stats", given, namespace))


def mission_metric_over_runs(
    store: Store, metric: str, runs: Sequence[str], namespace: str = DEFAULT_NAMESPACE
) -> ValueStats | None:
    """The mission values of ``metric`` over ``runs``."""
    if not runs:
        return None
    given = {"metric": metric, "run": list(runs)}
    return stats_of(run_query(store, "mission_metric_stats", given, namespace))


def waypoints_visited(
    store: Store, robot: str, runs: Sequence[str], namespace: str = DEFAULT_NAMESPACE
) -> ValueStats | None:
    """How many waypoints ``robot`` reached (goals that SUCCEEDED), over ``runs``."""
    return robot_metric_over_runs(store, "waypoints_visited", robot, runs, namespace)


def mission_duration(
    store: Store, runs: Sequence[str], namespace: str = DEFAULT_NAMESPACE
) -> ValueStats | None:
    """The mission's duration over ``runs``."""
    return mission_metric_over_runs(store, "mission_duration", runs, namespace)
