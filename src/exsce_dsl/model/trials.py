"""Trials: N runs of one scenario judged by the same oracles, and what they say of each clause.

One run's verdict says whether a clause held once; a trial says how often it holds.  Each clause
(an oracle with its relation, the scenario it compares against and its window) gets the count of
runs that passed, failed or could not be judged, its pass rate over the judged runs with a
Wilson score interval, and a :class:`TrialOutcome` that compares that interval with the pass rate
the user requires (:mod:`exsce_dsl.oracles.trials` computes them).
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

from exsce_dsl.model.verdicts import Verdict


class TrialOutcome(enum.Enum):
    PASSED = "passed"
    """The interval's lower bound reaches the required pass rate: the clause holds often enough."""
    FAILED = "failed"
    """The interval's upper bound is below the required pass rate: it fails too often."""
    FLAKY = "flaky"
    """Runs passed and failed, and the interval straddles the required pass rate: a test that
    cannot be trusted to pass."""
    INCONCLUSIVE = "inconclusive"
    """Too few runs to tell (all judged runs agreed, but not enough of them), or none judged."""


@dataclass(frozen=True)
class ClauseKey:
    """What makes verdicts of several runs verdicts on one clause."""

    scenario: str
    oracle: str
    relation: str
    against: str | None
    window: str | None

    @classmethod
    def of(cls, verdict: Verdict) -> ClauseKey:
        return cls(verdict.scenario, verdict.oracle, verdict.relation, verdict.against, verdict.window)


@dataclass(frozen=True)
class ClauseTrial:
    """One clause over the runs of a trial: counts, pass rate, its interval, the outcome."""

    key: ClauseKey
    metric: str
    robot: str | None
    criterion: str
    passed: int
    failed: int
    inconclusive: int
    low: float | None
    """The Wilson interval's lower bound of the pass rate (None: no run judged)."""
    high: float | None
    outcome: TrialOutcome
    reason: str
    """Why the outcome is what it is, in a sentence (counts, interval, threshold)."""
    required_pass_rate: float
    confidence: float
    runs: tuple[str, ...] = ()
    """The runs whose verdicts were counted (uuids)."""
    runs_needed: int | None = None
    """For a clause inconclusive for too few runs: how many agreeing runs would settle it."""

    @property
    def judged(self) -> int:
        return self.passed + self.failed

    @property
    def pass_rate(self) -> float | None:
        """Passed over judged runs (None: none judged)."""
        return self.passed / self.judged if self.judged else None

    @property
    def description(self) -> str:
        """``tiago1 max_velocity below_max during delivery_a``: the clause, without its bound (which
        a rebuilt baseline may have moved between runs)."""
        who = f"{self.robot} " if self.robot else ""
        against = f" of {self.key.against}" if self.key.against else ""
        window = f" {self.key.window}" if self.key.window else ""
        return f"{who}{self.metric} {self.key.relation}{against}{window}"


@dataclass(frozen=True)
class Trial:
    """The verdicts of every run of a trial and each clause's statistics."""

    scenario: str
    runs: tuple[str, ...]
    verdicts: tuple[Verdict, ...]
    clauses: tuple[ClauseTrial, ...]
    required_pass_rate: float
    confidence: float
    warnings: tuple[str, ...] = ()

    def count(self, outcome: TrialOutcome) -> int:
        return sum(c.outcome is outcome for c in self.clauses)

    @property
    def outcome(self) -> TrialOutcome:
        """The trial's outcome: failed if a clause failed, else flaky if one is, else
        inconclusive if one is, else passed."""
        for worst in (TrialOutcome.FAILED, TrialOutcome.FLAKY, TrialOutcome.INCONCLUSIVE):
            if self.count(worst):
                return worst
        return TrialOutcome.PASSED
