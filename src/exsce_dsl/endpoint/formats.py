"""Answers' formats: which one a client asks for (its ``Accept`` header, or ``format=``), among
SPARQL results (SELECT, ASK), graphs (CONSTRUCT, DESCRIBE, one graph of the Graph Store) and
datasets (the whole store)."""

from __future__ import annotations

from http import HTTPStatus
from typing import Any

from pyoxigraph import QueryResultsFormat, RdfFormat

from exsce_dsl.endpoint.protocol import Parameters
from exsce_dsl.errors import RefusedRequest

RESULT_FORMATS = {
    "application/sparql-results+json": QueryResultsFormat.JSON,
    "application/json": QueryResultsFormat.JSON,
    "application/sparql-results+xml": QueryResultsFormat.XML,
    "application/xml": QueryResultsFormat.XML,
    "text/xml": QueryResultsFormat.XML,
    "text/csv": QueryResultsFormat.CSV,
    "text/tab-separated-values": QueryResultsFormat.TSV,
}
"""SELECT's and ASK's answers, by media type."""
GRAPH_FORMATS = {
    "text/turtle": RdfFormat.TURTLE,
    "application/x-turtle": RdfFormat.TURTLE,
    "application/n-triples": RdfFormat.N_TRIPLES,
    "text/plain": RdfFormat.N_TRIPLES,
    "application/rdf+xml": RdfFormat.RDF_XML,
}
"""CONSTRUCT's and DESCRIBE's answers, and one graph of the Graph Store, by media type."""
DATASET_FORMATS = {
    "application/n-quads": RdfFormat.N_QUADS,
    "application/trig": RdfFormat.TRIG,
}
"""The whole dataset (the Graph Store without ``graph``), by media type."""
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


def format_parameter(params: Parameters) -> str:
    """``format=`` / ``output=`` (short names or media types, as clients send them) as an Accept value."""
    wanted = [*params.get("format", []), *params.get("output", [])]
    return ", ".join(_FORMAT_NAMES.get(w.strip().lower(), w.strip()) for w in wanted if w.strip())


def negotiate(accept: str, offered: dict[str, Any], default: str) -> str:
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
    raise RefusedRequest(
        HTTPStatus.NOT_ACCEPTABLE,
        f"cannot answer as {accept}; available: {', '.join(dict.fromkeys(offered))}",
    )
