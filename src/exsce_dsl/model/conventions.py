"""Where a robot's signals are in its bags: its pose, velocity, laser scan and navigation goals.

A robot type names a *convention* in one word (the method's own topics, Nav2's
or move_base's) and may override any single source.  Each signal lists its
sources in order of preference; ingestion takes the first one the bag has, so
one convention serves Nav2 on Humble (``Twist`` on ``cmd_vel``) and on Jazzy
(``TwistStamped``), robots with or without AMCL, with or without TF recorded.
Topic names are patterns: ``{ns}`` is the robot's namespace (empty for a robot
at the root, whose ``/{ns}/odom`` is ``/odom``).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from enum import Enum

from exsce_dsl.errors import SourceLocation

ODOMETRY = "nav_msgs/msg/Odometry"
POSE_STAMPED = "geometry_msgs/msg/PoseStamped"
POSE_WITH_COVARIANCE = "geometry_msgs/msg/PoseWithCovarianceStamped"
TWIST = "geometry_msgs/msg/Twist"
TWIST_STAMPED = "geometry_msgs/msg/TwistStamped"
LASER_SCAN = "sensor_msgs/msg/LaserScan"
FLOAT64 = "std_msgs/msg/Float64"

POSE_TYPES = (ODOMETRY, POSE_STAMPED, POSE_WITH_COVARIANCE)
"""The types a pose topic may have (its pose is read where the type keeps it)."""
VELOCITY_TYPES = (TWIST, TWIST_STAMPED, ODOMETRY)
"""The types a velocity topic may have (an odometry's twist is the robot's velocity)."""
DISTANCE_TYPES = (FLOAT64, ODOMETRY)
"""The types a distance topic may have (the distance so far, or an odometry whose path it is)."""


class Navigation(Enum):
    """Which navigation interface a robot's goals come through (segments follow from them)."""

    DISPATCHER = "dispatcher"
    """The method's waypoint dispatcher (``waypoint_dispatcher/feedback`` and ``result``)."""
    NAV2 = "nav2"
    """Nav2's actions: ``navigate_to_pose``, ``follow_waypoints``, ``navigate_through_poses``."""
    MOVE_BASE = "move_base"
    """ROS 1 move_base's actionlib topics: ``status``, ``goal``, ``result``."""
    NONE = "none"
    """No goals in the bags: segments come from arrival at the planned waypoints."""


class MetricSpan(Enum):
    """What a robot's whole-run metrics cover."""

    GOALS = "goals"
    """Its first goal's start to its last goal's end (without goals: the whole recording), as
    the method's dispatcher measures a mission."""
    RECORDING = "whole recording"
    """The whole recording, goals or not."""


@dataclass(frozen=True)
class TopicSource:
    """A signal read from one topic; ``msgtype`` None: whatever type of the signal's the bag has."""

    topic: str
    msgtype: str | None = None
    rate: float | None = None
    """The rate (Hz) the topic is published at, when the author declared it (``at 10 Hz``):
    a run that recorded it far below is told (:class:`~exsce_dsl.model.coverage.Shortfall`)."""

    def clause(self) -> str:
        """How a robot type writes it: ``on "/{ns}/odom" nav_msgs/msg/Odometry [at 50 Hz]``."""
        rate = f" at {hertz(self.rate)}" if self.rate is not None else ""
        return f'on "{self.topic}"' + (f" {self.msgtype}" if self.msgtype else "") + rate


def hertz(rate: float) -> str:
    """A rate as the language writes it: ``10 Hz``, ``12.5 Hz`` (read back as the same float)."""
    return f"{int(rate)} Hz" if rate.is_integer() and abs(rate) < 1e15 else f"{rate!r} Hz"


@dataclass(frozen=True)
class TfSource:
    """A pose read from TF: the pose of ``body`` in ``fixed``, composed along the frame tree from
    ``tf`` and ``tf_static``, each transform interpolated at its own rate."""

    fixed: str = "map"
    body: str = "base_link"
    tf: str = "/{ns}/tf"
    tf_static: str = "/{ns}/tf_static"

    def clause(self) -> str:
        """How a robot type writes it: ``from tf map -> base_link``."""
        return f"from tf {self.fixed} -> {self.body}"


PoseSource = TopicSource | TfSource


@dataclass(frozen=True)
class Tolerance:
    """How close a pose must be to a planned waypoint to be that waypoint (map frame).

    ``position`` (metres, in the plane) defaults to 0.35 m: Nav2's default goal checker declares
    success within ``xy_goal_tolerance`` = 0.25 m of the goal (move_base's DWA planner: 0.1 m), and
    the track we compare with (AMCL, TF map → base_link, a simulator's ground truth) differs from
    the estimate the checker used by up to ~0.1 m.  Goals read from the bag carry the planned pose
    itself, so for them any tolerance above float rounding works.  Planned waypoints closer than
    twice the tolerance cannot be told apart by position (scenario_c's closest pair is 1.9 m apart).
    A track that updates only every so far (``/amcl_pose`` publishes after ``update_min_d`` =
    0.25 m of motion) lags the robot by that much: prefer TF, or widen the tolerance.

    ``heading`` (radians) is ``None`` by default: not compared.  Planned waypoints often leave the
    final heading free (a pose's yaw is whatever its declaration says, and stacks are commonly run
    with a loose yaw tolerance), and the position alone names the waypoint.  Set it (e.g. 0.35 rad:
    Nav2's ``yaw_goal_tolerance`` 0.25 rad plus localisation) when a plan visits one position with
    two headings.
    """

    position: float = 0.35
    heading: float | None = None
    written: tuple[str, ...] = field(default=(), compare=False, repr=False)
    """The position (and heading) as the author wrote them (``30 cm``, ``10 deg``), for the formatter."""


@dataclass(frozen=True)
class Signals:
    """Where a robot's signals are: each a list of sources, the first one the bag has wins."""

    convention: str
    pose: tuple[PoseSource, ...]
    velocity: tuple[TopicSource, ...]
    scan: tuple[TopicSource, ...]
    distance: tuple[TopicSource, ...] = ()
    """Where the distance travelled is: a Float64 of it so far (the method's), or an Odometry
    whose path it is (wheel odometry is smooth where a localised pose jitters, and a path length
    adds up jitter); with neither, it is the pose's path length."""
    navigation: Navigation = Navigation.NONE
    actions: tuple[str, ...] = ()
    """The navigation interface's action (or dispatcher) names, patterns with ``{ns}``."""
    tolerance: Tolerance = field(default_factory=Tolerance)
    window: MetricSpan = MetricSpan.GOALS
    """What a robot's whole-run metrics cover (see :class:`MetricSpan`)."""
    rates: tuple[tuple[str, float], ...] = ()
    """(signal, Hz) the author declared for a signal wherever it is read from (``scan at 10
    Hz``); a source's own rate (``scan on "/{ns}/scan" at 10 Hz``) wins for that source."""
    named: bool = True
    """Whether the author named the convention; if not, ingestion detects it from each bag, and
    only what ``said`` lists is the author's."""
    said: frozenset[str] = frozenset()
    """The fields the author's own lines set (``pose``, ``velocity``, ``scan``, ``navigation``,
    ``tolerance``, ``window``, ``rates``): they win over a convention detected from the bag."""
    location: SourceLocation | None = field(default=None, compare=False, repr=False)

    def overridden(self, **sources: object) -> Signals:
        """These signals with some replaced (a robot type's own ``pose``, ``velocity``...)."""
        return replace(self, **sources)  # type: ignore[arg-type]

    def rate_of(self, signal: str) -> float | None:
        """The rate (Hz) declared for ``signal`` as a whole (``velocity at 20 Hz``), if any."""
        return next((hz for name, hz in self.rates if name == signal), None)

    def over(self, detected: Signals) -> Signals:
        """``detected`` (a convention found in a bag) with what the author said of these signals."""
        said = {name: getattr(self, name) for name in self.said}
        if "navigation" in said:
            said["actions"] = self.actions
        return detected.overridden(**said, said=self.said, named=False)


METHOD_TOPICS = {
    "pose": "/{ns}/robot_pose",
    "velocity": "/{ns}/nav_vel",
    "scan": "/{ns}/scan",
    "distance": "/{ns}/distance_travelled",
    "dispatcher": "/{ns}/waypoint_dispatcher",
    "feedback": "/{ns}/waypoint_dispatcher/feedback",
    "result": "/{ns}/waypoint_dispatcher/result",
}
"""The method's topic names (patterns with ``{ns}``), by what each carries: the only place they are
written (``tests/project/test_method_topics.py`` holds it); the simulator, the code generators and
ingestion take them from here."""

METHOD = Signals(
    convention="method",
    pose=(TopicSource(METHOD_TOPICS["pose"], POSE_WITH_COVARIANCE),),
    velocity=(TopicSource(METHOD_TOPICS["velocity"], TWIST),),
    scan=(TopicSource(METHOD_TOPICS["scan"], LASER_SCAN),),
    distance=(TopicSource(METHOD_TOPICS["distance"], FLOAT64),),
    navigation=Navigation.DISPATCHER,
    actions=(METHOD_TOPICS["dispatcher"],),
)
"""The method's own topics, as its executor and the robots of its published runs publish them."""

DISPATCHER_FEEDBACK, DISPATCHER_RESULT = METHOD_TOPICS["feedback"], METHOD_TOPICS["result"]
"""The method's waypoint dispatcher's feedback and result topics (patterns with ``{ns}``)."""

NAV2 = Signals(
    convention="nav2",
    pose=(TfSource(), TopicSource("/{ns}/amcl_pose"), TopicSource("/{ns}/odom")),
    velocity=(TopicSource("/{ns}/cmd_vel"), TopicSource("/{ns}/odom")),
    scan=(TopicSource("/{ns}/scan", LASER_SCAN),),
    distance=(TopicSource("/{ns}/odom", ODOMETRY),),
    navigation=Navigation.NAV2,
    actions=("/{ns}/navigate_to_pose", "/{ns}/follow_waypoints", "/{ns}/navigate_through_poses"),
)
"""Nav2 (Humble and Jazzy): pose from TF ``map → base_link`` (else AMCL's, else odometry),
velocity commanded on ``cmd_vel`` (Twist on Humble, TwistStamped from Jazzy on), distance
travelled along the wheel odometry."""

MOVE_BASE = Signals(
    convention="move_base",
    pose=(TfSource(), TopicSource("/{ns}/amcl_pose"), TopicSource("/{ns}/odom")),
    velocity=(TopicSource("/{ns}/cmd_vel"), TopicSource("/{ns}/odom")),
    scan=(TopicSource("/{ns}/scan", LASER_SCAN),),
    distance=(TopicSource("/{ns}/odom", ODOMETRY),),
    navigation=Navigation.MOVE_BASE,
    actions=("/{ns}/move_base",),
)
"""ROS 1 move_base: the same signals as Nav2's, goals through actionlib's ``move_base``."""

CONVENTIONS = {c.convention: c for c in (METHOD, NAV2, MOVE_BASE)}
"""The conventions a robot type names in one word."""
