"""Write a PROV document as text: PROV-N, PROV-JSON, PROV-XML, or PROV-O in RDF.

PROV-N, PROV-JSON and PROV-XML come from prov's own serialisers (PROV-XML
needs lxml, prov's ``xml`` extra).  The RDF formats come from a direct mapping
of the document's records to PROV-O quads, one named graph per bundle
(prov's own PROV-O serialiser is about twenty times slower, and its Turtle
flattens the bundles).  :func:`to_dataset` gives those quads as an rdflib
``Dataset``; Turtle, TriG, N-Quads and JSON-LD are written straight from them,
in document order (rdflib's writers order graphs and subjects as Python sets
do, so their text changes from one process to the next).

The mapping, record by record:

* an entity, activity or agent is an instance of ``prov:Entity``,
  ``prov:Activity`` or ``prov:Agent``; a ``prov:type`` that is a qualified name
  is an ``rdf:type``, one that is a literal stays a ``prov:type`` value;
  ``prov:label`` is ``rdfs:label``, ``prov:location`` is ``prov:atLocation``,
  start and end times are ``prov:startedAtTime`` and ``prov:endedAtTime``;
* a relation is its binary property (``prov:wasDerivedFrom``, ``prov:used``,
  ``prov:hadMember``...) between its first two arguments and, when it has an
  identifier or anything beyond those two arguments, also its qualified form:
  ``prov:qualifiedDerivation`` to a ``prov:Derivation`` node (the relation's
  identifier, or a blank node) holding the second argument (``prov:entity``),
  the other arguments (``prov:hadActivity``, ``prov:hadPlan``, ``prov:atTime``...),
  ``prov:hadRole`` for ``prov:role`` and every other attribute.  A derivation
  typed ``prov:PrimarySource``, ``prov:Revision`` or ``prov:Quotation`` also gets
  that relation's own property (``prov:hadPrimarySource``...) and qualifies
  through ``prov:qualifiedPrimarySource``...;
* attribute values: qualified names are IRIs, strings are plain literals,
  floats are ``xsd:double`` (written in full, never shortened), booleans
  ``xsd:boolean``, integers ``xsd:int`` (``xsd:long``/``xsd:integer`` when larger),
  date-times ``xsd:dateTime``, typed literals keep their datatype.

Blank nodes are numbered in document order, so the same document always gives
the same text.
"""

from __future__ import annotations

import datetime
import json
import math
import re
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from typing import Any

from prov.constants import (
    PROV_ACTIVITY,
    PROV_AGENT,
    PROV_ALTERNATE,
    PROV_ASSOCIATION,
    PROV_ATTR_ENDTIME,
    PROV_ATTR_STARTTIME,
    PROV_ATTRIBUTION,
    PROV_COMMUNICATION,
    PROV_DELEGATION,
    PROV_DERIVATION,
    PROV_END,
    PROV_ENTITY,
    PROV_GENERATION,
    PROV_INFLUENCE,
    PROV_INVALIDATION,
    PROV_LABEL,
    PROV_LOCATION,
    PROV_MEMBERSHIP,
    PROV_MENTION,
    PROV_ROLE,
    PROV_SPECIALIZATION,
    PROV_START,
    PROV_TYPE,
    PROV_USAGE,
)
from prov.identifier import Identifier, QualifiedName
from prov.model import Literal as ProvLiteral
from prov.model import ProvBundle, ProvDocument, ProvRecord
from prov.serializers import DoNotExist
from rdflib import RDF, RDFS, XSD, BNode, Dataset, Graph, Literal, URIRef
from rdflib.graph import DATASET_DEFAULT_GRAPH_ID
from rdflib.term import Node

from exsce_dsl.errors import ExportError
from exsce_dsl.prov.identifiers import PROV_NAMESPACE, XSD_NAMESPACE, is_valid_prefix

__all__ = ["FORMATS", "FILE_SUFFIXES", "serialize", "to_dataset"]

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


def serialize(document: ProvDocument, fmt: str) -> str:
    """``document`` as text in ``fmt``, one of :data:`FORMATS`.

    ``ttl`` holds every triple in one graph (Turtle has no named graphs);
    ``trig``, ``nq`` and ``jsonld`` keep one named graph per bundle, in the
    document's order.
    """
    if fmt == "provn":
        return str(document.get_provn())
    if fmt == "json":
        return _prov_text(document, "json", indent=2)
    if fmt == "xml":
        return _prov_text(document, "xml")
    if fmt == "ttl":
        return _turtle(document)
    if fmt == "trig":
        return _trig(document)
    if fmt == "nq":
        return _nquads(document)
    if fmt == "jsonld":
        return _jsonld(document)
    raise ExportError(f"unknown PROV format '{fmt}'; expected one of {', '.join(FORMATS)}")


def to_dataset(document: ProvDocument) -> Dataset:
    """The document in PROV-O: its own records in the default graph, one named graph per bundle."""
    dataset = Dataset()
    for prefix, iri in _prefixes(document).items():
        dataset.bind(prefix, iri, override=False)
    graphs: dict[URIRef | None, Graph] = {None: dataset.graph(DATASET_DEFAULT_GRAPH_ID)}
    quads = []
    for graph_name, s, p, o in _quads(document):
        graph = graphs.get(graph_name)
        if graph is None:
            graph = graphs[graph_name] = dataset.graph(graph_name)
        quads.append((s, p, o, graph))
    dataset.addN(quads)
    return dataset


def _prov_text(document: ProvDocument, fmt: str, **options: Any) -> str:
    try:
        serialized = document.serialize(format=fmt, **options)
    except DoNotExist as missing:  # PROV-XML needs lxml, prov's "xml" extra
        raise ExportError(f"cannot write PROV-{fmt.upper()}: {missing}") from missing
    if serialized is None:  # pragma: no cover - only with a destination
        raise ExportError(f"prov wrote no PROV-{fmt.upper()}")
    return serialized


def _prefixes(document: ProvDocument) -> dict[str, str]:
    """Prefix name → IRI of the document's and its bundles' namespaces (first one wins)."""
    found = {"prov": PROV_NAMESPACE, "xsd": XSD_NAMESPACE, "rdf": str(RDF), "rdfs": str(RDFS)}
    containers: list[ProvBundle] = [document, *document.bundles]
    for container in containers:
        for namespace in container.get_registered_namespaces():
            prefix, iri = namespace.prefix, namespace.uri
            usable = is_valid_prefix(prefix) and prefix not in _IRI_SCHEMES
            if usable and iri[-1:] in _GEN_DELIMS:
                found.setdefault(prefix, iri)
    return found


# -- the RDF texts -------------------------------------------------------------
#
# Written here rather than by rdflib: its TriG, N-Quads and JSON-LD writers
# iterate over sets, and its Turtle writer takes about 80 µs a triple.  The
# tests read every text back with rdflib's parsers.

_IRI_SCHEMES = frozenset({"http", "https", "urn", "file", "mailto", "tag", "data"})
"""Prefix names that would read as the scheme of a full IRI in JSON-LD."""

_GEN_DELIMS = frozenset(":/?#[]@")
"""How a namespace must end for JSON-LD to use it as a prefix."""

_LOCAL_NAME = re.compile(r"[A-Za-z0-9_](?:[A-Za-z0-9_.\-]*[A-Za-z0-9_\-])?")
_IRI_ESCAPES = re.compile(r'[\x00-\x20<>"{}|^`\\]')
_STRING_ESCAPES = {ord("\\"): "\\\\", ord('"'): '\\"', ord("\n"): "\\n", ord("\r"): "\\r"}


def _iri_ref(iri: str) -> str:
    return "<" + _IRI_ESCAPES.sub(lambda m: f"\\u{ord(m[0]):04X}", iri) + ">"


def _quoted(text: str) -> str:
    return '"' + text.translate(_STRING_ESCAPES) + '"'


class _Spelling:
    """How terms are written: in full (N-Quads), or with the document's prefixes."""

    def __init__(self, prefixes: dict[str, str]) -> None:
        self.prefixes = prefixes
        self._prefix_of: dict[str, str] = {}
        for prefix, iri in prefixes.items():
            self._prefix_of.setdefault(iri, prefix)
        self._separators = frozenset(iri[-1] for iri in prefixes.values() if iri)
        self._curies: dict[str, str | None] = {}
        self._short: dict[Node, str] = {}
        self._full: dict[Node, str] = {}

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

    def short(self, term: Node) -> str:
        """Turtle and TriG."""
        text = self._short.get(term)
        if text is None:
            if isinstance(term, URIRef):
                text = self.curie(str(term)) or _iri_ref(str(term))
            elif isinstance(term, Literal) and term.datatype is not None:
                text = _quoted(str(term)) + "^^" + self.short(term.datatype)
            else:
                text = self.full(term)
            self._short[term] = text
        return text

    def full(self, term: Node) -> str:
        """N-Quads."""
        text = self._full.get(term)
        if text is None:
            if isinstance(term, URIRef):
                text = _iri_ref(str(term))
            elif isinstance(term, BNode):
                text = f"_:{term}"
            else:
                assert isinstance(term, Literal)
                text = _quoted(str(term))
                if term.language:
                    text += f"@{term.language}"
                elif term.datatype is not None:
                    text += "^^" + _iri_ref(str(term.datatype))
            self._full[term] = text
        return text

    def header(self) -> str:
        return "".join(f"@prefix {p}: {_iri_ref(iri)} .\n" for p, iri in self.prefixes.items())


_Triple = tuple[Node, URIRef, Node]


def _statements(triples: Iterable[_Triple], spell: _Spelling, indent: str) -> str:
    """Turtle statements, one per subject, in the order the subjects come."""
    subjects: dict[Node, dict[URIRef, list[Node]]] = {}
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


def _unique_quads(document: ProvDocument) -> list[_Quad]:
    return list(dict.fromkeys(_quads(document)))


def _turtle(document: ProvDocument) -> str:
    spell = _Spelling(_prefixes(document))
    triples = dict.fromkeys((s, p, o) for _, s, p, o in _quads(document))
    return spell.header() + "\n" + _statements(triples, spell, "")


def _trig(document: ProvDocument) -> str:
    spell = _Spelling(_prefixes(document))
    graphs: dict[URIRef | None, list[_Triple]] = {}
    for graph, s, p, o in _unique_quads(document):
        graphs.setdefault(graph, []).append((s, p, o))
    parts = [spell.header()]
    for name, triples in graphs.items():
        label = "" if name is None else spell.short(name) + " "
        parts.append(f"\n{label}{{\n{_statements(triples, spell, '    ')}}}\n")
    return "".join(parts)


def _nquads(document: ProvDocument) -> str:
    """N-Quads, one line per quad in document order (the default graph's first)."""
    full = _Spelling({}).full
    lines = []
    for graph, s, p, o in _unique_quads(document):
        name = "" if graph is None else " " + full(graph)
        lines.append(f"{full(s)} {full(p)} {full(o)}{name} .\n")
    return "".join(lines)


def _jsonld(document: ProvDocument) -> str:
    """JSON-LD 1.1 with the document's prefixes as context, one ``@graph`` per bundle."""
    spell = _Spelling(_prefixes(document))

    def iri(term: Node) -> str:
        if isinstance(term, BNode):
            return f"_:{term}"
        return spell.curie(str(term)) or str(term)

    def value(term: Node) -> dict[str, str]:
        if not isinstance(term, Literal):
            return {"@id": iri(term)}
        if term.language:
            return {"@value": str(term), "@language": term.language}
        if term.datatype is None or term.datatype == XSD.string:
            return {"@value": str(term)}
        return {"@value": str(term), "@type": iri(term.datatype)}

    graphs: dict[URIRef | None, dict[Node, dict[str, Any]]] = {None: {}}
    for graph, s, p, o in _unique_quads(document):
        nodes = graphs.setdefault(graph, {})
        node = nodes.get(s)
        if node is None:
            node = nodes[s] = {"@id": iri(s)}
        if p == _RDF_TYPE and isinstance(o, URIRef):
            node.setdefault("@type", []).append(iri(o))
        else:
            node.setdefault(iri(p), []).append(value(o))
    top: list[dict[str, Any]] = list(graphs.pop(None).values())
    for name, nodes in graphs.items():
        assert name is not None
        top.append({"@id": iri(name), "@graph": list(nodes.values())})
    document_ld = {"@context": spell.prefixes, "@graph": top}
    return json.dumps(document_ld, indent=2, ensure_ascii=False) + "\n"


# -- the mapping ---------------------------------------------------------------

_Quad = tuple[URIRef | None, Node, URIRef, Node]


def _p(local: str) -> URIRef:
    return URIRef(PROV_NAMESPACE + local)


@dataclass(frozen=True)
class _RelationForm:
    """How one kind of relation is written in PROV-O."""

    binary: URIRef
    qualified: URIRef | None = None
    node_class: URIRef | None = None
    object_property: URIRef | None = None
    """The node's property for the relation's second argument."""
    others: tuple[URIRef, ...] = ()
    """The node's properties for the third and later arguments, in order."""


_RELATIONS: dict[QualifiedName, _RelationForm] = {
    PROV_GENERATION: _RelationForm(
        _p("wasGeneratedBy"),
        _p("qualifiedGeneration"),
        _p("Generation"),
        _p("activity"),
        (_p("atTime"),),
    ),
    PROV_USAGE: _RelationForm(_p("used"), _p("qualifiedUsage"), _p("Usage"), _p("entity"), (_p("atTime"),)),
    PROV_COMMUNICATION: _RelationForm(
        _p("wasInformedBy"), _p("qualifiedCommunication"), _p("Communication"), _p("activity")
    ),
    PROV_START: _RelationForm(
        _p("wasStartedBy"),
        _p("qualifiedStart"),
        _p("Start"),
        _p("entity"),
        (_p("hadActivity"), _p("atTime")),
    ),
    PROV_END: _RelationForm(
        _p("wasEndedBy"),
        _p("qualifiedEnd"),
        _p("End"),
        _p("entity"),
        (_p("hadActivity"), _p("atTime")),
    ),
    PROV_INVALIDATION: _RelationForm(
        _p("wasInvalidatedBy"),
        _p("qualifiedInvalidation"),
        _p("Invalidation"),
        _p("activity"),
        (_p("atTime"),),
    ),
    PROV_DERIVATION: _RelationForm(
        _p("wasDerivedFrom"),
        _p("qualifiedDerivation"),
        _p("Derivation"),
        _p("entity"),
        (_p("hadActivity"), _p("hadGeneration"), _p("hadUsage")),
    ),
    PROV_ATTRIBUTION: _RelationForm(
        _p("wasAttributedTo"), _p("qualifiedAttribution"), _p("Attribution"), _p("agent")
    ),
    PROV_ASSOCIATION: _RelationForm(
        _p("wasAssociatedWith"),
        _p("qualifiedAssociation"),
        _p("Association"),
        _p("agent"),
        (_p("hadPlan"),),
    ),
    PROV_DELEGATION: _RelationForm(
        _p("actedOnBehalfOf"),
        _p("qualifiedDelegation"),
        _p("Delegation"),
        _p("agent"),
        (_p("hadActivity"),),
    ),
    PROV_INFLUENCE: _RelationForm(
        _p("wasInfluencedBy"), _p("qualifiedInfluence"), _p("Influence"), _p("influencer")
    ),
    PROV_SPECIALIZATION: _RelationForm(_p("specializationOf")),
    PROV_ALTERNATE: _RelationForm(_p("alternateOf")),
    PROV_MENTION: _RelationForm(_p("mentionOf"), others=(_p("asInBundle"),)),
    PROV_MEMBERSHIP: _RelationForm(_p("hadMember")),
}

_DERIVATION = _RELATIONS[PROV_DERIVATION]

_DERIVATION_KINDS: dict[str, tuple[URIRef, URIRef]] = {
    f"{PROV_NAMESPACE}PrimarySource": (_p("hadPrimarySource"), _p("qualifiedPrimarySource")),
    f"{PROV_NAMESPACE}Revision": (_p("wasRevisionOf"), _p("qualifiedRevision")),
    f"{PROV_NAMESPACE}Quotation": (_p("wasQuotedFrom"), _p("qualifiedQuotation")),
}

_ELEMENT_CLASSES = {
    PROV_ENTITY: _p("Entity"),
    PROV_ACTIVITY: _p("Activity"),
    PROV_AGENT: _p("Agent"),
}

_ATTRIBUTE_PROPERTIES = {
    PROV_LABEL: RDFS.label,
    PROV_LOCATION: _p("atLocation"),
    PROV_ROLE: _p("hadRole"),
    PROV_ATTR_STARTTIME: _p("startedAtTime"),
    PROV_ATTR_ENDTIME: _p("endedAtTime"),
}
_PROV_TYPE_LITERAL = _p("type")
_RDF_TYPE = URIRef(str(RDF) + "type")


class _Double(Literal):
    """An ``xsd:double`` that Turtle and TriG write in full.

    rdflib writes a bare ``xsd:double`` in Turtle as ``%e`` (seven significant
    digits), which would round coordinates; this keeps the quoted, typed form.
    """

    def _literal_n3(
        self,
        use_plain: bool = False,
        qname_callback: Callable[[URIRef], str | None] | None = None,
    ) -> str:
        return super()._literal_n3(False, qname_callback)


class _Terms:
    """RDF terms for attribute values and names, made once per value."""

    def __init__(self) -> None:
        self._iris: dict[str, URIRef] = {}
        self._literals: dict[tuple[type, Any], Node] = {}
        self._blank = 0

    def iri(self, qname: QualifiedName) -> URIRef:
        uri = qname.uri
        found = self._iris.get(uri)
        if found is None:
            found = self._iris[uri] = URIRef(uri)
        return found

    def blank(self) -> BNode:
        self._blank += 1
        return BNode(f"q{self._blank}")

    def value(self, value: Any) -> Node:
        if isinstance(value, QualifiedName):
            return self.iri(value)
        if isinstance(value, ProvRecord):
            return self.iri(_identifier(value))
        key = (type(value), value)
        found = self._literals.get(key)
        if found is None:
            found = self._literals[key] = _literal(value)
        return found


def _identifier(record: ProvRecord) -> QualifiedName:
    if record.identifier is None:  # pragma: no cover - prov requires one for elements
        raise ExportError(f"a PROV {record.get_type()} has no identifier")
    return record.identifier


def _literal(value: Any) -> Node:
    if isinstance(value, bool):
        return Literal("true" if value else "false", datatype=XSD.boolean)
    if isinstance(value, int):
        if -(2**31) <= value < 2**31:
            return Literal(str(value), datatype=XSD.int)
        if -(2**63) <= value < 2**63:
            return Literal(str(value), datatype=XSD.long)
        return Literal(str(value), datatype=XSD.integer)
    if isinstance(value, float):
        if math.isnan(value):
            text = "NaN"
        elif math.isinf(value):
            text = "INF" if value > 0 else "-INF"
        else:
            text = repr(value)
        return _Double(text, datatype=XSD.double, normalize=False)
    if isinstance(value, datetime.datetime):
        return Literal(value.isoformat(), datatype=XSD.dateTime)
    if isinstance(value, ProvLiteral):
        if value.langtag:
            return Literal(value.value, lang=value.langtag)
        datatype = value.datatype
        return Literal(value.value, datatype=URIRef(datatype.uri) if datatype else None)
    if isinstance(value, Identifier):
        return Literal(value.uri, datatype=XSD.anyURI)
    return Literal(str(value))


def _quads(document: ProvDocument) -> Iterator[_Quad]:
    terms = _Terms()
    yield from _bundle_quads(document, None, terms)
    for bundle in document.bundles:
        identifier = bundle.identifier
        assert identifier is not None  # a document's bundles are named
        yield from _bundle_quads(bundle, terms.iri(identifier), terms)


def _bundle_quads(bundle: ProvBundle, graph: URIRef | None, terms: _Terms) -> Iterator[_Quad]:
    for record in bundle.get_records():
        if record.is_element():
            yield from _element_quads(record, graph, terms)
        else:
            yield from _relation_quads(record, graph, terms)


def _attribute_quads(subject: Node, attributes: Any, graph: URIRef | None, terms: _Terms) -> Iterator[_Quad]:
    for name, value in attributes:
        if value is None:
            continue
        if name == PROV_TYPE:
            if isinstance(value, QualifiedName):
                yield graph, subject, _RDF_TYPE, terms.iri(value)
            else:
                yield graph, subject, _PROV_TYPE_LITERAL, terms.value(value)
            continue
        predicate = _ATTRIBUTE_PROPERTIES.get(name)
        yield graph, subject, predicate or terms.iri(name), terms.value(value)


def _element_quads(record: ProvRecord, graph: URIRef | None, terms: _Terms) -> Iterator[_Quad]:
    subject = terms.iri(_identifier(record))
    yield graph, subject, _RDF_TYPE, _ELEMENT_CLASSES[record.get_type()]
    yield from _attribute_quads(subject, record.formal_attributes, graph, terms)
    yield from _attribute_quads(subject, record.extra_attributes, graph, terms)


def _relation_quads(record: ProvRecord, graph: URIRef | None, terms: _Terms) -> Iterator[_Quad]:
    form = _RELATIONS[record.get_type()]
    formal = record.formal_attributes
    extra = record.extra_attributes
    first, second = formal[0][1], formal[1][1]
    if first is None:  # nothing to hang the relation on
        return
    subject = terms.iri(first)
    binary, qualified = form.binary, form.qualified
    if form is _DERIVATION:
        for name, value in extra:
            if name == PROV_TYPE and isinstance(value, QualifiedName):
                kind = _DERIVATION_KINDS.get(value.uri)
                if kind is not None and second is not None:
                    yield graph, subject, kind[0], terms.iri(second)
                    qualified = kind[1]
    if second is not None:
        yield graph, subject, binary, terms.value(second)
    if qualified is None or form.node_class is None:
        for _, value in formal[2:]:  # mentionOf's bundle
            if value is not None and form.others:
                yield graph, subject, form.others[0], terms.value(value)
        return
    has_more = any(value is not None for _, value in formal[2:]) or bool(extra)
    if record.identifier is None and not has_more:
        return
    node: Node = terms.iri(record.identifier) if record.identifier else terms.blank()
    yield graph, subject, qualified, node
    yield graph, node, _RDF_TYPE, form.node_class
    if second is not None and form.object_property is not None:
        yield graph, node, form.object_property, terms.value(second)
    for predicate, (_, value) in zip(form.others, formal[2:], strict=False):
        if value is not None:
            yield graph, node, predicate, terms.value(value)
    yield from _attribute_quads(node, extra, graph, terms)
