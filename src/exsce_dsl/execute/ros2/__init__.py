"""The ROS 2 adapter of the mission core: Nav2's actions through rclpy, exsce's recorder to MCAP.

Optional: importing it needs no ROS 2.  :mod:`.nav2` builds the goals sent to each robot's Nav2
and maps their ends onto the core's outcomes; :mod:`.recorder` starts and stops the recorder,
:mod:`.record_node` (an rclpy node writing a rosbag2 MCAP bag with rosbags: no rosbag2), which
describes each topic's type and QoS with :mod:`.record_types`.

:mod:`.live` (:class:`~.live.Ros2Navigator`, :class:`~.live.Ros2Clock`), :mod:`.dispatcher_node`
and :mod:`.session` (:func:`~.session.execute_runs_ros2`) talk to a live graph, as do the Nav2
stand-in robots (:mod:`.stand_in`, :mod:`.robot_topics`): they import rclpy only when called and
raise :class:`~exsce_dsl.errors.RosGraphError` saying how to get it when it is missing.  The tests
run them on a live ROS 2 graph of PyPI's Jazzy wheels (``scripts/install-ros2``).
"""

from exsce_dsl.execute.ros2.live import Ros2Clock, Ros2Navigator, require_rclpy
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
    "follow_waypoints_goals",
    "goal_outcome",
    "nav2_actions",
    "navigate_to_pose_goals",
    "require_rclpy",
    "waypoint_outcomes",
]
