"""The ROS 1 adapter of the mission core: rospy's Python runs exsce's nodes, this process the rest.

:mod:`.graph` finds rospy's Python and talks to the master over XML-RPC (parameters, topics) or
starts one; :mod:`.channel` runs a node of ``nodes/`` (the dispatcher's action clients, the
stand-in robot) and exchanges JSON lines with it.
"""
