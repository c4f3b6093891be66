"""Serving exsce to other programs: the store as a SPARQL endpoint (``exscec serve``), the store
and the checker to MCP clients (``exscec mcp``), the language to editors (``exscec lsp``).

Each call serves until Ctrl-C or SIGTERM; what the server needs is imported when it starts.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Collection, Mapping
from dataclasses import dataclass
from pathlib import Path


@dataclass(frozen=True)
class UpdateToken:
    """The bearer token SPARQL updates need, and whether it was made here (then it is shown once)."""

    text: str
    minted: bool


def update_token(given: str | None = None) -> UpdateToken:
    """``given`` (a StoreError if it is too short to be a secret), else a new token."""
    from exsce_dsl.endpoint.server import check_token, new_token

    if given:
        return UpdateToken(check_token(given), minted=False)
    return UpdateToken(new_token(), minted=True)


def is_loopback(host: str) -> bool:
    """Whether ``host`` (a name or an address) is this machine's loopback: no other machine can
    reach an endpoint bound there."""
    from exsce_dsl.endpoint.guard import is_loopback as loopback

    return loopback(host)


def serve_endpoint(
    store_url: str | None, host: str, port: int, *, token: str | None = None,
    union_default_graph: bool = False, query_timeout: float = 60.0, max_answer_mb: float = 256.0,
    allowed_hosts: Collection[str] = (), federation_hosts: Collection[str] = (),
    log: Callable[[str], None] | None = None, on_ready: Callable[[str, Path | None], None] | None = None,
    wording: Mapping[str, str] | None = None,
) -> None:  # fmt: skip
    """``exscec serve``: the embedded store ``store_url`` names as a SPARQL 1.1 endpoint on
    ``host:port`` (updates only with ``token``); a StoreError if the store is an endpoint already
    or served.  ``on_ready`` gets the server's URL and the store's folder (None: in memory).
    ``wording``: how the refusals say their remedies (the command line's, which starts it, with
    its options: ``cli.common.REMEDIES``); in words without it."""
    from exsce_dsl.endpoint.server import ServeOptions, allowed_names, servable_store, serve

    options = ServeOptions(
        host,
        port,
        token=token,
        union_default_graph=union_default_graph,
        query_timeout=query_timeout,
        max_answer=int(max_answer_mb * 2**20),
        allowed_hosts=allowed_names(allowed_hosts),
        federation_hosts=allowed_names(federation_hosts),
        log=log,
        wording=dict(wording or {}),
    )
    store_path = servable_store(store_url)

    def ready(url: str) -> None:
        if on_ready is not None:
            on_ready(url, store_path)

    serve(store_path, options, on_ready=ready)


def serve_mcp(
    store_url: str | None, *, timeout: float, max_rows: int, root: str | None = None,
    on_ready: Callable[[str], None] | None = None,
) -> None:  # fmt: skip
    """``exscec mcp``: the store (read-only) and the checker for an MCP client on stdio; the
    check tool reads files below ``root`` only (default: the current folder).  The store is
    opened once first, so that a URL that cannot work fails now; ``on_ready`` gets its URL."""
    from exsce_dsl import store as store_face
    from exsce_dsl.mcp_server import Access, serve

    with store_face.open_store(store_url):  # a store URL that cannot work fails now, not at a request
        pass
    if on_ready is not None:
        on_ready(store_face.store_url(store_url))
    folder = os.path.abspath(root or os.getcwd())
    serve(Access(store_url, timeout=timeout, max_rows=max_rows, root=folder))


def serve_lsp(address: tuple[str, int] | None = None) -> None:
    """``exscec lsp``: the language server on stdio, or on TCP at ``address`` (to debug it)."""
    from exsce_dsl.lsp import serve

    serve(address)
