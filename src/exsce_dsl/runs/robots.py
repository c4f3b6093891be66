"""A run's robots and their signals: where each robot's signals are read from in its bag.

Every robot's signals (pose, velocity, scan, distance) are read from the sources its
convention, or its type's own lines, name and the bag has
(:mod:`~exsce_dsl.runs.signals.sources`), each under its own name (``/{ns}/~pose``), which is
what the metrics read (``reads pose: robot pose``); a metric that reads a topic by name reads
that topic of the bag, nothing served under its name.  The metrics' sources in the run's PROV
name the bag's topics the values came from; its goals signal names the topics its path segments
came from (the dispatcher's feedback and result, Nav2's or move_base's actions, else its pose).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace

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


@dataclass
class StackRobots:
    """What ingestion reads of robots' signals (``/{ns}/~pose``...), and where it came from."""

    sources: dict[str, RobotSources] = field(default_factory=dict)
    real_topics: dict[str, tuple[str, ...]] = field(default_factory=dict)
    """A signal's name (``/{ns}/~pose``) → the bag's topics its values came from."""
    real_chains: dict[str, str] = field(default_factory=dict)
    """A signal composed from TF → the transforms composed (``map → odom → base_link``)."""
    estimated: dict[str, str] = field(default_factory=dict)
    """A signal → what it was estimated from (``pose``), where the bag lacked it."""

    def adapt(self, wanted: Mapping[str, Wanted], robots: list[Robot]) -> dict[str, Wanted]:
        """``wanted`` with the robots' signals replaced by their sources, and their navigation
        goals' topics added (as message objects).  A topic a metric reads by name is the bag's."""
        adapted = dict(wanted)
        scan_paths: list[FieldPath] = []
        for robot in robots:
            scan = adapted.pop(signal_topic("scan", robot.namespace), None)
            if scan is not None:  # a metric's scan signal: what it reads of the chosen scan
                scan_paths += scan.paths
            adapted.update(goal_wanted(robot.signals, robot.namespace))
        for topic, more in signals_wanted(self.sources.values(), scan_paths).items():
            # a source a metric also reads by name (the method's robot_pose) keeps what the
            # metric reads of it beyond the signal (a user metric's pose.pose.covariance)
            before = adapted.get(topic)
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
        """The bag topic a signal (``/{ns}/~scan``) is read from, when it is one topic (not a TF
        chain); None otherwise."""
        for robot in self.sources.values():
            for signal, chosen in robot.chosen.items():
                if name == signal_topic(signal, robot.namespace) and chosen.tf is None and chosen.topic:
                    return chosen.topic
        return None

    def signal_series(self, data: BagData, problems: list[str]) -> dict[str, Topic]:
        """The robots' signals, each under its own name (``/{ns}/~pose``)."""
        found: dict[str, Topic] = {}
        for robot in self.sources.values():
            for name, series in signal_topics(robot, data, problems).items():
                found[name] = series
                used = robot.used[name.rsplit("~", 1)[1]]
                self.real_topics[name] = used.topics
                if used.tf_chain is not None:
                    self.real_chains[name] = used.tf_chain
                if used.from_pose:
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
                own = expand_topic(METHOD_TOPICS[signal], ns)
                chosen = mine.used.get(signal) or mine.chosen.get(signal)
                looked = [_looked_for(s, ns) for s in sources]
                if chosen is not None:
                    said = ", ".join(chosen.topics)
                elif looked == [own]:
                    said = own  # the method's own topic: its name says what was looked for
                elif looked:
                    said = f"no {signal} (looked for {', '.join(looked)})"
                else:
                    said = f"no {signal} (none detected in the bag)"
                found[signal_topic(signal, ns)] = said
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


def stack_robots(robots: list[Robot], available: Mapping[str, str]) -> StackRobots:
    """``robots``' signals, from the sources the bag (``available``) has."""
    return StackRobots({r.id: choose_sources(r, available) for r in robots})


def _looked_for(source: TopicSource | TfSource, ns: str) -> str:
    if isinstance(source, TfSource):
        return f"TF {source.fixed} -> {source.body} on {expand_topic(source.tf, ns)}"
    return expand_topic(source.topic, ns)
