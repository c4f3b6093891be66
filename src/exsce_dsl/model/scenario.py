"""Scenarios: a mission, robots and an environment under one id."""

from __future__ import annotations

import enum
from dataclasses import dataclass, field

from exsce_dsl.errors import SourceLocation
from exsce_dsl.model.environment import Environment
from exsce_dsl.model.metrics import MetricDefinition
from exsce_dsl.model.robots import Robot
from exsce_dsl.model.tasks import Task


class MissionType(enum.Enum):
    PARALLEL = "parallel"
    """Each robot runs its own tasks one at a time, robots side by side."""
    SEQUENTIAL = "sequential"
    """One robot executes a task at any time."""


@dataclass(frozen=True)
class Assignment:
    """One entry of an allocation: this robot does this task."""

    robot: str
    task: str
    location: SourceLocation | None = field(default=None, compare=False, repr=False)


@dataclass(frozen=True)
class Mission:
    id: str
    type: MissionType
    allocation: tuple[Assignment, ...]
    """In execution order; per robot, the order of its tasks."""
    location: SourceLocation | None = field(default=None, compare=False, repr=False)
    timeout: float | None = None
    """Seconds each goal may take unless its task gives its own (``timeout 2 min``)."""
    timeout_written: str | None = field(default=None, compare=False, repr=False)
    """The timeout as the author wrote it, for the formatter."""

    def tasks_of(self, robot_id: str) -> tuple[str, ...]:
        return tuple(a.task for a in self.allocation if a.robot == robot_id)


@dataclass(frozen=True)
class Scenario:
    """A whole scenario, with every element it uses resolved."""

    id: str
    environment: Environment
    robots: tuple[Robot, ...]
    mission: Mission
    tasks: tuple[Task, ...]
    """The tasks the mission allocates, each once, in order of first use."""
    location: SourceLocation | None = field(default=None, compare=False, repr=False)
    metrics: tuple[MetricDefinition, ...] = field(default=(), compare=False, repr=False)
    """The metrics its specification declares (the standard library's are not repeated here)."""

    def robot(self, robot_id: str) -> Robot | None:
        return next((r for r in self.robots if r.id == robot_id), None)

    def task(self, task_id: str) -> Task | None:
        return next((t for t in self.tasks if t.id == task_id), None)
