"""What a stand-in robot publishes on ROS 2, sample by sample: Nav2's topics as a Nav2 robot has them.

Per robot namespace (``/{ns}/...``): ``odom`` (nav_msgs/Odometry, ``odom → base_link``), ``tf``
(``odom → base_link`` every sample, ``map → odom`` every :data:`CORRECTION_EVERY`), ``tf_static``
(``base_link → base_footprint``, ``base_link → base_laser_link``; transient local), ``amcl_pose``,
``cmd_vel`` (geometry_msgs/Twist at 20 Hz: Jazzy's Nav2 default, ``enable_stamped_cmd_vel``
false) and ``scan``.  The rates and frames are those of the ROS 1 stand-in node
(``execute/ros1/nodes/stand_in_node.py``), so that a run reads the same on either graph.  A row
of a leg holds :data:`~exsce_dsl.execute.stand_in.legs.FIELDS` values: odometry x, y, yaw;
estimate x, y, yaw; correction x, y, yaw; measured v, w; commanded v, w.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from types import ModuleType
from typing import Any

import numpy as np

from exsce_dsl.sim.laser import SCAN_EVERY, Laser

DT_NS = 20_000_000
"""The 50 Hz sample clock."""
STATIC_EVERY, CORRECTION_EVERY, AMCL_EVERY, FEEDBACK_EVERY = 50, 5, 25, 10
"""Samples between two: ``tf_static`` (1 Hz), ``map → odom`` (10 Hz), ``amcl_pose`` (2 Hz),
feedback (5 Hz)."""
CMD_VEL_PERIOD_NS = 50_000_000
"""20 Hz."""
PLAN_SPACING = 0.05
"""Metres between two poses of a published global plan (a grid planner's cell)."""
LOCALISATION_NOISE, LOCALISATION_YAW_NOISE = 0.02, 0.01
FOOTPRINT_HEIGHT, LASER_HEIGHT = 0.1, 0.2
Row = Sequence[float] | np.ndarray
"""A sample's values (see the module's docstring)."""
TOPICS = ("odom", "tf", "tf_static", "amcl_pose", "cmd_vel", "scan")


def diagonal(values: Sequence[float]) -> list[float]:
    matrix = [0.0] * 36
    for i, value in enumerate(values):
        matrix[i * 7] = value
    return matrix


ODOM_COVARIANCE = diagonal([1e-3, 1e-3, 1e6, 1e6, 1e6, 1e-3])
AMCL_COVARIANCE = diagonal(
    [LOCALISATION_NOISE**2, LOCALISATION_NOISE**2, 0.0, 0.0, 0.0, LOCALISATION_YAW_NOISE**2]
)


class RobotMessages:
    """Builds one robot's messages; ``msgs`` maps a package to its ``.msg`` module."""

    def __init__(self, msgs: dict[str, ModuleType], laser: Laser) -> None:
        self.msgs, self.laser = msgs, laser

    def stamp(self, ns: int) -> Any:
        return self.msgs["builtin_interfaces"].Time(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)

    def clock(self, ns: int) -> Any:
        return self.msgs["rosgraph_msgs"].Clock(clock=self.stamp(ns))

    def sample(self, n: int, t: int, v: Row, scan: np.ndarray | None) -> list[tuple[str, Any]]:
        """The messages of global sample ``n`` at ``t`` ns: (topic's last level, message)."""
        stamp = self.stamp(t)
        out: list[tuple[str, Any]] = []
        if n % STATIC_EVERY == 0:  # transient local, and again: a recorder started later has it on its clock
            out.append(("tf_static", self.static(stamp)))
        out.append(("odom", self.odometry(stamp, v)))
        transforms = [self.transform(stamp, "odom", "base_link", v[0], v[1], v[2])]
        if n % CORRECTION_EVERY == 0:
            transforms.append(self.transform(stamp, "map", "odom", v[6], v[7], v[8]))
        out.append(("tf", self.msgs["tf2_msgs"].TFMessage(transforms=transforms)))
        if n % AMCL_EVERY == 0:
            out.append(("amcl_pose", self.amcl(stamp, v)))
        # 20 Hz: one per multiple of the period in [t, t + DT_NS)
        for _ in range(-(-t // CMD_VEL_PERIOD_NS), -(-(t + DT_NS) // CMD_VEL_PERIOD_NS)):
            twist = self.msgs["geometry_msgs"].Twist()
            twist.linear.x, twist.angular.z = float(v[11]), float(v[12])
            out.append(("cmd_vel", twist))
        if n % SCAN_EVERY == 0 and scan is not None:
            out.append(("scan", self.scan(stamp, scan)))
        return out

    def odometry(self, stamp: Any, v: Row) -> Any:
        odom = self.msgs["nav_msgs"].Odometry()
        odom.header.stamp, odom.header.frame_id, odom.child_frame_id = stamp, "odom", "base_link"
        odom.pose.pose.position.x, odom.pose.pose.position.y = float(v[0]), float(v[1])
        set_yaw(odom.pose.pose.orientation, v[2])
        odom.pose.covariance = ODOM_COVARIANCE
        odom.twist.twist.linear.x, odom.twist.twist.angular.z = float(v[9]), float(v[10])
        odom.twist.covariance = ODOM_COVARIANCE
        return odom

    def amcl(self, stamp: Any, v: Row) -> Any:
        amcl = self.msgs["geometry_msgs"].PoseWithCovarianceStamped()
        amcl.header.stamp, amcl.header.frame_id = stamp, "map"
        amcl.pose.pose.position.x, amcl.pose.pose.position.y = float(v[3]), float(v[4])
        set_yaw(amcl.pose.pose.orientation, v[5])
        amcl.pose.covariance = AMCL_COVARIANCE
        return amcl

    def where(self, stamp: Any, v: Row) -> Any:
        """The robot's estimated pose in the map (Nav2's feedback ``current_pose``)."""
        pose = self.msgs["geometry_msgs"].PoseStamped()
        pose.header.stamp, pose.header.frame_id = stamp, "map"
        pose.pose.position.x, pose.pose.position.y = float(v[3]), float(v[4])
        set_yaw(pose.pose.orientation, v[5])
        return pose

    def scan(self, stamp: Any, ranges: np.ndarray) -> Any:
        laser = self.laser
        message = self.msgs["sensor_msgs"].LaserScan(
            angle_min=laser.angle_min,
            angle_max=laser.angle_max,
            angle_increment=laser.angle_increment,
            time_increment=0.0,
            scan_time=SCAN_EVERY * DT_NS / 1e9,
            range_min=laser.range_min,
            range_max=laser.range_max,
            ranges=ranges.astype(np.float32),
        )
        message.header.stamp, message.header.frame_id = stamp, "base_laser_link"
        return message

    def plan(self, stamp: Any, x: np.ndarray, y: np.ndarray, yaw: float) -> Any:
        """The global plan (nav_msgs/Path in ``map``) along ``x, y``: a pose every
        :data:`PLAN_SPACING` metres facing along it, the last one the target with its heading
        ``yaw``, as Nav2's planner publishes on ``plan`` when a goal comes."""
        keep = np.concatenate([[True], np.hypot(np.diff(x), np.diff(y)) > 0])  # a robot standing: one point
        x, y = x[keep], y[keep]
        steps = np.hypot(np.diff(x), np.diff(y))
        along = np.concatenate([[0.0], np.cumsum(steps)])
        at = np.append(np.arange(0.0, along[-1], PLAN_SPACING), along[-1])
        px, py = np.interp(at, along, x), np.interp(at, along, y)
        headings = np.append(np.arctan2(np.diff(py), np.diff(px)), yaw)
        path = self.msgs["nav_msgs"].Path()
        path.header.stamp, path.header.frame_id = stamp, "map"
        for px_i, py_i, heading in zip(px, py, headings, strict=True):
            pose = self.msgs["geometry_msgs"].PoseStamped()
            pose.header.stamp, pose.header.frame_id = stamp, "map"
            pose.pose.position.x, pose.pose.position.y = float(px_i), float(py_i)
            set_yaw(pose.pose.orientation, float(heading))
            path.poses.append(pose)
        return path

    def static(self, stamp: Any) -> Any:
        return self.msgs["tf2_msgs"].TFMessage(
            transforms=[
                self.transform(stamp, "base_link", "base_footprint", 0.0, 0.0, 0.0, -FOOTPRINT_HEIGHT),
                self.transform(stamp, "base_link", "base_laser_link", 0.0, 0.0, 0.0, LASER_HEIGHT),
            ]
        )

    def transform(
        self, stamp: Any, parent: str, child: str, x: float, y: float, yaw: float, z: float = 0.0
    ) -> Any:
        moved = self.msgs["geometry_msgs"].TransformStamped()
        moved.header.stamp, moved.header.frame_id, moved.child_frame_id = stamp, parent, child
        moved.transform.translation.x, moved.transform.translation.y = float(x), float(y)
        moved.transform.translation.z = float(z)
        set_yaw(moved.transform.rotation, yaw)
        return moved


def set_yaw(q: Any, yaw: float) -> None:
    q.x, q.y, q.z, q.w = 0.0, 0.0, math.sin(float(yaw) / 2), math.cos(float(yaw) / 2)
