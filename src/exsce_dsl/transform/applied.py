"""What applying input transformations gives, and the helpers the transformations share:
the robot or pose a name says (an error with a did-you-mean otherwise), a scenario with a
new allocation, the step a transformation records."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace

from exsce_dsl.errors import ExsceError
from exsce_dsl.model import Assignment, Pose, Robot, Scenario, Task
from exsce_dsl.model.derivation import ParameterValue, TaskOrigin, TransformationStep
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


def recorded(name: str, **arguments: ParameterValue | None) -> TransformationStep:
    """The step transformation ``name`` records: the arguments given (not None), in order."""
    return TransformationStep(name, tuple((k, v) for k, v in arguments.items() if v is not None))


def robot_of(scenario: Scenario, robot_id: str) -> Robot:
    robot = scenario.robot(robot_id)
    if robot is None:
        known = [r.id for r in scenario.robots]
        raise ExsceError(f"scenario '{scenario.id}' has no robot '{robot_id}'{did_you_mean(robot_id, known)}")
    return robot


def with_allocation(
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


def pose_of(scenario: Scenario, pose_id: str) -> Pose:
    poses = {p.id: p for p in scenario.environment.poses()}
    if pose_id not in poses:
        hint = did_you_mean(pose_id, poses)
        raise ExsceError(f"environment '{scenario.environment.id}' has no pose '{pose_id}'{hint}")
    return poses[pose_id]
