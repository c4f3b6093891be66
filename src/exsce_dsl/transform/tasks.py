"""The transformations of a task's plan: a new task made from one, in place of it."""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping
from dataclasses import replace

from exsce_dsl.errors import ExsceError
from exsce_dsl.model import Orientation, Pose, Position, Scenario, Task
from exsce_dsl.model.derivation import TaskOrigin
from exsce_dsl.model.names import is_valid_name
from exsce_dsl.transform.applied import Applied, pose_of, recorded, with_allocation
from exsce_dsl.transform.records import Arguments, Transformation, transformation

TASKS: list[Transformation] = []
"""This module's transformations, in the order they are declared."""


@transformation(TASKS, "reverse waypoints of {task} [as {as}]", "task: task, as: new_task?",
                records="task to", help="a new task AS: TASK's waypoints reversed")
def reverse_waypoint_order(scenario: Scenario, a: Arguments, tasks: Mapping[str, Task]) -> Applied:
    """A new task with the waypoints of ``task`` in reverse order, substituted for it."""
    old = scenario.task(a["task"])
    if old is None:
        raise ExsceError(f"mission '{scenario.mission.id}' allocates no task '{a['task']}'")
    new_id = a.get("as", f"{old.id}_reversed")
    if not is_valid_name(new_id):
        raise ExsceError(f"'{new_id}' cannot be a task id")
    if new_id in tasks or scenario.task(new_id) is not None:
        raise ExsceError(f"there is a task '{new_id}' already; name the reversed one with 'as'")
    subtasks = tuple(replace(s, waypoints=tuple(reversed(s.waypoints))) for s in reversed(old.subtasks))
    # not the source file of the old task any more; the same time for each goal
    reversed_task = Task(new_id, subtasks, timeout=old.timeout, timeout_written=old.timeout_written)
    allocation = [replace(e, task=new_id) if e.task == old.id else e for e in scenario.mission.allocation]
    new = with_allocation(scenario, allocation, {new_id: reversed_task})
    step = recorded("reverse_waypoint_order", task=old.id, to=new_id)
    return Applied(new, (reversed_task,), (step,), (TaskOrigin(new_id, old.id, 1),))


def _propose_mirrors(s: Scenario, tasks: Mapping[str, Task]) -> Iterator[Arguments]:
    """Each allocated task about each robot's start pose, where the environment has no map: in
    a building, a mirrored path runs into walls (there, a mirror is for the user to write)."""
    if s.environment.map is not None:
        return
    starts = list(dict.fromkeys(r.start_pose.id for r in s.robots if r.start_pose is not None))
    for task in dict.fromkeys(e.task for e in s.mission.allocation):
        yield from ({"task": task, "about": pose} for pose in starts)


@transformation(TASKS, "mirror waypoints of {task} about {about} [as {as}]",
                "task: task, about: pose, as: new_task?", records="task about to", propose=_propose_mirrors,
                help="a new task AS: TASK's waypoints mirrored about the line through pose ABOUT")
def mirror_waypoints(scenario: Scenario, a: Arguments, tasks: Mapping[str, Task]) -> Applied:
    """A new task with the waypoints of ``task`` mirrored about the line through pose ``about``
    along its heading (headings mirrored too), substituted for it: where the environment is
    symmetric about that line, its runs should cover the same distances in the same times.
    The mirrored waypoints are coordinates of the new task (``NEW-w001``...)."""
    old = scenario.task(a["task"])
    if old is None:
        raise ExsceError(f"mission '{scenario.mission.id}' allocates no task '{a['task']}'")
    axis = pose_of(scenario, a["about"])
    new_id = a.get("as", f"{old.id}_mirrored")
    if not is_valid_name(new_id):
        raise ExsceError(f"'{new_id}' cannot be a task id")
    if new_id in tasks or scenario.task(new_id) is not None:
        raise ExsceError(f"there is a task '{new_id}' already; name the mirrored one with 'as'")
    count = iter(range(1, 1 + sum(1 for _ in old.waypoints())))
    subtasks = tuple(
        replace(s, waypoints=tuple(_mirrored(w, axis, f"{new_id}-w{next(count):03d}") for w in s.waypoints))
        for s in old.subtasks
    )
    moved = (w.position.distance_to(_mirrored(w, axis, w.id).position) for w in old.waypoints())
    if max(moved) < 1e-9:
        raise ExsceError(
            f"every waypoint of '{old.id}' lies on the axis through '{axis.id}': mirroring moves none"
        )
    mirrored = Task(new_id, subtasks, timeout=old.timeout, timeout_written=old.timeout_written)
    allocation = [replace(e, task=new_id) if e.task == old.id else e for e in scenario.mission.allocation]
    new = with_allocation(scenario, allocation, {new_id: mirrored})
    step = recorded("mirror_waypoints", task=old.id, about=axis.id, to=new_id)
    return Applied(new, (mirrored,), (step,), (TaskOrigin(new_id, old.id, 1),))


def _mirrored(pose: Pose, axis: Pose, new_id: str) -> Pose:
    """``pose`` mirrored about the vertical plane through ``axis`` along its heading."""
    heading = axis.orientation.yaw
    ux, uy = math.cos(heading), math.sin(heading)
    dx, dy = pose.position.x - axis.position.x, pose.position.y - axis.position.y
    along = dx * ux + dy * uy
    x, y = axis.position.x + 2 * along * ux - dx, axis.position.y + 2 * along * uy - dy
    o = pose.orientation
    yaw = math.remainder(2 * heading - o.yaw, math.tau)
    return Pose(new_id, Position(x, y, pose.position.z), Orientation(-o.roll, o.pitch, yaw))
