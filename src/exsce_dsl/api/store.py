"""The store itself: opening it, what it holds, and its housekeeping (``exscec store ...``).

Each function opens the store its URL names (None: ``$EXSCE_STORE``, else ``.exsce/store``) and
closes it again, so that it may be called from anywhere; :func:`open_store` gives the store to a
caller that does several things with it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from exsce_dsl import store as store_face

if TYPE_CHECKING:
    from prov.model import ProvDocument

    from exsce_dsl.store import Store, WriteReport


def open_store(url: str | None = None, *, read_only: bool = False) -> Store:
    """The store ``url`` names (default: ``$EXSCE_STORE``, else ``.exsce/store`` here); use it in a
    ``with`` block, which closes it.  ``read_only``: an embedded store's folder is only read."""
    return store_face.open_store(url, read_only=read_only)


def store_url(url: str | None = None) -> str:
    """The store URL ``url`` stands for (the default store's when None)."""
    return store_face.store_url(url)


@dataclass(frozen=True)
class StoreInfo:
    """``exscec store info``: where the store is, what it is, and how much it holds."""

    location: str
    kind: str
    graphs: int
    """Named graphs, not counting revisions and the segment index."""
    revisions: int
    index_graphs: int
    statements: int


def store_info(url: str | None = None) -> StoreInfo:
    """``exscec store info``: the store's kind (embedded, held by ``exscec serve``, an endpoint)
    and its sizes."""
    from exsce_dsl.store import EmbeddedStore, RemoteStore, is_index_graph, is_revision

    with open_store(url, read_only=True) as store:
        sizes = store.graph_sizes()
        if isinstance(store, EmbeddedStore):
            if store.path is None:
                kind = "embedded Oxigraph, in memory"
            elif store.path.exists():
                kind = "embedded Oxigraph"
            else:
                kind = "embedded Oxigraph, not created yet (made on the first write)"
        elif isinstance(store, RemoteStore) and store.served_by is not None:
            server = f"exscec serve (pid {store.served_by}) at {store.url}"
            kind = f"embedded Oxigraph, held by {server}, read through it"
        else:
            kind = "SPARQL 1.1 endpoint"
        revisions = sum(1 for name in sizes if is_revision(name))
        index = sum(1 for name in sizes if is_index_graph(name))
        location = store.location
    graphs = len(sizes) - revisions - index
    return StoreInfo(location, kind, graphs, revisions, index, sum(sizes.values()))


@dataclass(frozen=True)
class StoreGraphs:
    """``exscec store graphs``: statements per named graph, and how many graphs of the segment
    index were left out."""

    sizes: dict[str, int]
    hidden_index: int


def store_graphs(url: str | None = None, *, with_index: bool = False) -> StoreGraphs:
    """The store's named graphs with their sizes; the segment index's only ``with_index``."""
    from exsce_dsl.store import is_index_graph

    with open_store(url, read_only=True) as store:
        sizes = store.graph_sizes()
    if with_index:
        return StoreGraphs(sizes, 0)
    shown = {name: n for name, n in sizes.items() if not is_index_graph(name)}
    return StoreGraphs(shown, len(sizes) - len(shown))


def export_store(url: str | None = None, format: str = "trig") -> str:
    """``exscec store export``: every named graph as TriG or N-Quads (``nq``)."""
    with open_store(url, read_only=True) as store:
        return store.export(format).decode("utf-8")


@dataclass(frozen=True)
class ClearedStore:
    """``exscec store clear``: the store and how many graphs it held."""

    location: str
    removed: int


def clear_store(url: str | None = None) -> ClearedStore:
    """``exscec store clear``: remove every graph, in one transaction."""
    with open_store(url) as store:
        count = len(store.graph_names())
        store.clear()
    return ClearedStore(store.location, count)


def add_to_store(document: ProvDocument, url: str | None = None, *, replace: bool = False) -> WriteReport:
    """``exscec compile --store``: add a compiled PROV document, one graph per bundle; a changed
    scenario is replaced (keeping a revision) only with ``replace``."""
    from exsce_dsl.store import add_prov

    with open_store(url) as store:
        return add_prov(store, document, replace=replace)
