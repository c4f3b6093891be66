"""Binding query parameters as RDF terms.

Parameters become ``VALUES`` blocks at the top of the query's first group
(``WHERE {``), written with the RDF library's own term syntax, so a value is
always one term whatever characters it holds (quotes, braces, ``#``); no
user text is pasted into a query.  Both stores use this one mechanism.
"""

from __future__ import annotations

import re
from collections.abc import Sequence

from pyoxigraph import BlankNode, Literal, NamedNode

from exsce_dsl.store.base import Bindings, StoreError, Term

_VARIABLE = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_WHERE = re.compile(r"\bWHERE\s*\{", re.IGNORECASE)


def term_text(term: Term) -> str:
    """A term in SPARQL/N-Triples syntax (escaping done by pyoxigraph)."""
    if isinstance(term, BlankNode):
        raise StoreError("blank nodes cannot be query parameters")
    if not isinstance(term, (NamedNode, Literal)):
        raise StoreError(f"not an RDF term: {term!r}")
    return str(term)


def values_block(bindings: Bindings) -> str:
    blocks = []
    for name, value in sorted(bindings.items()):
        if not _VARIABLE.fullmatch(name):
            raise StoreError(f"not a SPARQL variable name: {name!r}")
        terms: Sequence[Term] = value if isinstance(value, (list, tuple)) else (value,)
        blocks.append(f"VALUES ?{name} {{ {' '.join(term_text(t) for t in terms)} }}")
    return " ".join(blocks)


def bind(query: str, bindings: Bindings | None) -> str:
    """The query with ``bindings`` as VALUES blocks opening its first ``WHERE {`` group."""
    if not bindings:
        return query
    match = _WHERE.search(query)
    if match is None:
        raise StoreError("a query with parameters needs a WHERE { ... } clause")
    return f"{query[: match.end()]} {values_block(bindings)}\n{query[match.end():]}"
