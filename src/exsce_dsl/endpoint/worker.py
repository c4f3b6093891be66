"""The query worker: a process of its own that holds the store and runs, one at a time, the
queries, updates and Graph Store reads the HTTP process sends it.

Why a process: Oxigraph cannot stop a query once started, so a query past its time limit is
stopped by killing the process that runs it (:mod:`~exsce_dsl.endpoint.evaluator` then starts
another, which opens the store again).  Only one process may open an embedded store folder
for writing, and pyoxigraph says that opening one read-only while another process writes it is
undefined behaviour, so the worker is the only process that opens the store: the HTTP
process never does.

Messages go over a :func:`multiprocessing.Pipe`.  A request is a :class:`Job` (pickled by
multiprocessing: both ends are ours).  Every reply is one byte string whose first byte says
what it is (:data:`READY`, :data:`HEAD`, :data:`DATA`, :data:`END`, :data:`REFUSED`).  An
answer is serialized straight into the pipe in chunks of :data:`CHUNK` bytes, counted as it
goes: past ``max_answer`` bytes the serialization is stopped and the answer refused, so
neither process ever holds more than a chunk (and the HTTP process its first buffer).
A full pipe blocks the worker, so a slow reader slows the answer down, never the memory.
"""

from __future__ import annotations

import contextlib
import json
import os
import re
import signal
import sys
import threading
from collections.abc import Mapping
from dataclasses import dataclass, field
from http import HTTPStatus
from multiprocessing.connection import Connection
from pathlib import Path
from typing import Any

from pyoxigraph import (
    DefaultGraph,
    NamedNode,
    QueryBoolean,
    QuerySolutions,
    QueryTriples,
    serialize,
)

from exsce_dsl.endpoint.formats import DATASET_FORMATS, GRAPH_FORMATS, RESULT_FORMATS, negotiate
from exsce_dsl.errors import FederationRefused, RefusedRequest, Remedied, StoreError
from exsce_dsl.remedies import ALLOW_FEDERATION
from exsce_dsl.store import EmbeddedStore, refuse_federation

READY, HEAD, DATA, END, REFUSED = b"R", b"H", b"D", b"E", b"X"
"""The first byte of each reply: the store is open (or REFUSED: it cannot be); an answer's media
type; a chunk of it; its end (or an update done); a refusal (JSON: status and message)."""
CHUNK = 64 * 1024
"""Bytes of an answer sent at a time."""
_MAY_FEDERATE = re.compile(r"service|load|\\u|\\U", re.IGNORECASE)
"""A text without these cannot hold SERVICE or LOAD (keywords cannot be escaped but by ``\\u``):
it is not given to the slower SPARQL 1.1 parser of :func:`refuse_federation`."""
_UPDATE_START = re.compile(
    r"^\s*(?:(?:PREFIX\s+\S*\s*<[^>]*>|BASE\s*<[^>]*>|#[^\n]*)\s*)*"
    r"(INSERT|DELETE|LOAD|CLEAR|DROP|CREATE|ADD|MOVE|COPY|WITH)\b",
    re.IGNORECASE,
)


@dataclass(frozen=True)
class Settings:
    """What every job of one server shares."""

    store_path: Path | None
    """The store folder (None: a store in memory, empty, lost when the worker is replaced)."""
    union_default_graph: bool = False
    federation_hosts: tuple[str, ...] = ()
    """The hosts SERVICE and LOAD may reach (none by default)."""
    max_answer: int = 256 * 1024 * 1024
    wording: Mapping[str, str] = field(default_factory=dict)
    """How refusals say their remedies (:meth:`~exsce_dsl.errors.Remedied.said`)."""


@dataclass(frozen=True)
class Job:
    """One request: ``kind`` is ``query``, ``update`` or ``graph`` (the Graph Store: ``graph``
    names one graph, ``default`` the default graph, neither the whole dataset)."""

    kind: str
    text: str = ""
    accept: str = ""
    default_graphs: tuple[str, ...] = ()
    named_graphs: tuple[str, ...] = ()
    graph: str | None = None
    default: bool = False


class _TooLarge(Exception):
    pass


class _Chunks:
    """A binary file that sends what is written to it down the pipe, CHUNK bytes at a time,
    and stops the writer (an exception from ``write``) past ``limit`` bytes."""

    def __init__(self, conn: Connection, limit: int) -> None:
        self.conn = conn
        self.limit = limit
        self.size = 0
        self.buffer = bytearray()

    def write(self, data: bytes) -> int:
        self.size += len(data)
        if self.size > self.limit:
            raise _TooLarge()
        self.buffer += data
        if len(self.buffer) >= CHUNK:
            self.flush()
        return len(data)

    def flush(self) -> None:
        if self.buffer:
            self.conn.send_bytes(DATA + bytes(self.buffer))
            self.buffer.clear()


def run_worker(conn: Connection, lifeline: Connection, settings: Settings) -> None:
    """The worker's life: open the store, say READY, answer jobs until the pipe closes (or a
    ``None`` job), then flush and release the store."""
    _leave_stopping_to_the_server(lifeline)
    try:
        store = EmbeddedStore(settings.store_path)
        oxigraph = store.oxigraph
    except StoreError as exc:
        conn.send_bytes(REFUSED + json.dumps({"status": 503, "message": exc.message}).encode())
        return
    conn.send_bytes(READY)
    threading.Thread(target=_import_parser, daemon=True).start()
    try:
        while True:
            try:
                job = conn.recv()
            except (EOFError, OSError):
                break
            if job is None:
                break
            try:
                _answer(oxigraph, job, settings, conn)
            except RefusedRequest as exc:
                refusal = {"status": int(exc.status), "message": exc.message}
                conn.send_bytes(REFUSED + json.dumps(refusal).encode())
    finally:
        store.close()


def _answer(oxigraph: Any, job: Job, settings: Settings, conn: Connection) -> None:
    if job.kind == "graph":
        _graph_store(oxigraph, job, settings, conn)
        return
    _check_federation(job, settings)
    if job.kind == "update":
        try:
            oxigraph.update(job.text)
        except SyntaxError as exc:
            raise RefusedRequest(HTTPStatus.BAD_REQUEST, f"SPARQL syntax error: {exc}") from None
        except (OSError, RuntimeError, ValueError) as exc:
            raise _failed("update", exc) from None
        conn.send_bytes(END)
        return
    options: dict[str, Any] = {"use_default_graph_as_union": settings.union_default_graph}
    if job.default_graphs:
        options["default_graph"] = [NamedNode(g) for g in job.default_graphs]
        options["use_default_graph_as_union"] = False
    if job.named_graphs:
        options["named_graphs"] = [NamedNode(g) for g in job.named_graphs]
    try:
        result = oxigraph.query(job.text, **options)
    except SyntaxError as exc:
        hint = " (this is an update: POST it to /update)" if _UPDATE_START.match(job.text) else ""
        raise RefusedRequest(HTTPStatus.BAD_REQUEST, f"SPARQL syntax error: {exc}{hint}") from None
    except (OSError, RuntimeError, ValueError) as exc:
        raise _failed("query", exc) from None
    if isinstance(result, (QuerySolutions, QueryBoolean)):
        media = negotiate(job.accept, RESULT_FORMATS, "application/sparql-results+json")
        fmt: Any = RESULT_FORMATS[media]
    else:
        assert isinstance(result, QueryTriples)
        media = negotiate(job.accept, GRAPH_FORMATS, "text/turtle")
        fmt = GRAPH_FORMATS[media]
    _send(conn, media, settings.max_answer, lambda out: result.serialize(out, format=fmt), "query")


def _graph_store(oxigraph: Any, job: Job, settings: Settings, conn: Connection) -> None:
    if job.graph is not None or job.default:
        graph = NamedNode(job.graph) if job.graph is not None else DefaultGraph()
        if isinstance(graph, NamedNode) and not oxigraph.contains_named_graph(graph):
            raise RefusedRequest(HTTPStatus.NOT_FOUND, f"no graph <{graph.value}> in the store")
        media = negotiate(job.accept, GRAPH_FORMATS, "application/n-triples")
        triples = (quad.triple for quad in oxigraph.quads_for_pattern(None, None, None, graph))
        fmt = GRAPH_FORMATS[media]
        _send(conn, media, settings.max_answer, lambda out: serialize(triples, out, format=fmt), "read")
    else:
        media = negotiate(job.accept, DATASET_FORMATS, "application/n-quads")
        fmt = DATASET_FORMATS[media]
        _send(conn, media, settings.max_answer, lambda out: serialize(oxigraph, out, format=fmt), "read")


def _send(conn: Connection, media: str, limit: int, write: Any, what: str) -> None:
    """Send HEAD, the answer ``write(file)`` writes in chunks, then END; or REFUSED past ``limit``."""
    conn.send_bytes(HEAD + media.encode("utf-8"))
    out = _Chunks(conn, limit)
    try:
        write(out)
    except _TooLarge:
        raise too_large(out.size, limit) from None
    except (OSError, RuntimeError, ValueError) as exc:
        if isinstance(exc.__context__, _TooLarge) or isinstance(exc.__cause__, _TooLarge) or out.size > limit:
            raise too_large(out.size, limit) from None
        raise _failed(what, exc) from None
    out.flush()
    conn.send_bytes(END)


def too_large(size: int, limit: int) -> RefusedRequest:
    """The refusal of an answer over the limit, stopped at ``size`` bytes."""
    return RefusedRequest(
        HTTPStatus.SERVICE_UNAVAILABLE,
        f"the answer is larger than {size / 2**20:.1f} MiB, over the endpoint's limit of "
        f"{limit / 2**20:.3g} MiB: ask for less (LIMIT, fewer variables)",
    )


def _check_federation(job: Job, settings: Settings) -> None:
    if not _MAY_FEDERATE.search(job.text):
        return
    try:
        refuse_federation(job.text, settings.federation_hosts, update=job.kind == "update")
    except FederationRefused as exc:
        said = Remedied(exc.message, ALLOW_FEDERATION).said(settings.wording)
        raise RefusedRequest(HTTPStatus.FORBIDDEN, said) from None


def _failed(what: str, exc: BaseException) -> RefusedRequest:
    """A generic refusal for an error of the store: its detail goes to the server's log only
    (it could tell about other hosts or the machine)."""
    print(f"exscec serve: the {what} failed: {type(exc).__name__}: {exc}", file=sys.stderr, flush=True)
    return RefusedRequest(
        HTTPStatus.INTERNAL_SERVER_ERROR, f"the {what} failed in the store (the server's log says why)"
    )


def _import_parser() -> None:
    """Import the SPARQL 1.1 parser ahead of the first text that needs it (it takes ~0.5 s)."""
    with contextlib.suppress(Exception):
        import rdflib.plugins.sparql.parser  # noqa: F401


def _leave_stopping_to_the_server(lifeline: Connection) -> None:
    """Leave Ctrl-C to the HTTP process (a terminal sends SIGINT to the whole process group; the
    server then stops this process), and end this process as soon as the HTTP process is gone:
    ``lifeline``'s other end is held by the HTTP process only, so it reads EOF when that process
    dies, even by SIGKILL, and a runaway query never outlives the server.  (The fork server
    cannot do it: it lives as long as any of its children.)"""
    signal.signal(signal.SIGINT, signal.SIG_IGN)

    def watch() -> None:
        with contextlib.suppress(EOFError, OSError):
            lifeline.recv_bytes()
        os._exit(1)

    threading.Thread(target=watch, name="lifeline", daemon=True).start()


__all__ = ["CHUNK", "Job", "Settings", "run_worker", "too_large"]
