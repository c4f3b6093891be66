"""Scenarios in the store: their ids, robots, path segments and derivations."""

from __future__ import annotations

from dataclasses import dataclass

from exsce_dsl.errors import ExsceError
from exsce_dsl.model.derivation import Derivation, ParameterValue, TransformationStep
from exsce_dsl.prov.identifiers import DEFAULT_NAMESPACE
from exsce_dsl.store.base import Store
from exsce_dsl.store.queries.terms import (
    bool_of,
    int_of,
    python_value,
    run_query,
    text_of,
)


@dataclass(frozen=True)
class RobotFacts:
    """A robot of a scenario with the hardware facts similarity uses."""

    robot: str
    type: str | None
    base: str | None
    torso: bool | None


def scenario_ids(store: Store, namespace: str = DEFAULT_NAMESPACE) -> list[str]:
    """The id of every scenario in the store, in order."""
    return [text_of(row["scenario"]) or "" for row in run_query(store, "scenarios", {}, namespace)]


def robots(store: Store, scenario: str, namespace: str = DEFAULT_NAMESPACE) -> list[RobotFacts]:
    """The robots of ``scenario``, by id, with their type, base type and torso."""
    return [
        RobotFacts(
            text_of(row["robot"]) or "", text_of(row["type"]), text_of(row["base"]), bool_of(row["torso"])
        )
        for row in run_query(store, "robots", {"scenario": scenario}, namespace)
    ]


@dataclass(frozen=True)
class PathSegment:
    """Two consecutive poses of a robot's path (pose entity names, with their headings)."""

    robot: str
    start: str
    goal: str


def path_segments(store: Store, scenario: str, namespace: str = DEFAULT_NAMESPACE) -> list[PathSegment]:
    """The path segments of ``scenario``: for each robot, from its start pose through the
    waypoints of its tasks in order, each pair of consecutive poses."""
    return [
        PathSegment(text_of(row["robot"]) or "", text_of(row["start"]) or "", text_of(row["goal"]) or "")
        for row in run_query(store, "path_segments", {"scenario": scenario}, namespace)
    ]


def derivation_of(store: Store, scenario: str, namespace: str = DEFAULT_NAMESPACE) -> Derivation | None:
    """How ``scenario`` was derived: its base and the transformations applied, in order (None if
    it was written, not derived)."""
    bases: set[str] = set()
    steps: dict[int, tuple[str, list[tuple[str, ParameterValue]]]] = {}
    for row in run_query(store, "derivation", {"scenario": scenario}, namespace):
        bases.add(text_of(row["base"]) or "")
        if row["step"] is None:
            continue
        number = int_of(row["step"])
        _, parameters = steps.setdefault(number, (text_of(row["transformation"]) or "", []))
        key, value = text_of(row["parameter"]), python_value(row["value"])
        if key is not None and value is not None:
            parameters.append((key, value))
    if not bases:
        return None
    if len(bases) > 1:
        raise ExsceError(
            f"the store says scenario '{scenario}' was derived from {len(bases)} scenarios: "
            f"{', '.join(sorted(bases))}"
        )
    return Derivation(
        scenario,
        bases.pop(),
        tuple(TransformationStep(name, tuple(sorted(params))) for _, (name, params) in sorted(steps.items())),
    )


def lineage(store: Store, scenario: str, namespace: str = DEFAULT_NAMESPACE) -> list[Derivation]:
    """Where ``scenario`` comes from, transitively: its derivation, its base's, and so on back to a
    scenario that was written by hand (first the scenario's own)."""
    chain: list[Derivation] = []
    seen = {scenario}
    current = scenario
    while (derivation := derivation_of(store, current, namespace)) is not None:
        chain.append(derivation)
        if derivation.base in seen:
            raise ExsceError(f"scenario '{derivation.base}' is its own ancestor in the store")
        seen.add(derivation.base)
        current = derivation.base
    return chain


def derived_scenarios(store: Store, scenario: str, namespace: str = DEFAULT_NAMESPACE) -> list[str]:
    """The scenarios derived from ``scenario`` directly."""
    rows = run_query(store, "derived_scenarios", {"base": scenario}, namespace)
    return [text_of(row["derived"]) or "" for row in rows]
