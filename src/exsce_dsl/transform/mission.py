"""The transformations of a mission: which robot does which task, in which order."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace

from exsce_dsl.errors import ExsceError
from exsce_dsl.model import Assignment, Scenario, Task
from exsce_dsl.suggest import did_you_mean
from exsce_dsl.transform.applied import Applied, recorded, robot_of, with_allocation
from exsce_dsl.transform.records import Arguments, Transformation, transformation

MISSION: list[Transformation] = []
"""This module's transformations, in the order they are declared."""


@transformation(MISSION, "add task {task} to {robot} [at {position}]",
                "robot: robot, task: task, position: count?",
                records="robot task position", help="give ROBOT the TASK, at POSITION among its tasks")
def add_task(scenario: Scenario, a: Arguments, tasks: Mapping[str, Task]) -> Applied:
    robot, task_id = robot_of(scenario, a["robot"]).id, a["task"]
    if task_id not in tasks and scenario.task(task_id) is None:
        raise ExsceError(f"unknown task '{task_id}'{did_you_mean(task_id, tasks)}")
    position = int(a.get("position", len(scenario.mission.tasks_of(robot)) + 1))
    own = [n for n, e in enumerate(scenario.mission.allocation) if e.robot == robot]
    if not 1 <= position <= len(own) + 1:
        raise ExsceError(f"'{robot}' has {len(own)} tasks: a new one goes at position 1 to {len(own) + 1}")
    at = (
        own[position - 1]
        if position <= len(own)
        else (own[-1] + 1 if own else len(scenario.mission.allocation))
    )
    allocation = list(scenario.mission.allocation)
    allocation.insert(at, Assignment(robot, task_id))
    new = with_allocation(scenario, allocation, {task_id: tasks[task_id]} if task_id in tasks else {})
    return Applied(new, (), (recorded("add_task", robot=robot, task=task_id, position=position),))


@transformation(MISSION, ("remove task {task} [from {robot}]", "remove tasks of {robot}"),
                "task: task?, robot: robot?",
                records="task robot", help="take TASK away (from ROBOT, or every robot)")
def remove_task(scenario: Scenario, a: Arguments, tasks: Mapping[str, Task]) -> Applied:
    task_id, robot = a.get("task"), a.get("robot")
    if task_id is None and robot is None:
        raise ExsceError("remove_task needs a task, a robot, or both")
    if robot is not None:
        robot_of(scenario, robot)
    kept = [
        e
        for e in scenario.mission.allocation
        if not ((task_id in (None, e.task)) and (robot in (None, e.robot)))
    ]
    if len(kept) == len(scenario.mission.allocation):
        raise ExsceError(f"mission '{scenario.mission.id}' allocates no such task to remove")
    return Applied(with_allocation(scenario, kept), (), (recorded("remove_task", task=task_id, robot=robot),))


@transformation(MISSION, "substitute task {task} by {with}", "task: task, with: task",
                records="task by", help="allocate task WITH wherever TASK was")
def substitute_task(scenario: Scenario, a: Arguments, tasks: Mapping[str, Task]) -> Applied:
    old, new_id = a["task"], a["with"]
    if old not in {e.task for e in scenario.mission.allocation}:
        raise ExsceError(f"mission '{scenario.mission.id}' allocates no task '{old}'")
    if new_id not in tasks and scenario.task(new_id) is None:
        raise ExsceError(f"unknown task '{new_id}'{did_you_mean(new_id, tasks)}")
    allocation = [replace(e, task=new_id) if e.task == old else e for e in scenario.mission.allocation]
    extra = {new_id: tasks[new_id]} if new_id in tasks else {}
    return Applied(
        with_allocation(scenario, allocation, extra), (), (recorded("substitute_task", task=old, by=new_id),)
    )


@transformation(MISSION, "swap tasks of {robot} and {with}", "robot: robot, with: robot",
                records="robot to", help="ROBOT and WITH swap their tasks")
def swap_assignment(scenario: Scenario, a: Arguments, tasks: Mapping[str, Task]) -> Applied:
    first, second = robot_of(scenario, a["robot"]).id, robot_of(scenario, a["with"]).id
    if first == second:
        raise ExsceError(f"cannot swap the tasks of '{first}' with its own")
    swap = {first: second, second: first}
    allocation = [replace(e, robot=swap.get(e.robot, e.robot)) for e in scenario.mission.allocation]
    return Applied(
        with_allocation(scenario, allocation), (), (recorded("swap_assignment", robot=first, to=second),)
    )


@transformation(MISSION, "reverse task order [of {robot}]", "robot: robot?",
                records="robot", help="each robot (or ROBOT) does its tasks in reverse")
def reverse_task_order(scenario: Scenario, a: Arguments, tasks: Mapping[str, Task]) -> Applied:
    robot = a.get("robot")
    robots = [robot_of(scenario, robot).id] if robot else [r.id for r in scenario.robots]
    allocation = list(scenario.mission.allocation)
    for r in robots:
        places = [n for n, e in enumerate(allocation) if e.robot == r]
        for n, entry in zip(places, reversed([allocation[p] for p in places]), strict=True):
            allocation[n] = entry
    return Applied(with_allocation(scenario, allocation), (), (recorded("reverse_task_order", robot=robot),))


@transformation(MISSION, "reallocate {allocation}", "allocation: allocation",
                records="allocation robot to",
                help="the mission becomes ALLOCATION: robot:task,robot:task,... in order")
def substitute_allocation(scenario: Scenario, a: Arguments, tasks: Mapping[str, Task]) -> Applied:
    """A whole new allocation: ``robot:task,robot:task,...`` in execution order."""
    entries = []
    for item in a["allocation"].split(","):
        robot, _, task = item.strip().partition(":")
        if not task:
            raise ExsceError(f"'{item.strip()}' is not robot:task")
        entries.append(Assignment(robot_of(scenario, robot).id, task))
    extra = {e.task: tasks[e.task] for e in entries if e.task in tasks}
    new = with_allocation(scenario, entries, extra)
    return Applied(new, (), (recorded("substitute_allocation", allocation=a["allocation"].replace(" ", "")),))
