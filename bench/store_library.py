"""The library's queries in bench/store.py: the parameters each is called with on the synthetic
store, what it reads (a list of runs, the scenario's runs, the store), its p50/p95 beside its target,
and its answers (to compare two stores)."""

from __future__ import annotations

import math
import time
from collections.abc import Callable

from store_synthetic import ROBOTS
from store_targets import Timed, target_ms

from exsce_dsl.model import Scenario
from exsce_dsl.prov.identifiers import point_name, pose_name
from exsce_dsl.store.embedded import EmbeddedStore
from exsce_dsl.store.queries import query as library_query
from exsce_dsl.store.queries import query_names
from exsce_dsl.store.queries import runs as list_runs
from exsce_dsl.store.queries.terms import run_query


def percentile(samples: list[float], q: float) -> float:
    ordered = sorted(samples)
    return ordered[min(len(ordered) - 1, max(0, math.ceil(q * len(ordered)) - 1))]


def timed(call: Callable[[], object], repeat: int, warm_up: bool = True) -> list[float]:
    if warm_up:
        call()
    samples = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        call()
        samples.append(time.perf_counter() - t0)
    return samples


NOT_TIMED = ("campaign_shrinkings", "campaign_trials", "update_baseline", "update_mission_baseline")
"""Library queries the table leaves out: the campaigns' (no campaign in these stores) and updates."""
METRIC_OF = {
    "hotspot_counts": "max_velocity",
    "violation_durations": "max_velocity",
    "violation_duration_stats": "max_velocity",
    "mission_metric_stats": "mission_duration",
    "run_mission_metric": "mission_duration",
}


def library_parameters(name: str, scenario: Scenario, some_runs: list[str]) -> tuple[dict[str, object], str]:
    """Parameters for library query ``name`` on the synthetic store, and what it reads."""
    start_pose = scenario.robots[0].start_pose
    first_task = scenario.task(scenario.mission.tasks_of(ROBOTS[0])[0])
    assert start_pose is not None and first_task is not None
    goal_pose = next(first_task.waypoints())
    by_kind: dict[str, object] = {
        "scenario": scenario.id,
        "id": scenario.id,
        "robot": ROBOTS[0],
        "metric": METRIC_OF.get(name, "task_duration"),
        "metric_property": "distance_travelled",
    }
    given: dict[str, object] = {}
    scope = "the store"
    for parameter in library_query(name).parameters:
        if parameter.from_runs:
            continue  # bound from the runs given
        if parameter.kind in ("run", "run_activity"):
            given[parameter.name] = some_runs if parameter.many else some_runs[0]
            scope = f"{len(some_runs)} runs" if parameter.many else "1 run"
        elif parameter.kind == "pose":
            poses = [pose_name(start_pose), pose_name(goal_pose)]
            given[parameter.name] = poses if parameter.many else poses[parameter.name == "goal"]
        elif parameter.name == "prefix":  # run_ids: the first 8 characters, as users type them
            given[parameter.name] = some_runs[0][:8]
            scope = "1 run"
        elif parameter.kind == "point":
            given[parameter.name] = point_name(start_pose if parameter.name == "from" else goal_pose)
        else:
            given[parameter.name] = by_kind[parameter.kind]
            if parameter.kind in ("scenario", "id") and scope == "the store":
                scope = "the scenario"
    return given, scope


def time_library(
    store: EmbeddedStore,
    scenario: Scenario,
    some_runs: list[str],
    repeat: int,
    budget: float,
    partial: frozenset[str] = frozenset(),
) -> list[Timed]:
    """p50 and p95 of every library query the report and the oracles use, against its target.  A
    query whose first (warm-up) call takes long gets fewer timed calls: as many as ``budget``
    seconds hold; one that takes longer than ``budget`` is timed by that first call alone."""
    found = []
    size = len(list_runs(store, scenario.id))
    for name in query_names():
        if name in NOT_TIMED:
            continue
        given, scope = library_parameters(name, scenario, some_runs)

        def call(name: str = name, given: dict[str, object] = given) -> object:
            return run_query(store, name, given)  # type: ignore[arg-type]

        t0 = time.perf_counter()
        rows = len(call().rows)  # type: ignore[attr-defined]
        first = time.perf_counter() - t0
        count = min(repeat, int(budget / max(first, 1e-9)))
        samples = timed(call, count, warm_up=False) if count else [first]  # over budget: its one call
        p50, p95 = percentile(samples, 0.5), percentile(samples, 0.95)
        target = target_ms(name, scope, size)
        found.append(Timed(name, scope, len(samples), p50, p95, rows, target, name in partial))
    return found


def answers(store: EmbeddedStore, scenario: Scenario, some_runs: list[str]) -> dict[str, object]:
    """Every timed library query's rows on ``store`` (as text, order kept)."""
    found: dict[str, object] = {}
    for name in query_names():
        if name not in NOT_TIMED:
            given, _ = library_parameters(name, scenario, some_runs)
            rows = run_query(store, name, given)  # type: ignore[arg-type]
            found[name] = [tuple(None if t is None else str(t) for t in row) for row in rows.rows]
    return found
