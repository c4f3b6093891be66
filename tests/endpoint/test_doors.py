"""``exscec serve`` opens no door it was not told to (issue 46, items 2 and 8): SERVICE and LOAD
reach no other host, the ``Host`` and ``Origin`` headers are checked, HTTP framing is uvicorn's
and h11's, and a short update token is refused.  Real servers, real sockets."""

from __future__ import annotations

import concurrent.futures
import os
import re
import socket
import subprocess
import sys
import urllib.error
import urllib.parse
import urllib.request
from collections.abc import Iterator
from pathlib import Path

import pytest

from tests.support.cli import run_exscec
from tests.support.store_servers import Server, exscec_serve

TOKEN = "a-token-long-enough-for-the-doors-tests"
SELECT_ALL = "SELECT * WHERE { ?s ?p ?o } LIMIT 1"


@pytest.fixture(scope="module")
def endpoint(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Server]:
    """A read-only server that also answers for the name ``proxy.example``."""
    folder = tmp_path_factory.mktemp("doors")
    with exscec_serve("--store", str(folder / "store"), "--allowed-host", "proxy.example") as server:
        yield server


@pytest.fixture(scope="module")
def writable(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Server]:
    folder = tmp_path_factory.mktemp("doors-writable")
    with exscec_serve("--store", str(folder / "store"), "--allow-updates", "--token", TOKEN) as server:
        yield server


@pytest.fixture
def listener() -> Iterator[socket.socket]:
    """A TCP listener on 127.0.0.1 that nothing should ever connect to."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as sock:
        sock.bind(("127.0.0.1", 0))
        sock.listen(8)
        sock.settimeout(0.5)
        yield sock


def connected(sock: socket.socket) -> bool:
    """Whether anything has connected to ``sock`` (waiting half a second)."""
    try:
        peer, _ = sock.accept()
    except TimeoutError:
        return False
    peer.close()
    return True


def http(url: str, data: bytes | None = None, headers: dict[str, str] | None = None) -> tuple[int, bytes]:
    request = urllib.request.Request(url, data=data, headers=headers or {})
    try:
        with urllib.request.urlopen(request, timeout=20) as answer:
            return answer.status, answer.read()
    except urllib.error.HTTPError as refused:
        return refused.code, refused.read()


def ask(server: Server, query: str, headers: dict[str, str] | None = None) -> tuple[int, bytes]:
    return http(f"{server.url}/query?{urllib.parse.urlencode({'query': query})}", headers=headers)


def raw(server: Server, request: bytes) -> bytes:
    """Send ``request`` as is on one connection; everything the server sends until it closes."""
    port = int(server.url.rsplit(":", 1)[1])
    with socket.create_connection(("127.0.0.1", port), timeout=5) as sock:
        sock.sendall(request)
        received = b""
        try:
            while chunk := sock.recv(65536):
                received += chunk
        except TimeoutError:
            received += b"<still open>"
    return received


# -- SERVICE and LOAD ----------------------------------------------------------------


def test_service_to_local_listener_refused(endpoint: Server, listener: socket.socket) -> None:
    target = f"http://127.0.0.1:{listener.getsockname()[1]}/sparql"
    texts = [
        f"SELECT * WHERE {{ SERVICE <{target}> {{ ?s ?p ?o }} }}",
        f"select * {{ ?s ?p ?o.service <{target}> {{ ?s ?p ?o }} }}",  # a dot, not a variable's end
        f"PREFIX remote: <{target}>\nSELECT * {{ SERVICE SILENT remote: {{ ?s ?p ?o }} }}",
        f"SELECT * {{ SERV\\u0049CE <{target}> {{ ?s ?p ?o }} }}",
    ]
    for text in texts:
        status, body = ask(endpoint, text)
        assert status == 403, (text, body)
        assert b"is refused" in body and b"--allow-federation" in body
        form = urllib.parse.urlencode({"query": text}).encode()
        posted = {"Content-Type": "application/x-www-form-urlencoded"}
        assert http(f"{endpoint.url}/sparql", form, posted)[0] == 403
    assert not connected(listener)


def test_federation_allowed_by_host_flag(tmp_path: Path, listener: socket.socket) -> None:
    target = f"http://127.0.0.1:{listener.getsockname()[1]}/sparql"
    with exscec_serve("--store", str(tmp_path / "store"), "--allow-federation", "127.0.0.1") as server:
        with concurrent.futures.ThreadPoolExecutor(1) as pool:
            asking = pool.submit(ask, server, f"SELECT * WHERE {{ SERVICE <{target}> {{ ?s ?p ?o }} }}")
            listener.settimeout(10)
            assert connected(listener)  # the door is open for the host named (and closed at once)
            status, body = asking.result(timeout=20)
        refused = ask(server, "SELECT * WHERE { SERVICE <http://localhost:9/x> { ?s ?p ?o } }")
    assert refused[0] == 403 and b"only 127.0.0.1 may be reached" in refused[1]
    assert status == 500 and body == b"the query failed in the store (the server's log says why)\n"


def test_load_refused_with_updates(writable: Server, listener: socket.socket) -> None:
    target = f"http://127.0.0.1:{listener.getsockname()[1]}/data.ttl"
    headers = {"Content-Type": "application/sparql-update", "Authorization": f"Bearer {TOKEN}"}
    for text in (f"LOAD <{target}>", f"LOAD SILENT <{target}> INTO GRAPH <http://example.org/g>"):
        status, body = http(f"{writable.url}/update", text.encode(), headers)
        assert status == 403 and b"LOAD <" in body and b"is refused" in body
    service = f"INSERT {{ ?s ?p ?o }} WHERE {{ SERVICE <{target}> {{ ?s ?p ?o }} }}"
    status, body = http(f"{writable.url}/update", service.encode(), headers)
    assert status == 403 and b"SERVICE <" in body
    assert not connected(listener)
    ok = b"INSERT DATA { <http://example.org/s> <http://example.org/p> 'download service' }"
    assert http(f"{writable.url}/update", ok, headers)[0] == 204  # the words in data are no clause


# -- who may ask ---------------------------------------------------------------------


def test_host_header_checked(endpoint: Server) -> None:
    port = endpoint.url.rsplit(":", 1)[1]
    for host in ("evil.example", f"evil.example:{port}", "127.0.0.1:1", "10.0.0.1:" + port):
        status, body = ask(endpoint, SELECT_ALL, {"Host": host})
        assert status == 421 and b"--allowed-host" in body, host
    for host in (f"127.0.0.1:{port}", f"localhost:{port}", "proxy.example", f"PROXY.example:{port}"):
        assert ask(endpoint, SELECT_ALL, {"Host": host})[0] == 200, host


def test_cross_origin_request_refused(endpoint: Server) -> None:
    port = endpoint.url.rsplit(":", 1)[1]
    for headers in (
        {"Origin": "http://127.0.0.1:1"},
        {"Origin": "http://evil.example"},
        {"Origin": "null"},
        {"Sec-Fetch-Site": "cross-site"},
        {"Sec-Fetch-Site": "same-site"},  # another port of localhost is the same site
    ):
        status, body = ask(endpoint, SELECT_ALL, headers)
        assert status == 403 and b"refused" in body, headers
        posted = {**headers, "Content-Type": "application/sparql-query"}
        assert http(f"{endpoint.url}/query", SELECT_ALL.encode(), posted)[0] == 403
    own = {"Origin": f"http://127.0.0.1:{port}", "Sec-Fetch-Site": "same-origin"}
    status, _ = http(
        f"{endpoint.url}/query", SELECT_ALL.encode(), {**own, "Content-Type": "application/sparql-query"}
    )
    assert status == 200  # the query page's own requests
    page = raw(endpoint, f"GET / HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nConnection: close\r\n\r\n".encode())
    assert b"access-control-allow" not in page.lower()


# -- HTTP framing --------------------------------------------------------------------


def test_negative_content_length_refused(endpoint: Server) -> None:
    port = endpoint.url.rsplit(":", 1)[1]
    get = f"GET /query?query=ASK%7B%7D HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n\r\n".encode()
    received = raw(
        endpoint,
        f"POST /query HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nContent-Type: application/sparql-query\r\n"
        "Content-Length: -1\r\n\r\n".encode()
        + get,
    )
    assert received.startswith(b"HTTP/1.1 400 ") and received.count(b"HTTP/1.1") == 1
    assert b"<still open>" not in received and b"boolean" not in received


def test_request_smuggling_not_answered(endpoint: Server) -> None:
    port = endpoint.url.rsplit(":", 1)[1]
    host = f"Host: 127.0.0.1:{port}\r\n"
    smuggled = f"GET /query?query=ASK%7B%7D HTTP/1.1\r\n{host}\r\n".encode()
    body = b"0\r\n\r\n" + smuggled
    both = (
        f"POST /query HTTP/1.1\r\n{host}Content-Type: application/sparql-query\r\n"
        f"Content-Length: {len(body)}\r\nTransfer-Encoding: chunked\r\n\r\n".encode()
        + body
    )
    bad_chunk = (
        f"POST /query HTTP/1.1\r\n{host}Content-Type: application/sparql-query\r\n"
        "Transfer-Encoding: chunked\r\n\r\nzz\r\nASK {}\r\n0\r\n\r\n".encode()
        + smuggled
    )
    two_lengths = (
        f"POST /query HTTP/1.1\r\n{host}Content-Type: application/sparql-query\r\n"
        "Content-Length: 6\r\nContent-Length: 40\r\n\r\nASK {}".encode()
        + smuggled
    )
    for request in (both, bad_chunk, two_lengths):
        received = raw(endpoint, request)
        assert received.startswith(b"HTTP/1.1 400 "), received[:200]
        assert received.count(b"HTTP/1.1 ") == 1 and b"boolean" not in received
        assert b"<still open>" not in received  # the connection was closed


# -- the token -----------------------------------------------------------------------


def test_short_token_refused(tmp_path: Path) -> None:
    store = str(tmp_path / "store")
    refused = run_exscec(
        "serve", "--store", store, "--bind", "127.0.0.1:0", "--allow-updates", "--token", "abc"
    )
    assert refused.returncode == 2 and "Traceback" not in refused.stderr
    assert "the update token is 3 characters long; it must have at least 16" in refused.stderr
    process = subprocess.Popen(
        [
            str(Path(sys.executable).with_name("exscec")),
            "serve",
            "--store",
            store,
            "--bind",
            "127.0.0.1:0",
            "--allow-updates",
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env={k: v for k, v in os.environ.items() if k != "EXSCE_STORE_TOKEN"},
    )
    try:
        assert process.stderr is not None
        line = process.stderr.readline()
    finally:
        process.terminate()
        process.communicate(timeout=10)
    made = re.search(r"bearer token: (\S+)", line)
    assert made is not None and len(made.group(1)) >= 32, line
