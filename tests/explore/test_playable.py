"""Derivations no fleet could play (a robot must reach a place another stands on for good) are
named, and neither draw offers them."""

from __future__ import annotations

from collections.abc import Callable

import pytest

from exsce_dsl.explore.cover import covering_derivations
from exsce_dsl.explore.draw import Candidate, draw_derivations
from exsce_dsl.explore.playable import standing_in_the_way
from exsce_dsl.explore.steps import applicable_steps
from exsce_dsl.model import Scenario, Task
from exsce_dsl.transform.derivation import derive

TAKE_OVER = (
    "add_robot",
    {"robot": "tiago3", "like": "tiago1", "start": "classroom_c069-w001", "take_over": "tiago2"},
)
"""tiago2, left without tasks, stands at classroom_c025-w002: the goal of navigate_home_2,
which tiago3 now drives."""


def test_a_robot_left_without_tasks_on_anothers_goal_is_named(
    spec_c: tuple[Scenario, dict[str, Task]],
) -> None:
    base, tasks = spec_c
    assert standing_in_the_way(base) == []
    derived = derive(base, [TAKE_OVER], tasks=tasks).scenario
    assert standing_in_the_way(derived) == [
        "tiago2 has no task and stands at classroom_c025-w002, a waypoint of tiago3 (classroom_c025-w002)"
    ]
    # taking tiago2 out of play as well makes it playable
    gone = derive(base, [TAKE_OVER, ("remove_start_pose", {"robot": "tiago2"})], tasks=tasks).scenario
    assert standing_in_the_way(gone) == []


def test_two_robots_that_end_at_one_place_are_named(spec_c: tuple[Scenario, dict[str, Task]]) -> None:
    base, tasks = spec_c
    derived = derive(
        base, [("substitute_task", {"task": "navigate_home_2", "with": "navigate_home_1"})], tasks=tasks
    )
    problems = standing_in_the_way(derived.scenario)
    assert any(
        p.startswith("tiago1 ends its tasks at classroom_c025-w001, a waypoint of tiago2") for p in problems
    )


@pytest.mark.parametrize("draw", [covering_derivations, draw_derivations])
def test_draws_offer_no_derivation_that_cannot_be_played(
    draw: Callable[..., list[Candidate]], spec_c: tuple[Scenario, dict[str, Task]]
) -> None:
    base, tasks = spec_c
    unplayable = [s for s in applicable_steps(base, tasks) if standing_in_the_way(s.applied.scenario)]
    assert len(unplayable) >= 5  # the draws have something to leave out: every add_robot --take_over
    for seed in (0, 1):
        drawn = draw(base, tasks, 25, seed)
        assert len(drawn) == 25
        assert [c.requests for c in drawn if standing_in_the_way(c.scenario)] == []
