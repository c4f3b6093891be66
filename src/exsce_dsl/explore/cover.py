"""Draws that cover the steps first: the campaign's default way of choosing derivations.

Uniform draws (:mod:`exsce_dsl.explore.draw`) spend a small budget where steps are many: with
101 single steps of ``scenario_c``, 24 of them ``add_task`` and one ``swap_start_poses``, forty
uniform draws often miss the lone swap.  A fault hides behind one feature of a scenario, and
which feature is what nobody knows, so these draws spread the budget over what can change: each
derivation is built step by step, each step chosen among the applicable ones whose
transformation has been used least so far, then, among those, one that sends robots into areas
of the environment no derivation drawn so far (nor the base) drives in (a start pose in another
room: a robot's software is as likely to fail in a place as on a feature), then whose own
arguments have been used least; ties are broken by the seeded generator.  A derivation has
``max_steps`` steps (fewer when nothing more applies), so one execution tries several steps at
once, and shrinking (:mod:`exsce_dsl.explore.shrink`) finds which of them a violation needs.
Results equal to the base or to an earlier derivation (see
:mod:`exsce_dsl.explore.fingerprint`) are drawn again with the next-least-used last step, and a
step that would lead back to one of them is taken only when no other applies.  Results no fleet
could play (:mod:`exsce_dsl.explore.playable`) are not drawn; a step on the way may lead
through one.
"""

from __future__ import annotations

import random
from collections import Counter
from collections.abc import Collection, Mapping

from exsce_dsl.explore.draw import Candidate, check_draw
from exsce_dsl.explore.fingerprint import fingerprint
from exsce_dsl.explore.playable import standing_in_the_way
from exsce_dsl.explore.steps import ProposedStep, applicable_steps
from exsce_dsl.model import Scenario, Task
from exsce_dsl.transform import Applied, Request

ATTEMPTS = 20
"""Draws per derivation asked for, at most, before the space counts as spent."""


def covering_derivations(
    base: Scenario,
    tasks: Mapping[str, Task],
    count: int,
    seed: int,
    max_steps: int = 2,
    transformations: Collection[str] | None = None,
) -> list[Candidate]:
    """Up to ``count`` derivations of ``base`` with distinct results that spread over the
    applicable steps (see the module's docstring); the same for the same seed."""
    check_draw(max_steps, transformations)
    rng = random.Random(seed)
    base_robots = frozenset(r.id for r in base.robots)
    seen = {fingerprint(base, base_robots)}
    by_name: Counter[str] = Counter()
    by_step: Counter[str] = Counter()
    steps_of: dict[str, list[ProposedStep]] = {}
    drawn: list[Candidate] = []
    covered = areas_driven(base)
    for _ in range(count * ATTEMPTS):
        if len(drawn) == count:
            break
        applied = Applied(base)
        known = dict(tasks)
        requests: list[Request] = []
        for _depth in range(max_steps):
            key = fingerprint(applied.scenario, base_robots) + repr(sorted(known))
            if key not in steps_of:
                steps_of[key] = applicable_steps(applied.scenario, known, transformations)
            steps = steps_of[key]
            # steps to a scenario not drawn yet (nor the base: reversing a task twice) come first;
            # when there are none, a derivation that is new already stops here
            here = fingerprint(applied.scenario, base_robots)
            steps = [s for s in steps if fingerprint(s.applied.scenario, base_robots) != here]  # no no-ops
            fresh = [s for s in steps if fingerprint(s.applied.scenario, base_robots) not in seen]
            if not steps or (
                not fresh and requests and fingerprint(applied.scenario, base_robots) not in seen
            ):
                break
            step = min(
                fresh or steps,
                key=lambda s: (
                    by_name[s.name],
                    not areas_driven(s.applied.scenario) - covered,
                    by_step[_step_key(s)],
                    rng.random(),
                ),
            )
            by_name[step.name] += 1
            by_step[_step_key(step)] += 1
            applied = applied.then(step.applied)
            known |= {t.id: t for t in step.applied.new_tasks}
            requests.append(step.request)
        if not requests:
            break  # nothing applies to the base
        reached = fingerprint(applied.scenario, base_robots)
        if reached in seen:
            continue
        seen.add(reached)
        if standing_in_the_way(applied.scenario):  # no fleet could play it
            continue
        drawn.append(Candidate(tuple(requests), applied.scenario, reached))
        covered |= areas_driven(applied.scenario)
    return drawn


def areas_driven(scenario: Scenario) -> set[str]:
    """The areas whose poses robots with tasks start at or drive to."""
    area_of = {p.id: a.id for a in scenario.environment.areas for p in a.poses}
    poses = set()
    for robot in scenario.robots:
        tasks = scenario.mission.tasks_of(robot.id)
        if not tasks or robot.start_pose is None:
            continue
        poses.add(robot.start_pose.id)
        for task_id in tasks:
            task = scenario.task(task_id)
            poses.update(w.id for w in (task.waypoints() if task is not None else ()))
    return {area_of[p] for p in poses if p in area_of}


def _step_key(step: ProposedStep) -> str:
    return f"{step.name}{step.arguments!r}"
