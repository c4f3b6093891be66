"""One request to the endpoint: routing, queries, updates and the Graph Store Protocol (reading),
each answered, or an :class:`~exsce_dsl.endpoint.protocol.RefusedRequest` as plain text."""

from __future__ import annotations

import concurrent.futures
import hmac
import urllib.parse
from http import HTTPStatus
from http.server import BaseHTTPRequestHandler
from typing import TYPE_CHECKING, Any

from pyoxigraph import DefaultGraph, serialize

from exsce_dsl import __version__
from exsce_dsl.endpoint.formats import DATASET_FORMATS, GRAPH_FORMATS, evaluate, format_parameter, negotiate
from exsce_dsl.endpoint.protocol import MAX_BODY, Parameters, RefusedRequest, iri, one, operation
from exsce_dsl.store.base import MAX_QUERY

if TYPE_CHECKING:
    from exsce_dsl.endpoint.server import SparqlServer


class SparqlHandler(BaseHTTPRequestHandler):
    """Answers one connection's requests for a :class:`~exsce_dsl.endpoint.server.SparqlServer`."""

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
        except RefusedRequest as exc:
            self._send(
                exc.status, exc.message.encode("utf-8") + b"\n", "text/plain; charset=utf-8", exc.headers
            )
        except Exception as exc:  # a bug of ours: answer 500, keep serving
            message = f"internal error: {type(exc).__name__}: {exc}\n"
            self._send(HTTPStatus.INTERNAL_SERVER_ERROR, message.encode(), "text/plain; charset=utf-8")

    def _route(self, method: str, path: str, params: Parameters, body: bytes) -> None:
        path = path.rstrip("/") or "/"
        if path == "/":
            if method in ("GET", "HEAD") and "query" not in params:
                self._send(HTTPStatus.OK, self.server.page, "text/html; charset=utf-8", head=method == "HEAD")
                return
            path = "/sparql"
        if path in ("/query", "/sparql", "/update"):
            if method == "GET" and path != "/update":
                self._query(one(params, "query"), params)
                return
            if method != "POST":
                allowed = "POST" if path == "/update" else "GET, POST"
                raise RefusedRequest(
                    HTTPStatus.METHOD_NOT_ALLOWED, f"{path} takes {allowed}", {"Allow": allowed}
                )
            content_type = (self.headers.get("Content-Type") or "").split(";")[0].strip().lower()
            kind, text, params = operation(path, params, body, content_type)
            if kind == "query":
                self._query(text, params)
            else:
                self._update(text, params)
            return
        if path == "/store":
            if method not in ("GET", "HEAD"):
                raise RefusedRequest(
                    HTTPStatus.METHOD_NOT_ALLOWED,
                    "the Graph Store Protocol is read-only here; write with SPARQL Update at /update",
                    {"Allow": "GET, HEAD"},
                )
            self._graph_store(params, head=method == "HEAD")
            return
        raise RefusedRequest(
            HTTPStatus.NOT_FOUND, f"{method} {path}: no such resource (try /, /query, /update)"
        )

    # -- queries

    def _query(self, text: str, params: Parameters) -> None:
        options: dict[str, Any] = {"use_default_graph_as_union": self.server.union_default_graph}
        default_graphs = params.get("default-graph-uri", [])
        named_graphs = params.get("named-graph-uri", [])
        if default_graphs:
            options["default_graph"] = [iri(g) for g in default_graphs]
            options["use_default_graph_as_union"] = False
        if named_graphs:
            options["named_graphs"] = [iri(g) for g in named_graphs]
        if len(text.encode("utf-8")) > MAX_QUERY:
            too_long = f"a query is at most {MAX_QUERY // 1024} KiB"
            raise RefusedRequest(HTTPStatus.REQUEST_ENTITY_TOO_LARGE, too_long)
        accept = format_parameter(params) or self.headers.get("Accept", "")
        server = self.server
        running = server.evaluator.submit(evaluate, server.oxigraph, text, options, accept)
        try:
            data, media = running.result(timeout=server.query_timeout)
        except concurrent.futures.TimeoutError:
            raise RefusedRequest(
                HTTPStatus.SERVICE_UNAVAILABLE,
                f"the query ran over the endpoint's time limit of {server.query_timeout:g} s",
            ) from None
        if len(data) > server.max_answer:
            raise RefusedRequest(
                HTTPStatus.SERVICE_UNAVAILABLE,
                f"the answer is {len(data) / 2**20:.1f} MiB, over the endpoint's limit of "
                f"{server.max_answer / 2**20:.3g} MiB: ask for less (LIMIT, fewer variables)",
            )
        assert data is not None
        charset = "; charset=utf-8" if media.startswith("text/") or media.endswith("json") else ""
        self._send(HTTPStatus.OK, data, media + charset)

    # -- updates

    def _update(self, text: str, params: Parameters) -> None:
        token = self.server.token
        if token is None:
            raise RefusedRequest(
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
            raise RefusedRequest(
                HTTPStatus.UNAUTHORIZED,
                "updates need the endpoint's token (Authorization: Bearer <token>); "
                f"the request had {reason}; exscec commands send EXSCE_STORE_TOKEN",
                {"WWW-Authenticate": 'Bearer realm="exscec serve"'},
            )
        if params.get("using-graph-uri") or params.get("using-named-graph-uri"):
            raise RefusedRequest(
                HTTPStatus.BAD_REQUEST, "using-graph-uri and using-named-graph-uri are not supported"
            )
        try:
            self.server.oxigraph.update(text)
        except SyntaxError as exc:
            raise RefusedRequest(HTTPStatus.BAD_REQUEST, f"SPARQL syntax error: {exc}") from None
        except (OSError, RuntimeError, ValueError) as exc:
            raise RefusedRequest(HTTPStatus.INTERNAL_SERVER_ERROR, f"the update failed: {exc}") from None
        self._send(HTTPStatus.NO_CONTENT, b"", None)

    # -- Graph Store Protocol (reading)

    def _graph_store(self, params: Parameters, *, head: bool) -> None:
        store = self.server.oxigraph
        accept = format_parameter(params) or self.headers.get("Accept", "")
        if "graph" in params or "default" in params:
            graph = iri(one(params, "graph")) if "graph" in params else None
            if graph is not None and not store.contains_named_graph(graph):
                raise RefusedRequest(HTTPStatus.NOT_FOUND, f"no graph <{graph.value}> in the store")
            media = negotiate(accept, GRAPH_FORMATS, "application/n-triples")
            quads = store.quads_for_pattern(None, None, None, graph if graph is not None else DefaultGraph())
            data = serialize([q.triple for q in quads], format=GRAPH_FORMATS[media])
        else:
            media = negotiate(accept, DATASET_FORMATS, "application/n-quads")
            data = serialize(store, format=DATASET_FORMATS[media])
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
            raise RefusedRequest(HTTPStatus.LENGTH_REQUIRED, "a POST needs a Content-Length")
        try:
            length = int(length_text)
        except ValueError:
            raise RefusedRequest(HTTPStatus.BAD_REQUEST, "Content-Length is not a number") from None
        if length > MAX_BODY:
            self.close_connection = True
            raise RefusedRequest(
                HTTPStatus.REQUEST_ENTITY_TOO_LARGE, f"the body is larger than {MAX_BODY} bytes"
            )
        return self.rfile.read(length)

    def _chunked_body(self) -> bytes:
        parts: list[bytes] = []
        total = 0
        while True:
            line = self.rfile.readline(1024)
            try:
                size = int(line.split(b";")[0].strip(), 16)
            except ValueError:
                raise RefusedRequest(HTTPStatus.BAD_REQUEST, "bad chunked encoding") from None
            if size == 0:
                while self.rfile.readline(1024) not in (b"\r\n", b"\n", b""):
                    pass
                return b"".join(parts)
            total += size
            if total > MAX_BODY:
                self.close_connection = True
                raise RefusedRequest(
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
