"""A store on any SPARQL 1.1 endpoint, over HTTP (standard library only).

* Queries: SPARQL 1.1 Protocol, ``POST`` URL-encoded (``query=``; a large query
  as an ``application/sparql-query`` body, see FORM_QUERY_BYTES), answers read
  as SPARQL JSON results into pyoxigraph terms.
* Updates: ``POST`` with ``application/sparql-update`` (or ``update=``).  A
  :meth:`RemoteStore.write` is *one* update request (``DROP SILENT GRAPH`` for
  each replaced graph, then one ``INSERT DATA`` with a ``GRAPH`` block per
  graph), so it is all or nothing wherever the endpoint runs a request in one
  transaction (Oxigraph, Fuseki, GraphDB, Neptune).  On a server whose flavour's
  write strategy says it commits each operation on its own (Virtuoso), the write
  goes in steps, its commit graphs last (:mod:`exsce_dsl.store.write_strategy`).
* Reading one graph: the Graph Store Protocol (``GET ?graph=``) when a GSP URL
  is known, else a ``CONSTRUCT``.
* What a kind of server does its own way is its flavour's record
  (:mod:`exsce_dsl.store.flavours`, told by the ``Server`` header): blank nodes written as
  Skolem IRIs (read back as blank nodes), answers read as Turtle where SPARQL JSON loses
  digits (Virtuoso), graphs of the server's own, left out and never dropped.

Authentication: a bearer token (``token``; ``exscec serve`` and
token-protected gateways), or a user and password (HTTP Basic, sent with
every request, or HTTP Digest).
"""

from __future__ import annotations

import base64
import itertools
import socket
import urllib.error
import urllib.parse
import urllib.request
from collections.abc import Sequence
from typing import Any

from pyoxigraph import (
    BlankNode,
    NamedNode,
    Quad,
    QueryBoolean,
    QueryResultsFormat,
    QuerySolutions,
    RdfFormat,
    parse,
    parse_query_results,
)

from exsce_dsl import __version__
from exsce_dsl.errors import StoreError
from exsce_dsl.prov.identifiers import SKOLEM_BASE
from exsce_dsl.store.base import Bindings, GraphSet, Replace, Rows, Store
from exsce_dsl.store.flavours import StoreFlavour, ask_columns, server_flavour
from exsce_dsl.store.sparql import bind, graph_node, query_form, term_text, write_update
from exsce_dsl.store.timing import none, one, timed_query
from exsce_dsl.store.write_strategy import write_in_steps

RESULTS_JSON = "application/sparql-results+json"
FORM_QUERY_BYTES = 64 * 1024
"""Queries up to this size go URL-encoded (``query=``), which every SPARQL 1.1 endpoint takes
(Virtuoso 7 never answers a query sent as an ``application/sparql-query`` body); larger ones
go as a body, since web servers cap forms (Jetty, under Fuseki, at 200 kB)."""
N_TRIPLES = "application/n-triples"
SKOLEM = SKOLEM_BASE
"""Where the IRIs that stand for blank nodes begin (RDF 1.1 Concepts, 3.5), on a server whose
flavour writes them in their place: read back as blank nodes."""


class RemoteStore(Store):
    """A SPARQL 1.1 endpoint: ``url`` answers queries, ``update_url`` (default: ``url``) updates.

    ``gsp_url`` is the Graph Store Protocol service (``.../store`` for
    Oxigraph, ``.../data`` for Fuseki), used to read whole graphs.  ``form``
    sends queries and updates URL-encoded (Virtuoso, Neptune).  A ``user``
    and ``password`` (or ``user:password@`` in the URL) go as HTTP Basic
    credentials, or Digest with ``digest`` (Virtuoso's ``/sparql-auth``).  ``label``
    names the store in error messages (default: the URL).
    """

    served_by: int | None = None
    """The pid of the ``exscec serve`` that this store reaches a project's folder through, if so."""

    def __init__(
        self,
        url: str,
        *,
        update_url: str | None = None,
        gsp_url: str | None = None,
        token: str | None = None,
        user: str | None = None,
        password: str | None = None,
        timeout: float = 60.0,
        form: bool = False,
        digest: bool = False,
        label: str | None = None,
    ) -> None:
        url, url_user, url_password = _split_credentials(url)
        self.url = url
        self.update_url = _split_credentials(update_url)[0] if update_url else url
        self.gsp_url = _split_credentials(gsp_url)[0] if gsp_url else None
        self.location = url
        self.label = label or f"the SPARQL endpoint {url}"
        self.timeout = timeout
        self.form = form
        self._headers = {"User-Agent": f"exsce/{__version__}"}
        user = user if user is not None else url_user
        password = password if password is not None else url_password
        handlers: list[urllib.request.BaseHandler] = []
        if token:
            self._headers["Authorization"] = f"Bearer {token}"
        elif user is not None and digest:
            manager = urllib.request.HTTPPasswordMgrWithDefaultRealm()
            for endpoint in (self.url, self.update_url, self.gsp_url):
                if endpoint is not None:
                    manager.add_password(None, endpoint, user, password or "")
            handlers.append(urllib.request.HTTPDigestAuthHandler(manager))
        elif user is not None:
            credentials = f"{user}:{password or ''}".encode()
            self._headers["Authorization"] = "Basic " + base64.b64encode(credentials).decode("ascii")
        self._opener = urllib.request.build_opener(*handlers)
        self._server: str | None = None
        """The endpoint's ``Server`` header, once it has answered."""
        self._headers_seen: dict[str, str] = {}
        """The headers of the endpoint's last answer."""

    # -- HTTP ----------------------------------------------------------------

    def _request(
        self,
        url: str,
        *,
        data: bytes | None = None,
        content_type: str | None = None,
        accept: str | None = None,
        method: str | None = None,
        missing_ok: bool = False,
    ) -> tuple[bytes, str]:
        """The body and Content-Type of the answer; a StoreError naming the URL on failure."""
        headers = dict(self._headers)
        if content_type:
            headers["Content-Type"] = content_type
        if accept:
            headers["Accept"] = accept
        request = urllib.request.Request(url, data=data, headers=headers, method=method)
        shown = url.split("?", 1)[0]
        try:
            with self._opener.open(request, timeout=self.timeout) as answer:
                self._server = answer.headers.get("Server", "")
                self._headers_seen = {k.lower(): v for k, v in answer.headers.items()}
                return answer.read(), answer.headers.get("Content-Type", "")
        except urllib.error.HTTPError as exc:
            if missing_ok and exc.code == 404:
                return b"", ""
            raise StoreError(self._refusal(shown, exc)) from None
        except urllib.error.URLError as exc:
            raise StoreError(f"cannot reach {self.label} ({shown}): {_reason(exc.reason)}") from None
        except TimeoutError:
            raise StoreError(f"{self.label} ({shown}) did not answer within {self.timeout:g} s") from None
        except OSError as exc:
            raise StoreError(f"cannot talk to {self.label} ({shown}): {exc}") from None

    def _refusal(self, url: str, exc: urllib.error.HTTPError) -> str:
        try:
            body = exc.read().decode("utf-8", "replace").strip()
        except OSError:
            body = ""
        detail = " ".join(body.split())[:600]
        base = urllib.parse.urlsplit(url)
        where = "" if f"{base.scheme}://{base.netloc}" in self.label else f" ({url})"
        message = f"{self.label}{where} answered {exc.code} {exc.reason}"
        if detail:
            message += f": {detail}"
        if exc.code == 401 and "Authorization" not in self._headers:
            message += (
                "; the endpoint wants credentials: set EXSCE_STORE_TOKEN to its bearer token, "
                "or put user:password@ in the store URL"
            )
        elif exc.code == 413:
            message += "; the request is larger than the endpoint accepts"
        elif advice := server_flavour(self._server or exc.headers.get("Server", "") or "").advice_for(body):
            message += f"; {advice}"
        return message

    def _post_sparql(self, url: str, kind: str, text: str, accept: str | None) -> tuple[bytes, str]:
        if self.form or (kind == "query" and len(text) <= FORM_QUERY_BYTES):
            data = urllib.parse.urlencode({kind: text}).encode("utf-8")
            return self._request(
                url, data=data, content_type="application/x-www-form-urlencoded", accept=accept
            )
        return self._request(
            url, data=text.encode("utf-8"), content_type=f"application/sparql-{kind}", accept=accept
        )

    def _query(self, query: str, bindings: Bindings | None) -> QuerySolutions | QueryBoolean:
        body, content_type = self._post_sparql(self.url, "query", bind(query, bindings), RESULTS_JSON)
        try:
            format_ = QueryResultsFormat.from_media_type(content_type.split(";")[0].strip() or RESULTS_JSON)
            return parse_query_results(body, format=format_ or QueryResultsFormat.JSON)
        except (SyntaxError, ValueError) as exc:
            start = body[:200].decode("utf-8", "replace")
            raise StoreError(
                f"{self.label} did not answer with SPARQL results ({content_type or 'no Content-Type'}): "
                f"{exc}; the answer began {start!r}"
            ) from None

    # -- Store ---------------------------------------------------------------

    @timed_query(len)
    def select(self, query: str, bindings: Bindings | None = None) -> Rows:
        answers = self.flavour().answers
        if answers is None:
            return self._solutions(query, bindings, None)[0]
        if query_form(query) != "SELECT":
            raise StoreError("not a SELECT query")
        body, _ = self._post_sparql(self.url, "query", bind(query, bindings), answers.media_type)
        rows = answers.rows(body, self.label)
        _check_whole(self.flavour(), self._headers_seen, len(rows), self.label)
        return Rows(rows.variables, tuple(tuple(_unskolemised(t) for t in row) for row in rows.rows))

    def select_first(self, query: str, most: int, bindings: Bindings | None = None) -> tuple[Rows, bool]:
        """As the base's, but SPARQL JSON's solutions are turned into rows lazily."""
        if self.flavour().answers is not None:
            return super().select_first(query, most, bindings)
        return self._solutions(query, bindings, most)

    @timed_query(lambda found: len(found[0]))
    def _solutions(self, query: str, bindings: Bindings | None, most: int | None) -> tuple[Rows, bool]:
        """The rows of a SELECT's answer (the first ``most``) and whether it has more."""
        result = self._query(query, bindings)
        variables = tuple(v.value for v in result.variables) if isinstance(result, QuerySolutions) else ()
        if not isinstance(result, QuerySolutions) or (
            len(variables) == 1 and variables[0] in ask_columns() and query_form(query) == "ASK"
        ):
            raise StoreError("not a SELECT query")
        taken = result if most is None else itertools.islice(result, most + 1)
        rows = tuple(tuple(_unskolemised(solution[v]) for v in variables) for solution in taken)
        _check_whole(self.flavour(), self._headers_seen, len(rows), self.label)
        if most is not None and len(rows) > most:
            return Rows(variables, rows[:most]), True
        return Rows(variables, rows), False

    @timed_query(one)
    def ask(self, query: str, bindings: Bindings | None = None) -> bool:
        result = self._query(query, bindings)
        columns = [v.value for v in result.variables] if isinstance(result, QuerySolutions) else []
        if isinstance(result, QuerySolutions) and len(columns) == 1 and columns[0] in ask_columns():
            return any(row[0] is not None and row[0].value not in ("0", "false") for row in result)
        if not isinstance(result, QueryBoolean):
            raise StoreError("not an ASK query")
        return bool(result)

    @timed_query(none)
    def update(self, update: str, bindings: Bindings | None = None) -> None:
        self._post_sparql(self.update_url, "update", bind(update, bindings), None)

    def write(self, graphs: GraphSet, *, replace: Replace = False) -> None:
        """One request where the server makes one request a transaction; else in steps, the
        set's commit graphs last (its flavour's write strategy says which)."""
        flavour = self.flavour()
        if flavour.writes.in_steps:
            write_in_steps(self, graphs, replace, flavour.writes, skolem=flavour.skolem)
            return
        text = write_update(graphs, replace, skolem=flavour.skolem)
        if text:
            self._post_sparql(self.update_url, "update", text, None)

    def can_post_graphs(self) -> bool:
        """Whether graphs can be written through the Graph Store Protocol (its URL is known)."""
        return self.gsp_url is not None

    def post_graph(self, name: str, n_triples: bytes) -> None:
        """Add N-Triples to the graph ``name`` (Graph Store Protocol ``POST ?graph=``)."""
        if self.gsp_url is None:
            raise StoreError(f"no Graph Store Protocol URL is known for {self.label}")
        separator = "&" if "?" in self.gsp_url else "?"
        url = f"{self.gsp_url}{separator}{urllib.parse.urlencode({'graph': graph_node(name).value})}"
        self._request(url, data=n_triples, content_type=N_TRIPLES, method="POST")

    def flavour(self) -> StoreFlavour:
        """The server's flavour, told by its ``Server`` header (an empty ASK learns it first)."""
        if self._server is None:
            self.ask("ASK {}")
        return server_flavour(self._server or "")

    def remove_graphs(self, names: Sequence[str]) -> None:
        if names:
            self.update(" ;\n".join(f"DROP SILENT GRAPH {graph_node(name)}" for name in names))

    def graph_names(self) -> set[str]:
        rows = self.select("SELECT DISTINCT ?g WHERE { GRAPH ?g { ?s ?p ?o } }")
        return {g.value for (g,) in rows.rows if isinstance(g, NamedNode) and not self._servers_own(g.value)}

    def existing_graphs(self, names: Sequence[str]) -> set[str]:
        """As the base's, asked with ``FILTER EXISTS``: Virtuoso keeps the plan of a query text, and
        the base's join, planned while a run's graphs were empty, took 11 s once they held 4*10^4
        triples (the filter: 14 ms)."""
        if not names:
            return set()
        values = " ".join(term_text(graph_node(name)) for name in dict.fromkeys(names))
        held = "FILTER EXISTS { GRAPH ?g { ?s ?p ?o } }"
        rows = self.select(f"SELECT ?g WHERE {{ VALUES ?g {{ {values} }} {held} }}")
        return {g.value for (g,) in rows.rows if isinstance(g, NamedNode)}

    def graph_sizes(self) -> dict[str, int]:
        return {g: n for g, n in super().graph_sizes().items() if not self._servers_own(g)}

    def quads(self) -> list[Quad]:
        flavour = self.flavour()
        if flavour.answers is not None or flavour.keeps_graphs:  # graph by graph, the server's left out
            return [q for quads in self.graphs(sorted(self.graph_names())).values() for q in quads]
        return super().quads()

    def clear(self) -> None:
        """Remove every graph but those the server keeps for itself (its flavour's ``owns``)."""
        if self.flavour().keeps_graphs:
            self.remove_graphs(sorted(self.graph_names()))
        else:
            super().clear()

    def _servers_own(self, graph: str) -> bool:
        return self.flavour().owns(graph)

    def graph(self, name: str) -> list[Quad]:
        graph = graph_node(name)
        answers = self.flavour().answers
        if answers is not None:  # a SELECT: a server may cut a CONSTRUCT at a row limit unsaid
            rows = self.select(f"SELECT ?s ?p ?o WHERE {{ GRAPH {term_text(graph)} {{ ?s ?p ?o }} }}")
            return [
                Quad(s, p, o, graph)
                for s, p, o in rows.rows
                if isinstance(s, (NamedNode, BlankNode)) and isinstance(p, NamedNode) and o is not None
            ]
        if self.gsp_url is not None:
            separator = "&" if "?" in self.gsp_url else "?"
            url = f"{self.gsp_url}{separator}{urllib.parse.urlencode({'graph': name})}"
            body, content_type = self._request(url, accept=N_TRIPLES, missing_ok=True)
        else:
            query = f"CONSTRUCT {{ ?s ?p ?o }} WHERE {{ GRAPH {term_text(graph)} {{ ?s ?p ?o }} }}"
            body, content_type = self._post_sparql(
                self.url, "query", query, f"{N_TRIPLES}, text/turtle;q=0.9"
            )
        if not body.strip():
            return []
        format_ = RdfFormat.from_media_type(content_type.split(";")[0].strip()) or RdfFormat.N_TRIPLES
        try:
            triples = list(parse(body, format=format_))
        except (SyntaxError, ValueError) as exc:
            raise StoreError(
                f"{self.label} sent graph <{name}> as unreadable {content_type}: {exc}"
            ) from None
        return [Quad(_unskolemised(t.subject), t.predicate, _unskolemised(t.object), graph) for t in triples]

    def graphs(self, names: Sequence[str]) -> dict[str, list[Quad]]:
        found: dict[str, list[Quad]] = {name: [] for name in names}
        if not names:
            return found
        if self.flavour().answers is not None:  # graph by graph, read as the flavour reads them
            return {name: self.graph(name) for name in names}
        values = " ".join(term_text(graph_node(name)) for name in names)
        rows = self.select(f"SELECT ?g ?s ?p ?o WHERE {{ VALUES ?g {{ {values} }} GRAPH ?g {{ ?s ?p ?o }} }}")
        for g, s, p, o in rows.rows:
            if not (isinstance(g, NamedNode) and isinstance(p, NamedNode) and o is not None):
                continue
            if isinstance(s, (NamedNode, BlankNode)):
                found.setdefault(g.value, []).append(Quad(s, p, o, g))
        return found


def _check_whole(flavour: StoreFlavour, headers: dict[str, str], count: int, label: str) -> None:
    """A StoreError if an answer of ``count`` rows, with these ``headers`` (lower-case names), says
    the server cut it at a row limit of its configuration (the flavour's ``row_limit``): a cut
    answer is a wrong one."""
    limit = flavour.row_limit
    said = headers.get(limit.header.lower(), "") if limit is not None else ""
    if limit is not None and said.strip().isdigit() and count >= int(said):
        raise StoreError(
            f"{label} cut its answer at {said} rows ({limit.setting}), so it would be wrong; "
            "raise that limit on the server"
        )


def _unskolemised(term: Any) -> Any:
    """``term``, or the blank node a Skolem IRI of exsce's (SKOLEM) stands for."""
    if isinstance(term, NamedNode) and term.value.startswith(SKOLEM):
        return BlankNode(term.value[len(SKOLEM) :])
    return term


def _split_credentials(url: str) -> tuple[str, str | None, str | None]:
    """The URL without ``user:password@``, and the user and password it held."""
    parts = urllib.parse.urlsplit(url)
    if parts.scheme not in ("http", "https") or not parts.netloc:
        raise StoreError(f"not an http(s) URL of a SPARQL endpoint: {url!r}")
    if parts.username is None:
        return url, None, None
    host = parts.hostname or ""
    if ":" in host:
        host = f"[{host}]"
    netloc = f"{host}:{parts.port}" if parts.port else host
    bare = urllib.parse.urlunsplit(parts._replace(netloc=netloc))
    user = urllib.parse.unquote(parts.username)
    password = urllib.parse.unquote(parts.password) if parts.password is not None else None
    return bare, user, password


def _reason(reason: Any) -> str:
    if isinstance(reason, ConnectionRefusedError):
        return "connection refused (is the server running, and on this host and port?)"
    if isinstance(reason, socket.gaierror):
        return f"unknown host ({reason})"
    if isinstance(reason, (TimeoutError, socket.timeout)):
        return "timed out"
    return str(reason)
