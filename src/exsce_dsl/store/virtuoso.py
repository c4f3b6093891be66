"""Reading Virtuoso's answers without losing digits.

Virtuoso 7.2 writes ``xsd:double`` values with six significant digits in every SPARQL results
format (JSON, XML, CSV, TSV) and in N-Triples and RDF/XML (``12.3456789012345`` comes back as
``12.3457``; openlink/virtuoso-opensource#1006), and with 16 in RDF/JSON.  Only its Turtle is
exact: a double is written with 20 digits (``0.30000000000000004441``), as a Turtle number.  So
exsce asks Virtuoso for SELECT answers as a Turtle result set (the DAWG ``res:`` vocabulary)
and for graphs as Turtle, and reads them here.

In Turtle a number with a decimal point is an ``xsd:decimal``, so Virtuoso's doubles and
decimals look alike.  exsce writes every number as an ``xsd:double`` or an integer, so a decimal
read here is taken for a double (its nearest one, in canonical form); an exponent is a double
in Turtle already.  A user's own ``xsd:decimal`` data therefore reads back as doubles from
Virtuoso (the value, to a double's precision, not the type): ``docs/stores.md`` says so.
Virtuoso keeps an ``xsd:integer`` as an ``xsd:int``: read back as the ``xsd:integer`` written.
"""

from __future__ import annotations

from pyoxigraph import BlankNode, Literal, NamedNode, RdfFormat, Triple, parse

from exsce_dsl.errors import StoreError
from exsce_dsl.prov.identifiers import LDP_NAMESPACE, SPARQL_RESULTS_NAMESPACE, XSD_NAMESPACE
from exsce_dsl.store.base import Rows, Term

OWN_GRAPHS = (
    "http://www.openlinksw.com/schemas/virtrdf#",
    LDP_NAMESPACE,
    "http://localuriqaserver/",
    "http://www.openlinksw.com/",
)
"""Graphs a new Virtuoso database holds for itself (its RDF views, LDP): not exsce's, so not
listed, exported or cleared (dropping ``virtrdf#`` breaks the server)."""
OWN_GRAPH_NAMES = (r"https?://[^/]+/DAV/", r"https?://[^/]+/sparql")
"""Graphs named after the host of ``[URIQA] DefaultHost`` (Debian's ``virtuoso.ini``:
``localhost:8890``): ``http://HOST/DAV/`` (its WebDAV folder's metadata) and ``http://HOST/sparql``
(the endpoint's SPARQL 1.1 Service Description)."""

TURTLE = "text/turtle"

INSERT_DATA_TRIPLES = 1000
"""The most triples exsce puts in one ``INSERT DATA`` for Virtuoso.  Virtuoso 7.2.5 compiles an
``INSERT DATA`` to SQL and refuses one of more SQL than it allows (``SP031 ... The length of
generated SQL text has exceeded 10000 lines of code``): measured with Debian's default
configuration, 1,421 triples go and 1,429 do not, whatever the terms (IRIs, plain, typed or
language-tagged literals).  Two operations of 1,000 in one request are compiled together (3.6 s),
ten are refused (``SQ199 Maximum size (32767) of a code vector exceeded``): one per request."""
GRAPH_POST_BYTES = 8 * 1024 * 1024
"""The most bytes of N-Triples exsce posts to Virtuoso's Graph Store Protocol in one request.
Virtuoso took a 43 MB post of 500,000 triples in 12 s (its limit, if any, was not reached); the
parts keep each request short.  10^5 triples go in ~2 s this way, ~27 s as INSERT DATA."""
MAX_ROWS_HEADER = "X-SPARQL-MaxRows"
ADVICE = (
    (
        "The estimated execution time",
        "Virtuoso's cost estimate refused the query before running it, a known fault of its "
        'MaxQueryCostEstimationTime (openlink/virtuoso-opensource#246: "0 (sec) exceeds the limit"); '
        "OpenLink's advice is to comment that setting out of the [SPARQL] section of virtuoso.ini "
        "(Debian's sets it to 400) and restart the server",
    ),
)
"""Refusals of Virtuoso that say nothing of what to do, and what to do (see :class:`StoreFlavour`)."""
"""The header Virtuoso sends with a SPARQL JSON answer cut at ``[SPARQL] ResultSetMaxRows``
(Debian's default: 10,000).  Its Turtle result sets, which exsce reads, are not cut (measured:
100,000 rows); its ``CONSTRUCT`` answers and Graph Store ``GET`` are, without the header: so
exsce reads a Virtuoso graph with a SELECT."""

_RES = SPARQL_RESULTS_NAMESPACE
_XSD = XSD_NAMESPACE
_DECIMAL, _DOUBLE = NamedNode(_XSD + "decimal"), NamedNode(_XSD + "double")
_INT, _INTEGER = NamedNode(_XSD + "int"), NamedNode(_XSD + "integer")


def result_set_rows(body: bytes, source: str) -> Rows:
    """The solutions of a SELECT answered as a Turtle result set, in the order written."""
    triples = _parsed(body, source)
    variables = [_text(t.object) for t in triples if t.predicate.value == _RES + "resultVariable"]
    order: dict[str, int] = {}  # solution node -> its position (res:index, else first mention)
    indexes: dict[str, int] = {}
    bindings_of: dict[str, list[str]] = {}
    variable_of: dict[str, str] = {}
    value_of: dict[str, Term] = {}
    for t in triples:
        predicate = t.predicate.value
        if predicate == _RES + "solution":
            order.setdefault(_key(t.object), len(order))
        elif predicate == _RES + "binding":
            order.setdefault(_key(t.subject), len(order))
            bindings_of.setdefault(_key(t.subject), []).append(_key(t.object))
        elif predicate == _RES + "variable":
            variable_of[_key(t.subject)] = _text(t.object)
        elif predicate == _RES + "value":
            value_of[_key(t.subject)] = _retyped(t.object)
        elif predicate == _RES + "index" and isinstance(t.object, Literal):
            indexes[_key(t.subject)] = int(t.object.value)
    solutions = sorted(order, key=lambda s: (indexes.get(s, 0), order[s]))
    rows = []
    for solution in solutions:
        values = {
            variable_of[b]: value_of[b]
            for b in bindings_of.get(solution, ())
            if b in variable_of and b in value_of
        }
        rows.append(tuple(values.get(v) for v in variables))
    return Rows(tuple(variables), tuple(rows))


def _parsed(body: bytes, source: str) -> list[Triple]:
    try:
        return list(parse(body, format=RdfFormat.TURTLE))
    except (SyntaxError, ValueError) as exc:
        raise StoreError(f"{source} answered with Turtle that cannot be read: {exc}") from None


def _retyped(term: Term | Triple) -> Term:
    if isinstance(term, Triple):
        raise StoreError("Virtuoso answered with an RDF-star triple term, which exsce does not read")
    if isinstance(term, Literal) and term.datatype == _DECIMAL:
        return Literal(repr(float(term.value)), datatype=_DOUBLE)
    if isinstance(term, Literal) and term.datatype == _INT:  # how Virtuoso keeps an xsd:integer
        return Literal(term.value, datatype=_INTEGER)
    return term


def _text(term: Term | Triple) -> str:
    if isinstance(term, Triple):
        raise StoreError("Virtuoso answered with an RDF-star triple term, which exsce does not read")
    return term.value


def _key(term: Term | Triple) -> str:
    return f"_:{term.value}" if isinstance(term, BlankNode) else str(term)
