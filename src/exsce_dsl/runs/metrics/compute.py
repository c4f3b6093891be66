"""A run's metrics, computed by the generated monitors of its metric declarations.

Windows come from the waypoint dispatcher (the mission, each robot's part of
it, each path segment); the values inside them from ``RobotMetrics`` and
``MissionMetrics`` (:mod:`exsce_dsl.monitor_code`).  A metric that is
``safe below|above`` a limit also gets its ``violation_duration`` and its
hotspots, from the per-message values its monitor prepared.  A metric whose
topics are missing from the bag is *missing* (no value, and a problem is
reported), never 0.
"""

from __future__ import annotations

from collections.abc import Collection, Mapping, Sequence
from types import ModuleType
from typing import Any

import numpy as np

from exsce_dsl.model.conventions import METHOD_TOPICS
from exsce_dsl.model.geometry import Position
from exsce_dsl.model.metrics import SIGNAL_TYPES, ComputedFor, MetricDefinition, signal_pattern
from exsce_dsl.model.robots import Robot
from exsce_dsl.model.runs import Accounting, ActionId, Hotspot, MetricScope, MetricValue, SourceCount
from exsce_dsl.monitor_code import topics_used
from exsce_dsl.monitor_kit import monitor_core as core
from exsce_dsl.runs.metrics.accounting import GOALS_SPAN, MISSION_SPAN, SampleCounter, segment_reason
from exsce_dsl.runs.segments.recorded import RecordedAction

HOTSPOT_RADIUS = 1.0  # metres: violations closer than this to a hotspot belong to it
POSE_SIGNAL = signal_pattern("pose")
"""Where hotspots are located: each robot's pose signal (its ``x`` and ``y``), wherever its
convention puts it."""

Window = tuple[RecordedAction | None, float, float]


def compute_metrics(
    monitors: ModuleType,
    metrics: Sequence[MetricDefinition],
    robots: Sequence[Robot],
    topics: Mapping[str, core.Topic],
    actions: Sequence[RecordedAction],
    results: Mapping[str, int | None],
    problems: list[str],
    whole_runs: Mapping[str, tuple[float, float]] | None = None,
    named: Mapping[str, str] | None = None,
    reasons: Mapping[str, str] | None = None,
    standing: Collection[str] = (),
) -> tuple[list[MetricValue], list[Hotspot]]:
    """Every metric of ``metrics`` for a run. ``results``: robot → waypoints SUCCEEDED (None: no topic);
    ``whole_runs``: robot → the span its whole-run values cover, where it is not its path
    segments' (a robot without segments, or whose window is its whole recording);
    ``named``: a topic the monitors read → how the run's problems name it: the bag's topics it was
    read from, or the sources looked for (a robot's signals are read where its convention puts
    them); ``reasons``: robot → why
    its ``whole_runs`` span is its whole-run window (the recording, and why); ``standing``: the
    robots given no tasks that have no path segments, measured standing by over their recording
    (what they were given no goals for, such as ``task_duration``, is not computed, and said so);
    the mission's values that do not read goals count them (a robot standing in a corridor is one
    the others must keep away from) over the mission's window, which their recordings do not
    widen.  Each value carries its accounting: window, reason, and the samples of each source it
    used."""
    named = named or {}
    values: list[MetricValue] = []
    hotspots: list[Hotspot] = []
    done = [(a, a.start, a.end) for a in actions if a.start is not None and a.end is not None]
    spans = [(s, e) for _, s, e in done] + [w for r, w in (whole_runs or {}).items() if r not in standing]
    by_subject = {s: [m for m in metrics if m.subject is s] for s in ComputedFor}
    for robot in robots:
        mine: list[Window] = [(a, s, e) for a, s, e in done if a.robot == robot.id]
        whole = (whole_runs or {}).get(robot.id)
        if not mine and whole is None:
            problems.append(f"robot '{robot.id}' started no waypoint goal: its metrics are missing")
            continue
        # the robot's whole-run window: its goals' (first start to last end), unless told otherwise
        start, end = whole if whole is not None else (min(s for _, s, _ in mine), max(e for _, _, e in mine))
        why = (reasons or {}).get(robot.id, "the recording") if whole is not None else GOALS_SPAN
        monitor = monitors.RobotMetrics(robot.id, robot.namespace, topics, results.get(robot.id))
        counter = SampleCounter(topics)
        measured = by_subject[ComputedFor.ROBOT]
        if robot.id in standing:
            measured = _standing_by(robot, measured, problems)
        for metric in measured:
            windows = [(None, start, end), *mine]
            values += _robot_values(monitor, metric, robot, windows, problems, named, (counter, why))
            if metric.safety is not None:
                values += _robot_violations(monitor, metric, robot, (start, end), hotspots, (counter, why))
    if spans:
        start, end = min(s for s, _ in spans), max(e for _, e in spans)
        fleet = [(r.id, r.namespace) for r in robots]
        monitor = monitors.MissionMetrics(fleet, topics)
        # a robot not in the recording (no goals, no signals) adds nothing to what the mission read
        acting = [r for r in robots if any(a.robot == r.id for a, _, _ in done) or r.id in (whole_runs or {})]
        for metric in by_subject[ComputedFor.MISSION] + by_subject[ComputedFor.PAIRS]:
            reading = [r for r in acting if r.id not in standing] if _reads_goals(metric) else acting
            values += _mission_values(monitor, metric, reading, start, end, topics, hotspots, problems, named)
    return values, hotspots


def _standing_by(
    robot: Robot, metrics: Sequence[MetricDefinition], problems: list[str]
) -> list[MetricDefinition]:
    """The metrics of a robot given no tasks: those that do not read its goals (it has none to
    time or count), the others said in ``problems``."""
    kept = [m for m in metrics if not _reads_goals(m)]
    left = [m.name for m in metrics if m not in kept]
    if left:
        problems.append(
            f"robot '{robot.id}' has no tasks: {', '.join(left)} not measured (it was given no goals); "
            "its other metrics are of the recording, standing by"
        )
    return kept


def _reads_goals(metric: MetricDefinition) -> bool:
    """Whether ``metric`` reads a robot's navigation goals (a robot given no tasks has none)."""
    return any(r.signal == "goals" for r in metric.reads)


def _topics(metric: MetricDefinition, alternative: int, namespaces: Sequence[str]) -> tuple[str, ...]:
    """The topics an alternative of ``metric`` read, for robots of these namespaces (in order)."""
    used = topics_used(metric, alternative)
    found: list[str] = []
    for n, ns in enumerate(namespaces):
        for whose, pattern in used:
            if whose is None or (metric.pair is not None and metric.pair.index(whose) == n):
                topic = core.expand_topic(pattern, ns)
                if topic not in found:
                    found.append(topic)
    return tuple(found)


def _missing(
    metric: MetricDefinition,
    robot: Robot,
    topics: Mapping[str, core.Topic],
    start: float,
    end: float,
    named: Mapping[str, str],
) -> str:
    wanted = _topics(metric, 0, [robot.namespace])
    absent = [t for t in wanted if t not in topics or not len(topics[t])]  # dispatcher topics never are
    what = f"{metric.name} of '{robot.id}'" + (" and its violation duration" if metric.safety else "")
    verb = "are" if metric.safety else "is"
    if absent:
        return f"{_absent(absent, named)}: {what} {verb} missing{_signal_hint(absent, [robot.namespace])}"
    outside = _outside(wanted, topics, start, end, named)
    return f"{what} {verb} missing" + (f": {outside}" if outside else "")


def _signal_hint(absent: Sequence[str], namespaces: Sequence[str]) -> str:
    """Where a metric reads one of the method's topics by name and the bag lacks it: the signal
    that reads it wherever the robot's type says it is (a topic read by name is the bag's)."""
    said = [
        f"`robot {signal}`"
        for signal in SIGNAL_TYPES
        if signal in METHOD_TOPICS
        and any(core.expand_topic(METHOD_TOPICS[signal], ns) in absent for ns in namespaces)
    ]
    return (
        f" (to read it wherever the robot's type says it is, read the signal {' or '.join(said)})"
        if said
        else ""
    )


def _absent(absent: Sequence[str], named: Mapping[str, str]) -> str:
    """``topic /a, /b is missing``, or what was looked for instead where ``named`` says (``no
    velocity (looked for /cmd_vel, /odom)``)."""
    said = list(dict.fromkeys(named.get(t, t) for t in absent))
    if not any(s.startswith("no ") for s in said):
        return f"topic {', '.join(said)} is missing"
    return "; ".join(s if s.startswith("no ") else f"no topic {s}" for s in said)


def _outside(
    wanted: Sequence[str],
    topics: Mapping[str, core.Topic],
    start: float,
    end: float,
    named: Mapping[str, str],
) -> str:
    """Which of the ``wanted`` topics have no message near the window, with both time ranges."""
    found = [
        f"{named.get(name, name)} ({_span(topic.t[0], topic.t[-1])})"
        for name in wanted
        if (topic := topics.get(name)) is not None and len(topic) and not core.overlaps(topic.t, start, end)
    ]
    if not found:
        return ""
    return f"the window {_span(start, end)} does not overlap {', '.join(found)}"


def _span(start: float, end: float) -> str:
    return f"{start:.3f}..{end:.3f} s"


def _robot_values(
    monitor: Any,
    metric: MetricDefinition,
    robot: Robot,
    windows: list[Window],
    problems: list[str],
    named: Mapping[str, str],
    counting: tuple[SampleCounter, str],
) -> list[MetricValue]:
    prepared = monitor.prepared(metric.name)
    if prepared is None:
        problems.append(_missing(metric, robot, monitor.topics, windows[0][1], windows[0][2], named))
        return []
    counter, whole_reason = counting
    getter = getattr(monitor, f"get_{metric.name}")
    unit = metric.unit or None  # a count has no unit
    topics = _topics(metric, prepared[0], [robot.namespace])  # one alternative for the whole run
    found: list[MetricValue] = []
    lacking: list[tuple[float, float]] = []
    for action, start, end in windows if metric.per_segment else windows[:1]:
        value = getter(start, end)
        if value is None:
            if action is None:
                problems.append(_missing(metric, robot, monitor.topics, start, end, named))
            else:
                lacking.append((start, end))
            continue
        why = (
            whole_reason
            if action is None
            else segment_reason(action.allocation, action.subtask, action.waypoint)
        )
        used = counter.accounting(prepared[1], topics, (start, end), why)
        if action is None:
            found.append(
                MetricValue(
                    metric.name, MetricScope.ROBOT, value, topics, robot.id, unit=unit, accounting=used
                )
            )
        else:
            aid = ActionId(robot.id, action.allocation, action.subtask, action.waypoint)
            found.append(
                MetricValue(metric.name, MetricScope.SEGMENT, value, topics, None, aid, unit, accounting=used)
            )
    if lacking:
        outside = _outside(topics, monitor.topics, *lacking[0], named)
        problems.append(
            f"{metric.name} of '{robot.id}' is missing for {len(lacking)} of {len(windows) - 1} path segments"
            + (f" (the first: {outside})" if outside else "")
        )
    return found


def _over(metric: MetricDefinition, values: np.ndarray) -> np.ndarray:
    """Which per-message values break the metric's safety limit (a message without one does not)."""
    assert metric.safety is not None
    limit = metric.safety.limit
    with np.errstate(invalid="ignore"):
        over: np.ndarray = values > limit if metric.safety.bound == "below" else values < limit
    return over


def _violations(p: core.Prepared, metric: MetricDefinition, start: float, end: float) -> tuple[Any, ...]:
    w = core.window(p.t, start, end)
    t = p.t[w]
    held = core.hold(t)
    over = _over(metric, p.v[w])
    return t, held, over


def _robot_violations(
    monitor: Any,
    metric: MetricDefinition,
    robot: Robot,
    window: tuple[float, float],
    hotspots: list[Hotspot],
    counting: tuple[SampleCounter, str],
) -> list[MetricValue]:
    start, end = window
    topics = monitor.topics
    prepared = monitor.prepared(metric.name)
    if prepared is None or getattr(monitor, f"get_{metric.name}")(start, end) is None:
        return []  # the metric is missing, so are its violations and hotspots
    choice, aggregates = prepared
    t, held, over = _violations(aggregates[0], metric, start, end)
    source = _topics(metric, choice, [robot.namespace])
    pose = _pose(topics, robot.namespace)
    if over.any() and pose is not None:
        where = _position_at(pose, t[over])
        hotspots.extend(
            Hotspot(metric.name, Position(float(c[0]), float(c[1])), n, d, robot.id)
            for c, n, d in group_hotspots(where, held[over])
        )
    return [
        MetricValue(
            "violation_duration",
            MetricScope.ROBOT,
            float(held[over].sum()),
            source,
            robot.id,
            unit="s",
            safety_metric=metric.name,
            accounting=counting[0].accounting(aggregates[:1], source, window, counting[1], held=True),
        )
    ]


def _mission_values(
    monitor: Any,
    metric: MetricDefinition,
    robots: Sequence[Robot],
    start: float,
    end: float,
    topics: Mapping[str, core.Topic],
    hotspots: list[Hotspot],
    problems: list[str],
    named: Mapping[str, str],
) -> list[MetricValue]:
    value = getattr(monitor, f"get_{metric.name}")(start, end)
    if metric.subject is ComputedFor.MISSION:
        if value is None:
            problems.append(f"{metric.name} of the mission is missing")
            return []
        read = _topics(metric, 0, [r.namespace for r in robots])
        found = monitor.prepared(metric.name, ("", ""), ("", ""))
        used = SampleCounter(topics).accounting(found[1] if found else [], read, (start, end), MISSION_SPAN)
        return [
            MetricValue(
                metric.name, MetricScope.MISSION, value, read, unit=metric.unit or None, accounting=used
            )
        ]
    if value is None:
        if len(robots) >= 2:
            problems.append(_pairs_missing(monitor, metric, start, end, named))
        return []
    source: list[str] = []
    violation = 0.0
    counter, counts = SampleCounter(topics), dict[str, SourceCount]()
    for first, second in monitor.pairs():
        prepared = monitor.prepared(metric.name, first, second)
        if prepared is None:
            continue
        choice, aggregates = prepared
        read = _topics(metric, choice, [first[1], second[1]])
        source += [t for t in read if t not in source]
        for c in counter.accounting(aggregates, read, (start, end), MISSION_SPAN).sources:
            if c.topics[0] not in counts or counts[c.topics[0]].used < c.used:
                counts[c.topics[0]] = c
        if metric.safety is None:
            continue
        t, held, over = _violations(aggregates[0], metric, start, end)
        violation += float(held[over].sum())
        poses = [_pose(topics, ns) for _, ns in (first, second)]
        if over.any() and poses[0] is not None and poses[1] is not None:
            middle = (_position_at(poses[0], t[over]) + _position_at(poses[1], t[over])) / 2
            hotspots.extend(
                Hotspot(metric.name, Position(float(c[0]), float(c[1])), n, d)
                for c, n, d in group_hotspots(middle, held[over])
            )
    used = Accounting(start, end, MISSION_SPAN, tuple(counts.values()))
    found = [
        MetricValue(
            metric.name, MetricScope.MISSION, value, tuple(source), unit=metric.unit or None, accounting=used
        )
    ]
    if metric.safety is not None:
        found.append(
            MetricValue(
                "violation_duration",
                MetricScope.MISSION,
                violation,
                tuple(source),
                unit="s",
                safety_metric=metric.name,
                accounting=used,
            )
        )
    return found


def _pairs_missing(
    monitor: Any, metric: MetricDefinition, start: float, end: float, named: Mapping[str, str]
) -> str:
    """Why a metric over pairs of robots is missing: the pairs that have no value."""
    lacking, hint = [], ""
    for first, second in monitor.pairs():
        if getattr(monitor, f"_{metric.name}")(start, end, first, second) is not None:
            continue
        read = _topics(metric, 0, [first[1], second[1]])
        absent = [t for t in read if t not in monitor.topics or not len(monitor.topics[t])]
        said = list(dict.fromkeys(named.get(t, t) for t in absent))
        lacked = "; ".join(s if s.startswith("no ") else f"no {s}" for s in said)
        why = lacked if absent else _outside(read, monitor.topics, start, end, named)
        lacking.append(f"{first[0]} and {second[0]}" + (f" ({why})" if why else ""))
        hint = hint or _signal_hint(absent, [first[1], second[1]])
    what = f"{metric.name} of the mission" + (" and its violation duration are" if metric.safety else " is")
    return f"{what} missing: no value for {'; '.join(lacking)}{hint}"


def _pose(topics: Mapping[str, core.Topic], namespace: str) -> core.Topic | None:
    found = topics.get(core.expand_topic(POSE_SIGNAL, namespace))
    return found if found is not None and len(found) else None


def _position_at(pose: core.Topic, times: np.ndarray) -> np.ndarray:
    x, y = (np.interp(times, pose.t, pose.fields[axis]) for axis in ("x", "y"))
    return np.column_stack([x, y])


def group_hotspots(points: np.ndarray, durations: np.ndarray) -> list[tuple[np.ndarray, int, float]]:
    """Greedy spatial clustering: a point joins the first centre within HOTSPOT_RADIUS."""
    centres: list[list[float]] = []
    members: list[list[int]] = []
    for i, p in enumerate(points):
        for k, c in enumerate(centres):
            if np.hypot(p[0] - c[0], p[1] - c[1]) <= HOTSPOT_RADIUS:
                members[k].append(i)
                c[:] = points[members[k]].mean(axis=0)
                break
        else:
            centres.append([float(p[0]), float(p[1])])
            members.append([i])
    return [(np.asarray(c), len(m), float(durations[m].sum())) for c, m in zip(centres, members, strict=True)]
