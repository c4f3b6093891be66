"""Bags of the shapes real users bring (issue 32), written with rosbags' writers in every format.

Each shape is what a kind of robot or data set records, with nothing of the method's topics:

- ``jackal``: a Clearpath Jackal driven outdoors (ROS 1 style): odometry on
  ``/jackal_velocity_controller/odom``, commands on ``/cmd_vel`` (Twist), an IMU; no goals, no TF;
- ``kitti``: a KITTI-like sequence: ground truth and two visual odometries (``groundtruth``,
  ``ORB-SLAM``, ``DSO``), PoseStamped under relative names; the odometries start late (they
  initialise) and drift;
- ``tf_only``: TF and nothing else: ``map → odom`` (a localiser, 10 Hz, drifting), ``odom →
  base_link`` (30 Hz) on ``/tf``, ``base_link → base_laser_link`` on ``/tf_static``;
- ``namespaced``: one PoseStamped stream under ``/scout``, its header stamps in simulated time
  (a Gazebo world's 120 s) and log times on the wall clock, without ``/clock``; header-less
  Float32 topics beside it (a reported speed during the drive, a battery voltage only before
  the robot set off);
- ``drone``: a drone's PoseStamped (``/mavros/local_position/pose``) climbing 12 m as it flies.

The robots follow one :class:`Route` (rest, two straight legs at two speeds, rest), sampled at
each topic's rate; the test computes every reference value again from rosbags' deserialisation
of the written bag, never from this module's numbers.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from tests.support.bag_factory import (
    IMU,
    ODOMETRY,
    POSE_STAMPED,
    START_NS,
    TF_MESSAGE,
    Topic,
    header,
    imu,
    point,
    quaternion,
    vector3,
)

TWIST = "geometry_msgs/msg/Twist"
FLOAT32 = "std_msgs/msg/Float32"
DURATION = 18.0
"""Seconds every recording lasts."""
SIM_START = 120.0
"""Simulated seconds at the first message of the ``namespaced`` shape (its header stamps)."""
LATENCY = 0.013
"""Seconds from a ``namespaced`` message's stamp to its log time (beside the clocks' offset)."""


@dataclass(frozen=True)
class Route:
    """Where the robot is at each time (seconds from the first message): corners ``(x, y, z)``
    driven in straight legs at ``speeds`` (m/s, in the plane), after ``rest`` seconds standing
    at the first, standing at the last until :data:`DURATION`."""

    corners: Sequence[tuple[float, float, float]]
    speeds: Sequence[float]
    rest: float = 2.0

    def keyframes(self) -> np.ndarray:
        times = [0.0, self.rest]
        for (x0, y0, _), (x1, y1, _), speed in zip(
            self.corners[:-1], self.corners[1:], self.speeds, strict=True
        ):
            times.append(times[-1] + float(np.hypot(x1 - x0, y1 - y0)) / speed)
        times.append(DURATION)
        return np.array(times)

    def at(self, t: np.ndarray) -> dict[str, np.ndarray]:
        """``x``, ``y``, ``z``, ``yaw`` (the heading of the leg driven, or last driven) and
        ``speed`` (the leg's speed, 0 standing) at times ``t``."""
        frames = self.keyframes()
        corners = np.array([self.corners[0], *self.corners, self.corners[-1]])
        found = {a: np.interp(t, frames, corners[:, k]) for k, a in enumerate("xyz")}
        legs = np.diff(np.array(self.corners), axis=0)
        headings = np.arctan2(legs[:, 1], legs[:, 0])
        leg = np.clip(np.searchsorted(frames, t, side="right") - 2, 0, len(legs) - 1)
        found["yaw"] = headings[leg]
        moving = (t > frames[1]) & (t < frames[-2])
        found["speed"] = np.where(moving, np.asarray(self.speeds)[leg], 0.0)
        return found


ROUTE = Route([(0.0, 0.0, 0.0), (8.0, 0.0, 0.0), (8.0, 6.0, 0.0)], [1.2, 0.8])
"""Through the field's poses ``field-1`` (8, 0) and ``field-2`` (8, 6) from ``field-start``."""
CLIMB = Route([(0.0, 0.0, 0.0), (8.0, 0.0, 6.0), (8.0, 6.0, 12.0)], [1.2, 0.8])
"""The drone's: the same legs in the plane, climbing 12 m."""


def times(hz: float, start: float = 0.0, end: float = DURATION) -> np.ndarray:
    """Seconds from ``start`` to ``end`` (both included) at ``hz``."""
    return start + np.arange(int(round((end - start) * hz)) + 1) / hz


def ns_of(seconds: float) -> int:
    """Wall-clock log time (ns) of a time in seconds from the first message."""
    return START_NS + int(round(seconds * 1e9))


def _stamped_pose(
    store: Any, msgtype: str, stamp_ns: int, frame: str, index: int, where: Sequence[float]
) -> Any:
    x, y, z, yaw = (float(v) for v in where[:4])
    body = store.types["geometry_msgs/msg/Pose"](
        position=point(store, (x, y, z)), orientation=quaternion(store, yaw)
    )
    if msgtype == POSE_STAMPED:
        return store.types[POSE_STAMPED](header=header(store, stamp_ns, frame, index), pose=body)
    t = store.types
    return t[ODOMETRY](
        header=header(store, stamp_ns, frame, index),
        child_frame_id="base_link",
        pose=t["geometry_msgs/msg/PoseWithCovariance"](pose=body, covariance=np.zeros(36)),
        twist=t["geometry_msgs/msg/TwistWithCovariance"](
            twist=twist(store, where[4] if len(where) > 4 else 0.0), covariance=np.zeros(36)
        ),
    )


def twist(store: Any, forward: float, turn: float = 0.0) -> Any:
    return store.types[TWIST](
        linear=vector3(store, (forward, 0.0, 0.0)), angular=vector3(store, (0.0, 0.0, turn))
    )


def pose_topic(
    store: Any,
    name: str,
    msgtype: str,
    route: Route,
    hz: float,
    start: float = 0.0,
    end: float = DURATION,
    noise: float = 0.0,
    scale: float = 1.0,
    seed: int = 0,
    stamp: Callable[[float], int] = ns_of,
    log: Callable[[float], int] = ns_of,
    frame: str = "map",
) -> Topic:
    """A pose topic along ``route`` (``noise``: metres of Gaussian noise per axis, ``scale``:
    a visual odometry's scale error); header stamps from ``stamp``, log times from ``log``."""
    t = times(hz, start, end)
    at = route.at(t)
    rng = np.random.default_rng(seed)
    shaken = {a: at[a] * scale + (rng.normal(0, noise, len(t)) if noise else 0.0) for a in "xyz"}
    return Topic(
        name,
        msgtype,
        [
            (
                log(s),
                _stamped_pose(
                    store,
                    msgtype,
                    stamp(s),
                    frame,
                    i,
                    (shaken["x"][i], shaken["y"][i], shaken["z"][i], at["yaw"][i], at["speed"][i]),
                ),
            )
            for i, s in enumerate(t)
        ],
    )


def jackal(store: Any) -> list[Topic]:
    t = times(10.0, 1.0, 17.0)
    speed = ROUTE.at(t)["speed"]
    return [
        pose_topic(store, "/jackal_velocity_controller/odom", ODOMETRY, ROUTE, 20.0, frame="odom"),
        Topic(
            "/cmd_vel",
            TWIST,
            [(ns_of(s), twist(store, v * 1.05, 0.1)) for s, v in zip(t, speed, strict=True)],
        ),
        Topic("/imu/data", IMU, [(ns_of(i * 0.2), imu(store, i, ns_of(i * 0.2))) for i in range(80)]),
    ]


def kitti(store: Any) -> list[Topic]:
    return [
        pose_topic(store, "groundtruth", POSE_STAMPED, ROUTE, 10.0, frame="world"),
        pose_topic(
            store, "ORB-SLAM", POSE_STAMPED, ROUTE, 10.0, 1.0, 17.5, 0.02, 0.97, seed=1, frame="world"
        ),
        pose_topic(store, "DSO", POSE_STAMPED, ROUTE, 10.0, 0.5, 17.8, 0.03, 1.02, seed=2, frame="world"),
    ]


MAP_TO_ODOM_YAW = 0.2
"""The localiser's correction turns the odometry frame by this (radians), and shifts it by
:func:`map_to_odom_shift` (metres, drifting linearly in time)."""


def map_to_odom_shift(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return 0.5 + 0.01 * t, -0.3 + 0.005 * t


def transform_stamped(store: Any, stamp_ns: int, parent: str, child: str, x: float, y: float, yaw: float) -> Any:
    t = store.types
    return t["geometry_msgs/msg/TransformStamped"](
        header=header(store, stamp_ns, parent),
        child_frame_id=child,
        transform=t["geometry_msgs/msg/Transform"](
            translation=vector3(store, (x, y, 0.0)), rotation=quaternion(store, yaw)
        ),
    )


def tf_only(store: Any) -> list[Topic]:
    """``map → odom`` at 10 Hz and ``odom → base_link`` at 30 Hz on ``/tf``, one laser mount on
    ``/tf_static``: ``map → odom → base_link`` is :data:`ROUTE`."""
    messages = []
    slow = times(10.0)
    dx, dy = map_to_odom_shift(slow)
    for s, x, y in zip(slow, dx, dy, strict=True):
        moved = transform_stamped(store, ns_of(s), "map", "odom", x, y, MAP_TO_ODOM_YAW)
        messages.append((ns_of(s), store.types[TF_MESSAGE](transforms=[moved])))
    fast = times(30.0)
    at = ROUTE.at(fast)
    ox, oy = map_to_odom_shift(fast)
    c, s_ = np.cos(-MAP_TO_ODOM_YAW), np.sin(-MAP_TO_ODOM_YAW)
    bx = c * (at["x"] - ox) - s_ * (at["y"] - oy)
    by = s_ * (at["x"] - ox) + c * (at["y"] - oy)
    for i, s in enumerate(fast):
        moved = transform_stamped(store, ns_of(s), "odom", "base_link", bx[i], by[i], at["yaw"][i] - MAP_TO_ODOM_YAW)
        messages.append((ns_of(s), store.types[TF_MESSAGE](transforms=[moved])))
    messages.sort(key=lambda m: m[0])
    mount = transform_stamped(store, ns_of(0.0), "base_link", "base_laser_link", 0.2, 0.0, 0.0)
    return [
        Topic("/tf", TF_MESSAGE, messages),
        Topic("/tf_static", TF_MESSAGE, [(ns_of(0.0), store.types[TF_MESSAGE](transforms=[mount]))]),
    ]


def sim_stamp(seconds: float) -> int:
    """A ``namespaced`` header stamp (ns of simulated time)."""
    return int(round((SIM_START + seconds) * 1e9))


def wall_log(seconds: float) -> int:
    return ns_of(seconds + LATENCY)


def namespaced(store: Any) -> list[Topic]:
    speed_times = times(5.0, 2.5, 14.0)
    speeds = ROUTE.at(speed_times)["speed"]
    float32 = store.types[FLOAT32]
    return [
        pose_topic(store, "/scout/pose", POSE_STAMPED, ROUTE, 20.0, stamp=sim_stamp, log=wall_log),
        Topic(
            "/scout/speed",
            FLOAT32,
            [(wall_log(s), float32(data=float(v))) for s, v in zip(speed_times, speeds, strict=True)],
        ),
        Topic(
            "/scout/battery", FLOAT32, [(wall_log(s), float32(data=24.0 - s)) for s in times(5.0, 0.0, 1.5)]
        ),
    ]


def drone(store: Any) -> list[Topic]:
    return [pose_topic(store, "/mavros/local_position/pose", POSE_STAMPED, CLIMB, 30.0, frame="map")]


SHAPES: dict[str, Callable[[Any], list[Topic]]] = {
    "jackal": jackal,
    "kitti": kitti,
    "tf_only": tf_only,
    "namespaced": namespaced,
    "drone": drone,
}
"""Shape name → its topics, made with a format's typestore."""
