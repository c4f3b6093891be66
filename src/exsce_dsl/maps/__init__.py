"""Maps: the occupancy grid and the shortest paths on it, shared by ``lang`` (poses in free space),
``sim`` (planning robots' paths) and ``derive`` (path lengths for estimates).

* :mod:`~exsce_dsl.maps.grid` — the occupancy grid: reading and writing ROS map_server maps,
  the state of a point, free space;
* :mod:`~exsce_dsl.maps.paths` — the 8-connected graph of free cells and shortest paths on it;
* :mod:`~exsce_dsl.maps.planning` — a map at planning resolution (occupied space inflated by a
  robot's radius, clearance to walls) and collision-free paths on it; the planning grid of a
  scenario.
"""
