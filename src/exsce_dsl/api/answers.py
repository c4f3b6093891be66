"""Answers of the store for people and programs: the query library's and any SPARQL SELECT or
ASK (``exscec query``, ``sparql``, ``runs``), and their text as aligned columns, SPARQL 1.1
results JSON or CSV."""

from __future__ import annotations

import csv
import io
import json
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from pyoxigraph import BlankNode, Literal, NamedNode

from exsce_dsl.errors import ExsceError
from exsce_dsl.remedies import SELECT_OR_ASK
from exsce_dsl.store import Rows, Term, literal_text
from exsce_dsl.tables import aligned

if TYPE_CHECKING:
    from exsce_dsl.store import Query

ANSWER_FORMATS = ("table", "json", "csv")
_PREFIX_DECLARATION = re.compile(r"^\s*PREFIX\s+([A-Za-z][\w.-]*)?:", re.IGNORECASE | re.MULTILINE)
_KIND_AFTER_PROLOGUE = re.compile(
    r"^(?:\s|#[^\n]*\n|PREFIX\s+[^\s:]*:\s*<[^>]*>|BASE\s*<[^>]*>)*\s*(SELECT|ASK|CONSTRUCT|DESCRIBE)\b",
    re.IGNORECASE,
)


def results_json(rows: Rows) -> str:
    """SPARQL 1.1 Query Results JSON."""
    from exsce_dsl.store import results_json as answer

    return json.dumps(answer(rows), indent=2) + "\n"


def results_csv(rows: Rows) -> str:
    """SPARQL 1.1 Query Results CSV: lexical forms (each literal in its one form), CRLF line ends."""
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\r\n")
    writer.writerow(rows.variables)
    for row in rows.rows:
        writer.writerow([_csv_text(t) for t in row])
    return out.getvalue()


def _csv_text(t: Term | None) -> str:
    if t is None:
        return ""
    if isinstance(t, Literal):
        return literal_text(t)
    return f"_:{t.value}" if isinstance(t, BlankNode) else t.value


def results_table(rows: Rows, prefixes: Mapping[str, str]) -> str:
    """Aligned columns, IRIs shortened with the library's prefixes, literals as their text (in
    their one form, doubles to 15 significant digits: :mod:`exsce_dsl.store.literals`)."""
    namespaces = sorted(((iri, p) for p, iri in prefixes.items()), key=lambda item: -len(item[0]))

    def show(t: Term | None) -> str:
        if t is None:
            return ""
        if isinstance(t, NamedNode):
            for iri, prefix in namespaces:
                if t.value.startswith(iri) and len(t.value) > len(iri):
                    return f"{prefix}:{t.value[len(iri) :]}"
            return f"<{t.value}>"
        if isinstance(t, BlankNode):
            return f"_:{t.value}"
        return literal_text(t)

    cells = [list(rows.variables)] + [[show(t) for t in row] for row in rows.rows]
    if not rows.variables:
        return ""
    widths = [max(len(line[i]) for line in cells) for i in range(len(rows.variables))]
    lines = aligned(cells)
    lines.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(lines) + "\n"


def answer_text(rows: Rows, format: str = "table") -> str:
    """A SELECT's answer in one of :data:`ANSWER_FORMATS`."""
    from exsce_dsl.store import standard_prefixes

    if format == "json":
        return results_json(rows)
    if format == "csv":
        return results_csv(rows)
    return results_table(rows, standard_prefixes())


def library_queries() -> list[Query]:
    """The queries of the library, by name, each with what it answers and its parameters."""
    from exsce_dsl.store import query, query_names

    return [query(name) for name in query_names()]


@dataclass(frozen=True)
class QueryAnswer:
    """A library query's answer (None for an update, which answers nothing), and a warning for
    each name given that the store does not hold (with its closest names)."""

    rows: Rows | None
    warnings: tuple[str, ...] = ()


def answer_query(store_url: str | None, name: str, parameters: Mapping[str, Sequence[str]]) -> QueryAnswer:
    """``exscec query NAME -p k=v``: the library's query ``name``, its parameters bound as RDF
    terms (checked before the store is opened; a run by a unique prefix of its uuid, or its IRI)."""
    from exsce_dsl.api.store import open_store
    from exsce_dsl.store import query, run_query, unknown_names

    library_query = query(name)
    library_query.bindings(parameters)  # check the parameters before opening the store
    with open_store(store_url, read_only=not library_query.is_update) as store:
        rows = run_query(store, name, parameters, check_runs=True)
        if library_query.is_update:
            return QueryAnswer(None)
        return QueryAnswer(rows, tuple(unknown_names(store, name, parameters)))


def stored_runs(store_url: str | None, scenario: str | None = None) -> QueryAnswer:
    """``exscec runs``: the runs of ``scenario`` (of every scenario when None), oldest first; a
    scenario the store does not hold is a warning."""
    from exsce_dsl.api.store import open_store
    from exsce_dsl.store import run_query, unknown_names

    given = {} if scenario is None else {"scenario": scenario}
    with open_store(store_url, read_only=True) as store:
        rows = run_query(store, "runs", given)
        unknown = unknown_names(store, "runs", given) if not rows else []
    return QueryAnswer(rows, tuple(unknown))


def answer_sparql(store_url: str | None, text: str) -> Rows | bool:
    """``exscec sparql``: a SELECT's rows or an ASK's answer; the library's prefixes are declared
    unless the query declares them itself.  Other kinds of query are an ExsceError."""
    from exsce_dsl.api.store import open_store
    from exsce_dsl.store import standard_prefixes

    declared = {m.group(1) or "" for m in _PREFIX_DECLARATION.finditer(text)}
    prologue = "".join(
        f"PREFIX {p}: <{iri}>\n" for p, iri in standard_prefixes().items() if p not in declared
    )
    kind = _KIND_AFTER_PROLOGUE.match(text)
    verb = kind.group(1).upper() if kind else ""
    if verb not in ("SELECT", "ASK"):
        raise ExsceError("the query is neither a SELECT nor an ASK query", remedy=SELECT_OR_ASK)
    with open_store(store_url, read_only=True) as store:
        if verb == "ASK":
            return store.ask(prologue + text)
        return store.select(prologue + text)
