"""The method's topics: what the method's executor and its waypoint dispatcher publish.

Per robot namespace (names from :data:`~exsce_dsl.model.conventions.METHOD_TOPICS`): the pose
(PoseWithCovarianceStamped, 50 Hz), velocity (Twist, 25 Hz), distance travelled (Float64, 10 Hz),
scan (LaserScan, 10 Hz) and the dispatcher's feedback and result (see :mod:`exsce_dsl.sim.messages`).
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np

from exsce_dsl.maps.planning import PlanningGrid
from exsce_dsl.model.conventions import METHOD_TOPICS
from exsce_dsl.model.metrics import expand_topic
from exsce_dsl.sim.batches import Batch, stamp_columns
from exsce_dsl.sim.executor import GoalStatus, SimulatedExecution
from exsce_dsl.sim.laser import Laser
from exsce_dsl.sim.messages import FEEDBACK, RESULT
from exsce_dsl.sim.scan import laser_scans
from exsce_dsl.sim.values import (
    header,
    header_at,
    heading_columns,
    planar_rotation,
    ros_time,
    sample_stamps,
    samples_per,
)
from exsce_dsl.sim.writing import Message, RobotRun

POSE_PERIOD, VEL_PERIOD, DIST_PERIOD = 0.02, 0.04, 0.1  # seconds: 50, 25 and 10 Hz
POSE_NOISE, YAW_NOISE = 0.005, 0.002


@dataclass(frozen=True)
class Topics:
    """The topic names of one robot namespace (the method's, from its convention)."""

    ns: str

    def _name(self, carries: str) -> str:
        """``/ns/topic``; ``/topic`` for a robot at the root (no namespace)."""
        return expand_topic(METHOD_TOPICS[carries], self.ns)

    @property
    def pose(self) -> str:
        return self._name("pose")

    @property
    def scan(self) -> str:
        return self._name("scan")

    @property
    def vel(self) -> str:
        return self._name("velocity")

    @property
    def distance(self) -> str:
        return self._name("distance")

    @property
    def feedback(self) -> str:
        return self._name("feedback")

    @property
    def result(self) -> str:
        return self._name("result")


def method_messages(run: RobotRun) -> Iterator[Message | Batch]:
    """Every message of one robot in the method's convention."""
    topics = Topics(run.namespace)
    yield from robot_messages(
        run.store, run.robot, topics, run.execution, run.grid, run.laser, run.rng, run.start_ns
    )
    yield from dispatcher_messages(run.store, run.robot, topics, run.execution, run.start_ns)


def robot_messages(
    store: Any,
    robot: str,
    topics: Topics,
    execution: SimulatedExecution,
    grid: PlanningGrid,
    laser: Laser,
    rng: np.random.Generator,
    start_ns: int,
) -> Iterator[Message | Batch]:
    tr = execution.trajectories[robot]
    n = len(tr)
    stamps = sample_stamps(start_ns, n, execution.dt)
    T = store.types
    # robot_pose: PoseWithCovarianceStamped, with measurement noise
    px = tr.x + rng.normal(0, POSE_NOISE, n)
    py = tr.y + rng.normal(0, POSE_NOISE, n)
    pyaw = tr.yaw + rng.normal(0, YAW_NOISE, n)
    covariance = np.zeros(36)
    covariance[[0, 7, 35]] = [POSE_NOISE**2, POSE_NOISE**2, YAW_NOISE**2]
    pose_type = "geometry_msgs/msg/PoseWithCovarianceStamped"

    def robot_pose(sec: int, nanosec: int, seq: int, x: float, y: float, qz: float, qw: float) -> Any:
        pose = T["geometry_msgs/msg/Pose"](
            position=T["geometry_msgs/msg/Point"](x=x, y=y, z=0.0), orientation=planar_rotation(store, qz, qw)
        )
        return T[pose_type](
            header=header_at(store, sec, nanosec, "map", seq),
            pose=T["geometry_msgs/msg/PoseWithCovariance"](pose=pose, covariance=covariance),
        )

    at = np.arange(0, n, samples_per(POSE_PERIOD, execution.dt))
    yield Batch(
        topics.pose,
        pose_type,
        stamps[at],
        robot_pose,
        {
            **stamp_columns(stamps[at]),
            "seq": at.astype("<u4"),
            "x": px[at],
            "y": py[at],
            **heading_columns(pyaw[at]),
        },
    )
    # nav_vel: Twist (the command the robot follows)

    def velocity(v: float, w: float) -> Any:
        return T["geometry_msgs/msg/Twist"](
            linear=T["geometry_msgs/msg/Vector3"](x=v, y=0.0, z=0.0),
            angular=T["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=w),
        )

    at = np.arange(0, n, samples_per(VEL_PERIOD, execution.dt))
    yield Batch(topics.vel, "geometry_msgs/msg/Twist", stamps[at], velocity, {"v": tr.v[at], "w": tr.w[at]})
    # distance_travelled: Float64, cumulative
    step = np.concatenate([[0.0], np.hypot(np.diff(tr.x), np.diff(tr.y))])
    travelled = np.cumsum(step)
    at = np.arange(0, n, samples_per(DIST_PERIOD, execution.dt))
    yield Batch(
        topics.distance,
        "std_msgs/msg/Float64",
        stamps[at],
        lambda data: T["std_msgs/msg/Float64"](data=data),
        {"data": travelled[at]},
    )
    # scan: LaserScan against the map and the other robots
    yield from laser_scans(
        store, topics.scan, f"{topics.ns}/base_laser_link", robot, execution, grid, laser, rng, stamps
    )


def dispatcher_messages(
    store: Any, robot: str, topics: Topics, execution: SimulatedExecution, start_ns: int
) -> Iterator[Message]:
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
                    stamp=ros_time(store, last_change[(event.goal_key, i)]), id=wid
                ),
                status=int(s),
                text="",
            )
            for i, (wid, s) in enumerate(zip(event.waypoint_ids, event.statuses, strict=True))
        ]
        array = T["actionlib_msgs/msg/GoalStatusArray"](
            header=header(store, stamp, "map", seq), status_list=status_list
        )
        failed = any(s == GoalStatus.ABORTED for s in event.statuses)
        goal_state = (
            GoalStatus.ABORTED
            if failed and event.final
            else (GoalStatus.SUCCEEDED if event.final else GoalStatus.ACTIVE)
        )
        goal = T["actionlib_msgs/msg/GoalStatus"](
            goal_id=T["actionlib_msgs/msg/GoalID"](stamp=ros_time(store, stamp), id=event.goal_key),
            status=int(goal_state),
            text="",
        )
        feedback = T[FEEDBACK](
            header=header(store, stamp, "map", seq),
            status=goal,
            feedback=T["waypoint_dispatcher/msg/FollowWaypointsFeedback"](goal_status=array),
        )
        yield topics.feedback, FEEDBACK, stamp, feedback
        if event.final:
            result = T[RESULT](
                header=header(store, stamp, "map", seq),
                status=goal,
                result=T["waypoint_dispatcher/msg/FollowWaypointsResult"](goal_status=array),
            )
            yield topics.result, RESULT, stamp, result
        seq += 1
