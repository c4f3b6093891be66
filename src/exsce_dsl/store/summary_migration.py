"""Run summaries for a store written before them (``exscec store migrate``).

The scenario-wide queries read the run summaries (:mod:`.run_summary`), which a store written
by exsce 0.x before issue 52 lacks: there they would find no runs.  :func:`runs_without_summary`
finds the runs (and verifications) whose summary is missing; :func:`write_summaries` derives
each from the run's graphs, as a write of the run would have, and writes them, a batch of runs
per write (a run's summary whole or not at all).
"""

from __future__ import annotations

import re
import weakref
from collections.abc import Callable, Collection, Iterable, Sequence

from pyoxigraph import NamedNode, Quad

from exsce_dsl.errors import StoreError
from exsce_dsl.prov import identifiers as ids
from exsce_dsl.prov.identifiers import DEFAULT_NAMESPACE, Namespaces
from exsce_dsl.remedies import MIGRATE_THE_STORE
from exsce_dsl.store.base import GraphSet, Store
from exsce_dsl.store.indexes import is_index_graph
from exsce_dsl.store.run_replacing import run_graphs
from exsce_dsl.store.run_summary import run_summary
from exsce_dsl.store.sparql import term_text
from exsce_dsl.store.writing import is_revision

__all__ = ["require_summaries", "runs_without_summary", "write_summaries"]

BATCH = 100
"""Runs summarised per write."""

_RUN_BUNDLE = re.compile(r"/runs/run_([^/?]+)_bundle$")


def runs_without_summary(names: Iterable[str]) -> list[str]:
    """The runs (uuids) among the graph ``names`` whose bundle has no summary graph beside it,
    sorted.  Their verdicts' summaries are written with theirs (a verification without defects has
    an empty one, which a store does not keep, so a missing one says nothing)."""
    names = set(names)
    runs = set()
    for name in names:
        found = _RUN_BUNDLE.search(name)
        if (
            found is not None
            and f"{name[: found.start()]}/runs/run_{found.group(1)}/{ids.RUN_SUMMARY}" not in names
        ):
            runs.add(found.group(1))
    return sorted(runs)


def write_summaries(
    store: Store,
    runs: Sequence[str],
    graph_names: Collection[str],
    namespace: str = DEFAULT_NAMESPACE,
    progress: Callable[[int], None] | None = None,
) -> int:
    """Derive and write the summaries of ``runs`` (uuids) from their graphs (those named under the
    run, and its bag's: ``graph_names`` are the store's), :data:`BATCH` runs a write; the number
    of runs that got a summary graph.  ``progress`` is told the runs done after each write."""
    names = Namespaces(namespace)
    written = 0
    for start in range(0, len(runs), BATCH):
        derived: dict[str, list[Quad]] = {}
        for run in runs[start : start + BATCH]:
            own = names.of_run(run)
            found = {*run_graphs(store, run, namespace), own[:-1] + "_bundle"}
            found |= {name for name in graph_names if name.startswith(own)}
            graphs = sorted(
                g for g in found if g in graph_names and not is_revision(g) and not is_index_graph(g)
            )
            summary = run_summary(store.graphs(graphs))
            derived.update(summary)
            written += any(name.startswith(own) and quads for name, quads in summary.items())
        own_graphs = {name for name, quads in derived.items() if "/runs/" in name and quads}
        writes = {name: quads for name, quads in derived.items() if quads}
        if writes:
            store.write(GraphSet(writes), replace=own_graphs)
        if progress is not None:
            progress(min(start + BATCH, len(runs)))
    return written


_CHECKED: weakref.WeakSet[Store] = weakref.WeakSet()


def require_summaries(store: Store, namespace: str = DEFAULT_NAMESPACE) -> None:
    """Raise a StoreError when ``store`` holds runs but no run summary: written before them, it
    would answer the queries that read them with no runs at all.  Two look-ups, once per store
    object.  (A store with some runs summarised and some not, written by two versions, is what
    ``store check`` finds.)"""
    if store in _CHECKED:
        return
    names = Namespaces(namespace)
    exsce = names.fixed[ids.EXSCE]
    runs = store.ask(f"ASK {{ GRAPH ?g {{ ?run a {term_text(NamedNode(exsce + ids.RUN_TYPE.local))} }} }}")
    if runs and not store.ask(
        f"ASK {{ GRAPH ?g {{ ?key a {term_text(NamedNode(names.iri(ids.SCENARIO_RUNS)))} }} }}"
    ):
        raise StoreError(
            f"{store.location} holds runs written by an earlier exsce, without the run summaries "
            "this question reads",
            remedy=MIGRATE_THE_STORE,
        )
    _CHECKED.add(store)
