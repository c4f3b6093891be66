"""Reading a SPARQL 1.1 Protocol request: its parameters, its body (read with a cap), whether a POST
is a query or an update, and the HTTP errors a bad request is answered with.

The HTTP framing itself (Content-Length, chunked bodies, one request after another on a
connection) is uvicorn's and h11's: a request framed two ways, or with a negative or bad
Content-Length, is refused there with 400 and its connection closed."""

from __future__ import annotations

import urllib.parse
from collections.abc import AsyncIterator
from http import HTTPStatus

from pyoxigraph import NamedNode

from exsce_dsl.errors import RefusedRequest

MAX_BODY = 256 * 1024 * 1024
"""The largest request body accepted with the update token (bytes): a write through the endpoint."""
MAX_QUERY_BODY = 4 * 1024 * 1024
"""The largest body accepted without it: a query (at most MAX_QUERY), URL-encoded."""

Parameters = dict[str, list[str]]
"""A query string's or a form's parameters, each with every value given."""


async def read_body(length: str | None, stream: AsyncIterator[bytes], cap: int) -> bytes:
    """A request's body (``length``: its Content-Length header), refused with 413 past ``cap``
    bytes, before it is read when the header says so, else as soon as it passes."""
    if length is not None and length.isdigit() and int(length) > cap:
        raise _too_large(cap)
    parts: list[bytes] = []
    size = 0
    async for part in stream:
        size += len(part)
        if size > cap:
            raise _too_large(cap)
        parts.append(part)
    return b"".join(parts)


def _too_large(cap: int) -> RefusedRequest:
    return RefusedRequest(
        HTTPStatus.REQUEST_ENTITY_TOO_LARGE,
        f"the body is larger than {cap // 2**20} MiB"
        + ("" if cap >= MAX_BODY else " (larger bodies need the update token)"),
        {"Connection": "close"},
    )


def one(params: Parameters, name: str, default: str | None = None) -> str:
    """The one value of parameter ``name`` (``default`` when it is missing, if given)."""
    values = params.get(name)
    if not values:
        if default is not None:
            return default
        raise RefusedRequest(HTTPStatus.BAD_REQUEST, f"missing parameter '{name}'")
    if len(values) > 1:
        raise RefusedRequest(HTTPStatus.BAD_REQUEST, f"parameter '{name}' given {len(values)} times")
    return values[0]


def text(body: bytes) -> str:
    """A body as text (UTF-8)."""
    try:
        return body.decode("utf-8")
    except UnicodeDecodeError:
        raise RefusedRequest(HTTPStatus.BAD_REQUEST, "the body is not UTF-8") from None


def iri(value: str) -> NamedNode:
    """A parameter naming a graph, as an IRI."""
    try:
        return NamedNode(value)
    except ValueError:
        raise RefusedRequest(HTTPStatus.BAD_REQUEST, f"not an IRI: {value!r}") from None


def operation(path: str, params: Parameters, body: bytes, content_type: str) -> tuple[str, str, Parameters]:
    """``("query" | "update", text, parameters)`` of a POST to ``path`` with this body of this
    ``Content-Type`` (lower case, without its parameters)."""
    if content_type == "application/x-www-form-urlencoded":
        form = urllib.parse.parse_qs(text(body), keep_blank_values=True)
        merged = {**params, **form}
        if "update" in form and path != "/query":
            return "update", one(form, "update"), merged
        if "query" in form and path != "/update":
            return "query", one(form, "query"), merged
        wanted = "update" if path == "/update" else "query"
        raise RefusedRequest(HTTPStatus.BAD_REQUEST, f"the form has no '{wanted}' field")
    if content_type == "application/sparql-query" and path != "/update":
        return "query", text(body), params
    if content_type == "application/sparql-update" and path != "/query":
        return "update", text(body), params
    if content_type == "application/sparql-update":
        raise RefusedRequest(HTTPStatus.UNSUPPORTED_MEDIA_TYPE, "updates go to /update")
    expected = {
        "/query": "application/sparql-query",
        "/update": "application/sparql-update",
    }.get(path, "application/sparql-query or application/sparql-update")
    raise RefusedRequest(
        HTTPStatus.UNSUPPORTED_MEDIA_TYPE,
        f"Content-Type {content_type or '(none)'} is not accepted here; send {expected} "
        "or application/x-www-form-urlencoded",
    )
