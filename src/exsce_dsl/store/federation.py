"""Which other servers a SPARQL query or update would reach, read by a real SPARQL parser.

A query's ``SERVICE <iri>`` makes the evaluating store send a request to
``iri``, and an update's ``LOAD <iri>`` fetches it: both turn the store into a
client of whatever host the text names.  The endpoint (``exscec serve``) and
the MCP server refuse both unless the host is allowed by name
(:func:`refuse_federation`).

The text is parsed by rdflib's SPARQL 1.1 grammar, never scanned for
keywords (``?o.SERVICE <x>`` is a variable, a dot and a SERVICE clause).
Oxigraph accepts a little more than SPARQL 1.1 (SPARQL 1.2 triple terms, for
one); a text rdflib cannot parse is let through only if no ``SERVICE`` or
``LOAD`` can be in it at all: none in its text, its ``\\u`` escapes decoded,
in any case.
"""

from __future__ import annotations

import re
import urllib.parse
from collections.abc import Collection, Iterator
from dataclasses import dataclass
from typing import Any

from exsce_dsl.errors import FederationRefused, Unparsable

__all__ = ["Federated", "federated_targets", "refuse_federation"]


@dataclass(frozen=True)
class Federated:
    """One clause that reaches another server: ``SERVICE`` or ``LOAD``, and its IRI (None when it is
    a variable, or a prefixed name or relative IRI that cannot be resolved)."""

    clause: str
    iri: str | None

    @property
    def host(self) -> str | None:
        if self.iri is None:
            return None
        return urllib.parse.urlsplit(self.iri).hostname

    def __str__(self) -> str:
        return f"{self.clause} <{self.iri}>" if self.iri is not None else f"{self.clause} with a variable"


_ESCAPE = re.compile(r"\\u([0-9A-Fa-f]{4})|\\U([0-9A-Fa-f]{8})")
_KEYWORD = re.compile(r"service|load", re.IGNORECASE)


def federated_targets(text: str, *, update: bool = False) -> list[Federated]:
    """The SERVICE and LOAD clauses of a query (or, with ``update``, an update), in text order.

    Raises :class:`Unparsable` if rdflib's parser does not take the text."""
    from rdflib.plugins.sparql.parser import parseQuery, parseUpdate

    try:
        tree = parseUpdate(text) if update else parseQuery(text)
    except Exception as exc:  # pyparsing's ParseException, and rdflib's own on bad IRIs or prefixes
        raise Unparsable(str(exc)) from None
    prefixes: dict[str, str] = {}
    base: list[str] = []
    found: list[Federated] = []
    for node in _nodes(tree):
        name = getattr(node, "name", None)
        if name == "PrefixDecl":
            prefixes[str(node.get("prefix") or "")] = str(node["iri"])
        elif name == "Base":
            base.append(str(node["iri"]))
        elif name == "ServiceGraphPattern":
            found.append(Federated("SERVICE", _iri(node.get("term"), prefixes, base)))
        elif name == "Load":
            found.append(Federated("LOAD", _iri(node.get("iri"), prefixes, base)))
    return found


def refuse_federation(text: str, allowed_hosts: Collection[str] = (), *, update: bool = False) -> None:
    """A :class:`FederationRefused` if the query (or update) would reach a host not in
    ``allowed_hosts`` (compared without case); nothing otherwise."""
    allowed = {host.lower().strip("[]") for host in allowed_hosts}
    try:
        targets = federated_targets(text, update=update)
    except Unparsable as exc:
        if _KEYWORD.search(_decoded(text)):
            raise FederationRefused(
                "this text holds SERVICE or LOAD and does not parse as SPARQL 1.1, so which server it "
                f"would reach cannot be checked ({_first_line(str(exc))}); it is refused"
            ) from None
        return
    for target in targets:
        host = target.host
        if host is None or host.lower() not in allowed:
            hint = (
                f"only {', '.join(sorted(allowed))} may be reached"
                if allowed
                else "no other server may be reached unless a host is allowed by name"
            )
            raise FederationRefused(f"{target} is refused: {hint}")


def _nodes(tree: Any) -> Iterator[Any]:
    """Every node of rdflib's parse tree, depth first, in text order."""
    stack = [tree]
    while stack:
        node = stack.pop()
        yield node
        if isinstance(node, dict):  # CompValue is an OrderedDict of its parts
            children = list(node.values())
        elif isinstance(node, (list, tuple)) or type(node).__name__ == "ParseResults":
            children = list(node)
        else:
            continue
        stack.extend(reversed(children))


def _iri(term: Any, prefixes: dict[str, str], base: list[str]) -> str | None:
    """An absolute IRI for a SERVICE or LOAD term, or None (a variable, an unknown prefix, a relative
    IRI without a base)."""
    if getattr(term, "name", None) == "pname":
        prefix = str(term.get("prefix") or "")
        if prefix not in prefixes:
            return None
        iri = prefixes[prefix] + str(term.get("localname") or "")
    elif type(term).__name__ == "URIRef":
        iri = str(term)
    else:
        return None
    if base:
        iri = urllib.parse.urljoin(base[-1], iri)
    return iri if urllib.parse.urlsplit(iri).scheme else None


def _decoded(text: str) -> str:
    """``text`` with SPARQL's ``\\uXXXX`` and ``\\UXXXXXXXX`` escapes decoded."""

    def char(match: re.Match[str]) -> str:
        code = int(match.group(1) or match.group(2), 16)
        return chr(code) if code <= 0x10FFFF else ""

    return _ESCAPE.sub(char, text)


def _first_line(text: str) -> str:
    return text.strip().splitlines()[0] if text.strip() else "no detail"
