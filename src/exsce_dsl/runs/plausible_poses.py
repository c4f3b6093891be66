"""The step between a bag's signals and the monitors that refuses a pose no robot could make.

Each robot's pose signal (wherever its convention reads it: a topic or a TF chain) and every pose
topic a metric reads of the bag itself is measured by
:func:`~exsce_dsl.runs.signals.plausibility.check_poses`, against the spec's speed limit and the
robot's own velocity when the bag records one.  A series that fails is refused whole: the topics
the monitors would read of it (the pose, and what is computed from it: the distance travelled
along it, a speed estimated from it, the bag topic itself for a user metric) are withheld, so the
values reading them are missing, and the reason is in the run's problems and in each missing
value's message.  No sample is removed from a series that passes.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path

from exsce_dsl.model.conventions import (
    FLOAT64,
    ODOMETRY,
    POSE_STAMPED,
    POSE_WITH_COVARIANCE,
    TWIST,
    TWIST_STAMPED,
    TopicSource,
)
from exsce_dsl.model.messages import FieldPath, path_of
from exsce_dsl.model.metrics import MetricDefinition, expand_topic
from exsce_dsl.model.robots import Robot
from exsce_dsl.monitor_kit.monitor_core import Topic
from exsce_dsl.runs.bags.data import BagData, Series, Wanted
from exsce_dsl.runs.bags.reading import read_bag
from exsce_dsl.runs.robots import StackRobots
from exsce_dsl.runs.signals.detect import robot_namespaces, under_namespace
from exsce_dsl.runs.signals.plausibility import (
    Implausible,
    Velocity,
    check_poses,
    speed_bound,
    velocity_peak,
)
from exsce_dsl.runs.signals.sources import Chosen, RobotSources, signal_topic

POSITION_AT = {
    ODOMETRY: "pose.pose.position",
    POSE_WITH_COVARIANCE: "pose.pose.position",
    POSE_STAMPED: "pose.position",
}
"""Where a pose type's position is among a bag topic's decoded fields."""
LINEAR_AT = {TWIST: "linear", TWIST_STAMPED: "twist.linear", ODOMETRY: "twist.twist.linear"}
"""Where a velocity type's linear velocity is among a bag topic's decoded fields."""


@dataclass
class Refused:
    """The topics the monitors may not read, each with why (``no plausible pose (...)``, in the
    words of a missing value's message), the run's problems that say it, and the findings."""

    reasons: dict[str, str] = field(default_factory=dict)
    problems: list[str] = field(default_factory=list)
    findings: list[Implausible] = field(default_factory=list)

    def usable(self, topics: Mapping[str, Topic]) -> dict[str, Topic]:
        """``topics`` without the refused ones."""
        return {name: topic for name, topic in topics.items() if name not in self.reasons}


def spec_speed_limit(metrics: Iterable[MetricDefinition]) -> float | None:
    """The spec's own speed limit: the largest ``safe below`` limit of its metrics in m/s (None:
    none).  The standard library's ``max_velocity`` (safe below 1 m/s) is the method's limit for
    indoor robots, not the spec's: a drone or a car is not refused for going faster."""
    below = [m.safety for m in metrics if m.unit == "m/s" and m.safety is not None]
    return max((s.limit for s in below if s.bound == "below"), default=None)


def refuse_implausible(
    robots: Iterable[Robot],
    stacks: StackRobots,
    topics: Mapping[str, Topic],
    data: BagData,
    limit: float | None,
) -> Refused:
    """What the monitors may not read of ``topics`` (the robots' signals and the bag's series),
    each robot's pose measured against ``limit`` (:func:`spec_speed_limit`) and its velocity."""
    refused = Refused()
    bound = speed_bound(limit)
    checked: set[str] = set()
    for robot in robots:
        mine = stacks.sources.get(robot.id)
        pose_used = mine.used.get("pose") if mine is not None else None
        pose = topics.get(signal_topic("pose", robot.namespace))
        if mine is None or pose_used is None or pose is None:
            continue
        checked.update(pose_used.topics)
        axes = [pose.fields[a] for a in ("x", "y", "z")[: 3 if robot.three_d else 2]]
        found = check_poses(
            _named(pose_used), pose.t, axes, bound, _own_velocity(mine, topics, robot.three_d)
        )
        if found is None:
            continue
        refused.findings.append(found)
        said = found.describe()
        refused.problems.append(f"robot '{robot.id}': its pose makes no distance or speed: {said}")
        names = _refused_names(robot, mine)
        refused.reasons.update(dict.fromkeys(names, f"no plausible pose ({said})"))
    for name, series in data.series.items():
        if name in checked:
            continue
        found = check_series(series, bound)
        if found is not None:
            refused.findings.append(found)
            refused.problems.append(f"topic {name} makes no distance or speed: {found.describe()}")
            refused.reasons[name] = f"no plausible pose on {name} ({found.describe()})"
    return refused


def check_series(series: Series, bound: float, velocity: Velocity | None = None) -> Implausible | None:
    """The finding of a bag topic of a pose type whose position was decoded (None: it passes,
    or it is no pose)."""
    at = POSITION_AT.get(series.msgtype)
    keys = [f"{at}.{a}" for a in ("x", "y")]
    if at is None or not all(k in series.fields for k in keys):
        return None
    return check_poses(series.topic, series.t, [series.fields[k] for k in keys], bound, velocity)


def series_velocity(series: Series) -> Velocity | None:
    """The largest speed a bag topic of a velocity type reports (None: not one, or not decoded)."""
    at = LINEAR_AT.get(series.msgtype)
    keys = [f"{at}.{a}" for a in ("x", "y")]
    if at is None or not all(k in series.fields for k in keys):
        return None
    return velocity_peak(series.topic, [series.fields[k] for k in keys])


def _named(chosen: Chosen) -> str:
    """A pose source as a finding names it: its topic, or ``TF map -> base_link on /tf``."""
    if chosen.tf is None:
        return chosen.topic
    return f"TF {chosen.tf.fixed} -> {chosen.tf.body} on {chosen.topics[0]}"


def _own_velocity(mine: RobotSources, topics: Mapping[str, Topic], three_d: bool) -> Velocity | None:
    """The robot's velocity when the bag records one (not estimated from its pose)."""
    used = mine.used.get("velocity")
    velocity = topics.get(signal_topic("velocity", mine.namespace))
    if used is None or used.from_pose or velocity is None:
        return None
    axes = [velocity.fields[f"linear.{a}"] for a in ("x", "y", "z")[: 3 if three_d else 2]]
    return velocity_peak(", ".join(used.topics), axes)


def _refused_names(robot: Robot, mine: RobotSources) -> list[str]:
    """The topics the monitors read of a robot's implausible pose: the pose, its velocity and
    distance where they come from it, under the robot's own names, and the bag topic itself (a
    user metric may read it)."""
    pose = mine.used["pose"]
    refused = ["pose"]
    for signal in ("velocity", "distance"):
        used = mine.used.get(signal)
        along = signal == "distance" and used is not None and used.msgtype != FLOAT64
        if used is not None and (used.from_pose or (along and used.topics == pose.topics)):
            refused.append(signal)
    names = [signal_topic(s, robot.namespace) for s in refused]
    return names + ([pose.topic] if pose.tf is None else [])


def bag_findings(path: Path, types: Mapping[str, str]) -> tuple[str, ...]:
    """What :func:`check_series` finds of every pose topic of the bag at ``path`` (``types``: its
    topic → type), without a spec: against the default bound, and the velocity that ingestion
    would detect for the robot of the pose's namespace (``exscec bag info``)."""
    poses = sorted(t for t, m in types.items() if m in POSITION_AT)
    if not poses:
        return ()
    velocities = _namespace_velocities(types)
    paths: dict[str, list[FieldPath]] = {}
    for topic in poses:
        paths.setdefault(topic, []).extend(_paths(POSITION_AT[types[topic]]))
    for topic in dict.fromkeys(velocities.values()):
        paths.setdefault(topic, []).extend(_paths(LINEAR_AT[types[topic]]))
    data = read_bag(path, {t: Wanted(types[t], tuple(dict.fromkeys(p))) for t, p in paths.items()})
    said = []
    for topic in poses:
        series = data.series.get(topic)
        namespace = max((ns for ns in velocities if under_namespace(topic, ns)), key=len, default=None)
        own = data.series.get(velocities[namespace]) if namespace is not None else None
        found = (
            check_series(series, speed_bound(None), series_velocity(own) if own else None) if series else None
        )
        if found is not None:
            said.append(found.describe())
    return tuple(said)


def _paths(at: str) -> list[FieldPath]:
    return [path_of(*at.split("."), axis) for axis in ("x", "y")]


def _namespace_velocities(types: Mapping[str, str]) -> dict[str, str]:
    """Each robot namespace of the bag → the topic its velocity would be read from."""
    found: dict[str, str] = {}
    for namespace, signals, _ in robot_namespaces(types):
        for source in signals.velocity:
            topic = expand_topic(source.topic, namespace) if isinstance(source, TopicSource) else ""
            if types.get(topic) in LINEAR_AT:
                found[namespace] = topic
                break
    return found
