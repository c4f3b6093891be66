"""A navigation stack's goals: one per planned waypoint, on the executor's 50 Hz clock.

Where the method's dispatcher sends one goal per subtask and tracks its waypoints, a robot
driven through Nav2 or move_base gets one navigation goal per waypoint.  Each goal is accepted
when the executor starts its action, executes from the next sample on and ends, succeeded or
aborted, when the action ends.  A stack publishes its goals' statuses when one changes and
periodically, and keeps a finished goal in its status list for a while.
"""

from __future__ import annotations

import enum
import uuid
from dataclasses import dataclass

import numpy as np

from exsce_dsl.model import Pose
from exsce_dsl.sim.executor import GoalStatus, SimulatedExecution
from exsce_dsl.sim.motion import DT


class Phase(enum.Enum):
    ACCEPTED = "accepted"
    EXECUTING = "executing"
    SUCCEEDED = "succeeded"
    ABORTED = "aborted"


@dataclass(frozen=True)
class NavigationGoal:
    number: int
    """Per robot, from 1, in the order the goals were sent."""
    accepted: int
    """Sample at which the stack accepted the goal (the action's start)."""
    executing: int
    ended: int
    outcome: Phase
    target: Pose
    path: tuple[tuple[float, float], ...]
    """The planned path, from the robot's position at ``accepted`` to the target."""
    uuid: bytes
    """A seeded random version-4 UUID (16 bytes), as ROS 2 action clients make them."""

    def phase(self, sample: int) -> Phase | None:
        """The goal's phase at ``sample``; None before it was accepted."""
        if sample < self.accepted:
            return None
        if sample < self.executing:
            return Phase.ACCEPTED
        return Phase.EXECUTING if sample < self.ended else self.outcome


def navigation_goals(
    execution: SimulatedExecution, robot: str, rng: np.random.Generator
) -> list[NavigationGoal]:
    """The goals of ``robot``, in order; each gets its UUID from ``rng``."""
    goals = []
    actions = sorted((a for a in execution.actions if a.robot == robot), key=lambda a: a.start)
    for number, action in enumerate(actions, start=1):
        accepted, ended = _sample(action.start, execution.dt), _sample(action.end, execution.dt)
        goals.append(
            NavigationGoal(
                number,
                accepted,
                min(accepted + 1, ended),
                ended,
                Phase.SUCCEEDED if action.status is GoalStatus.SUCCEEDED else Phase.ABORTED,
                action.goal,
                action.path,
                uuid.UUID(bytes=rng.bytes(16), version=4).bytes,
            )
        )
    return goals


def status_samples(goals: list[NavigationGoal], samples: int, every: int) -> list[int]:
    """When a stack publishes its status list: at each change, and every ``every`` samples from the
    first goal on (until the end of the run)."""
    if not goals:
        return []
    changes = {s for g in goals for s in (g.accepted, g.executing, g.ended)}
    periodic = range(goals[0].accepted, samples, every)
    return sorted(s for s in changes.union(periodic) if s < samples)


def listed(
    goals: list[NavigationGoal], sample: int, keep: float, dt: float = DT
) -> list[tuple[NavigationGoal, Phase]]:
    """The goals in the status list at ``sample``, with their phases: accepted ones, and finished
    ones for ``keep`` seconds after they ended (samples ``dt`` apart)."""
    kept = int(round(keep / dt))
    return [(g, phase) for g in goals if (phase := g.phase(sample)) is not None and sample <= g.ended + kept]


def _sample(seconds: float, dt: float) -> int:
    return int(round(seconds / dt))
