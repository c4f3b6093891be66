"""The embedded store: Oxigraph (pyoxigraph) in a folder on disk, or in memory."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from pyoxigraph import NamedNode, Quad, QuerySolutions
from pyoxigraph import Store as OxStore

from exsce_dsl.store.base import Bindings, GraphSet, Rows, Store, StoreError
from exsce_dsl.store.sparql import bind


class EmbeddedStore(Store):
    """``path=None`` keeps the data in memory (tests, benchmarks)."""

    def __init__(self, path: Path | None = None) -> None:
        try:
            self._store = OxStore(str(path)) if path is not None else OxStore()
        except OSError as exc:
            raise StoreError(f"cannot open the store at {path}: {exc}") from None
        self.path = path

    def write(self, graphs: GraphSet, *, replace: bool = False) -> None:
        if replace:
            for name in graphs.graphs:
                self._store.remove_graph(NamedNode(name))
        self._store.extend([q for quads in graphs.graphs.values() for q in quads])

    def select(self, query: str, bindings: Bindings | None = None) -> Rows:
        result = self._store.query(bind(query, bindings))
        if not isinstance(result, QuerySolutions):
            raise StoreError("not a SELECT query")
        variables = tuple(v.value for v in result.variables)
        return Rows(variables, tuple(tuple(solution[v] for v in variables) for solution in result))

    def ask(self, query: str, bindings: Bindings | None = None) -> bool:
        return bool(self._store.query(bind(query, bindings)))

    def update(self, update: str, bindings: Bindings | None = None) -> None:
        self._store.update(bind(update, bindings))

    def graph_names(self) -> set[str]:
        return {g.value for g in self._store.named_graphs() if isinstance(g, NamedNode)}

    def graph(self, name: str) -> list[Quad]:
        return list(self._store.quads_for_pattern(None, None, None, NamedNode(name)))

    def remove_graphs(self, names: Sequence[str]) -> None:
        for name in names:
            self._store.remove_graph(NamedNode(name))

    def close(self) -> None:
        self._store.flush() if self.path is not None else None

