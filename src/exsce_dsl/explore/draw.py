"""Seeded draws of derivations: compositions of 1..``max_steps`` applicable steps, without
duplicates (see :mod:`exsce_dsl.explore.fingerprint` for what counts as equal).

The draws walk the tree of compositions: the base at its root, a node's children the steps that
apply to its scenario (:func:`~exsce_dsl.explore.steps.applicable_steps`).  Each walk goes down
from the root through a child drawn uniformly among those not yet exhausted, and stops at a node
of depth ``d`` with probability ``1 / (max_steps - d + 1)`` (always at ``max_steps``), so that
every length is about as likely.  The node it stops at is a candidate unless its scenario equals
the base or an earlier candidate.  A node whose scenario was reached already at the same depth or
above is not walked into again (its compositions are those of the other node), and a node whose
candidate and children are all spent is exhausted: when the root is, the space is, and the draws
end with fewer than asked for.
"""

from __future__ import annotations

import random
from collections.abc import Collection, Mapping
from dataclasses import dataclass, field

from exsce_dsl.errors import ExsceError
from exsce_dsl.explore.fingerprint import fingerprint
from exsce_dsl.explore.playable import standing_in_the_way
from exsce_dsl.explore.steps import ProposedStep, applicable_steps
from exsce_dsl.model import Scenario, Task
from exsce_dsl.suggest import did_you_mean
from exsce_dsl.transform import TRANSFORMATIONS, Applied, Request, derive


@dataclass(frozen=True)
class Candidate:
    """A drawn derivation: the requests ``derive`` takes, the scenario they give, its fingerprint."""

    requests: tuple[Request, ...]
    scenario: Scenario
    fingerprint: str


@dataclass
class _Node:
    """A composition: the steps so far (``requests``), what they gave, the tasks known after them."""

    depth: int
    applied: Applied
    known: dict[str, Task]
    requests: tuple[Request, ...]
    considered: bool = False
    """Its candidate was drawn (or found a duplicate)."""
    steps: list[ProposedStep] | None = None
    made: dict[int, _Node] = field(default_factory=dict)
    open: list[int] = field(default_factory=list)
    """The children (indices into ``steps``) not exhausted nor pruned."""


def draw_derivations(
    base: Scenario,
    tasks: Mapping[str, Task],
    count: int,
    seed: int,
    max_steps: int = 2,
    transformations: Collection[str] | None = None,
) -> list[Candidate]:
    """Up to ``count`` derivations of ``base`` with distinct results, the same for the same seed;
    ``tasks`` are those the spec declares; ``transformations`` keeps only steps of those names."""
    check_draw(max_steps, transformations)
    base_robots = frozenset(r.id for r in base.robots)
    rng = random.Random(seed)
    root = _Node(0, Applied(base), dict(tasks), (), considered=True)
    shallowest = {fingerprint(base, base_robots): 0}
    """The depth each scenario reached was first reached at: a node reaching it again no higher
    up is pruned (the base, at depth 0, is never a candidate)."""
    seen: set[str] = set()
    drawn: list[Candidate] = []
    exhausted = False
    while len(drawn) < count and not exhausted:
        path = [root]
        while True:
            node = path[-1]
            if node.steps is None and node.depth < max_steps:
                node.steps = applicable_steps(node.applied.scenario, node.known, transformations)
                node.open = list(range(len(node.steps)))
            if not node.considered and (not node.open or rng.random() < 1 / (max_steps - node.depth + 1)):
                node.considered = True
                candidate = _candidate(base, tasks, node.requests, base_robots)
                if candidate.fingerprint not in seen:
                    seen.add(candidate.fingerprint)
                    if not standing_in_the_way(candidate.scenario):  # else no fleet could play it
                        drawn.append(candidate)
                break
            if not node.open:
                break
            index = rng.choice(node.open)
            child = _child(node, index, base_robots, shallowest)
            if child is None:
                node.open.remove(index)
            else:
                path.append(child)
        for depth in range(len(path) - 1, -1, -1):  # spent nodes close their parent's branch
            node = path[depth]
            if not (node.considered and not node.open):
                break
            if depth == 0:
                exhausted = True
            else:
                parent = path[depth - 1]
                parent.open = [i for i in parent.open if parent.made.get(i) is not node]
    return drawn


def check_draw(max_steps: int, transformations: Collection[str] | None) -> None:
    """Refuse draws of no steps, or of transformations that do not exist."""
    if max_steps < 1:
        raise ExsceError("a derivation has at least one step: give max_steps of 1 or more")
    unknown = sorted(set(transformations or ()) - TRANSFORMATIONS.keys())
    if unknown:
        raise ExsceError(f"unknown transformation '{unknown[0]}'{did_you_mean(unknown[0], TRANSFORMATIONS)}")


def _child(node: _Node, index: int, base_robots: frozenset[str], shallowest: dict[str, int]) -> _Node | None:
    """The node below ``node`` through its step ``index``; ``None`` when pruned."""
    if index in node.made:
        return node.made[index]
    assert node.steps is not None
    step = node.steps[index]
    depth = node.depth + 1
    reached = fingerprint(step.applied.scenario, base_robots)
    if shallowest.get(reached, depth + 1) <= depth:
        return None
    shallowest[reached] = depth
    known = node.known | {t.id: t for t in step.applied.new_tasks}
    child = _Node(depth, step.applied, known, (*node.requests, step.request))
    node.made[index] = child
    return child


def _candidate(
    base: Scenario, tasks: Mapping[str, Task], requests: tuple[Request, ...], base_robots: frozenset[str]
) -> Candidate:
    derived = derive(base, requests, tasks=tasks)
    return Candidate(requests, derived.scenario, fingerprint(derived.scenario, base_robots))
