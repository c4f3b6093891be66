"""Adding PROV documents to a store: one named graph per bundle, in one write.

What happens to each of a document's graphs, compared with what the store
holds under the same name:

* **new** — the store has no such graph: it is added;
* **unchanged** — the store holds the same statements (blank nodes compared
  by structure, literals by value, so ``"0.0"^^xsd:double`` equals the ``"0"``
  a store may give back): nothing is written.  Adding the same spec twice
  changes nothing;
* **merged** — a *pose graph* (an area bundle: poses, points and orientations
  only, no blank nodes) is shared by the scenarios of one environment and
  holds the union of the poses they use.  Poses the store lacks are added; a
  pose, point or orientation the store describes otherwise (other
  coordinates) is a conflict;
* **conflict** — any other difference.  The whole document is refused with a
  :class:`~exsce_dsl.store.base.StoreConflictError` naming each graph that
  differs and how, unless ``replace`` is given: then the new version replaces
  the old one, and the old graph is kept as a **revision** graph.

Revisions: the old content of graph ``G`` moves to ``G?revision=N`` (N = 1,
2, ... per graph), with the graph's own entity ``E`` (``exsce:scenario_c`` for
``exsce:scenario_c_bundle``) renamed ``E?revision=N`` there, marked
``prov:invalidatedAtTime`` (when it was replaced), and linked by
``E prov:wasRevisionOf E?revision=N`` (for a bundle without an entity of its
own, an area's, ``G prov:wasRevisionOf G?revision=N``).  Those statements live
in the revision graph, so the current graphs stay exactly what the compiler
wrote.  Queries about the current state leave revision graphs out
(:func:`is_revision`).

Everything — new, merged and replaced graphs and the revisions — is one
:meth:`~exsce_dsl.store.base.Store.write`: all of it or none.  Runs are written
the same way (their graphs are new, named by their uuids).
"""

from __future__ import annotations

import datetime
import re
from collections.abc import Collection, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from decimal import Decimal, InvalidOperation

from prov.model import ProvDocument
from pyoxigraph import (
    BlankNode,
    CanonicalizationAlgorithm,
    Dataset,
    DefaultGraph,
    Literal,
    NamedNode,
    Quad,
)

from exsce_dsl.errors import StoreConflictError, StoreError
from exsce_dsl.prov.identifiers import PROV_NAMESPACE, RDF_TYPE, ROBOT_SCHEMA, XSD_NAMESPACE
from exsce_dsl.store.base import Store
from exsce_dsl.store.graph_owners import replace_advice
from exsce_dsl.store.indexes import index_graphs
from exsce_dsl.store.literals import INTEGER_TYPES
from exsce_dsl.store.run_commit import run_graph_set, unfinished_run_graphs
from exsce_dsl.store.segment_index import stale_index_graphs

__all__ = [
    "WriteReport",
    "add_graphs",
    "add_prov",
    "bundle_graphs",
    "is_revision",
    "revision_name",
    "stored_graphs",
]

_RDF_TYPE = RDF_TYPE
_POSE_TYPES = frozenset(f"{ROBOT_SCHEMA}{local}" for local in ("Pose", "Point", "EulerAngles"))
_WAS_REVISION_OF = NamedNode(f"{PROV_NAMESPACE}wasRevisionOf")
_INVALIDATED_AT = NamedNode(f"{PROV_NAMESPACE}invalidatedAtTime")
_REVISION = re.compile(r"[?&]revision=(\d+)$")


def revision_name(iri: str, number: int) -> str:
    """``iri?revision=N``: the name of revision ``number`` of a graph or an entity."""
    return f"{iri}{'&' if '?' in iri else '?'}revision={number}"


def is_revision(name: str) -> bool:
    """True for a revision graph's (or a revised entity's) name."""
    return _REVISION.search(name) is not None


@dataclass(frozen=True)
class WriteReport:
    """What a write did, graph by graph."""

    location: str
    added: tuple[str, ...] = ()
    merged: tuple[str, ...] = ()
    replaced: tuple[str, ...] = ()
    unchanged: tuple[str, ...] = ()
    revisions: tuple[str, ...] = ()
    statements: int = 0
    """Statements written (revisions included)."""
    prefixes: Mapping[str, str] = field(default_factory=dict, compare=False, repr=False)

    @property
    def changed(self) -> bool:
        return bool(self.added or self.merged or self.replaced)

    def summary(self) -> str:
        """One line for people."""
        if not self.changed:
            return f"{self.location}: no change (the store already holds these {len(self.unchanged)} graphs)"
        parts = []
        for verb, names in (("added", self.added), ("merged into", self.merged), ("replaced", self.replaced)):
            if names:
                parts.append(f"{verb} {len(names)} graph{'s' if len(names) != 1 else ''}")
        if self.unchanged:
            parts.append(f"{len(self.unchanged)} unchanged")
        if self.revisions:
            kept = ", ".join(compact(name, self.prefixes) for name in self.revisions)
            parts.append(f"old versions kept as {kept}")
        return f"{self.location}: {'; '.join(parts)} ({self.statements} statements written)"


def add_prov(store: Store, document: ProvDocument, *, replace: bool = False) -> WriteReport:
    """Add a PROV document, one named graph per bundle, in one write (see the module's rules).

    A run's index graphs (its segment index and summary: :mod:`exsce_dsl.store.indexes`) go in
    the same write.
    """
    from exsce_dsl.rdf import prefixes_of

    graphs = bundle_graphs(document)
    index = index_graphs(graphs)
    if replace and index:
        for stale in stale_index_graphs(store, graphs, index):
            index[stale] = []  # an action the new version of a run no longer has
    derived = [name for name in index if name not in graphs]
    for name in derived:
        graphs[name] = index[name]
    return add_graphs(store, graphs, replace=replace, prefixes=prefixes_of(document), derived=derived)


def bundle_graphs(document: ProvDocument) -> dict[str, list[Quad]]:
    """The document in PROV-O, a named graph per bundle (graph IRI → quads)."""
    from exsce_dsl.rdf import to_quads

    graphs: dict[str, list[Quad]] = {}
    outside = 0
    for quad in to_quads(document):
        if isinstance(quad.graph_name, NamedNode):
            graphs.setdefault(quad.graph_name.value, []).append(quad)
        else:
            outside += 1
    if outside:
        raise StoreError(
            f"the document has {outside} statements outside any bundle; the store keeps PROV bundles "
            "as named graphs, so put every record in a bundle"
        )
    return graphs


def stored_graphs(document: ProvDocument) -> dict[str, list[Quad]]:
    """What :func:`add_prov` writes of a document into an empty store: its bundles and, for a
    run, its segment index (for comparisons with other stores)."""
    graphs = bundle_graphs(document)
    for name, quads in index_graphs(graphs).items():
        graphs.setdefault(name, quads)
    return graphs


def add_graphs(
    store: Store,
    graphs: Mapping[str, Sequence[Quad]],
    *,
    replace: bool = False,
    prefixes: Mapping[str, str] | None = None,
    derived: Collection[str] = (),
) -> WriteReport:
    """Add named graphs with the rules of :func:`add_prov`; ``prefixes`` shorten names in messages.

    ``derived`` graphs (the segment index) say again what the others say: a
    changed one is replaced with no revision kept and is no conflict of its own
    (its source graphs' conflict is); an empty one is dropped.
    """
    prefixes = dict(prefixes or {})
    derived = frozenset(derived)
    names = list(graphs)
    existing = store.existing_graphs(names)
    unfinished = unfinished_run_graphs(names, existing)  # left by a write that stopped: written over
    existing -= unfinished
    stored = store.graphs([name for name in names if name in existing]) if existing else {}
    plan = _WritePlan()
    for name in names:
        plan.compare(name, stored.get(name, []), list(graphs[name]), derived=name in derived)
    if plan.conflicts and not replace:
        problem, remedy, about = _conflict_message(store, graphs, plan.conflicts, prefixes)
        raise StoreConflictError(problem, [c.graph for c in plan.conflicts], remedy=remedy, about=about)
    revisions = _revisions(store, plan.conflicts, stored) if plan.conflicts else {}
    writes = {**plan.to_add, **plan.to_replace, **revisions, **plan.derived_changes}
    if writes:
        replaced = {*plan.to_replace, *revisions, *plan.derived_changes, *(unfinished & set(writes))}
        store.write(run_graph_set(writes), replace=replaced)
    return WriteReport(
        location=store.location,
        added=tuple(plan.added),
        merged=tuple(plan.merged),
        replaced=tuple(plan.to_replace),
        unchanged=tuple(plan.unchanged),
        revisions=tuple(revisions),
        statements=sum(len(q) for q in writes.values()),
        prefixes=prefixes,
    )


@dataclass
class _WritePlan:
    """What :func:`add_graphs` does with each graph, by what the store holds under its name."""

    added: list[str] = field(default_factory=list)
    merged: list[str] = field(default_factory=list)
    unchanged: list[str] = field(default_factory=list)
    conflicts: list[_Difference] = field(default_factory=list)
    to_add: dict[str, list[Quad]] = field(default_factory=dict)
    to_replace: dict[str, list[Quad]] = field(default_factory=dict)
    derived_changes: dict[str, list[Quad]] = field(default_factory=dict)

    def compare(self, name: str, old: list[Quad], new: list[Quad], *, derived: bool) -> None:
        """Graph ``name``: new, unchanged, merged (a pose graph), a conflict, or a derived change."""
        if derived:
            if not old and new:
                self.to_add[name] = new
            elif old and _canonical(old) != _canonical(new):
                self.derived_changes[name] = new
        elif not old:
            self.added.append(name)
            self.to_add[name] = new
        elif _is_pose_graph(old) and _is_pose_graph(new):
            self.merge_poses(name, old, new)
        elif _canonical(old) == _canonical(new):
            self.unchanged.append(name)
        else:
            self.conflicts.append(_subject_difference(name, old, new))
            self.to_replace[name] = new

    def merge_poses(self, name: str, old: list[Quad], new: list[Quad]) -> None:
        """A pose graph holds the union of the poses its scenarios use; a pose described
        otherwise is a conflict, replaced (if allowed) by the union with the new description."""
        old_subjects, new_subjects = _descriptions(old), _descriptions(new)
        changed = sorted(
            s for s in new_subjects.keys() & old_subjects.keys() if new_subjects[s] != old_subjects[s]
        )
        if changed:
            predicates = {p for s in changed for p, _ in old_subjects[s] ^ new_subjects[s]}
            self.conflicts.append(
                _Difference(
                    name, changed=tuple(changed), predicates=tuple(sorted(predicates)), pose_graph=True
                )
            )
            kept = [q for q in old if _key(q.subject) not in changed]
            self.to_replace[name] = _union(kept, new)
            return
        missing = _missing(old, new)
        if missing:
            self.merged.append(name)
            self.to_add[name] = missing
        else:
            self.unchanged.append(name)


def _revisions(
    store: Store, conflicts: list[_Difference], stored: Mapping[str, list[Quad]]
) -> dict[str, list[Quad]]:
    """Each conflicting graph's old content, kept under its next revision name."""
    revisions: dict[str, list[Quad]] = {}
    existing = store.graph_names()
    now = datetime.datetime.now(datetime.timezone.utc).replace(microsecond=0)
    for difference in conflicts:
        number = 1 + max((_revision_number(n, difference.graph) for n in existing), default=0)
        revision = revision_name(difference.graph, number)
        revisions[revision] = _revision_quads(
            difference.graph, stored[difference.graph], revision, number, now
        )
    return revisions


# -- comparing graphs ------------------------------------------------------------


_XSD_INTEGER = NamedNode(XSD_NAMESPACE + "integer")


def _normal_literal(literal: Literal) -> Literal:
    """The literal as a store may give it back: integer types as xsd:integer, numbers,
    booleans and date-times in canonical form, language tags in lower case."""
    if literal.language:
        return Literal(literal.value, language=literal.language.lower())
    datatype = literal.datatype.value
    text = literal.value.strip()
    try:
        if datatype in INTEGER_TYPES:
            return Literal(str(int(text)), datatype=_XSD_INTEGER)
        local = datatype.removeprefix(XSD_NAMESPACE) if datatype.startswith(XSD_NAMESPACE) else ""
        if local == "decimal":
            number = Decimal(text)
            return Literal(f"{number.normalize():f}" if number else "0", datatype=literal.datatype)
        if local in ("double", "float"):
            return Literal(repr(float(text)), datatype=literal.datatype)
        if local == "boolean" and text in ("true", "false", "1", "0"):
            return Literal("true" if text in ("true", "1") else "false", datatype=literal.datatype)
        if local == "dateTime":
            moment = datetime.datetime.fromisoformat(text.replace("Z", "+00:00"))
            if moment.tzinfo is not None:
                moment = moment.astimezone(datetime.timezone.utc)
            return Literal(moment.isoformat(), datatype=literal.datatype)
    except (ValueError, InvalidOperation):
        pass
    return literal


def _normal(quad: Quad) -> Quad:
    o = quad.object
    return Quad(
        quad.subject, quad.predicate, _normal_literal(o) if isinstance(o, Literal) else o, DefaultGraph()
    )


def _canonical(quads: Iterable[Quad]) -> set[str]:
    """The statements with blank nodes named by structure and literals by value."""
    dataset = Dataset([_normal(q) for q in quads])
    dataset.canonicalize(CanonicalizationAlgorithm.UNSTABLE)
    return {str(q) for q in dataset}


def _key(term: object) -> str:
    return str(term)


def _is_pose_graph(quads: Sequence[Quad]) -> bool:
    """A graph of poses, points and orientations only (an area bundle), with no blank nodes."""
    if not quads:
        return False
    typed = set()
    subjects = set()
    for q in quads:
        if isinstance(q.subject, BlankNode) or isinstance(q.object, BlankNode):
            return False
        subjects.add(q.subject)
        if (
            q.predicate.value == _RDF_TYPE
            and isinstance(q.object, NamedNode)
            and q.object.value in _POSE_TYPES
        ):
            typed.add(q.subject)
    return subjects == typed


def _descriptions(quads: Iterable[Quad]) -> dict[str, frozenset[tuple[str, str]]]:
    """IRI subject → its (predicate IRI, object) pairs (blank nodes as ``[]``, literals by value)."""
    found: dict[str, set[tuple[str, str]]] = {}
    for q in quads:
        if isinstance(q.subject, NamedNode):
            o = q.object
            text = (
                "[]" if isinstance(o, BlankNode) else str(_normal_literal(o) if isinstance(o, Literal) else o)
            )
            found.setdefault(_key(q.subject), set()).add((q.predicate.value, text))
    return {s: frozenset(d) for s, d in found.items()}


def _missing(old: Sequence[Quad], new: Sequence[Quad]) -> list[Quad]:
    """The quads of ``new`` that ``old`` lacks (graphs without blank nodes)."""
    have = {str(_normal(q)) for q in old}
    return [q for q in new if str(_normal(q)) not in have]


def _union(first: Sequence[Quad], second: Sequence[Quad]) -> list[Quad]:
    return [*first, *_missing(first, second)]


@dataclass(frozen=True)
class _Difference:
    graph: str
    changed: tuple[str, ...] = ()
    predicates: tuple[str, ...] = ()
    """The properties whose values differ, for pose graphs."""
    only_old: tuple[str, ...] = ()
    only_new: tuple[str, ...] = ()
    pose_graph: bool = False


def _subject_difference(name: str, old: Sequence[Quad], new: Sequence[Quad]) -> _Difference:
    before, after = _descriptions(old), _descriptions(new)
    return _Difference(
        name,
        changed=tuple(sorted(s for s in before.keys() & after.keys() if before[s] != after[s])),
        only_old=tuple(sorted(before.keys() - after.keys())),
        only_new=tuple(sorted(after.keys() - before.keys())),
    )


def compact(iri: str, prefixes: Mapping[str, str]) -> str:
    """``prefix:local`` with the longest namespace that fits, else ``<iri>``."""
    text = iri[1:-1] if iri.startswith("<") and iri.endswith(">") else iri
    best = ""
    for prefix, namespace in prefixes.items():
        if (
            text.startswith(namespace)
            and len(namespace) > len(prefixes.get(best, ""))
            and len(text) > len(namespace)
        ):
            best = prefix
    return f"{best}:{text[len(prefixes[best]) :]}" if best else f"<{text}>"


def _some(names: Sequence[str], prefixes: Mapping[str, str], limit: int = 3) -> str:
    shown = ", ".join(compact(n, prefixes) for n in names[:limit])
    return shown + (f" and {len(names) - limit} more" if len(names) > limit else "")


def _conflict_message(
    store: Store,
    graphs: Mapping[str, Sequence[Quad]],
    conflicts: Sequence[_Difference],
    prefixes: Mapping[str, str],
) -> tuple[str, str, str]:
    """What differs, one line per graph, then the remedy and what it is about (:func:`replace_advice`)."""
    what = _what(graphs, prefixes)
    count = len(conflicts)
    lines = [
        f"{store.location} already holds another version of {what}: "
        f"{count} graph{'s' if count != 1 else ''} differ{'s' if count == 1 else ''}"
    ]
    for c in conflicts:
        details = []
        if c.changed:
            if c.pose_graph:
                which = ", ".join(compact(p, prefixes) for p in c.predicates)
                verb = "have" if len(c.changed) > 1 else "has"
                details.append(f"{_some(c.changed, prefixes)} {verb} other values ({which})")
            else:
                details.append(f"{_some(c.changed, prefixes)} differ{'' if len(c.changed) > 1 else 's'}")
        if c.only_old:
            details.append(f"{_some(c.only_old, prefixes)} only in the store")
        if c.only_new:
            details.append(f"{_some(c.only_new, prefixes)} only in the new version")
        if not details:
            details.append("blank-node statements differ")
        lines.append(f"  {compact(c.graph, prefixes)}: {'; '.join(details)}")
    last, remedy, about = replace_advice([c.graph for c in conflicts])
    return "\n".join([*lines, last] if last else lines), remedy, about


def _what(graphs: Mapping[str, Sequence[Quad]], prefixes: Mapping[str, str]) -> str:
    """``scenario exsce:scenario_c`` when the graphs hold one, else ``these graphs``."""
    for quads in graphs.values():
        for q in quads:
            if (
                q.predicate.value == _RDF_TYPE
                and isinstance(q.object, NamedNode)
                and q.object.value.endswith("ConcreteScenario")
                and isinstance(q.subject, NamedNode)
            ):
                return f"scenario {compact(q.subject.value, prefixes)}"
    return "these graphs"


# -- revisions -------------------------------------------------------------------


def _revision_number(name: str, graph: str) -> int:
    prefix = f"{graph}{'&' if '?' in graph else '?'}revision="
    rest = name[len(prefix) :] if name.startswith(prefix) else ""
    return int(rest) if rest.isdigit() else 0


def _revision_quads(
    graph: str, old: Sequence[Quad], revision: str, number: int, now: datetime.datetime
) -> list[Quad]:
    """The old content of ``graph`` under ``revision``, its entity renamed, and the revision links."""
    target = NamedNode(revision)
    entity = graph.removesuffix("_bundle") if graph.endswith("_bundle") else None
    subjects = {q.subject for q in old if isinstance(q.subject, NamedNode)}
    current = NamedNode(entity) if entity is not None and NamedNode(entity) in subjects else NamedNode(graph)
    revised = NamedNode(revision_name(current.value, number))

    quads = [
        Quad(
            revised if q.subject == current else q.subject,
            q.predicate,
            revised if q.object == current else q.object,
            target,
        )
        for q in old
    ]
    when = Literal(now.isoformat(), datatype=NamedNode(XSD_NAMESPACE + "dateTime"))
    quads.append(Quad(current, _WAS_REVISION_OF, revised, target))
    quads.append(Quad(revised, _INVALIDATED_AT, when, target))
    return quads
