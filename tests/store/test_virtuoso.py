"""The remote store against a real Virtuoso 7.2 (Debian's ``virtuoso-opensource-7-bin``,
started by the tests on free ports and stopped after).

What used to fail there: a query sent to a plain ``http://.../sparql`` URL as an
``application/sparql-query`` body is never answered (it hung until the timeout); a write with
blank nodes was refused (``SP031 ... Blank node '_:q1' is not allowed in a constant clause``:
Virtuoso takes no blank nodes in ``INSERT DATA``); and Virtuoso answers ASK with a table, not
a boolean.  Every request here has a 20 s timeout, so a hang fails rather than waits.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest
from pyoxigraph import BlankNode, Literal, NamedNode, Quad

from exsce_dsl.store.base import GraphSet
from exsce_dsl.store.open import open_store
from exsce_dsl.store.remote import RemoteStore

from conftest import EXAMPLES, run_exscec
from store_servers import Server, virtuoso_server

EX = "http://example.org/virtuoso/"
G1, G2 = f"{EX}g1", f"{EX}g2"
P = NamedNode(f"{EX}p")


@pytest.fixture(scope="module")
def virtuoso(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Server]:
    with virtuoso_server(tmp_path_factory.mktemp("virtuoso")) as server:
        yield server


@pytest.fixture(params=["plain URL", "virtuoso+ preset"])
def store(request: pytest.FixtureRequest, virtuoso: Server) -> Iterator[RemoteStore]:
    url = f"{virtuoso.url}/sparql" if request.param == "plain URL" else f"virtuoso+{virtuoso.url}"
    opened = open_store(url, timeout=20)
    assert isinstance(opened, RemoteStore)
    opened.remove_graphs([G1, G2])
    yield opened
    opened.remove_graphs([G1, G2])


def test_select_and_ask_are_answered(store: RemoteStore) -> None:
    store.write(GraphSet({G1: [Quad(NamedNode(f"{EX}a"), P, Literal("1"), NamedNode(G1))]}))
    rows = store.select(f"SELECT ?o WHERE {{ GRAPH <{G1}> {{ <{EX}a> ?p ?o }} }}")
    assert [o.value for (o,) in rows.rows] == ["1"]
    assert store.ask(f"ASK {{ GRAPH <{G1}> {{ <{EX}a> ?p ?o }} }}") is True
    assert store.ask(f"ASK {{ GRAPH <{G1}> {{ <{EX}nobody> ?p ?o }} }}") is False


def test_a_write_with_blank_nodes_in_two_graphs_reads_back(store: RemoteStore) -> None:
    """Virtuoso fails a template of two graphs with 500 after inserting them: one template
    per graph, in one request."""
    inner, other = BlankNode("q1"), BlankNode("q2")
    store.write(
        GraphSet(
            {
                G1: [
                    Quad(NamedNode(f"{EX}a"), P, inner, NamedNode(G1)),
                    Quad(inner, P, Literal("inside"), NamedNode(G1)),
                ],
                G2: [Quad(NamedNode(f"{EX}b"), P, other, NamedNode(G2))],
            }
        )
    )
    first, second = store.graph(G1), store.graph(G2)
    assert len(first) == 2 and len(second) == 1
    node = next(q.object for q in first if q.subject == NamedNode(f"{EX}a"))
    assert isinstance(node, BlankNode)
    assert any(q.subject == node and q.object == Literal("inside") for q in first)
    assert isinstance(second[0].object, BlankNode) and second[0].object != node
    store.write(GraphSet({G1: [Quad(NamedNode(f"{EX}c"), P, Literal("new"), NamedNode(G1))]}), replace=True)
    assert [(q.subject.value, q.object.value) for q in store.graph(G1)] == [(f"{EX}c", "new")]
    assert {G1, G2} <= store.graph_names()


def test_exscec_compile_stores_a_scenario_in_virtuoso(virtuoso: Server, tmp_path: Path) -> None:
    """The command the issue saw refused (its PROV has blank nodes)."""
    url = f"virtuoso+{virtuoso.url}"
    done = run_exscec(
        "compile", str(EXAMPLES / "brsu_building_c" / "scenario_c.exsce"), "--store", url, cwd=tmp_path
    )
    assert done.returncode == 0, done.stderr
    store = open_store(url, timeout=20)
    scenarios = store.select(
        "SELECT ?s WHERE { GRAPH ?g { ?s a <http://www.w3.org/ns/prov#Entity> } "
        "FILTER(CONTAINS(STR(?s), 'scenario_c')) } LIMIT 5"
    )
    assert scenarios.rows
