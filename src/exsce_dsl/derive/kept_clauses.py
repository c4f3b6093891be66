"""What a derived scenario's acceptance criteria keep of its base's safety clauses, and a note for
each clause they leave out, saying why: nothing is left out silently.

A robot given no tasks stands by: its runs measure it (velocity, scans, distance), so the base's
safety limits judge it, but it has no performance clause (:func:`standing_note`).  A robot without a
start pose is in no run, so no clause can judge it: an ``each robot`` limit is written for each
robot that is in the runs instead, and a limit between robots needs two of them.  A robot whose
tasks take it nowhere (every waypoint where it starts: it only turns on the spot) is judged by
the base's limits on peaks, not by its limits on a mean or a total (:func:`is_mean_or_total`):
a mean turn rate over a second of turning on the spot is not the mean of a mission.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace

from exsce_dsl.model import Acceptance, Scenario
from exsce_dsl.model.acceptance import BasicRelation, Expectation, Quantifier, Subject
from exsce_dsl.model.expressions import Aggregate

PAIRWISE = frozenset({"distance_between_robots"})
"""Mission metrics that need two robots at least."""
IN_PLACE = 0.3
"""Metres: a waypoint this close to where a robot starts takes it nowhere."""


def safety_clauses(
    derived: Scenario, base_acceptance: Acceptance | None
) -> tuple[list[Expectation], list[str]]:
    """The base's safety clauses that apply to ``derived`` (see
    :func:`~exsce_dsl.derive.expect.derived_criteria`), and the notes on what they leave out.
    A robot without a start pose (``remove_start_pose``) is in no run: an ``each robot`` clause
    is written for each robot that is instead, and a clause between robots needs two of them."""
    if base_acceptance is None:
        return [], []
    placed = [r.id for r in derived.robots if r.start_pose is not None]
    absent = [r.id for r in derived.robots if r.start_pose is None]
    kept = [
        e
        for c in base_acceptance.criteria
        if c.when is None or c.when.robot is None  # a task's criteria look at a part of the run
        for e in c.expectations
        if e.relation in (BasicRelation.BELOW_MAX, BasicRelation.ABOVE_MIN)
        and e.window is None
        and (e.subject.robot is None or e.subject.robot in placed)
    ]
    pairs = [e for e in kept if e.metric in PAIRWISE]
    clauses = [e for e in kept if e.metric not in PAIRWISE or len(placed) > 1]
    notes = []
    if absent:
        clauses = [one for e in clauses for one in _each_of(e, placed)]
    still = [r for r in placed if drives_nowhere(derived, r)]
    averaged = sorted({e.metric for e in clauses if is_mean_or_total(e.metric, derived)})
    if still and averaged:
        moving = [r for r in placed if r not in still]
        clauses = [
            one
            for e in clauses
            for one in (_each_of(e, moving) if e.metric in averaged else [e])
            if one.subject.robot not in still or one.metric not in averaged
        ]
        notes += [
            f"{robot} drives nowhere in {derived.id} (every waypoint of its tasks is where it starts: "
            f"it only turns on the spot): no {', '.join(averaged)} clause for it, a limit on a mean or "
            "a total is about a mission that drives; the base's other limits judge it"
            for robot in still
        ]
    for robot in absent:
        notes.append(
            f"{robot} has no start pose in {derived.id}: it is in none of its runs, so no clause "
            "judges it (the base's 'each robot' limits are written for each robot that is)"
        )
    if pairs and len(placed) < 2:
        names = ", ".join(sorted({e.metric for e in pairs}))
        notes.append(f"{names}: no clause, fewer than two robots are in the runs of {derived.id}")
    return clauses, notes


def drives_nowhere(scenario: Scenario, robot: str) -> bool:
    """Whether ``robot`` has tasks and every waypoint of them is within IN_PLACE of its start."""
    start = next((r.start_pose for r in scenario.robots if r.id == robot), None)
    tasks = [scenario.task(e.task) for e in scenario.mission.allocation if e.robot == robot]
    waypoints = [w for t in tasks if t is not None for w in t.waypoints()]
    if start is None or not waypoints:
        return False
    x, y = start.position.x, start.position.y
    return all(math.hypot(w.position.x - x, w.position.y - y) <= IN_PLACE for w in waypoints)


def is_mean_or_total(metric: str, scenario: Scenario) -> bool:
    """Whether ``metric`` (one of the scenario's own) is a mean or a total over the run (an
    aggregate other than ``max`` and ``min``, with no safety limit declared); the built-in
    metrics are peaks, or the time a peak was broken."""
    definition = next((m for m in scenario.metrics if m.name == metric), None)
    if definition is None or definition.safety is not None:
        return False
    return isinstance(definition.value, Aggregate) and definition.value.func not in ("max", "min")


def _each_of(clause: Expectation, robots: Sequence[str]) -> list[Expectation]:
    """An ``each robot`` clause as one clause per robot of ``robots``; another as it is."""
    if clause.subject.quantifier is not Quantifier.EACH_ROBOT:
        return [clause]
    return [replace(clause, subject=Subject(Quantifier.ROBOT, robot)) for robot in robots]


def standing_note(robot: str, scenario: str) -> str:
    """Why a robot given no tasks has no performance clause.  It is expected to visit no
    waypoints, but a run records no goals for a robot given none (``waypoints_visited`` counts
    goals that succeeded: it has no value, and a value from a missing one is missing, never 0);
    it has no path to expect a distance or a duration from.  Standing by is still measured: its
    velocity, scans and distance are recorded, so the safety clauses judge it."""
    return (
        f"{robot} has no tasks in {scenario}: no waypoints_visited, distance_travelled or "
        "task_duration clause (it is expected to visit no waypoint, but a run records no goals "
        "for a robot given none, so waypoints_visited has no value; and it has no path to expect "
        "a distance or a duration from); the safety clauses judge it standing by, over its recording"
    )
