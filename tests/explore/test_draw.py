"""Seeded draws of derivations of scenario_c: reproducible, applicable, bounded, filtered,
without duplicates, and the fingerprint that decides what a duplicate is."""

from __future__ import annotations

import pytest

from exsce_dsl.errors import ExsceError
from exsce_dsl.explore.draw import Candidate, draw_derivations
from exsce_dsl.explore.fingerprint import fingerprint
from exsce_dsl.model import Scenario, Task
from exsce_dsl.transform.derivation import derive

BASE_ROBOTS = {"tiago1", "tiago2"}


def names(candidate: Candidate) -> list[str]:
    return [name for name, _ in candidate.requests]


def test_reversing_a_task_twice_is_the_base(spec_c: tuple[Scenario, dict[str, Task]]) -> None:
    base, tasks = spec_c
    once = [("reverse_waypoint_order", {"task": "delivery_a"})]
    twice = [*once, ("reverse_waypoint_order", {"task": "delivery_a_reversed"})]
    print_of = {
        n: fingerprint(derive(base, s, tasks=tasks).scenario, BASE_ROBOTS) for n, s in ((1, once), (2, twice))
    }
    assert print_of[2] == fingerprint(base, BASE_ROBOTS) != print_of[1]


def test_minted_robot_ids_do_not_count(spec_c: tuple[Scenario, dict[str, Task]]) -> None:
    base, tasks = spec_c
    prints = {
        fingerprint(
            derive(base, [("replace_robot", {"robot": "tiago1", "by": by})], tasks=tasks).scenario,
            BASE_ROBOTS,
        )
        for by in ("new_robot_1", "other")
    }
    assert len(prints) == 1 and fingerprint(base, BASE_ROBOTS) not in prints


def test_the_same_seed_draws_the_same(spec_c: tuple[Scenario, dict[str, Task]]) -> None:
    base, tasks = spec_c
    first, again = (draw_derivations(base, tasks, 12, seed=7) for _ in range(2))
    other = draw_derivations(base, tasks, 12, seed=8)
    assert len(first) == 12
    assert [c.requests for c in first] == [c.requests for c in again]
    assert [c.requests for c in first] != [c.requests for c in other]


def test_draws_apply_and_are_distinct_and_not_the_base(spec_c: tuple[Scenario, dict[str, Task]]) -> None:
    base, tasks = spec_c
    drawn = draw_derivations(base, tasks, 40, seed=1)
    prints = [c.fingerprint for c in drawn]
    assert len(drawn) == 40 and len(set(prints)) == 40
    assert fingerprint(base, BASE_ROBOTS) not in prints
    for candidate in drawn:
        derived = derive(base, candidate.requests, tasks=tasks)
        assert derived.scenario == candidate.scenario
        assert fingerprint(derived.scenario, BASE_ROBOTS) == candidate.fingerprint


@pytest.mark.parametrize("max_steps", [1, 3])
def test_max_steps_is_respected(spec_c: tuple[Scenario, dict[str, Task]], max_steps: int) -> None:
    base, tasks = spec_c
    lengths = {len(c.requests) for c in draw_derivations(base, tasks, 30, seed=3, max_steps=max_steps)}
    assert max(lengths) == max_steps and min(lengths) >= 1


def test_the_filter_is_respected_and_the_space_exhausted(spec_c: tuple[Scenario, dict[str, Task]]) -> None:
    base, tasks = spec_c
    kinds = ["swap_start_poses", "reverse_task_order"]
    drawn = draw_derivations(base, tasks, 100, seed=5, transformations=kinds)
    assert {n for c in drawn for n in names(c)} == set(kinds)
    # By hand: S (swap), R1, R2 (reverse tiago1's, tiago2's; each robot has two tasks, so each is
    # its own inverse; reversing every robot is R1 R2): S, R1, R2, R1R2, SR1, SR2, SR1R2.
    assert len(drawn) == 7


def test_an_unknown_transformation_is_refused(spec_c: tuple[Scenario, dict[str, Task]]) -> None:
    base, tasks = spec_c
    with pytest.raises(ExsceError, match="swap_start_poses"):
        draw_derivations(base, tasks, 3, seed=0, transformations=["swap_start_pose"])
