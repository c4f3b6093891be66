"""The query library: SPARQL files shipped in this package, loaded by name.

Each ``NAME.rq`` (a query) or ``NAME.ru`` (an update) starts with comment lines:
the first says in one line what it answers (``exscec query --list`` shows it),
and each parameter has a line of its own::

    # The runs of a scenario, oldest first.
    #
    # ?scenario  scenario?  the scenario, by id (all runs without it)

``kind`` says how a value given as text becomes an RDF term (:data:`KINDS`); a
``+`` after it means the parameter takes one value or more (a ``VALUES`` list),
a ``?`` that it may be left out, ``*`` both.  A parameter that may be left out
is written so that the query is right either way.

The files use the prefixes of :meth:`Query.prologue` without declaring them
(``exsce:``, ``run:``, ``pose:``... of the project's base namespace, and
``prov:``, ``xsd:``, ``rdf:``, ``rdfs:``), so one file serves any base
namespace.  Parameters are bound by :func:`exsce_dsl.store.sparql.bind`, as
``VALUES`` of RDF terms: never pasted into the text.

Every ``GRAPH ?g`` block of a query that reads the current state leaves out
revision graphs (``FILTER(!CONTAINS(STR(?g), "revision="))``; see
:mod:`exsce_dsl.store.writing`).
"""

from __future__ import annotations

import functools
import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from importlib.resources import files

from pyoxigraph import Literal, NamedNode

from exsce_dsl.errors import ExsceError
from exsce_dsl.prov import identifiers as ids
from exsce_dsl.prov.identifiers import DEFAULT_NAMESPACE, Namespaces
from exsce_dsl.remedies import LIST_THE_QUERIES
from exsce_dsl.store.base import Bindings, Term
from exsce_dsl.store.run_summary import RUN_ID_BUCKET, run_id_bucket
from exsce_dsl.suggest import did_you_mean

__all__ = ["FROM_RUNS", "KINDS", "QueryParameter", "Query", "query", "query_names", "standard_prefixes"]

_XSD_DOUBLE = NamedNode(ids.XSD_NAMESPACE + "double")
_SUMMARY_TERMS = tuple(f"exsce:{t.local}" for t in (ids.SUMMARY_OF, ids.SUMMARY_RUN, ids.SUMMARY_METRIC))


def _iri(names: Namespaces, prefix: str, local: str, what: str) -> NamedNode:
    try:
        return NamedNode(names.fixed[prefix] + local)
    except ValueError:
        raise ExsceError(f"{what} '{local}' cannot be part of an IRI") from None


def _double(names: Namespaces, text: str) -> Literal:
    try:
        number = float(text)
    except ValueError:
        raise ExsceError(f"'{text}' is not a number") from None
    return Literal(repr(number), datatype=_XSD_DOUBLE)


KINDS: Mapping[str, Callable[[Namespaces, str], Term]] = {
    "scenario": lambda names, text: _iri(names, ids.EXSCE, text, "scenario id"),
    "pose": lambda names, text: _iri(names, ids.POSE, text, "pose"),
    "point": lambda names, text: _iri(names, ids.POINT, text, "pose"),
    "id": lambda names, text: Literal(text),
    "run": lambda names, text: Literal(text),
    "run_activity": lambda names, text: _iri(names, ids.RUN, ids.run_local_name(text), "run uuid"),
    "run_bundle": lambda names, text: _iri(names, ids.RUN, f"{ids.run_local_name(text)}_bundle", "run uuid"),
    "run_part": lambda names, text: _iri(names, ids.RUN, f"{ids.run_local_name(text)}/", "run uuid"),
    "run_prefix": lambda names, text: Literal(text),
    "run_id_bucket": lambda names, text: NamedNode(run_id_bucket(names.fixed[ids.EXSCE], text)),
    "robot": lambda names, text: Literal(text),
    "metric": lambda names, text: Literal(text),
    "metric_property": lambda names, text: _iri(names, ids.METRIC, text, "metric"),
    "string": lambda names, text: Literal(text),
    "double": _double,
}
"""How a parameter's text becomes a term: ``scenario`` → ``exsce:<id>``, ``pose`` →
``pose:<pose name>`` (``classroom_c025-w001-R0.00_P0.00_Y0.00``), ``point`` → ``point:<pose id>``
(the position of every heading of the pose), ``double`` → an ``xsd:double``,
``metric_property`` → ``metric:<name>`` (the segment index's property for the metric),
``run_activity`` → ``run:run_<uuid>`` (the run's activity, given by its uuid: a query starts
from it with a look-up, where the uuid literal is one of every run entity's), ``run_bundle`` →
``run:run_<uuid>_bundle`` (the run's bundle, a graph: a ``GRAPH ?bundle`` block bound to it reads
that graph's indexes alone, the fastest start a query has), ``run_part`` → the run's graph
named like the parameter (``?hotspots_bundle`` → ``run:run_<uuid>/hotspots_bundle``),
``run_id_bucket`` → the run summaries' key of the runs whose uuid starts like the ``run_prefix``
given (:func:`~exsce_dsl.store.run_summary.run_id_bucket`: a look-up, where a ``STRSTARTS`` reads
every run's uuid), and ``id``, ``run_prefix`` (the start of a run's uuid),
``run`` (a uuid), ``robot``, ``metric``, ``string`` → a plain literal."""


FROM_RUNS = frozenset({"run_bundle", "run_part", "run_id_bucket"})
"""The kinds bound from the runs given to the query (a run's graphs, the key of a run id's
prefix), never given themselves."""


@dataclass(frozen=True)
class QueryParameter:
    name: str
    kind: str
    many: bool = False
    optional: bool = False
    description: str = ""

    @property
    def from_runs(self) -> bool:
        """Whether the parameter is bound from the runs given to the query (a run's graph), never
        given itself."""
        return self.kind in FROM_RUNS

    def term(self, text: str, names: Namespaces) -> Term:
        made = KINDS[self.kind](names, text)
        # run_part: the run's parts' namespace, then the part named like the parameter (a name
        # of letters, digits and '_')
        return NamedNode(made.value + self.name) if self.kind == "run_part" else made


@dataclass(frozen=True)
class Query:
    """One file of the library."""

    name: str
    description: str
    text: str
    """The SPARQL as written (comments included), without the prologue."""
    parameters: tuple[QueryParameter, ...]
    is_update: bool

    @property
    def reads_summaries(self) -> bool:
        """Whether the query reads the run summaries (:mod:`exsce_dsl.store.run_summary`), which
        a store written by an earlier exsce lacks."""
        return any(term in self.text for term in _SUMMARY_TERMS)

    def sparql(self, namespace: str = DEFAULT_NAMESPACE) -> str:
        """The text to run: the prologue of prefixes, then the query."""
        return prologue(namespace) + self.text

    def parameter(self, name: str) -> QueryParameter:
        for p in self.parameters:
            if p.name == name:
                return p
        known = ", ".join(p.name for p in self.parameters) or "none"
        raise ExsceError(f"query '{self.name}' has no parameter '{name}' (its parameters: {known})")

    def bindings(self, given: Mapping[str, Sequence[str]], namespace: str = DEFAULT_NAMESPACE) -> Bindings:
        """Terms for parameters given as text (name → values), checked against the declarations."""
        names = Namespaces(namespace)
        found: dict[str, Term | Sequence[Term]] = {}
        for name, values in self._derived(given).items():
            parameter = self.parameter(name)
            if not parameter.many and len(values) > 1:
                raise ExsceError(f"parameter '{name}' of query '{self.name}' takes one value")
            terms = [parameter.term(v, names) for v in values]
            found[name] = terms if parameter.many else terms[0]
        missing = [p.name for p in self.parameters if not p.optional and p.name not in given]
        if missing:
            raise ExsceError(f"query '{self.name}' needs {', '.join(missing)} (give each with -p NAME=VALUE)")
        return found

    def _derived(self, given: Mapping[str, Sequence[str]]) -> dict[str, Sequence[str]]:
        """The parameters given, with the runs given to a query that names their bundles
        (``run_bundle``, ``run_part``) bound as those bundles instead: the query starts from them, and
        reads each run's uuid there (a list of uuids bound beside them would be joined to
        every row); and a run id's prefix as its key too (``run_id_bucket``)."""
        derived = dict(given)
        prefixes = [p.name for p in self.parameters if p.kind == "run_prefix" and p.name in given]
        for bucket in (p.name for p in self.parameters if p.kind == "run_id_bucket"):
            # (a prefix too short for a key of its own is looked for among every run's uuid)
            if prefixes and all(len(v) >= RUN_ID_BUCKET and ids.is_name(v) for v in given[prefixes[0]]):
                derived[bucket] = given[prefixes[0]]
        given = derived
        bundles = [p.name for p in self.parameters if p.kind in ("run_bundle", "run_part")]
        runs = [p.name for p in self.parameters if p.kind == "run" and p.name in given]
        if not bundles or not runs or not all(map(ids.is_name, given[runs[0]])):
            return dict(given)  # (a value that is no run id is bound as given, and found nowhere)
        derived = {name: values for name, values in given.items() if name not in runs}
        derived.update((name, given[runs[0]]) for name in bundles)
        return derived


_PARAMETER_LINE = re.compile(r"#\s*\?([A-Za-z_][A-Za-z0-9_]*)\s+([a-z_]+)([+?*]?)(?:\s+(.*))?")


def _parse(name: str, text: str, is_update: bool) -> Query:
    description = ""
    parameters = []
    for line in text.splitlines():
        stripped = line.strip()
        if not stripped:
            continue
        if not stripped.startswith("#"):
            break
        match = _PARAMETER_LINE.fullmatch(stripped)
        if match:
            pname, kind, mark, about = match.groups(default="")
            if kind not in KINDS:
                raise ExsceError(f"query '{name}': parameter ?{pname} has an unknown kind '{kind}'")
            parameters.append(QueryParameter(pname, kind, mark in ("+", "*"), mark in ("?", "*"), about))
        elif not description and stripped.lstrip("#").strip():
            description = stripped.lstrip("#").strip()
    return Query(name, description, text, tuple(parameters), is_update)


@functools.lru_cache(maxsize=1)
def _library() -> dict[str, Query]:
    found = {}
    for entry in files("exsce_dsl.store.queries").iterdir():
        filename = entry.name
        for suffix, is_update in ((".rq", False), (".ru", True)):
            if filename.endswith(suffix):
                name = filename[: -len(suffix)]
                found[name] = _parse(name, entry.read_text(encoding="utf-8"), is_update)
    return dict(sorted(found.items()))


def query_names() -> tuple[str, ...]:
    """The names of the library's queries and updates, sorted."""
    return tuple(_library())


def query(name: str) -> Query:
    """The query called ``name`` (an ExsceError naming the known ones otherwise)."""
    found = _library().get(name)
    if found is None:
        hint = did_you_mean(name, _library())
        raise ExsceError(f"no query called '{name}'{hint}", remedy=LIST_THE_QUERIES)
    return found


def standard_prefixes(namespace: str = DEFAULT_NAMESPACE) -> dict[str, str]:
    """The prefixes every library query may use: exsce's namespaces, PROV, XSD, RDF, RDFS."""
    return {
        "prov": ids.PROV_NAMESPACE,
        "xsd": ids.XSD_NAMESPACE,
        "rdf": ids.RDF_NAMESPACE,
        "rdfs": ids.RDFS_NAMESPACE,
        **Namespaces(namespace).fixed,
    }


@functools.lru_cache(maxsize=8)
def prologue(namespace: str = DEFAULT_NAMESPACE) -> str:
    return "".join(f"PREFIX {p}: <{iri}>\n" for p, iri in standard_prefixes(namespace).items())
