"""Kinds of SPARQL server, each a record of all it does its own way (:class:`StoreFlavour`).

A flavour owns where the server puts its services (:class:`Preset`, for ``virtuoso+http://...``
store URLs), how its Server header tells it, how it wants blank nodes written (``skolem``), the
graphs it keeps for itself, how its answers are read when SPARQL JSON would lose digits
(:class:`Answers`), how it takes a write (:class:`~exsce_dsl.store.write_strategy.WriteStrategy`)
and how it says that it cut an answer (:class:`RowLimit`).
:class:`~exsce_dsl.store.remote.RemoteStore` asks its server's flavour and never names a server.
Packages add flavours under the entry-point group ``exsce.store_flavours`` (:mod:`exsce_dsl.plugins`).
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass

from exsce_dsl.plugins import Registry
from exsce_dsl.prov.identifiers import SKOLEM_BASE
from exsce_dsl.store import virtuoso
from exsce_dsl.store.base import Rows
from exsce_dsl.store.write_strategy import WriteStrategy

__all__ = [
    "FLAVOURS",
    "SPARQL",
    "Answers",
    "Preset",
    "RowLimit",
    "StoreFlavour",
    "flavour_named",
    "server_flavour",
]


@dataclass(frozen=True)
class Preset:
    """Where a flavour puts its services, relative to the URL given."""

    query: str
    update: str
    gsp: str | None = None
    form: bool = False
    strip: tuple[str, ...] = ()
    """Endpoint suffixes to take off the URL given, to find the base."""


@dataclass(frozen=True)
class Answers:
    """How SELECT answers are asked for (``media_type``) and read, when a server's SPARQL JSON
    loses what was written (a graph is read by a SELECT too)."""

    media_type: str
    rows: Callable[[bytes, str], Rows]
    """(the answer, the store's label for errors) → the rows of a SELECT."""


@dataclass(frozen=True)
class RowLimit:
    """How a server says that it cut an answer at a row limit of its configuration."""

    header: str
    """The answer's header that holds the limit when the answer may be cut at it."""
    setting: str
    """The setting, as its administrator knows it (said in the error)."""


@dataclass(frozen=True)
class StoreFlavour:
    """One kind of SPARQL server; the defaults are SPARQL 1.1's, what every endpoint does.

    ``preset``: where it puts its services (None: reached by its URLs only).  ``server``: what
    its ``Server`` header holds (lower case) when it is this flavour (None: not told so).
    ``skolem``: where the IRIs written for blank nodes begin, for a server that takes none in
    ``INSERT DATA`` (RDF 1.1 Concepts, 3.5; read back as blank nodes; None: blank nodes are
    written).  ``own_graphs``: beginnings of the names of the graphs the server keeps for
    itself, never listed, exported or cleared.  ``answers``: how its answers are read when not
    as SPARQL JSON (then graph by graph).  ``ask_column``: the one column of the table it
    answers an ASK with (a row of 1: true), if it does so.  ``writes``: how it takes a write
    (:class:`~exsce_dsl.store.write_strategy.WriteStrategy`).
    """

    name: str
    preset: Preset | None = None
    server: str | None = None
    """Matched against the ``Server`` header of the server's first answer; a store URL's
    ``name+http://`` does not set the flavour, the server's answer does."""
    skolem: str | None = None
    own_graphs: tuple[str, ...] = ()
    own_graph_names: tuple[str, ...] = ()
    """Regular expressions matching the whole names of more graphs the server keeps for itself,
    names that hold its host, so that no beginning tells them."""
    answers: Answers | None = None
    ask_column: str | None = None
    writes: WriteStrategy = WriteStrategy()
    row_limit: RowLimit | None = None
    """How the server says it cut an answer (then exsce refuses the answer, never a wrong number)."""
    advice: tuple[tuple[str, str], ...] = ()
    """Known refusals of the server: (text its answer holds, what to do), said after its message."""

    def advice_for(self, answer: str) -> str | None:
        """What to do about a refusal whose answer says ``answer``, if the refusal is a known one."""
        return next((what for said, what in self.advice if said in answer), None)

    def owns(self, graph: str) -> bool:
        """Whether ``graph`` is one the server keeps for itself (``own_graphs``, ``own_graph_names``)."""
        return graph.startswith(self.own_graphs) or any(re.fullmatch(p, graph) for p in self.own_graph_names)

    @property
    def keeps_graphs(self) -> bool:
        """Whether the server keeps graphs of its own."""
        return bool(self.own_graphs or self.own_graph_names)

    @property
    def whole_requests(self) -> bool:
        """Whether a request of several operations is one transaction (all or nothing); False: each
        operation is committed on its own, so a write goes in steps."""
        return self.writes.whole_requests


SPARQL = StoreFlavour("sparql")
"""Any SPARQL 1.1 endpoint, and every server no other flavour's ``server`` tells."""

VIRTUOSO = StoreFlavour(
    "virtuoso",
    Preset("/sparql", "/sparql", "/sparql-graph-crud", form=True, strip=("/sparql",)),
    server="virtuoso",
    skolem=SKOLEM_BASE,
    own_graphs=virtuoso.OWN_GRAPHS,
    own_graph_names=virtuoso.OWN_GRAPH_NAMES,
    answers=Answers(virtuoso.TURTLE, virtuoso.result_set_rows),
    ask_column="__ASK_RETVAL",
    writes=WriteStrategy(
        whole_requests=False,
        statements=virtuoso.INSERT_DATA_TRIPLES,
        request_bytes=virtuoso.GRAPH_POST_BYTES,
        graph_post=True,
    ),
    row_limit=RowLimit(virtuoso.MAX_ROWS_HEADER, "[SPARQL] ResultSetMaxRows in its virtuoso.ini"),
    advice=virtuoso.ADVICE,
)
"""Virtuoso 7 (:mod:`exsce_dsl.store.virtuoso`): no blank nodes in ``INSERT DATA``, doubles
exact only in its Turtle, graphs of its own, ASK answered as a table, each operation of a
request committed on its own and no ``INSERT DATA`` of more than ~1,400 triples: a write goes
graph by graph through its Graph Store Protocol, its commit graphs last."""

_BUILT_IN = (
    StoreFlavour("oxigraph", Preset("/query", "/update", "/store", strip=("/query", "/update", "/store"))),
    StoreFlavour(
        "exsce", Preset("/query", "/update", "/store", strip=("/query", "/update", "/sparql", "/store"))
    ),
    StoreFlavour(
        "fuseki", Preset("/query", "/update", "/data", strip=("/query", "/sparql", "/update", "/data"))
    ),
    StoreFlavour("graphdb", Preset("", "/statements", "/rdf-graphs/service", strip=("/statements",))),
    VIRTUOSO,
    StoreFlavour("neptune", Preset("/sparql", "/sparql", "/sparql/gsp/", form=True, strip=("/sparql",))),
    SPARQL,
)


def _accepted(name: str, loaded: object) -> StoreFlavour | None:
    made = loaded() if callable(loaded) and not isinstance(loaded, StoreFlavour) else loaded
    return made if isinstance(made, StoreFlavour) and made.name == name else None


FLAVOURS: Registry[StoreFlavour] = Registry(
    "store flavour", ((f.name, f) for f in _BUILT_IN), _accepted, "a StoreFlavour"
)
"""The flavours by name: exsce's, then the plug-ins'."""


def flavour_named(name: str) -> StoreFlavour | None:
    """The flavour a store URL's ``name+http://`` asks for, if it has a preset."""
    found = FLAVOURS.get(name.lower())
    return found if found is not None and found.preset is not None else None


def server_flavour(server: str) -> StoreFlavour:
    """The flavour of a server that says ``server`` in its ``Server`` header (else :data:`SPARQL`)."""
    said = server.lower()
    for flavour in FLAVOURS.entries().values():
        if flavour.server is not None and flavour.server in said:
            return flavour
    return SPARQL


def ask_columns() -> frozenset[str]:
    """The columns some flavour answers an ASK with as a table (read before the flavour is known)."""
    return frozenset(f.ask_column for f in FLAVOURS.entries().values() if f.ask_column is not None)
