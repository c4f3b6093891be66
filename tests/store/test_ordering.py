"""The library's rows sorted in Python (exsce_dsl.store.queries.ordering) come out in the order
Oxigraph's own ORDER BY gives (the independent path), ties aside."""

from __future__ import annotations

from pyoxigraph import Literal, NamedNode

from exsce_dsl.store.base import Rows
from exsce_dsl.store.embedded import EmbeddedStore
from exsce_dsl.store.queries import library
from exsce_dsl.store.queries.ordering import sorted_rows, without_order

XSD = "http://www.w3.org/2001/XMLSchema#"

VALUES = """
  (1 "b") (2 "a") (3 "a"@en) (4 "10"^^<http://www.w3.org/2001/XMLSchema#integer>)
  (5 "9.5"^^<http://www.w3.org/2001/XMLSchema#double>) (6 "-3"^^<http://www.w3.org/2001/XMLSchema#decimal>)
  (7 "2026-01-02T00:00:00Z"^^<http://www.w3.org/2001/XMLSchema#dateTime>)
  (8 "2026-01-01T23:00:00-02:00"^^<http://www.w3.org/2001/XMLSchema#dateTime>)
  (9 <https://example.org/b>) (10 <https://example.org/a>) (11 UNDEF) (12 "true"^^<http://www.w3.org/2001/XMLSchema#boolean>)
  (13 "ab") (14 "B") (15 "1e3"^^<http://www.w3.org/2001/XMLSchema#double>)
"""


def test_rows_sort_as_oxigraph_sorts_them() -> None:
    store = EmbeddedStore(None)
    text = f"SELECT ?n ?x WHERE {{ VALUES (?n ?x) {{ {VALUES} }} }}"
    theirs = store.select(text + " ORDER BY ?x ?n")
    ours = sorted_rows(store.select(text), ["x", "n"])

    # kinds Oxigraph cannot compare with each other (a number and a date) may come in any order
    # among themselves: compare each kind's order, and the kinds' order
    def kind(term: object) -> str:
        if term is None:
            return "unbound"
        if isinstance(term, NamedNode):
            return "iri"
        assert isinstance(term, Literal)
        name = term.datatype.value.removeprefix(XSD)
        return "number" if name in ("integer", "double", "decimal") else name

    for wanted in ("unbound", "iri", "string", "langString", "number", "dateTime", "boolean"):
        order = [row[0] for row in theirs.rows if kind(row[1]) == wanted]
        assert [row[0] for row in ours.rows if kind(row[1]) == wanted] == order, wanted
    assert [kind(row[1]) for row in ours.rows][:3] == ["unbound", "iri", "iri"]
    numbers = [float(row[1].value) for row in ours.rows if kind(row[1]) == "number"]  # type: ignore[union-attr]
    assert numbers == sorted(numbers) == [-3.0, 9.5, 10.0, 1000.0]


def test_ties_are_broken_by_the_other_columns() -> None:
    rows = Rows(
        ("a", "b"), ((Literal("x"), Literal("2")), (Literal("x"), Literal("1")), (None, Literal("3")))
    )
    assert [r[1].value for r in sorted_rows(rows, ["a"]).rows] == ["3", "1", "2"]  # type: ignore[union-attr]


def test_the_library_s_plain_orders_are_sorted_here_and_expressions_left_to_the_store() -> None:
    ordered = {name: without_order(library.query(name).text) for name in library.query_names()}
    assert ordered["violation_durations"] is not None and ordered["violation_durations"][1] == (
        "run",
        "robot",
    )
    assert ordered["runs"] is not None and "ORDER BY" not in ordered["runs"][0]
    assert ordered["verdicts"] is None  # ORDER BY (IF(...)) ...: the store orders it
    assert without_order("SELECT ?a WHERE { ?a ?b ?c }\nORDER BY ?b") is None  # ?b not projected
    assert without_order("SELECT ?a WHERE { ?a ?b ?c }\nORDER BY ?a") == (
        "SELECT ?a WHERE { ?a ?b ?c }\n",
        ("a",),
    )
