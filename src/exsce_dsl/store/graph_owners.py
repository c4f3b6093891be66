"""Whose a named graph is, from its name alone: a run's (``<base>runs/run_<uuid>_bundle``, its
bundles ``<base>runs/run_<uuid>/<name>_bundle`` and its action graphs under the same prefix), or
a bag's bundle named by the old scheme (``<base><bag file>_bundle``, before bag bundles were
named by their run).  The store's conflict advice and ``store check`` read graph names this way."""

from __future__ import annotations

import re
from collections.abc import Sequence

__all__ = ["graph_run", "replace_advice"]

_RUN_GRAPH = re.compile(r"/runs/run_([^/?]+?)(?:_bundle)?(?:/[^?]*)?(?:[?&]revision=\d+)?$")


def graph_run(graph: str) -> str | None:
    """The uuid of the run whose graph ``graph`` is, by its name; None for any other graph."""
    found = _RUN_GRAPH.search(graph)
    return found.group(1) if found is not None else None


def replace_advice(graphs: Sequence[str]) -> str:
    """What to run to replace conflicting ``graphs``: ``ingest --replace`` for a run's (a run is
    analysed again from its bag), ``compile --store --replace`` for a spec's."""
    runs = sorted({run for g in graphs if (run := graph_run(g)) is not None})
    if runs:
        which = ", ".join(runs[:3]) + (f" and {len(runs) - 3} more" if len(runs) > 3 else "")
        return (
            f"the store holds run {which} with other content: to analyse the run again and replace "
            "it, ingest its bag with replace (`exscec ingest BAG --scenario SPEC --replace`)"
        )
    return (
        "to replace it, add it again with replace (`exscec compile SPEC --store --replace`): "
        "the old version is kept as a revision (prov:wasRevisionOf)"
    )
