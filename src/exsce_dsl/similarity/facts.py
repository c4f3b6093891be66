"""What the distances need of a scenario, read from the store with the query library."""

from __future__ import annotations

from exsce_dsl.lang import builtin_metrics
from exsce_dsl.model.metrics import Combine
from exsce_dsl.similarity.distances import ScenarioFacts, pose_id
from exsce_dsl.store import (
    Store,
    hotspot_counts,
    mission_metric_over_runs,
    path_segments,
    robot_metric_over_runs,
    safety_metrics,
    violation_duration,
)
from exsce_dsl.store import robots as stored_robots
from exsce_dsl.store import runs as stored_runs


def _combined(combine: Combine | None, means: list[float]) -> float:
    """A scenario's value from its robots': as segments combine (waypoints visited: summed)."""
    if combine is Combine.MAX:
        return max(means)
    if combine is Combine.MIN:
        return min(means)
    return sum(means)


def scenario_facts(store: Store, scenario: str) -> ScenarioFacts:
    """The robots, path segments and (if it has runs) metric means, violation time and hotspot
    count of ``scenario``."""
    robots = stored_robots(store, scenario)
    segments = tuple((pose_id(s.start), pose_id(s.goal)) for s in path_segments(store, scenario))
    runs = [r.uuid for r in stored_runs(store, scenario)]
    bases, torsos = tuple(r.base for r in robots), tuple(r.torso for r in robots)
    if not runs:
        return ScenarioFacts(scenario, bases, torsos, segments)
    metrics: dict[str, float] = {}
    for name, info in builtin_metrics().items():
        if name == "violation_duration":
            continue
        if info.per_robot:
            found = [robot_metric_over_runs(store, name, r.robot, runs) for r in robots]
            means = [a.mean for a in found if a is not None]
            if means:
                metrics[name] = _combined(info.combine, means)
        else:
            aggregate = mission_metric_over_runs(store, name, runs)
            if aggregate is not None:
                metrics[name] = aggregate.mean
    if "waypoints_visited" in metrics and segments:
        metrics["waypoints_visited"] = 100.0 * metrics["waypoints_visited"] / len(segments)  # a percentage
    safety = safety_metrics(store, scenario)  # the built-ins' and the user's with a safety limit
    violation = sum(a.mean for m in safety for a in violation_duration(store, scenario, m).values())
    per_run: dict[str, int] = dict.fromkeys(runs, 0)
    for m in safety:
        for run, count in hotspot_counts(store, scenario, m).items():
            per_run[run] = per_run.get(run, 0) + count
    hotspots = sum(per_run.values()) / len(per_run)
    return ScenarioFacts(scenario, bases, torsos, segments, metrics, violation, hotspots)
