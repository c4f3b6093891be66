"""A bag file and its scenario in, the run (actions, metrics, hotspots) out."""

from __future__ import annotations

import datetime as dt
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from types import ModuleType

from exsce_dsl.errors import BagError, IncompleteRunError
from exsce_dsl.lang import standard_metrics
from exsce_dsl.messages.field_check import field_checker
from exsce_dsl.model import Scenario
from exsce_dsl.model.conventions import MetricSpan
from exsce_dsl.model.expressions import Field, walk
from exsce_dsl.model.messages import DISPATCHER, FieldPath
from exsce_dsl.model.metrics import MetricDefinition
from exsce_dsl.model.robots import Robot
from exsce_dsl.model.runs import (
    Bag,
    MetricValue,
    Run,
    RunClock,
    run_uuid,
)
from exsce_dsl.monitor_code import load_monitors
from exsce_dsl.monitor_kit.monitor_core import Compute, Topic, expand_topic, reducer
from exsce_dsl.remedies import STRICT_STORES_NONE
from exsce_dsl.runs.bag_identity import content_hash
from exsce_dsl.runs.bags.data import OBJECTS, BagData, Reduce, Wanted
from exsce_dsl.runs.bags.reading import OpenedBag, open_bag
from exsce_dsl.runs.coverage import (
    PROV_TOPIC,
    Recording,
    declared_rates,
    find_coverage,
    recorded_mission_status,
    with_findings,
)
from exsce_dsl.runs.metrics.accounting import on_wall_clock
from exsce_dsl.runs.metrics.compute import compute_metrics
from exsce_dsl.runs.missing import missing_metrics, unread_topics
from exsce_dsl.runs.plausible_poses import Refused, refuse_implausible, spec_speed_limit
from exsce_dsl.runs.recorded_execution import recorded_execution
from exsce_dsl.runs.robots import StackRobots, stack_robots
from exsce_dsl.runs.segments.recorded import RecordedAction, task_executions
from exsce_dsl.runs.segments.sources import DISPATCHER_SOURCE, segment_robot
from exsce_dsl.runs.segments.track import Track
from exsce_dsl.runs.signals.detect import Detected, pose_like_topics, with_detected_conventions
from exsce_dsl.runs.signals.recording import read_on_timeline
from exsce_dsl.runs.signals.timeline import Timeline
from exsce_dsl.wording import counted


@dataclass(frozen=True)
class AnalysedRun:
    run: Run
    content_hash: str
    problems: list[str] = field(default_factory=list)
    timeline: Timeline | None = None
    """The run's timeline: which clock each source was timed by."""
    detected: list[Detected] = field(default_factory=list)
    """The conventions detected for robots whose type names none."""

    def picked(self) -> list[str]:
        """What ingestion decided for this bag: each detected convention, and the timeline when
        it is not simply the wall clock (in ``exscec bag info``'s words)."""
        said = [d.describe() for d in self.detected]
        if self.timeline is not None and _told(self.timeline):
            said.append(f"timeline: {self.timeline.describe()}")
        return said

    def clocks(self) -> list[str]:
        """Which clock each source was timed by, on the run's timeline."""
        if self.timeline is None:
            return []
        said = [] if _told(self.timeline) else [f"timeline: {self.timeline.describe()}"]
        mapping = self.timeline.mapping()
        said += [mapping] if mapping else []
        return said + [f"clock of {c.describe()}" for c in self.timeline.clocks]


def _told(timeline: Timeline) -> bool:
    """Whether ingestion tells the timeline without ``-v``: simulated, or log time no date."""
    return timeline.simulated or not timeline.dated


def run_metrics(scenario: Scenario) -> tuple[MetricDefinition, ...]:
    """The metrics a run of ``scenario`` gets: the standard library's, then its specification's."""
    return standard_metrics() + scenario.metrics


def wanted_topics(metrics: tuple[MetricDefinition, ...], robots: list[Robot]) -> dict[str, Wanted]:
    """Topic → its message type (the dispatcher's: kept as message objects) and the fields the
    metrics read of it."""
    types: dict[str, str] = {}
    paths: dict[str, dict[FieldPath, None]] = {}
    for robot in robots:
        ns = robot.namespace.strip("/")
        for metric in metrics:
            read_paths = fields_read(metric)
            for read in metric.reads:
                if read.signal and read.signal != "scan":  # read from the sources runs/signals chooses
                    continue
                # a scan signal keeps the fields the metric reads of it (StackRobots.adapt)
                topic = expand_topic(read.topic, ns)
                types.setdefault(topic, OBJECTS if read.msgtype in DISPATCHER else read.msgtype)
                paths.setdefault(topic, {}).update(dict.fromkeys(read_paths.get(read.name, ())))
    return {topic: Wanted(msgtype, tuple(paths.get(topic, {}))) for topic, msgtype in types.items()}


def fields_read(metric: MetricDefinition) -> dict[str, list[FieldPath]]:
    """Read name → the field paths the metric's expressions use of it."""
    found: dict[str, list[FieldPath]] = {}
    for expr in (metric.value, metric.fallback):
        for node in walk(expr) if expr is not None else []:
            if isinstance(node, Field) and node.path not in found.setdefault(node.read, []):
                found[node.read].append(node.path)
    return found


def reductions(monitors: ModuleType, robots: list[Robot], stacks: StackRobots) -> dict[str, Reduce]:
    """Topic → what to reduce of each block of its messages as the bag is read (the monitors'
    aggregates over arrays), so that no topic's arrays are ever all in memory.  A scan signal
    (``/{ns}/~scan``) is reduced as its bag topic (``/base_scan``) is read: the reader keeps no
    arrays of a topic it reduces, so a reduction keyed by the signal's name alone left the
    monitors without the scan's ranges."""
    entries: dict[str, list[tuple[str, str, Compute]]] = {}
    for robot in robots:
        for pattern, key, func, compute in monitors.REDUCERS:
            name = expand_topic(pattern, robot.namespace)
            for topic in dict.fromkeys([name, stacks.read_from(name) or name]):
                entries.setdefault(topic, []).append((key, func, compute))
    return {topic: reducer(found) for topic, found in entries.items()}


def analyse_bag(
    path: Path,
    scenario: Scenario,
    digest: str | None = None,
    run_id: str | None = None,
    strict: bool = False,
) -> AnalysedRun:
    """The metrics of the bag at ``path`` as a run of ``scenario``; ``digest`` is the bag's
    :func:`content_hash` when the caller has it already, ``run_id`` the run's id when it is not
    the bag's own (:func:`~exsce_dsl.model.runs.run_uuid` of its sha256); ``strict``: a metric value
    that would be missing is an :class:`IncompleteRunError` (saying why, as the run's problems
    would).

    Every robot goes through the same steps: its signals from the sources its convention names
    (detected from the bag when its type names none), every series on the run's one timeline,
    then its path segments, then the metrics over both."""
    if digest is None:
        digest = content_hash(path) if path.exists() else ""
    metrics = run_metrics(scenario)
    source = scenario.location.file if scenario.location else scenario.id
    monitors = load_monitors(metrics, source)
    bag = _read_signals(path, scenario, metrics, monitors)
    dated = bag.timeline.dated  # taken as the signals step ends: assembling the run enters no step
    found = _segment_robots(path, scenario, bag)
    tasks = task_executions(found.actions, found.segmented_by, bag.timeline.to_wall)
    robots, stacks = bag.robots, bag.stacks
    values, hotspots = compute_metrics(
        monitors,
        metrics,
        robots,
        bag.refused.usable(bag.topics),
        found.actions,
        found.results,
        bag.problems,
        found.whole_runs,
        {**bag.named, **bag.refused.reasons},
        found.reasons,
        found.standing,
    )
    values = [_bag_named(stacks.with_real_sources(v), bag.data.spellings) for v in values]
    real = {n: _spelt(stacks.real_topics.get(n, (n,)), bag.data.spellings) for n in bag.topics}
    values = on_wall_clock(values, bag.timeline.to_wall, real, stacks.real_chains)
    if strict:
        acting = [r.id for r in robots if scenario.mission.tasks_of(r.id)]
        lacking = missing_metrics(metrics, robots, acting, found.actions, values)
        if lacking:
            problem, why = _incomplete(path, lacking, bag.problems)
            raise IncompleteRunError(problem, remedy=STRICT_STORES_NONE, about=why)
    status = recorded_mission_status(path, bag.data.messages.get(PROV_TOPIC, ()))
    covered = find_coverage(
        Recording(
            scenario, robots, bag.data, bag.timeline, found.actions, values, status, found.whole_runs,
            declared_rates(robots, stacks.sources, bag.data),
        )
    )  # fmt: skip
    bag.problems += covered.said()
    values = [with_findings(v, covered.gaps) for v in values]
    run = Run(
        uuid=run_id or run_uuid(digest),
        scenario=scenario.id,
        start=_time(bag.recorded.start),
        end=_time(bag.recorded.end),
        bag=Bag(path.name, bag.data.topics, str(path.resolve())),
        tasks=tasks,
        metrics=tuple(values),
        hotspots=tuple(hotspots),
        clocks=_run_clocks(bag.timeline, bag.data.spellings),
        dated=dated,
        conventions=tuple((d.robot, d.convention, d.evidence) for d in bag.detected),
        status=status,
        coverage=covered.gaps,
        topic_rates=covered.rates,
        problems=tuple(dict.fromkeys(bag.problems)),
        execution=recorded_execution(path, scenario.id, bag.data.messages.get(PROV_TOPIC, ())),
    )
    return AnalysedRun(run, digest, bag.problems, bag.timeline, bag.detected)


@dataclass
class _Signals:
    """A bag read as a run of a scenario: its robots (conventions detected where their type names
    none), where their signals were read from, every series on the run's one timeline, and the
    problems found so far."""

    opened: OpenedBag
    """The bag, its topics and their types from its index."""
    robots: list[Robot]
    detected: list[Detected]
    stacks: StackRobots
    unread: list[str]
    recorded: BagData
    timeline: Timeline
    data: BagData
    topics: dict[str, Topic]
    problems: list[str]
    refused: Refused = field(default_factory=Refused)
    """The topics whose poses no robot could make: the monitors do not read them."""
    named: dict[str, str] = field(default_factory=dict)
    """How the run's problems name what the monitors read of the robots (:meth:`StackRobots.named`)."""
    tracks: dict[str, Track] = field(default_factory=dict)
    """Each robot's pose, for segmentation (an implausible pose is none)."""
    spans: dict[str, tuple[float, float] | None] = field(default_factory=dict)
    """Each robot's signals' first and last message (None: it has none)."""


def _read_signals(
    path: Path, scenario: Scenario, metrics: tuple[MetricDefinition, ...], monitors: ModuleType
) -> _Signals:
    """Read what the metrics need of the bag at ``path``, put it on one timeline, and each
    robot's signals from the sources its convention names (``/{ns}/~pose``...)."""
    opened = open_bag(path)
    types = opened.topics
    robots, detected = with_detected_conventions(
        [r for r in scenario.robots if r.start_pose is not None], types
    )
    stacks = stack_robots(robots, types)
    unread = unread_topics(scenario.metrics, robots, types)
    wanted = stacks.adapt(wanted_topics(metrics, robots), robots)
    if PROV_TOPIC in types:
        wanted[PROV_TOPIC] = Wanted(OBJECTS)
    checked = field_checker(metrics, robots)
    on_line = read_on_timeline(opened, wanted, reductions(monitors, robots, stacks), checked)
    recorded, timeline, data = on_line.recorded, on_line.timeline, on_line.data
    problems = unread + list(data.problems) + list(timeline.notes)
    for sources in stacks.sources.values():
        problems += sources.notes
    topics = {name: Topic(name, s.t, s.fields) for name, s in data.series.items()}
    topics.update(stacks.signal_series(data, problems))
    refused = refuse_implausible(robots, stacks, topics, data, spec_speed_limit(scenario.metrics))
    problems += refused.problems
    # an implausible pose places no arrival; the whole run still spans the recording
    usable = refused.usable(topics)
    return _Signals(
        opened, robots, detected, stacks, unread, recorded, timeline, data, topics, problems, refused,
        stacks.named(robots),
        {r.id: stacks.track(r, usable) for r in robots},
        {r.id: stacks.recorded_span(r, topics) for r in robots},
    )  # fmt: skip


@dataclass
class _Segmented:
    """Each robot's path segments, whether its mission succeeded, the span that stands for its
    whole run (where it has no segments, its segments are arrivals, not recorded goals, or its
    metrics are windowed on the recording), and
    which source segmented it when not the method's dispatcher."""

    actions: list[RecordedAction] = field(default_factory=list)
    results: dict[str, int | None] = field(default_factory=dict)
    whole_runs: dict[str, tuple[float, float]] = field(default_factory=dict)
    segmented_by: dict[str, str] = field(default_factory=dict)
    reasons: dict[str, str] = field(default_factory=dict)
    """Robot → why its whole-run window is the recording."""
    standing: list[str] = field(default_factory=list)
    """The robots given no tasks and with no path segments, whose signals are in the bag: they
    stand by, and their whole run is the recording."""


def _segment_robots(path: Path, scenario: Scenario, bag: _Signals) -> _Segmented:
    """Each robot's path segments from the first segmentation source that finds them."""
    stacks, data, out = bag.stacks, bag.data, _Segmented()
    for robot in bag.robots:
        ns = robot.namespace.strip("/")
        found = segment_robot(scenario, robot, data, bag.tracks[robot.id])
        bag.problems += found.problems
        out.actions.extend(found.segments)
        if found.source and found.source != DISPATCHER_SOURCE:
            out.segmented_by[robot.id] = found.source
        out.results[robot.id] = found.succeeded
        stacks.name_goals(ns, found.topics, found.outcomes, found.source == DISPATCHER_SOURCE)
        # the whole run is the recording unless recorded goals span it: never an arrival
        recording = robot.signals.window is MetricSpan.RECORDING or not found.goals
        span = bag.spans[robot.id]
        if not scenario.mission.tasks_of(robot.id):
            if not found.segments and span is not None:  # it stands by: its signals still measure it
                out.whole_runs[robot.id] = _recording(span, data)
                out.reasons[robot.id] = "the recording (no tasks: the robot stands by)"
                out.standing.append(robot.id)
        elif not found.segments or recording:
            if span is None and not found.segments:
                raise BagError("\n  ".join([_nothing_of(path, robot, bag.opened.topics), *bag.unread]))
            if span is not None:
                out.whole_runs[robot.id] = _recording(span, data)
                out.reasons[robot.id] = _why_recording(robot, found.goals, bool(found.segments))
    return out


def _why_recording(robot: Robot, goals: bool, segmented: bool) -> str:
    """Why a robot's whole-run window is the recording."""
    if robot.signals.window is MetricSpan.RECORDING:
        return "the recording (the spec's window whole recording)"
    if not goals:
        return "the recording (no recorded goals" + (
            "; arrivals cut path segments only)" if segmented else ")"
        )
    return "the recording (no path segments)"


def _spelt(topics: tuple[str, ...], spellings: Mapping[str, tuple[str, ...]]) -> tuple[str, ...]:
    """``topics`` as the bag spells them."""
    return tuple(dict.fromkeys(s for t in topics for s in spellings.get(t, (t,))))


def _bag_named(value: MetricValue, spellings: Mapping[str, tuple[str, ...]]) -> MetricValue:
    """``value`` with its topics named as the bag spells them (``groundtruth`` for a
    specification's ``/groundtruth``)."""
    if all(spellings.get(t, (t,)) == (t,) for t in value.topics):
        return value
    return replace(value, topics=_spelt(value.topics, spellings))


def _recording(span: tuple[float, float], data: BagData) -> tuple[float, float]:
    """The whole-run window of a robot without goals (or whose window is its whole recording):
    the recording, from its first message to its last, on the run's timeline — never the span of
    the robot's signals alone (an event-driven velocity topic, teleop's ``cmd_vel``, starts after
    the pose and ends before it, and a metric over the pose would lose its samples outside)."""
    return min(span[0], data.start), max(span[1], data.end)


def _run_clocks(timeline: Timeline, spellings: Mapping[str, tuple[str, ...]]) -> tuple[RunClock, ...]:
    """Each bag topic's clock, named as the bag spells it (once: two names may read one topic)."""
    found: dict[str, RunClock] = {}
    for c in timeline.clocks:
        for spelt in spellings.get(c.topic, (c.topic,)):
            found.setdefault(spelt, RunClock(spelt, c.clock, c.simulated, c.offset))
    return tuple(found.values())


def _incomplete(path: Path, lacking: list[str], problems: list[str]) -> tuple[str, str]:
    """Why a strict ingest refuses a run: the values it would lack, and (what its remedy,
    :data:`~exsce_dsl.remedies.STRICT_STORES_NONE`, is about) the run's problems."""
    why = "".join(f"\n  {p}" for p in dict.fromkeys(problems))
    values = counted(len(lacking), "metric value")
    return f"{path}: {values} would be missing ({'; '.join(lacking)})", (f":{why}" if why else "")


def _nothing_of(path: Path, robot: Robot, types: Mapping[str, str]) -> str:
    """Why a bag cannot be a run of a scenario with ``robot``: nothing places it."""
    listed = "; ".join(pose_like_topics(types)) or "none"
    return (
        f"{path}: robot '{robot.id}' has no navigation goals and no pose in this bag (namespace "
        f"'{robot.namespace or '/'}'); the bag's pose-like topics: {listed}. Say where its pose is "
        'in its robot type (pose on "TOPIC" or pose from tf FIXED -> BODY)'
    )


def _time(seconds: float) -> dt.datetime:
    return dt.datetime.fromtimestamp(seconds, tz=dt.timezone.utc)
