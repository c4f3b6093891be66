"""The campaign summary's counts agree: each number says what it counts, relations on the first
line (distinct checks, as shrinking counts them), trials on the second.  Issue 50 found "4
inconclusive" (relations, by their text) printed next to "1 inconclusive" (trials) for one
campaign."""

from __future__ import annotations

import datetime
from pathlib import Path

from exsce_dsl.api.exploring import Exploration
from exsce_dsl.explore.campaign import CampaignResult
from exsce_dsl.model.campaign import (
    CampaignFigures,
    CampaignPlan,
    CampaignRecord,
    CampaignTrial,
    CheckedRelation,
)

PLAN = CampaignPlan("campaign_x", "scenario_c", 3, 0, 1, 2, (), "simulator", "covering", True, 25.0)
SPEED = CheckedRelation("max_velocity", "tiago1", "below_max")
CLEARANCE = CheckedRelation("distance_to_obstacles", "tiago1", "above_min")
WAYPOINTS = CheckedRelation("waypoints_visited", "tiago1", "invariant")
FEWER = CheckedRelation("waypoints_visited", "tiago1", "decreasing", "scenario_c")
DURATION = CheckedRelation("task_duration", "tiago2", "invariant")
LONGER = CheckedRelation("task_duration", "tiago2", "increasing")
"""The same check as DURATION (an expected value missed, whichever way the estimate went)."""
CHECKED = (SPEED, CLEARANCE, WAYPOINTS, FEWER, DURATION)


def _trial(
    number: int, violated: tuple[CheckedRelation, ...], inconclusive: tuple[CheckedRelation, ...]
) -> CampaignTrial:
    runs = (f"run{number}",)
    return CampaignTrial(PLAN.id, number, f"s{number}", (), runs, CHECKED, violated, (), inconclusive)


def _summary(trials: list[CampaignTrial]) -> list[str]:
    record = CampaignRecord(
        PLAN, datetime.datetime(2026, 1, 1, tzinfo=datetime.timezone.utc), tuple(trials), ()
    )
    result = CampaignResult(record, Path("explore/x"), 0, record.figures)
    return Exploration(result, None).summary_lines()


def test_one_inconclusive_trial_with_four_undecided_relations_is_said_as_both() -> None:
    trials = [_trial(1, (), (SPEED, CLEARANCE, WAYPOINTS, FEWER)), _trial(2, (), ())]
    figures = CampaignFigures.of(trials)
    assert (figures.inconclusive, figures.inconclusive_relations) == (1, 4)
    lines = _summary(trials)
    assert (
        lines[0] == "campaign campaign_x: 2 derivations tried, 0 relations violated, 4 relations inconclusive"
    )
    assert lines[2].endswith("; 1 trial inconclusive")


def test_relations_are_counted_as_checks_and_a_violated_one_is_not_also_inconclusive() -> None:
    # trial 1 leaves DURATION undecided, trial 2 violates LONGER (the same check) and SPEED,
    # trial 3 leaves SPEED (violated in trial 2) and CLEARANCE undecided
    trials = [
        _trial(1, (), (DURATION,)),
        _trial(2, (LONGER, SPEED), ()),
        _trial(3, (), (SPEED, CLEARANCE)),
    ]
    figures = CampaignFigures.of(trials)
    assert (figures.violated_relations, figures.inconclusive_relations, figures.inconclusive) == (2, 1, 2)
    lines = _summary(trials)
    assert (
        lines[0] == "campaign campaign_x: 3 derivations tried, 2 relations violated, 1 relation inconclusive"
    )
    assert lines[2] == (
        "  3 executions, 1 counterexample (33.3 per 100 executions), first failure after: 2; 2 trials inconclusive"
    )


def test_a_clean_campaign_says_no_inconclusive_count() -> None:
    lines = _summary([_trial(1, (), ()), _trial(2, (), ())])
    assert lines[0] == "campaign campaign_x: 2 derivations tried, 0 relations violated"
    assert "inconclusive" not in "\n".join(lines)
