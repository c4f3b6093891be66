"""Message types of the waypoint dispatcher, registered into rosbags type stores.

The dispatcher is an actionlib server ``FollowWaypoints`` (package
``waypoint_dispatcher``): its goal is a list of poses, and both its feedback
and its result carry ``actionlib_msgs/GoalStatusArray goal_status`` with one
status per waypoint.  Bags carry these definitions, so any reader can decode
them.
"""

from __future__ import annotations

from functools import lru_cache

from rosbags.typesys import Stores, get_types_from_msg, get_typestore
from rosbags.typesys.store import Typestore

from exsce_dsl.messages.navigation import register_navigation_types

PACKAGE = "waypoint_dispatcher"
FEEDBACK = f"{PACKAGE}/msg/FollowWaypointsActionFeedback"
RESULT = f"{PACKAGE}/msg/FollowWaypointsActionResult"

_DEFINITIONS = {
    f"{PACKAGE}/msg/FollowWaypointsFeedback": "actionlib_msgs/GoalStatusArray goal_status\n",
    f"{PACKAGE}/msg/FollowWaypointsResult": "actionlib_msgs/GoalStatusArray goal_status\n",
    FEEDBACK: (
        "std_msgs/Header header\n"
        "actionlib_msgs/GoalStatus status\n"
        f"{PACKAGE}/FollowWaypointsFeedback feedback\n"
    ),
    RESULT: (
        f"std_msgs/Header header\nactionlib_msgs/GoalStatus status\n{PACKAGE}/FollowWaypointsResult result\n"
    ),
}

STORES = {"ros1": Stores.ROS1_NOETIC, "ros2": Stores.ROS2_HUMBLE, "mcap": Stores.ROS2_HUMBLE}


@lru_cache(maxsize=4)
def typestore(fmt: str) -> Typestore:
    """The type store for a bag format, with the dispatcher's types added."""
    store = get_typestore(STORES[fmt])
    types = {}
    for name, text in _DEFINITIONS.items():
        types.update(get_types_from_msg(text, name))
    store.register(types)
    return store


@lru_cache(maxsize=4)
def navigation_typestore(fmt: str) -> Typestore:
    """The type store for a bag format with the navigation stacks' types too (``nav2_msgs``,
    ``move_base_msgs``, and what a ROS 1 store lacks: ``tf2_msgs``, ``action_msgs``)."""
    store = get_typestore(STORES[fmt])
    register_navigation_types(store)
    return store
