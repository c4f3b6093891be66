"""The graphs the store derives from a write and writes with it: the segment index
(:mod:`.segment_index`) and the run summaries (:mod:`.run_summary`).  Each says again what the
write's own statements say, laid out for the questions asked most; neither is shown among a
store's graphs unless asked for."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from pyoxigraph import Quad

from exsce_dsl.store.run_summary import is_summary_graph, run_summary
from exsce_dsl.store.segment_index import is_segment_index_graph, segment_index

__all__ = ["index_graphs", "is_index_graph"]


def index_graphs(graphs: Mapping[str, Sequence[Quad]]) -> dict[str, list[Quad]]:
    """The index graphs (name → quads) derived from ``graphs``: empty for what is no run."""
    return {**segment_index(graphs), **run_summary(graphs)}


def is_index_graph(name: str) -> bool:
    """True for the name of a graph the store derives (the segment index's, a summary's)."""
    return is_segment_index_graph(name) or is_summary_graph(name)
