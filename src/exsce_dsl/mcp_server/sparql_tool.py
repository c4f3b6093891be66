"""The ``sparql`` tool: any SELECT or ASK query, read-only, with the endpoint's limits.

What ``exscec serve`` does for a query, this tool does too: a query is at most
:data:`~exsce_dsl.store.base.MAX_QUERY` long and runs within the time limit
(:data:`~exsce_dsl.store.base.QUERY_TIMEOUT` by default), and it never
updates.  The query's form is read by rdflib's SPARQL 1.1 parser; a text that
parser does not take (Oxigraph reads a little more SPARQL) has its form read
from its tokens (comments, strings and IRIs skipped).  Anything but SELECT and
ASK is refused before the store is touched, and a wrong guess costs nothing:
what is sent goes to the store's query operation, whose parser takes no
update (Oxigraph's for the embedded store, the endpoint's for a remote one),
and an answer of another form than the one read is refused.  Further than the
endpoint, ``SERVICE`` is refused, found by the same parser
(:func:`~exsce_dsl.store.federation.refuse_federation`; a text it cannot parse
is refused if it holds the word at all): a model's query reads this store, and
makes no requests to other servers.

An answer holds at most the server's ``--max-rows`` rows; the store is asked
for one more (to say the answer is cut), never for every solution.

The library's prefixes (``exsce:``, ``run:``, ``pose:``, ``prov:``, ``xsd:``...)
are declared for the query unless it declares them itself, as ``exscec sparql``
does.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import mcp_types as types

from exsce_dsl.errors import ArgumentError, ExsceError, FederationRefused
from exsce_dsl.mcp_server.access import Access
from exsce_dsl.mcp_server.answers import READ_ONLY, ToolEntry, first_rows_json
from exsce_dsl.mcp_server.arguments import object_schema
from exsce_dsl.store import MAX_QUERY, declared_prefixes, query_form, refuse_federation, standard_prefixes

__all__ = ["read_only_query", "sparql_tool"]

_READING = frozenset({"SELECT", "ASK"})


def read_only_query(text: str) -> tuple[str, str]:
    """The form (SELECT or ASK) of a query that may run here, and its text with the library's
    prefixes it does not declare; an ExsceError saying why otherwise."""
    if len(text.encode("utf-8")) > MAX_QUERY:
        raise ArgumentError(f"a query is at most {MAX_QUERY // 1024} KiB")
    declared = declared_prefixes(text)
    prologue = "".join(
        f"PREFIX {p}: <{iri}>\n" for p, iri in standard_prefixes().items() if p not in declared
    )
    form = _form(prologue + text)
    if form not in _READING:
        what = f"this is {form}" if form else "this is no query"
        raise ExsceError(f"the sparql tool runs SELECT and ASK queries only, never updates: {what}")
    try:
        refuse_federation(prologue + text)
    except FederationRefused as exc:
        raise ExsceError(
            f"{exc.message} (the sparql tool reads this store only, never another server)"
        ) from None
    return form, prologue + text


_FORMS = {
    "SelectQuery": "SELECT",
    "AskQuery": "ASK",
    "ConstructQuery": "CONSTRUCT",
    "DescribeQuery": "DESCRIBE",
}


def _form(text: str) -> str:
    """The query's form as rdflib's parser reads it; as its first keyword says when that parser
    does not take the text (an update, or SPARQL only Oxigraph reads)."""
    from rdflib.plugins.sparql.parser import parseQuery

    try:
        tree = parseQuery(text)
    except Exception:  # pyparsing's ParseException, and rdflib's own on bad IRIs or prefixes
        return query_form(text)
    return _FORMS.get(getattr(tree[-1], "name", ""), "")


def _answer(access: Access, arguments: Mapping[str, Any]) -> dict[str, Any]:
    form, text = read_only_query(str(arguments["query"]))
    with access.store() as store:
        if form == "ASK":
            return {"head": {}, "boolean": store.ask(text)}
        return first_rows_json(store, text, access.max_rows)


def sparql_tool() -> ToolEntry:
    prefixes = ", ".join(f"{p}:" for p in standard_prefixes())
    tool = types.Tool(
        name="sparql",
        title="SPARQL query (read-only)",
        description=(
            "Run a SPARQL 1.1 SELECT or ASK query on the provenance store (updates and SERVICE are "
            "refused).  Every PROV bundle is a named graph: match with GRAPH ?g { ... }.  These prefixes "
            f"are declared unless the query declares them: {prefixes}.  Answers SPARQL 1.1 Query "
            "Results JSON; long answers are cut (see 'truncated': rows shown, and more: true)."
        ),
        input_schema=object_schema(
            {
                "query": {
                    "type": "string",
                    "maxLength": MAX_QUERY,
                    "description": "the query, e.g. SELECT ?run WHERE { GRAPH ?g { ?a a exsce:run ; "
                    "exsce:run ?run } }",
                }
            },
            ("query",),
        ),
        annotations=READ_ONLY,
    )
    return ToolEntry(tool, _answer)
