"""Typed queries of what runs left in the store: verdicts, hotspots, and where waypoints are.

The report reads these; they run files of the query library like the rest of
:mod:`exsce_dsl.store.queries`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from exsce_dsl.model.geometry import Position
from exsce_dsl.model.runs import Hotspot
from exsce_dsl.model.verdicts import Outcome, Verdict
from exsce_dsl.prov.identifiers import DEFAULT_NAMESPACE
from exsce_dsl.store.base import Store
from exsce_dsl.store.queries import _float, _int, _text, run_query

__all__ = ["RunHotspot", "hotspots", "pose_positions", "verdicts"]


def verdicts(store: Store, scenario: str | None = None, namespace: str = DEFAULT_NAMESPACE) -> list[Verdict]:
    """The verdicts of each run's last validation (of ``scenario``'s runs, or all): failed ones
    first, then those that could not be judged, then the passed ones."""
    given = {} if scenario is None else {"scenario": scenario}
    found = []
    for row in run_query(store, "verdicts", given, namespace):
        runs = _text(row["runs"])
        found.append(
            Verdict(
                run=_text(row["run"]) or "",
                scenario=_text(row["scenario"]) or "",
                criterion=_text(row["criterion"]) or "",
                oracle=_text(row["oracle"]) or "",
                metric=_text(row["metric"]) or "",
                robot=_text(row["robot"]),
                relation=_text(row["relation"]) or "",
                outcome=Outcome(_text(row["outcome"])),
                observed=_float(row["observed"]),
                expected=_float(row["expected"]),
                limit=_float(row["limit"]),
                delta=_float(row["delta"]),
                tolerance=_float(row["tolerance"]),
                margin=_float(row["margin"]),
                window=_text(row["window"]),
                sources=tuple(runs.split()) if runs else (),
                reason=_text(row["reason"]) or "",
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
        x, y = _float(row["x"]), _float(row["y"])
        if x is None or y is None:
            continue
        hotspot = Hotspot(
            metric=_text(row["metric"]) or "",
            position=Position(x, y, 0.0),
            violations=_int(row["violations"]),
            duration=_float(row["duration"]) or 0.0,
            robot=_text(row["robot"]),
        )
        found.append(RunHotspot(_text(row["run"]) or "", hotspot))
    return found


def pose_positions(
    store: Store, poses: Sequence[str], namespace: str = DEFAULT_NAMESPACE
) -> dict[str, tuple[float, float]]:
    """Pose name (with its heading, as :func:`path_segments` gives it) → its x and y."""
    if not poses:
        return {}
    found = {}
    for row in run_query(store, "pose_positions", {"pose": list(dict.fromkeys(poses))}, namespace):
        name, x, y = _text(row["name"]), _float(row["x"]), _float(row["y"])
        if name is not None and x is not None and y is not None:
            found[name] = (x, y)
    return found
