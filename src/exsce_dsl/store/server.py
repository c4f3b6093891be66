"""``exscec serve``: the embedded store as a SPARQL 1.1 Protocol endpoint.

Standard library HTTP (``ThreadingHTTPServer``) over a pyoxigraph store:

* ``GET /query?query=...``, ``POST /query`` (``application/sparql-query`` or a
  form with ``query=``); ``default-graph-uri`` and ``named-graph-uri`` are
  honoured.  SELECT and ASK answer in SPARQL JSON, XML, CSV or TSV, CONSTRUCT
  and DESCRIBE in Turtle, N-Triples or RDF/XML, by the ``Accept`` header (or
  ``?format=json|xml|csv|tsv|ttl|nt``); JSON and Turtle when anything goes;
* ``POST /update`` (``application/sparql-update`` or a form with
  ``update=``): ``403`` unless the server was started with updates allowed,
  then ``401`` without ``Authorization: Bearer <token>`` (compared in
  constant time);
* ``/sparql`` takes both, like Virtuoso's and Neptune's endpoints;
* ``GET /store?graph=IRI`` (Graph Store Protocol, reading only): one graph,
  or the whole dataset as N-Quads or TriG without ``graph``;
* ``GET /``: a query page (no external resources).

Only one process may open an embedded store folder, so while the endpoint
runs it holds the store, and says so in ``<store>.serve.json`` (URL, pid,
whether updates are allowed; never the token) next to the folder.
:func:`exsce_dsl.store.open.open_store` reads that file: other exscec
commands on the same store go through the endpoint (queries always; writes
when updates are allowed and ``EXSCE_STORE_TOKEN`` holds the token) and
otherwise fail with a message naming the server and what to do.  The file
is removed when the server stops (Ctrl-C, SIGTERM).
"""

from __future__ import annotations

import concurrent.futures
import contextlib
import hmac
import json
import os
import re
import signal
import threading
import urllib.parse
from collections.abc import Callable, Iterator
from dataclasses import asdict, dataclass
from http import HTTPStatus
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from importlib.resources import files
from pathlib import Path
from types import FrameType
from typing import Any

from pyoxigraph import (
    DefaultGraph,
    NamedNode,
    QueryBoolean,
    QueryResultsFormat,
    QuerySolutions,
    QueryTriples,
    RdfFormat,
    serialize,
)

from exsce_dsl import __version__
from exsce_dsl.store.base import QUERY_TIMEOUT as QUERY_TIMEOUT
from exsce_dsl.store.base import StoreError
from exsce_dsl.store.embedded import EmbeddedStore

__all__ = ["ServeInfo", "SparqlServer", "make_server", "read_serve_info", "run_server", "serve_info_path"]

MAX_BODY = 256 * 1024 * 1024
"""The largest request body accepted (bytes)."""
MAX_QUERY = 1024 * 1024
"""The longest query text accepted (bytes)."""
MAX_ANSWER = 256 * 1024 * 1024
"""The largest answer sent (bytes), by default."""

_RESULT_FORMATS = {
    "application/sparql-results+json": QueryResultsFormat.JSON,
    "application/json": QueryResultsFormat.JSON,
    "application/sparql-results+xml": QueryResultsFormat.XML,
    "application/xml": QueryResultsFormat.XML,
    "text/xml": QueryResultsFormat.XML,
    "text/csv": QueryResultsFormat.CSV,
    "text/tab-separated-values": QueryResultsFormat.TSV,
}
_GRAPH_FORMATS = {
    "text/turtle": RdfFormat.TURTLE,
    "application/x-turtle": RdfFormat.TURTLE,
    "application/n-triples": RdfFormat.N_TRIPLES,
    "text/plain": RdfFormat.N_TRIPLES,
    "application/rdf+xml": RdfFormat.RDF_XML,
}
_DATASET_FORMATS = {
    "application/n-quads": RdfFormat.N_QUADS,
    "application/trig": RdfFormat.TRIG,
}
_FORMAT_NAMES = {
    "json": "application/sparql-results+json",
    "xml": "application/sparql-results+xml",
    "csv": "text/csv",
    "tsv": "text/tab-separated-values",
    "ttl": "text/turtle",
    "turtle": "text/turtle",
    "nt": "application/n-triples",
    "ntriples": "application/n-triples",
    "rdfxml": "application/rdf+xml",
    "nq": "application/n-quads",
    "trig": "application/trig",
}
_UPDATE_START = re.compile(
    r"^\s*(?:(?:PREFIX\s+\S*\s*<[^>]*>|BASE\s*<[^>]*>|#[^\n]*)\s*)*"
    r"(INSERT|DELETE|LOAD|CLEAR|DROP|CREATE|ADD|MOVE|COPY|WITH)\b",
    re.IGNORECASE,
)


# -- serve.json ------------------------------------------------------------------


@dataclass(frozen=True)
class ServeInfo:
    """What ``<store>.serve.json`` says about a running ``exscec serve``."""

    url: str
    """The base URL, for clients on this machine (``http://127.0.0.1:7878``)."""
    pid: int
    store: str
    updates: bool

    @property
    def query_url(self) -> str:
        return f"{self.url}/query"

    @property
    def update_url(self) -> str:
        return f"{self.url}/update"

    def is_alive(self) -> bool:
        """True while the process that wrote the file runs."""
        try:
            os.kill(self.pid, 0)
        except ProcessLookupError:
            return False
        except PermissionError:  # someone else's process: alive
            return True
        except OSError:
            return False
        return True


def serve_info_path(store_path: Path) -> Path:
    """``<store folder>.serve.json``, beside the folder (``.exsce/store.serve.json``)."""
    return store_path.with_name(store_path.name + ".serve.json")


def read_serve_info(store_path: Path) -> ServeInfo | None:
    """The running server's record for this store folder, or None (no file, unreadable)."""
    try:
        data = json.loads(serve_info_path(store_path).read_text(encoding="utf-8"))
        return ServeInfo(str(data["url"]), int(data["pid"]), str(data["store"]), bool(data["updates"]))
    except (OSError, ValueError, KeyError, TypeError):
        return None


def _write_serve_info(path: Path, info: ServeInfo) -> None:
    temporary = path.with_name(path.name + f".{os.getpid()}.tmp")
    temporary.write_text(json.dumps(asdict(info), indent=2) + "\n", encoding="utf-8")
    os.replace(temporary, path)


# -- the server ------------------------------------------------------------------


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
        page = files("exsce_dsl.store").joinpath("server_page.html").read_text(encoding="utf-8")
        mode = "enabled, with a bearer token" if token else "read-only"
        self.page = page.replace("MODE", mode).encode("utf-8")
        try:
            super().__init__(address, _Handler)
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
        _write_serve_info(info_path, info)
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


# -- requests --------------------------------------------------------------------


class _HttpError(Exception):
    def __init__(self, status: HTTPStatus, message: str, headers: dict[str, str] | None = None) -> None:
        super().__init__(message)
        self.status = status
        self.message = message
        self.headers = headers or {}


class _Handler(BaseHTTPRequestHandler):
    server: SparqlServer
    protocol_version = "HTTP/1.1"
    server_version = f"exscec-serve/{__version__}"

    # -- dispatch

    def do_GET(self) -> None:
        self._handle("GET")

    def do_POST(self) -> None:
        self._handle("POST")

    def do_HEAD(self) -> None:
        self._handle("HEAD")

    def do_PUT(self) -> None:
        self._handle("PUT")

    def do_DELETE(self) -> None:
        self._handle("DELETE")

    def _handle(self, method: str) -> None:
        try:
            split = urllib.parse.urlsplit(self.path)
            params = urllib.parse.parse_qs(split.query, keep_blank_values=True)
            body = self._body() if method in ("POST", "PUT") else b""
            self._route(method, split.path, params, body)
        except _HttpError as exc:
            self._send(
                exc.status, exc.message.encode("utf-8") + b"\n", "text/plain; charset=utf-8", exc.headers
            )
        except Exception as exc:  # a bug of ours: answer 500, keep serving
            message = f"internal error: {type(exc).__name__}: {exc}\n"
            self._send(HTTPStatus.INTERNAL_SERVER_ERROR, message.encode(), "text/plain; charset=utf-8")

    def _route(self, method: str, path: str, params: dict[str, list[str]], body: bytes) -> None:
        path = path.rstrip("/") or "/"
        if path == "/":
            if method in ("GET", "HEAD") and "query" not in params:
                self._send(HTTPStatus.OK, self.server.page, "text/html; charset=utf-8", head=method == "HEAD")
                return
            path = "/sparql"
        if path in ("/query", "/sparql", "/update"):
            if method == "GET" and path != "/update":
                self._query(_one(params, "query"), params)
                return
            if method != "POST":
                allowed = "POST" if path == "/update" else "GET, POST"
                raise _HttpError(HTTPStatus.METHOD_NOT_ALLOWED, f"{path} takes {allowed}", {"Allow": allowed})
            kind, text, params = self._operation(path, params, body)
            if kind == "query":
                self._query(text, params)
            else:
                self._update(text, params)
            return
        if path == "/store":
            if method not in ("GET", "HEAD"):
                raise _HttpError(
                    HTTPStatus.METHOD_NOT_ALLOWED,
                    "the Graph Store Protocol is read-only here; write with SPARQL Update at /update",
                    {"Allow": "GET, HEAD"},
                )
            self._graph_store(params, head=method == "HEAD")
            return
        raise _HttpError(HTTPStatus.NOT_FOUND, f"{method} {path}: no such resource (try /, /query, /update)")

    def _operation(
        self, path: str, params: dict[str, list[str]], body: bytes
    ) -> tuple[str, str, dict[str, list[str]]]:
        """``("query" | "update", text, parameters)`` of a POST."""
        content_type = (self.headers.get("Content-Type") or "").split(";")[0].strip().lower()
        if content_type == "application/x-www-form-urlencoded":
            form = urllib.parse.parse_qs(_text(body), keep_blank_values=True)
            merged = {**params, **form}
            if "update" in form and path != "/query":
                return "update", _one(form, "update"), merged
            if "query" in form and path != "/update":
                return "query", _one(form, "query"), merged
            wanted = "update" if path == "/update" else "query"
            raise _HttpError(HTTPStatus.BAD_REQUEST, f"the form has no '{wanted}' field")
        if content_type == "application/sparql-query" and path != "/update":
            return "query", _text(body), params
        if content_type == "application/sparql-update" and path != "/query":
            return "update", _text(body), params
        if content_type == "application/sparql-update":
            raise _HttpError(HTTPStatus.UNSUPPORTED_MEDIA_TYPE, "updates go to /update")
        expected = {
            "/query": "application/sparql-query",
            "/update": "application/sparql-update",
        }.get(path, "application/sparql-query or application/sparql-update")
        raise _HttpError(
            HTTPStatus.UNSUPPORTED_MEDIA_TYPE,
            f"Content-Type {content_type or '(none)'} is not accepted here; send {expected} "
            "or application/x-www-form-urlencoded",
        )

    # -- queries

    def _query(self, text: str, params: dict[str, list[str]]) -> None:
        options: dict[str, Any] = {"use_default_graph_as_union": self.server.union_default_graph}
        default_graphs = params.get("default-graph-uri", [])
        named_graphs = params.get("named-graph-uri", [])
        if default_graphs:
            options["default_graph"] = [_iri(g) for g in default_graphs]
            options["use_default_graph_as_union"] = False
        if named_graphs:
            options["named_graphs"] = [_iri(g) for g in named_graphs]
        if len(text.encode("utf-8")) > MAX_QUERY:
            too_long = f"a query is at most {MAX_QUERY // 1024} KiB"
            raise _HttpError(HTTPStatus.REQUEST_ENTITY_TOO_LARGE, too_long)
        accept = _format_parameter(params) or self.headers.get("Accept", "")
        server = self.server
        running = server.evaluator.submit(_evaluate, server.oxigraph, text, options, accept)
        try:
            data, media = running.result(timeout=server.query_timeout)
        except concurrent.futures.TimeoutError:
            raise _HttpError(
                HTTPStatus.SERVICE_UNAVAILABLE,
                f"the query ran over the endpoint's time limit of {server.query_timeout:g} s",
            ) from None
        if len(data) > server.max_answer:
            raise _HttpError(
                HTTPStatus.SERVICE_UNAVAILABLE,
                f"the answer is {len(data) / 2**20:.1f} MiB, over the endpoint's limit of "
                f"{server.max_answer / 2**20:.3g} MiB: ask for less (LIMIT, fewer variables)",
            )
        assert data is not None
        charset = "; charset=utf-8" if media.startswith("text/") or media.endswith("json") else ""
        self._send(HTTPStatus.OK, data, media + charset)

    # -- updates

    def _update(self, text: str, params: dict[str, list[str]]) -> None:
        token = self.server.token
        if token is None:
            raise _HttpError(
                HTTPStatus.FORBIDDEN,
                "this endpoint is read-only (exscec serve without --allow-updates): stop the server to "
                "write to its store directly, or restart it with --allow-updates and send its bearer "
                "token (exscec commands: EXSCE_STORE_TOKEN)",
            )
        given = self.headers.get("Authorization", "")
        scheme, _, credential = given.partition(" ")
        if scheme.lower() != "bearer" or not hmac.compare_digest(
            credential.strip().encode("utf-8"), token.encode("utf-8")
        ):
            reason = "a wrong bearer token" if scheme.lower() == "bearer" else "no bearer token"
            raise _HttpError(
                HTTPStatus.UNAUTHORIZED,
                "updates need the endpoint's token (Authorization: Bearer <token>); "
                f"the request had {reason}; exscec commands send EXSCE_STORE_TOKEN",
                {"WWW-Authenticate": 'Bearer realm="exscec serve"'},
            )
        if params.get("using-graph-uri") or params.get("using-named-graph-uri"):
            raise _HttpError(
                HTTPStatus.BAD_REQUEST, "using-graph-uri and using-named-graph-uri are not supported"
            )
        try:
            self.server.oxigraph.update(text)
        except SyntaxError as exc:
            raise _HttpError(HTTPStatus.BAD_REQUEST, f"SPARQL syntax error: {exc}") from None
        except (OSError, RuntimeError, ValueError) as exc:
            raise _HttpError(HTTPStatus.INTERNAL_SERVER_ERROR, f"the update failed: {exc}") from None
        self._send(HTTPStatus.NO_CONTENT, b"", None)

    # -- Graph Store Protocol (reading)

    def _graph_store(self, params: dict[str, list[str]], *, head: bool) -> None:
        store = self.server.oxigraph
        accept = _format_parameter(params) or self.headers.get("Accept", "")
        if "graph" in params or "default" in params:
            graph = _iri(_one(params, "graph")) if "graph" in params else None
            if graph is not None and not store.contains_named_graph(graph):
                raise _HttpError(HTTPStatus.NOT_FOUND, f"no graph <{graph.value}> in the store")
            media = _negotiate(accept, _GRAPH_FORMATS, "application/n-triples")
            quads = store.quads_for_pattern(None, None, None, graph if graph is not None else DefaultGraph())
            data = serialize([q.triple for q in quads], format=_GRAPH_FORMATS[media])
        else:
            media = _negotiate(accept, _DATASET_FORMATS, "application/n-quads")
            data = serialize(store, format=_DATASET_FORMATS[media])
        assert data is not None
        self._send(
            HTTPStatus.OK, data, media + ("; charset=utf-8" if media.startswith("text/") else ""), head=head
        )

    # -- plumbing

    def _body(self) -> bytes:
        if "chunked" in (self.headers.get("Transfer-Encoding") or "").lower():
            return self._chunked_body()
        length_text = self.headers.get("Content-Length")
        if length_text is None:
            raise _HttpError(HTTPStatus.LENGTH_REQUIRED, "a POST needs a Content-Length")
        try:
            length = int(length_text)
        except ValueError:
            raise _HttpError(HTTPStatus.BAD_REQUEST, "Content-Length is not a number") from None
        if length > MAX_BODY:
            self.close_connection = True
            raise _HttpError(HTTPStatus.REQUEST_ENTITY_TOO_LARGE, f"the body is larger than {MAX_BODY} bytes")
        return self.rfile.read(length)

    def _chunked_body(self) -> bytes:
        parts: list[bytes] = []
        total = 0
        while True:
            line = self.rfile.readline(1024)
            try:
                size = int(line.split(b";")[0].strip(), 16)
            except ValueError:
                raise _HttpError(HTTPStatus.BAD_REQUEST, "bad chunked encoding") from None
            if size == 0:
                while self.rfile.readline(1024) not in (b"\r\n", b"\n", b""):
                    pass
                return b"".join(parts)
            total += size
            if total > MAX_BODY:
                self.close_connection = True
                raise _HttpError(
                    HTTPStatus.REQUEST_ENTITY_TOO_LARGE, f"the body is larger than {MAX_BODY} bytes"
                )
            parts.append(self.rfile.read(size))
            self.rfile.readline(1024)

    def _send(
        self,
        status: HTTPStatus,
        data: bytes,
        content_type: str | None,
        headers: dict[str, str] | None = None,
        *,
        head: bool = False,
    ) -> None:
        self.send_response(status)
        if content_type is not None:
            self.send_header("Content-Type", content_type)
        self.send_header("Content-Length", str(len(data)))
        self.send_header("Cache-Control", "no-store")
        self.send_header("X-Content-Type-Options", "nosniff")
        for name, value in (headers or {}).items():
            self.send_header(name, value)
        self.end_headers()
        if not head and data:
            self.wfile.write(data)

    def log_message(self, format: str, *args: Any) -> None:
        if self.server.log is not None:
            self.server.log(f"{self.address_string()} {format % args}")


def _evaluate(store: Any, text: str, options: dict[str, Any], accept: str) -> tuple[bytes, str]:
    """Run a query and serialize its answer in the format ``accept`` asks for: (bytes, media type)."""
    try:
        result = store.query(text, **options)
    except SyntaxError as exc:
        hint = " (this is an update: POST it to /update)" if _UPDATE_START.match(text) else ""
        raise _HttpError(HTTPStatus.BAD_REQUEST, f"SPARQL syntax error: {exc}{hint}") from None
    except (OSError, RuntimeError, ValueError) as exc:
        raise _HttpError(HTTPStatus.INTERNAL_SERVER_ERROR, f"the query failed: {exc}") from None
    if isinstance(result, (QuerySolutions, QueryBoolean)):
        media = _negotiate(accept, _RESULT_FORMATS, "application/sparql-results+json")
        formats: dict[str, Any] = _RESULT_FORMATS
    else:
        assert isinstance(result, QueryTriples)
        media = _negotiate(accept, _GRAPH_FORMATS, "text/turtle")
        formats = _GRAPH_FORMATS
    try:
        data = result.serialize(format=formats[media])
    except (ValueError, OSError, RuntimeError) as exc:
        raise _HttpError(HTTPStatus.INTERNAL_SERVER_ERROR, f"the query failed: {exc}") from None
    assert data is not None
    return data, media


def _one(params: dict[str, list[str]], name: str, default: str | None = None) -> str:
    values = params.get(name)
    if not values:
        if default is not None:
            return default
        raise _HttpError(HTTPStatus.BAD_REQUEST, f"missing parameter '{name}'")
    if len(values) > 1:
        raise _HttpError(HTTPStatus.BAD_REQUEST, f"parameter '{name}' given {len(values)} times")
    return values[0]


def _format_parameter(params: dict[str, list[str]]) -> str:
    """``format=`` / ``output=`` (short names or media types, as clients send them) as an Accept value."""
    wanted = [*params.get("format", []), *params.get("output", [])]
    return ", ".join(_FORMAT_NAMES.get(w.strip().lower(), w.strip()) for w in wanted if w.strip())


def _text(body: bytes) -> str:
    try:
        return body.decode("utf-8")
    except UnicodeDecodeError:
        raise _HttpError(HTTPStatus.BAD_REQUEST, "the body is not UTF-8") from None


def _iri(text: str) -> NamedNode:
    try:
        return NamedNode(text)
    except ValueError:
        raise _HttpError(HTTPStatus.BAD_REQUEST, f"not an IRI: {text!r}") from None


def _negotiate(accept: str, offered: dict[str, Any], default: str) -> str:
    """The offered media type the ``Accept`` header prefers (``default`` for ``*/*`` or none)."""
    if not accept.strip():
        return default
    ranges = []
    for position, item in enumerate(accept.split(",")):
        media, *options = (part.strip() for part in item.split(";"))
        quality = 1.0
        for option in options:
            name, _, value = option.partition("=")
            if name.strip().lower() == "q":
                try:
                    quality = float(value)
                except ValueError:
                    quality = 0.0
        if media and quality > 0:
            ranges.append((-quality, position, media.lower()))
    for _, _, media in sorted(ranges):
        if media in offered:
            return media
        if media == "*/*":
            return default
        if media.endswith("/*"):
            family = media[:-1]
            if default.startswith(family):
                return default
            for candidate in offered:
                if candidate.startswith(family):
                    return candidate
    raise _HttpError(
        HTTPStatus.NOT_ACCEPTABLE,
        f"cannot answer as {accept}; available: {', '.join(dict.fromkeys(offered))}",
    )
