"""Which graphs of a write make its run visible, so that a server that commits in steps writes
them last (:class:`~exsce_dsl.store.base.GraphSet` ``commit``).

Every query that finds runs (the runs of a scenario, a run id's prefix, a run's lineage) starts
from the run's activity, typed ``exsce:run`` in the run's bundle ``run:run_<uuid>_bundle``.  So the
bundle is the write's commit graph, and its ``rdf:type exsce:run`` statements its last, together
with the run's summary, where the scenario-wide queries start (:mod:`.run_summary`): on Virtuoso,
which commits each operation on its own (:mod:`exsce_dsl.store.write_strategy`), a run becomes
visible with the last operation of its write, once every other graph of it is whole.  A
transactional store writes the set in one step and needs no order.
"""

from __future__ import annotations

import re
from collections.abc import Collection, Mapping, Sequence

from pyoxigraph import NamedNode, Quad

from exsce_dsl.prov import identifiers as ids
from exsce_dsl.store.base import GraphSet

__all__ = ["run_graph_set", "unfinished_run_graphs"]

_RUN_BUNDLE = re.compile(r"/runs/(run_[^/?]+)_bundle$")
_RUN_SUMMARY = re.compile(rf"/runs/run_[^/?]+/(?:{ids.RUN_SUMMARY}|{ids.VERDICTS_SUMMARY})$")
_RUN_TYPE_ENDING = f"/{ids.RUN_TYPE.local}"


def run_graph_set(graphs: Mapping[str, Sequence[Quad]]) -> GraphSet:
    """``graphs`` to write together, a run's bundle and summary among them committed last, its
    run's type in the last operation (with the summary, which the scenario-wide queries read:
    :mod:`exsce_dsl.store.run_summary`)."""
    commit = frozenset(name for name in graphs if _RUN_BUNDLE.search(name) or _RUN_SUMMARY.search(name))
    if not commit:
        return GraphSet(graphs)
    ordered = {name: _type_last(quads) if name in commit else quads for name, quads in graphs.items()}
    return GraphSet(ordered, commit=commit)


def _type_last(quads: Sequence[Quad]) -> list[Quad]:
    def marks_the_run(quad: Quad) -> bool:
        kind = quad.object
        return (
            quad.predicate.value == ids.RDF_TYPE
            and isinstance(kind, NamedNode)
            and kind.value.endswith(_RUN_TYPE_ENDING)
        )

    return [q for q in quads if not marks_the_run(q)] + [q for q in quads if marks_the_run(q)]


def unfinished_run_graphs(names: Collection[str], existing: Collection[str]) -> set[str]:
    """Of the graphs ``existing`` of a write of ``names``, those a write of the same run left when
    it stopped before its last step (its bundle absent): not stored, to be written over.  Only a
    store that commits in steps can hold them (and ``exscec store check --fix`` removes them)."""
    runs = {m.group(1) for name in names if (m := _RUN_BUNDLE.search(name)) and name not in existing}
    if not runs:
        return set()
    return {name for name in existing if any(f"/runs/{run}/" in name for run in runs)}
