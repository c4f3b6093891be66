"""What an exploration campaign did, as it is written to the store and read back: the campaign
itself, each derivation it tried (a *trial*) and each violation it shrank.

A *checked relation* here is one oracle of a derived scenario, named by what it checks (robot, metric,
relationship), not by the scenario: the same relation can then be looked for in a smaller
derivation, whose scenario has another id.
"""

from __future__ import annotations

import datetime
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

Request = tuple[str, Mapping[str, str]]
"""A transformation step as ``derive`` takes it: ``("remove_robot", {"robot": "tiago2"})``."""


@dataclass(frozen=True)
class CheckedRelation:
    """What an oracle checks: ``tiago1 task_duration invariant``, ``tiago1 task_duration
    increasing vs scenario_c`` (a metamorphic relation to the base's runs)."""

    metric: str
    robot: str | None
    relationship: str
    against: str | None = None

    @property
    def text(self) -> str:
        against = f"vs {self.against}" if self.against else None
        return " ".join(p for p in (self.robot, self.metric, self.relationship, against) if p)

    def same_check(self, other: CheckedRelation) -> bool:
        """Whether ``other`` checks the same thing: the same metric of the same robot, against
        the same scenario, by the same limit, or by an expected value whichever way it moved
        (the direction, ``increasing`` or ``invariant``, comes from the estimate, which a
        smaller derivation changes)."""
        expected = {"invariant", "increasing", "decreasing"}
        return (self.metric, self.robot, self.against) == (other.metric, other.robot, other.against) and (
            self.relationship == other.relationship or {self.relationship, other.relationship} <= expected
        )

    @classmethod
    def parse(cls, text: str) -> CheckedRelation:
        """The inverse of :attr:`text`."""
        words = text.split()
        against = None
        if len(words) >= 2 and words[-2] == "vs":
            against, words = words[-1], words[:-2]
        if len(words) == 2:
            return cls(words[0], None, words[1], against)
        robot, metric, relationship = words
        return cls(metric, robot, relationship, against)


@dataclass(frozen=True)
class CampaignPlan:
    """How a campaign explores; its id comes from all of it but the budget (a larger budget, the
    same command otherwise, goes on with the same campaign)."""

    id: str
    base: str
    """The base scenario's id."""
    budget: int
    seed: int
    runs_per_scenario: int
    max_steps: int
    transformations: tuple[str, ...]
    """Only these transformations (empty: every one)."""
    executor: str
    """What executed the runs: ``simulator``, ``simulator --fault slow-area:classroom_c069``, a command."""
    strategy: str
    relations: bool
    """Whether derived scenarios are checked against their metamorphic relations (else their
    base's safety limits only)."""
    tolerance: float
    """Percent of an expected value a run may be off."""


@dataclass(frozen=True)
class CampaignTrial:
    """One derivation tried: its scenario, its runs, and the relations checked and violated."""

    campaign: str
    number: int
    """1, 2, ...: the order of the draws."""
    scenario: str
    steps: tuple[Request, ...]
    runs: tuple[str, ...]
    checked: tuple[CheckedRelation, ...]
    violated: tuple[CheckedRelation, ...]
    """Failed in more than half of the runs."""
    failing_verdicts: tuple[tuple[str, str], ...] = ()
    """``(run uuid, verdict local name)`` of every failed verdict of a violated relation."""
    inconclusive: tuple[CheckedRelation, ...] = ()
    """Not violated, but they would be had the runs that could not judge them (cut short, not
    covered by their recordings) failed them: neither passed nor counterexamples."""

    @property
    def outcome(self) -> str:
        """``violated``, ``inconclusive`` (nothing violated, but something undecided), ``passed``
        or ``unchecked`` (no relation to check)."""
        if self.violated:
            return "violated"
        if self.inconclusive:
            return "inconclusive"
        return "passed" if self.checked else "unchecked"


@dataclass(frozen=True)
class CampaignFigures:
    """What a campaign's trials found, in the figures falsification tools report: counterexamples
    per 100 executions and executions to the first failure.  An *execution* is one run of a
    drawn derivation (the base's runs and the shrinkings' are not draws and are not counted); a
    *counterexample* is a trial that violated a relation."""

    trials: int
    executions: int
    counterexamples: int
    """Trials that violated at least one relation."""
    violated_relations: int
    """Distinct relations violated, one per check (:meth:`CheckedRelation.same_check`), as shrinking
    counts them."""
    inconclusive: int
    """Trials neither violated nor passed (:attr:`Trial.inconclusive`): counted in ``executions``
    (their runs were executed) but neither as counterexamples nor as passes."""
    executions_to_first_failure: int | None
    """Executions in draw order up to and with the first violating trial's; None when none violated."""
    inconclusive_relations: int = 0
    """Distinct relations inconclusive in some trial and violated in none, counted as
    ``violated_relations`` is (one per check): a trial may leave several undecided, so this is
    not ``inconclusive`` (trials)."""

    @property
    def per_100_executions(self) -> float | None:
        """Counterexamples per 100 executions; None when nothing was executed."""
        return 100 * self.counterexamples / self.executions if self.executions else None

    @classmethod
    def of(cls, trials: Sequence[CampaignTrial]) -> CampaignFigures:
        """The figures of ``trials`` in the order they were drawn."""
        executions, first = 0, None
        for trial in trials:
            executions += len(trial.runs)
            if trial.violated and first is None:
                first = executions
        violated = _distinct(r for t in trials for r in t.violated)
        undecided = [
            r
            for r in _distinct(r for t in trials for r in t.inconclusive)
            if not any(r.same_check(known) for known in violated)
        ]
        return cls(
            trials=len(trials),
            executions=executions,
            counterexamples=sum(bool(t.violated) for t in trials),
            violated_relations=len(violated),
            inconclusive=sum(t.outcome == "inconclusive" for t in trials),
            executions_to_first_failure=first,
            inconclusive_relations=len(undecided),
        )


def _distinct(relations: Iterable[CheckedRelation]) -> list[CheckedRelation]:
    """``relations`` one per check (:meth:`CheckedRelation.same_check`), first seen first."""
    distinct: list[CheckedRelation] = []
    for relation in relations:
        if not any(relation.same_check(known) for known in distinct):
            distinct.append(relation)
    return distinct


@dataclass(frozen=True)
class ShrinkTry:
    scenario: str
    steps: tuple[Request, ...]
    violated: bool


@dataclass(frozen=True)
class Shrinking:
    """A violated relation, the trial it was found in and the smallest derivation that still violates it."""

    campaign: str
    number: int
    relation: CheckedRelation
    trial: int
    original: str
    """The scenario of the trial it was found in."""
    minimal: str
    minimal_steps: tuple[Request, ...]
    tries: tuple[ShrinkTry, ...]


@dataclass(frozen=True)
class CampaignRecord:
    """A campaign as the store holds it."""

    plan: CampaignPlan
    started: datetime.datetime | None
    trials: tuple[CampaignTrial, ...]
    shrinkings: tuple[Shrinking, ...]

    @property
    def figures(self) -> CampaignFigures:
        return CampaignFigures.of(self.trials)
