"""Shrinking a failing derivation, the way property-based testing shrinks a failing example.

Pure: the campaign says whether a derivation still fails (``still_fails``, which runs it); this
module only proposes smaller derivations and keeps the smallest that fails.  The smaller ones are
tried in this order, and the first that still fails is shrunk again from the start:

1. each step dropped, one at a time, first step first;
2. each step's arguments simplified, first step first: each optional argument it was given
   dropped (a ``remove_robot`` without ``reassign``, an ``add_task`` at its default position,
   an ``add_robot`` taking over no one, a ``replace_robot`` of the old robot's type or at its
   start pose, a reversed task under its default id, a ``reverse_task_order`` of every robot, a
   ``remove_task`` of a task from every robot or of every task of a robot).

Only derivations that apply (``derive`` succeeds) and differ from the base are tried.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass

from exsce_dsl.errors import ExsceError
from exsce_dsl.explore.fingerprint import fingerprint
from exsce_dsl.explore.playable import standing_in_the_way
from exsce_dsl.model import Scenario, Task
from exsce_dsl.transform import TRANSFORMATIONS, Request, derive

MAX_TRIES = 500
"""Calls of ``still_fails`` a shrink makes at most (each runs a derivation)."""


@dataclass(frozen=True)
class Try:
    """One call of the predicate: the derivation tried and whether it still failed."""

    requests: tuple[Request, ...]
    fails: bool


@dataclass(frozen=True)
class Shrunk:
    requests: tuple[Request, ...]
    """The smallest derivation found that still fails (the one given, if none smaller does)."""
    chain: tuple[Try, ...]
    """Every try, in order."""


def smaller(requests: Sequence[Request]) -> Iterator[tuple[Request, ...]]:
    """The derivations one shrink away from ``requests``, in the order they are tried (whether
    they apply is not checked here)."""
    steps = tuple((name, dict(arguments)) for name, arguments in requests)
    for n in range(len(steps)):
        yield steps[:n] + steps[n + 1 :]
    for n, (name, arguments) in enumerate(steps):
        optional = TRANSFORMATIONS[name].optional if name in TRANSFORMATIONS else ()
        for key in arguments:
            if key in optional:
                simpler = {k: v for k, v in arguments.items() if k != key}
                yield steps[:n] + ((name, simpler),) + steps[n + 1 :]


def shrink(
    base: Scenario,
    tasks: Mapping[str, Task],
    requests: Sequence[Request],
    still_fails: Callable[[tuple[Request, ...]], bool],
    max_tries: int = MAX_TRIES,
) -> Shrunk:
    """The smallest derivation of ``base`` reached from the failing ``requests`` that still fails."""
    base_robots = frozenset(r.id for r in base.robots)
    base_print = fingerprint(base, base_robots)
    current: tuple[Request, ...] = tuple((name, dict(arguments)) for name, arguments in requests)
    chain: list[Try] = []
    tried: set[str] = set()
    shrinking = True
    while shrinking and len(chain) < max_tries:
        shrinking = False
        for candidate in smaller(current):
            key = repr(candidate)
            if key in tried or not _applies(base, tasks, candidate, base_robots, base_print):
                continue
            tried.add(key)
            fails = still_fails(candidate)
            chain.append(Try(candidate, fails))
            if fails:
                current, shrinking = candidate, True
                break
            if len(chain) >= max_tries:
                break
    return Shrunk(current, tuple(chain))


def _applies(
    base: Scenario,
    tasks: Mapping[str, Task],
    requests: tuple[Request, ...],
    base_robots: frozenset[str],
    base_print: str,
) -> bool:
    if not requests:
        return False
    try:
        derived = derive(base, requests, tasks=tasks)
    except ExsceError:
        return False
    if fingerprint(derived.scenario, base_robots) == base_print:
        return False
    return not standing_in_the_way(derived.scenario)  # else no fleet could play it
