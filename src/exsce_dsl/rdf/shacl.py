"""SHACL validation of exsce's graphs, and violations reported at DSL locations.

The shapes ship in the package (``exsce_dsl/rdf/shapes/*.ttl``, every file
there is loaded) and are validated with pyshacl over the *union* of the named
graphs: PROV relations span bundles (a mission's plan is derived from a task
in the task's bundle), so no bundle is valid on its own.

:func:`check_scenario_shapes` compiles a scenario, validates it and turns each
violation into a :class:`~exsce_dsl.errors.Diagnostic` at the DSL element its
focus node was made from (:func:`exsce_dsl.prov.source_locations`).
"""

from __future__ import annotations

import functools
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from pyoxigraph import Quad

from exsce_dsl.errors import Diagnostic, ExsceError, Severity, SourceLocation
from exsce_dsl.model.document import Specification
from exsce_dsl.model.scenario import Scenario
from exsce_dsl.prov import compile_scenario, source_locations
from exsce_dsl.prov.identifiers import DEFAULT_NAMESPACE, SHACL_NAMESPACE, SHAPES_NAMESPACE
from exsce_dsl.rdf.prov_o import prefixes_of, to_quads
from exsce_dsl.rdf.serialize import as_graph
from exsce_dsl.resources import package_file

if TYPE_CHECKING:
    from rdflib import Dataset, Graph
    from rdflib.term import Node

__all__ = [
    "Violation",
    "check_scenario_shapes",
    "check_spec_shapes",
    "shape_names",
    "shapes_graph",
    "validate",
    "violation_diagnostics",
    "vocabulary_graph",
]

_SH = SHACL_NAMESPACE


@dataclass(frozen=True)
class Violation:
    """One SHACL result, its nodes spelt as IRIs (``_:`` for blank nodes) or N-Triples literals."""

    focus: str
    """The node that does not conform."""
    path: str | None
    """The property (path) concerned, when the constraint is on one."""
    message: str
    shape: str
    """The shape that says so."""
    component: str
    """The SHACL constraint component, e.g. ``MinCountConstraintComponent``."""
    value: str | None = None
    """The offending value, when there is one."""
    severity: str = "Violation"
    """``Violation``, ``Warning`` or ``Info``."""


# -- packaged resources ----------------------------------------------------------


def shape_names() -> tuple[str, ...]:
    """The packaged shape files, by stem (``spec``, ``runs``, ``oracles``...), sorted."""
    shapes = package_file("rdf", "shapes")
    return tuple(sorted(p.name[: -len(".ttl")] for p in shapes.iterdir() if p.name.endswith(".ttl")))


@functools.lru_cache(maxsize=8)
def shapes_graph(names: tuple[str, ...] | None = None, namespace: str = DEFAULT_NAMESPACE) -> Graph:
    """The packaged shapes called ``names`` (all of them by default), in one graph.

    The shapes are written for the default base namespace; for a project with
    another one (``namespace``), the exsce terms they name move with it, as
    they do in the compiled graphs.  Parsed once per process; do not change
    the graph you get.
    """
    from rdflib import Graph

    known = shape_names()
    graph = Graph()
    for name in known if names is None else names:
        if name not in known:
            raise ExsceError(f"no SHACL shapes called '{name}'; the package has {', '.join(known)}")
        text = package_file("rdf", "shapes", f"{name}.ttl").read_text(encoding="utf-8")
        if namespace != DEFAULT_NAMESPACE:  # IRIs, and namespaces spelt in SPARQL and sh:declare
            text = text.replace(DEFAULT_NAMESPACE, namespace)
        graph.parse(data=text, format="turtle")
    return graph


@functools.lru_cache(maxsize=8)
def _owners(shapes: Graph) -> dict[str, str]:
    """Property shape (a blank node) → the named shape it belongs to, for messages."""
    from rdflib import URIRef

    owners: dict[str, str] = {}
    sh_property = URIRef(_SH + "property")
    for owner, _, shape in shapes.triples((None, sh_property, None)):
        if isinstance(owner, URIRef):
            owners[_spelt(shape) or ""] = str(owner)
    return owners


@functools.lru_cache(maxsize=1)
def vocabulary_graph() -> Graph:
    """The exsce vocabulary (``vocabulary.ttl``): classes and properties with labels and comments."""
    from rdflib import Graph

    text = package_file("rdf", "vocabulary.ttl").read_text(encoding="utf-8")
    return Graph().parse(data=text, format="turtle")


# -- validation ------------------------------------------------------------------


def validate(
    data: Iterable[Quad] | Graph | Dataset,
    shapes: Sequence[str] | Graph | None = None,
    namespace: str = DEFAULT_NAMESPACE,
) -> list[Violation]:
    """The SHACL results of ``data`` against ``shapes``, sorted; empty when it conforms.

    ``data`` is pyoxigraph quads or an rdflib graph or dataset; of quads and
    datasets the union of the graphs is validated.  ``shapes`` names packaged shape files
    (default: all of them, read for the base ``namespace``) or is an rdflib
    graph of shapes.  A property shape's violation names the shape it belongs to.
    """
    from pyshacl import validate as pyshacl_validate
    from rdflib import Dataset, Graph

    if isinstance(data, Dataset):  # pyshacl would validate each named graph on its own
        union = Graph()
        union.addN((s, p, o, union) for s, p, o, _ in data.quads((None, None, None, None)))
    elif isinstance(data, Graph):
        union = data
    else:
        union = as_graph(data)
    if not isinstance(shapes, Graph):
        shapes = shapes_graph(None if shapes is None else tuple(shapes), namespace)
    _, results, _ = pyshacl_validate(
        union,
        shacl_graph=shapes,
        inference="none",
        abort_on_first=False,
        allow_infos=True,
        allow_warnings=True,
        meta_shacl=False,
        advanced=False,
        inplace=True,
    )
    return sorted(_violations(results, _owners(shapes)), key=_order)


def _order(v: Violation) -> tuple[str, ...]:
    return (v.focus, v.path or "", v.shape, v.message, v.value or "", v.component, v.severity)


def _violations(results: Graph, owners: Mapping[str, str]) -> Iterable[Violation]:
    """The top-level results (not the details of a nested shape's result)."""
    from rdflib import URIRef

    names = ("result", "focusNode", "resultPath", "value", "resultMessage", "sourceShape")
    sh = {name: URIRef(_SH + name) for name in (*names, "sourceConstraintComponent", "resultSeverity")}
    for result in results.objects(None, sh["result"]):

        def one(prop: str, result: Node = result) -> Node | None:
            return results.value(result, sh[prop])

        focus, path, value = one("focusNode"), one("resultPath"), one("value")
        messages = sorted(str(m) for m in results.objects(result, sh["resultMessage"]))
        component = str(one("sourceConstraintComponent") or "")
        shape = _spelt(one("sourceShape")) or ""
        yield Violation(
            focus=_spelt(focus) or "",
            path=_spelt(path) if isinstance(path, URIRef) else None,
            message="; ".join(messages) or component,
            shape=owners.get(shape, shape),
            component=component.removeprefix(_SH),
            value=_spelt(value),
            severity=str(one("resultSeverity") or _SH + "Violation").removeprefix(_SH),
        )


def _spelt(node: Node | None) -> str | None:
    from rdflib import BNode, Literal

    if node is None:
        return None
    if isinstance(node, BNode):
        return f"_:{node}"
    if isinstance(node, Literal):
        return str(node.n3())
    return str(node)


# -- violations as diagnostics -----------------------------------------------------

_VALUE_FIRST = frozenset({"NodeConstraintComponent"})
"""Components whose violation concerns the value more than the focus node: a
value that does not conform to a nested shape (a mission member that is not
an allocated plan is the plan's fault)."""


def violation_diagnostics(
    violations: Iterable[Violation],
    locations: Mapping[str, SourceLocation],
    fallback: SourceLocation | None = None,
    prefixes: Mapping[str, str] | None = None,
) -> list[Diagnostic]:
    """Each violation as an error (code ``shacl``) at the location of the node it concerns.

    The node is the focus node, or for ``sh:node`` results the value when it
    has a location; a node without one falls back to ``fallback``.
    ``prefixes`` shorten the IRIs in the messages (``exsce-sh:`` is the shapes'
    namespace unless they say otherwise).
    """
    curie = _Shortener({"exsce-sh": SHAPES_NAMESPACE, **(prefixes or {})})
    found = []
    for v in violations:
        candidates = [v.value, v.focus] if v.component in _VALUE_FIRST else [v.focus]
        where = next((locations[c] for c in candidates if c is not None and c in locations), fallback)
        subject = curie(v.focus) + (f" {curie(v.path)}" if v.path else "")
        value = f"; value {curie(v.value)}" if v.value is not None and v.value != v.focus else ""
        severity = Severity.ERROR if v.severity == "Violation" else Severity.WARNING
        message = f"{subject}: {v.message} (SHACL shape {curie(v.shape)}{value})"
        found.append(Diagnostic(message, where, severity=severity, code="shacl"))
    return found


class _Shortener:
    def __init__(self, prefixes: Mapping[str, str]) -> None:
        self._by_length = sorted(prefixes.items(), key=lambda item: -len(item[1]))

    def __call__(self, spelt: str) -> str:
        if spelt.startswith(("_:", '"')):
            return spelt
        for prefix, iri in self._by_length:
            if spelt.startswith(iri) and len(spelt) > len(iri):
                return f"{prefix}:{spelt[len(iri) :]}"
        return f"<{spelt}>"


def check_scenario_shapes(scenario: Scenario, namespace: str = DEFAULT_NAMESPACE) -> list[Diagnostic]:
    """Compile ``scenario``, validate its graphs against the packaged shapes, and
    report each violation at the DSL element it concerns (the scenario's own
    location when the element has none).

    A scenario that cannot be compiled (two elements would share one IRI) is
    reported as the compiler's error, code ``prov``.
    """
    try:
        document = compile_scenario(scenario, namespace)
        quads = to_quads(document)
    except ExsceError as exc:
        return [Diagnostic(d.message, d.location or scenario.location, code="prov") for d in exc.diagnostics]
    prefixes = {**prefixes_of(document), "exsce-sh": SHAPES_NAMESPACE.replace(DEFAULT_NAMESPACE, namespace)}
    violations = validate(quads, namespace=namespace)
    locations = source_locations(scenario, namespace)
    return violation_diagnostics(violations, locations, scenario.location, prefixes)


def check_spec_shapes(spec: Specification, namespace: str = DEFAULT_NAMESPACE) -> list[Diagnostic]:
    """:func:`check_scenario_shapes` for every scenario of a checked specification."""
    found: list[Diagnostic] = []
    for scenario in spec.scenarios:
        found.extend(check_scenario_shapes(scenario, namespace))
    return found
