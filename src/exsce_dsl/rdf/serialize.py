"""Every format exsce writes a PROV document in: PROV-N/JSON/XML and PROV-O as RDF text.

PROV-N, PROV-JSON and PROV-XML are prov's own (:mod:`exsce_dsl.prov.serialize`);
Turtle, TriG, N-Quads and JSON-LD come from the PROV-O mapping
(:mod:`exsce_dsl.rdf.prov_o`), one named graph per bundle, in document order,
so that the same document always gives the same bytes.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import TYPE_CHECKING

from prov.model import ProvDocument
from pyoxigraph import BlankNode, DefaultGraph, Literal, NamedNode, Quad, Triple

from exsce_dsl.errors import ExportError
from exsce_dsl.prov.identifiers import RDF_LANG_STRING, XSD_STRING
from exsce_dsl.prov.serialize import PROV_FORMATS, serialize_prov
from exsce_dsl.rdf import text
from exsce_dsl.rdf.prov_o import nquad_lines, prefixes_of, quads_of_lines

if TYPE_CHECKING:  # rdflib is imported only when a dataset or graph is asked for
    from rdflib import Dataset, Graph
    from rdflib.term import Node

__all__ = ["FILE_SUFFIXES", "FORMATS", "RDF_FORMATS", "as_dataset", "as_graph", "serialize", "to_dataset"]

FILE_SUFFIXES: dict[str, str] = {
    "provn": ".provn",
    "json": ".json",
    "xml": ".xml",
    "ttl": ".ttl",
    "trig": ".trig",
    "nq": ".nq",
    "jsonld": ".jsonld",
}
"""Each format's usual file name suffix."""

FORMATS: tuple[str, ...] = tuple(FILE_SUFFIXES)
"""The formats :func:`serialize` writes."""

RDF_FORMATS: tuple[str, ...] = tuple(f for f in FORMATS if f not in PROV_FORMATS)
"""The formats of PROV-O: Turtle, TriG, N-Quads, JSON-LD."""


def serialize(document: ProvDocument, fmt: str) -> str:
    """``document`` as text in ``fmt``, one of :data:`FORMATS`.

    ``ttl`` holds every triple in one graph (Turtle has no named graphs);
    ``trig``, ``nq`` and ``jsonld`` keep one named graph per bundle, in the
    document's order.
    """
    if fmt in PROV_FORMATS:
        return serialize_prov(document, fmt)
    if fmt not in RDF_FORMATS:
        raise ExportError(f"unknown PROV format '{fmt}'; expected one of {', '.join(FORMATS)}")
    lines = nquad_lines(document)
    if fmt == "nq":
        return "".join(lines)
    quads = quads_of_lines(lines)
    prefixes = prefixes_of(document)
    if fmt == "ttl":
        return text.turtle(quads, prefixes)
    if fmt == "trig":
        return text.trig(quads, prefixes)
    return text.jsonld(quads, prefixes)


def to_dataset(document: ProvDocument) -> Dataset:
    """The document in PROV-O as an rdflib ``Dataset``: its own records in the
    default graph, one named graph per bundle, the document's prefixes bound."""
    return as_dataset(quads_of_lines(nquad_lines(document)), prefixes_of(document))


def as_dataset(quads: Iterable[Quad], prefixes: dict[str, str] | None = None) -> Dataset:
    """pyoxigraph quads as an rdflib ``Dataset`` (numbers keep their lexical form)."""
    from rdflib import Dataset
    from rdflib.graph import DATASET_DEFAULT_GRAPH_ID

    dataset = Dataset()
    for prefix, iri in (prefixes or {}).items():
        dataset.bind(prefix, iri, override=False)
    convert = _RdflibTerms()
    default = dataset.graph(DATASET_DEFAULT_GRAPH_ID)
    graphs: dict[NamedNode | BlankNode, Graph] = {}
    rows = []
    for q in quads:
        name = q.graph_name
        if isinstance(name, DefaultGraph):
            graph = default
        else:
            found = graphs.get(name)
            graph = graphs[name] = found if found is not None else dataset.graph(convert(name))  # type: ignore[arg-type]
        rows.append((convert(q.subject), convert(q.predicate), convert(q.object), graph))
    dataset.addN(rows)
    return dataset


def as_graph(quads: Iterable[Quad]) -> Graph:
    """The union of the quads' graphs as one rdflib ``Graph`` (for SHACL, which spans bundles)."""
    from rdflib import Graph

    graph = Graph()
    convert = _RdflibTerms()
    graph.addN((convert(q.subject), convert(q.predicate), convert(q.object), graph) for q in quads)
    return graph


class _RdflibTerms:
    """pyoxigraph term → rdflib term, each converted once."""

    def __init__(self) -> None:
        self._cache: dict[NamedNode | BlankNode | Literal, Node] = {}
        self._plain = {XSD_STRING, RDF_LANG_STRING}

    def __call__(self, term: NamedNode | BlankNode | Literal | Triple) -> Node:
        from rdflib import BNode, URIRef
        from rdflib import Literal as RdflibLiteral

        if isinstance(term, Triple):
            raise ExportError(f"rdflib cannot hold the triple term {term}")
        found = self._cache.get(term)
        if found is None:
            if isinstance(term, NamedNode):
                found = URIRef(term.value)
            elif isinstance(term, BlankNode):
                found = BNode(term.value)
            elif term.language:
                found = RdflibLiteral(term.value, lang=term.language)
            elif term.datatype.value in self._plain:
                found = RdflibLiteral(term.value)
            else:
                found = RdflibLiteral(term.value, datatype=URIRef(term.datatype.value), normalize=False)
            self._cache[term] = found
        return found
