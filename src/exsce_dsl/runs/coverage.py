"""What a run's recording does not cover, found once its segments and metric values are known.

A verdict is only worth what the recording behind it shows, so ingestion checks each run and
keeps what it found with it (:class:`~exsce_dsl.model.coverage.CoverageGap`), and how densely
each topic a metric reads was recorded (:class:`~exsce_dsl.model.coverage.TopicRate`):

- **cut short**: a robot's goal still ACTIVE when the recording ends, or planned waypoints it
  never finished while none of its goals failed (nothing but the end of the recording stopped
  it); or the mission was cancelled or stopped (the run-time PROV says so).  Every metric of the
  robot (of the run) is concerned: ``metrics`` is empty.
- **no data**: a signal a metric reads starts later, or ends earlier, than the robot's window
  (its first goal's start to its last goal's end; its recorded signals' span when it has no
  goals or its type says ``window whole recording``) by more than the topic's gap threshold.
- **gap**: two consecutive messages of such a topic further apart than its gap threshold
  (:func:`gap_threshold`), unless the topic is event-driven (:func:`event_driven`: bursts with
  pauses, which are said once and are no gaps).
- **low rate**: a topic recorded at less than :data:`LOW_RATE_FRACTION` of the rate its robot
  type declares (``scan at 10 Hz``) over its span.
- **clock jump**: ``/clock`` or a source's stamps going back (a simulation reset): from there to
  the end of the run nothing is on one timeline; every metric is concerned.

Only topics that some metric value was computed from are checked (the values name them, as the
bag spells them), so an unread topic never makes a run incomplete.  Times are on the run's
timeline while checking and dates of the recorder's wall clock in what is kept.
"""

from __future__ import annotations

import datetime as dt
import json
from collections import Counter
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from exsce_dsl.model import Scenario
from exsce_dsl.model.coverage import CoverageGap, Shortfall, TopicRate
from exsce_dsl.model.robots import Robot
from exsce_dsl.model.runs import MetricValue, RunStatus
from exsce_dsl.monitor_kit.monitor_core import expand_topic
from exsce_dsl.runs.bags.data import BagData
from exsce_dsl.runs.segments.recorded import RecordedAction
from exsce_dsl.runs.signals.sources import SIGNALS, RobotSources
from exsce_dsl.runs.signals.timeline import CLOCK_TOPIC, Timeline
from exsce_dsl.wording import counted

PROV_TOPIC = "/exsce/prov"
"""Where the mission dispatcher publishes the run-time PROV (std_msgs/String, latched), so that
the bag carries the mission's status too (``exscec execute`` records it)."""

GAP_FLOOR = 0.5
"""Seconds: no gap threshold is shorter (see :func:`gap_threshold`)."""
GAP_PERIODS = 10.0
"""A gap is longer than this many of the topic's median periods (see :func:`gap_threshold`)."""
GAP_TICKS = 3.0
"""For a topic whose times come in bursts at its clock's ticks: a gap is longer than this many
ticks (the 95th percentile of the steps between its distinct times; see :func:`gap_threshold`)."""
_SAME_TIME = 1e-6
"""Seconds: two messages closer than this were logged at one clock tick."""
LOW_RATE_FRACTION = 0.5
"""A topic recorded below this fraction of its declared rate is recorded at a low rate."""
EVENT_PAUSES = 3
"""A topic with at least this many silences longer than its gap threshold, holding together at
least :data:`EVENT_SHARE` of its span, comes in bursts: it is event-driven (teleop's ``cmd_vel``,
sent while a key is held), and its pauses are not gaps (see :func:`event_driven`)."""
EVENT_SHARE = 0.2
MIN_MESSAGES = 3
"""Fewer messages than this give no period to measure gaps and rates by: such a topic (a latched
``tf_static``, a map) is not checked."""

FINISHED = ("SUCCEEDED",)
UNFINISHED = ("NOT_STARTED", "NOT_REACHED")


def gap_threshold(times: np.ndarray) -> float:
    """The longest silence of a topic that is not a gap: ``max(GAP_FLOOR, GAP_PERIODS × median
    period)``.

    The median period is the topic's own rate, robust to the gaps themselves and to a few late
    messages.  Ten periods: a periodic publisher on a loaded machine, or a recorder flushing its
    queue, delays a message by one or a few periods, never by ten in a row; ten lost in a row is
    data that is not there.  The half-second floor keeps a fast topic (100 Hz TF, 50 Hz odometry)
    from reporting a recorder's stall of tens of milliseconds, while staying shorter than what a
    safety metric must see (a robot at 1 m/s moves 0.5 m in it).  A thinned topic (every k-th
    message kept) has a k times longer median period, so it is not a series of gaps: that is
    :data:`LOW_RATE_FRACTION`'s to find, against a declared rate.

    Times can be coarser than the topic's rate: a recorder on simulated time stamps what it logs
    with the last ``/clock`` it heard, so a simulator that publishes its clock a few times a
    second (Stage at 10 Hz, exsce's stand-in at 2 Hz of simulated time) gives bursts of messages
    at one time and silences of one clock tick between them.  Such a topic's period is its mean
    (span over messages), and no silence shorter than :data:`GAP_TICKS` of its clock's ticks is a
    gap: the data is there, its times are not finer than the clock's."""
    if len(times) < 2:
        return GAP_FLOOR
    steps = np.diff(times)
    period = float(np.median(steps))
    ticks = steps[steps > _SAME_TIME]
    if period <= _SAME_TIME and len(ticks):  # bursts at the clock's ticks: most steps are none
        mean = float(times[-1] - times[0]) / (len(times) - 1)
        return max(GAP_FLOOR, GAP_PERIODS * mean, GAP_TICKS * float(np.percentile(ticks, 95)))
    return max(GAP_FLOOR, GAP_PERIODS * period)


def event_driven(topic: str, times: np.ndarray, threshold: float) -> str:
    """Why ``topic`` is event-driven (empty: it is periodic, and a silence is a gap).

    A periodic publisher's steps are its period, and a silence longer than the gap threshold is
    data lost: one or two such, short beside the recording.  A topic published only when
    something happens (a velocity command while a key is held, a goal, a button) is many bursts
    at a period with pauses of any length between them: :data:`EVENT_PAUSES` or more pauses
    holding :data:`EVENT_SHARE` of its span or more.  Said once, so that a periodic topic with
    repeated long drop-outs, taken for one, is still seen."""
    steps = np.diff(times)
    pauses = steps[steps > threshold]
    span = float(times[-1] - times[0]) if len(times) > 1 else 0.0
    if len(pauses) < EVENT_PAUSES or span <= 0 or float(pauses.sum()) < EVENT_SHARE * span:
        return ""
    return (
        f"{topic} is event-driven ({counted(len(pauses) + 1, 'burst')} with pauses of "
        f"{float(pauses.min()):.3f} to {float(pauses.max()):.3f} s, {float(pauses.sum()) / span:.0%} "
        "of its span): its pauses are not gaps"
    )


@dataclass(frozen=True)
class ReadTopic:
    """One topic of the bag that metric values were computed from, on the run's timeline."""

    topic: str
    """As the bag spells it."""
    robot: str | None
    """The one robot whose values read it (None: several, or only mission values)."""
    metrics: tuple[str, ...]
    times: np.ndarray


@dataclass(frozen=True)
class Recording:
    """What the checks look at: the run's bag data (on its timeline), segments and values."""

    scenario: Scenario
    robots: list[Robot]
    data: BagData
    timeline: Timeline
    segments: list[RecordedAction]
    values: list[MetricValue]
    status: RunStatus
    whole_runs: Mapping[str, tuple[float, float]]
    """Robot → its whole-run window where that is not its goals' span: the recording (no goals,
    segments from arrivals, which cut segments, never the run, or ``window whole recording``)."""
    declared: Mapping[str, float]
    """Bag topic (as spelt) → the rate its robot type declares (Hz)."""


@dataclass(frozen=True)
class Coverage:
    gaps: tuple[CoverageGap, ...]
    rates: tuple[TopicRate, ...]
    notes: tuple[str, ...] = ()
    """What was found and is no gap (an event-driven topic), said once."""

    def said(self) -> list[str]:
        """The gaps as warnings of the run, one per kind: the worst (the longest) with how many
        there are and where (``coverage: gap: /scan has no message for 2.100 s (...); the
        longest of 12 of this kind in this run: /scan 9, /odom 3``); then the notes."""
        kinds: dict[Shortfall, list[CoverageGap]] = {}
        for gap in self.gaps:
            kinds.setdefault(gap.kind, []).append(gap)
        said = []
        for kind, found in kinds.items():
            line = f"coverage: {kind.value.replace('_', ' ')}: {max(found, key=_length).reason}"
            if len(found) > 1:
                where = Counter(g.topic or (f"robot '{g.robot}'" if g.robot else "the run") for g in found)
                listed = ", ".join(f"{w} {n}" for w, n in where.items())
                line += f"; the longest of {len(found)} of this kind in this run: {listed}"
            said.append(line)
        return said + [f"coverage: {note}" for note in self.notes]


def _length(gap: CoverageGap) -> float:
    """Seconds a gap lasts (unbounded: longer than any)."""
    if gap.start is None or gap.end is None:
        return float("inf")
    return (gap.end - gap.start).total_seconds()


def find_coverage(recording: Recording) -> Coverage:
    """Every gap of ``recording``, and the rate of each topic its metrics read."""
    wall = _wall(recording.timeline)
    topics = topics_read_by(recording.data, recording.values, recording.robots)
    gaps = _cut_short(recording, wall)
    windows = robot_windows(recording)
    notes: list[str] = []
    for read in topics:
        if len(read.times) < MIN_MESSAGES:
            continue  # a latched topic (tf_static, a map) or too few to tell
        threshold = gap_threshold(read.times)
        bursts = event_driven(read.topic, read.times, threshold)
        notes += [bursts] if bursts else []
        gaps += [] if bursts else _silences(read, threshold, wall)
        window = windows.get(read.robot) if read.robot is not None else None
        if window is not None and not bursts:  # a command starts when the robot is told to move
            gaps += _no_data(read, window, threshold, wall)
        declared = recording.declared.get(read.topic)
        if declared is not None:
            gaps += _low_rate(read, declared, wall)
    gaps += _clock_jumps(recording, wall)
    rates = tuple(_rate(read) for read in topics)
    return Coverage(tuple(gaps), rates, tuple(notes))


def with_findings(value: MetricValue, gaps: Iterable[CoverageGap]) -> MetricValue:
    """``value`` with the findings of ``gaps`` that touch it in its accounting: about its metric
    and robot, on one of its topics or sources (or on none), and overlapping its window (on the
    wall clock: :func:`~exsce_dsl.runs.metrics.accounting.on_wall_clock`)."""
    found = value.accounting
    if found is None:
        return value
    topics = set(value.topics) | {t for c in found.sources for t in c.topics}
    metric = value.safety_metric or value.metric
    touching = [
        g.reason
        for g in gaps
        if g.concerns(metric, value.robot)
        and (g.topic is None or g.topic in topics)
        and _overlaps(g, found.start, found.end)
    ]
    return replace(value, accounting=replace(found, annotations=tuple(dict.fromkeys(touching))))


def _overlaps(gap: CoverageGap, start: float, end: float) -> bool:
    """Whether ``gap`` (open where its start or end is None) meets ``[start, end]`` (wall clock)."""
    first = gap.start.timestamp() if gap.start is not None else -np.inf
    last = gap.end.timestamp() if gap.end is not None else np.inf
    return bool(first <= end and last >= start)


def topics_read_by(
    data: BagData, values: Iterable[MetricValue], robots: Iterable[Robot] = ()
) -> list[ReadTopic]:
    """The series of ``data`` that ``values`` were computed from, with the robot and the metrics
    that read each (the values name topics as the bag spells them).  A topic only mission values
    read is its robot's when it is in the robot's namespace (``/tiago1/odom``)."""
    spaces = {f"/{r.namespace.strip('/')}/": r.id for r in robots if r.namespace.strip("/")}
    metrics: dict[str, dict[str, None]] = {}
    owned: dict[str, set[str]] = {}
    for value in values:
        for topic in value.topics:
            metrics.setdefault(topic, {})[value.metric] = None
            if value.robot is not None:
                owned.setdefault(topic, set()).add(value.robot)
    found = []
    for key, series in sorted(data.series.items()):
        for spelt in data.spellings.get(key, (key,)):
            if spelt not in metrics:
                continue
            inside = (series.t >= data.start) & (series.t <= data.end)
            owners = owned.get(spelt) or {r for space, r in spaces.items() if spelt.startswith(space)}
            robot = next(iter(owners)) if len(owners) == 1 else None
            found.append(ReadTopic(spelt, robot, tuple(sorted(metrics[spelt])), series.t[inside]))
    return found


def robot_windows(recording: Recording) -> dict[str, tuple[float, float]]:
    """Each robot's window on the timeline, as its whole-run values have it: the recording where
    analysis said so (:attr:`Recording.whole_runs`), else its first goal's start to its last goal's
    end (the recording's end while a goal is still active)."""
    found: dict[str, tuple[float, float]] = {}
    for robot in recording.robots:
        started = [s for s in recording.segments if s.robot == robot.id and s.start is not None]
        if robot.id in recording.whole_runs:
            found[robot.id] = recording.whole_runs[robot.id]
        elif started:
            first = min(s.start for s in started if s.start is not None)
            last = max(s.end if s.end is not None else recording.data.end for s in started)
            found[robot.id] = (first, last)
    return found


def declared_rates(
    robots: Iterable[Robot], sources: Mapping[str, RobotSources], data: BagData
) -> dict[str, float]:
    """Bag topic (as spelt) → the rate its robot type declares for the signal read from it: the
    source's own (``scan on "/{ns}/base_scan" at 10 Hz``), else the signal's (``scan at 10 Hz``).  A
    pose from TF has no rate of its own (``/tf`` carries every frame)."""
    found: dict[str, float] = {}
    for robot in robots:
        mine = sources.get(robot.id)
        if mine is None:
            continue
        signals = robot.signals
        for signal in SIGNALS:
            chosen = mine.used.get(signal) or mine.chosen.get(signal)
            if chosen is None or chosen.tf is not None or chosen.from_pose:
                continue
            listed = getattr(signals, signal)
            own = next(
                (
                    s.rate
                    for s in listed
                    if getattr(s, "rate", None) is not None
                    and expand_topic(s.topic, robot.namespace) == chosen.topic
                ),
                None,
            )
            rate = own if own is not None else signals.rate_of(signal)
            if rate is not None:
                for spelt in data.spellings.get(chosen.topic, (chosen.topic,)):
                    found[spelt] = rate
    return found


def recorded_mission_status(bag: Path, published: Iterable[tuple[float, Any]] = ()) -> RunStatus:
    """How the mission of the run in ``bag`` ended, as the run-time PROV says: the messages the
    bag recorded on :data:`PROV_TOPIC` (``published``: (time, std_msgs/String)), else the file
    beside the bag (``<bag's stem>.prov.json``, which ``exscec execute`` and ``simulate`` write).
    A run whose mission was cancelled or stopped carries ``exsce:mission_status``; without
    either, or with one that does not say, the run counts as completed."""
    documents: list[object] = []
    for _, message in published:
        try:
            documents.append(json.loads(str(getattr(message, "data", ""))))
        except ValueError:
            continue
    beside = bag.with_name(bag.stem + ".prov.json") if bag.suffix else bag.with_name(bag.name + ".prov.json")
    try:
        documents.append(json.loads(beside.read_text(encoding="utf-8")))
    except (OSError, ValueError):
        pass
    said = {str(v) for document in documents for v in _values_of(document, "exsce:mission_status")}
    for status in (RunStatus.CANCELLED, RunStatus.STOPPED):
        if status.value in said:
            return status
    return RunStatus.COMPLETED


def _values_of(document: object, key: str) -> list[object]:
    """Every value of ``key`` in a PROV-JSON document, at any depth (bundles nest records)."""
    found: list[object] = []
    stack = [document]
    while stack:
        node = stack.pop()
        if isinstance(node, dict):
            for k, v in node.items():
                if k == key:
                    found.append(v.get("$") if isinstance(v, dict) else v)
                else:
                    stack.append(v)
        elif isinstance(node, list):
            stack.extend(node)
    return found


Wall = Callable[[float], dt.datetime]


def _wall(timeline: Timeline) -> Wall:
    def at(t: float) -> dt.datetime:
        seconds = float(timeline.to_wall(np.array([t], dtype=np.float64))[0])
        return dt.datetime.fromtimestamp(seconds, tz=dt.timezone.utc)

    return at


def _cut_short(recording: Recording, wall: Wall) -> list[CoverageGap]:
    """Robots whose goals the recording's end interrupted, and a cancelled or stopped mission."""
    end = recording.data.end
    gaps: list[CoverageGap] = []
    interrupted: list[float] = []
    for robot in recording.robots:
        mine = [s for s in recording.segments if s.robot == robot.id]
        active = [s for s in mine if s.status == "ACTIVE" and s.start is not None]
        if active:
            goal = active[0]
            assert goal.start is not None
            interrupted.append(goal.start)
            reason = (
                f"robot '{robot.id}': its goal to {goal.goal.id or 'a waypoint'} (task {goal.task}, "
                f"subtask {goal.subtask}, waypoint {goal.waypoint}) was still active when the recording ended"
            )
            gaps.append(
                CoverageGap(Shortfall.CUT_SHORT, reason, robot.id, None, (), wall(goal.start), wall(end))
            )
            continue
        left = _never_finished(mine)
        if left:
            done = [s.end for s in mine if s.end is not None]
            since = max(done) if done else end
            interrupted.append(since)
            reason = (
                f"robot '{robot.id}': {counted(len(left), 'planned waypoint')} never "
                f"finished (the next: {left[0].goal.id or 'a waypoint'} of task {left[0].task}) when the "
                "recording ended, and none of its goals failed"
            )
            gaps.append(CoverageGap(Shortfall.CUT_SHORT, reason, robot.id, None, (), wall(since), wall(end)))
    if recording.status is not RunStatus.COMPLETED:
        since = min(interrupted) if interrupted else end
        reason = f"the mission was {recording.status.value} (the run-time PROV says so)"
        gaps.append(CoverageGap(Shortfall.CUT_SHORT, reason, None, None, (), wall(since), wall(end)))
    return gaps


def _never_finished(segments: list[RecordedAction]) -> list[RecordedAction]:
    """A robot's planned waypoints after its last finished one, when it started some and none
    failed (a failed goal, not the recording, explains the rest)."""
    if not any(s.start is not None for s in segments):
        return []
    if any(s.status not in (*FINISHED, *UNFINISHED) for s in segments):
        return []
    return [s for s in segments if s.status in UNFINISHED]


def _silences(read: ReadTopic, threshold: float, wall: Wall) -> list[CoverageGap]:
    gaps = []
    steps = np.diff(read.times)
    for i in np.flatnonzero(steps > threshold):
        a, b = float(read.times[i]), float(read.times[i + 1])
        reason = (
            f"{read.topic} has no message for {b - a:.3f} s (longer than {threshold:.3f} s, "
            f"{GAP_PERIODS:g} of its median periods or {GAP_FLOOR:g} s)"
        )
        gaps.append(
            CoverageGap(Shortfall.GAP, reason, read.robot, read.topic, read.metrics, wall(a), wall(b))
        )
    return gaps


def _no_data(read: ReadTopic, window: tuple[float, float], threshold: float, wall: Wall) -> list[CoverageGap]:
    start, end = window
    first, last = float(read.times[0]), float(read.times[-1])
    gaps = []
    if first - start > threshold:
        reason = f"{read.topic} starts {first - start:.3f} s after robot '{read.robot}''s window"
        gaps.append(
            CoverageGap(
                Shortfall.NO_DATA, reason, read.robot, read.topic, read.metrics, wall(start), wall(first)
            )
        )
    if end - last > threshold:
        reason = f"{read.topic} ends {end - last:.3f} s before robot '{read.robot}''s window"
        gaps.append(
            CoverageGap(
                Shortfall.NO_DATA, reason, read.robot, read.topic, read.metrics, wall(last), wall(end)
            )
        )
    return gaps


def _low_rate(read: ReadTopic, declared: float, wall: Wall) -> list[CoverageGap]:
    if len(read.times) < MIN_MESSAGES:
        return []
    rate = _rate(read).rate
    if rate >= LOW_RATE_FRACTION * declared:
        return []
    first, last = float(read.times[0]), float(read.times[-1])
    reason = (
        f"{read.topic} was recorded at {rate:.3g} Hz, below {LOW_RATE_FRACTION:g} of the "
        f"{declared:g} Hz its robot type declares"
    )
    return [
        CoverageGap(Shortfall.LOW_RATE, reason, read.robot, read.topic, read.metrics, wall(first), wall(last))
    ]


def _clock_jumps(recording: Recording, wall: Wall) -> list[CoverageGap]:
    """A gap from each clock jump to the end of the run; the stamps of series that went back with
    ``/clock`` are the same reset, said once."""
    jumps = recording.timeline.jumps
    if any(j.topic == CLOCK_TOPIC for j in jumps):
        jumps = tuple(j for j in jumps if j.topic == CLOCK_TOPIC)
    end = recording.data.end
    return [
        CoverageGap(
            Shortfall.CLOCK_JUMP,
            f"{j.describe()}: nothing from there on is on the run's timeline",
            None,
            j.topic,
            (),
            wall(j.at),
            wall(max(end, j.at)),
        )
        for j in jumps
    ]


def _rate(read: ReadTopic) -> TopicRate:
    """Messages per second over the topic's span: (messages − 1) / (last − first), the mean
    number of periods per second (a 10 Hz topic gives 10, whatever its length)."""
    n = len(read.times)
    span = float(read.times[-1] - read.times[0]) if n > 1 else 0.0
    rate = (n - 1) / span if span > 0 else 0.0
    return TopicRate(read.topic, read.robot, n, rate, read.metrics)
