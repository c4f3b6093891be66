"""Open a store from a store URL (what ``--store`` and ``EXSCE_STORE`` hold).

==========================================  =====================================================
``--store``                                  the store
==========================================  =====================================================
(nothing)                                    ``$EXSCE_STORE``, else ``.exsce/store`` in the current
                                             folder (embedded; the folder is made on the first write)
``path/to/folder``, ``file:path``            an embedded store in that folder
``memory:``                                  an embedded store in memory, empty, gone at exit
``http(s)://host/path``                      a SPARQL 1.1 endpoint; queries go to that URL
``...?update=URL&gsp=URL``                   ... with its update and Graph Store Protocol URLs
                                             (``form=1``: URL-encoded requests; ``auth=digest``)
``oxigraph+http://host:7878``                Oxigraph server (also ``exsce+`` for ``exscec serve``)
``fuseki+http://host:3030/dataset``          Apache Jena Fuseki
``graphdb+http://host:7200/repositories/r``  GraphDB
``virtuoso+http://host:8890``                Virtuoso
``neptune+https://cluster:8182``             Amazon Neptune
==========================================  =====================================================

Without ``update=``, a URL ending in ``/query`` updates at the sibling
``/update`` (Oxigraph, Fuseki, ``exscec serve``) and any other URL updates at
itself (``/sparql`` of Virtuoso, Neptune, ``exscec serve``).  Credentials:
``EXSCE_STORE_TOKEN`` (a bearer token), or ``user:password@`` in the URL.

An embedded store folder opens in one process at a time.  When it is held by
a running ``exscec serve`` (its ``<folder>.serve.json`` names a live process),
the store is reached through that server instead: queries always work;
writes work when the server allows updates and ``EXSCE_STORE_TOKEN`` holds its
token, and otherwise fail saying which server holds the store and what to do.
When another process holds it (an ingest, say), reads see a read-only view of
what that process had committed and writes fail saying who holds it.
"""

from __future__ import annotations

import os
import threading
import urllib.parse
from pathlib import Path
from typing import TYPE_CHECKING

from exsce_dsl.errors import StoreError
from exsce_dsl.store.base import Store
from exsce_dsl.store.embedded import EmbeddedStore

if TYPE_CHECKING:  # imported when a URL names an endpoint: urllib.request and http.client are slow
    from exsce_dsl.store.flavours import Preset
    from exsce_dsl.store.remote import RemoteStore

__all__ = [
    "DEFAULT_STORE",
    "STORE_ENV",
    "TOKEN_ENV",
    "StoreOpening",
    "open_store",
    "store_url",
]

DEFAULT_STORE = Path(".exsce") / "store"
"""The project's embedded store, relative to the current folder."""
STORE_ENV = "EXSCE_STORE"
TOKEN_ENV = "EXSCE_STORE_TOKEN"


def store_url(url: str | None = None) -> str:
    """The store URL in force: ``url``, else ``$EXSCE_STORE``, else ``.exsce/store``."""
    return url or os.environ.get(STORE_ENV) or str(DEFAULT_STORE)


def open_store(
    url: str | None = None, *, token: str | None = None, timeout: float = 60.0, read_only: bool = False
) -> Store:
    """The store ``url`` names (see the module's table); ``token`` defaults to ``$EXSCE_STORE_TOKEN``.

    ``read_only``: an embedded store folder is only ever read (a read-only view: nothing is
    written to its folder, which may be on a read-only mount), and a write fails saying so."""
    spec = store_url(url).strip()
    token = token or os.environ.get(TOKEN_ENV) or None
    if spec == "memory:":
        return EmbeddedStore(None)
    scheme, sep, rest = spec.partition("://")
    if sep and "+" in scheme:
        from exsce_dsl.store.flavours import FLAVOURS, flavour_named

        flavour, _, protocol = scheme.partition("+")
        named = flavour_named(flavour)
        if named is None or named.preset is None:
            presets = [f.name for f in FLAVOURS.entries().values() if f.preset is not None]
            known = ", ".join(f"{name}+http://..." for name in presets)
            raise StoreError(f"unknown kind of store '{flavour}' in {spec!r}; known: {known}")
        return _preset_store(named.preset, f"{protocol}://{rest}", token, timeout)
    if sep and scheme.lower() in ("http", "https"):
        return _endpoint_store(spec, token, timeout)
    if sep and scheme.lower() != "file":
        raise StoreError(f"cannot open a store at {spec!r}: expected a folder, memory:, or an http(s):// URL")
    if spec.startswith("file:"):
        spec = urllib.parse.unquote(urllib.parse.urlsplit(spec).path)
    return _embedded_store(Path(spec), token, timeout, read_only)


class StoreOpening:
    """:func:`open_store` on a thread of its own, started at once, for a caller that will write:
    an embedded store's folder is opened (or made) there too.  Oxigraph opens its database
    without Python's lock, so the caller's own work (importing what it needs) goes on meanwhile.
    :meth:`store` waits for the store, or raises what opening it raised."""

    def __init__(self, url: str | None = None, *, token: str | None = None, timeout: float = 60.0) -> None:
        self._opened: Store | None = None
        self._error: BaseException | None = None
        self._thread = threading.Thread(target=self._open, args=(url, token, timeout), daemon=True)
        self._thread.start()

    def _open(self, url: str | None, token: str | None, timeout: float) -> None:
        try:
            self._opened = open_store(url, token=token, timeout=timeout)
            if isinstance(self._opened, EmbeddedStore):
                self._opened.open_for_writing()
        except BaseException as exc:  # noqa: BLE001 - given to the caller by store()
            self._error = exc

    def store(self) -> Store:
        self._thread.join()
        if self._error is not None:
            raise self._error
        assert self._opened is not None
        return self._opened


def _endpoint_store(url: str, token: str | None, timeout: float) -> RemoteStore:
    from exsce_dsl.store.remote import RemoteStore

    parts = urllib.parse.urlsplit(url)
    params = urllib.parse.parse_qsl(parts.query, keep_blank_values=True)
    own = {"update", "gsp", "store", "form", "auth"}
    options = {name: value for name, value in params if name in own}
    query_url = urllib.parse.urlunsplit(
        parts._replace(query=urllib.parse.urlencode([(n, v) for n, v in params if n not in own]))
    )
    update_url = options.get("update")
    if update_url is None:
        path = parts.path.rstrip("/")
        update_url = query_url
        if path.endswith("/query"):
            update_url = urllib.parse.urlunsplit(
                parts._replace(path=path[: -len("query")] + "update", query="")
            )
    return RemoteStore(
        query_url,
        update_url=update_url,
        gsp_url=options.get("gsp") or options.get("store"),
        token=token,
        timeout=timeout,
        form=options.get("form", "0").lower() in ("1", "true", "yes"),
        digest=options.get("auth", "").lower() == "digest",
    )


def _preset_store(preset: Preset, url: str, token: str | None, timeout: float) -> RemoteStore:
    from exsce_dsl.store.remote import RemoteStore

    parts = urllib.parse.urlsplit(url)
    base = parts.path.rstrip("/")
    for suffix in preset.strip:
        if base.endswith(suffix):
            base = base[: -len(suffix)]
            break

    def at(path: str) -> str:
        return urllib.parse.urlunsplit(parts._replace(path=base + path))

    return RemoteStore(
        at(preset.query),
        update_url=at(preset.update),
        gsp_url=at(preset.gsp) if preset.gsp is not None else None,
        token=token,
        timeout=timeout,
        form=preset.form,
    )


def _embedded_store(path: Path, token: str | None, timeout: float, read_only: bool = False) -> Store:
    embedded = EmbeddedStore(path, read_only=read_only)
    if not read_only and not embedded.held_elsewhere:
        return embedded
    from exsce_dsl.store.serve_info import read_serve_info

    info = read_serve_info(path) if path.exists() else None
    if info is None or not info.is_alive():
        return embedded  # reads see a read-only view; a write says who holds the store, or why not
    from exsce_dsl.store.remote import RemoteStore

    embedded.close()
    mode = "updates allowed" if info.updates else "read-only"
    label = f"the store {path} (held by exscec serve, pid {info.pid}, {mode}, at {info.url})"
    store = RemoteStore(info.query_url, update_url=info.update_url, token=token, timeout=timeout, label=label)
    store.location = str(path)
    store.served_by = info.pid
    return store
