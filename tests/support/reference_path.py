"""An independent reference for every metric exsce computes from a bag: rosbags' deserialisation
and plain numpy, written from the documentation (docs/bags.md "One timeline", "Windows", "3-D";
docs/language.md's metric functions), never from exsce's reading or metrics code, none of which
is imported here.

The rules it follows, the simplest that say what the documentation says:

- a topic's messages are taken in the bag's log-time order, every connection of the topic;
- a message is timed by its header stamp when its topic's stamps are finer than its rate (more
  than half of them distinct), else by its log time;
- a robot without recorded goals is measured over its whole recording: every sample of each
  source, and the recording's span (first message of the bag to its last) as its durations;
- a path is the sum of the Euclidean steps between consecutive samples (x-y); a speed is the
  norm of (vx, vy) of a Twist, a TwistStamped or an Odometry's twist, or, with no velocity
  signal, the straight distance between the positions 0.25 s before and after each pose sample
  (interpolated, both ends held within the series) over that time;
- a sample holds until the next one (the last for one median period, none longer than two);
  a violation lasts as long as the samples over the limit hold;
- two robots' distance is the second's position interpolated at the first's pose times, where
  both have data;
- arrival: a robot that left its start (more than the tolerance) set off at the last sample at
  which it was still at its first pose (1 cm, 0.01 rad), and arrives at each planned waypoint, in
  order, at its first pose sample within the tolerance from the previous arrival; each path
  segment runs from one to the next, its values over the samples of each source in that time.

A value the data cannot support is ``None``: the test then expects it missing with a reason.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_typestore

TOLERANCE = 0.35
"""Metres: the default arrival tolerance (docs/bags.md, "Path segments")."""
HALF_BASELINE = 0.25
"""Seconds before and after a sample over which a speed is taken (docs/bags.md, "3-D")."""
SPEED_LIMIT = 1.0
CLEARANCE_LIMIT = 0.1
SEPARATION_LIMIT = 0.1
"""The method's safety limits (lang/stdlib/metrics.exsce: ``safe below 1.0 m/s``, ``safe above
0.1 m`` twice)."""


@dataclass(frozen=True)
class Samples:
    """One topic's messages: their times on the run's timeline (s), their log times (s), and
    the messages as rosbags deserialises them."""

    t: np.ndarray
    log: np.ndarray
    messages: list[Any]

    def column(self, read: Callable[[Any], float]) -> np.ndarray:
        return np.array([read(m) for m in self.messages], dtype=np.float64)


@dataclass
class Recording:
    """A bag read once: each topic's samples on demand, and the span of all its messages."""

    path: Path
    start: float = 0.0
    end: float = 0.0
    topics: dict[str, str] = field(default_factory=dict)
    _read: dict[str, Samples] = field(default_factory=dict)

    def __post_init__(self) -> None:
        with _reader(self.path) as reader:
            times = [t for _, t, _ in reader.messages()]
            self.start, self.end = min(times) * 1e-9, max(times) * 1e-9
            self.topics = {c.topic: c.msgtype for c in reader.connections}

    @property
    def span(self) -> float:
        return self.end - self.start

    def samples(self, topic: str) -> Samples:
        if topic not in self._read:
            self._read[topic] = _samples(self.path, topic)
        return self._read[topic]


def _reader(path: Path) -> AnyReader:
    # a ROS 2 bag may carry no definitions (sqlite3 before Iron): rosbags' own Humble types
    return AnyReader([path], default_typestore=get_typestore(Stores.ROS2_HUMBLE))


def _samples(path: Path, topic: str) -> Samples:
    with _reader(path) as reader:
        chosen = [c for c in reader.connections if c.topic == topic]
        rows = [(t, reader.deserialize(raw, c.msgtype)) for c, t, raw in reader.messages(chosen)]
    rows.sort(key=lambda row: row[0])
    log = np.array([t for t, _ in rows], dtype=np.float64) * 1e-9
    messages = [m for _, m in rows]
    stamps = [_stamp(m) for m in messages]
    if messages and all(s is not None for s in stamps):
        t = np.array(stamps, dtype=np.float64)
        if len(np.unique(t)) * 2 > len(t):  # finer than the topic's rate
            return Samples(t, log, messages)
    return Samples(log, log, messages)


def _stamp(message: Any) -> float | None:
    header = getattr(message, "header", None)
    if header is None:
        return None
    return float(header.stamp.sec) + float(header.stamp.nanosec) * 1e-9


# ------------------------------------------------------------------ fields of messages


def position(message: Any) -> tuple[float, float, float]:
    """x, y, z of an Odometry, a PoseWithCovarianceStamped, a PoseStamped, or a header-less pose
    with fields ``x`` and ``y`` (turtlesim's)."""
    pose = getattr(message, "pose", None)
    if pose is None:
        return float(message.x), float(message.y), 0.0
    while hasattr(pose, "pose"):
        pose = pose.pose
    p = pose.position
    return float(p.x), float(p.y), float(p.z)


def planar_speed(message: Any) -> float:
    """|(vx, vy)| of a Twist, a TwistStamped, or an Odometry's twist."""
    twist = message
    while hasattr(twist, "twist"):
        twist = twist.twist
    return float(np.hypot(twist.linear.x, twist.linear.y))


def xy(samples: Samples) -> tuple[np.ndarray, np.ndarray]:
    found = np.array([position(m)[:2] for m in samples.messages], dtype=np.float64).reshape(-1, 2)
    return found[:, 0], found[:, 1]


# ------------------------------------------------------------------ the functions


def path_length(*coordinates: np.ndarray) -> float:
    steps = [np.diff(c) for c in coordinates]
    return float(np.sqrt(sum(np.square(s) for s in steps)).sum()) if len(coordinates[0]) > 1 else 0.0


def speeds(t: np.ndarray, *coordinates: np.ndarray) -> np.ndarray:
    """The speed at each sample: the chord from ``HALF_BASELINE`` before to after, over its time."""
    before = np.maximum(t - HALF_BASELINE, t[0])
    after = np.minimum(t + HALF_BASELINE, t[-1])
    moved = np.sqrt(sum(np.square(np.interp(after, t, c) - np.interp(before, t, c)) for c in coordinates))
    span = after - before
    return np.where(span > 0, moved / np.where(span > 0, span, 1.0), np.nan)


def hold(t: np.ndarray) -> np.ndarray:
    """How long each sample holds: until the next one, the last one median period, at most two;
    the period is the median of the steps that move (samples sharing a time hold nothing)."""
    if len(t) < 2:
        return np.zeros(len(t))
    gaps = np.diff(t)
    period = float(np.median(gaps[gaps > 0])) if np.any(gaps > 0) else 0.0
    held: np.ndarray = np.minimum(np.append(gaps, period), 2 * period)
    return held


def duration_where(t: np.ndarray, condition: np.ndarray) -> float:
    return float(hold(t)[condition].sum())


def nearest_ranges(samples: Samples) -> np.ndarray:
    """Per scan, its least range inside [range_min, range_max] (NaN: none)."""
    found = []
    for scan in samples.messages:
        r = np.asarray(scan.ranges, dtype=np.float64)
        valid = r[(r >= scan.range_min) & (r <= scan.range_max)]
        found.append(float(valid.min()) if len(valid) else np.nan)
    return np.array(found)


def separation(first: tuple[np.ndarray, ...], second: tuple[np.ndarray, ...]) -> np.ndarray:
    """Distances of two robots (t, x, y each): the second's position interpolated at the first's
    times within the second's span."""
    t, x, y = first
    inside = (t >= second[0][0]) & (t <= second[0][-1])
    ox = np.interp(t[inside], second[0], second[1])
    oy = np.interp(t[inside], second[0], second[2])
    return np.asarray(np.hypot(x[inside] - ox, y[inside] - oy))


def heading(message: Any) -> float:
    """The yaw of a pose message (turtlesim's ``theta``; 0 for a position alone)."""
    pose = getattr(message, "pose", None)
    if pose is None:
        return float(getattr(message, "theta", 0.0))
    while hasattr(pose, "pose"):
        pose = pose.pose
    q = pose.orientation
    return float(np.arctan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z)))


def cuts(samples: Samples, waypoints: Sequence[tuple[float, float]]) -> list[int] | None:
    """The pose samples that start and end the path segments of arrival: the moment the robot
    set off (the last sample still at its first pose, within 1 cm and 0.01 rad, before it first
    went farther than the tolerance), then its arrival at each planned waypoint reached, in order;
    None when it never moved."""
    x, y = xy(samples)
    yaw = samples.column(heading)
    away = np.hypot(x - x[0], y - y[0]) if len(x) else np.zeros(0)
    if not (away > TOLERANCE).any():
        return None
    moved = int(np.flatnonzero(away > TOLERANCE)[0])
    turned = np.abs(np.angle(np.exp(1j * (yaw[:moved] - yaw[0]))))
    still = np.flatnonzero((away[:moved] <= 0.01) & (turned <= 0.01))
    found = [int(still[-1]) if len(still) else 0]
    for wx, wy in waypoints:
        near = np.flatnonzero(np.hypot(x[found[-1] :] - wx, y[found[-1] :] - wy) <= TOLERANCE)
        if not len(near):
            break
        found.append(found[-1] + int(near[0]))
    return found


def inside(t: np.ndarray, start: float, end: float) -> slice:
    """The samples of ``t`` in ``[start, end]``."""
    return slice(int(np.searchsorted(t, start, "left")), int(np.searchsorted(t, end, "right")))


# ------------------------------------------------------------------ a robot's built-in metrics


@dataclass(frozen=True)
class RobotSources:
    """Where a robot's signals are in a bag, as the test states them: its pose (a topic, or TF
    ``fixed → body`` as ``(tf_reader, frames)``), its velocity topic (None: estimated from the
    pose), its distance topic (an odometry whose path is the distance; None: the pose's path),
    its scan, and its planned waypoints; ``implausible``: the test wrote its pose so that no robot
    could have made it (two tracks alternating, a teleport), and nothing is computed from it."""

    robot: str
    pose: str | None = None
    velocity: str | None = None
    distance: str | None = None
    scan: str | None = None
    waypoints: tuple[tuple[float, float], ...] = ()
    tf_pose: Callable[[Recording], Samples] | None = None
    implausible: bool = False


Key = tuple[str, str | None]
"""(metric, robot; None for the mission's)."""


@dataclass(frozen=True)
class Expected:
    """A reference value and the topics it was computed from (``value`` None: missing)."""

    value: float | None
    topics: tuple[str, ...] = ()


def _pose(bag: Recording, robot: RobotSources) -> Samples | None:
    if robot.implausible:
        return None
    if robot.tf_pose is not None:
        return robot.tf_pose(bag)
    return bag.samples(robot.pose) if robot.pose else None


@dataclass(frozen=True)
class _Signal:
    """A robot's signal for one built-in metric: times, per-sample values (x and y for a path),
    and the topics it came from."""

    t: np.ndarray
    v: tuple[np.ndarray, ...]
    topics: tuple[str, ...]


def _signals(bag: Recording, robot: RobotSources, pose: Samples | None) -> dict[str, _Signal | None]:
    """The samples each of the robot's per-segment metrics reads."""
    pose_topic: tuple[str, ...] = (robot.pose,) if robot.pose else ()
    found: dict[str, _Signal | None] = {"distance_travelled": None, "max_velocity": None}
    if robot.distance:
        odometry = bag.samples(robot.distance)
        found["distance_travelled"] = _Signal(odometry.t, xy(odometry), (robot.distance,))
    elif pose is not None:
        found["distance_travelled"] = _Signal(pose.t, xy(pose), pose_topic)
    if robot.velocity:
        vel = bag.samples(robot.velocity)
        found["max_velocity"] = _Signal(vel.t, (vel.column(planar_speed),), (robot.velocity,))
    elif pose is not None and len(pose.t) > 1:
        found["max_velocity"] = _Signal(pose.t, (speeds(pose.t, *xy(pose)),), pose_topic)
    scans = bag.samples(robot.scan) if robot.scan else None
    found["distance_to_obstacles"] = (
        _Signal(scans.t, (nearest_ranges(scans),), (robot.scan,)) if scans and robot.scan else None
    )
    return found


def _aggregate(metric: str, signal: _Signal, window: slice) -> float | None:
    values = [v[window] for v in signal.v]
    if not len(values[0]):
        return None
    if metric == "distance_travelled":
        return path_length(*values)
    found = float(np.nanmax(values[0]) if metric == "max_velocity" else np.nanmin(values[0]))
    return None if np.isnan(found) else found


LIMITS = {"max_velocity": (SPEED_LIMIT, 1.0), "distance_to_obstacles": (CLEARANCE_LIMIT, -1.0)}
"""Each safety metric's limit, and the sign of its excess (above a 'below' limit, below an
'above' one)."""


def robot_values(bag: Recording, robot: RobotSources) -> dict[Key, Expected]:
    """The robot's built-in values: over the whole run (task_duration, waypoints_visited,
    distance_travelled, max_velocity, distance_to_obstacles, the violation durations), and per
    path segment of arrival (``metric@k``, k from 1: the same but the count and violations)."""
    r = robot.robot
    pose = _pose(bag, robot)
    found: dict[Key, Expected] = {("task_duration", r): Expected(bag.span)}
    segments = cuts(pose, robot.waypoints) if pose is not None and robot.waypoints else None
    found[("waypoints_visited", r)] = Expected(
        float(len(segments) - 1) if segments and len(segments) > 1 else None
    )
    windows = []
    if pose is not None and segments:
        for k, (a, b) in enumerate(zip(segments, segments[1:], strict=False), start=1):
            start, end = float(pose.t[a]), float(pose.t[b])
            windows.append((f"@{k}", start, end))
            found[(f"task_duration@{k}", r)] = Expected(end - start)
    for metric, signal in _signals(bag, robot, pose).items():
        if signal is None:
            found[(metric, r)] = Expected(None)
            continue
        found[(metric, r)] = Expected(_aggregate(metric, signal, slice(None)), signal.topics)
        for suffix, start, end in windows:
            found[(metric + suffix, r)] = Expected(
                _aggregate(metric, signal, inside(signal.t, start, end)), signal.topics
            )
        limit, sign = LIMITS.get(metric, (None, 0.0))
        if limit is not None:
            with np.errstate(invalid="ignore"):
                over = sign * (signal.v[0] - limit) > 0
            found[(f"violation_duration/{metric}", r)] = Expected(
                duration_where(signal.t, over), signal.topics
            )
    return found


def run_values(bag: Recording, robots: Sequence[RobotSources]) -> dict[Key, Expected]:
    """Every whole-run built-in value of a run of ``robots`` without recorded goals."""
    found: dict[Key, Expected] = {("mission_duration", None): Expected(bag.span)}
    for robot in robots:
        found.update(robot_values(bag, robot))
    if len(robots) >= 2:
        poses = [_pose(bag, r) for r in robots]
        if any(p is None for p in poses):
            found[("distance_between_robots", None)] = Expected(None)
        else:
            tracks = [(p.t, *xy(p)) for p in poses if p is not None]
            apart = np.concatenate([separation(a, b) for i, a in enumerate(tracks) for b in tracks[i + 1 :]])
            found[("distance_between_robots", None)] = Expected(float(apart.min()))
            close = sum(
                duration_where(
                    a[0][(a[0] >= b[0][0]) & (a[0] <= b[0][-1])], separation(a, b) < SEPARATION_LIMIT
                )
                for i, a in enumerate(tracks)
                for b in tracks[i + 1 :]
            )
            found[("violation_duration/distance_between_robots", None)] = Expected(close)
    return found


def tf_pose(fixed: str, middle: str, body: str, topic: str = "/tf") -> Callable[[Recording], Samples]:
    """The pose of ``body`` in ``fixed`` through ``middle`` from ``topic``'s transforms: every
    ``middle → body`` transform (timed by its stamp), composed with ``fixed → middle``
    interpolated at its stamp (x, y, yaw linearly; held past either end)."""

    def read(bag: Recording) -> Samples:
        edges: dict[tuple[str, str], list[tuple[float, float, float, float]]] = {}
        for message in bag.samples(topic).messages:
            for tr in message.transforms:
                v, q = tr.transform.translation, tr.transform.rotation
                yaw = float(np.arctan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z)))
                stamp = float(tr.header.stamp.sec) + float(tr.header.stamp.nanosec) * 1e-9
                edges.setdefault((tr.header.frame_id, tr.child_frame_id), []).append((stamp, v.x, v.y, yaw))
        moving = np.array(sorted(edges[(middle, body)]))
        base = np.array(sorted(edges[(fixed, middle)]))
        t = moving[:, 0]
        bx, by, byaw = (np.interp(t, base[:, 0], base[:, k]) for k in (1, 2, 3))
        x = bx + np.cos(byaw) * moving[:, 1] - np.sin(byaw) * moving[:, 2]
        y = by + np.sin(byaw) * moving[:, 1] + np.cos(byaw) * moving[:, 2]
        return Samples(t, t, [_Point(float(a), float(b)) for a, b in zip(x, y, strict=True)])

    return read


@dataclass(frozen=True)
class _Point:
    """A header-less position, as :func:`position` reads one."""

    x: float
    y: float
