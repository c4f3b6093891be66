"""A robot's convention, detected from its bag when its type names none.

A robot type that names no convention gets its signals from what the bag holds under the robot's
namespace, in this order (the first that matches wins), and the lines it does have (a ``pose``
source, an ``arrival`` tolerance, a ``window``) win over what is detected:

1. the method's waypoint dispatcher (its feedback topic): ``method``;
2. Nav2's actions (``/{ns}/navigate_to_pose/_action/status``, ``follow_waypoints``,
   ``navigate_through_poses``): ``nav2``;
3. move_base's actionlib topics (``/{ns}/move_base/status``): ``move_base``;
4. else no goals (segments by arrival at the planned waypoints, or the whole recording), with the
   signals found: the pose from TF (``map`` or ``odom`` → ``base_link`` or ``base_footprint``, on
   ``/{ns}/tf``), else ``/{ns}/amcl_pose``, else an odometry under the namespace (``/{ns}/odom``
   first, then any other such as ``/jackal_velocity_controller/odom``), else the namespace's only
   PoseStamped or PoseWithCovarianceStamped topic; the velocity from ``/{ns}/cmd_vel``, else the
   odometry's twist, else another Twist or TwistStamped topic under the namespace or at the root
   (``/velocity``; else, later, from the poses); the distance along the odometry; the scan on the
   method's scan topic, else the namespace's only LaserScan.

"Under the namespace" is every topic below ``/{ns}/`` (every topic, for a robot at the root).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, replace

from exsce_dsl.model.conventions import (
    DISPATCHER_FEEDBACK,
    FLOAT64,
    LASER_SCAN,
    METHOD,
    METHOD_TOPICS,
    MOVE_BASE,
    NAV2,
    ODOMETRY,
    POSE_STAMPED,
    POSE_TYPES,
    POSE_WITH_COVARIANCE,
    TWIST,
    TWIST_STAMPED,
    VELOCITY_TYPES,
    Navigation,
    PoseSource,
    Signals,
    TfSource,
    TopicSource,
)
from exsce_dsl.model.metrics import expand_topic
from exsce_dsl.model.robots import Robot, RobotType

TF_CHAINS = tuple(
    TfSource(fixed, body) for fixed in ("map", "odom") for body in ("base_link", "base_footprint")
)
"""The TF chains a detected pose is read from, in order of preference."""


@dataclass(frozen=True)
class Detected:
    """The convention picked for one robot and the topics that showed it."""

    robot: str
    convention: str
    evidence: tuple[str, ...]
    own: tuple[str, ...] = ()
    """What the robot's type said itself, which wins over the detected (``pose``, ``window``...)."""

    def describe(self) -> str:
        shown = ", ".join(self.evidence) if self.evidence else "nothing of its namespace"
        said = f"; its own {', '.join(self.own)}" if self.own else ""
        return f"robot '{self.robot}': convention {self.convention} (detected from {shown}{said})"


def with_detected_conventions(
    robots: list[Robot], types: Mapping[str, str]
) -> tuple[list[Robot], list[Detected]]:
    """``robots`` with the convention of each whose type names none detected from the bag's
    topics (``types``: topic → message type), and what was picked."""
    found: list[Robot] = []
    picked: list[Detected] = []
    for robot in robots:
        if robot.names_convention:
            found.append(robot)
            continue
        signals, detected = detect_convention(robot, types)
        if robot.declares_signals:  # its own lines (a pose source, a window...) win
            signals = robot.signals.over(signals)
            detected = replace(detected, own=tuple(sorted(robot.signals.said)))
        found.append(replace(robot, declared_signals=signals))
        picked.append(detected)
    return found, picked


def detect_convention(robot: Robot, types: Mapping[str, str]) -> tuple[Signals, Detected]:
    """The signals of ``robot`` as its bag has them (the rules of this module's docstring)."""
    ns = robot.namespace
    dispatcher = expand_topic(DISPATCHER_FEEDBACK, ns)
    if dispatcher in types:
        return METHOD, Detected(robot.id, "method", (dispatcher,))
    for action in NAV2.actions:
        status = expand_topic(f"{action}/_action/status", ns)
        if status in types:
            return NAV2, Detected(robot.id, "nav2", (status,))
    move_base = expand_topic(f"{MOVE_BASE.actions[0]}/status", ns)
    if move_base in types:
        return MOVE_BASE, Detected(robot.id, "move_base", (move_base,))
    return _without_goals(robot, types)


def _without_goals(robot: Robot, types: Mapping[str, str]) -> tuple[Signals, Detected]:
    ns = robot.namespace
    mine = {t: m for t, m in types.items() if under_namespace(t, ns)}
    odometry = _odometries(mine, ns)
    poses: list[PoseSource] = []
    evidence: list[str] = []
    tf = expand_topic("/{ns}/tf", ns)
    if types.get(tf) == "tf2_msgs/msg/TFMessage":
        poses += TF_CHAINS
        evidence.append(tf)
    amcl = expand_topic("/{ns}/amcl_pose", ns)
    if mine.get(amcl) == POSE_WITH_COVARIANCE:
        poses.append(TopicSource(amcl, POSE_WITH_COVARIANCE))
        evidence.append(amcl)
    poses += [TopicSource(t, ODOMETRY) for t in odometry]
    evidence += odometry
    streams = [t for t, m in mine.items() if m in (POSE_STAMPED, POSE_WITH_COVARIANCE) and t != amcl]
    if len(streams) == 1:
        poses.append(TopicSource(streams[0], mine[streams[0]]))
        evidence.append(streams[0])
    cmd_vel = expand_topic("/{ns}/cmd_vel", ns)
    # /{ns}/cmd_vel is always looked for, so that a robot without a velocity is told where
    velocity = [TopicSource(cmd_vel)] + [TopicSource(t, ODOMETRY) for t in odometry]
    velocity += [TopicSource(t, types[t]) for t in _twists(types, ns) if t != cmd_vel]
    scans = sorted(t for t, m in mine.items() if m == LASER_SCAN)
    scan_topic = expand_topic(METHOD_TOPICS["scan"], ns)
    scan = [scan_topic] if scan_topic in scans else scans[:1] if len(scans) == 1 else []
    signals = Signals(
        convention="detected",
        pose=tuple(poses),
        velocity=tuple(velocity),
        scan=tuple(TopicSource(t, LASER_SCAN) for t in scan),
        distance=_distance(mine, ns, odometry),
        navigation=Navigation.NONE,
    )
    return signals, Detected(robot.id, "none (no navigation goals)", tuple(evidence))


def _distance(mine: Mapping[str, str], ns: str, odometry: list[str]) -> tuple[TopicSource, ...]:
    """The method's distance so far when the robot has it (a robot of a method bag that was given
    no tasks has no dispatcher, but its distance is there), else its first odometry's path."""
    method = expand_topic(METHOD_TOPICS["distance"], ns)
    if mine.get(method) == FLOAT64:
        return (TopicSource(method, FLOAT64),)
    return tuple(TopicSource(t, ODOMETRY) for t in odometry[:1])


def _twists(types: Mapping[str, str], ns: str) -> list[str]:
    """The Twist and TwistStamped topics a robot's velocity may be read from besides its
    ``cmd_vel`` and odometry: under its namespace (a robot at the root: the root's own topics,
    one level deep, not another robot's), then at the root; ``velocity`` and ``vel`` first."""
    level = ns.strip("/")

    def at_root(topic: str) -> bool:
        return "/" not in topic.lstrip("/")

    def preferred(topic: str) -> tuple[bool, bool, str]:
        name = topic.rstrip("/").rsplit("/", 1)[-1]
        return (at_root(topic) and bool(level), name not in ("velocity", "vel"), topic)

    found = [
        t
        for t, m in types.items()
        if m in (TWIST, TWIST_STAMPED) and (at_root(t) or (level and under_namespace(t, level)))
    ]
    return sorted(found, key=preferred)


def _odometries(mine: Mapping[str, str], ns: str) -> list[str]:
    """The namespace's odometry topics, ``/{ns}/odom`` first, then the others by name."""
    own = expand_topic("/{ns}/odom", ns)
    found = sorted(t for t, m in mine.items() if m == ODOMETRY)
    return sorted(found, key=lambda t: t != own)


def under_namespace(topic: str, namespace: str) -> bool:
    """Whether ``topic`` is below ``namespace`` (every topic is below the root)."""
    ns = namespace.strip("/")
    return not ns or topic.lstrip("/").startswith(f"{ns}/")


def pose_like_topics(types: Mapping[str, str]) -> list[str]:
    """The bag's topics a pose could be read from, for a message that found none."""
    kinds = (ODOMETRY, POSE_STAMPED, POSE_WITH_COVARIANCE, "tf2_msgs/msg/TFMessage")
    return sorted(f"{t} ({m})" for t, m in types.items() if m in kinds)


NOT_ROBOTS = frozenset(
    {
        "move_base",
        "move_base_simple",
        "navigate_to_pose",
        "navigate_through_poses",
        "follow_waypoints",
        METHOD_TOPICS["dispatcher"].rsplit("/", 1)[-1],
        "tf",
        "tf_static",
        "clock",
        "rosout",
        "rosout_agg",
        "parameter_events",
        "diagnostics",
    }
)
"""First levels of topic names that are a root robot's interfaces or the graph's, never a robot."""
_BODY_TYPES = (*POSE_TYPES, *VELOCITY_TYPES, LASER_SCAN)
_ROBOT_TYPES = (*_BODY_TYPES, "tf2_msgs/msg/TFMessage")


def robot_namespaces(types: Mapping[str, str]) -> list[tuple[str, Signals, Detected]]:
    """The namespaces of a bag (``types``: topic → message type) that hold a robot, the root
    (``""``) first, each with the signals detected there and what showed them: the root when a
    topic at the root is a robot's (a pose, a velocity, a scan, TF) or a navigation interface is
    there; each first level of the topics' names that shows a convention or a pose (but not the
    names of navigation interfaces, :data:`NOT_ROBOTS`).  A root with a robot's topics of its own (a
    velocity, a scan, a pose) takes in the namespaces that show nothing it does not (a Jackal's
    ``/cmd_vel`` with its ``/jackal_velocity_controller/odom``); a root without, whose every piece of
    evidence is the global ``/tf`` or another robot's topic (a fleet's, or a Gazebo robot's whose
    topics are all under ``/elektron/`` but whose TF is at the root), is not a robot of its own."""
    levels = {t.lstrip("/").split("/")[0] for t in types if "/" in t.lstrip("/")}
    namespaces = sorted(levels - NOT_ROBOTS)
    interfaces = [f"{action}/_action/status" for action in NAV2.actions]
    interfaces += [f"{MOVE_BASE.actions[0]}/status", DISPATCHER_FEEDBACK]
    at_root = any("/" not in t.lstrip("/") and m in _ROBOT_TYPES for t, m in types.items()) or any(
        expand_topic(i, "") in types for i in interfaces
    )
    found: list[tuple[str, Signals, Detected]] = []
    for namespace in ([""] if at_root else []) + namespaces:
        robot = Robot(namespace or "root", RobotType("unknown"), namespace)
        signals, detected = detect_convention(robot, types)
        if detected.evidence or signals.pose:
            found.append((namespace, signals, detected))
    if not found or found[0][0]:
        return found
    root = set(found[0][2].evidence)
    if any("/" not in t.lstrip("/") and m in _BODY_TYPES for t, m in types.items()):
        return found[:1] + [f for f in found[1:] if not set(f[2].evidence) <= root]
    others = [ns for ns, _, _ in found[1:]]
    tf = expand_topic("/{ns}/tf", "")  # a global /tf is the namespaced robots' (Gazebo's elektron)
    if root and others and all(t == tf or any(under_namespace(t, ns) for ns in others) for t in root):
        found.pop(0)
    return found
