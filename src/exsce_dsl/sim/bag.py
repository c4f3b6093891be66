"""Write an execution as a real bag (ROS 1, ROS 2 sqlite3 or MCAP) with rosbags."""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from rosbags.rosbag1 import Writer as Ros1Writer
from rosbags.rosbag2 import StoragePlugin
from rosbags.rosbag2 import Writer as Ros2Writer

from exsce_dsl.model import Scenario
from exsce_dsl.sim.executor import Execution, GoalStatus
from exsce_dsl.sim.messages import FEEDBACK, RESULT, typestore
from exsce_dsl.sim.motion import DT
from exsce_dsl.sim.planner import PlanningGrid
from exsce_dsl.sim.scan import Laser, scan_ranges

POSE_EVERY, VEL_EVERY, DIST_EVERY, SCAN_EVERY = 1, 2, 5, 5  # samples of the 50 Hz clock
POSE_NOISE, YAW_NOISE = 0.005, 0.002
ROBOT_RADIUS = 0.3


@dataclass(frozen=True)
class Topics:
    """The topic names of one robot namespace (the method's defaults)."""

    ns: str

    def __getattr__(self, name: str) -> str:  # pragma: no cover - only the names below are used
        raise AttributeError(name)

    def _name(self, topic: str) -> str:
        """``/ns/topic``; ``/topic`` for a robot at the root (no namespace)."""
        return f"/{self.ns}/{topic}" if self.ns else f"/{topic}"

    @property
    def pose(self) -> str:
        return self._name("robot_pose")

    @property
    def scan(self) -> str:
        return self._name("scan")

    @property
    def vel(self) -> str:
        return self._name("nav_vel")

    @property
    def distance(self) -> str:
        return self._name("distance_travelled")

    @property
    def feedback(self) -> str:
        return self._name("waypoint_dispatcher/feedback")

    @property
    def result(self) -> str:
        return self._name("waypoint_dispatcher/result")


def write_bag(
    path: Path,
    fmt: str,
    scenario: Scenario,
    execution: Execution,
    grid: PlanningGrid,
    start_ns: int,
    seed: int,
    laser: Laser | None = None,
) -> int:
    """Write the bag; return the number of messages."""
    laser = laser or Laser()
    store = typestore(fmt)
    rng = np.random.default_rng(seed)
    messages: list[tuple[int, int, str, Any]] = []  # (time, order, topic, message)
    types: dict[str, str] = {}
    robots = [r for r in scenario.robots if r.id in execution.trajectories]
    for order, robot in enumerate(robots):
        topics = Topics(robot.namespace.strip("/"))
        for topic, msgtype, stamp, msg in _robot_messages(
            store, robot.id, topics, execution, grid, laser, rng, start_ns
        ):
            types[topic] = msgtype
            messages.append((stamp, order, topic, msg))
        for topic, msgtype, stamp, msg in _dispatcher_messages(store, robot.id, topics, execution, start_ns):
            types[topic] = msgtype
            messages.append((stamp, order, topic, msg))
    messages.sort(key=lambda m: (m[0], m[1], m[2]))
    serialize = store.serialize_ros1 if fmt == "ros1" else store.serialize_cdr
    if fmt == "ros1":
        with Ros1Writer(path) as writer:
            connections = {t: writer.add_connection(t, types[t], typestore=store) for t in sorted(types)}
            for stamp, _, topic, msg in messages:
                writer.write(connections[topic], stamp, serialize(msg, types[topic]))
    else:
        plugin = StoragePlugin.MCAP if fmt == "mcap" else StoragePlugin.SQLITE3
        with Ros2Writer(path, version=8, storage_plugin=plugin) as writer2:
            conns = {t: writer2.add_connection(t, types[t], typestore=store) for t in sorted(types)}
            for stamp, _, topic, msg in messages:
                writer2.write(conns[topic], stamp, serialize(msg, types[topic]))
    return len(messages)


def _time(store: Any, ns: int) -> Any:
    return store.types["builtin_interfaces/msg/Time"](sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)


def _header(store: Any, ns: int, frame: str, seq: int = 0) -> Any:
    header = store.types["std_msgs/msg/Header"]
    if "seq" in header.__dataclass_fields__:
        return header(seq=seq, stamp=_time(store, ns), frame_id=frame)
    return header(stamp=_time(store, ns), frame_id=frame)


def _quaternion(store: Any, yaw: float) -> Any:
    return store.types["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2))


def _robot_messages(
    store: Any,
    robot: str,
    topics: Topics,
    execution: Execution,
    grid: PlanningGrid,
    laser: Laser,
    rng: np.random.Generator,
    start_ns: int,
) -> Iterator[tuple[str, str, int, Any]]:
    tr = execution.trajectories[robot]
    n = len(tr)
    stamps = start_ns + (np.arange(n) * DT * 1e9).astype(np.int64)
    T = store.types
    # robot_pose: PoseWithCovarianceStamped, with measurement noise
    px = tr.x + rng.normal(0, POSE_NOISE, n)
    py = tr.y + rng.normal(0, POSE_NOISE, n)
    pyaw = tr.yaw + rng.normal(0, YAW_NOISE, n)
    covariance = np.zeros(36)
    covariance[[0, 7, 35]] = [POSE_NOISE**2, POSE_NOISE**2, YAW_NOISE**2]
    pose_type = "geometry_msgs/msg/PoseWithCovarianceStamped"
    for i in range(0, n, POSE_EVERY):
        pose = T["geometry_msgs/msg/Pose"](
            position=T["geometry_msgs/msg/Point"](x=float(px[i]), y=float(py[i]), z=0.0),
            orientation=_quaternion(store, float(pyaw[i])),
        )
        msg = T[pose_type](
            header=_header(store, int(stamps[i]), "map", i),
            pose=T["geometry_msgs/msg/PoseWithCovariance"](pose=pose, covariance=covariance),
        )
        yield topics.pose, pose_type, int(stamps[i]), msg
    # nav_vel: Twist (the command the robot follows)
    for i in range(0, n, VEL_EVERY):
        msg = T["geometry_msgs/msg/Twist"](
            linear=T["geometry_msgs/msg/Vector3"](x=float(tr.v[i]), y=0.0, z=0.0),
            angular=T["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=float(tr.w[i])),
        )
        yield topics.vel, "geometry_msgs/msg/Twist", int(stamps[i]), msg
    # distance_travelled: Float64, cumulative
    step = np.concatenate([[0.0], np.hypot(np.diff(tr.x), np.diff(tr.y))])
    travelled = np.cumsum(step)
    for i in range(0, n, DIST_EVERY):
        yield (
            topics.distance,
            "std_msgs/msg/Float64",
            int(stamps[i]),
            T["std_msgs/msg/Float64"](data=float(travelled[i])),
        )
    # scan: LaserScan against the map and the other robots
    idx = np.arange(0, n, SCAN_EVERY)
    others = [(o.x[idx], o.y[idx]) for r, o in execution.trajectories.items() if r != robot]
    ranges = scan_ranges(grid, laser, tr.x[idx], tr.y[idx], tr.yaw[idx], others, ROBOT_RADIUS, rng)
    empty = np.zeros(0, dtype=np.float32)
    for k, i in enumerate(idx.tolist()):
        msg = T["sensor_msgs/msg/LaserScan"](
            header=_header(store, int(stamps[i]), f"{topics.ns}/base_laser_link", k),
            angle_min=laser.angle_min,
            angle_max=laser.angle_max,
            angle_increment=laser.angle_increment,
            time_increment=0.0,
            scan_time=SCAN_EVERY * DT,
            range_min=laser.range_min,
            range_max=laser.range_max,
            ranges=ranges[k],
            intensities=empty,
        )
        yield topics.scan, "sensor_msgs/msg/LaserScan", int(stamps[i]), msg


def _dispatcher_messages(
    store: Any, robot: str, topics: Topics, execution: Execution, start_ns: int
) -> Iterator[tuple[str, str, int, Any]]:
    T = store.types
    last_change: dict[tuple[str, int], int] = {}
    previous: dict[str, tuple[GoalStatus, ...]] = {}
    seq = 0
    for event in execution.events:
        if event.robot != robot:
            continue
        stamp = start_ns + int(round(event.t * 1e9))
        before = previous.get(event.goal_key)
        for i, status in enumerate(event.statuses):
            if before is None or before[i] != status:
                last_change[(event.goal_key, i)] = stamp
        previous[event.goal_key] = event.statuses
        status_list = [
            T["actionlib_msgs/msg/GoalStatus"](
                goal_id=T["actionlib_msgs/msg/GoalID"](
                    stamp=_time(store, last_change[(event.goal_key, i)]), id=wid
                ),
                status=int(s),
                text="",
            )
            for i, (wid, s) in enumerate(zip(event.waypoint_ids, event.statuses, strict=True))
        ]
        array = T["actionlib_msgs/msg/GoalStatusArray"](
            header=_header(store, stamp, "map", seq), status_list=status_list
        )
        failed = any(s == GoalStatus.ABORTED for s in event.statuses)
        goal_state = (
            GoalStatus.ABORTED
            if failed and event.final
            else (GoalStatus.SUCCEEDED if event.final else GoalStatus.ACTIVE)
        )
        goal = T["actionlib_msgs/msg/GoalStatus"](
            goal_id=T["actionlib_msgs/msg/GoalID"](stamp=_time(store, stamp), id=event.goal_key),
            status=int(goal_state),
            text="",
        )
        feedback = T[FEEDBACK](
            header=_header(store, stamp, "map", seq),
            status=goal,
            feedback=T["waypoint_dispatcher/msg/FollowWaypointsFeedback"](goal_status=array),
        )
        yield topics.feedback, FEEDBACK, stamp, feedback
        if event.final:
            result = T[RESULT](
                header=_header(store, stamp, "map", seq),
                status=goal,
                result=T["waypoint_dispatcher/msg/FollowWaypointsResult"](goal_status=array),
            )
            yield topics.result, RESULT, stamp, result
        seq += 1
