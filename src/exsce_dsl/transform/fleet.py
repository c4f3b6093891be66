"""The transformations of the fleet: robots added, removed and replaced (a composite)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace

from exsce_dsl.errors import ExsceError
from exsce_dsl.model import Robot, Scenario, Task
from exsce_dsl.model.names import is_valid_name
from exsce_dsl.transform.applied import Applied, pose_of, recorded, robot_of, with_allocation
from exsce_dsl.transform.records import Arguments, Transformation, transformation

FLEET: list[Transformation] = []
"""This module's transformations, in the order they are declared."""


@transformation(FLEET, "remove robot {robot} [reassign to {reassign}]", "robot: robot, reassign: robot?",
                records="robot reassign", help="drop ROBOT (its tasks go to REASSIGN, or go)")
def remove_robot(scenario: Scenario, a: Arguments, tasks: Mapping[str, Task]) -> Applied:
    """Drop a robot; its tasks are dropped, or reassigned to another robot (``reassign``)."""
    robot = robot_of(scenario, a["robot"]).id
    if len(scenario.robots) == 1:
        raise ExsceError(f"cannot remove '{robot}', the last robot of '{scenario.id}'")
    heir = a.get("reassign")
    if heir is not None:
        heir = robot_of(scenario, heir).id
        if heir == robot:
            raise ExsceError(f"cannot reassign the tasks of '{robot}' to itself")
    allocation = [
        replace(e, robot=heir) if e.robot == robot and heir else e
        for e in scenario.mission.allocation
        if e.robot != robot or heir
    ]
    robots = tuple(r for r in scenario.robots if r.id != robot)
    new = with_allocation(replace(scenario, robots=robots), allocation)
    return Applied(new, (), (recorded("remove_robot", robot=robot, reassign=heir),))


@transformation(FLEET, "add robot {robot} like {like} at {start} [taking over {take_over}]",
                "robot: new_robot, like: robot, start: pose, take_over: robot?",
                records="robot like start",
                help="a robot typed LIKE at START (taking over TAKE_OVER's tasks)")
def add_robot(scenario: Scenario, a: Arguments, tasks: Mapping[str, Task]) -> Applied:
    """A robot like ``like`` (its type) at ``start`` (a pose of the environment), taking over
    the tasks of ``take_over`` (a robot) if given."""
    robot, template = a["robot"], robot_of(scenario, a["like"])
    if not is_valid_name(robot) or scenario.robot(robot) is not None:
        raise ExsceError(f"'{robot}' cannot be the id of a new robot of '{scenario.id}'")
    start = pose_of(scenario, a["start"])
    taken = {r.start_pose.id for r in scenario.robots if r.start_pose is not None}
    if a["start"] in taken:
        raise ExsceError(f"pose '{a['start']}' is another robot's start pose")
    new_robot = Robot(robot, template.type, robot, start)
    new = replace(scenario, robots=scenario.robots + (new_robot,))
    applied = Applied(new, (), (recorded("add_robot", robot=robot, like=template.id, start=a["start"]),))
    if "take_over" in a:
        donor = robot_of(scenario, a["take_over"]).id
        allocation = [replace(e, robot=robot) if e.robot == donor else e for e in new.mission.allocation]
        applied = applied.then(
            Applied(
                with_allocation(new, allocation),
                (),
                (recorded("substitute_allocation", robot=donor, to=robot),),
            )
        )
    return applied


@transformation(FLEET, "replace robot {robot} by {by} [like {like}] [at {start}]",
                "robot: robot, by: new_robot, like: robot?, start: pose?",
                records="", help="BY (typed LIKE) takes ROBOT's tasks, and its place (or starts at START)")
def replace_robot(scenario: Scenario, a: Arguments, tasks: Mapping[str, Task]) -> Applied:
    """Composite: add a robot like ``like`` at the old one's start pose (or at ``start``), taking
    over its tasks, then remove the old one."""
    old = robot_of(scenario, a["robot"])
    start = a.get("start") or (old.start_pose.id if old.start_pose is not None else None)
    if start is None:
        raise ExsceError(f"'{old.id}' has no start pose for its replacement to take (give one with 'at')")
    parked = replace(
        scenario, robots=tuple(r if r.id != old.id else replace(r, start_pose=None) for r in scenario.robots)
    )
    added = add_robot(
        parked,
        {
            "robot": a["by"],
            "like": a.get("like", old.id),
            "start": start,
            "take_over": old.id,
        },
        tasks,
    )
    removed = remove_robot(added.scenario, {"robot": old.id}, tasks)
    return added.then(removed)
