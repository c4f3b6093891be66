"""PROV documents in PROV-O: N-Quads lines and pyoxigraph quads, one named graph per bundle.

prov's own PROV-O serialiser is about twenty times slower than this mapping,
and its Turtle flattens the bundles.  Here each record becomes its quads
directly, every term is spelt in N-Triples syntax once per distinct name or
value, and the lines are handed to pyoxigraph's parser when quads are wanted
(building each ``Quad`` from Python costs more than Oxigraph's parser does
for a whole line; ``bench/rdf.py`` measures both).

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

Blank nodes are numbered in document order and duplicate quads are dropped,
so the same document always gives the same lines in the same order.
"""

from __future__ import annotations

import datetime
import functools
import gc
import math
import re
from collections.abc import Iterable
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
from pyoxigraph import Quad, RdfFormat, parse

from exsce_dsl.errors import ExportError
from exsce_dsl.prov.identifiers import (
    PROV_NAMESPACE,
    RDF_NAMESPACE,
    RDF_TYPE,
    RDFS_NAMESPACE,
    XSD_NAMESPACE,
    is_valid_prefix,
)

__all__ = ["nquad_lines", "prefixes_of", "quads_of_lines", "to_quads"]

_IRI_SCHEMES = frozenset({"http", "https", "urn", "file", "mailto", "tag", "data"})
"""Prefix names that would read as the scheme of a full IRI in JSON-LD."""

_GEN_DELIMS = frozenset(":/?#[]@")
"""How a namespace must end for JSON-LD to use it as a prefix."""


def to_quads(document: ProvDocument) -> list[Quad]:
    """The document in PROV-O, as pyoxigraph quads in document order, each once.

    The document's own records are in the default graph, each bundle's in the
    named graph of the bundle's identifier.
    """
    return quads_of_lines(nquad_lines(document))


def nquad_lines(document: ProvDocument, blank_prefix: str = "q") -> list[str]:
    """The document in PROV-O as N-Quads lines (each ending in a newline), each once.

    Blank nodes are labelled ``_:<blank_prefix><n>``: a prefix of its own for each document
    keeps two documents' blank nodes apart when their lines are loaded together.
    Raises :class:`~exsce_dsl.errors.ExportError` for a name that is not an
    absolute IRI (RDF cannot hold it).
    """
    was_enabled = gc.isenabled()
    gc.disable()  # tens of thousands of strings that all stay alive: nothing to collect
    try:
        if not blank_prefix.isalnum() or not blank_prefix.isascii():
            raise ValueError(f"a blank node prefix is letters and digits, not {blank_prefix!r}")
        mapper = _Mapper(blank_prefix)
        mapper.document(document)
        return list(dict.fromkeys(mapper.out))
    finally:
        if was_enabled:
            gc.enable()


def quads_of_lines(lines: list[str]) -> list[Quad]:
    """Parse N-Quads lines, as :func:`nquad_lines` writes them, into pyoxigraph quads.

    The parser is lenient (it skips checking IRIs again): :func:`nquad_lines`
    has checked every IRI and language tag it wrote, once per distinct one.
    """
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        return list(parse("".join(lines), format=RdfFormat.N_QUADS, lenient=True))
    except SyntaxError as exc:  # pragma: no cover - nquad_lines writes valid N-Quads
        raise ExportError(f"the document cannot be written as RDF: {exc}") from None
    finally:
        if was_enabled:
            gc.enable()


def prefixes_of(document: ProvDocument) -> dict[str, str]:
    """Prefix name → IRI of the document's and its bundles' namespaces (first one wins).

    Only names that every RDF syntax accepts as prefixes, for namespaces that
    end in a separator, are kept.
    """
    found = {"prov": PROV_NAMESPACE, "xsd": XSD_NAMESPACE, "rdf": RDF_NAMESPACE, "rdfs": RDFS_NAMESPACE}
    containers: list[ProvBundle] = [document, *document.bundles]
    for container in containers:
        for namespace in container.get_registered_namespaces():
            prefix, iri = namespace.prefix, namespace.uri
            usable = is_valid_prefix(prefix) and prefix not in _IRI_SCHEMES
            if usable and iri[-1:] in _GEN_DELIMS:
                found.setdefault(prefix, iri)
    return found


# -- spelling terms in N-Triples syntax ------------------------------------------

_IRI_ESCAPES = re.compile(r'[\x00-\x20<>"{}|^`\\]')
_STRING_ESCAPES = {ord("\\"): "\\\\", ord('"'): '\\"', ord("\n"): "\\n", ord("\r"): "\\r"}


def iri_ref(iri: str) -> str:
    """``<iri>``, with the characters an IRI reference cannot hold escaped."""
    return "<" + _IRI_ESCAPES.sub(lambda m: f"\\u{ord(m[0]):04X}", iri) + ">"


def quoted(text: str) -> str:
    """A string literal's quoted form (N-Triples, Turtle)."""
    return '"' + text.translate(_STRING_ESCAPES) + '"'


def _p(local: str) -> str:
    return iri_ref(PROV_NAMESPACE + local)


def _xsd(local: str) -> str:
    return iri_ref(XSD_NAMESPACE + local)


_XSD_BOOLEAN, _XSD_INT, _XSD_LONG, _XSD_INTEGER = _xsd("boolean"), _xsd("int"), _xsd("long"), _xsd("integer")
_XSD_DOUBLE, _XSD_DATETIME, _XSD_ANY_URI = _xsd("double"), _xsd("dateTime"), _xsd("anyURI")
_RDF_TYPE = iri_ref(RDF_TYPE)
_RDFS_LABEL = iri_ref(RDFS_NAMESPACE + "label")


_IRI = re.compile(r"[A-Za-z][A-Za-z0-9+.\-]*:[^\x00-\x20<>\"{}|^`\\]*")
_LANGUAGE_TAG = re.compile(r"[A-Za-z]{1,8}(?:-[A-Za-z0-9]{1,8})*")


class _Terms:
    """N-Triples spellings of names and values, each made (and checked) once."""

    def __init__(self, blank_prefix: str = "q") -> None:
        self._iris: dict[str, str] = {}
        self._literals: dict[tuple[type, Any], str] = {}
        self._blank = 0
        self._blank_label = f"_:{blank_prefix}"

    def iri(self, qname: Identifier) -> str:
        uri = qname._uri
        found = self._iris.get(uri)
        if found is None:
            if not _IRI.fullmatch(uri):
                raise ExportError(f"'{uri}' is not an absolute IRI; it cannot name anything in RDF")
            found = self._iris[uri] = f"<{uri}>"
        return found

    def blank(self) -> str:
        self._blank += 1
        return f"{self._blank_label}{self._blank}"

    def value(self, value: Any) -> str:
        if isinstance(value, QualifiedName):
            return self.iri(value)
        if isinstance(value, ProvRecord):
            return self.iri(_identifier(value))
        key = (type(value), value)
        found = self._literals.get(key)
        if found is None:
            found = self._literals[key] = _literal(value)
        return found


def _literal(value: Any) -> str:
    if isinstance(value, bool):
        return f'"{"true" if value else "false"}"^^{_XSD_BOOLEAN}'
    if isinstance(value, int):
        if -(2**31) <= value < 2**31:
            return f'"{value}"^^{_XSD_INT}'
        if -(2**63) <= value < 2**63:
            return f'"{value}"^^{_XSD_LONG}'
        return f'"{value}"^^{_XSD_INTEGER}'
    if isinstance(value, float):
        if math.isnan(value):
            text = "NaN"
        elif math.isinf(value):
            text = "INF" if value > 0 else "-INF"
        else:
            text = repr(value)
        return f'"{text}"^^{_XSD_DOUBLE}'
    if isinstance(value, datetime.datetime):
        return f'"{value.isoformat()}"^^{_XSD_DATETIME}'
    if isinstance(value, ProvLiteral):
        if value.langtag:
            if not _LANGUAGE_TAG.fullmatch(value.langtag):
                raise ExportError(f"'{value.langtag}' is not a language tag")
            return f"{quoted(str(value.value))}@{value.langtag}"
        datatype = value.datatype
        if datatype is None:
            return quoted(str(value.value))
        if not _IRI.fullmatch(datatype.uri):
            raise ExportError(f"'{datatype.uri}' is not an absolute IRI; it cannot be a datatype")
        return f"{quoted(str(value.value))}^^<{datatype.uri}>"
    if isinstance(value, Identifier):
        return f"{quoted(value.uri)}^^{_XSD_ANY_URI}"
    return quoted(str(value))


def _identifier(record: ProvRecord) -> QualifiedName:
    if record.identifier is None:  # pragma: no cover - prov requires one for elements
        raise ExportError(f"a PROV {record.get_type()} has no identifier")
    return record.identifier


# -- the mapping -----------------------------------------------------------------


@dataclass(frozen=True)
class _RelationForm:
    """How one kind of relation is written in PROV-O."""

    binary: str
    qualified: str | None = None
    node_class: str | None = None
    object_property: str | None = None
    """The node's property for the relation's second argument."""
    others: tuple[str, ...] = ()
    """The node's properties for the third and later arguments, in order."""


def _form(binary: str, node: str, second: str, *others: str) -> _RelationForm:
    """A qualifiable relation: ``prov:<binary>``, ``prov:qualified<node>``, ``prov:<node>``."""
    return _RelationForm(_p(binary), _p("qualified" + node), _p(node), _p(second), tuple(map(_p, others)))


_RELATIONS: dict[QualifiedName, _RelationForm] = {
    PROV_GENERATION: _form("wasGeneratedBy", "Generation", "activity", "atTime"),
    PROV_USAGE: _form("used", "Usage", "entity", "atTime"),
    PROV_COMMUNICATION: _form("wasInformedBy", "Communication", "activity"),
    PROV_START: _form("wasStartedBy", "Start", "entity", "hadActivity", "atTime"),
    PROV_END: _form("wasEndedBy", "End", "entity", "hadActivity", "atTime"),
    PROV_INVALIDATION: _form("wasInvalidatedBy", "Invalidation", "activity", "atTime"),
    PROV_DERIVATION: _form(
        "wasDerivedFrom", "Derivation", "entity", "hadActivity", "hadGeneration", "hadUsage"
    ),
    PROV_ATTRIBUTION: _form("wasAttributedTo", "Attribution", "agent"),
    PROV_ASSOCIATION: _form("wasAssociatedWith", "Association", "agent", "hadPlan"),
    PROV_DELEGATION: _form("actedOnBehalfOf", "Delegation", "agent", "hadActivity"),
    PROV_INFLUENCE: _form("wasInfluencedBy", "Influence", "influencer"),
    PROV_SPECIALIZATION: _RelationForm(_p("specializationOf")),
    PROV_ALTERNATE: _RelationForm(_p("alternateOf")),
    PROV_MENTION: _RelationForm(_p("mentionOf"), others=(_p("asInBundle"),)),
    PROV_MEMBERSHIP: _RelationForm(_p("hadMember")),
}

_DERIVATION = _RELATIONS[PROV_DERIVATION]

_DERIVATION_KINDS: dict[str, tuple[str, str]] = {
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
    PROV_LABEL.uri: _RDFS_LABEL,
    PROV_LOCATION.uri: _p("atLocation"),
    PROV_ROLE.uri: _p("hadRole"),
    PROV_ATTR_STARTTIME.uri: _p("startedAtTime"),
    PROV_ATTR_ENDTIME.uri: _p("endedAtTime"),
}
_PROV_TYPE_LITERAL = _p("type")
_PROV_TYPE_URI = PROV_TYPE.uri

_Pairs = list[tuple[QualifiedName, Any]]


class _Mapper:
    """Appends the N-Quads lines of a document's records to :attr:`out`.

    Written for speed (the store ingests what it makes): records are told
    apart by their Python class, and attributes are read straight from the
    record's attribute map; prov's ``formal_attributes`` and
    ``extra_attributes`` rebuild their tuples on every call, which costs more
    than all the rest.  The values and their order are the same.
    """

    def __init__(self, blank_prefix: str = "q") -> None:
        self.out: list[str] = []
        self.terms = _Terms(blank_prefix)
        self._kinds: dict[type, str | _RelationForm] = {}

    def document(self, document: ProvDocument) -> None:
        self.bundle(document, " .\n")
        for bundle in document.bundles:
            identifier = bundle.identifier
            assert identifier is not None  # a document's bundles are named
            self.bundle(bundle, f" {self.terms.iri(identifier)} .\n")

    def bundle(self, bundle: ProvBundle, end: str) -> None:
        """The lines of one bundle's records; ``end`` closes each line (graph name, dot)."""
        kinds = self._kinds
        for record in bundle.get_records():
            kind = kinds.get(type(record))
            if kind is None:
                prov_type = record.get_type()
                kind = kinds[type(record)] = (
                    _ELEMENT_CLASSES[prov_type] if record.is_element() else _RELATIONS[prov_type]
                )
            if isinstance(kind, str):
                self.element(record, kind, end)
            else:
                self.relation(record, kind, end)

    def element(self, record: ProvRecord, element_class: str, end: str) -> None:
        subject = self.terms.iri(_identifier(record))
        self.out.append(f"{subject} {_RDF_TYPE} {element_class}{end}")
        formal, extra = _split_attributes(record)
        self.attributes(subject, zip(record.FORMAL_ATTRIBUTES, formal, strict=True), end)
        self.attributes(subject, extra, end)

    def attributes(self, subject: str, attributes: Iterable[tuple[QualifiedName, Any]], end: str) -> None:
        add, terms = self.out.append, self.terms
        for name, value in attributes:
            if value is None:
                continue
            if name._uri == _PROV_TYPE_URI:
                if isinstance(value, QualifiedName):
                    add(f"{subject} {_RDF_TYPE} {terms.iri(value)}{end}")
                else:
                    add(f"{subject} {_PROV_TYPE_LITERAL} {terms.value(value)}{end}")
                continue
            predicate = _ATTRIBUTE_PROPERTIES.get(name._uri) or terms.iri(name)
            add(f"{subject} {predicate} {terms.value(value)}{end}")

    def relation(self, record: ProvRecord, form: _RelationForm, end: str) -> None:
        add, terms = self.out.append, self.terms
        formal, extra = _split_attributes(record)
        first, second = formal[0], formal[1]
        if first is None:  # nothing to hang the relation on
            return
        subject = terms.iri(first)
        if form.qualified is None and not extra and len(formal) == 2:  # hadMember & co: one line
            if second is not None:
                add(f"{subject} {form.binary} {terms.value(second)}{end}")
            return
        qualified = form.qualified
        if form is _DERIVATION:
            for name, value in extra:
                if name._uri == _PROV_TYPE_URI and isinstance(value, QualifiedName):
                    kind = _DERIVATION_KINDS.get(value._uri)
                    if kind is not None and second is not None:
                        add(f"{subject} {kind[0]} {terms.iri(second)}{end}")
                        qualified = kind[1]
        if second is not None:
            add(f"{subject} {form.binary} {terms.value(second)}{end}")
        if qualified is None or form.node_class is None:
            for value in formal[2:]:  # mentionOf's bundle
                if value is not None and form.others:
                    add(f"{subject} {form.others[0]} {terms.value(value)}{end}")
            return
        has_more = bool(extra) or any(value is not None for value in formal[2:])
        if record.identifier is None and not has_more:
            return
        node = terms.iri(record.identifier) if record.identifier else terms.blank()
        add(f"{subject} {qualified} {node}{end}")
        add(f"{node} {_RDF_TYPE} {form.node_class}{end}")
        if second is not None and form.object_property is not None:
            add(f"{node} {form.object_property} {terms.value(second)}{end}")
        for predicate, value in zip(form.others, formal[2:], strict=False):
            if value is not None:
                add(f"{node} {predicate} {terms.value(value)}{end}")
        self.attributes(node, extra, end)


def _split_attributes(record: ProvRecord) -> tuple[list[Any], _Pairs]:
    """The formal attributes' values (None where missing) and the other (name, value) pairs,
    as prov's ``formal_attributes`` and ``extra_attributes`` give them."""
    values = record._attributes
    formal_names = record.FORMAL_ATTRIBUTES
    formal = []
    for name in formal_names:
        found = values.get(name)
        formal.append(next(iter(found), None) if found else None)
    formal_uris = _formal_uris(formal_names)
    extra = [(name, v) for name, found in values.items() if name._uri not in formal_uris for v in found]
    return formal, extra


@functools.cache
def _formal_uris(names: tuple[QualifiedName, ...]) -> frozenset[str]:
    return frozenset(name.uri for name in names)
