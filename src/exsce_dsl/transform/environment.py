"""The transformations of the environment: where robots start, where obstacles are."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import replace

from exsce_dsl.errors import ExsceError
from exsce_dsl.model import Position, Scenario, Task
from exsce_dsl.model.names import NUMBER
from exsce_dsl.suggest import did_you_mean
from exsce_dsl.transform.applied import Applied, pose_of, recorded, robot_of
from exsce_dsl.transform.records import Arguments, Transformation, transformation

ENVIRONMENT: list[Transformation] = []
"""This module's transformations, in the order they are declared."""


@transformation(ENVIRONMENT, "swap start poses of {robot} and {with}", "robot: robot, with: robot",
                records="robot to", help="ROBOT and WITH swap start poses")
def swap_start_poses(scenario: Scenario, a: Arguments, tasks: Mapping[str, Task]) -> Applied:
    first, second = robot_of(scenario, a["robot"]), robot_of(scenario, a["with"])
    if first.id == second.id:
        raise ExsceError(f"cannot swap the start pose of '{first.id}' with its own")
    swapped = {first.id: second.start_pose, second.id: first.start_pose}
    robots = tuple(replace(r, start_pose=swapped[r.id]) if r.id in swapped else r for r in scenario.robots)
    swap = recorded("swap_start_poses", robot=first.id, to=second.id)
    return Applied(replace(scenario, robots=robots), (), (swap,))


@transformation(ENVIRONMENT, "start {robot} at {pose}", "robot: robot, pose: pose",
                records="robot pose", help="ROBOT (without one) starts at POSE")
def add_start_pose(scenario: Scenario, a: Arguments, tasks: Mapping[str, Task]) -> Applied:
    """Give a robot that has none a start pose (a pose no other robot starts at)."""
    robot = robot_of(scenario, a["robot"])
    if robot.start_pose is not None:
        raise ExsceError(
            f"'{robot.id}' starts at '{robot.start_pose.id}' already (swap or remove that first)"
        )
    pose = pose_of(scenario, a["pose"])
    if any(r.start_pose is not None and r.start_pose.id == pose.id for r in scenario.robots):
        raise ExsceError(f"pose '{pose.id}' is another robot's start pose")
    robots = tuple(replace(r, start_pose=pose) if r.id == robot.id else r for r in scenario.robots)
    return Applied(
        replace(scenario, robots=robots), (), (recorded("add_start_pose", robot=robot.id, pose=pose.id),)
    )


@transformation(ENVIRONMENT, "remove start pose of {robot}", "robot: robot",
                records="robot", help="ROBOT (without tasks) loses its start pose")
def remove_start_pose(scenario: Scenario, a: Arguments, tasks: Mapping[str, Task]) -> Applied:
    """Take a robot's start pose away; only a robot without tasks may have none."""
    robot = robot_of(scenario, a["robot"])
    if robot.start_pose is None:
        raise ExsceError(f"'{robot.id}' has no start pose to remove")
    if scenario.mission.tasks_of(robot.id):
        raise ExsceError(f"'{robot.id}' has tasks, so it needs a start pose (remove its tasks first)")
    robots = tuple(replace(r, start_pose=None) if r.id == robot.id else r for r in scenario.robots)
    return Applied(replace(scenario, robots=robots), (), (recorded("remove_start_pose", robot=robot.id),))


def _coordinates(text: str) -> tuple[float, ...]:
    """``x,y`` or ``x,y,z`` in metres."""
    parts = [p.strip() for p in text.split(",")]
    if len(parts) not in (2, 3):
        raise ExsceError(f"'{text}' is not a position: write x,y or x,y,z in metres")
    values = []
    for part in parts:
        value = float(part) if NUMBER.fullmatch(part) else math.nan
        if not math.isfinite(value):
            raise ExsceError(f"'{part}' in position '{text}' is not a number of metres")
        values.append(value)
    return tuple(values)


@transformation(ENVIRONMENT, "move obstacle {obstacle} to {to}", "obstacle: obstacle, to: position",
                records="obstacle to",
                help="OBSTACLE moves to TO: x,y or x,y,z in metres (same heading, model and size)")
def move_obstacle(scenario: Scenario, a: Arguments, tasks: Mapping[str, Task]) -> Applied:
    """The obstacle at another position (``x,y`` or ``x,y,z`` in metres; z is 0 unless given),
    with its heading, model and size.  The step records z only when it is not 0, as the
    formatter writes positions."""
    env = scenario.environment
    obstacles = {o.id: o for o in env.obstacles}
    obstacle = obstacles.get(a["obstacle"])
    if obstacle is None:
        hint = did_you_mean(a["obstacle"], obstacles)
        raise ExsceError(f"environment '{env.id}' has no obstacle '{a['obstacle']}'{hint}")
    x, y, *z = _coordinates(a["to"])
    position = Position(x, y, z[0] if z else 0.0)
    written = [repr(x), repr(y)] + ([repr(position.z)] if position.z != 0.0 else [])
    if position == obstacle.pose.position:
        raise ExsceError(f"obstacle '{obstacle.id}' is at ({', '.join(written)}) already")
    moved = replace(obstacle, pose=replace(obstacle.pose, position=position))
    environment = replace(env, obstacles=tuple(moved if o.id == obstacle.id else o for o in env.obstacles))
    step = recorded("move_obstacle", obstacle=obstacle.id, to=",".join(written))
    return Applied(replace(scenario, environment=environment), (), (step,))
