"""The endpoint's server, its start and its stop: :func:`serve` binds the address, starts the
query worker, writes ``<store>.serve.json``, and runs the application on uvicorn until Ctrl-C or
SIGTERM; then it stops the worker (killing a running query), removes the file and returns.

Why uvicorn and Starlette: a maintained HTTP stack (h11 parses HTTP/1.1: a request framed two
ways, a negative or bad ``Content-Length``, bytes after a framing error are refused with 400 and
the connection closed, never read as a new request), already installed with the ``mcp``
dependency, and ASGI, so that an answer streams from the worker without a thread per client.
uvicorn runs programmatically on a socket bound here (port 0: the real port is known at once),
without lifespan, websockets or its own logging; its signal handling is replaced by ours
(:class:`_Server`), which kills a running query so that the server stops within a second.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import os
import secrets
import signal
import socket
import threading
from collections.abc import Callable, Collection, Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import FrameType

import uvicorn

from exsce_dsl.endpoint.app import make_app
from exsce_dsl.endpoint.evaluator import Evaluator
from exsce_dsl.endpoint.guard import HostRule, is_loopback
from exsce_dsl.endpoint.worker import Settings
from exsce_dsl.errors import StoreError
from exsce_dsl.remedies import MAKE_A_TOKEN, SERVE_A_FOLDER
from exsce_dsl.store import QUERY_TIMEOUT, ServeInfo, serve_info_path, write_serve_info

__all__ = ["MAX_ANSWER", "MIN_TOKEN", "ServeOptions", "check_token", "new_token", "serve", "servable_store"]

MAX_ANSWER = 256 * 1024 * 1024
"""The largest answer sent (bytes), by default."""
MIN_TOKEN = 16
"""The shortest update token accepted (characters)."""
MAX_CONNECTIONS = 64
"""Connections served at once; more are answered 503 by uvicorn."""


@dataclass(frozen=True)
class ServeOptions:
    """How the endpoint serves: its address, its doors and its limits."""

    host: str = "127.0.0.1"
    port: int = 7878
    token: str | None = None
    """The bearer token updates need; None: read-only."""
    union_default_graph: bool = False
    query_timeout: float = QUERY_TIMEOUT
    max_answer: int = MAX_ANSWER
    allowed_hosts: tuple[str, ...] = ()
    """Names the ``Host`` header may give besides the bound address."""
    federation_hosts: tuple[str, ...] = ()
    """Hosts that SERVICE and LOAD may reach."""
    log: Callable[[str], None] | None = field(default=None, compare=False)
    wording: Mapping[str, str] = field(default_factory=dict, compare=False)
    """How refusals say their remedies (:meth:`~exsce_dsl.errors.Remedied.said`)."""


def new_token() -> str:
    """A new update token: 43 characters, 256 random bits."""
    return secrets.token_urlsafe(32)


def check_token(token: str) -> str:
    """``token``, or a StoreError if it is too short to be a secret."""
    if len(token) < MIN_TOKEN:
        raise StoreError(
            f"the update token is {len(token)} characters long; it must have at least {MIN_TOKEN}",
            remedy=MAKE_A_TOKEN,
        )
    return token


def servable_store(store_url: str | None) -> Path | None:
    """The folder of the embedded store ``store_url`` names (None: ``memory:``), free to serve;
    a StoreError if it is an endpoint, or served already."""
    from exsce_dsl.store import EmbeddedStore, RemoteStore, open_store

    store = open_store(store_url)
    try:
        if isinstance(store, RemoteStore):
            if store.served_by is not None:
                raise StoreError(f"{store.location}: the store is served already (pid {store.served_by})")
            raise StoreError(f"{store.location} is a SPARQL endpoint already", remedy=SERVE_A_FOLDER)
        assert isinstance(store, EmbeddedStore)
        return store.path
    finally:
        store.close()


def url_of(host: str, port: int) -> str:
    """The base URL for clients on this machine (a wildcard address shown as the loopback)."""
    shown = {"0.0.0.0": "127.0.0.1", "": "127.0.0.1", "::": "::1"}.get(host, host)
    if ":" in shown:
        shown = f"[{shown}]"
    return f"http://{shown}:{port}"


def serve(
    store_path: Path | None, options: ServeOptions, *, on_ready: Callable[[str], None] | None = None
) -> None:
    """Serve the store in ``store_path`` (None: in memory) until Ctrl-C or SIGTERM; ``on_ready``
    gets the URL once the server listens.  ``<store>.serve.json`` exists meanwhile."""
    listener = _listen(options.host, options.port)
    port = int(listener.getsockname()[1])
    url = url_of(options.host, port)
    settings = Settings(
        store_path, options.union_default_graph, options.federation_hosts, options.max_answer, options.wording
    )
    evaluator = Evaluator(settings, options.query_timeout, options.log)
    info_path = serve_info_path(store_path) if store_path is not None else None
    try:
        evaluator.start()
        if info_path is not None and store_path is not None:
            info = ServeInfo(url, os.getpid(), str(store_path.resolve()), options.token is not None)
            write_serve_info(info_path, info)
        rule = HostRule(options.host, port, options.allowed_hosts)
        app = make_app(evaluator, rule, options.token, options.log, options.wording)
        config = uvicorn.Config(
            app,
            lifespan="off",
            http="h11",
            ws="none",
            log_config=None,
            access_log=False,
            proxy_headers=False,
            server_header=False,
            date_header=True,
            limit_concurrency=MAX_CONNECTIONS,
            timeout_graceful_shutdown=1,
            timeout_keep_alive=5,
        )
        _log_to_stderr()
        if on_ready is not None:
            on_ready(url)
        server = _Server(config, evaluator)
        with contextlib.suppress(KeyboardInterrupt):
            asyncio.run(server.serve(sockets=[listener]))
    finally:
        listener.close()
        evaluator.close()
        if info_path is not None:
            with contextlib.suppress(FileNotFoundError):
                info_path.unlink()


def _log_to_stderr() -> None:
    """uvicorn's warnings and errors (a malformed request, a bug of ours) and the endpoint's own,
    one line each on stderr; an answer cut after its headers is said once, by the guard."""
    handler = logging.StreamHandler()
    handler.setFormatter(logging.Formatter("exscec serve: %(message)s"))
    handler.addFilter(lambda record: "without completing response" not in record.getMessage())
    for name in ("uvicorn.error", "exsce_dsl.endpoint"):
        logger = logging.getLogger(name)
        logger.handlers[:] = [handler]
        logger.setLevel(logging.WARNING)
        logger.propagate = False


def _listen(host: str, port: int) -> socket.socket:
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    listener = socket.socket(family, socket.SOCK_STREAM)
    try:
        listener.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        listener.bind((host, port))
        listener.listen(128)
    except OSError as exc:
        listener.close()
        raise StoreError(f"cannot listen on {host}:{port}: {exc.strerror or exc}") from None
    listener.set_inheritable(False)
    return listener


class _Server(uvicorn.Server):
    """uvicorn's server, stopped by Ctrl-C or SIGTERM with the running query killed first (and
    without uvicorn raising the signal again once stopped: the stop is a clean exit)."""

    def __init__(self, config: uvicorn.Config, evaluator: Evaluator) -> None:
        super().__init__(config)
        self.evaluator = evaluator

    @contextlib.contextmanager
    def capture_signals(self) -> Iterator[None]:
        if threading.current_thread() is not threading.main_thread():
            yield
            return
        stopping = (signal.SIGINT, signal.SIGTERM)
        previous = {sig: signal.signal(sig, self._stop) for sig in stopping}
        try:
            yield
        finally:
            for sig, handler in previous.items():
                signal.signal(sig, handler)

    def _stop(self, signum: int, frame: FrameType | None) -> None:
        if self.should_exit:
            self.force_exit = True
        self.should_exit = True
        self.evaluator.interrupt()


def allowed_names(names: Collection[str]) -> tuple[str, ...]:
    """Host names as given to ``--allowed-host`` or ``--allow-federation``, checked."""
    for name in names:
        if not name or any(c in name for c in "/ @?#"):
            raise StoreError(f"not a host name: {name!r} (give a name or an address, without a scheme)")
    return tuple(names)


__all__ += ["allowed_names", "is_loopback", "url_of"]
