"""The store interface: named graphs of RDF, SPARQL in, plain values out.

Two implementations: :class:`exsce_dsl.store.embedded.EmbeddedStore`
(pyoxigraph in a project folder, the default) and
:class:`exsce_dsl.store.remote.RemoteStore` (any SPARQL 1.1 endpoint, through
the SPARQL 1.1 Protocol and the Graph Store Protocol).

Terms are pyoxigraph terms (``NamedNode``, ``Literal``, ``BlankNode``)
everywhere in this layer; callers outside ``store`` get plain Python values
from the typed query functions in :mod:`exsce_dsl.store.queries`.
"""

from __future__ import annotations

import abc
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass

from pyoxigraph import BlankNode, Literal, NamedNode, Quad

from exsce_dsl.errors import ExsceError

Term = NamedNode | BlankNode | Literal
Bindings = Mapping[str, Term | Sequence[Term]]
"""Query parameters: variable name (without ``?``) → one term, or several (a VALUES list)."""


class StoreError(ExsceError):
    """The store cannot do what was asked (unreachable, locked, refused, conflicting)."""


@dataclass(frozen=True)
class Rows:
    """The answer to a SELECT: variable names and one tuple of terms (or None) per solution."""

    variables: tuple[str, ...]
    rows: tuple[tuple[Term | None, ...], ...]

    def __iter__(self) -> Iterator[dict[str, Term | None]]:
        for row in self.rows:
            yield dict(zip(self.variables, row, strict=True))

    def __len__(self) -> int:
        return len(self.rows)


@dataclass(frozen=True)
class GraphSet:
    """Named graphs to write together: graph IRI → its quads (in that graph)."""

    graphs: Mapping[str, Sequence[Quad]]

    def triple_count(self) -> int:
        return sum(len(q) for q in self.graphs.values())


class Store(abc.ABC):
    """A dataset of named graphs (one per PROV bundle) that answers SPARQL."""

    @abc.abstractmethod
    def write(self, graphs: GraphSet, *, replace: bool = False) -> None:
        """Add all of ``graphs`` in one transaction: all of them or none.

        With ``replace``, each named graph is emptied first (in the same
        transaction); otherwise the quads are added to what the graph holds.
        """

    @abc.abstractmethod
    def select(self, query: str, bindings: Bindings | None = None) -> Rows:
        """Run a SELECT; ``bindings`` are bound as RDF terms, never pasted into the text."""

    @abc.abstractmethod
    def ask(self, query: str, bindings: Bindings | None = None) -> bool: ...

    @abc.abstractmethod
    def update(self, update: str, bindings: Bindings | None = None) -> None:
        """Run a SPARQL Update atomically."""

    @abc.abstractmethod
    def graph_names(self) -> set[str]: ...

    @abc.abstractmethod
    def graph(self, name: str) -> list[Quad]:
        """The quads of one named graph (empty if it does not exist)."""

    @abc.abstractmethod
    def remove_graphs(self, names: Sequence[str]) -> None:
        """Drop these named graphs, in one transaction."""

    def close(self) -> None:  # noqa: B027 - optional for stores without resources
        """Release the store (files, connections)."""

    def __enter__(self) -> Store:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
