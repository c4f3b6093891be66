"""Answers to SELECT queries as SPARQL 1.1 Query Results JSON, as every reader of the store gets
them: ``exscec query`` and ``exscec sparql`` with ``--format json``, and the MCP server's tools.
Literals are in their one form, doubles to 15 significant digits (:mod:`exsce_dsl.store.literals`),
so every store gives the same text."""

from __future__ import annotations

from typing import Any

from pyoxigraph import BlankNode, NamedNode

from exsce_dsl.prov.identifiers import XSD_STRING
from exsce_dsl.store.base import Rows, Term
from exsce_dsl.store.literals import canonical_literal, literal_text

_XSD_STRING = XSD_STRING


def term_json(term: Term) -> dict[str, str]:
    """One RDF term as SPARQL 1.1 Query Results JSON writes it."""
    if isinstance(term, NamedNode):
        return {"type": "uri", "value": term.value}
    if isinstance(term, BlankNode):
        return {"type": "bnode", "value": term.value}
    term = canonical_literal(term)
    found = {"type": "literal", "value": literal_text(term)}
    if term.language:
        found["xml:lang"] = term.language
    elif term.datatype.value != _XSD_STRING:
        found["datatype"] = term.datatype.value
    return found


def results_json(rows: Rows, max_rows: int | None = None) -> dict[str, Any]:
    """``rows`` as SPARQL 1.1 Query Results JSON; with ``max_rows``, the first that many, and a
    ``truncated`` member (rows shown, rows found) when there were more."""
    shown = rows.rows if max_rows is None else rows.rows[:max_rows]
    bindings = [
        {name: term_json(t) for name, t in zip(rows.variables, row, strict=True) if t is not None}
        for row in shown
    ]
    answer: dict[str, Any] = {"head": {"vars": list(rows.variables)}, "results": {"bindings": bindings}}
    if len(rows) > len(shown):
        answer["truncated"] = {"shown": len(shown), "rows": len(rows)}
    return answer
