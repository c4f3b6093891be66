"""Derivations no fleet could play: a robot would have to reach a place another stands on for good.

A robot without tasks stands at its start pose all the run, and a robot that has done its
tasks stays at its last waypoint.  When such a place is a waypoint of another robot, that
robot cannot reach it: a real planner aborts the goal, and a metamorphic relation fails for a
reason that lies in the derivation, not in the robot's software.  Two robots that end at the
same place are one case of it.  Draws and shrinking skip such derivations (a step that leads
to one does not apply); the base scenario is what its author wrote and is never refused.
"""

from __future__ import annotations

import math

from exsce_dsl.model import Pose, Scenario

REACH = 0.8
"""Metres between a waypoint and a robot standing there within which the waypoint is taken
(two robots of 0.3 m radius, with room to stop)."""


def standing_in_the_way(scenario: Scenario) -> list[str]:
    """Why robots of ``scenario`` would have to drive onto a robot that stands for good; empty
    when none would."""
    waypoints: dict[str, list[Pose]] = {}
    for entry in scenario.mission.allocation:
        task = scenario.task(entry.task)
        if task is not None:
            waypoints.setdefault(entry.robot, []).extend(w for s in task.subtasks for w in s.waypoints)
    problems = []
    for robot in scenario.robots:
        mine = waypoints.get(robot.id)
        if mine:
            place, why = mine[-1], "ends its tasks"
        elif robot.start_pose is not None:
            place, why = robot.start_pose, "has no task and stands"
        else:
            continue
        for other, theirs in waypoints.items():
            if other == robot.id:
                continue
            taken = [w for w in theirs if _distance(w, place) < REACH]
            if taken:
                problems.append(
                    f"{robot.id} {why} at {_name(place)}, a waypoint of {other} ({_name(taken[0])})"
                )
    return problems


def _distance(a: Pose, b: Pose) -> float:
    return math.hypot(a.position.x - b.position.x, a.position.y - b.position.y)


def _name(pose: Pose) -> str:
    return pose.id or f"({pose.position.x:.2f}, {pose.position.y:.2f})"
