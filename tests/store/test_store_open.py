"""Store URLs, the default project store, and a store folder held by another process."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from pyoxigraph import Literal, NamedNode, Quad

from exsce_dsl.cli.common import REMEDIES
from exsce_dsl.errors import StoreError, StoreLockedError
from exsce_dsl.store.base import GraphSet
from exsce_dsl.store.embedded import EmbeddedStore
from exsce_dsl.store.open import open_store
from exsce_dsl.store.remote import RemoteStore
from exsce_dsl.store.serve_info import serve_info_path

G = "http://example.org/g"


def one_quad() -> GraphSet:
    return GraphSet(
        {
            G: [
                Quad(
                    NamedNode("http://example.org/s"),
                    NamedNode("http://example.org/p"),
                    Literal("o"),
                    NamedNode(G),
                )
            ]
        }
    )


def test_the_default_store_is_the_project_folder_made_on_the_first_write(
    in_tmp: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.delenv("EXSCE_STORE", raising=False)
    with open_store() as store:
        assert isinstance(store, EmbeddedStore)
        assert store.location == os.path.join(".exsce", "store")
        assert store.graph_names() == set() and store.quads() == []
        assert not (in_tmp / ".exsce").exists()  # reading made nothing
        store.write(one_quad())
    assert (in_tmp / ".exsce" / "store" / "CURRENT").exists()
    with open_store(None) as store:
        assert store.graph_names() == {G}


def test_exsce_store_names_the_default(in_tmp: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("EXSCE_STORE", str(in_tmp / "elsewhere"))
    with open_store() as store:
        store.write(one_quad())
    assert (in_tmp / "elsewhere" / "CURRENT").exists()
    with open_store(f"file:{in_tmp / 'elsewhere'}") as store:
        assert store.graph_names() == {G}
    monkeypatch.setenv("EXSCE_STORE", "memory:")
    with open_store() as store:
        assert isinstance(store, EmbeddedStore) and store.path is None


@pytest.mark.parametrize(
    ("url", "query", "update", "gsp", "form"),
    [
        ("http://h:7878/query", "http://h:7878/query", "http://h:7878/update", None, False),
        ("http://h:8890/sparql", "http://h:8890/sparql", "http://h:8890/sparql", None, False),
        (
            "http://h/q?update=http://h/u&gsp=http://h/g&form=1&timeout=5",
            "http://h/q?timeout=5",
            "http://h/u",
            "http://h/g",
            True,
        ),
        (
            "oxigraph+http://h:7878",
            "http://h:7878/query",
            "http://h:7878/update",
            "http://h:7878/store",
            False,
        ),
        (
            "exsce+http://h:7878/sparql/",
            "http://h:7878/query",
            "http://h:7878/update",
            "http://h:7878/store",
            False,
        ),
        (
            "fuseki+http://h:3030/ds",
            "http://h:3030/ds/query",
            "http://h:3030/ds/update",
            "http://h:3030/ds/data",
            False,
        ),
        (
            "graphdb+http://h:7200/repositories/exsce",
            "http://h:7200/repositories/exsce",
            "http://h:7200/repositories/exsce/statements",
            "http://h:7200/repositories/exsce/rdf-graphs/service",
            False,
        ),
        (
            "virtuoso+http://h:8890/sparql",
            "http://h:8890/sparql",
            "http://h:8890/sparql",
            "http://h:8890/sparql-graph-crud",
            True,
        ),
        (
            "neptune+https://db.cluster:8182",
            "https://db.cluster:8182/sparql",
            "https://db.cluster:8182/sparql",
            "https://db.cluster:8182/sparql/gsp/",
            True,
        ),
    ],
)
def test_endpoint_urls_and_presets(url: str, query: str, update: str, gsp: str | None, form: bool) -> None:
    store = open_store(url)
    assert isinstance(store, RemoteStore)
    assert (store.url, store.update_url, store.gsp_url, store.form) == (query, update, gsp, form)


def test_credentials_and_tokens(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("EXSCE_STORE_TOKEN", raising=False)
    store = open_store("https://ann:s%40cret@h/sparql")
    assert isinstance(store, RemoteStore)
    assert store.url == "https://h/sparql" and "s@cret" not in store.location
    assert store._headers["Authorization"].startswith("Basic ")
    monkeypatch.setenv("EXSCE_STORE_TOKEN", "t0k3n")
    store = open_store("http://h/sparql")
    assert isinstance(store, RemoteStore)
    assert store._headers["Authorization"] == "Bearer t0k3n"


@pytest.mark.parametrize(
    ("url", "message"),
    [
        ("mongo+http://h/x", "unknown kind of store 'mongo'"),
        ("ftp://h/store", "expected a folder, memory:, or an http"),
    ],
)
def test_bad_store_urls(url: str, message: str) -> None:
    with pytest.raises(StoreError, match=message):
        open_store(url)


def test_a_folder_that_is_not_a_store_is_refused(tmp_path: Path) -> None:
    (tmp_path / "notes").mkdir()
    (tmp_path / "notes" / "todo.txt").write_text("x")
    with pytest.raises(StoreError, match="holds no Oxigraph store"):
        open_store(str(tmp_path / "notes"))
    (tmp_path / "file").write_text("x")
    with pytest.raises(StoreError, match="is a file"):
        open_store(str(tmp_path / "file"))


HOLD = """
import sys, time
from exsce_dsl.store.embedded import EmbeddedStore
from pyoxigraph import NamedNode, Quad
from exsce_dsl.store.base import GraphSet
store = EmbeddedStore(sys.argv[1])
store.write(GraphSet({"http://example.org/held": [Quad(NamedNode("http://example.org/s"),
    NamedNode("http://example.org/p"), NamedNode("http://example.org/o"), NamedNode("http://example.org/held"))]}))
print("holding", flush=True)
sys.stdin.read()
"""


def test_a_store_held_by_another_process_is_read_only_and_writing_is_a_clear_error(tmp_path: Path) -> None:
    path = tmp_path / "store"
    holder = subprocess.Popen(
        [sys.executable, "-c", HOLD, str(path)], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True
    )
    try:
        assert holder.stdout is not None and holder.stdout.readline().strip() == "holding"
        with open_store(str(path)) as reader:  # readers see what the holder committed
            assert reader.graph_names() == {"http://example.org/held"}
            with pytest.raises(StoreLockedError) as held:
                reader.write(one_quad())
        message = str(held.value)
        assert f"the store at {path} is in use" in message
        assert "one process at a time" in message and "through a SPARQL endpoint" in message
        assert held.value.remedied is not None  # the command line says it with its option:
        assert "point --store at a SPARQL endpoint" in held.value.remedied.said(REMEDIES)
        if sys.platform == "linux":
            assert f"pid {holder.pid}" in message
        # a serve.json left by a server that is gone does not redirect anything
        serve_info_path(path).write_text(
            json.dumps({"url": "http://127.0.0.1:9", "pid": 2**22 + 7, "store": str(path), "updates": False})
        )
        with pytest.raises(StoreLockedError), open_store(str(path)) as store:
            store.write(one_quad())
    finally:
        holder.communicate("", timeout=10)
    with open_store(str(path)) as store:  # released when the other process ends
        store.write(one_quad())


def test_one_process_cannot_open_a_folder_twice_for_writing(tmp_path: Path) -> None:
    first = EmbeddedStore(tmp_path / "store")
    first.write(one_quad())
    second = EmbeddedStore(tmp_path / "store")
    assert second.graph_names() == {G}  # a read-only view
    with pytest.raises(StoreLockedError, match="this process has it open already"):
        second.write(one_quad())
    second.close()
    first.close()
    with EmbeddedStore(tmp_path / "store") as again:
        assert again.graph_names() == {G}
