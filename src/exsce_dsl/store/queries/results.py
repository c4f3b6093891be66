"""Typed queries of what runs left in the store: verdicts, hotspots, and where waypoints are.

The report reads these; they run files of the query library like the rest of
:mod:`exsce_dsl.store.queries`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from exsce_dsl.model.coverage import Shortfall
from exsce_dsl.model.geometry import Position
from exsce_dsl.model.runs import Hotspot
from exsce_dsl.model.verdicts import Outcome, Verdict
from exsce_dsl.prov.identifiers import DEFAULT_NAMESPACE
from exsce_dsl.store.base import Store
from exsce_dsl.store.queries.terms import float_of, int_of, run_query, text_of

__all__ = ["RunHotspot", "hotspots", "pose_positions", "verdicts"]


def verdicts(store: Store, scenario: str | None = None, namespace: str = DEFAULT_NAMESPACE) -> list[Verdict]:
    """The verdicts of each run's last validation (of ``scenario``'s runs, or all): failed ones
    first, then the inconclusive ones, then the passed ones."""
    given = {} if scenario is None else {"scenario": scenario}
    found = []
    for row in run_query(store, "verdicts", given, namespace):
        runs, shortfalls = text_of(row["runs"]), text_of(row["shortfalls"])
        found.append(
            Verdict(
                run=text_of(row["run"]) or "",
                scenario=text_of(row["scenario"]) or "",
                criterion=text_of(row["criterion"]) or "",
                oracle=text_of(row["oracle"]) or "",
                metric=text_of(row["metric"]) or "",
                robot=text_of(row["robot"]),
                relation=text_of(row["relation"]) or "",
                outcome=Outcome(text_of(row["outcome"])),
                observed=float_of(row["observed"]),
                expected=float_of(row["expected"]),
                limit=float_of(row["limit"]),
                delta=float_of(row["delta"]),
                tolerance=float_of(row["tolerance"]),
                margin=float_of(row["margin"]),
                window=text_of(row["window"]),
                sources=tuple(runs.split()) if runs else (),
                reason=text_of(row["reason"]) or "",
                against=text_of(row["against"]),
                shortfalls=tuple(Shortfall(kind) for kind in shortfalls.split()) if shortfalls else (),
            )
        )
    return found


@dataclass(frozen=True)
class RunHotspot:
    run: str
    hotspot: Hotspot


def hotspots(store: Store, runs: Sequence[str], namespace: str = DEFAULT_NAMESPACE) -> list[RunHotspot]:
    """The hotspots of ``runs``: where each safety metric was violated."""
    if not runs:
        return []
    found = []
    for row in run_query(store, "hotspots", {"run": list(runs)}, namespace):
        x, y = float_of(row["x"]), float_of(row["y"])
        if x is None or y is None:
            continue
        hotspot = Hotspot(
            metric=text_of(row["metric"]) or "",
            position=Position(x, y, 0.0),
            violations=int_of(row["violations"]),
            duration=float_of(row["duration"]) or 0.0,
            robot=text_of(row["robot"]),
        )
        found.append(RunHotspot(text_of(row["run"]) or "", hotspot))
    return found


def pose_positions(
    store: Store, poses: Sequence[str], namespace: str = DEFAULT_NAMESPACE
) -> dict[str, tuple[float, float]]:
    """Pose name (with its heading, as :func:`path_segments` gives it) → its x and y."""
    if not poses:
        return {}
    found = {}
    for row in run_query(store, "pose_positions", {"pose": list(dict.fromkeys(poses))}, namespace):
        name, x, y = text_of(row["name"]), float_of(row["x"]), float_of(row["y"])
        if name is not None and x is not None and y is not None:
            found[name] = (x, y)
    return found
