"""What a navigation stack's robot publishes about itself, Nav2 and move_base alike.

Per robot namespace (the root for ``""``):

| topic | type | rate |
|---|---|---|
| ``tf`` | tf2_msgs/TFMessage: ``odom → base_link`` | 50 Hz (odometry) |
| ``tf`` | tf2_msgs/TFMessage: ``map → odom`` | 10 Hz (the localiser) |
| ``tf`` | tf2_msgs/TFMessage: ``base_link →`` both wheels and the caster | 100 Hz (robot_state_publisher) |
| ``tf_static`` | ``base_link → base_footprint``, ``base_link → base_laser_link`` | once, latched |
| ``odom`` | nav_msgs/Odometry (odometry's pose, body twist) | 50 Hz |
| ``amcl_pose`` | geometry_msgs/PoseWithCovarianceStamped (the estimate) | 2 Hz |
| ``cmd_vel`` | geometry_msgs/Twist, or TwistStamped | 20 Hz (the controller's rate) |
| ``scan`` | sensor_msgs/LaserScan | 10 Hz |

Frames are plain (``map``, ``odom``, ``base_link``): each robot's TF is on its own namespaced
``tf`` topic, as Nav2's multi-robot bringup remaps it, so frame names need no prefix.  The wheels'
transforms are off the map → base_link chain, as a real robot's joints are: a reader of the pose
must step over them.  See :mod:`exsce_dsl.sim.localisation` for the odometry's drift and the
estimate's noise.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from typing import Any

import numpy as np

from exsce_dsl.sim.batches import Batch, stamp_columns
from exsce_dsl.sim.localisation import LOCALISATION_NOISE, LOCALISATION_YAW_NOISE, Localisation
from exsce_dsl.sim.scan import laser_scans
from exsce_dsl.sim.values import (
    header,
    header_at,
    heading_columns,
    planar_rotation,
    pose,
    samples_per,
    transform,
    transform_at,
    twist,
)
from exsce_dsl.sim.writing import Message, RobotRun

MAP, ODOM, BASE, FOOTPRINT, LASER = "map", "odom", "base_link", "base_footprint", "base_laser_link"
ODOM_PERIOD, CORRECTION_PERIOD, AMCL_PERIOD = 0.02, 0.1, 0.5  # seconds: 50, 10, 2 Hz (at most the run's rate)
CMD_VEL_PERIOD_NS = 50_000_000  # 20 Hz: Nav2's default controller_frequency
FOOTPRINT_HEIGHT = 0.1  # base_footprint: on the floor, below base_link
LASER_HEIGHT = 0.2  # base_laser_link: above base_link's origin, where the executor's scans start
JOINTS_PERIOD = 0.01  # robot_state_publisher at 100 Hz
WHEELS = (
    ("wheel_left_link", 0.0, 0.2, 0.0985),
    ("wheel_right_link", 0.0, -0.2, 0.0985),
    ("caster_back_link", -0.2, 0.0, 0.025),
)
"""Each wheel's frame, its axle's place in base_link (x, y metres) and its radius (metres; TIAGo's)."""
TF_STATIC = "tf_static"
"""The latched topic (ROS 1 latching, ROS 2 transient-local durability)."""

ODOM_COVARIANCE = np.diag([1e-3, 1e-3, 1e6, 1e6, 1e6, 1e-3]).ravel()
TWIST_COVARIANCE = np.diag([1e-3, 1e-3, 1e6, 1e6, 1e6, 1e-3]).ravel()
AMCL_COVARIANCE = np.diag(
    [LOCALISATION_NOISE**2, LOCALISATION_NOISE**2, 0.0, 0.0, 0.0, LOCALISATION_YAW_NOISE**2]
).ravel()


def stack_messages(run: RobotRun, frames: Localisation, stamps: np.ndarray) -> Iterator[Message | Batch]:
    """TF, odometry, AMCL's pose, velocity commands and scans of one robot."""
    yield from _tf(run, frames, stamps)
    yield _odometry(run, frames, stamps)
    yield from _amcl_pose(run, frames, stamps)
    yield from _cmd_vel(run, stamps)
    yield from laser_scans(
        run.store, run.topic("scan"), LASER, run.robot, run.execution, run.grid, run.laser, run.rng, stamps
    )


def _tf(run: RobotRun, frames: Localisation, stamps: np.ndarray) -> Iterator[Message | Batch]:
    T, store = run.store.types, run.store
    tf, kind = run.topic("tf"), "tf2_msgs/msg/TFMessage"
    static = [
        transform(store, int(stamps[0]), BASE, FOOTPRINT, 0.0, 0.0, 0.0, -FOOTPRINT_HEIGHT),
        transform(store, int(stamps[0]), BASE, LASER, 0.0, 0.0, 0.0, LASER_HEIGHT),
    ]
    yield run.topic(TF_STATIC), kind, int(stamps[0]), T[kind](transforms=static)
    for parent, child, poses, every in (
        (ODOM, BASE, frames.odom, samples_per(ODOM_PERIOD, run.execution.dt)),
        (MAP, ODOM, frames.correction, samples_per(CORRECTION_PERIOD, run.execution.dt)),
    ):

        def moved(
            sec: int,
            nanosec: int,
            x: float,
            y: float,
            qz: float,
            qw: float,
            parent: str = parent,
            child: str = child,
        ) -> Any:
            rotation = planar_rotation(store, qz, qw)
            return T[kind](transforms=[transform_at(store, sec, nanosec, parent, child, x, y, rotation)])

        at = np.arange(0, len(stamps), every)
        columns = {
            **stamp_columns(stamps[at]),
            "x": poses.x[at],
            "y": poses.y[at],
            **heading_columns(poses.yaw[at]),
        }
        yield Batch(tf, kind, stamps[at], moved, columns)
    yield _joints(run, frames, stamps)


def _joints(run: RobotRun, frames: Localisation, stamps: np.ndarray) -> Batch:
    """robot_state_publisher's moving joints: each wheel turned about its axle (y) by the distance its
    contact point rolled, at twice the clock's rate (angles interpolated between samples)."""
    T, store = run.store.types, run.store
    kind = "tf2_msgs/msg/TFMessage"
    per_sample = samples_per(run.execution.dt, JOINTS_PERIOD)  # joint states between two samples
    times = np.arange(len(stamps) * per_sample) / per_sample
    joint_stamps = np.interp(times, np.arange(len(stamps)), stamps.astype(float)).astype(np.int64)
    columns = stamp_columns(joint_stamps)
    for number, (_, _, y, radius) in enumerate(WHEELS):
        speed = frames.v - frames.w * y  # the wheel's forward speed: the body's, less the turn's share
        rolled = np.concatenate([[0.0], np.cumsum(speed[:-1] * run.execution.dt)])
        half = (np.interp(times, np.arange(len(stamps)), rolled / radius) / 2).tolist()
        columns[f"sin{number}"] = np.array([math.sin(a) for a in half], dtype="<f8")
        columns[f"cos{number}"] = np.array([math.cos(a) for a in half], dtype="<f8")

    def turned(sec: int, nanosec: int, **halves: float) -> Any:
        transforms = [
            transform_at(
                store,
                sec,
                nanosec,
                BASE,
                child,
                x,
                y,
                T["geometry_msgs/msg/Quaternion"](x=0.0, y=halves[f"sin{n}"], z=0.0, w=halves[f"cos{n}"]),
            )
            for n, (child, x, y, _) in enumerate(WHEELS)
        ]
        return T[kind](transforms=transforms)

    return Batch(run.topic("tf"), kind, joint_stamps, turned, columns)


def _odometry(run: RobotRun, frames: Localisation, stamps: np.ndarray) -> Batch:
    T, store = run.store.types, run.store
    kind = "nav_msgs/msg/Odometry"
    odom = frames.odom

    def odometry(
        sec: int, nanosec: int, seq: int, x: float, y: float, qz: float, qw: float, v: float, w: float
    ) -> Any:
        pose = T["geometry_msgs/msg/Pose"](
            position=T["geometry_msgs/msg/Point"](x=x, y=y, z=0.0), orientation=planar_rotation(store, qz, qw)
        )
        return T[kind](
            header=header_at(store, sec, nanosec, ODOM, seq),
            child_frame_id=BASE,
            pose=T["geometry_msgs/msg/PoseWithCovariance"](pose=pose, covariance=ODOM_COVARIANCE),
            twist=T["geometry_msgs/msg/TwistWithCovariance"](
                twist=twist(store, v, w), covariance=TWIST_COVARIANCE
            ),
        )

    at = np.arange(0, len(stamps), samples_per(ODOM_PERIOD, run.execution.dt))
    columns = {
        **stamp_columns(stamps[at]),
        "seq": np.arange(len(at)).astype("<u4"),
        "x": odom.x[at],
        "y": odom.y[at],
        **heading_columns(odom.yaw[at]),
        "v": frames.v[at],
        "w": frames.w[at],
    }
    return Batch(run.topic("odom"), kind, stamps[at], odometry, columns)


def _amcl_pose(run: RobotRun, frames: Localisation, stamps: np.ndarray) -> Iterator[Message]:
    T, store = run.store.types, run.store
    kind = "geometry_msgs/msg/PoseWithCovarianceStamped"
    estimate = frames.estimate
    for seq, i in enumerate(range(0, len(stamps), samples_per(AMCL_PERIOD, run.execution.dt))):
        msg = T[kind](
            header=header(store, int(stamps[i]), MAP, seq),
            pose=T["geometry_msgs/msg/PoseWithCovariance"](
                pose=pose(store, estimate.x[i], estimate.y[i], estimate.yaw[i]), covariance=AMCL_COVARIANCE
            ),
        )
        yield run.topic("amcl_pose"), kind, int(stamps[i]), msg


def _cmd_vel(run: RobotRun, stamps: np.ndarray) -> Iterator[Message]:
    """The controller's commands on its own 20 Hz clock: the executor's speed at that moment."""
    T, store = run.store.types, run.store
    tr = run.execution.trajectories[run.robot]
    start, end = int(stamps[0]), int(stamps[-1])
    for seq, stamp in enumerate(range(start, end + 1, CMD_VEL_PERIOD_NS)):
        i = min(int(np.searchsorted(stamps, stamp, side="right")) - 1, len(stamps) - 1)
        command = twist(store, tr.v[i], tr.w[i])
        if run.twist_stamped:
            kind = "geometry_msgs/msg/TwistStamped"
            yield (
                run.topic("cmd_vel"),
                kind,
                stamp,
                T[kind](header=header(store, stamp, BASE, seq), twist=command),
            )
        else:
            yield run.topic("cmd_vel"), "geometry_msgs/msg/Twist", stamp, command
