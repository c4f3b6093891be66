"""What a bag says of its robots, for a specification drafted from it (``exscec init --from-bag``).

Each namespace that holds a robot (:func:`~exsce_dsl.runs.signals.detect.robot_namespaces`) is
one robot, with the convention detected there.  Its places, in the order it went to them:

- with the method's dispatcher: the waypoints of each dispatcher goal, by the ids the bag gives
  them (segmentation matches them by id), placed where the robot's pose was when each SUCCEEDED
  (the dispatcher's messages carry no poses);
- with Nav2's or move_base's goals: each goal's target, read as segmentation reads it (a
  move_base goal's target pose, the last pose of the plan Nav2 published for it, else where the
  robot was when it SUCCEEDED), one task per goal;
- without goals: the start, the point farthest from it and the end of the robot's path.

Every robot also gets its start, the first pose of its path.  The bag is read as ingestion reads
it (the same sources, on the same timeline), so the places are the ones ingestion will match.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from exsce_dsl.errors import BagError
from exsce_dsl.model.conventions import Navigation, Signals
from exsce_dsl.model.goals import GoalStatus
from exsce_dsl.model.names import is_ros_namespace
from exsce_dsl.model.robots import Robot, RobotType
from exsce_dsl.runs.bags.data import OBJECTS, BagData, Wanted
from exsce_dsl.runs.bags.reading import bag_topics, read_bag
from exsce_dsl.runs.robots import StackRobots
from exsce_dsl.runs.segments.dispatcher import dispatcher_goals
from exsce_dsl.runs.segments.goals import goal_legs
from exsce_dsl.runs.segments.track import DEFAULT_TOLERANCE, Track
from exsce_dsl.runs.signals.detect import Detected, pose_like_topics, robot_namespaces
from exsce_dsl.runs.signals.dispatcher_statuses import dispatcher_statuses
from exsce_dsl.runs.signals.navigation_goals import goal_wanted, read_goals
from exsce_dsl.runs.signals.sources import choose_sources, signals_wanted
from exsce_dsl.runs.signals.timeline import decide_timeline, on_timeline, stamp_catalogue, with_stamps

OCCUPANCY_GRID = "nav_msgs/msg/OccupancyGrid"
APART = 2 * DEFAULT_TOLERANCE.position
"""Places of a path closer than this are one place (arrival could not tell them apart)."""


@dataclass(frozen=True)
class Place:
    """Where a robot went: ``name`` as the bag gives it (a dispatcher waypoint's id) or None."""

    x: float
    y: float
    yaw: float | None
    note: str
    name: str | None = None


@dataclass
class BagRobot:
    """One robot of a bag: its namespace, convention, start, and places grouped into tasks."""

    namespace: str
    signals: Signals
    detected: Detected
    start: Place | None = None
    tasks: list[list[Place]] = field(default_factory=list)
    goals_from: tuple[str, ...] = ()
    """The topics its goals were read from (none: the places are of its path)."""
    pose_from: tuple[str, ...] = ()
    scan: bool = False
    notes: list[str] = field(default_factory=list)

    @property
    def convention(self) -> str | None:
        """The convention to name (None: leave it to detection at each ingest)."""
        return self.signals.convention if self.signals.navigation is not Navigation.NONE else None


@dataclass(frozen=True)
class BagMap:
    topic: str
    messages: int
    width: int
    height: int
    resolution: float
    origin: tuple[float, float, float]
    values: np.ndarray


@dataclass(frozen=True)
class BagContents:
    path: Path
    start: float
    end: float
    topics: int
    robots: tuple[BagRobot, ...]
    map: BagMap | None
    other_maps: tuple[str, ...] = ()
    skipped: tuple[str, ...] = ()
    """Why robots found in the bag are left out."""
    pose_like: tuple[str, ...] = ()
    """The bag's pose-like topics (said when no robot can be placed)."""


def bag_contents(path: Path) -> BagContents:
    """The robots of the bag at ``path``, their places, and its occupancy grid (see the module)."""
    types = bag_topics(path)
    found = robot_namespaces(types)
    if not found:
        listed = "; ".join(pose_like_topics(types)) or "none"
        raise BagError(
            f"{path}: no robot found: no topic of a robot's pose, velocity or scan, no TF and no "
            f"navigation goals (its pose-like topics: {listed})"
        )
    skipped = tuple(
        f"namespace {ns!r} is not a valid ROS name: its robot is left out"
        for ns, _, _ in found
        if not is_ros_namespace(ns)
    )
    robots = [BagRobot(ns, signals, detected) for ns, signals, detected in found if is_ros_namespace(ns)]
    models = [_model(r) for r in robots]
    sources = {m.id: choose_sources(m, types) for m in models}
    sources = {
        k: replace(s, chosen={n: c for n, c in s.chosen.items() if n == "pose"}) for k, s in sources.items()
    }
    wanted = dict(signals_wanted(sources.values(), ()))
    for model in models:
        wanted.update(goal_wanted(model.signals, model.namespace))
    grids = sorted(t for t, m in types.items() if m == OCCUPANCY_GRID)
    maps = [t for t in grids if t.lstrip("/") == "map"] or [t for t in grids if "costmap" not in t][:1]
    wanted.update({t: Wanted(OBJECTS) for t in maps})
    recorded = read_bag(path, with_stamps(wanted, types, stamp_catalogue()))
    data = on_timeline(recorded, decide_timeline(recorded))
    stacks = StackRobots(sources)
    problems: list[str] = []
    topics = stacks.signal_series(data, problems)
    for robot, model in zip(robots, models, strict=True):
        robot.scan = choose_sources(model, types).chosen.get("scan") is not None
        used = sources[model.id].used.get("pose")
        robot.pose_from = used.topics if used is not None else ()
        robot.notes += [p for p in problems if f"'{model.id}'" in p]
        _places(robot, model, data, stacks.track(model, topics))
    grid = _map(maps[0], data) if maps else None
    return BagContents(
        path,
        recorded.start,
        recorded.end,
        len(types),
        tuple(robots),
        grid,
        tuple(t for t in grids if t not in maps),
        skipped,
        tuple(pose_like_topics(types)),
    )


def _model(robot: BagRobot) -> Robot:
    name = robot.namespace or "root"
    return Robot(name, RobotType(name, declared_signals=robot.signals), robot.namespace)


def _places(robot: BagRobot, model: Robot, data: BagData, track: Track) -> None:
    if len(track):
        robot.start = Place(float(track.x[0]), float(track.y[0]), None, "the first pose of its path")
    navigation = robot.signals.navigation
    if navigation is Navigation.DISPATCHER:
        _dispatched(robot, data, track)
    elif navigation in (Navigation.NAV2, Navigation.MOVE_BASE):
        _goals(robot, model, data, track)
    if not robot.tasks and navigation is not Navigation.NONE:
        robot.notes.append(f"no {navigation.value} goals in the bag: the places are of its path")
    if not robot.tasks:
        robot.goals_from = ()
        robot.tasks = [_path(track)] if len(track) else []
    if robot.start is None and robot.tasks and robot.tasks[0]:
        first = robot.tasks[0][0]
        robot.start = Place(first.x, first.y, None, "no pose in the bag: its first goal's")


def _dispatched(robot: BagRobot, data: BagData, track: Track) -> None:
    statuses = dispatcher_statuses(robot.namespace, data)
    topic, updates = statuses.topics[0], statuses.feedback or []
    for goal in dispatcher_goals(updates):
        places = []
        for w, waypoint in enumerate(goal[0].waypoints):
            done = next((u.t for u in goal if u.statuses[w] == GoalStatus.SUCCEEDED), None)
            when = done if done is not None else goal[-1].t
            x, y, _ = track.xy_yaw_at(when) if len(track) else (0.0, 0.0, 0.0)
            said = "SUCCEEDED" if done is not None else "never SUCCEEDED"
            places.append(
                Place(x, y, None, f"waypoint {waypoint} ({said}): where the robot was then", waypoint)
            )
        robot.tasks.append(places)
    robot.goals_from = (topic,) if updates else ()


def _goals(robot: BagRobot, model: Robot, data: BagData, track: Track) -> None:
    goals, used = read_goals(model.signals, model.namespace, data)
    warnings: list[str] = []
    for number, leg in enumerate(goal_legs(goals, track, warnings), start=1):
        if leg.target is None:
            robot.notes.append(f"goal {number} ({leg.status}) has no target in the bag: left out")
            continue
        x, y, yaw = leg.target
        robot.tasks.append([Place(x, y, yaw, f"{leg.label}: {leg.status}")])
    robot.notes += warnings
    robot.goals_from = tuple(dict.fromkeys(used))


def _path(track: Track) -> list[Place]:
    """The farthest point of the path from its start (when it is a place of its own) and its end."""
    xy = np.column_stack([track.x, track.y])
    far = int(np.argmax(np.hypot(*(xy - xy[0]).T)))
    places = []
    if all(float(np.hypot(*(xy[far] - xy[k]))) >= APART for k in (0, -1)):
        places.append(Place(float(xy[far, 0]), float(xy[far, 1]), None, "the farthest point from its start"))
    places.append(Place(float(xy[-1, 0]), float(xy[-1, 1]), None, "the end of its path"))
    return places


def _map(topic: str, data: BagData) -> BagMap | None:
    messages: list[tuple[float, Any]] = data.messages.get(topic) or []
    if not messages:
        return None
    _, grid = messages[-1]  # a map being built grows: its last state
    info, origin = grid.info, grid.info.origin
    q = origin.orientation
    yaw = float(np.arctan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z)))
    return BagMap(
        topic,
        len(messages),
        int(info.width),
        int(info.height),
        float(info.resolution),
        (float(origin.position.x), float(origin.position.y), yaw),
        np.asarray(grid.data, dtype=np.int16),
    )
