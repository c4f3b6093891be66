"""A small kinematic executor that plays scenarios and writes real bag files.

Not a robot simulator: robots follow grid paths around the occupancy map with
bounded speed and acceleration and seeded noise, so that the whole method
(runs, metrics, oracles) can be exercised without ROS.  The bags hold the
topics of a robot convention (:mod:`exsce_dsl.sim.conventions`): the method's
own, Nav2's or move_base's.
"""
