"""Reading a SPARQL 1.1 Protocol request: its parameters, its body's text, whether a POST is a query
or an update, and the HTTP errors a bad request is answered with."""

from __future__ import annotations

import urllib.parse
from http import HTTPStatus

from pyoxigraph import NamedNode

MAX_BODY = 256 * 1024 * 1024
"""The largest request body accepted (bytes)."""

Parameters = dict[str, list[str]]
"""A query string's or a form's parameters, each with every value given."""


class RefusedRequest(Exception):
    """A request answered with ``status`` and ``message`` (plain text) and these ``headers``."""

    def __init__(self, status: HTTPStatus, message: str, headers: dict[str, str] | None = None) -> None:
        super().__init__(message)
        self.status = status
        self.message = message
        self.headers = headers or {}


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
