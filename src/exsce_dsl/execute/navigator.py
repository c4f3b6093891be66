"""What the dispatcher needs of a robot stack and of time: send goals, cancel them, learn outcomes.

An adapter per middleware (ROS 1 actionlib, ROS 2 actions) and the kinematic navigator of the
tests (``tests/support/kinematic_navigator.py``) implement :class:`Navigator`.  Time comes from a
:class:`Clock` the caller gives: the ROS clock (simulated time under ``/clock``) or
:class:`SimulatedClock`, which only moves when a simulated navigator advances it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

from exsce_dsl.execute.outcomes import GoalOutcome
from exsce_dsl.model import Pose


class Clock(Protocol):
    def now(self) -> float:
        """Seconds, on the clock the run's time stamps use."""
        ...


@dataclass(frozen=True)
class Finished:
    """A goal's end, as its robot's stack reported it."""

    goal: int
    """The number the dispatcher gave the goal when it sent it."""
    outcome: GoalOutcome
    """SUCCEEDED, ABORTED or REJECTED."""
    time: float


class Navigator(Protocol):
    def send(self, goal: int, robot: str, pose: Pose) -> None:
        """Send ``robot`` the navigation goal ``pose``, numbered ``goal`` (unique in a run)."""
        ...

    def cancel(self, goal: int) -> None:
        """Cancel an active goal; its end is not reported afterwards."""
        ...

    def next_finished(self, deadline: float) -> Finished | None:
        """Wait for the next goal to end, at the latest until ``deadline`` on the clock; None if
        none ended by then (the clock then reads ``deadline`` or later)."""
        ...


class SimulatedClock:
    """A clock that stands still until it is advanced."""

    def __init__(self, start: float = 0.0) -> None:
        self._now = start

    def now(self) -> float:
        return self._now

    def advance_to(self, t: float) -> None:
        """Move the clock to ``t`` (never back)."""
        self._now = max(self._now, t)
