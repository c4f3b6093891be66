"""The reference: the method's metrics as exsce computed them by hand, before metrics were declared.

exsce now computes the built-in metrics through monitors generated from the
standard library (``lang/stdlib/metrics.exsce``); this hand-written path is
kept here, outside the package, only so that tests can check the generated
path gives the same values (tests/runs/metrics/test_generated_metrics.py).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from exsce_dsl.model.geometry import Position
from exsce_dsl.model.runs import ActionId, Hotspot, MetricScope, MetricValue
from exsce_dsl.runs.bags.data import BagData, Series
from exsce_dsl.runs.segments.recorded import RecordedAction

from tests.support.reference_path import hold

HOTSPOT_RADIUS = 1.0  # metres: violations closer than this to a hotspot belong to it


@dataclass(frozen=True)
class SafetyLimits:
    """The method's baseline safety limits (an oracle may set others)."""

    max_velocity: float = 1.0
    distance_to_obstacles: float = 0.1
    distance_between_robots: float = 0.1


def robot_topics(ns: str) -> dict[str, str]:
    ns = ns.strip("/")
    return {
        "pose": f"/{ns}/robot_pose",
        "scan": f"/{ns}/scan",
        "vel": f"/{ns}/nav_vel",
        "distance": f"/{ns}/distance_travelled",
        "feedback": f"/{ns}/waypoint_dispatcher/feedback",
        "result": f"/{ns}/waypoint_dispatcher/result",
    }


def _window(series: Series, start: float, end: float) -> slice:
    return slice(int(np.searchsorted(series.t, start, "left")), int(np.searchsorted(series.t, end, "right")))


@dataclass
class RobotSignals:
    """A robot's decoded topics, as the metrics need them."""

    robot: str
    topics: dict[str, str]
    pose: Series | None
    scan: Series | None
    vel: Series | None
    distance: Series | None
    _cache: dict[str, np.ndarray] = field(default_factory=dict, repr=False)

    @classmethod
    def from_bag(cls, robot: str, ns: str, bag: BagData) -> RobotSignals:
        topics = robot_topics(ns)
        return cls(
            robot,
            topics,
            bag.series.get(topics["pose"]),
            bag.series.get(topics["scan"]),
            bag.series.get(topics["vel"]),
            bag.series.get(topics["distance"]),
        )

    def speed(self) -> np.ndarray:
        assert self.vel is not None
        cached = self._cache.get("speed")
        if cached is None:
            cached = self._cache["speed"] = np.hypot(self.vel.fields["linear.x"], self.vel.fields["linear.y"])
        return cached

    def nearest_obstacle(self) -> np.ndarray:
        """Per scan, the smallest valid range (NaN when no beam is valid)."""
        assert self.scan is not None
        cached = self._cache.get("nearest")
        if cached is None:
            f = self.scan.fields
            cached = self._cache["nearest"] = nearest_valid(f["ranges"], f["range_min"], f["range_max"])
        return cached

    def travelled_between(self, start: float, end: float) -> tuple[float, str] | None:
        """Metres between two instants: from the cumulative topic, else integrated poses."""
        if self.distance is not None and len(self.distance):
            d = self.distance
            values = np.interp([start, end], d.t, d.fields["data"])
            return float(values[1] - values[0]), self.topics["distance"]
        if self.pose is not None and len(self.pose) > 1:
            w = _window(self.pose, start, end)
            x, y = self.pose.fields["pose.pose.position.x"][w], self.pose.fields["pose.pose.position.y"][w]
            return float(np.hypot(np.diff(x), np.diff(y)).sum()), self.topics["pose"]
        return None

    def position_at(self, times: np.ndarray) -> np.ndarray:
        assert self.pose is not None
        return np.column_stack(
            [
                np.interp(times, self.pose.t, self.pose.fields["pose.pose.position.x"]),
                np.interp(times, self.pose.t, self.pose.fields["pose.pose.position.y"]),
            ]
        )


def compute_metrics(
    signals: Sequence[RobotSignals],
    actions: Sequence[RecordedAction],
    results: dict[str, int | None],
    limits: SafetyLimits,
    problems: list[str],
) -> tuple[list[MetricValue], list[Hotspot]]:
    """Every metric of DESIGN §1 for a run. ``results``: robot → waypoints SUCCEEDED (None: no topic)."""
    values: list[MetricValue] = []
    hotspots: list[Hotspot] = []
    # (segment, became active, reached its final status) of every action that ended
    done = [(a, a.start, a.end) for a in actions if a.start is not None and a.end is not None]
    mission_start = min((s for _, s, _ in done), default=0.0)
    mission_end = max((e for _, _, e in done), default=0.0)
    if done:
        values.append(
            MetricValue(
                "mission_duration",
                MetricScope.MISSION,
                mission_end - mission_start,
                tuple(s.topics["feedback"] for s in signals),
                unit="s",
            )
        )
    for sig in signals:
        mine = [(a, s, e) for a, s, e in done if a.robot == sig.robot]
        feedback = (sig.topics["feedback"],)
        if not mine:
            problems.append(f"robot '{sig.robot}' started no waypoint goal: its metrics are missing")
            continue
        start, end = min(s for _, s, _ in mine), max(e for _, _, e in mine)
        values.append(
            MetricValue("task_duration", MetricScope.ROBOT, end - start, feedback, sig.robot, unit="s")
        )
        visited = results.get(sig.robot)
        if visited is None:
            problems.append(
                f"topic {sig.topics['result']} is missing: waypoints_visited of '{sig.robot}' is missing"
            )
        else:
            values.append(
                MetricValue(
                    "waypoints_visited", MetricScope.ROBOT, float(visited), (sig.topics["result"],), sig.robot
                )
            )
        windows: list[tuple[RecordedAction | None, float, float]] = [(None, start, end), *mine]
        for action, a_start, a_end in windows:
            aid = (
                None
                if action is None
                else ActionId(sig.robot, action.allocation, action.subtask, action.waypoint)
            )
            scope = MetricScope.ROBOT if action is None else MetricScope.SEGMENT
            robot = sig.robot if action is None else None
            if action is not None:
                values.append(MetricValue("task_duration", scope, a_end - a_start, feedback, robot, aid, "s"))
            travelled = sig.travelled_between(a_start, a_end)
            if travelled is not None:
                values.append(
                    MetricValue("distance_travelled", scope, travelled[0], (travelled[1],), robot, aid, "m")
                )
            if sig.scan is not None and len(sig.scan):
                w = _window(sig.scan, a_start, a_end)
                nearest = sig.nearest_obstacle()[w]
                if np.isfinite(nearest).any():
                    values.append(
                        MetricValue(
                            "distance_to_obstacles",
                            scope,
                            float(np.nanmin(nearest)),
                            (sig.topics["scan"],),
                            robot,
                            aid,
                            "m",
                        )
                    )
            if sig.vel is not None and len(sig.vel):
                w = _window(sig.vel, a_start, a_end)
                speed = sig.speed()[w]
                if len(speed):
                    values.append(
                        MetricValue(
                            "max_velocity", scope, float(speed.max()), (sig.topics["vel"],), robot, aid, "m/s"
                        )
                    )
        for name, topic, times, held, over in _safety_signals(sig, limits, start, end):
            values.append(
                MetricValue(
                    "violation_duration",
                    MetricScope.ROBOT,
                    float(held[over].sum()),
                    (topic,),
                    sig.robot,
                    unit="s",
                    safety_metric=name,
                )
            )
            if over.any() and sig.pose is not None:
                where = sig.position_at(times[over])
                hotspots.extend(
                    Hotspot(name, Position(float(c[0]), float(c[1])), n, d, sig.robot)
                    for c, n, d in _cluster(where, held[over])
                )
        for key in ("pose", "scan", "vel", "distance"):
            if getattr(sig, key) is None and key != "distance":
                problems.append(
                    f"topic {sig.topics[key]} is missing: the metrics it feeds are missing for '{sig.robot}'"
                )
    if done:
        values.extend(_between_robots(signals, mission_start, mission_end, limits, hotspots, problems))
    return values, hotspots


def nearest_valid(ranges: np.ndarray, low: np.ndarray, high: np.ndarray) -> np.ndarray:
    """Per scan, the smallest range within [range_min, range_max] (NaN and inf never are); NaN if none."""
    lo = low.astype(np.float32)[:, None]
    hi = high.astype(np.float32)[:, None]
    valid = (ranges >= lo) & (ranges <= hi)
    nearest = np.where(valid, ranges, np.float32(np.inf)).min(axis=1).astype(np.float64)
    result: np.ndarray = np.where(np.isfinite(nearest), nearest, np.nan)
    return result


SafetySignal = tuple[str, str, np.ndarray, np.ndarray, np.ndarray]
"""(safety metric, topic, sample times, sample durations, violating samples)."""


def _safety_signals(sig: RobotSignals, limits: SafetyLimits, start: float, end: float) -> list[SafetySignal]:
    found: list[SafetySignal] = []
    if sig.vel is not None and len(sig.vel):
        w = _window(sig.vel, start, end)
        t = sig.vel.t[w]
        found.append(("max_velocity", sig.topics["vel"], t, hold(t), sig.speed()[w] > limits.max_velocity))
    if sig.scan is not None and len(sig.scan):
        w = _window(sig.scan, start, end)
        t = sig.scan.t[w]
        nearest = np.nan_to_num(sig.nearest_obstacle()[w], nan=np.inf)
        found.append(
            (
                "distance_to_obstacles",
                sig.topics["scan"],
                t,
                hold(t),
                nearest < limits.distance_to_obstacles,
            )
        )
    return found


def _cluster(points: np.ndarray, durations: np.ndarray) -> list[tuple[np.ndarray, int, float]]:
    """The hotspots' rule, written out again with plain Python numbers: in order, a point joins the
    first group whose centre (the mean of its points so far) is within HOTSPOT_RADIUS, else it
    starts a group."""
    groups: list[list[tuple[float, float, float]]] = []  # (x, y, duration) of each member
    for (x, y), duration in zip(points.tolist(), durations.tolist(), strict=True):
        for group in groups:
            cx = sum(m[0] for m in group) / len(group)
            cy = sum(m[1] for m in group) / len(group)
            if math.hypot(x - cx, y - cy) <= HOTSPOT_RADIUS:
                group.append((x, y, duration))
                break
        else:
            groups.append([(x, y, duration)])
    return [
        (
            np.array([sum(m[0] for m in g) / len(g), sum(m[1] for m in g) / len(g)]),
            len(g),
            sum(m[2] for m in g),
        )
        for g in groups
    ]


def _between_robots(
    signals: Sequence[RobotSignals],
    start: float,
    end: float,
    limits: SafetyLimits,
    hotspots: list[Hotspot],
    problems: list[str],
) -> list[MetricValue]:
    """Minimum pairwise distance, the second robot's poses interpolated at the first one's times."""
    posed = [s for s in signals if s.pose is not None and len(s.pose) > 1]
    if len(posed) < 2:
        if len(signals) >= 2:
            problems.append("robot_pose of fewer than two robots: distance_between_robots is missing")
        return []
    nearest = np.inf
    violation = 0.0
    topics: list[str] = []
    for i, a in enumerate(posed):
        for b in posed[i + 1 :]:
            assert a.pose is not None and b.pose is not None
            w = _window(a.pose, max(start, b.pose.t[0]), min(end, b.pose.t[-1]))
            t = a.pose.t[w]
            if len(t) == 0:
                continue
            xa, ya = a.pose.fields["pose.pose.position.x"], a.pose.fields["pose.pose.position.y"]
            pa = np.column_stack([xa[w], ya[w]])
            pb = b.position_at(t)
            gap = np.hypot(*(pa - pb).T)
            nearest = min(nearest, float(gap.min()))
            over = gap < limits.distance_between_robots
            held = hold(t)
            violation += float(held[over].sum())
            topics += [a.topics["pose"], b.topics["pose"]]
            if over.any():
                mid = (pa[over] + pb[over]) / 2
                hotspots.extend(
                    Hotspot("distance_between_robots", Position(float(c[0]), float(c[1])), n, d)
                    for c, n, d in _cluster(mid, held[over])
                )
    if not np.isfinite(nearest):
        return []
    unique = tuple(dict.fromkeys(topics))
    return [
        MetricValue("distance_between_robots", MetricScope.MISSION, nearest, unique, unit="m"),
        MetricValue(
            "violation_duration",
            MetricScope.MISSION,
            violation,
            unique,
            unit="s",
            safety_metric="distance_between_robots",
        ),
    ]


_READ = {
    "pose": ("geometry_msgs/msg/PoseWithCovarianceStamped", ("pose.pose.position.x", "pose.pose.position.y")),
    "scan": ("sensor_msgs/msg/LaserScan", ("ranges", "range_min", "range_max")),
    "vel": ("geometry_msgs/msg/Twist", ("linear.x", "linear.y", "linear.z", "angular.z")),
    "distance": ("std_msgs/msg/Float64", ("data",)),
}
"""What the hand-written path reads of each of a robot's topics."""


def metrics_of_bag(path, scenario) -> tuple[list[MetricValue], list[Hotspot]]:  # type: ignore[no-untyped-def]
    """The hand-written path's values and hotspots for a bag of ``scenario``: the bag read with
    every field kept, the dispatcher's statuses segmented, then :func:`compute_metrics`."""
    from exsce_dsl.model.messages import path_of
    from exsce_dsl.runs.analyse import run_metrics, wanted_topics
    from exsce_dsl.runs.bags.data import OBJECTS, Wanted
    from exsce_dsl.runs.bags.reading import read_bag
    from exsce_dsl.runs.segments.dispatcher import SUCCEEDED, segments
    from exsce_dsl.runs.signals.dispatcher_statuses import dispatcher_statuses

    robots = [r for r in scenario.robots if r.start_pose is not None]
    wanted = wanted_topics(run_metrics(scenario), robots)
    for robot in robots:  # the method's topics, named here (the standard library reads signals)
        topics = robot_topics(robot.namespace)
        for key, (msgtype, names) in _READ.items():
            wanted[topics[key]] = Wanted(msgtype, tuple(path_of(*n.split(".")) for n in names))
        wanted[topics["feedback"]] = wanted[topics["result"]] = Wanted(OBJECTS)  # the dispatcher's goals
    data = read_bag(path, wanted)
    actions: list[RecordedAction] = []
    results: dict[str, int | None] = {}
    for robot in robots:
        statuses = dispatcher_statuses(robot.namespace, data)
        assert statuses.feedback is not None
        actions += segments(scenario, robot.id, statuses.feedback)
        final = statuses.result
        results[robot.id] = None if final is None else sum(s == SUCCEEDED for u in final for s in u.statuses)
    signals = [RobotSignals.from_bag(r.id, r.namespace, data) for r in robots]
    return compute_metrics(signals, actions, results, SafetyLimits(), [])
