"""Tasks: reusable plans of subtasks, each an ordered list of waypoints."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field

from exsce_dsl.errors import SourceLocation
from exsce_dsl.model.environment import RosResource
from exsce_dsl.model.geometry import Pose


@dataclass(frozen=True)
class Subtask:
    waypoints: tuple[Pose, ...]
    location: SourceLocation | None = field(default=None, compare=False, repr=False)


@dataclass(frozen=True)
class Task:
    """A plan. ``source`` is the method's task file it came from, if any."""

    id: str
    subtasks: tuple[Subtask, ...]
    source: RosResource | None = None
    location: SourceLocation | None = field(default=None, compare=False, repr=False)
    timeout: float | None = None
    """Seconds each of its goals may take (``timeout 120 s``); wins over the mission's."""
    timeout_written: str | None = field(default=None, compare=False, repr=False)
    """The timeout as the author wrote it (``2 min``), for the formatter."""

    def waypoints(self) -> Iterator[Pose]:
        for subtask in self.subtasks:
            yield from subtask.waypoints
