"""Which servers a query or update would reach, read by rdflib's SPARQL parser (store/federation.py)."""

from __future__ import annotations

import socket
import threading

import pyoxigraph
import pytest

from exsce_dsl.errors import FederationRefused, Unparsable
from exsce_dsl.store.federation import Federated, federated_targets, refuse_federation

REFUSED = [
    "SELECT * WHERE { SERVICE <http://127.0.0.1:9/sparql> { ?s ?p ?o } }",
    # the keyword after a variable and a dot, which a keyword scan read as part of '?o.SERVICE'
    "SELECT * WHERE { ?s ?p ?o.SERVICE <http://127.0.0.1:9/x> { ?a ?b ?c } }",
    "PREFIX e: <http://127.0.0.1:9/> SELECT * WHERE { SERVICE e:sparql { ?s ?p ?o } }",
    "BASE <http://127.0.0.1:9/> SELECT * WHERE { SERVICE <sparql> { ?s ?p ?o } }",
    "SELECT * WHERE { SERVICE SILENT ?endpoint { ?s ?p ?o } }",
    "select * where { service <http://example.org/> { ?s ?p ?o } }",
    "SELECT * WHERE { { SELECT ?s WHERE { SERVICE <http://h/> { ?s ?p ?o } } } }",
    # SPARQL's codepoint escapes, in a text rdflib cannot parse
    "SELECT * WHERE { \\u0053ERVICE <http://127.0.0.1:9/> { ?s ?p ?o } } <<",
]

ALLOWED = [
    "SELECT * WHERE { ?s ?p ?o }",
    "SELECT * WHERE { ?s <http://service.example/p> 'SERVICE <http://x/>' }",  # in an IRI, a string
    "SELECT * WHERE { ?s ?p ?o # SERVICE <http://x/> { }\n }",  # in a comment
    "SELECT ?service WHERE { ?service ?p ?o }",  # a variable of that name
    "ASK {}",
]


@pytest.mark.parametrize("query", REFUSED)
def test_federating_query_refused(query: str) -> None:
    with pytest.raises(FederationRefused):
        refuse_federation(query)


@pytest.mark.parametrize("query", ALLOWED)
def test_query_without_federation_passes(query: str) -> None:
    refuse_federation(query)


def test_allowed_host_by_name() -> None:
    query = "SELECT * WHERE { SERVICE <http://data.example.org/sparql> { ?s ?p ?o } }"
    refuse_federation(query, ["data.example.org"])
    with pytest.raises(FederationRefused, match="only data.example.org may be reached"):
        refuse_federation(query.replace("data.example.org", "127.0.0.1"), ["data.example.org"])
    with pytest.raises(FederationRefused):  # a variable names no host
        refuse_federation("SELECT * { SERVICE ?x { ?s ?p ?o } }", ["data.example.org"])


def test_load_in_an_update_refused() -> None:
    update = "LOAD <http://127.0.0.1:9/data.ttl> INTO GRAPH <urn:g>"
    assert federated_targets(update, update=True) == [Federated("LOAD", "http://127.0.0.1:9/data.ttl")]
    with pytest.raises(FederationRefused, match="LOAD <http://127.0.0.1:9/data.ttl>"):
        refuse_federation(update, update=True)
    where = "INSERT { ?s ?p ?o } WHERE { SERVICE <http://h/> { ?s ?p ?o } }"
    with pytest.raises(FederationRefused):
        refuse_federation(where, update=True)
    refuse_federation("INSERT DATA { <urn:a> <urn:b> 'LOAD <http://x/>' }", update=True)


def test_unparsable_text_reported() -> None:
    with pytest.raises(Unparsable):
        federated_targets("SELECT WHERE {")


def test_oxigraph_would_reach_the_listener() -> None:
    """The check guards a real door: the embedded store itself connects to a SERVICE's host."""
    listener = socket.socket()
    listener.bind(("127.0.0.1", 0))
    listener.listen(1)
    listener.settimeout(5)
    port = listener.getsockname()[1]
    reached = threading.Event()

    def accept() -> None:
        try:
            connection, _ = listener.accept()
            reached.set()
            connection.close()
        except OSError:
            pass

    thread = threading.Thread(target=accept)
    thread.start()
    query = f"SELECT * WHERE {{ SERVICE <http://127.0.0.1:{port}/sparql> {{ ?s ?p ?o }} }}"
    with pytest.raises(FederationRefused):
        refuse_federation(query)
    try:
        list(pyoxigraph.Store().query(query))
    except (OSError, RuntimeError, ValueError, SyntaxError):
        pass
    thread.join(6)
    listener.close()
    assert reached.is_set()
