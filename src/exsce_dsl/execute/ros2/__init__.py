"""The ROS 2 adapter of the mission core: Nav2's actions through rclpy, exsce's recorder to MCAP.

Optional: importing it needs no ROS 2.  :mod:`.nav2` builds the goals sent to each robot's Nav2
and maps their ends onto the core's outcomes; :mod:`.recorder` starts and stops the recorder,
:mod:`.record_node` (an rclpy node writing a rosbag2 MCAP bag with rosbags: no rosbag2), which
describes each topic's type and QoS with :mod:`.record_types`.

:mod:`.live` is the part that talks to a live graph (:func:`~.live.execute_ros2`,
:class:`~.live.Ros2Navigator`, :class:`~.live.Ros2Clock`): it imports rclpy only when called and
raises :class:`~exsce_dsl.errors.RosGraphError` saying how to get it when it is missing.  It is
not run on a live ROS 2 graph in this project's CI.
"""

from exsce_dsl.execute.ros2.live import Ros2Clock, Ros2Navigator, execute_ros2, require_rclpy
from exsce_dsl.execute.ros2.nav2 import (
    FOLLOW_WAYPOINTS,
    NAVIGATE_TO_POSE,
    FollowWaypointsGoal,
    Nav2Actions,
    NavigateToPoseGoal,
    StampedPose,
    follow_waypoints_goals,
    goal_outcome,
    nav2_actions,
    navigate_to_pose_goals,
    waypoint_outcomes,
)
from exsce_dsl.execute.ros2.recorder import RECORDER_NODE, Ros2Recorder, bag_counts

__all__ = [
    "FOLLOW_WAYPOINTS",
    "NAVIGATE_TO_POSE",
    "RECORDER_NODE",
    "FollowWaypointsGoal",
    "Nav2Actions",
    "NavigateToPoseGoal",
    "Ros2Clock",
    "Ros2Navigator",
    "Ros2Recorder",
    "StampedPose",
    "bag_counts",
    "execute_ros2",
    "follow_waypoints_goals",
    "goal_outcome",
    "nav2_actions",
    "navigate_to_pose_goals",
    "require_rclpy",
    "waypoint_outcomes",
]
