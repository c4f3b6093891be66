"""The stand-in robot: the kinematic executor played as live ROS 1 robots (issue 34, item 4).

:mod:`.legs` plans and drives each goal in this process (the robots' state, the faults);
:mod:`.session` runs the ROS side (``execute/ros1/nodes/stand_in_node.py``) and answers it.
"""

from exsce_dsl.execute.stand_in.session import GoalEnd, StandIn, Stats, start_stand_in

__all__ = ["GoalEnd", "StandIn", "Stats", "start_stand_in"]
