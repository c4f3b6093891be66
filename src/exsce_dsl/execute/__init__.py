"""Running a scenario's mission on a robot stack (DESIGN.md §2, ``execute``).

The mission core, without middleware: the mission as a schedule of navigation goals per robot
(:mod:`.mission`, with the goal timeouts of the spec or a default from distance and speed
limit), what a goal's outcome leads to (:mod:`.outcomes`), the dispatcher that drives a schedule
through any :class:`~.navigator.Navigator` on a clock the caller gives (:mod:`.dispatcher`), the
run-time PROV of a mission run (:mod:`.provenance`), what a run records (:mod:`.recording`)
and its files under the method's names (:mod:`.run_files`).  The tests drive the dispatcher with
a kinematic navigator on a simulated clock (``tests/support/kinematic_navigator.py``).

Adapters: :mod:`.ros1` (rospy's Python runs exsce's nodes — the dispatcher's actionlib clients
for move_base and the stand-in robot — and this process talks to them and to the master; the
real ``rosbag record``; tested on a real roscore) and :mod:`.ros2` (rclpy and Nav2, imported only
where rclpy exists: the dispatcher's Nav2 action clients and the stand-in's Nav2 robots; tested on
a live ROS 2 graph of PyPI's Jazzy wheels, ``scripts/install-ros2``).
"""

# mypy: implicit-reexport
from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from exsce_dsl.execute.mission import Goal, schedule
    from exsce_dsl.execute.outcomes import DEFAULT_POLICY, Policy
    from exsce_dsl.execute.recording import recorded_topics
    from exsce_dsl.execute.ros1.graph import master_uri, start_master
    from exsce_dsl.execute.ros1.session import (
        DEFAULT_SERVER_TIMEOUT,
        LOGS,
        ExecutedRun,
        Interruption,
        Options,
        execute_runs,
    )
    from exsce_dsl.execute.ros2.session import execute_runs_ros2
    from exsce_dsl.execute.ros2.stand_in import Ros2StandIn
    from exsce_dsl.execute.stand_in import StandIn, start_stand_in
    from exsce_dsl.execute.stand_in.session import DEFAULT_SPEED_UP
else:
    from exsce_dsl.faces import lazy_face

    __getattr__, __dir__ = lazy_face(__name__, __file__)
