"""The endpoint as an ASGI application (Starlette): its routes, and each request turned into a
job for the query worker (:mod:`~exsce_dsl.endpoint.evaluator`) or refused as plain text.

* ``/query``, ``/sparql``, ``/update`` and ``/`` with ``query=``: the SPARQL 1.1 Protocol;
* ``/store``: the Graph Store Protocol, reading only;
* ``/``: the query page.
"""

from __future__ import annotations

import hmac
import urllib.parse
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from http import HTTPStatus
from importlib.resources import files

from starlette.applications import Starlette
from starlette.requests import Request
from starlette.responses import PlainTextResponse, Response, StreamingResponse
from starlette.routing import Route

from exsce_dsl.endpoint.evaluator import Evaluator
from exsce_dsl.endpoint.formats import format_parameter
from exsce_dsl.endpoint.guard import Guard, HostRule
from exsce_dsl.endpoint.protocol import (
    MAX_BODY,
    MAX_QUERY_BODY,
    Parameters,
    iri,
    one,
    operation,
    read_body,
)
from exsce_dsl.endpoint.worker import Job
from exsce_dsl.errors import RefusedRequest, Remedied
from exsce_dsl.remedies import READ_ONLY, SEND_THE_TOKEN
from exsce_dsl.store import MAX_QUERY

METHODS = ["GET", "HEAD", "POST", "PUT", "DELETE", "PATCH", "OPTIONS"]


@dataclass(frozen=True)
class Endpoint:
    """What the routes need: the worker, the update token (None: read-only), the page, and how
    refusals say their remedies (:meth:`~exsce_dsl.errors.Remedied.said`)."""

    evaluator: Evaluator
    token: str | None
    page: bytes
    wording: Mapping[str, str] | None = None


def make_app(
    evaluator: Evaluator,
    rule: HostRule,
    token: str | None,
    log: Callable[[str], None] | None = None,
    wording: Mapping[str, str] | None = None,
) -> Guard:
    """The application: the routes behind the doors of :class:`~exsce_dsl.endpoint.guard.Guard`."""
    page = files("exsce_dsl.endpoint").joinpath("page.html").read_text(encoding="utf-8")
    mode = "enabled, with a bearer token" if token else "read-only"
    endpoint = Endpoint(evaluator, token, page.replace("MODE", mode).encode("utf-8"), wording)

    def route(path: str, handler: Callable[[Endpoint, Request], object]) -> list[Route]:
        async def call(request: Request) -> Response:
            result = await handler(endpoint, request)  # type: ignore[misc]
            assert isinstance(result, Response)
            return result

        paths = [path] if path == "/" else [path, path + "/"]
        return [Route(p, call, methods=METHODS) for p in paths]

    routes = [
        *route("/", _home),
        *route("/query", _protocol),
        *route("/sparql", _protocol),
        *route("/update", _protocol),
        *route("/store", _graph_store),
        Route("/{rest:path}", _not_found, methods=METHODS),
    ]
    app = Starlette(
        routes=routes,
        exception_handlers={RefusedRequest: _refused, Exception: _internal_error},  # type: ignore[dict-item]
    )
    return Guard(app, rule, log, wording)


async def _home(endpoint: Endpoint, request: Request) -> Response:
    if request.method in ("GET", "HEAD") and "query" not in request.query_params:
        return Response(endpoint.page, media_type="text/html; charset=utf-8")
    return await _protocol(endpoint, request)


async def _protocol(endpoint: Endpoint, request: Request) -> Response:
    path = request.url.path.rstrip("/") or "/sparql"
    params = _parameters(request)
    if request.method == "GET" and path != "/update":
        return await _query(endpoint, request, one(params, "query"), params)
    if request.method != "POST":
        allowed = "POST" if path == "/update" else "GET, POST"
        raise RefusedRequest(HTTPStatus.METHOD_NOT_ALLOWED, f"{path} takes {allowed}", {"Allow": allowed})
    if path == "/update":
        _check_token(endpoint, request)
    cap = MAX_BODY if _has_token(endpoint, request) else MAX_QUERY_BODY
    body = await read_body(request.headers.get("content-length"), request.stream(), cap)
    content_type = request.headers.get("content-type", "").split(";")[0].strip().lower()
    kind, text, params = operation(path, params, body, content_type)
    if kind == "query":
        return await _query(endpoint, request, text, params)
    _check_token(endpoint, request)
    if params.get("using-graph-uri") or params.get("using-named-graph-uri"):
        raise RefusedRequest(
            HTTPStatus.BAD_REQUEST, "using-graph-uri and using-named-graph-uri are not supported"
        )
    await endpoint.evaluator.run(Job("update", text))
    return Response(status_code=HTTPStatus.NO_CONTENT)


async def _query(endpoint: Endpoint, request: Request, text: str, params: Parameters) -> Response:
    if len(text.encode("utf-8")) > MAX_QUERY:
        too_long = f"a query is at most {MAX_QUERY // 1024} KiB"
        raise RefusedRequest(HTTPStatus.REQUEST_ENTITY_TOO_LARGE, too_long)
    job = Job(
        "query",
        text,
        accept=format_parameter(params) or request.headers.get("accept", ""),
        default_graphs=tuple(iri(g).value for g in params.get("default-graph-uri", [])),
        named_graphs=tuple(iri(g).value for g in params.get("named-graph-uri", [])),
    )
    return await _answer(endpoint, job)


async def _graph_store(endpoint: Endpoint, request: Request) -> Response:
    if request.method not in ("GET", "HEAD"):
        raise RefusedRequest(
            HTTPStatus.METHOD_NOT_ALLOWED,
            "the Graph Store Protocol is read-only here; write with SPARQL Update at /update",
            {"Allow": "GET, HEAD"},
        )
    params = _parameters(request)
    job = Job(
        "graph",
        accept=format_parameter(params) or request.headers.get("accept", ""),
        graph=iri(one(params, "graph")).value if "graph" in params else None,
        default="default" in params and "graph" not in params,
    )
    return await _answer(endpoint, job)


async def _answer(endpoint: Endpoint, job: Job) -> Response:
    answer = await endpoint.evaluator.run(job)
    media = answer.media
    if media.endswith("json") or media.endswith("+xml"):
        media += "; charset=utf-8"
    if answer.rest is None:
        return Response(answer.first, media_type=media)
    rest = answer.rest

    async def body() -> object:
        yield answer.first
        async for chunk in rest:
            yield chunk

    return StreamingResponse(body(), media_type=media)  # type: ignore[arg-type]


async def _not_found(request: Request) -> Response:
    raise RefusedRequest(
        HTTPStatus.NOT_FOUND,
        f"{request.method} {request.url.path}: no such resource (try /, /query, /update)",
    )


def _parameters(request: Request) -> Parameters:
    return urllib.parse.parse_qs(request.url.query, keep_blank_values=True)


def _has_token(endpoint: Endpoint, request: Request) -> bool:
    token = endpoint.token
    scheme, _, credential = request.headers.get("authorization", "").partition(" ")
    return (
        token is not None
        and scheme.lower() == "bearer"
        and hmac.compare_digest(credential.strip().encode("utf-8"), token.encode("utf-8"))
    )


def _check_token(endpoint: Endpoint, request: Request) -> None:
    if endpoint.token is None:
        read_only = Remedied("this endpoint is read-only", READ_ONLY)
        raise RefusedRequest(HTTPStatus.FORBIDDEN, read_only.said(endpoint.wording))
    if not _has_token(endpoint, request):
        scheme = request.headers.get("authorization", "").partition(" ")[0]
        reason = "a wrong bearer token" if scheme.lower() == "bearer" else "no bearer token"
        lacking = Remedied(
            f"updates need the endpoint's token (Authorization: Bearer <token>); the request had {reason}",
            SEND_THE_TOKEN,
        )
        raise RefusedRequest(
            HTTPStatus.UNAUTHORIZED,
            lacking.said(endpoint.wording),
            {"WWW-Authenticate": 'Bearer realm="exscec serve"'},
        )


async def _refused(request: Request, exc: RefusedRequest) -> Response:
    return PlainTextResponse(exc.message + "\n", status_code=exc.status, headers=exc.headers)


async def _internal_error(request: Request, exc: Exception) -> Response:
    return PlainTextResponse("internal error of the endpoint (its log says more)\n", status_code=500)


__all__ = ["make_app"]
