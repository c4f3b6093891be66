"""Shrinking a failing derivation of scenario_c: steps dropped one at a time, then arguments
simplified, every try recorded."""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable

from exsce_dsl.explore.shrink import Shrunk, shrink
from exsce_dsl.model import Scenario, Task
from exsce_dsl.transform.derivation import Request, derive

SWAP = ("swap_start_poses", {"robot": "tiago1", "with": "tiago2"})
THREE: list[Request] = [
    ("remove_task", {"task": "delivery_a"}),
    SWAP,
    ("remove_task", {"task": "delivery_b"}),
]


def run(
    spec_c: tuple[Scenario, dict[str, Task]],
    requests: list[Request],
    fails_if: Callable[[tuple[Request, ...]], bool],
) -> tuple[Shrunk, int]:
    base, tasks = spec_c
    calls: list[tuple[Request, ...]] = []

    def still_fails(tried: tuple[Request, ...]) -> bool:
        calls.append(tried)
        return fails_if(tried)

    shrunk = shrink(base, tasks, requests, still_fails)
    assert [t.requests for t in shrunk.chain] == calls  # the chain records each try
    return shrunk, len(calls)


def test_a_swap_failure_shrinks_to_the_swap(spec_c: tuple[Scenario, dict[str, Task]]) -> None:
    shrunk, calls = run(spec_c, THREE, lambda r: any(name == "swap_start_poses" for name, _ in r))
    assert shrunk.requests == (SWAP,)
    assert [(t.requests, t.fails) for t in shrunk.chain] == [
        ((SWAP, THREE[2]), True),  # the first step dropped
        ((THREE[2],), False),  # then the first of what was left
        ((SWAP,), True),  # then the second
    ]
    base, tasks = spec_c
    for tried in shrunk.chain:  # only derivations that apply are tried
        derive(base, tried.requests, tasks=tasks)


def test_two_of_a_kind_stops_at_two(spec_c: tuple[Scenario, dict[str, Task]]) -> None:
    shrunk, _ = run(spec_c, THREE, lambda r: max(Counter(name for name, _ in r).values()) >= 2)
    assert [name for name, _ in shrunk.requests] == ["remove_task", "remove_task"]
    assert not shrunk.chain[-1].fails


def test_a_step_keeps_only_the_arguments_the_failure_needs(spec_c: tuple[Scenario, dict[str, Task]]) -> None:
    requests: list[Request] = [SWAP, ("remove_robot", {"robot": "tiago2", "reassign": "tiago1"})]
    shrunk, _ = run(spec_c, requests, lambda r: any(name == "remove_robot" for name, _ in r))
    assert shrunk.requests == (("remove_robot", {"robot": "tiago2"}),)


def test_nothing_smaller_fails_keeps_the_derivation(spec_c: tuple[Scenario, dict[str, Task]]) -> None:
    shrunk, calls = run(spec_c, THREE, lambda r: len(r) == 3)
    assert shrunk.requests == tuple(THREE) and calls == 3  # the three drops, no optional argument
    assert not any(t.fails for t in shrunk.chain)
