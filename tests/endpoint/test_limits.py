"""``exscec serve`` keeps answering and keeps its memory (issue 46, items 5 and 6): a query past
its time limit is stopped (its worker process killed and another started), SIGTERM stops the
server at once, and answers (``/store``'s too) are counted while they stream."""

from __future__ import annotations

import concurrent.futures
import contextlib
import http.client
import signal
import threading
import time
import urllib.error
import urllib.parse
import urllib.request
from pathlib import Path

import psutil
import pytest
from pyoxigraph import Literal, NamedNode, Quad

from exsce_dsl.store.embedded import EmbeddedStore
from exsce_dsl.store.serve_info import serve_info_path

from tests.support.store_servers import Server, exscec_serve, start_exscec_serve, stop

GRAPH = NamedNode("http://example.org/g")
RUNAWAY = (
    "SELECT (COUNT(*) AS ?n) WHERE { GRAPH ?g { ?a ?p ?o . ?b ?q ?r . ?c ?s ?t . ?d ?u ?v . ?e ?w ?x } }"
)
"""A cross join of five patterns over a few thousand triples: it would run for days."""
HUGE = "SELECT * WHERE { GRAPH ?g { ?a ?p ?o . ?b ?q ?r } }"
"""Nine million rows: about a gigabyte as SPARQL JSON."""


@pytest.fixture(scope="module")
def store(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A store of 3,000 triples in one named graph."""
    path = tmp_path_factory.mktemp("limits") / "store"
    with EmbeddedStore(path) as created:
        created.oxigraph.extend(
            Quad(NamedNode(f"http://example.org/s{i}"), NamedNode("http://example.org/p"), Literal(i), GRAPH)
            for i in range(3000)
        )
    return path


def get(url: str, timeout: float = 30) -> tuple[int, bytes]:
    try:
        with urllib.request.urlopen(url, timeout=timeout) as answer:
            return answer.status, answer.read()
    except urllib.error.HTTPError as refused:
        return refused.code, refused.read()


def query(server: Server, text: str) -> tuple[int, bytes]:
    return get(f"{server.url}/query?{urllib.parse.urlencode({'query': text})}")


def ask_and_forget(server: Server, text: str) -> None:
    """Send a query whose answer will never come (the server is stopped meanwhile)."""
    with contextlib.suppress(OSError, http.client.HTTPException):
        query(server, text)


def test_ask_answered_within_a_second_after_two_runaway_queries(store: Path) -> None:
    with exscec_serve("--store", str(store), "--query-timeout", "1") as server:
        for _ in range(2):
            started = time.monotonic()
            status, body = query(server, RUNAWAY)
            assert status == 503 and b"time limit of 1 s and was stopped" in body
            assert time.monotonic() - started < 5
        started = time.monotonic()
        status, body = query(server, "ASK {}")
        assert status == 200 and b'"boolean":true' in body
        assert time.monotonic() - started < 1.0
        # and two runaway queries at once: the second waits for the first, then is stopped too
        with concurrent.futures.ThreadPoolExecutor(2) as pool:
            both = [pool.submit(query, server, RUNAWAY) for _ in range(2)]
            assert [f.result(timeout=30)[0] for f in both] == [503, 503]
        started = time.monotonic()
        assert query(server, "ASK {}")[0] == 200
        assert time.monotonic() - started < 1.0


def test_sigterm_stops_within_two_seconds_with_a_runaway_query(store: Path) -> None:
    server = start_exscec_serve("--store", str(store), "--query-timeout", "600")
    try:
        running = threading.Thread(target=ask_and_forget, args=(server, RUNAWAY), daemon=True)
        running.start()
        time.sleep(0.5)  # the query is running in the worker
        children = psutil.Process(server.process.pid).children(recursive=True)
        started = time.monotonic()
        server.process.send_signal(signal.SIGTERM)
        assert server.process.wait(timeout=10) == 0
        assert time.monotonic() - started < 2.0
    finally:
        stop(server.process)
    assert not serve_info_path(store).exists()
    gone, alive = psutil.wait_procs(children, timeout=2)
    assert not alive  # the worker (and the fork server) went with it
    with EmbeddedStore(store) as reopened:  # the folder is free again
        assert len(reopened.graph(GRAPH.value)) == 3000


def _peak_memory(process: psutil.Process, done: threading.Event, peaks: list[int]) -> None:
    """The largest resident size of ``process`` and its children together, until ``done``."""
    while not done.is_set():
        total = 0
        for member in [process, *process.children(recursive=True)]:
            try:
                total += member.memory_info().rss
            except psutil.NoSuchProcess:
                pass
        peaks.append(total)
        time.sleep(0.01)


def test_answer_over_limit_refused_with_bounded_memory(store: Path) -> None:
    """A gigabyte answer under a limit of 8 MiB: it starts (the first 4 MiB are sent with a 200)
    and is cut at the limit; the server's memory (HTTP process, fork server, worker) grows by far
    less than the answer."""
    with exscec_serve("--store", str(store), "--max-answer-mb", "8") as server:
        process = psutil.Process(server.process.pid)
        assert query(server, "ASK {}")[0] == 200  # the worker has started
        done, peaks = threading.Event(), [0]
        watcher = threading.Thread(target=_peak_memory, args=(process, done, peaks))
        before = sum(p.memory_info().rss for p in [process, *process.children(recursive=True)])
        watcher.start()
        try:
            url = f"{server.url}/query?{urllib.parse.urlencode({'query': HUGE})}"
            with urllib.request.urlopen(url, timeout=60) as answer:
                assert answer.status == 200
                with pytest.raises(http.client.IncompleteRead):  # cut, not ended
                    answer.read()
        finally:
            done.set()
            watcher.join()
        assert max(peaks) - before < 64 * 2**20
        status, body = query(server, "SELECT (COUNT(*) AS ?n) WHERE { GRAPH ?g { ?s ?p ?o } }")
        assert status == 200 and b"3000" in body  # and it goes on answering


def test_store_obeys_max_answer(store: Path) -> None:
    with exscec_serve("--store", str(store), "--max-answer-mb", "0.05") as server:
        status, body = get(f"{server.url}/store")
        assert status == 503 and b"over the endpoint's limit of 0.05 MiB" in body
        status, body = get(f"{server.url}/store?{urllib.parse.urlencode({'graph': GRAPH.value})}")
        assert status == 503 and b"over the endpoint's limit" in body
        status, body = query(server, "SELECT * WHERE { GRAPH ?g { ?s ?p ?o } } LIMIT 3")
        assert status == 200 and body.count(b'"s":') == 3


def test_runaway_query_does_not_outlive_a_killed_server(store: Path) -> None:
    """SIGKILL leaves the server no time to stop its worker: the worker goes with its fork server."""
    server = start_exscec_serve("--store", str(store), "--query-timeout", "600")
    try:
        running = threading.Thread(target=ask_and_forget, args=(server, RUNAWAY), daemon=True)
        running.start()
        time.sleep(0.5)
        children = psutil.Process(server.process.pid).children(recursive=True)
        assert len(children) >= 2  # the fork server and the worker
        server.process.kill()
        server.process.wait(timeout=10)
        gone, alive = psutil.wait_procs(children, timeout=3)
        assert not alive
    finally:
        stop(server.process)
    serve_info_path(store).unlink()  # a killed server leaves it (ignored: its pid is dead)
    with EmbeddedStore(store) as reopened:
        assert len(reopened.graph(GRAPH.value)) == 3000
