"""From acceptance criteria to oracles: one oracle per clause and robot it is about.

``each robot max_velocity stays below 1.0 m/s`` in a scenario of two robots is two
oracles, ``tiago1-max_velocity`` and ``tiago2-max_velocity``.  A clause in a
criterion whose *when* is ``tiago1 does delivery_a`` looks at that task only.
"""

from __future__ import annotations

from dataclasses import dataclass

from exsce_dsl.lang import metric_info
from exsce_dsl.model import Scenario
from exsce_dsl.model.acceptance import (
    Acceptance,
    BasicRelation,
    Expectation,
    Moment,
    Quantifier,
    Quantity,
    Window,
)
from exsce_dsl.model.oracles import OracleType


@dataclass(frozen=True)
class PlannedOracle:
    """One oracle as the criteria define it, before a baseline gives it numbers."""

    criterion: str
    expectation: Expectation
    robot: str | None
    window: Window | None

    @property
    def metric(self) -> str:
        return self.expectation.metric

    @property
    def relation(self) -> BasicRelation:
        return self.expectation.relation

    @property
    def type(self) -> OracleType:
        return OracleType.BASELINE if self.expectation.against is None else OracleType.METAMORPHIC

    @property
    def needs_runs(self) -> bool:
        """Whether the expected value comes from stored runs (no fixed value, no limit)."""
        e = self.expectation
        return e.limit is None and e.value is None

    @property
    def window_text(self) -> str | None:
        return None if self.window is None else self.window.text()


def plan_oracles(acceptance: Acceptance, scenario: Scenario) -> list[PlannedOracle]:
    """The oracles of ``acceptance``, in the order the clauses are written, robots in fleet order."""
    planned: list[PlannedOracle] = []
    for criterion in acceptance.criteria:
        implied = None
        if criterion.when is not None and criterion.when.robot is not None:
            assert criterion.when.task is not None
            implied = Window(Moment.DURING, criterion.when.robot, task=criterion.when.task)
        for expectation in criterion.expectations:
            window = expectation.window
            info = metric_info(expectation.metric, scenario)
            if window is None and implied is not None and info is not None and info.per_segment:
                window = implied
            for robot in _robots(expectation, scenario):
                planned.append(PlannedOracle(criterion.title, expectation, robot, window))
    return planned


def _robots(expectation: Expectation, scenario: Scenario) -> list[str | None]:
    subject = expectation.subject
    if subject.quantifier is Quantifier.MISSION:
        return [None]
    if subject.quantifier is Quantifier.ROBOT:
        return [subject.robot]
    return [robot.id for robot in scenario.robots]


def tolerance_of(tolerance: Quantity | None, mean: float, std: float, relation: BasicRelation) -> float:
    """An absolute tolerance: ``k std`` of the runs, ``p %`` of their mean, as written, or (none
    written) one standard deviation for ``invariant`` and nothing for the others."""
    if tolerance is None:
        return std if relation is BasicRelation.INVARIANT else 0.0
    if tolerance.unit == "std":
        return tolerance.value * std
    if tolerance.unit == "%":
        return tolerance.value / 100.0 * abs(mean)
    return tolerance.value
