"""What only a remote store meets: HTTP errors, timeouts, forms, credentials."""

from __future__ import annotations

import socket
import threading
from collections.abc import Iterator
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path

import pytest
from pyoxigraph import Literal, NamedNode, Quad

from exsce_dsl.errors import StoreError
from exsce_dsl.store.base import GraphSet
from exsce_dsl.store.remote import RemoteStore

from tests.support.store_servers import Server, free_port, oxigraph_server

G = "http://example.org/g"


@pytest.fixture(scope="module")
def oxigraph(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Server]:
    with oxigraph_server(tmp_path_factory.mktemp("oxigraph")) as server:
        yield server


def test_the_servers_message_and_url_are_in_the_error(oxigraph: Server) -> None:
    store = RemoteStore(f"{oxigraph.url}/query", update_url=f"{oxigraph.url}/update")
    with pytest.raises(StoreError) as failed:
        store.select("SELECT ?x WHERE { ?x ?y }")
    message = str(failed.value)
    assert f"the SPARQL endpoint {oxigraph.url}/query answered 400 Bad Request" in message
    assert "error at" in message  # Oxigraph's own words
    wrong = RemoteStore(f"{oxigraph.url}/nowhere")
    with pytest.raises(StoreError, match="answered 404"):
        wrong.ask("ASK {}")


def test_url_encoded_requests_and_graph_store_reads(oxigraph: Server) -> None:
    store = RemoteStore(f"{oxigraph.url}/query", update_url=f"{oxigraph.url}/update", form=True)
    store.clear()
    quad = Quad(
        NamedNode("http://example.org/s"),
        NamedNode("http://example.org/p"),
        Literal("a & b = c"),
        NamedNode(G),
    )
    store.write(GraphSet({G: [quad]}))
    assert store.select("SELECT ?o WHERE { GRAPH ?g { ?s ?p ?o } }").rows == ((Literal("a & b = c"),),)
    with_gsp = RemoteStore(f"{oxigraph.url}/query", gsp_url=f"{oxigraph.url}/store")
    assert with_gsp.graph(G) == [quad]
    assert with_gsp.graph("http://example.org/missing") == []
    store.clear()


def test_an_endpoint_that_does_not_answer_times_out(tmp_path: Path) -> None:
    with socket.socket() as silent:
        silent.bind(("127.0.0.1", 0))
        silent.listen(1)
        url = f"http://127.0.0.1:{silent.getsockname()[1]}/sparql"
        store = RemoteStore(url, timeout=0.3)
        with pytest.raises(StoreError, match=r"did not answer within 0\.3 s"):
            store.ask("ASK {}")


def test_nobody_listening_is_connection_refused() -> None:
    url = f"http://127.0.0.1:{free_port()}/sparql"
    with pytest.raises(StoreError, match="connection refused"):
        RemoteStore(url).ask("ASK {}")


class _Recorder(BaseHTTPRequestHandler):
    seen: list[dict[str, str]] = []

    def do_POST(self) -> None:
        self.rfile.read(int(self.headers.get("Content-Length", "0")))
        _Recorder.seen.append(dict(self.headers))
        body = b'{"head":{},"boolean":true}'
        self.send_response(200)
        self.send_header("Content-Type", "application/sparql-results+json")
        self.send_header("Content-Length", str(len(body)))
        self.end_headers()
        self.wfile.write(body)

    def log_message(self, format: str, *args: object) -> None:
        pass


def test_credentials_go_as_basic_auth_or_a_bearer_token() -> None:
    server = ThreadingHTTPServer(("127.0.0.1", 0), _Recorder)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        port = server.server_address[1]
        assert RemoteStore(f"http://ann:pa%3Ass@127.0.0.1:{port}/sparql").ask("ASK {}")
        assert RemoteStore(f"http://127.0.0.1:{port}/sparql", token="tok").ask("ASK {}")
    finally:
        server.shutdown()
        server.server_close()
    basic, bearer = _Recorder.seen[-2:]
    assert basic["Authorization"] == "Basic YW5uOnBhOnNz"  # ann:pa:ss
    assert bearer["Authorization"] == "Bearer tok"
    assert basic["Content-Type"] == "application/x-www-form-urlencoded"  # a small query: a form
