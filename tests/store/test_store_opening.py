"""Opening a store on a thread of its own while the caller imports (``exscec ingest``)."""

from __future__ import annotations

from pathlib import Path

import pytest

from exsce_dsl.errors import StoreError
from exsce_dsl.store.embedded import EmbeddedStore
from exsce_dsl.store.open import StoreOpening


def test_a_new_embedded_store_is_made_ready_to_write(tmp_path: Path) -> None:
    folder = tmp_path / "store"
    with StoreOpening(str(folder)).store() as store:
        assert isinstance(store, EmbeddedStore)
        assert (folder / "CURRENT").exists()  # the database is there before the first write
        assert store.quads() == []


def test_what_opening_raised_is_raised_by_store(tmp_path: Path) -> None:
    not_a_folder = tmp_path / "store"
    not_a_folder.write_text("a file")
    with pytest.raises(StoreError, match="it is a file, not a store folder"):  # as open_store says
        StoreOpening(str(not_a_folder)).store()
    with pytest.raises(StoreError, match="unknown kind of store"):
        StoreOpening("nosuch+http://localhost:1").store()
