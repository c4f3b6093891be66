"""SPARQL text: query parameters bound as RDF terms, and the update that writes graphs.

Parameters become ``VALUES`` blocks at the top of the query's WHERE group,
written with the RDF library's own term syntax, so a value is
always one term whatever characters it holds (quotes, braces, ``#``); no
user text is pasted into a query.  Both stores use this one mechanism.
"""

from __future__ import annotations

import re
import uuid
from collections.abc import Iterable, Iterator, Mapping, Sequence

from pyoxigraph import BlankNode, Literal, NamedNode, Quad

from exsce_dsl.errors import StoreError
from exsce_dsl.store.base import Bindings, GraphSet, Replace, Term, replaced_names

_VARIABLE = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


def term_text(term: Term) -> str:
    """A term in SPARQL/N-Triples syntax (escaping done by pyoxigraph)."""
    if isinstance(term, BlankNode):
        raise StoreError("blank nodes cannot be query parameters")
    if not isinstance(term, (NamedNode, Literal)):
        raise StoreError(f"not an RDF term: {term!r}")
    return str(term)


def values_block(bindings: Bindings) -> str:
    """The bindings as VALUES: the one-term parameters together as one row, each list apart.

    One row for all single values, rather than a block per variable: Oxigraph
    plans a chain of one-row VALUES blocks as joins it cannot use its indexes
    for (the segment query of ``bench/store.py`` took 12x longer that way).
    """
    single: list[tuple[str, Term]] = []
    blocks = []
    for name, value in sorted(bindings.items()):
        if not _VARIABLE.fullmatch(name):
            raise StoreError(f"not a SPARQL variable name: {name!r}")
        if isinstance(value, (NamedNode, BlankNode, Literal)):
            single.append((name, value))
        else:
            terms: Sequence[Term] = value
            blocks.append(f"VALUES ?{name} {{ {' '.join(term_text(t) for t in terms)} }}")
    if single:
        names = " ".join(f"?{name}" for name, _ in single)
        row = " ".join(term_text(t) for _, t in single)
        blocks.insert(0, f"VALUES ({names}) {{ ({row}) }}")
    return " ".join(blocks)


def bind(query: str, bindings: Bindings | None) -> str:
    """The query with ``bindings`` as VALUES blocks opening its WHERE group.

    The group is found by reading the query's tokens (comments, strings and
    IRIs skipped): the ``{`` after a top-level ``WHERE``, else the first
    top-level group (``ASK { ... }``, ``SELECT * { ... }``), or the second one
    for ``CONSTRUCT { template } { pattern }``.

    A query may say where a parameter's values go instead, with ``VALUES ?name { UNDEF }``
    (valid SPARQL on its own: the variable left free) in the group that should start from
    them, a subquery for instance: Oxigraph evaluates a subquery first and joins the rest
    to its few solutions, where it would otherwise join a list given at the top last.  Each
    such placeholder gets the values (a query whose branches of a ``UNION`` each start from them).
    """
    if not bindings:
        return query
    placed = _placeholders(query)
    spans = sorted(
        ((span, name) for name, found in placed.items() if name in bindings for span in found), reverse=True
    )
    for (start, end), name in spans:
        query = f"{query[:start]}{values_block({name: bindings[name]})}{query[end:]}"
    rest = {name: value for name, value in bindings.items() if name not in placed}
    if not rest:
        return query
    at = where_group(query)
    if at is None:
        raise StoreError("a query with parameters needs a WHERE { ... } group to bind them in")
    return f"{query[: at + 1]} {values_block(rest)}\n{query[at + 1 :]}"


def _placeholders(query: str) -> dict[str, list[tuple[int, int]]]:
    """Where the query holds ``VALUES ?name { UNDEF }``: variable name -> each (start, end)."""
    tokens = [t for t in _TOKEN.finditer(query) if not (t.lastgroup == "other" and t.group().isspace())]
    found: dict[str, list[tuple[int, int]]] = {}
    for i in range(len(tokens) - 4):
        values, variable, opening, undef, closing = tokens[i : i + 5]
        if (
            values.lastgroup == "word" and values.group().upper() == "VALUES"
            and variable.lastgroup == "word" and variable.group()[0] in "?$"
            and opening.lastgroup == "open" and undef.group().upper() == "UNDEF"
            and closing.lastgroup == "close"
        ):  # fmt: skip
            found.setdefault(variable.group()[1:], []).append((values.start(), closing.end()))
    return found


_TOKEN = re.compile(
    r"""
      (?P<comment>\#[^\n]*)
    | (?P<string>'''(?:[^'\\]|\\.|'(?!''))*'''|"""
    + r'''"""(?:[^"\\]|\\.|"(?!""))*"""'''
    + r"""|'(?:[^'\\\n\r]|\\.)*'|"(?:[^"\\\n\r]|\\.)*")
    | (?P<iri><[^<>"{}|^`\\\x00-\x20]*>)
    | (?P<word>[?$]?[A-Za-z_][\w\-.]*(?::[\w\-.%\\]*)?|:[\w\-.%\\]*)
    | (?P<open>\{)
    | (?P<close>\})
    | (?P<other>.)
    """,
    re.VERBOSE | re.DOTALL,
)
_FORMS = frozenset({"SELECT", "ASK", "CONSTRUCT", "DESCRIBE", "INSERT", "DELETE", "WITH", "LOAD", "CLEAR"})


_PROLOGUE = frozenset({"PREFIX", "BASE"})


def query_keywords(text: str) -> list[str]:
    """The bare words of a query, upper-cased, in order: outside comments, strings and IRIs, with
    variables and prefixed names left out."""
    found = []
    for token in _TOKEN.finditer(text):
        word = token.group("word")
        if word is not None and ":" not in word and word[0] not in "?$":
            found.append(word.upper())
    return found


def query_form(text: str) -> str:
    """The query's form: its first keyword after the prologue (SELECT, ASK, CONSTRUCT, DESCRIBE,
    or an update's INSERT, DELETE, LOAD, DROP...); empty if it has none."""
    return next((w for w in query_keywords(text) if w not in _PROLOGUE), "")


def declared_prefixes(text: str) -> set[str]:
    """The prefixes a query declares (``PREFIX p: <...>``; the empty prefix as ``""``), comments
    and strings not counted."""
    tokens = [t for t in _TOKEN.finditer(text) if not (t.lastgroup == "other" and t.group().isspace())]
    return {
        name.group().split(":", 1)[0]
        for keyword, name in zip(tokens, tokens[1:], strict=False)
        if keyword.lastgroup == "word" and keyword.group().upper() == "PREFIX"
        and name.lastgroup == "word" and ":" in name.group()
    }  # fmt: skip


def where_group(query: str) -> int | None:
    """The index of the ``{`` that opens the query's WHERE group, or None."""
    depth = 0
    form = None
    after_where = False
    top_groups: list[int] = []
    for token in _TOKEN.finditer(query):
        kind = token.lastgroup
        if kind == "word" and depth == 0:
            word = token.group().upper()
            if form is None and word in _FORMS:
                form = word
            elif word == "WHERE":
                after_where = True
        elif kind == "open":
            if depth == 0:
                if after_where:
                    return token.start()
                top_groups.append(token.start())
            depth += 1
        elif kind == "close":
            depth = max(depth - 1, 0)
    if form in ("SELECT", "ASK", "DESCRIBE") and top_groups:
        return top_groups[0]
    if form == "CONSTRUCT" and len(top_groups) >= 2:
        return top_groups[1]
    return None


def graph_node(name: str) -> NamedNode:
    """The IRI of a named graph, or a StoreError saying why it is not one."""
    try:
        return NamedNode(name)
    except (ValueError, TypeError) as exc:
        raise StoreError(f"not a graph name (an absolute IRI): {name!r}: {exc}") from None


def checked_quads(quads: Iterable[object], name: str) -> list[Quad]:
    """``quads`` as a list, each checked to be a pyoxigraph Quad."""
    try:
        found = list(quads)
    except StoreError:
        raise
    except Exception as exc:
        raise StoreError(f"cannot read the quads of graph <{name}>: {type(exc).__name__}: {exc}") from exc
    checked = []
    for quad in found:
        if not isinstance(quad, Quad):
            raise StoreError(f"graph <{name}> holds something that is not a quad: {quad!r}")
        checked.append(quad)
    return checked


class Skolemiser:
    """Terms in N-Triples syntax, each blank node label of one write made one fresh IRI starting
    with ``skolem`` (RDF 1.1 Concepts, 3.5 "Replacing Blank Nodes with IRIs"), the same in every
    graph and every request of the write; with ``skolem`` None, blank nodes are left as they are."""

    def __init__(self, skolem: str | None) -> None:
        self.skolem = skolem
        self.minted: dict[str, str] = {}  # blank node label -> its Skolem IRI, in N-Triples syntax

    def __call__(self, term: object) -> str:
        if self.skolem is not None and isinstance(term, BlankNode):
            return self.minted.setdefault(term.value, f"<{self.skolem}{uuid.uuid4().hex}>")
        return str(term)


def write_update(graphs: GraphSet, replace: Replace, *, skolem: str | None = None) -> str:
    """One SPARQL Update that writes ``graphs``: ``DROP SILENT GRAPH`` for each replaced
    graph, then one ``INSERT DATA`` with a ``GRAPH`` block per graph.

    One request, so one transaction wherever the endpoint makes a request atomic.  Terms are
    written in N-Triples syntax by pyoxigraph.  With ``skolem`` (for Virtuoso, which refuses
    blank nodes in ``INSERT DATA``), blank nodes are written as Skolem IRIs (:class:`Skolemiser`),
    so the write stays one ``INSERT DATA``.
    """
    parts = [f"DROP SILENT GRAPH {graph_node(name)}" for name in replaced_names(graphs, replace)]
    inserted = insert_data({name: checked_quads(quads, name) for name, quads in graphs.graphs.items()},
                           Skolemiser(skolem))  # fmt: skip
    if inserted:
        parts.append(inserted.removesuffix("\n"))
    return "".join(f"{part} ;\n" for part in parts[:-1]) + (f"{parts[-1]}\n" if parts else "")


def insert_data(graphs: Mapping[str, Sequence[Quad]], skolemise: Skolemiser) -> str:
    """One ``INSERT DATA`` with a ``GRAPH`` block per graph that holds quads ('' if none does)."""
    blocks = [
        f"GRAPH {graph_node(name)} {{\n{''.join(triple_lines(quads, skolemise))}}}\n"
        for name, quads in graphs.items()
        if quads
    ]
    return f"INSERT DATA {{\n{''.join(blocks)}}}\n" if blocks else ""


def triple_lines(quads: Iterable[Quad], skolemise: Skolemiser) -> Iterator[str]:
    """Each quad's triple as a line of N-Triples (blank nodes as ``skolemise`` writes them)."""
    for q in quads:
        yield f"{skolemise(q.subject)} {q.predicate} {skolemise(q.object)} .\n"
