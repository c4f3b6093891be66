"""Oracles, safety metrics and hotspots as the store holds them."""

from __future__ import annotations

from exsce_dsl.errors import ExsceError
from exsce_dsl.model.oracles import Oracle, OracleType
from exsce_dsl.prov.identifiers import DEFAULT_NAMESPACE, topic_of_name
from exsce_dsl.store.base import Store
from exsce_dsl.store.queries.terms import (
    float_of,
    int_of,
    run_query,
    text_of,
)


def safety_metrics(store: Store, scenario: str, namespace: str = DEFAULT_NAMESPACE) -> list[str]:
    """The metrics with a safety limit whose violation time the runs of ``scenario`` recorded."""
    rows = run_query(store, "safety_metrics", {"scenario": scenario}, namespace)
    return [text_of(row["metric"]) or "" for row in rows]


def hotspot_counts(
    store: Store, scenario: str, metric: str, namespace: str = DEFAULT_NAMESPACE
) -> dict[str, int]:
    """Run uuid → number of hotspots of safety ``metric``, for every run of ``scenario``."""
    rows = run_query(store, "hotspot_counts", {"scenario": scenario, "metric": metric}, namespace)
    return {text_of(row["run"]) or "": int_of(row["hotspots"]) for row in rows}


# -- oracles ----------------------------------------------------------------------------


def oracles(store: Store, scenario: str, namespace: str = DEFAULT_NAMESPACE) -> list[Oracle]:
    """The oracles that judge runs of ``scenario``: one per metric, robot, window, type and relation."""
    found = []
    for row in run_query(store, "oracles", {"scenario": scenario}, namespace):
        topics = tuple(sorted(topic_of_name(n) for n in (text_of(row["topic_ids"]) or "").split()))
        type_text = text_of(row["type"]) or ""
        try:
            oracle_type = OracleType(type_text)
        except ValueError:
            message = f"an oracle of scenario '{scenario}' has an unknown type '{type_text}'"
            raise ExsceError(message) from None
        found.append(
            Oracle(
                metric=text_of(row["metric"]) or "",
                robot=text_of(row["robot"]),
                relation=text_of(row["relation"]) or "",
                type=oracle_type,
                base_scenario=text_of(row["base"]) or "",
                topics=topics,
                value=float_of(row["value"]),
                limit=float_of(row["limit"]),
                delta=float_of(row["delta"]),
                tolerance=float_of(row["tolerance"]),
                package=text_of(row["package"]),
                window=text_of(row["window"]),
                criterion=text_of(row["criterion"]) or "",
                sources=tuple((text_of(row["runs"]) or "").split()),
                confidence=float_of(row["confidence"]),
            )
        )
    return found


def update_baseline(
    store: Store,
    scenario: str,
    metric: str,
    robot: str | None,
    value: float,
    tolerance: float,
    namespace: str = DEFAULT_NAMESPACE,
) -> None:
    """Set the baseline value and tolerance of the baseline oracle of ``metric`` (of ``robot``,
    or of the mission when None) of ``scenario``."""
    known = [
        o
        for o in oracles(store, scenario, namespace)
        if o.metric == metric and o.robot == robot and o.type is OracleType.BASELINE
    ]
    if not known:
        whose = f"robot '{robot}'" if robot is not None else "the mission"
        raise ExsceError(f"scenario '{scenario}' has no baseline oracle of '{metric}' for {whose}")
    given: dict[str, str] = {
        "scenario": scenario,
        "metric": metric,
        "value": repr(float(value)),
        "tolerance": repr(float(tolerance)),
    }
    if robot is None:
        run_query(store, "update_mission_baseline", given, namespace)
    else:
        run_query(store, "update_baseline", {**given, "robot": robot}, namespace)


# -- scenarios ----------------------------------------------------------------------------
