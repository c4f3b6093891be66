"""``exscec serve``: a real SPARQL 1.1 Protocol endpoint, driven by real clients.

The server runs as a child process over a project's store; its answers are
compared with those of an embedded store holding the same scenario.
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import urllib.error
import urllib.parse
import urllib.request
from collections.abc import Iterator
from pathlib import Path

import pytest
from prov.model import ProvDocument
from pyoxigraph import QueryResultsFormat, RdfFormat, parse
from SPARQLWrapper import CSV, JSON, POST, POSTDIRECTLY, TSV, XML, SPARQLWrapper

from exsce_dsl.lang import load_spec
from exsce_dsl.prov import compile_scenario
from exsce_dsl.store.embedded import EmbeddedStore
from exsce_dsl.store.serve_info import read_serve_info, serve_info_path
from exsce_dsl.store.writing import add_prov

from tests.support.cli import run_exscec
from tests.support.paths import EXAMPLES
from tests.support.store_servers import Server, exscec_serve, start_exscec_serve, stop

TOKEN = "s3cret-token-of-the-tests"
SCENARIO_C = EXAMPLES / "brsu_building_c" / "scenario_c.exsce"
SCENARIO_A = EXAMPLES / "brsu_building_c" / "scenario_a.exsce"
PREFIXES = """PREFIX geom: <https://robot-schema.org/>
PREFIX coord: <https://robot-schema.org/coordinates/>
PREFIX prov: <http://www.w3.org/ns/prov#>
"""
QUERIES = {
    "graphs": "SELECT ?g (COUNT(*) AS ?n) WHERE { GRAPH ?g { ?s ?p ?o } } GROUP BY ?g ORDER BY ?g",
    "points": PREFIXES
    + "SELECT ?point ?x ?y WHERE { GRAPH ?g { ?point a geom:Point ; coord:x ?x ; coord:y ?y } } ORDER BY ?point",
    "members": PREFIXES
    + 'SELECT ?m WHERE { GRAPH ?g { ?s prov:hadMember ?m } FILTER(CONTAINS(STR(?m), "tiago")) } ORDER BY ?m',
    "ask": PREFIXES + "ASK { GRAPH ?g { ?s a geom:Pose } }",
}
CONSTRUCT = PREFIXES + "CONSTRUCT { ?p coord:x ?x } WHERE { GRAPH ?g { ?p coord:x ?x } }"


def document(spec: Path) -> ProvDocument:
    return compile_scenario(load_spec(str(spec)).scenario(None))


@pytest.fixture(scope="module")
def reference() -> Iterator[EmbeddedStore]:
    """An embedded store holding scenario_c: what every answer must equal."""
    store = EmbeddedStore(None)
    add_prov(store, document(SCENARIO_C))
    yield store
    store.close()


@pytest.fixture(scope="module")
def project(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("project")
    with EmbeddedStore(folder / ".exsce" / "store") as store:
        add_prov(store, document(SCENARIO_C))
    return folder


@pytest.fixture(scope="module")
def endpoint(project: Path) -> Iterator[Server]:
    """``exscec serve`` over the project's store, read-only (the default)."""
    env = {"EXSCE_STORE_TOKEN": TOKEN}  # ignored without --allow-updates
    with exscec_serve(cwd=project, env=env) as server:
        yield server


@pytest.fixture(scope="module")
def writable(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[Server, Path]]:
    """``exscec serve --allow-updates`` over an empty project store, its token from the environment."""
    folder = tmp_path_factory.mktemp("writable")
    with exscec_serve("--allow-updates", cwd=folder, env={"EXSCE_STORE_TOKEN": TOKEN}) as server:
        yield server, folder


def http(
    url: str, data: bytes | None = None, headers: dict[str, str] | None = None, method: str | None = None
) -> tuple[int, str, bytes]:
    request = urllib.request.Request(url, data=data, headers=headers or {}, method=method)
    try:
        with urllib.request.urlopen(request, timeout=20) as answer:
            return answer.status, answer.headers.get("Content-Type", ""), answer.read()
    except urllib.error.HTTPError as refused:
        return refused.code, refused.headers.get("Content-Type", ""), refused.read()


def expected(reference: EmbeddedStore, query: str, fmt: QueryResultsFormat) -> bytes:
    result = reference.query(query)
    data = result.serialize(format=fmt)  # type: ignore[attr-defined]
    assert isinstance(data, bytes)
    return data


# -- real clients --------------------------------------------------------------------


@pytest.mark.parametrize("name", list(QUERIES))
@pytest.mark.parametrize("method", ["GET", "POST-form", "POST-direct"])
def test_sparqlwrapper_gets_the_embedded_stores_answers_in_json(
    endpoint: Server, reference: EmbeddedStore, name: str, method: str
) -> None:
    client = SPARQLWrapper(f"{endpoint.url}/query")
    client.setQuery(QUERIES[name])
    client.setReturnFormat(JSON)
    if method != "GET":
        client.setMethod(POST)
        client.setRequestMethod(POSTDIRECTLY if method == "POST-direct" else "urlencoded")
    answer = client.query().convert()
    assert answer == json.loads(expected(reference, QUERIES[name], QueryResultsFormat.JSON))
    if name == "graphs":
        assert len(answer["results"]["bindings"]) == 14  # type: ignore[index]


@pytest.mark.parametrize(
    ("fmt", "results"),
    [(XML, QueryResultsFormat.XML), (CSV, QueryResultsFormat.CSV), (TSV, QueryResultsFormat.TSV)],
)
def test_sparqlwrapper_gets_xml_csv_and_tsv(
    endpoint: Server, reference: EmbeddedStore, fmt: str, results: QueryResultsFormat
) -> None:
    for query in (QUERIES["points"], QUERIES["ask"]):
        client = SPARQLWrapper(f"{endpoint.url}/query")
        client.setQuery(query)
        client.setReturnFormat(fmt)
        response = client.query().response
        assert response.read() == expected(reference, query, results)


@pytest.mark.parametrize(
    ("accept", "fmt"),
    [
        ("application/sparql-results+json", QueryResultsFormat.JSON),
        ("application/sparql-results+xml", QueryResultsFormat.XML),
        ("text/csv", QueryResultsFormat.CSV),
        ("text/tab-separated-values; q=1.0, */*;q=0.1", QueryResultsFormat.TSV),
        ("*/*", QueryResultsFormat.JSON),
        ("", QueryResultsFormat.JSON),
    ],
)
def test_urllib_get_and_post_negotiate_the_results_format(
    endpoint: Server, reference: EmbeddedStore, accept: str, fmt: QueryResultsFormat
) -> None:
    query = QUERIES["points"]
    headers = {"Accept": accept} if accept else {}
    status, content_type, body = http(
        f"{endpoint.url}/query?{urllib.parse.urlencode({'query': query})}", headers=headers
    )
    assert status == 200 and content_type.startswith(fmt.media_type.split(";")[0])
    assert body == expected(reference, query, fmt)
    post = {**headers, "Content-Type": "application/sparql-query"}
    assert http(f"{endpoint.url}/query", query.encode(), post)[2] == body
    form = {**headers, "Content-Type": "application/x-www-form-urlencoded"}
    assert http(f"{endpoint.url}/sparql", urllib.parse.urlencode({"query": query}).encode(), form)[2] == body


@pytest.mark.parametrize(
    ("accept", "fmt"), [("text/turtle", RdfFormat.TURTLE), ("application/n-triples", RdfFormat.N_TRIPLES)]
)
def test_construct_answers_are_graphs(
    endpoint: Server, reference: EmbeddedStore, accept: str, fmt: RdfFormat
) -> None:
    status, content_type, body = http(
        f"{endpoint.url}/query",
        CONSTRUCT.encode(),
        {"Content-Type": "application/sparql-query", "Accept": accept},
    )
    assert status == 200 and content_type.startswith(accept)
    answered = {str(t) for t in parse(body, format=fmt)}
    assert answered == {str(t) for t in reference.query(CONSTRUCT)}  # type: ignore[attr-defined]
    assert len(answered) > 10


def test_the_graph_store_protocol_reads_one_graph(endpoint: Server, reference: EmbeddedStore) -> None:
    graph = "https://www.sesame-project.org/scenarios/scenario_c_bundle"
    status, _, body = http(f"{endpoint.url}/store?{urllib.parse.urlencode({'graph': graph})}")
    assert status == 200
    assert len(list(parse(body, format=RdfFormat.N_TRIPLES))) == len(reference.graph(graph))
    assert http(f"{endpoint.url}/store?graph=http://example.org/none")[0] == 404


def test_the_query_page_works_in_a_browser_without_external_resources(endpoint: Server) -> None:
    status, content_type, body = http(f"{endpoint.url}/")
    page = body.decode()
    assert status == 200 and content_type.startswith("text/html")
    assert "<textarea" in page and "fetch(" in page and "read-only" in page
    assert "<link" not in page and 'src="' not in page and "//cdn" not in page


def test_mistakes_get_clear_http_answers(endpoint: Server) -> None:
    url = endpoint.url
    status, _, body = http(f"{url}/query?query=SELECT%20WHERE%20%7B")
    assert status == 400 and b"SPARQL syntax error" in body
    status, _, body = http(f"{url}/query", b"DROP ALL", {"Content-Type": "application/sparql-query"})
    assert status == 400 and b"POST it to /update" in body
    assert http(f"{url}/query?query=ASK%7B%7D", headers={"Accept": "image/png"})[0] == 406
    assert http(f"{url}/query", b"ASK {}", {"Content-Type": "text/plain"})[0] == 415
    assert http(f"{url}/update")[0] == 405
    assert http(f"{url}/nowhere")[0] == 404


# -- updates -------------------------------------------------------------------------


def test_a_read_only_endpoint_refuses_updates_with_403(endpoint: Server) -> None:
    for token in (None, TOKEN):
        headers = {"Content-Type": "application/sparql-update"}
        if token:
            headers["Authorization"] = f"Bearer {token}"
        status, _, body = http(f"{endpoint.url}/update", b"DROP ALL", headers)
        assert status == 403 and b"--allow-updates" in body


def test_updates_need_the_bearer_token(writable: tuple[Server, Path]) -> None:
    server, _ = writable
    update = (
        b'INSERT DATA { GRAPH <http://example.org/g> { <http://example.org/s> <http://example.org/p> "o" } }'
    )
    plain = {"Content-Type": "application/sparql-update"}
    status, _, body = http(f"{server.url}/update", update, plain)
    assert status == 401 and b"no bearer token" in body
    status, _, body = http(f"{server.url}/update", update, {**plain, "Authorization": "Bearer wrong"})
    assert status == 401 and b"wrong bearer token" in body
    assert http(f"{server.url}/update", update, {**plain, "Authorization": f"Bearer {TOKEN}"})[0] == 204
    form = urllib.parse.urlencode({"update": "CLEAR GRAPH <http://example.org/g>"}).encode()
    headers = {"Content-Type": "application/x-www-form-urlencoded", "Authorization": f"Bearer {TOKEN}"}
    assert http(f"{server.url}/update", form, headers)[0] == 204
    ask = urllib.parse.urlencode({"query": "ASK { GRAPH ?g { ?s ?p ?o } }"})
    assert http(f"{server.url}/query?{ask}", headers={"Accept": "text/csv"})[2] == b"false"


# -- the CLI and the endpoint on the same store --------------------------------------


def test_cli_reads_through_a_read_only_server_and_cannot_write(endpoint: Server, project: Path) -> None:
    info = read_serve_info(project / ".exsce" / "store")
    assert (
        info is not None
        and info.url == endpoint.url
        and info.pid == endpoint.process.pid
        and not info.updates
    )
    assert TOKEN not in serve_info_path(project / ".exsce" / "store").read_text()
    listed = run_exscec("store", "graphs", cwd=project)
    assert listed.returncode == 0, listed.stderr
    assert len(listed.stdout.splitlines()) == 14
    refused = run_exscec("compile", str(SCENARIO_A), "--store", cwd=project)
    assert refused.returncode == 2
    assert f"held by exscec serve, pid {endpoint.process.pid}, read-only" in refused.stderr
    assert "403" in refused.stderr and "--allow-updates" in refused.stderr
    assert "Traceback" not in refused.stderr
    served = run_exscec("serve", "--bind", "127.0.0.1:0", cwd=project)
    assert served.returncode == 2 and f"served already (pid {endpoint.process.pid})" in served.stderr


def test_cli_writes_through_a_server_that_allows_updates(writable: tuple[Server, Path]) -> None:
    server, folder = writable
    without = {k: v for k, v in os.environ.items() if k != "EXSCE_STORE_TOKEN"}
    refused = run_exscec_env(["compile", str(SCENARIO_C), "--store"], folder, without)
    assert refused.returncode == 2 and "401" in refused.stderr and "EXSCE_STORE_TOKEN" in refused.stderr
    added = run_exscec_env(
        ["compile", str(SCENARIO_C), "--store"], folder, {**without, "EXSCE_STORE_TOKEN": TOKEN}
    )
    assert added.returncode == 0, added.stderr
    assert "added 14 graphs" in added.stderr
    query = urllib.parse.urlencode({"query": QUERIES["graphs"]})
    status, _, body = http(f"{server.url}/query?{query}", headers={"Accept": "text/csv"})
    assert status == 200 and len(body.decode().splitlines()) == 15


def run_exscec_env(args: list[str], cwd: Path, env: dict[str, str]) -> object:
    import subprocess
    import sys

    return subprocess.run(
        [str(Path(sys.executable).with_name("exscec")), *args],
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )


def test_sigterm_stops_the_server_cleanly(tmp_path: Path) -> None:
    store = tmp_path / "store"
    server = start_exscec_serve("--store", str(store))
    try:
        assert serve_info_path(store).exists()
        server.process.send_signal(signal.SIGTERM)
        assert server.process.wait(timeout=15) == 0
    finally:
        stop(server.process)
    assert not serve_info_path(store).exists()
    with EmbeddedStore(store) as reopened:  # the folder is free again
        assert reopened.graph_names() == set()
    shutil.rmtree(store)


# -- limits --------------------------------------------------------------------------


def test_queries_over_the_time_or_size_limit_get_503_and_the_server_goes_on(tmp_path: Path) -> None:
    folder = tmp_path / "limited"
    with EmbeddedStore(folder / ".exsce" / "store") as store:
        add_prov(store, document(SCENARIO_C))
    with exscec_serve("--query-timeout", "0.5", "--max-answer-mb", "0.01", cwd=folder) as server:
        slow = "SELECT (COUNT(*) AS ?n) WHERE { GRAPH ?a { ?s ?p ?o } GRAPH ?b { ?t ?q ?r } GRAPH ?c { ?u ?v ?w } }"
        status, _, body = http(f"{server.url}/query?" + urllib.parse.urlencode({"query": slow}))
        assert status == 503 and b"time limit of 0.5 s" in body
        everything = "SELECT * WHERE { GRAPH ?g { ?s ?p ?o } }"
        status, _, body = http(f"{server.url}/query?" + urllib.parse.urlencode({"query": everything}))
        assert status == 503 and b"MiB, over the endpoint's limit of 0.0" in body
        huge = ("ASK { " + "?s ?p ?o . " * 120_000 + "}").encode()
        status, _, body = http(f"{server.url}/query", huge, {"Content-Type": "application/sparql-query"})
        assert status == 413 and b"a query is at most 1024 KiB" in body
        small = "SELECT ?g WHERE { GRAPH ?g { ?s ?p ?o } } LIMIT 1"
        status, _, body = http(f"{server.url}/query?" + urllib.parse.urlencode({"query": small}))
        assert status == 200 and b"bindings" in body  # still answering
