"""Store flavours are records (``store/flavours.py``): told by the server's ``Server`` header or
named in a store URL, and added by plug-ins under ``exsce.store_flavours``."""

from __future__ import annotations

import warnings
from collections.abc import Iterator
from pathlib import Path

import pytest

from exsce_dsl.errors import StoreError
from exsce_dsl.store.flavours import FLAVOURS, SPARQL, VIRTUOSO, flavour_named, server_flavour
from exsce_dsl.store.open import open_store
from exsce_dsl.store.remote import RemoteStore

from tests.support.plugin_packages import installed_plugins

QUADSTORE = """\
from exsce_dsl.store.flavours import Preset, StoreFlavour

quadstore = StoreFlavour("quadstore", Preset("/q", "/u"), server="quadstore/", own_graphs=("urn:quadstore:",))
virtuoso = StoreFlavour("virtuoso")
"""


@pytest.fixture
def quadstore(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    points = "[exsce.store_flavours]\nquadstore = exsce_test_quadstore:quadstore\nvirtuoso = exsce_test_quadstore:virtuoso\n"
    yield from installed_plugins(tmp_path, monkeypatch, FLAVOURS, "exsce_test_quadstore", QUADSTORE, points)


def test_virtuoso_is_told_by_its_server_header_and_any_other_server_is_plain_sparql() -> None:
    assert server_flavour("Virtuoso/07.20.3240 (Linux) x86_64-generic-linux-glibc25  VDB") is VIRTUOSO
    assert server_flavour("oxigraph/0.4.11") is SPARQL
    assert server_flavour("") is SPARQL
    assert VIRTUOSO.skolem is not None and SPARQL.skolem is None
    assert not VIRTUOSO.whole_requests and SPARQL.whole_requests


def test_a_store_url_names_a_flavour_by_its_preset() -> None:
    store = open_store("fuseki+http://localhost:3030/ds/query")
    assert isinstance(store, RemoteStore)
    assert (store.url, store.update_url, store.gsp_url) == (
        "http://localhost:3030/ds/query",
        "http://localhost:3030/ds/update",
        "http://localhost:3030/ds/data",
    )
    assert flavour_named("Virtuoso") is VIRTUOSO
    assert flavour_named("sparql") is None  # no preset: reached by its URLs only
    with pytest.raises(StoreError, match="unknown kind of store 'sparql'"):
        open_store("sparql+http://localhost:1/")


@pytest.mark.usefixtures("quadstore")
def test_a_plugin_flavour_is_told_by_its_header_and_named_in_urls_but_replaces_no_built_in() -> None:
    with pytest.warns(UserWarning) as warned:
        told = server_flavour("QuadStore/2.1")
    assert told.name == "quadstore" and told.own_graphs == ("urn:quadstore:",)
    assert any("cannot replace exsce's own 'virtuoso'" in str(w.message) for w in warned)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # read once: no second warning
        store = open_store("quadstore+http://localhost:9999")
        assert flavour_named("virtuoso") is VIRTUOSO
    assert isinstance(store, RemoteStore)
    assert (store.url, store.update_url) == ("http://localhost:9999/q", "http://localhost:9999/u")
