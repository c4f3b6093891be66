"""A derivation followed by its inverse gives the base back (a property, over random chains)."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from exsce_dsl.lang import load_spec
from exsce_dsl.model import Scenario
from exsce_dsl.transform.derivation import derive

from tests.support.paths import EXAMPLES

BASE = load_spec(EXAMPLES / "brsu_building_c" / "scenario_c.exsce").scenario("scenario_c")

# transformations that are their own inverse, with the arguments they may take on scenario_c
SELF_INVERSE = st.sampled_from(
    [
        ("swap_assignment", {"robot": "tiago1", "with": "tiago2"}),
        ("swap_assignment", {"robot": "tiago2", "with": "tiago1"}),
        ("swap_start_poses", {"robot": "tiago1", "with": "tiago2"}),
        ("reverse_task_order", {}),
        ("reverse_task_order", {"robot": "tiago1"}),
        ("reverse_task_order", {"robot": "tiago2"}),
    ]
)


def _facts(scenario: Scenario) -> tuple[object, ...]:
    """What a derivation may change, less the ids it gives."""
    return (
        scenario.mission.allocation,
        scenario.mission.type,
        tuple((r.id, r.type, r.start_pose) for r in scenario.robots),
        scenario.tasks,
        scenario.environment,
    )


@settings(max_examples=60, deadline=None)
@given(st.lists(SELF_INVERSE, min_size=1, max_size=6))
def test_a_chain_then_its_inverse_is_the_base(chain: list[tuple[str, dict[str, str]]]) -> None:
    there = derive(BASE, chain, "there").scenario
    back = derive(there, list(reversed(chain)), "back").scenario
    assert _facts(back) == _facts(BASE)


@pytest.mark.parametrize("task", ["delivery_a", "delivery_b", "navigate_home_1"])
def test_reversing_a_task_s_waypoints_twice_visits_them_as_before(task: str) -> None:
    twice = derive(
        BASE,
        [("reverse_waypoint_order", {"task": task}), ("reverse_waypoint_order", {"task": f"{task}_reversed", "as": "again"})],
        "twice",
    )
    original, again = BASE.task(task), twice.scenario.task("again")
    assert original is not None and again is not None
    assert again.subtasks == original.subtasks
    assert [o.task for o in twice.derivation.origins] == [f"{task}_reversed", "again"]
