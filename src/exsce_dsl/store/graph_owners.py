"""Whose a named graph is, from its name alone: a run's (``<base>runs/run_<uuid>_bundle``, its
bundles ``<base>runs/run_<uuid>/<name>_bundle`` and its action graphs under the same prefix), or
a bag's bundle named by the old scheme (``<base><bag file>_bundle``, before bag bundles were
named by their run).  The store's conflict advice and ``store check`` read graph names this way."""

from __future__ import annotations

import re
from collections.abc import Sequence

__all__ = ["graph_run", "replace_advice", "shared_element"]

_SHARED_GRAPH = re.compile(r"/(robots|environments|tasks)/([^/?]+)_bundle$")
_SHARED_KINDS = {"robots": "robot", "environments": "environment or area", "tasks": "task"}
_RUN_GRAPH = re.compile(r"/runs/run_([^/?]+?)(?:_bundle)?(?:/[^?]*)?(?:[?&]revision=\d+)?$")


def graph_run(graph: str) -> str | None:
    """The uuid of the run whose graph ``graph`` is, by its name; None for any other graph."""
    found = _RUN_GRAPH.search(graph)
    return found.group(1) if found is not None else None


def shared_element(graph: str) -> tuple[str, str] | None:
    """(kind, id) when ``graph`` is the bundle of a robot, environment, area or task: named by the
    element's id alone, so every scenario of the store with an element of that id shares it."""
    found = _SHARED_GRAPH.search(graph)
    if found is None:
        return None
    kind, name = found.groups()
    return (_SHARED_KINDS[kind], name.split(".", 1)[0] if kind == "robots" else name)


def replace_advice(graphs: Sequence[str]) -> str:
    """What to run to replace conflicting ``graphs``: ``ingest --replace`` for a run's (a run is
    analysed again from its bag), ``compile --store --replace`` for a spec's, with a warning for
    graphs every scenario with an element of that id shares (another scenario's robot is
    replaced too)."""
    runs = sorted({run for g in graphs if (run := graph_run(g)) is not None})
    if runs:
        which = ", ".join(runs[:3]) + (f" and {len(runs) - 3} more" if len(runs) > 3 else "")
        return (
            f"the store holds run {which} with other content: to analyse the run again and replace "
            "it, ingest its bag with replace (`exscec ingest BAG --scenario SPEC --replace`)"
        )
    advice = (
        "to replace it, add it again with replace (`exscec compile SPEC --store --replace`): "
        "the old version is kept as a revision (prov:wasRevisionOf)"
    )
    shared = sorted({found for g in graphs if (found := shared_element(g)) is not None})
    if shared:
        which = ", ".join(f"{kind} '{element}'" for kind, element in shared[:3])
        advice += (
            f"; but {which} {'is' if len(shared) == 1 else 'are'} named by id alone, shared by every "
            "scenario of the store that names one so: if another scenario declares it otherwise, "
            "give this scenario's another id (--replace would change the other scenario's too)"
        )
    return advice
