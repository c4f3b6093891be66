"""The store's numbers as pandas DataFrames, for notebooks and scripts.

Tables are tidy (one row per value, one column per variable), so that they pivot, group and plot
with pandas as they are: ``metrics(store).pivot_table(index="run", columns=["robot", "metric"],
values="value")`` is the runs × robots × metrics table.  pandas is imported when a table is made.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict
from typing import TYPE_CHECKING, Any

from exsce_dsl.store import queries
from exsce_dsl.store.base import Rows, Store
from exsce_dsl.store.queries.library import query as library_query
from exsce_dsl.store.queries.results import verdicts as stored_verdicts

if TYPE_CHECKING:
    import pandas as pd

METRIC_COLUMNS = ("run", "scenario", "robot", "metric", "safety", "value", "unit")
SEGMENT_COLUMNS = ("run", "scenario", "robot", "action", "goal", "metric", "value")


def _frame(records: Sequence[dict[str, Any]], columns: Sequence[str]) -> pd.DataFrame:
    import pandas as pd

    return pd.DataFrame.from_records(list(records), columns=list(columns))


def _runs(store: Store, scenario: str | None, runs: Sequence[str] | None) -> dict[str, str]:
    """Run uuid → its scenario, for the runs asked for (all of ``scenario``'s, or every run; each
    given as its uuid, a unique prefix of it or its IRI)."""
    known = {r.uuid: r.scenario for r in queries.runs(store, scenario)}
    return known if runs is None else {r: known.get(r, "") for r in queries.resolve_runs(store, runs)}


def metrics(store: Store, scenario: str | None = None, runs: Sequence[str] | None = None) -> pd.DataFrame:
    """Every whole-run metric value of the runs (of ``scenario``, or those given by uuid or unique
    prefix, or all): columns
    run, scenario, robot (None for the mission's), metric, safety (the safety metric a
    ``violation_duration`` is about), value and unit (None for a count)."""
    scenario_of = _runs(store, scenario, runs)
    readings = queries.run_metric_values(store, list(scenario_of))
    return _frame(
        [
            {"run": r.run, "scenario": scenario_of.get(r.run, ""), "robot": r.robot, "metric": r.metric,
             "safety": r.safety, "value": r.value, "unit": r.unit}
            for r in readings
        ],
        METRIC_COLUMNS,
    )  # fmt: skip


def segments(store: Store, scenario: str | None = None, runs: Sequence[str] | None = None) -> pd.DataFrame:
    """Every path-segment metric value of the runs: columns run, scenario, robot, action (the
    segment's activity IRI), goal (the goal pose), metric and value."""
    scenario_of = _runs(store, scenario, runs)
    readings = queries.run_segment_values(store, list(scenario_of))
    return _frame(
        [
            {"run": r.run, "scenario": scenario_of.get(r.run, ""), "robot": r.robot, "action": r.action,
             "goal": r.goal, "metric": r.metric, "value": r.value}
            for r in readings
        ],
        SEGMENT_COLUMNS,
    )  # fmt: skip


def verdicts(store: Store, scenario: str | None = None) -> pd.DataFrame:
    """The verdicts the store holds (of ``scenario``, or all): one row per oracle and run, the
    columns of :class:`~exsce_dsl.model.verdicts.Verdict` (outcome as its text)."""
    rows = []
    for verdict in stored_verdicts(store, scenario):
        row = asdict(verdict)
        row["outcome"] = verdict.outcome.value
        row["sources"] = tuple(verdict.sources)
        rows.append(row)
    import pandas as pd

    return pd.DataFrame.from_records(rows)


def rows_frame(rows: Rows) -> pd.DataFrame:
    """A SELECT's answer with each literal as the Python value it holds (IRIs as their text)."""
    values = [[queries.python_value(term) for term in row] for row in rows.rows]
    return _frame([dict(zip(rows.variables, v, strict=True)) for v in values], rows.variables)


def query(store: Store, name: str, **parameters: str | Sequence[str]) -> pd.DataFrame:
    """``exscec query NAME -p k=v``: a query of the library, its parameters bound as RDF terms (a
    run given by a unique prefix of its uuid, as tables print it, or its IRI)."""
    if library_query(name).is_update:
        raise ValueError(f"'{name}' is an update; the Python API runs the library's queries only")
    return rows_frame(queries.run_query(store, name, parameters, check_runs=True))


def sparql(store: Store, text: str) -> pd.DataFrame:
    """A SELECT query of your own (the library's prefixes are not added: write your PREFIXes)."""
    return rows_frame(store.select(text))
