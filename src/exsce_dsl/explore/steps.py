"""Every applicable single step of a scenario: each transformation with concrete arguments drawn
from the scenario, kept when applying it succeeds.  The transformation is its own precondition:
nothing here re-checks what it checks.

Each transformation has a proposer (:data:`PROPOSERS`, one entry per transformation) that names
the arguments worth trying.  Bounds, so that a step's neighbours stay in the hundreds:

- poses (``add_start_pose``'s pose, ``add_robot``'s start) and obstacle targets
  (``move_obstacle``'s ``to``) are at most :data:`MAX_POSES` of the environment's poses, spread
  evenly over the order they are declared (the free ones, for start poses);
- ``add_robot`` is tried once per robot type of the fleet (``like`` its first robot), and mints
  one id; ``replace_robot`` tries the robot's own type and each other type of the fleet, at the
  robot's start pose, and its own type at each of the free poses (a robot of the same kind that
  starts elsewhere);
- ``add_task`` puts a task at the end of a robot's tasks (the default) or first;
- ``substitute_allocation`` tries two rotations of the current allocation: its entries one place
  on (the first last), and its robots one place on (each entry to the next robot of the fleet);
- everything else is tried for every robot, pair of robots, allocated or declared task.

New ids (``add_robot``'s and ``replace_robot``'s robot, a reversed task's ``as`` when its default
is taken) are minted as ``STEM_1``, ``STEM_2``, ... : the first that is a valid name and free.
"""

from __future__ import annotations

from collections.abc import Callable, Collection, Iterator, Mapping, Sequence
from dataclasses import dataclass
from itertools import combinations

from exsce_dsl.errors import ExsceError
from exsce_dsl.model import Pose, Robot, Scenario, Task
from exsce_dsl.model.names import is_valid_name
from exsce_dsl.transform import TRANSFORMATIONS, Applied, Arguments, Request

MAX_POSES = 6
ROBOT_STEM = "new_robot"


@dataclass(frozen=True)
class ProposedStep:
    """One transformation with its arguments, and what applying it gave."""

    name: str
    arguments: tuple[tuple[str, str], ...]
    applied: Applied

    @property
    def request(self) -> Request:
        return (self.name, dict(self.arguments))


def applicable_steps(
    scenario: Scenario, tasks: Mapping[str, Task], transformations: Collection[str] | None = None
) -> list[ProposedStep]:
    """The steps that apply to ``scenario``, in a fixed order (transformations as registered,
    arguments as proposed); ``tasks`` are those the spec declares (and earlier steps made);
    ``transformations`` keeps only those names."""
    known = dict(tasks) | {t.id: t for t in scenario.tasks}
    found: list[ProposedStep] = []
    tried: set[tuple[str, tuple[tuple[str, str], ...]]] = set()
    for name, propose in PROPOSERS.items():
        if transformations is not None and name not in transformations:
            continue
        for arguments in propose(scenario, known):
            key = (name, tuple(arguments.items()))
            if key in tried:
                continue
            tried.add(key)
            try:
                applied = TRANSFORMATIONS[name].apply(scenario, arguments, known)
            except ExsceError:
                continue
            found.append(ProposedStep(name, key[1], applied))
    return found


def mint(stem: str, taken: Collection[str]) -> str:
    """``STEM_1``, ``STEM_2``, ...: the first that is a valid id and not ``taken``."""
    n = 1
    while not is_valid_name(f"{stem}_{n}") or f"{stem}_{n}" in taken:
        n += 1
    return f"{stem}_{n}"


def _spread(items: Sequence[Pose], limit: int = MAX_POSES) -> list[Pose]:
    """At most ``limit`` of ``items``, evenly spaced, in their order."""
    if len(items) <= limit:
        return list(items)
    return [items[n * len(items) // limit] for n in range(limit)]


def _free_poses(scenario: Scenario) -> list[Pose]:
    taken = {r.start_pose.id for r in scenario.robots if r.start_pose is not None}
    return _spread([p for p in scenario.environment.poses() if p.id not in taken])


def _one_per_type(scenario: Scenario) -> list[Robot]:
    first: dict[str, Robot] = {}
    for robot in scenario.robots:
        first.setdefault(robot.type.id, robot)
    return list(first.values())


def _allocated(scenario: Scenario) -> list[str]:
    return list(dict.fromkeys(a.task for a in scenario.mission.allocation))


def _add_task(s: Scenario, tasks: Mapping[str, Task]) -> Iterator[Arguments]:
    for robot in s.robots:
        for task in tasks:
            yield {"robot": robot.id, "task": task}
            if s.mission.tasks_of(robot.id):
                yield {"robot": robot.id, "task": task, "position": "1"}


def _remove_task(s: Scenario, tasks: Mapping[str, Task]) -> Iterator[Arguments]:
    for task in _allocated(s):
        yield {"task": task}
    for robot in s.robots:
        yield {"robot": robot.id}
    for entry in s.mission.allocation:
        yield {"task": entry.task, "robot": entry.robot}


def _substitute_task(s: Scenario, tasks: Mapping[str, Task]) -> Iterator[Arguments]:
    for old in _allocated(s):
        yield from ({"task": old, "with": new} for new in tasks if new != old)


def _pairs(s: Scenario, tasks: Mapping[str, Task]) -> Iterator[Arguments]:
    for first, second in combinations(s.robots, 2):
        yield {"robot": first.id, "with": second.id}


def _reverse_task_order(s: Scenario, tasks: Mapping[str, Task]) -> Iterator[Arguments]:
    yield {}
    yield from ({"robot": r.id} for r in s.robots)


def _reverse_waypoint_order(s: Scenario, tasks: Mapping[str, Task]) -> Iterator[Arguments]:
    for task in _allocated(s):
        default = f"{task}_reversed"
        if is_valid_name(default) and default not in tasks:
            yield {"task": task}
        else:
            yield {"task": task, "as": mint(default, tasks)}


def _add_start_pose(s: Scenario, tasks: Mapping[str, Task]) -> Iterator[Arguments]:
    for robot in s.robots:
        if robot.start_pose is None:
            yield from ({"robot": robot.id, "pose": p.id} for p in _free_poses(s))


def _each_robot(s: Scenario, tasks: Mapping[str, Task]) -> Iterator[Arguments]:
    yield from ({"robot": r.id} for r in s.robots)


def _move_obstacle(s: Scenario, tasks: Mapping[str, Task]) -> Iterator[Arguments]:
    targets = _spread(list(s.environment.poses()))
    for obstacle in s.environment.obstacles:
        for pose in targets:
            yield {"obstacle": obstacle.id, "to": f"{pose.position.x!r},{pose.position.y!r}"}


def _substitute_allocation(s: Scenario, tasks: Mapping[str, Task]) -> Iterator[Arguments]:
    entries = [(a.robot, a.task) for a in s.mission.allocation]
    robots = [r.id for r in s.robots]
    following = {r: robots[(n + 1) % len(robots)] for n, r in enumerate(robots)}
    for rotated in (entries[1:] + entries[:1], [(following.get(r, r), t) for r, t in entries]):
        if rotated != entries:
            yield {"allocation": ",".join(f"{r}:{t}" for r, t in rotated)}


def _remove_robot(s: Scenario, tasks: Mapping[str, Task]) -> Iterator[Arguments]:
    for robot in s.robots:
        yield {"robot": robot.id}
        yield from ({"robot": robot.id, "reassign": h.id} for h in s.robots if h.id != robot.id)


def _add_robot(s: Scenario, tasks: Mapping[str, Task]) -> Iterator[Arguments]:
    new = mint(ROBOT_STEM, [r.id for r in s.robots])
    for like in _one_per_type(s):
        for pose in _free_poses(s):
            yield {"robot": new, "like": like.id, "start": pose.id}
            for donor in s.robots:
                if s.mission.tasks_of(donor.id):
                    yield {"robot": new, "like": like.id, "start": pose.id, "take_over": donor.id}


def _replace_robot(s: Scenario, tasks: Mapping[str, Task]) -> Iterator[Arguments]:
    new = mint(ROBOT_STEM, [r.id for r in s.robots])
    for robot in s.robots:
        yield {"robot": robot.id, "by": new}
        for like in _one_per_type(s):
            if like.type.id != robot.type.id:
                yield {"robot": robot.id, "by": new, "like": like.id}
        yield from ({"robot": robot.id, "by": new, "start": p.id} for p in _free_poses(s))


Proposer = Callable[[Scenario, Mapping[str, Task]], Iterator[Arguments]]

PROPOSERS: dict[str, Proposer] = {
    "add_task": _add_task,
    "remove_task": _remove_task,
    "substitute_task": _substitute_task,
    "swap_assignment": _pairs,
    "reverse_task_order": _reverse_task_order,
    "reverse_waypoint_order": _reverse_waypoint_order,
    "swap_start_poses": _pairs,
    "add_start_pose": _add_start_pose,
    "remove_start_pose": _each_robot,
    "move_obstacle": _move_obstacle,
    "substitute_allocation": _substitute_allocation,
    "remove_robot": _remove_robot,
    "add_robot": _add_robot,
    "replace_robot": _replace_robot,
} | {name: t.propose for name, t in TRANSFORMATIONS.items() if t.propose is not None}
"""The arguments worth trying, per transformation (every transformation has one: a test checks);
a transformation's record may carry its own (``propose``)."""
