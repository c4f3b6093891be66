"""One behaviour for every store: embedded (on disk and in memory) and remote.

The remote store is driven against three real servers: ``oxigraph serve``, ``exscec serve
--allow-updates`` and Virtuoso 7 (each a child process on 127.0.0.1).
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from pathlib import Path

import pytest
from pyoxigraph import BlankNode, Literal, NamedNode, Quad

from exsce_dsl.errors import StoreError
from exsce_dsl.store.base import GraphSet, Store
from exsce_dsl.store.embedded import EmbeddedStore
from exsce_dsl.store.remote import RemoteStore

from tests.support.store_servers import Server, exscec_serve, oxigraph_server, virtuoso_server

EX = "http://example.org/"
G1, G2, G3 = f"{EX}g1", f"{EX}g2", f"{EX}g3"
P = NamedNode(f"{EX}p")
TOKEN = "behaviour-token-of-the-tests"


def q(s: str, o: str | Literal | NamedNode, g: str, p: NamedNode = P) -> Quad:
    obj = Literal(o) if isinstance(o, str) else o
    return Quad(NamedNode(f"{EX}{s}"), p, obj, NamedNode(g))


def triples(quads: Sequence[Quad]) -> set[tuple[str, str, str]]:
    return {(str(x.subject), str(x.predicate), str(x.object)) for x in quads}


@pytest.fixture(scope="module")
def oxigraph(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Server]:
    with oxigraph_server(tmp_path_factory.mktemp("oxigraph")) as server:
        yield server


@pytest.fixture(scope="module")
def exsce_endpoint() -> Iterator[Server]:
    with exscec_serve("--store", "memory:", "--allow-updates", "--token", TOKEN) as server:
        yield server


@pytest.fixture(scope="module")
def virtuoso(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Server]:
    with virtuoso_server(tmp_path_factory.mktemp("virtuoso")) as server:
        yield server


def commits_each_operation(store: Store) -> bool:
    """Whether the store's server commits each operation of a request on its own (its flavour says)."""
    return isinstance(store, RemoteStore) and not store.flavour().whole_requests


@pytest.fixture(params=["embedded", "memory", "oxigraph", "exscec-serve", "virtuoso"])
def store(request: pytest.FixtureRequest, tmp_path: Path) -> Iterator[Store]:
    kind = request.param
    found: Store
    if kind == "embedded":
        found = EmbeddedStore(tmp_path / "store")
    elif kind == "memory":
        found = EmbeddedStore(None)
    elif kind == "oxigraph":
        url = request.getfixturevalue("oxigraph").url
        found = RemoteStore(f"{url}/query", update_url=f"{url}/update", gsp_url=f"{url}/store", timeout=20)
    elif kind == "virtuoso":
        found = RemoteStore(f"{request.getfixturevalue('virtuoso').url}/sparql", timeout=20)
    else:
        url = request.getfixturevalue("exsce_endpoint").url
        found = RemoteStore(f"{url}/query", update_url=f"{url}/update", token=TOKEN, timeout=20)
    found.clear()
    yield found
    found.close()


def test_a_write_adds_every_graph_and_reads_back(store: Store) -> None:
    store.write(GraphSet({G1: [q("a", "1", G1), q("b", "2", G1)], G2: [q("a", "3", G2)]}))
    assert store.graph_names() == {G1, G2}
    assert triples(store.graph(G1)) == triples([q("a", "1", G1), q("b", "2", G1)])
    assert all(x.graph_name == NamedNode(G1) for x in store.graph(G1))
    assert store.graph(G3) == []
    assert store.graph_sizes() == {G1: 2, G2: 1}
    assert len(store.quads()) == 3
    both = store.graphs([G1, G3])
    assert len(both[G1]) == 2 and both[G3] == []


def test_a_write_adds_to_a_graph_and_replace_empties_it_first(store: Store) -> None:
    store.write(GraphSet({G1: [q("a", "1", G1)], G2: [q("a", "2", G2)]}))
    store.write(GraphSet({G1: [q("b", "1", G1)]}))
    assert store.graph_sizes() == {G1: 2, G2: 1}
    store.write(GraphSet({G1: [q("c", "1", G1)], G2: [q("c", "2", G2)]}), replace={G1})
    assert triples(store.graph(G1)) == triples([q("c", "1", G1)])
    assert store.graph_sizes()[G2] == 2
    store.write(GraphSet({G1: [q("d", "1", G1)], G2: []}), replace=True)
    assert store.graph_sizes() == {G1: 1}


def test_graphs_written_to_the_same_graph_name_are_added_once(store: Store) -> None:
    store.write(GraphSet({G1: [q("a", "1", G1), q("a", "1", G1)]}))
    store.write(GraphSet({G1: [q("a", "1", G1)]}))
    assert store.graph_sizes() == {G1: 1}


TRICKY = [
    'quote " inside',
    "brace } and { and }}",
    "hash # not a comment",
    "newline\nand tab\t",
    "backslash \\ and \\u0022",
    "WHERE { ?s ?p ?o }",
    "ünïcödé ✓",
    "'single' and '''triple'''",
]


@pytest.mark.parametrize("text", TRICKY)
def test_parameters_are_bound_as_terms_whatever_they_hold(store: Store, text: str) -> None:
    store.write(GraphSet({G1: [q("x", text, G1), q("y", "other", G1)]}))
    rows = store.select("SELECT ?s WHERE { GRAPH ?g { ?s ?p ?o } }", {"o": Literal(text)})
    assert [row["s"] for row in rows] == [NamedNode(f"{EX}x")]
    assert store.ask("ASK { GRAPH ?g { ?s ?p ?o } }", {"o": Literal(text)})
    assert not store.ask("ASK { GRAPH ?g { ?s ?p ?o } }", {"o": Literal(text + "!")})
    rows = store.select("SELECT ?o WHERE { GRAPH ?g { ?s ?p ?o } }", {"s": NamedNode(f"{EX}x")})
    assert rows.rows == ((Literal(text),),)


def test_parameters_may_be_iris_with_fragments_languages_and_lists(store: Store) -> None:
    subject = NamedNode(f"{EX}thing?q=a%7D#part")
    store.write(
        GraphSet(
            {
                G1: [
                    Quad(subject, P, Literal("chat", language="fr"), NamedNode(G1)),
                    Quad(
                        subject,
                        P,
                        Literal("2.5", datatype=NamedNode("http://www.w3.org/2001/XMLSchema#double")),
                        NamedNode(G1),
                    ),
                    q("other", "x", G1),
                ]
            }
        )
    )
    rows = store.select("SELECT ?o WHERE { GRAPH ?g { ?s ?p ?o } } ORDER BY ?o", {"s": subject})
    assert len(rows) == 2
    assert store.ask("ASK { GRAPH ?g { ?s ?p ?o } }", {"o": Literal("chat", language="fr")})
    rows = store.select(
        "SELECT ?s WHERE { GRAPH ?g { ?s ?p ?o } }", {"o": [Literal("x"), Literal("chat", language="fr")]}
    )
    assert {row["s"] for row in rows} == {subject, NamedNode(f"{EX}other")}


def test_update_with_parameters(store: Store) -> None:
    store.write(GraphSet({G1: [q("a", "old } #", G1), q("b", "keep", G1)]}))
    store.update(
        "DELETE { GRAPH ?g { ?s ?p ?o } } INSERT { GRAPH ?g { ?s ?p ?new } } WHERE { GRAPH ?g { ?s ?p ?o } }",
        {"o": Literal("old } #"), "new": Literal('new "value"')},
    )
    assert triples(store.graph(G1)) == triples([q("a", 'new "value"', G1), q("b", "keep", G1)])


def test_remove_graphs_drops_them_together(store: Store) -> None:
    store.write(GraphSet({G1: [q("a", "1", G1)], G2: [q("a", "2", G2)], G3: [q("a", "3", G3)]}))
    store.remove_graphs([G1, G2, f"{EX}never-written"])
    assert store.graph_names() == {G3}
    store.clear()
    assert store.graph_names() == set()


def test_each_write_makes_fresh_blank_nodes_shared_across_its_graphs(store: Store) -> None:
    node = BlankNode("q1")
    first = GraphSet(
        {
            G1: [Quad(node, P, Literal("one"), NamedNode(G1))],
            G2: [Quad(NamedNode(f"{EX}s"), P, node, NamedNode(G2))],
        }
    )
    store.write(first)
    store.write(GraphSet({G1: [Quad(node, P, Literal("two"), NamedNode(G1))]}))
    rows = store.select(f"SELECT DISTINCT ?b WHERE {{ GRAPH <{G1}> {{ ?b ?p ?o }} }}")
    assert len(rows) == 2  # two writes, two blank nodes
    assert store.ask(f'ASK {{ GRAPH <{G1}> {{ ?b ?p "one" }} GRAPH <{G2}> {{ ?s ?p2 ?b }} }}')


class _Exploding(Sequence[Quad]):
    """Quads that raise half-way through being read."""

    def __init__(self, graph: str) -> None:
        self.graph = graph

    def __len__(self) -> int:
        return 3

    def __getitem__(self, index: int) -> Quad:  # type: ignore[override]
        if index >= 1:
            raise RuntimeError("disk on fire")
        return q("new", "1", self.graph)


@pytest.mark.parametrize("replace", [False, True])
def test_a_failed_write_leaves_the_store_untouched(store: Store, replace: bool) -> None:
    store.write(GraphSet({G1: [q("old", "1", G1)], G2: [q("old", "2", G2)]}))
    before = store.graph_sizes()
    bad_item = GraphSet({G1: [q("new", "1", G1)], G2: [q("new", "2", G2), "not a quad"]})  # type: ignore[list-item]
    with pytest.raises(StoreError, match="not a quad"):
        store.write(bad_item, replace=replace)
    with pytest.raises(StoreError, match="disk on fire"):
        store.write(GraphSet({G1: [q("new", "1", G1)], G3: _Exploding(G3)}), replace=replace)
    with pytest.raises(StoreError, match="graph name"):
        store.write(GraphSet({G1: [q("new", "1", G1)], "not an iri": [q("new", "1", G1)]}), replace=replace)
    assert store.graph_sizes() == before
    assert triples(store.graph(G1)) == triples([q("old", "1", G1)])


def test_an_update_that_fails_half_way_changes_nothing(store: Store) -> None:
    store.write(GraphSet({G1: [q("old", "1", G1)]}))
    with pytest.raises(StoreError):
        # the insert succeeds, then CREATE fails (the graph exists): the whole request is undone
        store.update(f'INSERT DATA {{ GRAPH <{G2}> {{ <{EX}new> <{EX}p> "x" }} }} ; CREATE GRAPH <{G1}>')
    if commits_each_operation(store):
        # Virtuoso commits each operation of a request on its own (docs/stores.md says so: exsce's
        # writes are one INSERT DATA there, and a replacing write a DROP before it)
        assert store.graph_names() == {G1, G2}
    else:
        assert store.graph_names() == {G1}


def test_invalid_queries_are_store_errors(store: Store) -> None:
    with pytest.raises(StoreError):
        store.select("SELECT WHERE {")
    with pytest.raises(StoreError, match="not a SELECT"):
        store.select("ASK {}")
    with pytest.raises(StoreError, match="not an ASK"):
        store.ask("SELECT * WHERE {}")
    with pytest.raises(StoreError):
        store.update("INSERT DATA { nonsense")
    with pytest.raises(StoreError, match="variable"):
        store.select("SELECT ?x WHERE { ?x ?p ?o }", {"x y": Literal("1")})
