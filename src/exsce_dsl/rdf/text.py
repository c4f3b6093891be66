"""RDF as text: Turtle, TriG, N-Quads and JSON-LD, from pyoxigraph quads, in their order.

Written here rather than by an RDF library: rdflib's TriG, N-Quads and JSON-LD
writers iterate over sets (their text changes from one process to the next)
and its Turtle writer takes about 80 µs a triple; pyoxigraph's writers keep
the order but only group consecutive triples of a subject, and its JSON-LD
has no context.  These group every subject's triples in one statement, in
the order the subjects come, and spell IRIs with the given prefixes.  The
tests read every text back with rdflib's parsers.
"""

from __future__ import annotations

import json
import re
from collections.abc import Iterable
from typing import Any

from pyoxigraph import BlankNode, DefaultGraph, Literal, NamedNode, Quad, Triple

from exsce_dsl.errors import ExportError
from exsce_dsl.prov.identifiers import RDF_LANG_STRING, RDF_TYPE, XSD_STRING
from exsce_dsl.rdf.prov_o import iri_ref, quoted

__all__ = ["jsonld", "nquads", "trig", "turtle"]

_Term = NamedNode | BlankNode | Literal | Triple
_Triple = tuple[_Term, NamedNode, _Term]

_LOCAL_NAME = re.compile(r"[A-Za-z0-9_](?:[A-Za-z0-9_.\-]*[A-Za-z0-9_\-])?")
_RDF_TYPE = NamedNode(RDF_TYPE)
_XSD_STRING = NamedNode(XSD_STRING)
_RDF_LANG_STRING = NamedNode(RDF_LANG_STRING)


class _Spelling:
    """How terms are written: in full (N-Quads), or with prefixes (Turtle, TriG, JSON-LD)."""

    def __init__(self, prefixes: dict[str, str]) -> None:
        self.prefixes = prefixes
        self._prefix_of: dict[str, str] = {}
        for prefix, iri in prefixes.items():
            self._prefix_of.setdefault(iri, prefix)
        self._separators = frozenset(iri[-1] for iri in prefixes.values() if iri)
        self._curies: dict[str, str | None] = {}
        self._short: dict[_Term, str] = {}
        self._full: dict[_Term, str] = {}

    def curie(self, iri: str) -> str | None:
        """``prefix:local`` for ``iri`` (longest namespace), or None."""
        if iri in self._curies:
            return self._curies[iri]
        found = None
        for end in range(len(iri) - 2, -1, -1):
            if iri[end] in self._separators:
                prefix = self._prefix_of.get(iri[: end + 1])
                if prefix is not None:
                    local = iri[end + 1 :]
                    found = f"{prefix}:{local}" if _LOCAL_NAME.fullmatch(local) else None
                    break
        self._curies[iri] = found
        return found

    def short(self, term: _Term) -> str:
        """Turtle and TriG."""
        text = self._short.get(term)
        if text is None:
            if isinstance(term, NamedNode):
                text = self.curie(term.value) or iri_ref(term.value)
            elif isinstance(term, Literal) and _is_typed(term):
                text = quoted(term.value) + "^^" + self.short(term.datatype)
            else:
                text = self.full(term)
            self._short[term] = text
        return text

    def full(self, term: _Term) -> str:
        """N-Quads."""
        text = self._full.get(term)
        if text is None:
            if isinstance(term, NamedNode):
                text = iri_ref(term.value)
            elif isinstance(term, BlankNode):
                text = f"_:{term.value}"
            elif isinstance(term, Triple):  # an RDF 1.2 triple term, in Oxigraph's own spelling
                text = str(term)
            else:
                text = quoted(term.value)
                if term.language:
                    text += f"@{term.language}"
                elif _is_typed(term):
                    text += "^^" + iri_ref(term.datatype.value)
            self._full[term] = text
        return text

    def header(self) -> str:
        return "".join(f"@prefix {p}: {iri_ref(iri)} .\n" for p, iri in self.prefixes.items())


def _is_typed(literal: Literal) -> bool:
    """True unless the literal is a plain or language-tagged string."""
    return literal.datatype != _XSD_STRING and literal.datatype != _RDF_LANG_STRING


def _graph(graph: NamedNode | BlankNode | DefaultGraph) -> NamedNode | BlankNode | None:
    return None if isinstance(graph, DefaultGraph) else graph


def _statements(triples: Iterable[_Triple], spell: _Spelling, indent: str) -> str:
    """Turtle statements, one per subject, in the order the subjects come."""
    subjects: dict[_Term, dict[NamedNode, list[_Term]]] = {}
    for s, p, o in triples:
        subjects.setdefault(s, {}).setdefault(p, []).append(o)
    blocks = []
    more = f" ;\n{indent}    "
    for subject, predicates in subjects.items():
        parts = [
            ("a" if p == _RDF_TYPE else spell.short(p)) + " " + ", ".join(spell.short(o) for o in objects)
            for p, objects in predicates.items()
        ]
        blocks.append(f"{indent}{spell.short(subject)} {more.join(parts)} .\n")
    return "\n".join(blocks)


def turtle(quads: Iterable[Quad], prefixes: dict[str, str]) -> str:
    """Every triple in one graph (Turtle has no named graphs), each once."""
    spell = _Spelling(prefixes)
    triples = dict.fromkeys((s, p, o) for s, p, o, _ in quads)
    return spell.header() + "\n" + _statements(triples, spell, "")


def trig(quads: Iterable[Quad], prefixes: dict[str, str]) -> str:
    """One block per graph, the default graph's first when it has triples."""
    spell = _Spelling(prefixes)
    graphs: dict[NamedNode | BlankNode | None, list[_Triple]] = {}
    for s, p, o, g in quads:
        graphs.setdefault(_graph(g), []).append((s, p, o))
    parts = [spell.header()]
    for name, triples in graphs.items():
        label = "" if name is None else spell.short(name) + " "
        parts.append(f"\n{label}{{\n{_statements(triples, spell, '    ')}}}\n")
    return "".join(parts)


def nquads(quads: Iterable[Quad]) -> str:
    """One line per quad, in the quads' order."""
    full = _Spelling({}).full
    lines = []
    for s, p, o, g in quads:
        graph = _graph(g)
        name = "" if graph is None else " " + full(graph)
        lines.append(f"{full(s)} {full(p)} {full(o)}{name} .\n")
    return "".join(lines)


def jsonld(quads: Iterable[Quad], prefixes: dict[str, str]) -> str:
    """JSON-LD 1.1 with the prefixes as context, one ``@graph`` per named graph."""
    spell = _Spelling(prefixes)

    def iri(term: _Term) -> str:
        if isinstance(term, BlankNode):
            return f"_:{term.value}"
        if isinstance(term, NamedNode):
            return spell.curie(term.value) or term.value
        raise ExportError(f"JSON-LD cannot hold the term {term}")

    def value(term: _Term) -> dict[str, str]:
        if not isinstance(term, Literal):
            return {"@id": iri(term)}
        if term.language:
            return {"@value": term.value, "@language": term.language}
        if not _is_typed(term):
            return {"@value": term.value}
        return {"@value": term.value, "@type": iri(term.datatype)}

    graphs: dict[NamedNode | BlankNode | None, dict[_Term, dict[str, Any]]] = {None: {}}
    for s, p, o, g in quads:
        nodes = graphs.setdefault(_graph(g), {})
        node = nodes.get(s)
        if node is None:
            node = nodes[s] = {"@id": iri(s)}
        if p == _RDF_TYPE and isinstance(o, NamedNode):
            node.setdefault("@type", []).append(iri(o))
        else:
            node.setdefault(iri(p), []).append(value(o))
    top: list[dict[str, Any]] = list(graphs.pop(None).values())
    for name, nodes in graphs.items():
        assert name is not None
        top.append({"@id": iri(name), "@graph": list(nodes.values())})
    document = {"@context": spell.prefixes, "@graph": top}
    return json.dumps(document, indent=2, ensure_ascii=False) + "\n"
