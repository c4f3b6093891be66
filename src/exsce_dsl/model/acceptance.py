"""Acceptance criteria as written, BDD style: what runs of a scenario must show.

``acceptance for scenario_c { scenario "moves safely" { given ... when ... then ... } }``
is an :class:`Acceptance` of :class:`Criterion` objects, each with its givens, its
*when* and its expectations (the *then* clauses).  The oracles layer turns each
expectation into one oracle per robot it is about (:mod:`exsce_dsl.oracles`).
Quantities are in SI units here (m, s, m/s); the unit as written rides along for
the formatter.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field

from exsce_dsl.errors import SourceLocation


class Quantifier(enum.Enum):
    EACH_ROBOT = "each robot"
    ROBOT = "robot"
    """One robot, named."""
    MISSION = "mission"
    """No robot: a metric of the whole mission (mission_duration, distance_between_robots)."""


@dataclass(frozen=True)
class Subject:
    """Whom a clause is about: ``each robot``, ``tiago1``, or the mission."""

    quantifier: Quantifier
    robot: str | None = None

    def __post_init__(self) -> None:
        assert (self.robot is not None) == (self.quantifier is Quantifier.ROBOT)

    def text(self) -> str:
        return self.robot or ("each robot" if self.quantifier is Quantifier.EACH_ROBOT else "")


@dataclass(frozen=True)
class Quantity:
    """A number with its unit: ``value`` in SI units (m, s, m/s), or in std or %."""

    value: float
    unit: str | None = None
    """As written: ``m/s``, ``cm``, ``s``, ``min``, ``std``, ``%``...; None for a bare number."""
    written: str = field(default="", compare=False)
    """The number as written (``1.0``, ``.5``), for the formatter."""

    def text(self) -> str:
        number = self.written or repr(self.value)
        return f"{number} {self.unit}" if self.unit else number


class BasicRelation(enum.Enum):
    """The method's basic output relations."""

    BELOW_MAX = "below_max"
    ABOVE_MIN = "above_min"
    INVARIANT = "invariant"
    INCREASING = "increasing"
    DECREASING = "decreasing"


class Moment(enum.Enum):
    DURING = "during"
    BEFORE = "before"
    AFTER = "after"


@dataclass(frozen=True)
class Window:
    """Part of a run a clause looks at: during, before or after a robot's task, or
    before or after a robot reaches a pose.  Only segment metrics can be windowed."""

    moment: Moment
    robot: str
    task: str | None = None
    pose: str | None = None
    """The pose whose reaching is the event (with ``task`` None)."""
    location: SourceLocation | None = field(default=None, compare=False, repr=False)

    def text(self) -> str:
        if self.task is not None:
            return f"{self.moment.value} {self.task}"
        return f"{self.moment.value} {self.robot} reaches {self.pose}"


@dataclass(frozen=True)
class Expectation:
    """One *then* clause: ``each robot max_velocity stays below 1.0 m/s``.

    ``against`` is None for the scenario's own baseline (its past runs), or the
    scenario whose runs a derived scenario's runs are compared with (metamorphic).
    ``tolerance`` of None means one standard deviation of the baseline for
    ``invariant`` around the baseline's mean, and none (exactly) around a fixed value
    and for ``increasing`` and ``decreasing``.  ``confidence`` (``at 99 %``, an ``invariant``
    around the baseline's or base's mean only) replaces a written tolerance: the band is the
    prediction interval for one new run given the runs the mean comes from.
    """

    subject: Subject
    metric: str
    relation: BasicRelation
    limit: Quantity | None = None
    value: Quantity | None = None
    """A fixed expected value (``around 97.6 s``, ``from 40 s``); else the baseline's or base's mean."""
    delta: Quantity | None = None
    tolerance: Quantity | None = None
    against: str | None = None
    window: Window | None = None
    location: SourceLocation | None = field(default=None, compare=False, repr=False)
    confidence: Quantity | None = None
    """``at 99 %``: in per cent as written, strictly between 50 and 100 (no ``tolerance`` then)."""

    def __post_init__(self) -> None:
        assert self.confidence is None or self.tolerance is None, "a band is a tolerance or a confidence"

    @property
    def confidence_level(self) -> float | None:
        """The confidence as a fraction (0.99 for ``at 99 %``), None without one."""
        return None if self.confidence is None else self.confidence.value / 100.0


@dataclass(frozen=True)
class AtStartPose:
    """``given each robot at its start pose``: each run starts from the scenario's start poses."""

    subject: Subject
    location: SourceLocation | None = field(default=None, compare=False, repr=False)


@dataclass(frozen=True)
class BaselineRuns:
    """``given at least 5 baseline runs``: how many stored runs a baseline needs."""

    runs: int
    location: SourceLocation | None = field(default=None, compare=False, repr=False)


Given = AtStartPose | BaselineRuns


@dataclass(frozen=True)
class When:
    """``when mission_c runs`` (the whole run), or ``when tiago1 does delivery_a``
    (the clauses look at that task only, unless they name a window of their own)."""

    mission: str | None = None
    robot: str | None = None
    task: str | None = None
    location: SourceLocation | None = field(default=None, compare=False, repr=False)

    def text(self) -> str:
        return f"{self.mission} runs" if self.mission else f"{self.robot} does {self.task}"


@dataclass(frozen=True)
class Criterion:
    """One BDD scenario of acceptance criteria."""

    title: str
    givens: tuple[Given, ...]
    when: When | None
    expectations: tuple[Expectation, ...]
    location: SourceLocation | None = field(default=None, compare=False, repr=False)


DEFAULT_BASELINE_RUNS = 3


@dataclass(frozen=True)
class Acceptance:
    """The acceptance criteria of one scenario."""

    scenario: str
    criteria: tuple[Criterion, ...]
    location: SourceLocation | None = field(default=None, compare=False, repr=False)

    @property
    def baseline_runs(self) -> int:
        """The runs a baseline needs: the largest ``given at least N baseline runs``, else 3."""
        asked = [g.runs for c in self.criteria for g in c.givens if isinstance(g, BaselineRuns)]
        return max(asked, default=DEFAULT_BASELINE_RUNS)

    def expectations(self) -> tuple[Expectation, ...]:
        return tuple(e for c in self.criteria for e in c.expectations)
