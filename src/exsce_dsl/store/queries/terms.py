"""Running the library's queries, and the Python values of the terms they answer with."""

from __future__ import annotations

import datetime
from collections.abc import Mapping, Sequence

from exsce_dsl.errors import ExsceError
from exsce_dsl.model.derivation import ParameterValue
from exsce_dsl.model.geometry import Pose
from exsce_dsl.prov.identifiers import DEFAULT_NAMESPACE, pose_name
from exsce_dsl.store.base import Rows, Store, Term
from exsce_dsl.store.literals import canonical_rows, literal_value, parse_datetime
from exsce_dsl.store.queries.library import query

Given = Mapping[str, str | Sequence[str]]
"""Parameters as text: name → one value or several."""


def run_query(store: Store, name: str, given: Given, namespace: str = DEFAULT_NAMESPACE) -> Rows:
    """Run library query ``name`` with parameters given as text; its rows (SELECT), each literal in
    its one form whatever the store (:mod:`exsce_dsl.store.literals`), or none (update)."""
    q = query(name)
    as_lists = {k: [v] if isinstance(v, str) else list(v) for k, v in given.items()}
    bindings = q.bindings(as_lists, namespace)
    if q.is_update:
        store.update(q.sparql(namespace), bindings)
        return Rows((), ())
    return canonical_rows(store.select(q.sparql(namespace), bindings))


# -- plain values of terms -----------------------------------------------------------


def text_of(term: Term | None) -> str | None:
    return None if term is None else term.value


def float_of(term: Term | None) -> float | None:
    if term is None:
        return None
    try:
        return float(term.value)
    except ValueError:
        raise ExsceError(f"the store holds '{term.value}' where a number belongs") from None


def int_of(term: Term | None) -> int:
    value = float_of(term)
    return 0 if value is None else int(value)


def bool_of(term: Term | None) -> bool | None:
    if term is None:
        return None
    return term.value in ("true", "1")


def datetime_of(term: Term | None) -> datetime.datetime | None:
    if term is None:
        return None
    try:
        return parse_datetime(term.value)
    except ValueError:
        return None


def python_value(term: Term | None) -> ParameterValue | None:
    """A literal as the Python value it was written from (numbers, booleans, strings)."""
    value = literal_value(term)
    if value is None or isinstance(value, str | int | float | bool):
        return value
    return term.value if term is not None else None


def pose_local_name(pose: Pose | str) -> str:
    return pose if isinstance(pose, str) else pose_name(pose)


# -- runs -------------------------------------------------------------------------------
