"""The method's input transformations, as pure functions on the semantic model.

Each takes a scenario and its arguments and returns the new scenario, the tasks it
made (a reversed task is a new task) and the step it records; a precondition that
does not hold is an :class:`~exsce_dsl.errors.ExsceError` saying which.  Composite
transformations (``replace_robot``) are made of basic ones and record those.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace

from exsce_dsl.errors import ExsceError
from exsce_dsl.model import Assignment, Pose, Position, Robot, Scenario, Task
from exsce_dsl.model.derivation import ParameterValue, TaskOrigin, TransformationStep
from exsce_dsl.model.names import NUMBER, is_valid_name
from exsce_dsl.suggest import did_you_mean


@dataclass(frozen=True)
class Applied:
    """What applying transformations gave: the new scenario, the tasks they made, the steps."""

    scenario: Scenario
    new_tasks: tuple[Task, ...] = ()
    steps: tuple[TransformationStep, ...] = ()
    origins: tuple[TaskOrigin, ...] = ()
    """The task each new task was made from, and by which of ``steps`` (from 1)."""

    def then(self, other: Applied) -> Applied:
        shifted = tuple(replace(o, step=o.step + len(self.steps)) for o in other.origins)
        return Applied(
            other.scenario, self.new_tasks + other.new_tasks, self.steps + other.steps, self.origins + shifted
        )


Arguments = Mapping[str, str]


@dataclass(frozen=True)
class Transformation:
    name: str
    required: tuple[str, ...]
    optional: tuple[str, ...]
    apply: Callable[[Scenario, Arguments, Mapping[str, Task]], Applied]
    help: str


def _step(name: str, **arguments: ParameterValue | None) -> TransformationStep:
    return TransformationStep(name, tuple((k, v) for k, v in arguments.items() if v is not None))


def _robot(scenario: Scenario, robot_id: str) -> Robot:
    robot = scenario.robot(robot_id)
    if robot is None:
        known = [r.id for r in scenario.robots]
        raise ExsceError(f"scenario '{scenario.id}' has no robot '{robot_id}'{did_you_mean(robot_id, known)}")
    return robot


def _with_allocation(
    scenario: Scenario, allocation: Sequence[Assignment], extra: Mapping[str, Task] | None = None
) -> Scenario:
    """The scenario with a new allocation; its task list follows the allocation."""
    known = {t.id: t for t in scenario.tasks} | dict(extra or {})
    used: dict[str, Task] = {}
    for entry in allocation:
        if entry.task not in known:
            raise ExsceError(f"unknown task '{entry.task}'{did_you_mean(entry.task, known)}")
        used.setdefault(entry.task, known[entry.task])
    if not allocation:
        raise ExsceError(f"the mission of '{scenario.id}' would allocate no task")
    mission = replace(scenario.mission, allocation=tuple(allocation))
    return replace(scenario, mission=mission, tasks=tuple(used.values()))


def add_task(scenario: Scenario, a: Arguments, tasks: Mapping[str, Task]) -> Applied:
    robot, task_id = _robot(scenario, a["robot"]).id, a["task"]
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
    new = _with_allocation(scenario, allocation, {task_id: tasks[task_id]} if task_id in tasks else {})
    return Applied(new, (), (_step("add_task", robot=robot, task=task_id, position=position),))


def remove_task(scenario: Scenario, a: Arguments, tasks: Mapping[str, Task]) -> Applied:
    task_id, robot = a.get("task"), a.get("robot")
    if task_id is None and robot is None:
        raise ExsceError("remove_task needs a task, a robot, or both")
    if robot is not None:
        _robot(scenario, robot)
    kept = [
        e
        for e in scenario.mission.allocation
        if not ((task_id in (None, e.task)) and (robot in (None, e.robot)))
    ]
    if len(kept) == len(scenario.mission.allocation):
        raise ExsceError(f"mission '{scenario.mission.id}' allocates no such task to remove")
    return Applied(_with_allocation(scenario, kept), (), (_step("remove_task", task=task_id, robot=robot),))


def substitute_task(scenario: Scenario, a: Arguments, tasks: Mapping[str, Task]) -> Applied:
    old, new_id = a["task"], a["with"]
    if old not in {e.task for e in scenario.mission.allocation}:
        raise ExsceError(f"mission '{scenario.mission.id}' allocates no task '{old}'")
    if new_id not in tasks and scenario.task(new_id) is None:
        raise ExsceError(f"unknown task '{new_id}'{did_you_mean(new_id, tasks)}")
    allocation = [replace(e, task=new_id) if e.task == old else e for e in scenario.mission.allocation]
    extra = {new_id: tasks[new_id]} if new_id in tasks else {}
    return Applied(
        _with_allocation(scenario, allocation, extra), (), (_step("substitute_task", task=old, by=new_id),)
    )


def swap_assignment(scenario: Scenario, a: Arguments, tasks: Mapping[str, Task]) -> Applied:
    first, second = _robot(scenario, a["robot"]).id, _robot(scenario, a["with"]).id
    if first == second:
        raise ExsceError(f"cannot swap the tasks of '{first}' with its own")
    swap = {first: second, second: first}
    allocation = [replace(e, robot=swap.get(e.robot, e.robot)) for e in scenario.mission.allocation]
    return Applied(
        _with_allocation(scenario, allocation), (), (_step("swap_assignment", robot=first, to=second),)
    )


def reverse_task_order(scenario: Scenario, a: Arguments, tasks: Mapping[str, Task]) -> Applied:
    robot = a.get("robot")
    robots = [_robot(scenario, robot).id] if robot else [r.id for r in scenario.robots]
    allocation = list(scenario.mission.allocation)
    for r in robots:
        places = [n for n, e in enumerate(allocation) if e.robot == r]
        for n, entry in zip(places, reversed([allocation[p] for p in places]), strict=True):
            allocation[n] = entry
    return Applied(_with_allocation(scenario, allocation), (), (_step("reverse_task_order", robot=robot),))


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
    new = _with_allocation(scenario, allocation, {new_id: reversed_task})
    step = _step("reverse_waypoint_order", task=old.id, to=new_id)
    return Applied(new, (reversed_task,), (step,), (TaskOrigin(new_id, old.id, 1),))


def swap_start_poses(scenario: Scenario, a: Arguments, tasks: Mapping[str, Task]) -> Applied:
    first, second = _robot(scenario, a["robot"]), _robot(scenario, a["with"])
    if first.id == second.id:
        raise ExsceError(f"cannot swap the start pose of '{first.id}' with its own")
    swapped = {first.id: second.start_pose, second.id: first.start_pose}
    robots = tuple(replace(r, start_pose=swapped[r.id]) if r.id in swapped else r for r in scenario.robots)
    return Applied(
        replace(scenario, robots=robots), (), (_step("swap_start_poses", robot=first.id, to=second.id),)
    )


def _pose(scenario: Scenario, pose_id: str) -> Pose:
    poses = {p.id: p for p in scenario.environment.poses()}
    if pose_id not in poses:
        hint = did_you_mean(pose_id, poses)
        raise ExsceError(f"environment '{scenario.environment.id}' has no pose '{pose_id}'{hint}")
    return poses[pose_id]


def add_start_pose(scenario: Scenario, a: Arguments, tasks: Mapping[str, Task]) -> Applied:
    """Give a robot that has none a start pose (a pose no other robot starts at)."""
    robot = _robot(scenario, a["robot"])
    if robot.start_pose is not None:
        raise ExsceError(
            f"'{robot.id}' starts at '{robot.start_pose.id}' already (swap or remove that first)"
        )
    pose = _pose(scenario, a["pose"])
    if any(r.start_pose is not None and r.start_pose.id == pose.id for r in scenario.robots):
        raise ExsceError(f"pose '{pose.id}' is another robot's start pose")
    robots = tuple(replace(r, start_pose=pose) if r.id == robot.id else r for r in scenario.robots)
    return Applied(
        replace(scenario, robots=robots), (), (_step("add_start_pose", robot=robot.id, pose=pose.id),)
    )


def remove_start_pose(scenario: Scenario, a: Arguments, tasks: Mapping[str, Task]) -> Applied:
    """Take a robot's start pose away; only a robot without tasks may have none."""
    robot = _robot(scenario, a["robot"])
    if robot.start_pose is None:
        raise ExsceError(f"'{robot.id}' has no start pose to remove")
    if scenario.mission.tasks_of(robot.id):
        raise ExsceError(f"'{robot.id}' has tasks, so it needs a start pose (remove its tasks first)")
    robots = tuple(replace(r, start_pose=None) if r.id == robot.id else r for r in scenario.robots)
    return Applied(replace(scenario, robots=robots), (), (_step("remove_start_pose", robot=robot.id),))


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
    step = _step("move_obstacle", obstacle=obstacle.id, to=",".join(written))
    return Applied(replace(scenario, environment=environment), (), (step,))


def substitute_allocation(scenario: Scenario, a: Arguments, tasks: Mapping[str, Task]) -> Applied:
    """A whole new allocation: ``robot:task,robot:task,...`` in execution order."""
    entries = []
    for item in a["allocation"].split(","):
        robot, _, task = item.strip().partition(":")
        if not task:
            raise ExsceError(f"'{item.strip()}' is not robot:task")
        entries.append(Assignment(_robot(scenario, robot).id, task))
    extra = {e.task: tasks[e.task] for e in entries if e.task in tasks}
    new = _with_allocation(scenario, entries, extra)
    return Applied(new, (), (_step("substitute_allocation", allocation=a["allocation"].replace(" ", "")),))


def remove_robot(scenario: Scenario, a: Arguments, tasks: Mapping[str, Task]) -> Applied:
    """Drop a robot; its tasks are dropped, or reassigned to another robot (``reassign``)."""
    robot = _robot(scenario, a["robot"]).id
    if len(scenario.robots) == 1:
        raise ExsceError(f"cannot remove '{robot}', the last robot of '{scenario.id}'")
    heir = a.get("reassign")
    if heir is not None:
        heir = _robot(scenario, heir).id
        if heir == robot:
            raise ExsceError(f"cannot reassign the tasks of '{robot}' to itself")
    allocation = [
        replace(e, robot=heir) if e.robot == robot and heir else e
        for e in scenario.mission.allocation
        if e.robot != robot or heir
    ]
    robots = tuple(r for r in scenario.robots if r.id != robot)
    new = _with_allocation(replace(scenario, robots=robots), allocation)
    return Applied(new, (), (_step("remove_robot", robot=robot, reassign=heir),))


def add_robot(scenario: Scenario, a: Arguments, tasks: Mapping[str, Task]) -> Applied:
    """A robot like ``like`` (its type) at ``start`` (a pose of the environment), taking over
    the tasks of ``take_over`` (a robot) if given."""
    robot, template = a["robot"], _robot(scenario, a["like"])
    if not is_valid_name(robot) or scenario.robot(robot) is not None:
        raise ExsceError(f"'{robot}' cannot be the id of a new robot of '{scenario.id}'")
    start = _pose(scenario, a["start"])
    taken = {r.start_pose.id for r in scenario.robots if r.start_pose is not None}
    if a["start"] in taken:
        raise ExsceError(f"pose '{a['start']}' is another robot's start pose")
    new_robot = Robot(robot, template.type, robot, start)
    new = replace(scenario, robots=scenario.robots + (new_robot,))
    applied = Applied(new, (), (_step("add_robot", robot=robot, like=template.id, start=a["start"]),))
    if "take_over" in a:
        donor = _robot(scenario, a["take_over"]).id
        allocation = [replace(e, robot=robot) if e.robot == donor else e for e in new.mission.allocation]
        applied = applied.then(
            Applied(
                _with_allocation(new, allocation),
                (),
                (_step("substitute_allocation", robot=donor, to=robot),),
            )
        )
    return applied


def replace_robot(scenario: Scenario, a: Arguments, tasks: Mapping[str, Task]) -> Applied:
    """Composite: add a robot like ``like`` at the old one's start pose (or at ``start``), taking
    over its tasks, then remove the old one."""
    old = _robot(scenario, a["robot"])
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


TRANSFORMATIONS: dict[str, Transformation] = {
    t.name: t
    for t in (
        Transformation(
            "add_task",
            ("robot", "task"),
            ("position",),
            add_task,
            "give ROBOT the TASK, at POSITION among its tasks",
        ),
        Transformation(
            "remove_task", (), ("task", "robot"), remove_task, "take TASK away (from ROBOT, or every robot)"
        ),
        Transformation(
            "substitute_task", ("task", "with"), (), substitute_task, "allocate task WITH wherever TASK was"
        ),
        Transformation(
            "swap_assignment", ("robot", "with"), (), swap_assignment, "ROBOT and WITH swap their tasks"
        ),
        Transformation(
            "reverse_task_order",
            (),
            ("robot",),
            reverse_task_order,
            "each robot (or ROBOT) does its tasks in reverse",
        ),
        Transformation(
            "reverse_waypoint_order",
            ("task",),
            ("as",),
            reverse_waypoint_order,
            "a new task AS: TASK's waypoints reversed",
        ),
        Transformation(
            "swap_start_poses", ("robot", "with"), (), swap_start_poses, "ROBOT and WITH swap start poses"
        ),
        Transformation(
            "add_start_pose", ("robot", "pose"), (), add_start_pose, "ROBOT (without one) starts at POSE"
        ),
        Transformation(
            "remove_start_pose",
            ("robot",),
            (),
            remove_start_pose,
            "ROBOT (without tasks) loses its start pose",
        ),
        Transformation(
            "move_obstacle",
            ("obstacle", "to"),
            (),
            move_obstacle,
            "OBSTACLE moves to TO: x,y or x,y,z in metres (same heading, model and size)",
        ),
        Transformation(
            "substitute_allocation",
            ("allocation",),
            (),
            substitute_allocation,
            "the mission becomes ALLOCATION: robot:task,robot:task,... in order",
        ),
        Transformation(
            "remove_robot",
            ("robot",),
            ("reassign",),
            remove_robot,
            "drop ROBOT (its tasks go to REASSIGN, or go)",
        ),
        Transformation(
            "add_robot",
            ("robot", "like", "start"),
            ("take_over",),
            add_robot,
            "a robot typed LIKE at START (taking over TAKE_OVER's tasks)",
        ),
        Transformation(
            "replace_robot",
            ("robot", "by"),
            ("like", "start"),
            replace_robot,
            "BY (typed LIKE) takes ROBOT's tasks, and its place (or starts at START)",
        ),
    )
}
