"""A stored run analysed again: its old graphs and its new ones swapped in one write.

A run's graphs are its bundles (the run's, its bag's, one per metric, its
hotspots), the action graphs of its segment index, and its verdicts (with their
revisions): every graph that names the run (``exsce:run "<uuid>"``), and the
graph that describes the bag the run generated.  :func:`replace_run` drops all
of them and writes the new document's in **one** :meth:`Store.write`: one
transaction in the embedded store, one SPARQL Update request on an endpoint.  A
reader, or a store opened after a crash, sees the old run or the new one, never
a mix and never neither.

The verdicts go with the old run: they judged values the run no longer has
(``exscec verify`` judges it again).  Baselines keep their numbers (they say
which runs they came from) until ``exscec baseline`` builds them again.  The
segment graphs a run shares with every run of its scenario are only added to.
Nothing else changes: a graph of the new run that the store holds for something
other than the old run is a conflict, and nothing is written.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from prov.model import ProvDocument
from pyoxigraph import Literal, NamedNode, Quad

from exsce_dsl.errors import StoreConflictError
from exsce_dsl.prov import identifiers as ids
from exsce_dsl.prov.identifiers import DEFAULT_NAMESPACE, PROV_NAMESPACE, Namespaces
from exsce_dsl.store.base import Store
from exsce_dsl.store.indexes import index_graphs
from exsce_dsl.store.run_commit import run_graph_set
from exsce_dsl.store.segment_index import orphan_segment_graphs
from exsce_dsl.store.sparql import term_text
from exsce_dsl.store.writing import WriteReport, bundle_graphs

__all__ = ["replace_run", "run_graphs", "verdict_graphs"]


def run_graphs(store: Store, run: str, namespace: str = DEFAULT_NAMESPACE) -> list[str]:
    """The named graphs of stored run ``run`` (a uuid), sorted; empty when the store lacks it."""
    exsce = Namespaces(namespace).fixed[ids.EXSCE]
    names = term_text(NamedNode(exsce + ids.RUN_ATTR.local))
    kind = term_text(NamedNode(exsce + ids.RUN_TYPE.local))
    generated = term_text(NamedNode(f"{PROV_NAMESPACE}wasGeneratedBy"))
    uuid = term_text(Literal(run))
    rows = store.select(
        "SELECT DISTINCT ?g WHERE {\n"
        f"  {{ GRAPH ?g {{ ?named {names} {uuid} }} }}\n"
        "  UNION\n"
        f"  {{ GRAPH ?r {{ ?activity a {kind} ; {names} {uuid} . ?bag {generated} ?activity }}\n"
        "    GRAPH ?g { ?bag ?p ?o } }\n"
        "}"
    )
    return sorted(g.value for (g,) in rows.rows if isinstance(g, NamedNode))


def verdict_graphs(names: Sequence[str]) -> list[str]:
    """Those of a run's graph ``names`` that hold verdicts (the current ones and revisions)."""
    return [name for name in names if f"/{ids.VERDICTS_BUNDLE}" in name]


def replace_run(
    store: Store, document: ProvDocument, run: str, namespace: str = DEFAULT_NAMESPACE
) -> WriteReport:
    """Write ``document`` (run ``run``, analysed again) in place of what the store holds of that
    run, in one write.  ``replaced`` in the report names the old graphs (dropped or written
    again, and the segment graphs no run drives any more), ``added`` the graphs only the new
    version has.

    Raises :class:`~exsce_dsl.store.base.StoreConflictError`, having written nothing, when a
    graph of the new version is in the store for something else than the old run.
    """
    graphs = bundle_graphs(document)
    own_prefix = Namespaces(namespace).of_run(run)
    shared: dict[str, list[Quad]] = {}
    for name, quads in index_graphs(graphs).items():
        if name.startswith(own_prefix):
            graphs.setdefault(name, quads)  # an action graph: the run's own
        else:
            shared[name] = quads  # a segment's graph: every run of the scenario says the same
    old = run_graphs(store, run, namespace)
    others = sorted(store.existing_graphs([n for n in graphs if n not in old]))
    if others:
        raise StoreConflictError(_conflict(store, run, others), others)
    exsce_run = Namespaces(namespace).fixed[ids.EXSCE] + ids.RUN_ATTR.local
    orphans = orphan_segment_graphs(store, old, exsce_run, kept={*graphs, *shared})
    writes: dict[str, Sequence[Quad]] = {name: [] for name in [*old, *orphans]}
    writes.update(graphs)
    for name, quads in shared.items():
        writes.setdefault(name, quads)
    store.write(run_graph_set(writes), replace={*old, *orphans, *graphs})
    return WriteReport(
        location=store.location,
        added=tuple(name for name in graphs if name not in old),
        replaced=tuple([*old, *orphans]),
        statements=_count(graphs) + _count(shared),
    )


def _count(graphs: Mapping[str, Sequence[Quad]]) -> int:
    return sum(len(quads) for quads in graphs.values())


def _conflict(store: Store, run: str, names: Sequence[str]) -> str:
    shown = ", ".join(f"<{n}>" for n in names[:3]) + (f" and {len(names) - 3} more" if len(names) > 3 else "")
    return (
        f"{store.location} holds {shown} for something other than run {run}: "
        "the run was not replaced (nothing was written)"
    )
