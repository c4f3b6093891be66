"""The HTTP process's side of the query worker (:mod:`~exsce_dsl.endpoint.worker`): it starts
the worker, gives it one job at a time, reads its answer, and stops it when a job runs past
the time limit (SIGKILL: Oxigraph cannot stop a query), then starts another.

One worker, one job at a time: the worker is the only process that opens the store, and a
second read-only process beside it would be undefined behaviour for pyoxigraph.  A job waits
for the one before it, which runs at most the time limit.  Workers are forked by a fork server
(``multiprocessing``'s ``forkserver``, the worker's module preloaded), so a new one is ready
within milliseconds plus the store's opening, and never inherits the HTTP process's threads.

The time limit covers the whole job: running the query and sending its answer.  An answer is
read into memory up to :data:`FIRST_BUFFER` bytes (or the size limit, if smaller) before its
headers are sent, so a small answer gets a ``Content-Length`` and an answer over a small limit
a clean 503; a larger answer is streamed on, and if it then passes the limit or the time limit,
the response is cut (the connection closed before the chunked body's end, which clients report
as an error).  Memory stays bounded by the first buffer and a chunk.
"""

from __future__ import annotations

import asyncio
import json
import logging
import multiprocessing
from collections.abc import AsyncIterator, Callable
from dataclasses import dataclass
from http import HTTPStatus
from multiprocessing.connection import Connection
from typing import Any

import anyio.to_thread

from exsce_dsl.endpoint.worker import DATA, END, HEAD, READY, REFUSED, Job, Settings, run_worker
from exsce_dsl.errors import AnswerCut, RefusedRequest, StoreError

LOGGER = logging.getLogger("exsce_dsl.endpoint")
FIRST_BUFFER = 4 * 1024 * 1024
"""Bytes of an answer read before its headers are sent."""
STARTUP_SECONDS = 30.0


@dataclass
class Answer:
    """An answer's media type, its first bytes, and the rest as it comes (None: that was all)."""

    media: str
    first: bytes
    rest: AsyncIterator[bytes] | None = None


class Evaluator:
    """The worker process for one server, and the one job it runs at a time."""

    def __init__(self, settings: Settings, timeout: float, log: Callable[[str], None] | None = None) -> None:
        self.settings = settings
        self.timeout = timeout
        self.log = log
        self._context: Any = multiprocessing.get_context("forkserver")
        self._context.set_forkserver_preload(["exsce_dsl.endpoint.worker"])
        self._process: Any = None
        self._conn: Connection | None = None
        self._lifeline: Connection | None = None
        """Held, never written: the worker ends when it reads EOF (this process has gone)."""
        self._lock: asyncio.Lock | None = None
        self._session = 0
        """The running job's number; 0 when none runs."""
        self._count = 0
        self._expired = 0
        self._done = 0
        """The job the worker has answered in full (with an answer or a refusal)."""
        self._timer: asyncio.TimerHandle | None = None
        self._respawning: asyncio.Task[None] | None = None
        self._stopping = False

    # -- the worker ----------------------------------------------------------

    def start(self) -> None:
        """Start a worker and wait until it has opened the store (a StoreError if it cannot)."""
        ours, theirs = self._context.Pipe()
        lifeline, held = self._context.Pipe(duplex=False)
        process = self._context.Process(
            target=run_worker, args=(theirs, lifeline, self.settings), daemon=True
        )
        process.start()
        theirs.close()
        lifeline.close()
        try:
            if not ours.poll(STARTUP_SECONDS):
                raise StoreError(f"the query worker did not start within {STARTUP_SECONDS:g} s")
            message = ours.recv_bytes()
        except (EOFError, OSError):
            message = REFUSED + json.dumps({"message": "the query worker stopped as it started"}).encode()
        except StoreError:
            process.kill()
            raise
        if message[:1] != READY:
            process.join(5)
            raise StoreError(json.loads(message[1:])["message"])
        self._process, self._conn, self._lifeline = process, ours, held

    def kill(self) -> None:
        """Stop the worker now (SIGKILL), whatever it is doing; the next job starts another."""
        process, self._process, self._conn = self._process, None, None
        if process is not None:
            process.kill()
            process.join(5)
        if self._lifeline is not None:
            self._lifeline.close()
            self._lifeline = None

    def interrupt(self) -> None:
        """Kill the worker if a job runs: the server is stopping (no other worker is started)."""
        self._stopping = True
        if self._session:
            self.kill()

    def close(self) -> None:
        """Let an idle worker flush and release the store, or kill a busy or stuck one."""
        process, conn = self._process, self._conn
        if process is None or conn is None:
            return
        if not self._session:
            try:
                conn.send(None)
                process.join(2)
            except OSError:
                pass
        self.kill()

    # -- jobs ----------------------------------------------------------------

    async def run(self, job: Job) -> Answer:
        """Run ``job``; its answer (or, for an update, an empty one), or a RefusedRequest."""
        if self._lock is None:
            self._lock = asyncio.Lock()
        await self._lock.acquire()
        self._count += 1
        session = self._session = self._count
        streaming = False
        finished = False
        loop = asyncio.get_running_loop()
        self._timer = loop.call_later(self.timeout, self._expire, session)
        try:
            if self._process is None or not self._process.is_alive():
                self.kill()
                try:
                    await anyio.to_thread.run_sync(self.start)
                except StoreError as exc:  # the detail (paths, processes) is the operator's
                    LOGGER.warning("the query worker could not start: %s", exc.message)
                    raise RefusedRequest(
                        HTTPStatus.SERVICE_UNAVAILABLE,
                        "the store cannot be opened now (the server's log says why)",
                    ) from None
            conn = self._conn
            assert conn is not None
            try:
                await anyio.to_thread.run_sync(conn.send, job)
            except OSError:
                raise RefusedRequest(
                    HTTPStatus.SERVICE_UNAVAILABLE, "the query worker stopped; try again"
                ) from None
            tag, payload = await self._receive(conn, session, job)
            if tag == END:
                finished = True
                return Answer("", b"")
            media = payload.decode("utf-8")
            first = bytearray()
            while len(first) < min(FIRST_BUFFER, self.settings.max_answer):
                tag, payload = await self._receive(conn, session, job)
                if tag == END:
                    finished = True
                    return Answer(media, bytes(first))
                first += payload
            streaming = True
            return Answer(media, bytes(first), self._rest(conn, session, job))
        finally:
            if not streaming:
                self._finish(session, finished)

    async def _rest(self, conn: Connection, session: int, job: Job) -> AsyncIterator[bytes]:
        finished = False
        try:
            while True:
                try:
                    tag, payload = await self._receive(conn, session, job)
                except RefusedRequest as exc:
                    raise AnswerCut(exc.message) from None
                if tag == END:
                    finished = True
                    return
                yield payload
        finally:
            self._finish(session, finished)

    async def _receive(self, conn: Connection, session: int, job: Job) -> tuple[bytes, bytes]:
        """The worker's next reply (DATA, HEAD or END), or a RefusedRequest (a refusal from the
        worker, the time limit, the worker's end)."""
        message = await anyio.to_thread.run_sync(_next_message, conn)
        if message is None or self._session != session:
            if self._expired == session:
                what = "update" if job.kind == "update" else "query"
                undone = "; nothing of it was written" if job.kind == "update" else ""
                raise RefusedRequest(
                    HTTPStatus.SERVICE_UNAVAILABLE,
                    f"the {what} ran over the endpoint's time limit of {self.timeout:g} s and was "
                    f"stopped{undone}",
                )
            raise RefusedRequest(HTTPStatus.SERVICE_UNAVAILABLE, "the query worker stopped; try again")
        tag, payload = message[:1], message[1:]
        if tag in (REFUSED, END):
            self._done = session
        if tag == REFUSED:
            refusal = json.loads(payload)
            raise RefusedRequest(HTTPStatus(refusal["status"]), refusal["message"])
        assert tag in (DATA, HEAD, END)
        return tag, payload

    def _expire(self, session: int) -> None:
        if self._session == session:
            self._expired = session
            if self.log is not None:
                self.log(f"a job ran over the time limit of {self.timeout:g} s: its worker is stopped")
            self._finish(session, False)

    def _finish(self, session: int, finished: bool) -> None:
        """End job ``session`` (once): a worker left mid-job is killed and another started."""
        if self._session != session:
            return
        self._session = 0
        if self._timer is not None:
            self._timer.cancel()
            self._timer = None
        if not finished and self._done != session:
            self.kill()
        if self._process is None and not self._stopping:
            self._respawning = asyncio.get_running_loop().create_task(self._respawn())
        assert self._lock is not None
        self._lock.release()

    async def _respawn(self) -> None:
        """Start the next worker at once, so that the next job does not wait for it."""
        assert self._lock is not None
        async with self._lock:
            if self._process is None:
                try:
                    await anyio.to_thread.run_sync(self.start)
                except StoreError as exc:
                    LOGGER.warning("the query worker could not start again: %s", exc.message)


def _next_message(conn: Connection) -> bytes | None:
    """The next message on ``conn``, or None once the worker has gone."""
    try:
        return conn.recv_bytes()
    except (EOFError, OSError):
        return None


__all__ = ["FIRST_BUFFER", "Answer", "Evaluator"]
