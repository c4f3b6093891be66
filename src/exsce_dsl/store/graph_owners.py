"""Whose a named graph is, from its name alone: a run's (``<base>runs/run_<uuid>_bundle``, its
bundles ``<base>runs/run_<uuid>/<name>_bundle`` and its action graphs under the same prefix), or
a bag's bundle named by the old scheme (``<base><bag file>_bundle``, before bag bundles were
named by their run).  The store's conflict advice and ``store check`` read graph names this way."""

from __future__ import annotations

import re
from collections.abc import Sequence

from exsce_dsl.remedies import REPLACE_A_SHARED_ELEMENT, REPLACE_A_STORED_RUN, REPLACE_A_STORED_SPEC

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


def replace_advice(graphs: Sequence[str]) -> tuple[str, str, str]:
    """How to replace conflicting ``graphs``, as the last line of the problem (or nothing), the
    remedy and what it is about: ingest again for a run's (a run is analysed again from its bag),
    add again for a spec's, with a warning for graphs every scenario with an element of that id
    shares (another scenario's robot is replaced too).  ``cli.common.REMEDIES`` says each with
    the command that does it (``ingest --replace``, ``compile --store --replace``)."""
    runs = sorted({run for g in graphs if (run := graph_run(g)) is not None})
    if runs:
        which = ", ".join(runs[:3]) + (f" and {len(runs) - 3} more" if len(runs) > 3 else "")
        return f"the store holds run {which} with other content", REPLACE_A_STORED_RUN, ""
    shared = sorted({found for g in graphs if (found := shared_element(g)) is not None})
    if shared:
        which = ", ".join(f"{kind} '{element}'" for kind, element in shared[:3])
        return "", REPLACE_A_SHARED_ELEMENT, f"{which} {'is' if len(shared) == 1 else 'are'}"
    return "", REPLACE_A_STORED_SPEC, ""
