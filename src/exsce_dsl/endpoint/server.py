"""The endpoint's server: a threading HTTP server over one embedded store (:func:`make_server`),
served until Ctrl-C or SIGTERM with ``<store>.serve.json`` beside the store meanwhile
(:func:`run_server`)."""

from __future__ import annotations

import concurrent.futures
import contextlib
import os
import signal
import threading
from collections.abc import Callable, Iterator
from http.server import ThreadingHTTPServer
from importlib.resources import files
from types import FrameType

from exsce_dsl.endpoint.handler import SparqlHandler
from exsce_dsl.store.base import QUERY_TIMEOUT, StoreError
from exsce_dsl.store.embedded import EmbeddedStore
from exsce_dsl.store.serve_info import ServeInfo, serve_info_path, write_serve_info

__all__ = ["MAX_ANSWER", "SparqlServer", "make_server", "run_server"]

MAX_ANSWER = 256 * 1024 * 1024
"""The largest answer sent (bytes), by default."""


class SparqlServer(ThreadingHTTPServer):
    """An HTTP server answering the SPARQL 1.1 Protocol over one embedded store."""

    daemon_threads = True
    block_on_close = False

    def __init__(
        self,
        address: tuple[str, int],
        store: EmbeddedStore,
        *,
        token: str | None = None,
        union_default_graph: bool = False,
        log: Callable[[str], None] | None = None,
        query_timeout: float = QUERY_TIMEOUT,
        max_answer: int = MAX_ANSWER,
    ) -> None:
        if token is not None and not token:
            raise StoreError("the update token must not be empty")
        self.query_timeout = query_timeout
        self.max_answer = max_answer
        # queries run here, so that one over its time limit is answered 503 while it finishes in the
        # background (Oxigraph cannot stop a query); two workers keep such queries from starving the rest
        self.evaluator = concurrent.futures.ThreadPoolExecutor(max_workers=2, thread_name_prefix="sparql")
        self.store = store
        self.oxigraph = store.oxigraph
        self.token = token
        self.union_default_graph = union_default_graph
        self.log = log
        page = files("exsce_dsl.endpoint").joinpath("page.html").read_text(encoding="utf-8")
        mode = "enabled, with a bearer token" if token else "read-only"
        self.page = page.replace("MODE", mode).encode("utf-8")
        try:
            super().__init__(address, SparqlHandler)
        except OSError as exc:
            host, port = address
            raise StoreError(f"cannot listen on {host}:{port}: {exc.strerror or exc}") from None

    @property
    def updates(self) -> bool:
        return self.token is not None

    def server_close(self) -> None:
        super().server_close()
        self.evaluator.shutdown(wait=False, cancel_futures=True)

    @property
    def url(self) -> str:
        """The base URL (a wildcard address shown as 127.0.0.1)."""
        host, port = self.server_address[:2]
        shown = str(host)
        if shown in ("0.0.0.0", ""):
            shown = "127.0.0.1"
        elif shown == "::":
            shown = "::1"
        if ":" in shown:
            shown = f"[{shown}]"
        return f"http://{shown}:{port}"


def make_server(
    store: EmbeddedStore,
    host: str = "127.0.0.1",
    port: int = 7878,
    *,
    token: str | None = None,
    union_default_graph: bool = False,
    log: Callable[[str], None] | None = None,
    query_timeout: float = QUERY_TIMEOUT,
    max_answer: int = MAX_ANSWER,
) -> SparqlServer:
    """A server over ``store`` on ``host:port`` (0 picks a free port); updates need ``token``.
    A query may run ``query_timeout`` seconds and answer ``max_answer`` bytes."""
    return SparqlServer(
        (host, port),
        store,
        token=token,
        union_default_graph=union_default_graph,
        log=log,
        query_timeout=query_timeout,
        max_answer=max_answer,
    )


def run_server(server: SparqlServer, *, on_ready: Callable[[SparqlServer], None] | None = None) -> None:
    """Serve until Ctrl-C or SIGTERM; ``<store>.serve.json`` exists meanwhile, then the store is closed."""
    store_path = server.store.path
    info_path = serve_info_path(store_path) if store_path is not None else None
    if info_path is not None and store_path is not None:
        info = ServeInfo(server.url, os.getpid(), str(store_path.resolve()), server.updates)
        write_serve_info(info_path, info)
    try:
        with _stopping_on_sigterm():
            if on_ready is not None:
                on_ready(server)
            server.serve_forever(poll_interval=0.2)
    except KeyboardInterrupt:
        pass
    finally:
        server.server_close()
        if info_path is not None:
            with contextlib.suppress(FileNotFoundError):
                info_path.unlink()
        server.store.close()


class _Stop(KeyboardInterrupt):
    """SIGTERM, turned into the same clean stop as Ctrl-C."""


@contextlib.contextmanager
def _stopping_on_sigterm() -> Iterator[None]:
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def stop(signum: int, frame: FrameType | None) -> None:
        raise _Stop()

    previous = signal.signal(signal.SIGTERM, stop)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)
