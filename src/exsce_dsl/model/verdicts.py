"""Verdicts: what judging a run against its scenario's oracles found."""

from __future__ import annotations

import enum
from dataclasses import dataclass

from exsce_dsl.model.coverage import Shortfall


class Outcome(enum.Enum):
    PASSED = "passed"
    FAILED = "failed"
    INCONCLUSIVE = "inconclusive"
    """Could not be judged: the data the clause needs is missing, too sparse, cut short or on a broken
    clock, or the oracle has no expectation yet; ``reason`` says why.  Never a pass."""

    @classmethod
    def _missing_(cls, value: object) -> Outcome | None:
        # stores written before the outcome was named 'inconclusive' say 'unjudged'
        return cls.INCONCLUSIVE if value == "unjudged" else None


@dataclass(frozen=True)
class Verdict:
    """One oracle applied to one run.

    ``expected`` is the baseline or base value the relation compares with (None
    for a limit), ``limit`` the bound of ``below_max`` / ``above_min``.  ``margin``
    is how far the observed value is inside the relation's bound (negative: by
    how much it is outside).  ``sources`` are the runs the expectation came from.
    """

    run: str
    scenario: str
    criterion: str
    """The title of the acceptance scenario the oracle comes from ('' for an oracle from the store only)."""
    oracle: str
    """The oracle's id, e.g. ``tiago1-max_velocity`` or ``mission_duration``."""
    metric: str
    robot: str | None
    relation: str
    outcome: Outcome
    observed: float | None = None
    expected: float | None = None
    limit: float | None = None
    delta: float | None = None
    tolerance: float | None = None
    margin: float | None = None
    window: str | None = None
    """The part of the run looked at (``during delivery_a``), None for the whole run."""
    sources: tuple[str, ...] = ()
    reason: str = ""
    against: str | None = None
    """For a metamorphic oracle, the base scenario whose runs it compares the run with (None:
    the run's own scenario).  A derived scenario can have both about one metric."""
    shortfalls: tuple[Shortfall, ...] = ()
    """What the recording did not cover of the part of the run the clause looks at (cut short, a
    gap, a thinned topic...): why an inconclusive verdict is one, or what a failed limit was not
    judged on (it failed on what was recorded)."""
    topics: tuple[str, ...] = ()
    """The bag topics the judged run's value was computed from, as the store's value names them
    (its odometry, ``/cmd_vel`` or TF for a Nav2 robot, not the method's ``/nav_vel``); written
    to the verdict's PROV, not read back from it."""

    @property
    def description(self) -> str:
        """``tiago1 max_velocity below_max 1.0`` — a line for people and test reports."""
        who = f"{self.robot} " if self.robot else ""
        bound = self.limit if self.limit is not None else self.expected
        shown = f" {bound:g}" if bound is not None else ""
        window = f" {self.window}" if self.window else ""
        against = f" of {self.against}" if self.against else ""
        return f"{who}{self.metric} {self.relation}{shown}{against}{window}"
