"""The metrics exsce computes from a run's bag, and what each one measures.

Acceptance criteria are checked against what a metric is (:class:`MetricInfo`): the metric
exists, a robot's metric is said of a robot and a mission's of the mission, a quantity has the
metric's dimension, and only metrics with per-segment values take a time window (a window's
value combines the values of the segments inside it).  The built-in metrics are declared in the
standard library (``lang/stdlib/metrics.exsce``), read by ``exsce_dsl.lang.builtin_metrics``.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from exsce_dsl.errors import SourceLocation
from exsce_dsl.model.conventions import METHOD_TOPICS
from exsce_dsl.model.expressions import Expression, Field
from exsce_dsl.model.messages import GOALS

if TYPE_CHECKING:
    from exsce_dsl.model.scenario import Scenario


class Dimension(enum.Enum):
    TIME = "time"
    LENGTH = "length"
    SPEED = "speed"
    ANGULAR_SPEED = "angular speed"
    ANGLE = "angle"
    COUNT = "count"
    NUMBER = "number"
    """A plain number (a ratio, a unit the language does not know)."""


class Combine(enum.Enum):
    """How a metric's values over consecutive segments make the value over all of them."""

    SUM = "sum"
    MAX = "max"
    MIN = "min"


SIGNAL_TYPES = {
    "pose": "exsce_msgs/msg/RobotPose",
    "velocity": "geometry_msgs/msg/Twist",
    "distance": "std_msgs/msg/Float64",
    "scan": "sensor_msgs/msg/LaserScan",
    "goals": GOALS,
}
"""A robot's signals a metric can read, and the type whose fields each has (goals: none, they are
read as windows)."""


def signal_pattern(signal: str) -> str:
    """The topic name a robot's signal goes under among a run's topics (``~`` is in no bag's)."""
    return f"/{{ns}}/~{signal}"


GOALS_READ_AS = {"elapsed": signal_pattern("goals"), "succeeded": signal_pattern("goals") + "/outcomes"}
"""What ``elapsed`` and ``succeeded`` read of a robot's goals signal, as a run's values name it: when
its goals were active, and how they ended; a stack may record the two on different topics (the
method's dispatcher: its feedback and its result)."""


def expand_topic(pattern: str, namespace: str) -> str:
    """``pattern`` with ``{ns}`` replaced by a robot's namespace; a robot at the root (no
    namespace) leaves no empty level: ``/{ns}/odom`` is then ``/odom``.  (``runs.monitor_core``
    has its own copy: it runs standalone in generated ROS nodes.)"""
    name = pattern.replace("{ns}", namespace.strip("/"))
    while "//" in name:
        name = name.replace("//", "/")
    return name


@dataclass(frozen=True)
class MetricInfo:
    name: str
    dimension: Dimension
    per_robot: bool
    """Said of a robot (``each robot``, ``tiago1``); otherwise of the mission."""
    combine: Combine | None = None
    """For a metric with a value per path segment: how segments combine (else None)."""
    also_mission: bool = False
    """Also has a value for the whole mission (violation_duration)."""
    meaning: str = ""

    @property
    def per_segment(self) -> bool:
        return self.combine is not None


VIOLATION_DURATION = MetricInfo(
    "violation_duration",
    Dimension.TIME,
    True,
    also_mission=True,
    meaning="seconds a safety limit was violated",
)
"""The one built-in metric the language does not declare: it follows from each metric that is
``safe below|above`` a limit.  The others are declared once, in the standard library
(``lang/stdlib/metrics.exsce``); ``exsce_dsl.lang.builtin_metrics`` gives them all."""

UNITS: dict[str, tuple[Dimension, float]] = {
    "s": (Dimension.TIME, 1.0),
    "ms": (Dimension.TIME, 0.001),
    "min": (Dimension.TIME, 60.0),
    "h": (Dimension.TIME, 3600.0),
    "m": (Dimension.LENGTH, 1.0),
    "cm": (Dimension.LENGTH, 0.01),
    "mm": (Dimension.LENGTH, 0.001),
    "km": (Dimension.LENGTH, 1000.0),
    "m/s": (Dimension.SPEED, 1.0),
    "cm/s": (Dimension.SPEED, 0.01),
    "km/h": (Dimension.SPEED, 1000.0 / 3600.0),
    "rad/s": (Dimension.ANGULAR_SPEED, 1.0),
    "deg/s": (Dimension.ANGULAR_SPEED, 0.017453292519943295),
    "rad": (Dimension.ANGLE, 1.0),
    "deg": (Dimension.ANGLE, 0.017453292519943295),
}
"""Units a quantity may carry, by dimension, with the factor to SI."""

SI_UNIT = {
    Dimension.TIME: "s",
    Dimension.LENGTH: "m",
    Dimension.SPEED: "m/s",
    Dimension.ANGULAR_SPEED: "rad/s",
    Dimension.ANGLE: "rad",
    Dimension.COUNT: "",
    Dimension.NUMBER: "",
}

_FEEDBACK, _RESULT, _POSE, _VEL, _SCAN, _DISTANCE = (
    METHOD_TOPICS[name].removeprefix("/{ns}/")
    for name in ("feedback", "result", "pose", "velocity", "scan", "distance")
)
TOPICS: dict[str, tuple[str, ...]] = {
    "mission_duration": (_FEEDBACK,),
    "task_duration": (_FEEDBACK,),
    "waypoints_visited": (_RESULT,),
    "distance_travelled": (_DISTANCE,),
    "distance_to_obstacles": (_SCAN,),
    "max_velocity": (_VEL,),
    "distance_between_robots": (_POSE,),
    "violation_duration": (_VEL, _SCAN),
}
"""The topics each metric is computed from, below a robot's namespace (DESIGN §1: the method's,
from its convention)."""


class ComputedFor(enum.Enum):
    """What a declared metric is said of."""

    ROBOT = "each robot"
    MISSION = "mission"
    PAIRS = "each pair of robots"


@dataclass(frozen=True)
class TopicRead:
    """A topic a metric reads: ``reads vel: geometry_msgs/msg/Twist on "/{ns}/cmd_vel"``."""

    name: str
    msgtype: str
    topic: str
    """The topic name; ``{ns}`` stands for the robot's namespace."""
    location: SourceLocation | None = field(default=None, compare=False, repr=False)
    fields: tuple[Field, ...] = ()
    """Every field the metric reads of the topic, where it is written: what the bag reader
    decodes, and what ``messages.field_check`` checks against the bag's definition."""
    signal: str | None = None
    """A robot's signal (``pose``, ``velocity``, ``scan``, ``distance``, ``goals``) rather than a
    topic: ``topic`` is then the name ingestion gives the signal (``/{ns}/~pose``), ``msgtype`` the
    signal's fields'."""

    def topic_of(self, namespace: str) -> str:
        return expand_topic(self.topic, namespace)


@dataclass(frozen=True)
class SafetyLimit:
    """A safety metric's limit: its values should stay ``below`` (or ``above``) it."""

    bound: str
    limit: float
    """In the metric's SI unit."""
    written: str = field(default="", compare=False, repr=False)
    """The limit as the author wrote it (``50 cm/s``), for the formatter."""


@dataclass(frozen=True)
class MetricDefinition:
    """A metric as declared in the language (the standard library's or a user's)."""

    name: str
    subject: ComputedFor
    per_segment: bool
    dimension: Dimension
    reads: tuple[TopicRead, ...]
    value: Expression
    fallback: Expression | None = None
    """Computed instead when a topic of ``value`` is not in the bag."""
    safety: SafetyLimit | None = None
    meaning: str = ""
    pair: tuple[str, str] | None = None
    """The names of the two robots of a pair metric (``a``, ``b``)."""
    combine: Combine | None = None
    """How values over segments (or over pairs of robots) make one: from the value's aggregate."""
    standard: bool = False
    """Declared by the standard library."""
    location: SourceLocation | None = field(default=None, compare=False, repr=False)

    @property
    def unit(self) -> str:
        return SI_UNIT[self.dimension]

    def info(self) -> MetricInfo:
        return MetricInfo(
            self.name,
            self.dimension,
            self.subject is ComputedFor.ROBOT,
            self.combine if self.per_segment else None,
            meaning=self.meaning,
        )

    def topics_of(self, namespaces: tuple[str, ...]) -> tuple[str, ...]:
        return tuple(read.topic_of(ns) for ns in namespaces for read in self.reads)


def default_topics(scenario: Scenario, metric: str, robot: str | None) -> tuple[str, ...]:
    """The topics ``metric`` is computed from: of ``robot``, or of every robot (fleet order) for
    the mission."""
    robots = [r for r in scenario.robots if robot is None or r.id == robot]
    for definition in scenario.metrics:
        if definition.name == metric:
            return definition.topics_of(tuple(r.namespace for r in robots))
    leaves = TOPICS.get(metric, ())
    if robot is None and metric == "violation_duration":
        leaves = (_POSE,)  # the mission's violations are of the distance between robots
    return tuple(expand_topic(f"/{{ns}}/{leaf}", r.namespace) for r in robots for leaf in leaves)
