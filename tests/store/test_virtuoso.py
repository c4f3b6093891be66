"""The remote store against a real Virtuoso 7.2 (Debian's ``virtuoso-opensource-7-bin``,
started by the tests on free ports and stopped after).

What used to fail there: a query sent to a plain ``http://.../sparql`` URL as an
``application/sparql-query`` body is never answered (it hung until the timeout); a write with
blank nodes was refused (``SP031 ... Blank node '_:q1' is not allowed in a constant clause``:
Virtuoso takes no blank nodes in ``INSERT DATA``); and Virtuoso answers ASK with a table, not
a boolean.  Every request here has a 20 s timeout, so a hang fails rather than waits.
"""

from __future__ import annotations

import datetime
import json
from collections.abc import Iterator
from pathlib import Path

import pytest
from pyoxigraph import BlankNode, CanonicalizationAlgorithm, Dataset, Literal, NamedNode, Quad

from exsce_dsl.errors import StoreError
from exsce_dsl.lang import load_spec
from exsce_dsl.sim.executor import Fault
from exsce_dsl.sim.run import simulate
from exsce_dsl.store import queries
from exsce_dsl.store.base import GraphSet, Store
from exsce_dsl.store.open import open_store
from exsce_dsl.store.remote import RemoteStore

from tests.support.cli import exscec_here, run_exscec
from tests.support.map_files import write_map
from tests.support.paths import EXAMPLES
from tests.support.store_servers import Server, virtuoso_server
from tests.support.yard_spec import YARD_SPEC

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


def test_doubles_read_back_to_the_last_bit_and_the_servers_graphs_stay(store: RemoteStore) -> None:
    """Virtuoso's SPARQL results carry six digits of a double; exsce reads its Turtle instead."""
    double = NamedNode("http://www.w3.org/2001/XMLSchema#double")
    values = [0.1 + 0.2, 123456.78901234567, 1e-7 / 3, 2.0**60, -0.5, 1.0]
    store.write(
        GraphSet(
            {
                G1: [
                    Quad(NamedNode(f"{EX}v{i}"), P, Literal(repr(v), datatype=double), NamedNode(G1))
                    for i, v in enumerate(values)
                ]
            }
        )
    )
    rows = store.select(f"SELECT ?s ?o WHERE {{ GRAPH <{G1}> {{ ?s ?p ?o }} }} ORDER BY ?s")
    assert [float(o.value) for _, o in rows.rows] == values
    assert all(o.datatype == double for _, o in rows.rows)
    assert sorted(float(q.object.value) for q in store.graph(G1)) == sorted(values)
    mean = store.select(f"SELECT (SUM(?o) AS ?sum) WHERE {{ GRAPH <{G1}> {{ ?s ?p ?o }} }}")
    assert float(mean.rows[0][0].value) == pytest.approx(sum(values), rel=1e-15)
    # Virtuoso's own graphs are neither listed nor cleared (dropping virtrdf# breaks the server)
    assert not {g for g in store.graph_names() if "openlinksw" in g or "virtrdf" in g}
    store.clear()
    assert store.graph_names() == set()
    store.write(GraphSet({G2: [Quad(NamedNode(f"{EX}a"), P, Literal("after"), NamedNode(G2))]}))
    assert store.ask(f"ASK {{ GRAPH <{G2}> {{ ?s ?p 'after' }} }}")
    with pytest.raises(StoreError, match="not a SELECT"):
        store.select("ASK {}")


@pytest.fixture(scope="module")
def yard(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, list[Path]]:
    """The yard of tests/oracles/test_verify_e2e: five clean runs and one over speed."""
    folder = tmp_path_factory.mktemp("yard")
    write_map(folder, size=200)
    (folder / "spec.exsce").write_text(YARD_SPEC)
    scenario = load_spec(folder / "spec.exsce").scenario()
    bags = [run.bag for run in simulate(scenario, folder / "runs", 5, seed=1)]
    bags += [
        run.bag
        for run in simulate(scenario, folder / "faults", 1, seed=2, faults=(Fault.parse("overspeed:r1"),))
    ]
    return folder, bags


def _method_on(store_url: str, folder: Path, bags: list[Path]) -> tuple[list[dict[str, object]], str]:
    """Ingest four runs, build the baseline, verify the other two: the verdicts, and the report's
    overview page."""

    def exscec(*args: str) -> str:
        done = exscec_here(*args, "--store", store_url, cwd=folder)
        assert done.returncode in (0, 1), done.stderr
        assert "Traceback" not in done.stderr
        return done.stdout

    exscec("compile", "spec.exsce")
    exscec("ingest", *map(str, bags[:4]), "--scenario", "spec.exsce")
    exscec("baseline", "spec.exsce")
    verdicts = json.loads(exscec("verify", *map(str, bags[4:]), "--scenario", "spec.exsce", "--json"))
    report = folder / f"report-{'virtuoso' if 'virtuoso' in store_url else 'embedded'}"
    exscec("report", "-o", str(report), "--spec", "spec.exsce")
    return verdicts, (report / "index.html").read_text()


def test_ingest_baseline_verify_and_report_give_the_embedded_stores_answers(
    virtuoso: Server, yard: tuple[Path, list[Path]]
) -> None:
    folder, bags = yard
    on_virtuoso, page = _method_on(f"virtuoso+{virtuoso.url}", folder, bags)
    embedded, embedded_page = _method_on(str(folder / "embedded-store"), folder, bags)

    def table(verdicts: list[dict[str, object]]) -> list[tuple[object, ...]]:
        return sorted(
            (v["run"], v["oracle"], v["verdict"], round(float(v["observed"]), 9))  # type: ignore[arg-type]
            for v in verdicts
        )

    assert table(on_virtuoso) == table(embedded)
    failed = {(v["oracle"]) for v in on_virtuoso if v["verdict"] == "failed"}
    assert failed == {"r1-max_velocity", "r1-task_duration"}  # the over-speed run's, as on Oxigraph
    assert "yard_run" in page and page.count("failed") == embedded_page.count("failed")
    # the stored runs' provenance is the same, blank nodes and doubles included
    virtuoso_store, folder_store = (
        open_store(f"virtuoso+{virtuoso.url}", timeout=60),
        open_store(str(folder / "embedded-store")),
    )
    runs = [g for g in folder_store.graph_names() if "/runs/" in g and "verdict" not in g]
    assert runs
    for name in runs:
        there, here = canonical(virtuoso_store.graph(name)), canonical(folder_store.graph(name))
        if there != here:
            a, b = {str(q) for q in there}, {str(q) for q in here}
            print("ONLY VIRT", sorted(a - b)[:4], "\nONLY EMB", sorted(b - a)[:4], len(a), len(b))
        assert there == here, name
    # each segment value with its unit and start pose (an OPTIONAL across graphs), as on Oxigraph
    uuids = [r.uuid for r in queries.runs(folder_store)]

    def segment_values(store: Store) -> list[tuple[object, ...]]:
        found = queries.run_segment_values(store, uuids)
        return sorted((r.run, r.action, r.metric, round(r.value, 9), r.unit, r.start) for r in found)

    here_values = segment_values(folder_store)
    assert here_values and all(unit and start for *_, unit, start in here_values)
    assert segment_values(virtuoso_store) == here_values
    folder_store.close()


DOUBLE = NamedNode("http://www.w3.org/2001/XMLSchema#double")
DATE_TIME = NamedNode("http://www.w3.org/2001/XMLSchema#dateTime")


def canonical(quads: list[Quad]) -> Dataset:
    """The quads up to blank node labels and a double's lexical form (a store may write 2 as 2.0)."""

    def same(term: object) -> object:
        if isinstance(term, Literal) and term.datatype == DOUBLE:
            return Literal(repr(float(term.value)), datatype=DOUBLE)
        if isinstance(term, Literal) and term.datatype == DATE_TIME:  # 17.34Z and 17.340Z
            return Literal(datetime.datetime.fromisoformat(term.value).isoformat(), datatype=DATE_TIME)
        return term

    dataset = Dataset([Quad(q.subject, q.predicate, same(q.object), q.graph_name) for q in quads])  # type: ignore[arg-type]
    dataset.canonicalize(CanonicalizationAlgorithm.UNSTABLE)
    return dataset
