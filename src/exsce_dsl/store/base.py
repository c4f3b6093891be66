"""The store interface: named graphs of RDF, SPARQL in, plain values out.

Two implementations: :class:`exsce_dsl.store.embedded.EmbeddedStore`
(pyoxigraph in a project folder, the default) and
:class:`exsce_dsl.store.remote.RemoteStore` (any SPARQL 1.1 endpoint, through
the SPARQL 1.1 Protocol and the Graph Store Protocol).
:func:`exsce_dsl.store.open.open_store` picks one from a store URL.

Terms are pyoxigraph terms (``NamedNode``, ``Literal``, ``BlankNode``)
everywhere in this layer; callers outside ``store`` get plain Python values
from the typed query functions in :mod:`exsce_dsl.store.queries`.

Blank nodes follow SPARQL's ``INSERT DATA``: each :meth:`Store.write` makes
fresh blank nodes, one per label (a label names the same node in every graph
of one write), so two writes never share a blank node.
"""

from __future__ import annotations

import abc
from collections.abc import Iterator, Mapping, Sequence, Set
from dataclasses import dataclass

from pyoxigraph import BlankNode, Literal, NamedNode, Quad

from exsce_dsl.errors import StoreError

QUERY_TIMEOUT = 60.0
"""Seconds a query may take, evaluation and serialization, by default (``exscec serve``, ``exscec mcp``)."""
MAX_QUERY = 1024 * 1024
"""The longest query text ``exscec serve`` and ``exscec mcp`` accept (bytes)."""

Term = NamedNode | BlankNode | Literal
Bindings = Mapping[str, Term | Sequence[Term]]
"""Query parameters: variable name (without ``?``) → one term, or several (a VALUES list)."""


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
    commit: frozenset[str] = frozenset()
    """Graphs written in the write's last operation, after every other graph of the set is whole
    (and dropped first when replaced), on a server that cannot write the set in one transaction:
    readers that start from them never see half a write.  Elsewhere the write is one transaction."""


Replace = bool | Set[str]
"""Which graphs a write empties first: all of them (True), none (False), or those named."""


def replaced_names(graphs: GraphSet, replace: Replace) -> list[str]:
    """The graphs of ``graphs`` that ``replace`` says to empty first, in order."""
    if replace is True:
        return list(graphs.graphs)
    if replace is False:
        return []
    return [name for name in graphs.graphs if name in replace]


class Store(abc.ABC):
    """A dataset of named graphs (one per PROV bundle) that answers SPARQL."""

    location: str = "a store"
    """Where the store is, for messages: a folder, ``memory:``, or the endpoint's URL."""

    @abc.abstractmethod
    def write(self, graphs: GraphSet, *, replace: Replace = False) -> None:
        """Add all of ``graphs`` in one transaction: all of them or none.

        With ``replace`` (True, or a set of graph names), those named graphs
        are emptied first, in the same transaction; the others get the quads
        added to what they hold.  Writing is one bulk operation, never one
        call per quad.
        """

    @abc.abstractmethod
    def select(self, query: str, bindings: Bindings | None = None) -> Rows:
        """Run a SELECT; ``bindings`` are bound as RDF terms, never pasted into the text."""

    def select_first(self, query: str, most: int, bindings: Bindings | None = None) -> tuple[Rows, bool]:
        """The first ``most`` rows of a SELECT, and whether it has more.  A store that can stop
        reading solutions after ``most + 1`` does (the embedded one): a query with a billion
        solutions answers its first thousand without computing the rest."""
        rows = self.select(query, bindings)
        return Rows(rows.variables, rows.rows[:most]), len(rows) > most

    @abc.abstractmethod
    def ask(self, query: str, bindings: Bindings | None = None) -> bool: ...

    @abc.abstractmethod
    def update(self, update: str, bindings: Bindings | None = None) -> None:
        """Run a SPARQL Update atomically."""

    @abc.abstractmethod
    def graph_names(self) -> set[str]:
        """The names of the named graphs that hold at least one quad."""

    @abc.abstractmethod
    def graph(self, name: str) -> list[Quad]:
        """The quads of one named graph (empty if it does not exist)."""

    @abc.abstractmethod
    def remove_graphs(self, names: Sequence[str]) -> None:
        """Drop these named graphs, in one transaction."""

    def graphs(self, names: Sequence[str]) -> dict[str, list[Quad]]:
        """The quads of each of these named graphs (blank nodes consistent across them)."""
        return {name: self.graph(name) for name in names}

    def existing_graphs(self, names: Sequence[str]) -> set[str]:
        """Those of ``names`` that name a graph holding at least one quad (one query)."""
        if not names:
            return set()
        from exsce_dsl.store.sparql import graph_node, term_text  # sparql builds on this module

        values = " ".join(term_text(graph_node(name)) for name in dict.fromkeys(names))
        rows = self.select(f"SELECT DISTINCT ?g WHERE {{ VALUES ?g {{ {values} }} GRAPH ?g {{ ?s ?p ?o }} }}")
        return {g.value for (g,) in rows.rows if isinstance(g, NamedNode)}

    def graph_sizes(self) -> dict[str, int]:
        """Named graph → number of quads in it."""
        rows = self.select("SELECT ?g (COUNT(*) AS ?n) WHERE { GRAPH ?g { ?s ?p ?o } } GROUP BY ?g")
        sizes = {}
        for g, n in rows.rows:
            if isinstance(g, NamedNode) and isinstance(n, Literal):
                sizes[g.value] = int(n.value)
        return sizes

    def quads(self) -> list[Quad]:
        """Every quad of every named graph (the default graph is left out)."""
        rows = self.select("SELECT ?s ?p ?o ?g WHERE { GRAPH ?g { ?s ?p ?o } }")
        found = []
        for s, p, o, g in rows.rows:
            if isinstance(s, (NamedNode, BlankNode)) and isinstance(p, NamedNode) and o is not None:
                if isinstance(g, NamedNode):
                    found.append(Quad(s, p, o, g))
        return found

    def export(self, fmt: str = "trig") -> bytes:
        """Every named graph as TriG (``trig``, with exsce's prefixes) or N-Quads (``nq``)."""
        from pyoxigraph import RdfFormat, serialize

        from exsce_dsl.prov.identifiers import PROV_NAMESPACE, XSD_NAMESPACE, Namespaces

        if fmt == "trig":
            prefixes = {"prov": PROV_NAMESPACE, "xsd": XSD_NAMESPACE, **Namespaces().fixed}
            data = serialize(self.quads(), format=RdfFormat.TRIG, prefixes=prefixes)
        elif fmt == "nq":
            data = serialize(self.quads(), format=RdfFormat.N_QUADS)
        else:
            raise StoreError(f"cannot export as '{fmt}'; expected trig or nq")
        return data or b""

    def clear(self) -> None:
        """Remove everything, in one transaction."""
        self.update("DROP ALL")

    def close(self) -> None:  # noqa: B027 - optional for stores without resources
        """Release the store (files, connections)."""

    def __enter__(self) -> Store:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"<{type(self).__name__} {self.location}>"
