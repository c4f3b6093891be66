"""Typed queries over the store: the SPARQL counterparts of the method's Neo4j questions.

Each function runs one file of the query library (:mod:`.library`, the ``.rq``
and ``.ru`` files next to this module), with its parameters bound as RDF terms
exactly as ``exscec query NAME -p key=value`` binds them, and returns plain
values or dataclasses, never raw bindings.  Aggregates (means, variances,
counts) are computed by the store; only the square root of a variance is
taken here (SPARQL 1.1 has none).

Identifiers are the DSL's: scenario, robot and metric ids, run uuids, and
poses either as :class:`~exsce_dsl.model.Pose` or as the local name of their
PROV entity (``classroom_c025-w001-R0.00_P0.00_Y0.00``).
"""

from __future__ import annotations

import datetime
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from pyoxigraph import Literal

from exsce_dsl.errors import ExsceError
from exsce_dsl.model.derivation import Derivation, ParameterValue, TransformationStep
from exsce_dsl.model.geometry import Pose
from exsce_dsl.model.oracles import Oracle, OracleType
from exsce_dsl.prov.identifiers import DEFAULT_NAMESPACE, point_name, pose_name
from exsce_dsl.store.base import Rows, Store, Term
from exsce_dsl.store.queries.library import KINDS, Parameter, Query, query, query_names, standard_prefixes

__all__ = [
    "KINDS",
    "Aggregate",
    "MetricSource",
    "Parameter",
    "PathSegment",
    "Query",
    "RobotFacts",
    "StoredRun",
    "ViolationDuration",
    "derivation_of",
    "derived_scenarios",
    "failed_runs",
    "hotspot_counts",
    "lineage",
    "mission_duration",
    "mission_metric",
    "mission_metric_over_runs",
    "metric_sources",
    "oracles",
    "path_segments",
    "query",
    "query_names",
    "robot_metric_over_runs",
    "robots",
    "run_metric",
    "run_query",
    "runs",
    "segment_metric",
    "segment_metric_any",
    "run_metric_values",
    "run_segment_values",
    "safety_metrics",
    "scenario_ids",
    "MetricReading",
    "standard_prefixes",
    "update_baseline",
    "violation_duration",
    "violation_durations",
    "python_value",
    "waypoints_visited",
]

Given = Mapping[str, str | Sequence[str]]
"""Parameters as text: name → one value or several."""


def run_query(store: Store, name: str, given: Given, namespace: str = DEFAULT_NAMESPACE) -> Rows:
    """Run library query ``name`` with parameters given as text; its rows (SELECT) or none (update)."""
    q = query(name)
    as_lists = {k: [v] if isinstance(v, str) else list(v) for k, v in given.items()}
    bindings = q.bindings(as_lists, namespace)
    if q.is_update:
        store.update(q.sparql(namespace), bindings)
        return Rows((), ())
    return store.select(q.sparql(namespace), bindings)


# -- plain values of terms -----------------------------------------------------------


def _text(term: Term | None) -> str | None:
    return None if term is None else term.value


def _float(term: Term | None) -> float | None:
    if term is None:
        return None
    try:
        return float(term.value)
    except ValueError:
        raise ExsceError(f"the store holds '{term.value}' where a number belongs") from None


def _int(term: Term | None) -> int:
    value = _float(term)
    return 0 if value is None else int(value)


def _bool(term: Term | None) -> bool | None:
    if term is None:
        return None
    return term.value in ("true", "1")


def _datetime(term: Term | None) -> datetime.datetime | None:
    if term is None:
        return None
    try:
        return datetime.datetime.fromisoformat(term.value.replace("Z", "+00:00"))
    except ValueError:
        return None


def python_value(term: Term | None) -> ParameterValue | None:
    """A literal as the Python value it was written from (numbers, booleans, strings)."""
    if term is None:
        return None
    if isinstance(term, Literal):
        datatype = term.datatype.value.rsplit("#", 1)[-1]
        if datatype == "boolean":
            return term.value in ("true", "1")
        if datatype in ("int", "integer", "long", "short", "byte"):
            return int(term.value)
        if datatype in ("double", "float", "decimal"):
            return float(term.value)
    return term.value


def _pose(pose: Pose | str) -> str:
    return pose if isinstance(pose, str) else pose_name(pose)


# -- runs -------------------------------------------------------------------------------


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


def runs(store: Store, scenario: str | None = None, namespace: str = DEFAULT_NAMESPACE) -> list[StoredRun]:
    """The runs of ``scenario`` (of every scenario if None), oldest first."""
    given = {} if scenario is None else {"scenario": scenario}
    found = []
    for row in run_query(store, "runs", given, namespace):
        found.append(
            StoredRun(
                uuid=_text(row["run"]) or "",
                scenario=_text(row["scenario_id"]) or "",
                start=_datetime(row["start"]),
                end=_datetime(row["end"]),
                bag=_text(row["bag"]) or None,
                path=_text(row["path"]),
            )
        )
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
    values = {_float(row["value"]) for row in rows}
    if len(values) > 1:
        raise ExsceError(f"the store holds {len(values)} values of {what}: {sorted(v or 0 for v in values)}")
    return next(iter(values), None)


@dataclass(frozen=True)
class Aggregate:
    """The mean and (population) standard deviation of ``count`` values."""

    mean: float
    std: float
    count: int


def _aggregate(rows: Rows) -> Aggregate | None:
    for row in rows:
        count = _int(row["count"])
        mean, variance = _float(row["mean"]), _float(row["variance"])
        if count == 0 or mean is None:
            return None
        return Aggregate(mean, math.sqrt(max(0.0, variance or 0.0)), count)
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
) -> Aggregate | None:
    """``metric`` over the path segment ``start`` → ``goal`` (that direction), in ``runs`` or in
    every run of ``scenario`` (give one of the two); None when no run went that way."""
    given: dict[str, str | Sequence[str]] = {"metric": metric, "start": _pose(start), "goal": _pose(goal)}
    if (runs is None) == (scenario is None):
        raise ExsceError("segment_metric needs either runs or a scenario")
    if runs is not None:
        if not runs:
            return None
        return _aggregate(run_query(store, "segment_metric", {**given, "run": list(runs)}, namespace))
    assert scenario is not None
    given["scenario"] = scenario
    return _aggregate(run_query(store, "segment_metric_of_scenario", given, namespace))


def segment_metric_any(
    store: Store, metric: str, start: Pose | str, goal: Pose | str, namespace: str = DEFAULT_NAMESPACE
) -> Aggregate | None:
    """``metric`` over the segment ``start`` → ``goal`` in every stored run of any scenario."""
    given = {"metric": metric, "start": _pose(start), "goal": _pose(goal)}
    return _aggregate(run_query(store, "segment_metric_any", given, namespace))


def segment_metric_between(
    store: Store, metric: str, start: Pose, goal: Pose, namespace: str = DEFAULT_NAMESPACE
) -> Aggregate | None:
    """``metric`` over every stored drive from ``start``'s position to ``goal``'s, whatever the
    headings, in runs of any scenario."""
    given = {"metric": metric, "from": point_name(start), "to": point_name(goal)}
    return _aggregate(run_query(store, "segment_metric_between", given, namespace))


def robot_metric_over_runs(
    store: Store, metric: str, robot: str, runs: Sequence[str], namespace: str = DEFAULT_NAMESPACE
) -> Aggregate | None:
    """A robot's whole-run values of ``metric`` over ``runs``."""
    if not runs:
        return None
    given = {"metric": metric, "robot": robot, "run": list(runs)}
    return _aggregate(run_query(store, "robot_metric_stats", given, namespace))


def mission_metric_over_runs(
    store: Store, metric: str, runs: Sequence[str], namespace: str = DEFAULT_NAMESPACE
) -> Aggregate | None:
    """The mission values of ``metric`` over ``runs``."""
    if not runs:
        return None
    given = {"metric": metric, "run": list(runs)}
    return _aggregate(run_query(store, "mission_metric_stats", given, namespace))


def waypoints_visited(
    store: Store, robot: str, runs: Sequence[str], namespace: str = DEFAULT_NAMESPACE
) -> Aggregate | None:
    """How many waypoints ``robot`` reached (goals that SUCCEEDED), over ``runs``."""
    return robot_metric_over_runs(store, "waypoints_visited", robot, runs, namespace)


def mission_duration(
    store: Store, runs: Sequence[str], namespace: str = DEFAULT_NAMESPACE
) -> Aggregate | None:
    """The mission's duration over ``runs``."""
    return mission_metric_over_runs(store, "mission_duration", runs, namespace)


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
        value, bag = _float(row["value"]) or 0.0, _text(row["bag"]) or ""
        key = (_text(row["robot"]), _text(row["segment"]), value, bag)
        grouped.setdefault(key, []).append(_text(row["topic"]) or "")
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
        ViolationDuration(_text(row["run"]) or "", _text(row["robot"]), _float(row["seconds"]) or 0.0)
        for row in rows
    ]


def violation_duration(
    store: Store, scenario: str, metric: str, namespace: str = DEFAULT_NAMESPACE
) -> dict[str | None, Aggregate]:
    """The mean (and deviation) over the runs of ``scenario`` of the violation duration of
    ``metric``, per robot (key None: the mission's)."""
    rows = run_query(store, "violation_duration_stats", {"scenario": scenario, "metric": metric}, namespace)
    found: dict[str | None, Aggregate] = {}
    for row in rows:
        aggregate = _aggregate(Rows(rows.variables, (tuple(row.values()),)))
        if aggregate is not None:
            found[_text(row["robot"])] = aggregate
    return found


def safety_metrics(store: Store, scenario: str, namespace: str = DEFAULT_NAMESPACE) -> list[str]:
    """The metrics with a safety limit whose violation time the runs of ``scenario`` recorded."""
    rows = run_query(store, "safety_metrics", {"scenario": scenario}, namespace)
    return [_text(row["metric"]) or "" for row in rows]


def hotspot_counts(
    store: Store, scenario: str, metric: str, namespace: str = DEFAULT_NAMESPACE
) -> dict[str, int]:
    """Run uuid → number of hotspots of safety ``metric``, for every run of ``scenario``."""
    rows = run_query(store, "hotspot_counts", {"scenario": scenario, "metric": metric}, namespace)
    return {_text(row["run"]) or "": _int(row["hotspots"]) for row in rows}


# -- oracles ----------------------------------------------------------------------------


def oracles(store: Store, scenario: str, namespace: str = DEFAULT_NAMESPACE) -> list[Oracle]:
    """The oracles that judge runs of ``scenario``: one per metric, robot, window, type and relation."""
    found = []
    for row in run_query(store, "oracles", {"scenario": scenario}, namespace):
        topics = tuple(sorted((_text(row["topics"]) or "").split()))
        type_text = _text(row["type"]) or ""
        try:
            oracle_type = OracleType(type_text)
        except ValueError:
            message = f"an oracle of scenario '{scenario}' has an unknown type '{type_text}'"
            raise ExsceError(message) from None
        found.append(
            Oracle(
                metric=_text(row["metric"]) or "",
                robot=_text(row["robot"]),
                relation=_text(row["relation"]) or "",
                type=oracle_type,
                base_scenario=_text(row["base"]) or "",
                topics=topics,
                value=_float(row["value"]),
                limit=_float(row["limit"]),
                delta=_float(row["delta"]),
                tolerance=_float(row["tolerance"]),
                package=_text(row["package"]),
                window=_text(row["window"]),
                criterion=_text(row["criterion"]) or "",
                sources=tuple((_text(row["runs"]) or "").split()),
            )
        )
    return found


def update_baseline(
    store: Store,
    scenario: str,
    metric: str,
    robot: str | None,
    value: float,
    tolerance: float,
    namespace: str = DEFAULT_NAMESPACE,
) -> None:
    """Set the baseline value and tolerance of the baseline oracle of ``metric`` (of ``robot``,
    or of the mission when None) of ``scenario``."""
    known = [
        o
        for o in oracles(store, scenario, namespace)
        if o.metric == metric and o.robot == robot and o.type is OracleType.BASELINE
    ]
    if not known:
        whose = f"robot '{robot}'" if robot is not None else "the mission"
        raise ExsceError(f"scenario '{scenario}' has no baseline oracle of '{metric}' for {whose}")
    given: dict[str, str] = {
        "scenario": scenario,
        "metric": metric,
        "value": repr(float(value)),
        "tolerance": repr(float(tolerance)),
    }
    if robot is None:
        run_query(store, "update_mission_baseline", given, namespace)
    else:
        run_query(store, "update_baseline", {**given, "robot": robot}, namespace)


# -- scenarios ----------------------------------------------------------------------------


@dataclass(frozen=True)
class RobotFacts:
    """A robot of a scenario with the hardware facts similarity uses."""

    robot: str
    type: str | None
    base: str | None
    torso: bool | None


def scenario_ids(store: Store, namespace: str = DEFAULT_NAMESPACE) -> list[str]:
    """The id of every scenario in the store, in order."""
    return [_text(row["scenario"]) or "" for row in run_query(store, "scenarios", {}, namespace)]


def robots(store: Store, scenario: str, namespace: str = DEFAULT_NAMESPACE) -> list[RobotFacts]:
    """The robots of ``scenario``, by id, with their type, base type and torso."""
    return [
        RobotFacts(_text(row["robot"]) or "", _text(row["type"]), _text(row["base"]), _bool(row["torso"]))
        for row in run_query(store, "robots", {"scenario": scenario}, namespace)
    ]


@dataclass(frozen=True)
class PathSegment:
    """Two consecutive poses of a robot's path (pose entity names, with their headings)."""

    robot: str
    start: str
    goal: str


def path_segments(store: Store, scenario: str, namespace: str = DEFAULT_NAMESPACE) -> list[PathSegment]:
    """The path segments of ``scenario``: for each robot, from its start pose through the
    waypoints of its tasks in order, each pair of consecutive poses."""
    return [
        PathSegment(_text(row["robot"]) or "", _text(row["start"]) or "", _text(row["goal"]) or "")
        for row in run_query(store, "path_segments", {"scenario": scenario}, namespace)
    ]


def derivation_of(store: Store, scenario: str, namespace: str = DEFAULT_NAMESPACE) -> Derivation | None:
    """How ``scenario`` was derived: its base and the transformations applied, in order (None if
    it was written, not derived)."""
    bases: set[str] = set()
    steps: dict[int, tuple[str, list[tuple[str, ParameterValue]]]] = {}
    for row in run_query(store, "derivation", {"scenario": scenario}, namespace):
        bases.add(_text(row["base"]) or "")
        if row["step"] is None:
            continue
        number = _int(row["step"])
        _, parameters = steps.setdefault(number, (_text(row["transformation"]) or "", []))
        key, value = _text(row["parameter"]), python_value(row["value"])
        if key is not None and value is not None:
            parameters.append((key, value))
    if not bases:
        return None
    if len(bases) > 1:
        raise ExsceError(
            f"the store says scenario '{scenario}' was derived from {len(bases)} scenarios: "
            f"{', '.join(sorted(bases))}"
        )
    return Derivation(
        scenario,
        bases.pop(),
        tuple(TransformationStep(name, tuple(sorted(params))) for _, (name, params) in sorted(steps.items())),
    )


def lineage(store: Store, scenario: str, namespace: str = DEFAULT_NAMESPACE) -> list[Derivation]:
    """Where ``scenario`` comes from, transitively: its derivation, its base's, and so on back to a
    scenario that was written by hand (first the scenario's own)."""
    chain: list[Derivation] = []
    seen = {scenario}
    current = scenario
    while (derivation := derivation_of(store, current, namespace)) is not None:
        chain.append(derivation)
        if derivation.base in seen:
            raise ExsceError(f"scenario '{derivation.base}' is its own ancestor in the store")
        seen.add(derivation.base)
        current = derivation.base
    return chain


def derived_scenarios(store: Store, scenario: str, namespace: str = DEFAULT_NAMESPACE) -> list[str]:
    """The scenarios derived from ``scenario`` directly."""
    rows = run_query(store, "derived_scenarios", {"base": scenario}, namespace)
    return [_text(row["derived"]) or "" for row in rows]


@dataclass(frozen=True)
class MetricReading:
    """One metric value of a run: a whole-run value (``action`` None), or one action's
    (``action`` its IRI, ``goal`` the goal pose's name with its heading)."""

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


def run_metric_values(
    store: Store, runs: Sequence[str], namespace: str = DEFAULT_NAMESPACE
) -> list[MetricReading]:
    """Every whole-run metric value of ``runs``: each robot's and the mission's."""
    if not runs:
        return []
    found = []
    for row in run_query(store, "run_metric_values", {"run": list(runs)}, namespace):
        run, metric, value = _text(row["run"]), _text(row["metric"]), _float(row["value"])
        if run is not None and metric is not None and value is not None:
            reading = MetricReading(
                run, metric, _text(row["robot"]), value, safety=_text(row["safety"]), unit=_text(row["unit"])
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
        run, metric, value = _text(row["run"]), _text(row["metric"]), _float(row["value"])
        action, goal = _text(row["action"]), _text(row["goal"])
        if None not in (run, metric, value, action, goal):
            assert run is not None and metric is not None and value is not None and goal is not None
            pose = goal.rsplit("/", 1)[-1]
            found.append(MetricReading(run, metric, _text(row["robot"]), value, action, pose))
    return found


def failed_runs(store: Store, scenario: str, namespace: str = DEFAULT_NAMESPACE) -> set[str]:
    """The runs of ``scenario`` an oracle failed when they were last verified."""
    rows = run_query(store, "failed_runs", {"scenario": scenario}, namespace)
    return {_text(row["run"]) or "" for row in rows}
