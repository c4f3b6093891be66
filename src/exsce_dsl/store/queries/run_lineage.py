"""One stored run from dispatch to verdict (``run_lineage.rq``), as plain values.

The ingested run and the dispatcher's run are one run: the store ties them by their bag
(``prov:alternateOf``, :mod:`exsce_dsl.prov.run_execution`), and :func:`dispatched_runs` finds
the ingested run from the id that ``exscec simulate`` and ``execute`` print.
"""

from __future__ import annotations

import datetime
from dataclasses import dataclass, field

from exsce_dsl.prov.identifiers import DEFAULT_NAMESPACE
from exsce_dsl.store.base import Store, Term
from exsce_dsl.store.queries.terms import datetime_of, float_of, run_query, text_of

__all__ = [
    "ChainExecution",
    "ChainGoal",
    "ChainValue",
    "ChainVerdict",
    "RunChain",
    "dispatched_runs",
    "run_chain",
]


@dataclass(frozen=True)
class ChainExecution:
    """The dispatcher's run: its id, where its run-time PROV was read, how its mission ended."""

    run_id: str
    source: str
    mission_status: str | None
    start: datetime.datetime | None
    end: datetime.datetime | None


@dataclass(frozen=True)
class ChainGoal:
    """A goal the dispatcher sent and its outcome."""

    name: str
    robot: str
    pose: str | None
    status: str
    outcome: str | None
    attempts: int
    start: datetime.datetime | None
    end: datetime.datetime | None


@dataclass(frozen=True)
class ChainValue:
    """A metric value of the run; ``action``: the segment's action (None: the whole run)."""

    metric: str
    robot: str | None
    action: str | None
    value: float
    unit: str | None
    window_reason: str | None
    safety_metric: str | None = None
    """The safety metric of a ``violation_duration`` value."""


@dataclass(frozen=True)
class ChainVerdict:
    """A verdict on the run; ``runs``: the runs its expectation came from (uuids)."""

    oracle: str
    metric: str
    robot: str | None
    relation: str
    outcome: str
    observed: float | None
    runs: tuple[str, ...]


@dataclass(frozen=True)
class RunChain:
    """What ``run_lineage.rq`` returns for one run; ``baselines``: (run, bag path) of the stored
    runs the verdicts' expectations came from."""

    run: str
    scenario: str | None = None
    derived_from: str | None = None
    execution: ChainExecution | None = None
    goals: tuple[ChainGoal, ...] = ()
    bag: str | None = None
    bag_path: str | None = None
    values: tuple[ChainValue, ...] = ()
    verdicts: tuple[ChainVerdict, ...] = ()
    baselines: tuple[tuple[str, str | None], ...] = field(default_factory=tuple)
    simulator: tuple[str, str, str] | None = None
    """What played the run, when a simulator did: its name, version and settings."""


def run_chain(store: Store, run: str, *, namespace: str = DEFAULT_NAMESPACE) -> RunChain:
    """The chain of the stored run ``run`` (a uuid), in one query."""
    parts: dict[str, list[dict[str, Term | None]]] = {}
    scenario: str | None = None
    for row in run_query(store, "run_lineage", {"run": run}, namespace):
        parts.setdefault(text_of(row["part"]) or "", []).append(row)
        scenario = scenario or text_of(row["scenario"])
    execution = next((_execution(r) for r in parts.get("execution", ())), None)
    bag = next(iter(parts.get("bag", ())), None)
    return RunChain(
        run,
        scenario,
        next((text_of(r["item"]) for r in parts.get("derived_from", ())), None),
        execution,
        tuple(_goal(r) for r in parts.get("goal", ())),
        text_of(bag["item"]) if bag else None,
        text_of(bag["path"]) if bag else None,
        tuple(_value(r) for r in parts.get("value", ())),
        tuple(_verdict(r) for r in parts.get("verdict", ())),
        tuple((text_of(r["item"]) or "", text_of(r["path"])) for r in parts.get("baseline", ())),
        next(
            (
                (text_of(r["item"]) or "", text_of(r["status"]) or "", text_of(r["detail"]) or "")
                for r in parts.get("simulator", ())
            ),
            None,
        ),
    )


def dispatched_runs(
    store: Store, prefix: str, *, namespace: str = DEFAULT_NAMESPACE
) -> list[tuple[str, str]]:
    """(stored run, dispatcher's run id) of every run whose dispatcher's id starts with ``prefix``."""
    rows = run_query(store, "dispatched_runs", {"prefix": prefix}, namespace)
    return [(text_of(r["run"]) or "", text_of(r["dispatched"]) or "") for r in rows]


def _execution(row: dict[str, Term | None]) -> ChainExecution:
    return ChainExecution(
        text_of(row["item"]) or "",
        text_of(row["detail"]) or "",
        text_of(row["status"]),
        datetime_of(row["start"]),
        datetime_of(row["end"]),
    )


def _goal(row: dict[str, Term | None]) -> ChainGoal:
    return ChainGoal(
        text_of(row["item"]) or "",
        text_of(row["robot"]) or "",
        text_of(row["pose"]) or None,
        text_of(row["status"]) or "",
        text_of(row["detail"]),
        int(float_of(row["value"]) or 1),
        datetime_of(row["start"]),
        datetime_of(row["end"]),
    )


def _value(row: dict[str, Term | None]) -> ChainValue:
    return ChainValue(
        text_of(row["metric"]) or "",
        text_of(row["robot"]),
        text_of(row["item"]),
        float_of(row["value"]) or 0.0,
        text_of(row["unit"]),
        text_of(row["detail"]),
        text_of(row["safety"]),
    )


def _verdict(row: dict[str, Term | None]) -> ChainVerdict:
    runs = text_of(row["runs"])
    return ChainVerdict(
        text_of(row["item"]) or "",
        text_of(row["metric"]) or "",
        text_of(row["robot"]),
        text_of(row["detail"]) or "",
        text_of(row["status"]) or "",
        float_of(row["value"]),
        tuple(runs.split()) if runs else (),
    )
