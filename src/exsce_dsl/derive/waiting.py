"""Time a robot may spend giving way to the robots it shares a derived scenario's runs with.

A robot's expected ``task_duration`` sums the durations of its path's segments as stored runs
drove them (:mod:`exsce_dsl.derive.expect`): it drives its path as it did there, with whatever
waiting for other robots those runs happened to show.  A derived scenario changes where and when
robots meet (start poses swapped, tasks reordered or reallocated, robots added): a robot may then
wait for another to go by, back away from one with right of way, or wait for one standing on its
goal to leave, none of which its segments' means can know.  Its duration clause allows for that
much more time, on the slow side only: giving way never makes a robot faster.

GIVE_WAY is what one robot in the way can cost: a fleet's right of way makes a robot wait for
another to go by, and the longest exsce's executor waits before it goes on anyway is 30 s (for a
robot standing in its way; 10 s for one driving at it, 15 s beside the path for one meeting it
head-on: ``sim.give_way``, ``sim.passing``), plus the ramps to stop and start again.  A fault
that holds robots far longer (a deadlock) still fails the clause.
"""

from __future__ import annotations

from dataclasses import dataclass

from exsce_dsl.model import Scenario

GIVE_WAY = 30.0
"""Seconds a robot may lose to each other robot of the run, beyond its segments' durations."""

WAITED = ("task_duration",)
"""The summed metrics giving way adds to (it changes when a robot drives, not where)."""


@dataclass(frozen=True)
class Waiting:
    """A robot's expected value of a time, driving as its segments were driven, and the time it
    may spend giving way on top: the clause's centre and allowance that accept both."""

    expected: float
    allowance: float
    waiting: float

    @property
    def centre(self) -> float:
        """The middle of [expected - allowance, expected + allowance + waiting]."""
        return self.expected + self.waiting / 2.0

    @property
    def half_width(self) -> float:
        return self.allowance + self.waiting / 2.0


def others_in_runs(scenario: Scenario, robot: str) -> int:
    """How many other robots are in the scenario's runs (those with a start pose)."""
    return sum(1 for r in scenario.robots if r.id != robot and r.start_pose is not None)


def waiting_for(scenario: Scenario, robot: str, metric: str, give_way: float = GIVE_WAY) -> float:
    """Seconds ``robot`` may spend giving way to the others in ``scenario``'s runs, for
    ``metric`` (none for a metric giving way does not lengthen, nor for a robot alone)."""
    if metric not in WAITED:
        return 0.0
    return give_way * others_in_runs(scenario, robot)


def waiting_note(scenario: Scenario, waits: dict[str, float]) -> str:
    """What the duration clauses of ``scenario`` allow for giving way (``waits``: seconds per robot)."""
    each = ", ".join(f"{robot} {seconds:g} s" for robot, seconds in sorted(waits.items()))
    return (
        f"task_duration: a robot's expected duration drives its path as stored runs drove it; in "
        f"{scenario.id} it shares the run with other robots and may give way to them, which no "
        f"segment's mean can know: its clauses allow up to {GIVE_WAY:g} s per other robot more "
        f"({each}), on the slow side only (centred on the expected value plus half of it)"
    )
