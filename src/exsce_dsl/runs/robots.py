"""Runs of robots whose type declares where its signals are (Nav2, move_base, or its own topics).

The standard library's metrics are declared over the method's topics
(:data:`~exsce_dsl.model.conventions.METHOD_TOPICS`) and its dispatcher's windows.  For a robot whose
type says otherwise, ingestion reads the signals from the sources chosen in the
bag (:mod:`~exsce_dsl.runs.signals.sources`) and serves them to the monitors under
those names, with the fields the method's types have there; the metrics' sources
in the run's PROV then name the topics the values really came from.  Its path
segments come from the first source that gives any: the method's dispatcher, the
navigation stack's goals matched to the planned waypoints by pose, arrival at
the planned waypoints; else the robot has whole-run metrics only, and a problem
says why.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace

import numpy as np

from exsce_dsl.model.conventions import (
    DISPATCHER_FEEDBACK,
    DISPATCHER_RESULT,
    METHOD_TOPICS,
    Navigation,
    TfSource,
    TopicSource,
)
from exsce_dsl.model.messages import FieldPath
from exsce_dsl.model.metrics import GOALS_READ_AS, expand_topic
from exsce_dsl.model.robots import Robot
from exsce_dsl.model.runs import MetricValue
from exsce_dsl.monitor_kit.monitor_core import Topic
from exsce_dsl.runs.bags.data import BagData, Wanted
from exsce_dsl.runs.segments.track import Track
from exsce_dsl.runs.signals.navigation_goals import goal_wanted
from exsce_dsl.runs.signals.sources import (
    RobotSources,
    choose_sources,
    signal_topic,
    signal_topics,
    signals_wanted,
)

FEEDBACK, RESULT = DISPATCHER_FEEDBACK, DISPATCHER_RESULT
SERVED = {signal: METHOD_TOPICS[signal] for signal in ("pose", "velocity", "scan", "distance")}
"""The method's topic each signal is served under, for the standard library's metrics."""


@dataclass
class StackRobots:
    """What ingestion reads of robots' signals, and where it came from: of the robots that declare
    where their signals are (``serves``: served under the method's names, segmented by their
    stack's goals) and of every robot when a metric reads a signal (``/{ns}/~pose``...)."""

    sources: dict[str, RobotSources] = field(default_factory=dict)
    serves: set[str] = field(default_factory=set)
    real_topics: dict[str, tuple[str, ...]] = field(default_factory=dict)
    """A served topic name → the bag's topics its values came from."""
    real_chains: dict[str, str] = field(default_factory=dict)
    """A served topic name composed from TF → the transforms composed (``map → odom → base_link``)."""
    estimated: dict[str, str] = field(default_factory=dict)
    """A served topic name → what it was estimated from (``pose``), where the bag lacked it."""

    def adapt(self, wanted: Mapping[str, Wanted], robots: list[Robot]) -> dict[str, Wanted]:
        """``wanted`` with the served topics of these robots replaced by their sources, and
        their navigation goals' topics added (as message objects)."""
        adapted = dict(wanted)
        scan_paths: list[FieldPath] = []
        popped: dict[str, Wanted] = {}
        for robot in robots:
            scan = adapted.pop(signal_topic("scan", robot.namespace), None)
            if scan is not None:  # a metric's scan signal: what it reads of the chosen scan
                scan_paths += scan.paths
            if robot.id not in self.serves:
                continue
            for signal, pattern in SERVED.items():
                name = expand_topic(pattern, robot.namespace)
                served = adapted.pop(name, None)
                if served is not None:
                    popped[name] = served
                if served is not None and signal == "scan":
                    scan_paths += served.paths
            signals = robot.signals
            if signals.navigation is not Navigation.DISPATCHER:
                for pattern in (FEEDBACK, RESULT):
                    adapted.pop(expand_topic(pattern, robot.namespace), None)
            adapted.update(goal_wanted(signals, robot.namespace))
        for topic, more in signals_wanted(self.sources.values(), scan_paths).items():
            # a source that is a served topic itself (the method's robot_pose) keeps what the
            # metrics read of it beyond the signal (a user metric's pose.pose.covariance)
            before = adapted.get(topic) or popped.get(topic)
            if before is not None and before.msgtype == more.msgtype:
                more = Wanted(
                    more.msgtype,
                    tuple(dict.fromkeys([*before.paths, *more.paths])),
                    tuple(dict.fromkeys([*before.texts, *more.texts])),
                    more.rows,
                )
            adapted[topic] = more
        return adapted

    def read_from(self, name: str) -> str | None:
        """The bag topic a served or signal topic (the method's scan, ``/{ns}/~scan``) is read from,
        when it is one topic (not a TF chain) of another name; None otherwise."""
        for robot in self.sources.values():
            for signal, chosen in robot.chosen.items():
                names = {signal_topic(signal, robot.namespace)}
                if robot.robot in self.serves and signal in SERVED:
                    names.add(expand_topic(SERVED[signal], robot.namespace))
                if name in names and chosen.tf is None and chosen.topic and chosen.topic != name:
                    return chosen.topic
        return None

    def served_topics(self, data: BagData, problems: list[str]) -> dict[str, Topic]:
        """The robots' signals under their own names (``/{ns}/~pose``), and under the method's
        topic names with the method's fields for the robots that declare where they are."""
        found: dict[str, Topic] = {}
        for robot in self.sources.values():
            signals = signal_topics(robot, data, problems)
            for name, series in signals.items():
                found[name] = series
                used = robot.used[name.rsplit("~", 1)[1]]
                self.real_topics[name] = used.topics
                if used.tf_chain is not None:
                    self.real_chains[name] = used.tf_chain
                if used.from_pose:
                    self.estimated[name] = "pose"
            if robot.robot not in self.serves:
                continue
            for signal, pattern in SERVED.items():
                topic = signals.get(signal_topic(signal, robot.namespace))
                if topic is None:
                    continue
                name = expand_topic(pattern, robot.namespace)
                found[name] = _as_method_fields(name, signal, topic, robot.three_d)
                self.real_topics[name] = robot.used[signal].topics
                chain = robot.used[signal].tf_chain
                if chain is not None:
                    self.real_chains[name] = chain
                if robot.used[signal].from_pose:
                    self.estimated[name] = "pose"
        return found

    def name_goals(
        self, namespace: str, windows: tuple[str, ...], outcomes: tuple[str, ...], dispatcher: bool
    ) -> None:
        """Say which bag topics the robot's goals signal came from: ``windows`` when its goals were
        active, ``outcomes`` how they ended (where not ``windows``); without goals, its pose's.
        A robot not segmented by the dispatcher has its goals served under the dispatcher's names
        too (a user metric's ``elapsed`` over the dispatcher's feedback)."""
        windows = windows or self.real_topics.get(signal_topic("pose", namespace), ())
        goals, results = (expand_topic(p, namespace) for p in GOALS_READ_AS.values())
        self.real_topics[goals], self.real_topics[results] = windows, outcomes or windows
        if not dispatcher:
            self.real_topics[expand_topic(FEEDBACK, namespace)] = windows
            self.real_topics[expand_topic(RESULT, namespace)] = windows

    def with_real_sources(self, value: MetricValue) -> MetricValue:
        """``value`` with the topics it came from named as the bag has them, and what it was
        estimated from where the bag lacked its signal."""
        if not any(t in self.real_topics for t in value.topics):
            return value
        named = [real for t in value.topics for real in self.real_topics.get(t, (t,))]
        estimated = next((self.estimated[t] for t in value.topics if t in self.estimated), None)
        return replace(value, topics=tuple(dict.fromkeys(named)), estimated_from=estimated)

    def named(self, robots: list[Robot]) -> dict[str, str]:
        """How the run's problems name what the monitors read of these robots: a signal by the
        bag's topics it was read from, else ``no velocity (looked for /cmd_vel, /odom)``; the
        dispatcher's topics, of a robot segmented otherwise, by what it was segmented from."""
        found: dict[str, str] = {}
        for robot in robots:
            mine = self.sources.get(robot.id)
            if mine is None:
                continue
            ns, signals = robot.namespace, robot.signals
            for signal, sources in (
                ("pose", signals.pose),
                ("velocity", signals.velocity),
                ("scan", signals.scan),
                ("distance", signals.distance),
            ):
                served = expand_topic(SERVED[signal], ns)
                chosen = mine.used.get(signal) or mine.chosen.get(signal)
                looked = [_looked_for(s, ns) for s in sources]
                if chosen is not None:
                    said = ", ".join(chosen.topics)
                elif looked == [served]:
                    said = served  # the method's own topic: its name says what was looked for
                elif looked:
                    said = f"no {signal} (looked for {', '.join(looked)})"
                else:
                    said = f"no {signal} (none detected in the bag)"
                names = [signal_topic(signal, ns)] + ([served] if robot.id in self.serves else [])
                found.update(dict.fromkeys(names, said))
            goals = [expand_topic(p, ns) for p in GOALS_READ_AS.values()]
            if signals.navigation is Navigation.DISPATCHER:  # its feedback, its result
                found.update(zip(goals, (expand_topic(FEEDBACK, ns), expand_topic(RESULT, ns)), strict=True))
                continue
            actions = ", ".join(expand_topic(a, ns) for a in signals.actions)
            said = (
                f"no navigation goals (looked for {actions})"
                if actions
                else "no path segments (no navigation goals, and no arrival at its planned waypoints)"
            )
            found.update(dict.fromkeys((*goals, expand_topic(FEEDBACK, ns), expand_topic(RESULT, ns)), said))
        return found

    def recorded_span(self, robot: Robot, topics: Mapping[str, Topic]) -> tuple[float, float] | None:
        """From the first to the last message of the robot's signals (None: it has none)."""
        found = [
            topics.get(signal_topic(s, robot.namespace)) for s in ("pose", "velocity", "scan", "distance")
        ]
        times = [t.t for t in found if t is not None and len(t)]
        if not times:
            return None
        return min(float(t[0]) for t in times), max(float(t[-1]) for t in times)

    def track(self, robot: Robot, topics: Mapping[str, Topic]) -> Track:
        """The robot's pose signal, for segmentation (empty if the bag has none)."""
        pose = topics.get(signal_topic("pose", robot.namespace))
        if pose is None or not len(pose):
            return Track.empty()
        fields = pose.fields
        return Track(pose.t, fields["x"], fields["y"], fields["yaw"], fields.get("z"), robot.three_d)


def stack_robots(robots: list[Robot], available: Mapping[str, str], serves: set[str]) -> StackRobots:
    """``robots``' signals, from the sources the bag (``available``) has; ``serves``: the robots
    whose signals are served under the method's topic names."""
    return StackRobots({r.id: choose_sources(r, available) for r in robots}, serves)


def _looked_for(source: TopicSource | TfSource, ns: str) -> str:
    if isinstance(source, TfSource):
        return f"TF {source.fixed} -> {source.body} on {expand_topic(source.tf, ns)}"
    return expand_topic(source.topic, ns)


def _as_method_fields(name: str, signal: str, topic: Topic, three_d: bool) -> Topic:
    """A signal with the fields of the method's type for it; a planar robot's velocity without
    its vertical part (the method's max_velocity is the norm of the linear velocity)."""
    if signal == "velocity" and not three_d:
        return Topic(name, topic.t, {**topic.fields, "linear.z": np.zeros(len(topic.t))})
    if signal != "pose":
        return Topic(name, topic.t, dict(topic.fields))
    yaw = topic.fields["yaw"]
    fields = {f"pose.pose.position.{a}": topic.fields[a] for a in ("x", "y", "z")}
    fields["pose.pose.orientation.x"] = fields["pose.pose.orientation.y"] = np.zeros_like(yaw)
    fields["pose.pose.orientation.z"], fields["pose.pose.orientation.w"] = np.sin(yaw / 2), np.cos(yaw / 2)
    return Topic(name, topic.t, fields)
