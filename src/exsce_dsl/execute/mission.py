"""The mission as a schedule of navigation goals, one per waypoint, built from the semantic model.

A ``parallel`` mission has one lane per robot: each robot works through its own allocation
entries in order, the robots side by side.  A ``sequential`` mission has one lane: the allocation
in its written order, one robot at a time.  A lane has at most one goal active at any time.

Every goal has a timeout, the first of: its task's (``timeout 120 s`` in the task), its
mission's (``timeout 2 min`` in the mission), the one the caller gives, or by default
``max(TIMEOUT_FLOOR, TIMEOUT_FACTOR * distance / speed)`` where ``distance`` is the straight
line from the robot's previous waypoint (its start pose for its first goal) to the goal and
``speed`` the robot's speed limit (``speeds[robot]``, else ``DEFAULT_SPEED``, the kinematic
executor's).  A path round walls is longer than the straight line; the factor leaves room for it
and for turning on the spot.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from exsce_dsl.errors import ExsceError
from exsce_dsl.model import MissionType, Pose, Scenario
from exsce_dsl.sim.motion import Limits

TIMEOUT_FLOOR = 60.0
"""Seconds: no goal times out sooner (a short leg still needs the stack to plan and turn)."""
TIMEOUT_FACTOR = 3.0
"""How many times the straight-line time at the speed limit a goal may take."""
DEFAULT_SPEED = Limits().max_speed
"""m/s: a robot's speed limit when the caller gives none (the kinematic executor's)."""


@dataclass(frozen=True)
class Goal:
    """One navigation goal: a waypoint of a subtask of a task allocated to a robot."""

    robot: str
    task: str
    task_number: int
    """Per robot, from 1, in allocation order (the method's ``task_NN``)."""
    subtask: int
    """From 1, inside the task."""
    waypoint: int
    """From 1, inside the subtask."""
    pose: Pose
    timeout: float
    """Seconds the goal may take, per attempt."""

    @property
    def task_key(self) -> tuple[str, int]:
        """Which allocation entry the goal belongs to (a robot may do the same task twice)."""
        return self.robot, self.task_number


@dataclass(frozen=True)
class Schedule:
    """The goals of a mission, in lanes that run side by side; each lane's goals one at a time."""

    scenario: str
    mission: str
    type: MissionType
    lanes: tuple[tuple[Goal, ...], ...]

    @property
    def goals(self) -> tuple[Goal, ...]:
        """Every goal, lane after lane."""
        return tuple(g for lane in self.lanes for g in lane)


def goal_timeout(distance: float, speed: float) -> float:
    """The default timeout of a goal ``distance`` metres away for a robot at most ``speed`` m/s fast."""
    if speed <= 0:
        raise ExsceError(f"a robot's speed limit must be above 0 m/s, not {speed:g}")
    return max(TIMEOUT_FLOOR, TIMEOUT_FACTOR * distance / speed)


def schedule(
    scenario: Scenario,
    speeds: Mapping[str, float] | None = None,
    timeout: float | None = None,
) -> Schedule:
    """The schedule of ``scenario``'s mission; ``timeout`` (seconds) replaces the default timeout
    of goals whose task and mission give none."""
    if timeout is not None and timeout <= 0:
        raise ExsceError(f"a goal timeout must be above 0 s, not {timeout:g}")
    speeds = speeds or {}
    mission_timeout = scenario.mission.timeout
    for given, whose in [(mission_timeout, f"mission '{scenario.mission.id}'")] + [
        (t.timeout, f"task '{t.id}'") for t in scenario.tasks
    ]:
        if given is not None and given <= 0:
            raise ExsceError(f"the goal timeout of {whose} must be above 0 s, not {given:g}")
    previous: dict[str, Pose | None] = {r.id: r.start_pose for r in scenario.robots}
    numbers: dict[str, int] = {}
    entries: list[tuple[str, tuple[Goal, ...]]] = []
    for assignment in scenario.mission.allocation:
        robot, task = assignment.robot, scenario.task(assignment.task)
        if task is None or robot not in previous:
            missing = f"task '{assignment.task}'" if task is None else f"robot '{robot}'"
            raise ExsceError(f"mission '{scenario.mission.id}' allocates an unknown {missing}")
        numbers[robot] = numbers.get(robot, 0) + 1
        goals = []
        for s_number, subtask in enumerate(task.subtasks, start=1):
            for w_number, pose in enumerate(subtask.waypoints, start=1):
                before = previous[robot]
                limit = next((t for t in (task.timeout, mission_timeout, timeout) if t is not None), None)
                if limit is None:
                    distance = 0.0 if before is None else before.position.distance_to(pose.position)
                    limit = goal_timeout(distance, speeds.get(robot, DEFAULT_SPEED))
                goals.append(Goal(robot, task.id, numbers[robot], s_number, w_number, pose, limit))
                previous[robot] = pose
        entries.append((robot, tuple(goals)))
    lanes: tuple[tuple[Goal, ...], ...]
    if scenario.mission.type is MissionType.SEQUENTIAL:
        lanes = (tuple(g for _, goals in entries for g in goals),)
    else:
        robots = [r.id for r in scenario.robots if any(robot == r.id for robot, _ in entries)]
        lanes = tuple(tuple(g for robot, goals in entries if robot == r for g in goals) for r in robots)
    return Schedule(scenario.id, scenario.mission.id, scenario.mission.type, lanes)
