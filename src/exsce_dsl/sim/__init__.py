"""A small kinematic executor that plays scenarios and writes real bag files.

Not a robot simulator: robots follow grid paths around the occupancy map with
bounded speed and acceleration and seeded noise, so that the whole method
(runs, metrics, oracles) can be exercised without ROS.
"""
