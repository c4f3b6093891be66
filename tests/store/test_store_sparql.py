"""SPARQL text: where parameters go, and the one update that writes graphs."""

from __future__ import annotations

import pytest
from pyoxigraph import BlankNode, Literal, NamedNode, Quad, Store

from exsce_dsl.errors import StoreError
from exsce_dsl.prov.identifiers import DEFAULT_NAMESPACE, Namespaces
from exsce_dsl.store.base import GraphSet
from exsce_dsl.store.queries import library
from exsce_dsl.store.sparql import bind, where_group, write_update


@pytest.mark.parametrize(
    ("query", "before"),
    [
        ("ASK { ?s ?p ?o }", "ASK {"),
        ("SELECT * { ?s ?p ?o }", "SELECT * {"),
        ("select * from <http://g> where { ?s ?p ?o }", "select * from <http://g> where {"),
        ("SELECT * WHERE { { SELECT ?s WHERE { ?s ?p ?o } } }", "SELECT * WHERE {"),
        ("CONSTRUCT { ?s ?p ?o } { ?s ?p ?o }", "CONSTRUCT { ?s ?p ?o } {"),
        ("CONSTRUCT { ?s ?p ?o } WHERE { ?s ?p ?o }", "CONSTRUCT { ?s ?p ?o } WHERE {"),
        ("DESCRIBE ?s WHERE { ?s ?p ?o }", "DESCRIBE ?s WHERE {"),
        (
            "DELETE { ?s ?p ?o } INSERT { ?s ?p 1 } WHERE { ?s ?p ?o }",
            "DELETE { ?s ?p ?o } INSERT { ?s ?p 1 } WHERE {",
        ),
        (
            "PREFIX ex: <http://x/WHERE#>\n# WHERE { in a comment\nSELECT (\"WHERE {\" AS ?w) ('}' AS ?z) ?where { ?where ex:WHERE ?o }",
            "PREFIX ex: <http://x/WHERE#>\n# WHERE { in a comment\nSELECT (\"WHERE {\" AS ?w) ('}' AS ?z) ?where {",
        ),
        ('SELECT ("""a " } { """ AS ?x) WHERE { ?s ?p ?o }', 'SELECT ("""a " } { """ AS ?x) WHERE {'),
    ],
)
def test_the_where_group_is_found_by_tokens(query: str, before: str) -> None:
    at = where_group(query)
    assert at is not None and query[: at + 1] == before


def test_an_update_without_a_where_group_takes_no_parameters() -> None:
    assert where_group("INSERT DATA { <http://a> <http://b> <http://c> }") is None
    with pytest.raises(StoreError, match="WHERE"):
        bind("INSERT DATA { <http://a> <http://b> ?o }", {"o": Literal("x")})


def test_bound_queries_run_and_blank_nodes_are_refused() -> None:
    store = Store()
    text = bind(
        "SELECT ?o # a comment with WHERE {\nWHERE { }", {"o": [Literal("}"), NamedNode("http://a#b")]}
    )
    assert [str(s["o"]) for s in store.query(text)] == ['"}"', "<http://a#b>"]  # type: ignore[union-attr]
    with pytest.raises(StoreError, match="blank nodes"):
        bind("ASK {}", {"o": BlankNode()})


def test_a_placeholder_says_where_a_parameter_is_bound() -> None:
    query = (
        "SELECT DISTINCT ?s WHERE {\n  { SELECT ?s WHERE { VALUES ?s { UNDEF } ?s ?p ?o } }\n"
        "  # VALUES ?o { UNDEF } in a comment is not one\n  ?s ?q ?o\n}"
    )
    text = bind(query, {"s": [NamedNode("http://a"), NamedNode("http://b")], "o": Literal("x")})
    inner = text.index("{ SELECT ?s WHERE {")
    assert text.index("VALUES ?s { <http://a> <http://b> }") > inner  # in the subquery, as placed
    assert text.index('VALUES (?o) { ("x") }') < inner  # no placeholder: at the top of WHERE
    assert "UNDEF" not in text.split("#")[0] and text.count("UNDEF") == 1  # the comment's stays
    store = Store()
    store.update(
        'INSERT DATA { <http://a> <http://p> "x" . <http://a> <http://q> "x" . <http://c> <http://p> "x" . <http://c> <http://q> "x" }'
    )
    assert [str(s["s"]) for s in store.query(text)] == ["<http://a>"]  # type: ignore[union-attr]
    assert len(list(store.query(query))) == 2  # unbound, the placeholder leaves ?s free  # type: ignore[arg-type]


def test_each_branch_of_a_union_gets_the_values_of_its_placeholder() -> None:
    """run_lineage starts every branch from the run's bundle: one placeholder per branch."""
    query = (
        "SELECT ?s ?o WHERE { { VALUES ?s { UNDEF } ?s <http://p> ?o }"
        " UNION { VALUES ?s { UNDEF } ?s <http://q> ?o } }"
    )
    text = bind(query, {"s": [NamedNode("http://a")]})
    assert text.count("VALUES ?s { <http://a> }") == 2 and "UNDEF" not in text
    store = Store()
    store.update(
        "INSERT DATA { <http://a> <http://p> 1 . <http://a> <http://q> 2 . <http://c> <http://p> 3 }"
    )
    found = sorted(int(s["o"].value) for s in store.query(text))  # type: ignore[union-attr]
    assert found == [1, 2]


def test_a_query_that_names_its_runs_bundles_is_bound_to_them_not_to_the_uuids() -> None:
    """The runs given to a query with a run_bundle parameter are bound as their bundles (graphs);
    the uuids are read there (bound beside them, they were joined to every row)."""
    lineage = library.query("run_lineage")
    uuid = "0d1e8a5c-1111-4a2b-9c3d-123456789abc"
    bound = lineage.bindings({"run": [uuid]})
    assert set(bound) == {"bundle", "execution_bundle", "verdicts_bundle", "verdicts_summary"}
    runs = Namespaces(DEFAULT_NAMESPACE).fixed["run"]
    assert bound["bundle"] == NamedNode(f"{runs}run_{uuid}_bundle")
    assert bound["verdicts_summary"] == NamedNode(f"{runs}run_{uuid}/verdicts_summary")
    # a value that is no run id stays a literal (found nowhere): never part of an IRI
    assert set(lineage.bindings({"run": ['x" } UNION { ?s ?p ?o']})) == {"run"}


def test_one_update_drops_the_replaced_graphs_then_inserts_everything() -> None:
    g1, g2 = NamedNode("http://example.org/g1"), NamedNode("http://example.org/g2")
    s, p = NamedNode("http://example.org/s"), NamedNode("http://example.org/p")
    graphs = GraphSet(
        {g1.value: [Quad(s, p, Literal('a "b"\n}'), g1)], g2.value: [Quad(s, p, BlankNode("x"), g2)]}
    )
    text = write_update(graphs, {g1.value})
    assert text.startswith("DROP SILENT GRAPH <http://example.org/g1> ;\nINSERT DATA {\n")
    assert text.count("INSERT DATA") == 1
    assert "DROP SILENT GRAPH <http://example.org/g2>" not in text
    store = Store()
    store.update(text)
    assert len(store) == 2
    assert isinstance(next(iter(store.quads_for_pattern(None, None, None, g2))).object, BlankNode)
    plain = write_update(GraphSet({g1.value: [Quad(s, p, Literal("a"), g1)]}), False)
    assert plain.startswith("INSERT DATA {\n") and plain.count("INSERT DATA") == 1
    # for Virtuoso: each blank node label of a write becomes one fresh Skolem IRI, in every graph
    skolem = "https://example.org/.well-known/genid/"
    shared = GraphSet(
        {g1.value: [Quad(s, p, BlankNode("x"), g1)], g2.value: [Quad(BlankNode("x"), p, s, g2)]}
    )
    skolemised = write_update(shared, {g1.value}, skolem=skolem)
    assert "_:" not in skolemised and skolemised.count("INSERT DATA") == 1
    store = Store()
    store.update(skolemised)
    (in_g1,) = store.quads_for_pattern(None, None, None, g1)
    (in_g2,) = store.quads_for_pattern(None, None, None, g2)
    assert isinstance(in_g1.object, NamedNode) and in_g1.object.value.startswith(skolem)
    assert in_g1.object == in_g2.subject  # one node in both graphs
    assert write_update(shared, False, skolem=skolem) != skolemised.split(";\n", 1)[1]  # fresh per write
    assert write_update(shared, False).count("_:x") == 2  # elsewhere one node, as INSERT DATA makes it
    assert write_update(GraphSet({g1.value: []}), True) == "DROP SILENT GRAPH <http://example.org/g1>\n"
    assert write_update(GraphSet({}), True) == ""
