"""Coverage: what a run's recording does not show, so that a verdict never claims more than it saw.

Ingestion checks each run before anything judges it and keeps what it found with the run: goals
still active when the recording ends (cut short), a robot with no data in part of its window,
gaps in a topic, a topic recorded far below its rate, a clock that jumps backwards.  A clause
whose metric reads such a topic (in the part of the run it looks at) is *inconclusive*, never
passed.  Each topic's recorded rate is kept too, so that a run can be compared with the rates of
the runs its baseline was built from.
"""

from __future__ import annotations

import datetime
import enum
from dataclasses import dataclass


class Shortfall(enum.Enum):
    """The ways a recording can fail to cover a run."""

    CUT_SHORT = "cut_short"
    """The recording ends while goals are still active, or the mission was cancelled or stopped."""
    NO_DATA = "no_data"
    """A robot's signal has no data in part of the robot's window."""
    GAP = "gap"
    """A topic has a gap between two messages longer than the threshold."""
    LOW_RATE = "low_rate"
    """A topic was recorded far below its rate (declared in the spec, or the baseline runs')."""
    CLOCK_JUMP = "clock_jump"
    """A clock (``/clock`` or a source's stamps) goes backwards: the timeline is broken."""


@dataclass(frozen=True)
class CoverageGap:
    """One thing a run's recording does not cover.

    ``metrics`` are the metrics whose values read the data concerned (empty: every metric of the
    run, e.g. when it was cut short); ``robot`` is None for the whole run; ``start``/``end`` bound
    the part of the run concerned on its timeline in wall time (None: unbounded on that side).
    """

    kind: Shortfall
    reason: str
    """A sentence for people: what is missing, where and when."""
    robot: str | None = None
    topic: str | None = None
    """The topic as the bag names it (None: not about one topic)."""
    metrics: tuple[str, ...] = ()
    start: datetime.datetime | None = None
    end: datetime.datetime | None = None

    def concerns(self, metric: str, robot: str | None) -> bool:
        """Whether this gap touches a clause about ``metric`` of ``robot`` (None: the mission's)."""
        if self.metrics and metric not in self.metrics:
            return False
        return self.robot is None or robot is None or self.robot == robot


@dataclass(frozen=True)
class TopicRate:
    """How densely a topic a metric reads was recorded in one run."""

    topic: str
    robot: str | None
    messages: int
    rate: float
    """Messages per second over the topic's part of the run's window (Hz)."""
    metrics: tuple[str, ...] = ()
    """The metrics whose values read it."""
