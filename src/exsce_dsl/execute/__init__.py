"""Running a scenario's mission on a robot stack: the pure mission core (DESIGN.md §2, ``execute``).

What is here: the mission as a schedule of navigation goals per robot (:mod:`.mission`), what a
goal's outcome leads to (:mod:`.outcomes`), the dispatcher that drives a schedule through any
:class:`~.navigator.Navigator` on a clock the caller gives (:mod:`.dispatcher`), and a kinematic
navigator on a simulated clock for tests (:mod:`.kinematic`).  No middleware is imported here.

Not built yet (issue 34, items 2-7): the ROS 1 (rospy/actionlib, move_base and the method's
dispatcher) and ROS 2 (Nav2) adapters, the scenario on the parameter server, publishing the
run-time PROV of tasks, allocation and actions, the recorder (``rosbag record``), the
``exscec execute`` command and the stand-in robot on a live graph.
"""
