"""How the server reaches the store: opened per request, off the event loop, with a time limit.

An embedded store folder opens in one process at a time, and an MCP client
keeps its server running for the whole conversation; so the server opens the
store for each request and closes it right after, leaving the folder free for
``exscec ingest`` and the other commands in between.  The store is chosen as
every command chooses it (:func:`exsce_dsl.store.open.open_store`: ``--store``,
``$EXSCE_STORE``, else ``.exsce/store`` of the folder the server started in).

Work runs in worker threads (two at a time, as ``exscec serve`` evaluates
queries) and is given up after the time limit: the client gets an error, the
thread finishes in the background (Oxigraph cannot stop a query), and the
server does not wait for it when the client leaves.  While such threads keep
:data:`MAX_WORKING` threads busy, new requests are refused rather than queued.
"""

from __future__ import annotations

import contextlib
import threading
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from typing import TypeVar

import anyio
import anyio.to_thread

from exsce_dsl.errors import TimeLimitError
from exsce_dsl.remedies import LONGER_TIME_LIMIT
from exsce_dsl.store import QUERY_TIMEOUT, Store

__all__ = ["DEFAULT_MAX_ROWS", "Access"]

T = TypeVar("T")

DEFAULT_MAX_ROWS = 1000
"""Rows a query answer shows at most, by default (the rest are counted, not sent)."""
WORKERS = 2
"""Requests worked on at the same time."""
MAX_WORKING = 4
"""Threads at work, those given up on included, beyond which requests are refused."""


@dataclass
class Access:
    """The store URL (None: the default store), the time limit of a request in seconds, the
    most rows an answer shows, and the server's folder (None: where it started), outside which
    no specification file is read."""

    store_url: str | None = None
    timeout: float = QUERY_TIMEOUT
    max_rows: int = DEFAULT_MAX_ROWS
    root: str | None = None
    _limiter: anyio.CapacityLimiter | None = field(default=None, init=False, repr=False)
    _working: int = field(default=0, init=False, repr=False)
    _count_lock: threading.Lock = field(default_factory=threading.Lock, init=False, repr=False)

    @contextlib.contextmanager
    def store(self) -> Iterator[Store]:
        """The store, open for one request."""
        from exsce_dsl.store import open_store

        with open_store(self.store_url, timeout=self.timeout) as store:
            yield store

    async def run(self, work: Callable[[], T]) -> T:
        """``work()`` in a worker thread; a TimeLimitError if it takes longer than the time limit."""
        if self._limiter is None:  # made on the event loop that uses it
            self._limiter = anyio.CapacityLimiter(WORKERS)
        if self.working >= MAX_WORKING:
            raise TimeLimitError(
                f"the server is still working on {self.working} requests that ran over its time limit; "
                "ask again when they are done"
            )
        try:
            with anyio.fail_after(self.timeout):
                return await anyio.to_thread.run_sync(
                    self._counted, work, abandon_on_cancel=True, limiter=self._limiter
                )
        except TimeoutError:
            raise TimeLimitError(
                f"the request ran over the server's time limit of {self.timeout:g} s",
                remedy=LONGER_TIME_LIMIT,
            ) from None

    @property
    def working(self) -> int:
        """Works still running in worker threads (those given up on after the time limit among them)."""
        with self._count_lock:
            return self._working

    def _counted(self, work: Callable[[], T]) -> T:
        with self._count_lock:
            self._working += 1
        try:
            return work()
        finally:
            with self._count_lock:
                self._working -= 1
