"""What the report shows of each exploration campaign, gathered from the store.

A campaign's page has its plan, a row per derivation it tried (a *trial*), a block per
violated relation it shrank to a minimal derivation, and how many distinct relations it had
found violated after each trial (the chart "violations found over budget").  Steps are shown
as ``exscec explore`` prints them (:func:`exsce_dsl.oracles.campaign_junit.steps_text`).
"""

from __future__ import annotations

import datetime
from dataclasses import dataclass

from exsce_dsl.model.campaign import CampaignPlan, CampaignRecord, CheckedRelation
from exsce_dsl.oracles import steps_text
from exsce_dsl.store import Store, campaign_record, campaigns

__all__ = [
    "CampaignContents",
    "ShrinkingContents",
    "TrialContents",
    "TryContents",
    "campaign_contents",
    "gather_campaigns",
]


@dataclass(frozen=True)
class TrialContents:
    number: int
    scenario: str
    steps: str
    """``remove_robot(robot=tiago2, reassign=tiago1) → reverse_waypoint_order(task=delivery_a)``."""
    runs: int
    checked: tuple[str, ...]
    """The relations checked, as text."""
    violated: tuple[str, ...]
    """The relations violated, as text: ``tiago1 task_duration invariant``."""
    new: tuple[str, ...]
    """Those of :attr:`violated` no earlier trial violated."""
    outcome: str
    """violated, passed or unchecked."""


@dataclass(frozen=True)
class TryContents:
    number: int
    scenario: str
    steps: str
    violated: bool


@dataclass(frozen=True)
class ShrinkingContents:
    number: int
    relation: str
    trial: int
    """The trial the relation was found violated in."""
    original: str
    minimal: str
    minimal_steps: str
    steps: int
    """How many steps the minimal derivation has."""
    original_steps: int
    """How many the trial's derivation had."""
    tries: tuple[TryContents, ...]


@dataclass(frozen=True)
class CampaignContents:
    plan: CampaignPlan
    started: datetime.datetime | None
    trials: tuple[TrialContents, ...]
    shrinkings: tuple[ShrinkingContents, ...]
    found: tuple[int, ...]
    """After each trial, in order: how many distinct relations had been found violated."""

    @property
    def id(self) -> str:
        return self.plan.id

    @property
    def checked(self) -> int:
        """Distinct relations checked, over all trials."""
        return len({r for t in self.trials for r in t.checked})

    @property
    def violated(self) -> int:
        """Distinct relations violated, over all trials."""
        return self.found[-1] if self.found else 0

    @property
    def violated_trials(self) -> int:
        return sum(t.outcome == "violated" for t in self.trials)


def campaign_contents(record: CampaignRecord) -> CampaignContents:
    """What the page of ``record``'s campaign shows."""
    seen: set[CheckedRelation] = set()
    trials: list[TrialContents] = []
    found: list[int] = []
    for trial in sorted(record.trials, key=lambda t: t.number):
        new = tuple(r for r in trial.violated if r not in seen)
        seen.update(trial.violated)
        found.append(len(seen))
        trials.append(
            TrialContents(
                number=trial.number,
                scenario=trial.scenario,
                steps=steps_text(trial.steps),
                runs=len(trial.runs),
                checked=tuple(r.text for r in trial.checked),
                violated=tuple(r.text for r in trial.violated),
                new=tuple(r.text for r in new),
                outcome=trial.outcome,
            )
        )
    by_number = {t.number: t for t in record.trials}
    shrinkings = tuple(
        ShrinkingContents(
            number=s.number,
            relation=s.relation.text,
            trial=s.trial,
            original=s.original,
            minimal=s.minimal,
            minimal_steps=steps_text(s.minimal_steps),
            steps=len(s.minimal_steps),
            original_steps=len(by_number[s.trial].steps) if s.trial in by_number else 0,
            tries=tuple(
                TryContents(n, t.scenario, steps_text(t.steps), t.violated)
                for n, t in enumerate(s.tries, start=1)
            ),
        )
        for s in sorted(record.shrinkings, key=lambda s: s.number)
    )
    return CampaignContents(record.plan, record.started, tuple(trials), shrinkings, tuple(found))


def gather_campaigns(store: Store) -> tuple[CampaignContents, ...]:
    """Every campaign of the store, oldest first."""
    gathered = []
    for campaign in dict.fromkeys(plan.id for plan in campaigns(store)):
        record = campaign_record(store, campaign)
        if record is not None:
            gathered.append(campaign_contents(record))
    return tuple(gathered)
