"""Issue 46: the MCP server is sandboxed to its folder.  The real ``exscec mcp`` over stdio, in a
folder of its own with an empty store: ``SERVICE`` is found by a SPARQL parser (``?o.SERVICE``
passed the keyword scan), rows are taken lazily up to ``--max-rows``, a text given to ``check``
imports nothing, and a folder outside the server's is refused."""

from __future__ import annotations

import socket
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from mcp.client.session import ClientSession

from tests.mcp_server.test_mcp_server import answer, error_text, in_session

SECRET = "hunter2_secret_name"


class Listener:
    """A TCP listener on 127.0.0.1 that counts the connections it is offered."""

    def __init__(self) -> None:
        self.socket = socket.socket()
        self.socket.bind(("127.0.0.1", 0))
        self.socket.listen(8)
        self.socket.settimeout(0.1)
        self.port = self.socket.getsockname()[1]
        self.connections = 0
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._accept, daemon=True)
        self._thread.start()

    def _accept(self) -> None:
        while not self._stop.is_set():
            try:
                conn, _ = self.socket.accept()
            except OSError:
                continue
            self.connections += 1
            conn.close()

    def close(self) -> None:
        self._stop.set()
        self._thread.join()
        self.socket.close()


@pytest.fixture
def listener() -> Iterator[Listener]:
    found = Listener()
    yield found
    found.close()


def test_mcp_service_after_dot_refused(tmp_path: Path, listener: Listener) -> None:
    url = f"http://127.0.0.1:{listener.port}/"
    queries = [
        f"SELECT * WHERE {{ ?s ?p ?o.SERVICE <{url}> {{ ?a ?b ?c }} }}",
        f"SELECT * WHERE {{ ?s ?p ?o .SERVICE SILENT <{url}> {{ ?a ?b ?c }} }}",
        f"PREFIX h: <{url}> SELECT * WHERE {{ ?s ?p ?o.SERVICE h: {{ ?a ?b ?c }} }}",
        f"SELECT * WHERE {{ BIND(<{url}> AS ?x) ?s ?p ?o.SERVICE ?x {{ ?a ?b ?c }} }}",
        f"ASK {{ ?s ?p ?o.SERVICE <{url}> {{ ?a ?b ?c }} }}",
    ]

    async def work(session: ClientSession) -> list[str]:
        return [error_text(await session.call_tool("sparql", {"query": q})) for q in queries]

    refused = in_session(tmp_path, work)
    for query, message in zip(queries, refused, strict=True):
        assert "SERVICE" in message and "is refused" in message, (query, message)
    time.sleep(0.3)
    assert listener.connections == 0


def test_mcp_rows_taken_lazily(tmp_path: Path) -> None:
    # 40^5 = 10^8 solutions: taking them all (as the tool did to show 1,000) runs far past the limit
    values = " ".join(str(i) for i in range(40))
    blocks = " ".join(f"VALUES ?v{k} {{ {values} }}" for k in range(5))
    query = f"SELECT * WHERE {{ {blocks} }}"

    async def work(session: ClientSession) -> tuple[Any, float]:
        start = time.monotonic()
        found = answer(await session.call_tool("sparql", {"query": query}))
        return found, time.monotonic() - start

    found, took = in_session(tmp_path, work, "--max-rows", "5", "--timeout", "20")
    assert len(found["results"]["bindings"]) == 5
    assert found["truncated"] == {"shown": 5, "more": True}
    assert took < 10

    def few(session: ClientSession) -> Any:
        return session.call_tool("sparql", {"query": "SELECT * WHERE { VALUES ?v { 1 2 3 } }"})

    whole = answer(in_session(tmp_path, few, "--max-rows", "3"))
    assert len(whole["results"]["bindings"]) == 3 and "truncated" not in whole  # 3 rows: none cut


def test_mcp_query_form_read_by_the_parser(tmp_path: Path) -> None:
    tricky = [
        "PREFIX select: <urn:x#> CONSTRUCT { ?s ?p ?o } WHERE { ?s ?p ?o }",
        "DESCRIBE <urn:select>",
        "BASE <urn:select> CONSTRUCT WHERE { ?s ?p ?o }",
    ]

    async def work(session: ClientSession) -> list[str]:
        return [error_text(await session.call_tool("sparql", {"query": q})) for q in tricky]

    for query, message in zip(tricky, in_session(tmp_path, work), strict=True):
        assert "SELECT and ASK queries only" in message, (query, message)
    assert "this is CONSTRUCT" in in_session(tmp_path, work)[0]


def test_check_tool_text_imports_nothing(tmp_path: Path) -> None:
    outside = tmp_path / "other"
    outside.mkdir()
    imported = outside / "robots.exsce"
    imported.write_text(f"robot type {SECRET} {{\n  %%% broken\n}}\n", encoding="utf-8")
    folder = tmp_path / "server"
    folder.mkdir()
    (folder / "robots.exsce").write_text(f"robot type {SECRET} {{\n}}\n", encoding="utf-8")
    text = f'import "{imported}"\nimport "robots.exsce"\n'

    async def work(session: ClientSession) -> tuple[Any, Any, str, str]:
        alone = answer(await session.call_tool("check", {"text": text}))
        within = answer(await session.call_tool("check", {"text": 'import "robots.exsce"\n', "folder": "."}))
        beyond = error_text(await session.call_tool("check", {"text": text, "folder": str(outside)}))
        escaping = error_text(await session.call_tool("check", {"text": text, "folder": ".."}))
        return alone, within, beyond, escaping

    alone, within, beyond, escaping = in_session(folder, work)
    assert alone["ok"] is False
    assert [(d["line"], d["column"]) for d in alone["diagnostics"]] == [(1, 1), (2, 1)]
    for d in alone["diagnostics"]:
        assert d["message"].startswith("imports are not read for a text given to check")
    assert SECRET not in str(alone) and "%%%" not in str(alone)
    assert within["ok"] is True  # a file inside the server's folder is imported
    for message in (beyond, escaping):
        assert "is outside the server's folder" in message and SECRET not in message


def test_check_tool_reads_no_map_outside_its_folder(tmp_path: Path) -> None:
    folder, outside = tmp_path / "server", tmp_path / "other"
    folder.mkdir()
    outside.mkdir()
    (outside / "m.yaml").write_text(f"{SECRET}: [\n", encoding="utf-8")  # a YAML error, were it read
    spec = (
        "environment e {{\n"
        '  map m from package "p" path "maps/" file "{}"\n'
        "  area a {{\n    pose p1 at (0.0, 0.0) facing 0\n  }}\n}}\n"
    )

    async def work(session: ClientSession) -> list[Any]:
        return [
            answer(await session.call_tool("check", {"text": spec.format(outside / name), "folder": "."}))
            for name in ("m.yaml", "missing.yaml")
        ]

    found = in_session(folder, work)
    messages = []
    for checked, name in zip(found, ("m.yaml", "missing.yaml"), strict=True):
        (d,) = checked["diagnostics"]
        assert (d["line"], d["column"]) == (2, 3)
        messages.append(d["message"].replace(name, "NAME"))
    assert messages[0] == messages[1] and "is outside the workspace" in messages[0]
    assert SECRET not in str(found)
