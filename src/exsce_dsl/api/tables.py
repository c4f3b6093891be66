"""The store's numbers as pandas DataFrames, for notebooks and scripts.

Tables are tidy (one row per value, one column per variable), so that they pivot, group and plot
with pandas as they are: ``metrics(store).pivot_table(index="run", columns=["robot", "metric"],
values="value")`` is the runs × robots × metrics table.  pandas is imported when a table is made.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import asdict
from typing import TYPE_CHECKING, Any

from exsce_dsl.errors import UnknownNameWarning
from exsce_dsl.store import (
    Rows,
    Store,
    canonical_rows,
    literal_value,
    pose_positions,
    resolve_runs,
    run_metric_values,
    run_query,
    run_segment_values,
    unknown_names,
)
from exsce_dsl.store import query as library_query
from exsce_dsl.store import runs as stored_runs
from exsce_dsl.store import verdicts as stored_verdicts

if TYPE_CHECKING:
    import pandas as pd

METRIC_COLUMNS = ("run", "scenario", "robot", "metric", "safety", "value", "unit")
SEGMENT_COLUMNS = (
    "run", "scenario", "robot", "action", "start", "start_x", "start_y", "goal", "metric", "value", "unit",
)  # fmt: skip


def _frame(records: Sequence[dict[str, Any]], columns: Sequence[str]) -> pd.DataFrame:
    import pandas as pd

    return pd.DataFrame.from_records(list(records), columns=list(columns))


def _runs(store: Store, scenario: str | None, runs: Sequence[str] | None) -> dict[str, str]:
    """Run uuid → its scenario, for the runs asked for (all of ``scenario``'s, or every run; each
    given as its uuid, a unique prefix of it or its IRI)."""
    known = {r.uuid: r.scenario for r in stored_runs(store, scenario)}
    return known if runs is None else {r: known.get(r, "") for r in resolve_runs(store, runs)}


def metrics(store: Store, scenario: str | None = None, runs: Sequence[str] | None = None) -> pd.DataFrame:
    """Every whole-run metric value of the runs (of ``scenario``, or those given by uuid or unique
    prefix, or all): columns
    run, scenario, robot (None for the mission's), metric, safety (the safety metric a
    ``violation_duration`` is about), value and unit (None for a count)."""
    scenario_of = _runs(store, scenario, runs)
    readings = run_metric_values(store, list(scenario_of))
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
    action's id in the run, ``tiago1-task_01-subtask_001-w_001``: the robot's first task, its first
    subtask's first waypoint), start (the pose the segment started from, with its heading),
    start_x and start_y (where that pose is, in metres, in the map's frame), goal (the goal pose),
    metric, value and unit (as the store holds it; None for a count)."""
    scenario_of = _runs(store, scenario, runs)
    readings = run_segment_values(store, list(scenario_of))
    where = pose_positions(store, [r.start for r in readings if r.start is not None])
    nowhere = (None, None)
    return _frame(
        [
            {"run": r.run, "scenario": scenario_of.get(r.run, ""), "robot": r.robot,
             "action": _action_id(r.action), "start": r.start,
             "start_x": where.get(r.start or "", nowhere)[0], "start_y": where.get(r.start or "", nowhere)[1],
             "goal": r.goal, "metric": r.metric, "value": r.value, "unit": r.unit}
            for r in readings
        ],
        SEGMENT_COLUMNS,
    )  # fmt: skip


def _action_id(action: str | None) -> str | None:
    """The action's id in its run: the last part of its IRI."""
    return None if action is None else action.rsplit("/", 1)[-1]


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
    """A SELECT's answer with each literal as the Python value it holds, whatever the store wrote
    (numbers, booleans, date-times aware of their zone; IRIs as their text)."""
    values = [[literal_value(term) for term in row] for row in canonical_rows(rows).rows]
    return _frame([dict(zip(rows.variables, v, strict=True)) for v in values], rows.variables)


def query(store: Store, name: str, **parameters: str | Sequence[str]) -> pd.DataFrame:
    """``exscec query NAME -p k=v``: a query of the library, its parameters bound as RDF terms (a
    run given by a unique prefix of its uuid, as tables print it, or its IRI).  A metric, robot or
    scenario the store does not hold is an :class:`~exsce_dsl.errors.UnknownNameWarning` naming
    the store's closest names (the answer is then empty)."""
    if library_query(name).is_update:
        raise ValueError(f"'{name}' is an update; the Python API runs the library's queries only")
    rows = run_query(store, name, parameters, check_runs=True)
    for warning in unknown_names(store, name, parameters):
        warnings.warn(warning, UnknownNameWarning, stacklevel=2)
    return rows_frame(rows)


def sparql(store: Store, text: str) -> pd.DataFrame:
    """A SELECT query of your own (the library's prefixes are not added: write your PREFIXes)."""
    return rows_frame(store.select(text))
