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
from exsce_dsl.store.queries.library import Query, query
from exsce_dsl.store.queries.ordering import sorted_rows, without_order
from exsce_dsl.store.queries.run_ids import names_a_prefix, resolve_run
from exsce_dsl.store.summary_migration import require_summaries
from exsce_dsl.store.timing import measured, none

Given = Mapping[str, str | Sequence[str]]
"""Parameters as text: name → one value or several."""


def run_query(
    store: Store, name: str, given: Given, namespace: str = DEFAULT_NAMESPACE, *, check_runs: bool = False
) -> Rows:
    """Run library query ``name`` with parameters given as text; its rows (SELECT), each literal in
    its one form whatever the store (:mod:`exsce_dsl.store.literals`), or none (update).

    A run parameter given as a prefix of a uuid or as a run's IRI is the one stored run it names
    (:func:`~.run_ids.resolve_run`); a whole uuid is taken as it is, unless ``check_runs`` (what
    people type: the CLI, the MCP server, the Python API), which makes every run given one the
    store holds, or an error."""
    q = query(name)
    as_lists = {k: [v] if isinstance(v, str) else list(v) for k, v in given.items()}
    bindings = q.bindings(as_lists, namespace)  # the parameters checked before any look-up
    if any(q.parameter(name).kind in RUN_KINDS for name in as_lists):
        bindings = q.bindings(_runs_resolved(store, q, as_lists, namespace, check_runs), namespace)
    text = q.sparql(namespace)
    if q.reads_summaries:
        require_summaries(store, namespace)
    if q.is_update:
        measured(text, lambda: store.update(text, bindings), none, name)
        return Rows((), ())
    unordered = without_order(text)
    if unordered is None:
        return canonical_rows(measured(text, lambda: store.select(text, bindings), len, name))
    asked, keys = unordered
    return measured(text, lambda: sorted_rows(canonical_rows(store.select(asked, bindings)), keys), len, name)


RUN_KINDS = ("run", "run_activity")
"""The kinds of parameter that name a run, by uuid."""


def _runs_resolved(
    store: Store, q: Query, given: dict[str, list[str]], namespace: str, check_runs: bool
) -> dict[str, list[str]]:
    """``given`` with each run parameter's value that is a prefix or an IRI (each value, with
    ``check_runs``) replaced by the id of the one run it names (:func:`~.run_ids.resolve_run`)."""
    resolved = {}
    for name, values in given.items():
        if q.parameter(name).kind in RUN_KINDS:
            asked = check_runs
            values = [resolve_run(store, v, namespace) if asked or names_a_prefix(v) else v for v in values]
        resolved[name] = values
    return resolved


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
