"""Names a query's parameters give that the store does not hold, with the store's own closest.

``exscec query run_metric -p metric=distance_travelld`` answers nothing, as a query about a
metric no run has must; :func:`unknown_names` says why: the store holds no metric of that name,
did you mean ``distance_travelled``?  The names are the store's own, read with the library's
queries (``metric_names``, ``robot_names``, ``scenarios``), so any store answers them.
"""

from __future__ import annotations

from collections.abc import Sequence

from exsce_dsl.errors import UnknownNameWarning
from exsce_dsl.prov.identifiers import DEFAULT_NAMESPACE
from exsce_dsl.store.base import Store
from exsce_dsl.store.queries.library import QueryParameter, query
from exsce_dsl.store.queries.terms import Given, run_query
from exsce_dsl.suggest import closest_several

__all__ = ["UnknownNameWarning", "stored_names", "unknown_names"]

NAMED = {"metric": "metric", "metric_property": "metric", "robot": "robot", "scenario": "scenario"}
"""A parameter's kind → what its value names."""
LISTING = {
    "metric": ("metric_names", "metric"),
    "robot": ("robot_names", "robot"),
    "scenario": ("scenarios", "scenario"),
}
"""What names → the library query that lists the store's names of it, and its column."""
SHOWN = 8
"""Names listed at most when none is close."""


def named_by(parameter: QueryParameter) -> str | None:
    """What ``parameter``'s values name (``metric``, ``robot``, ``scenario``), if one of these."""
    found = NAMED.get(parameter.kind)
    if found is None and parameter.kind == "id" and parameter.name in ("scenario", "base"):
        return "scenario"  # a scenario given by its id as a plain literal
    return found


def stored_names(store: Store, what: str, namespace: str = DEFAULT_NAMESPACE) -> list[str]:
    """Every name of a ``metric``, ``robot`` or ``scenario`` the store holds, sorted."""
    listing, column = LISTING[what]
    rows = run_query(store, listing, {}, namespace)
    at = rows.variables.index(column)
    return [term.value for row in rows.rows if (term := row[at]) is not None]


def unknown_names(store: Store, name: str, given: Given, namespace: str = DEFAULT_NAMESPACE) -> list[str]:
    """A warning for each value of query ``name``'s parameters (``given`` as text) that names a
    metric, robot or scenario the store does not hold, with the store's closest names."""
    said: list[str] = []
    held: dict[str, list[str]] = {}
    for parameter in query(name).parameters:
        what = named_by(parameter)
        value = given.get(parameter.name)
        if what is None or value is None:
            continue
        for text in [value] if isinstance(value, str) else list(value):
            if what == "metric" and run_query(store, "metric_names", {"metric": text}, namespace):
                continue  # a look-up: the store need not list every value's metric for a known one
            if what not in held:
                held[what] = stored_names(store, what, namespace)
            if text not in held[what]:
                said.append(_unknown(what, text, held[what]))
    return said


def _unknown(what: str, text: str, names: Sequence[str]) -> str:
    close = closest_several(text, names)
    if close:
        hint = f"; did you mean {' or '.join(repr(n) for n in close)}?"
    elif names:
        more = f" and {len(names) - SHOWN} more" if len(names) > SHOWN else ""
        hint = f" (it holds {', '.join(names[:SHOWN])}{more})"
    else:
        hint = f" (it holds no {what} yet)"
    return f"the store holds no {what} '{text}'{hint}"
