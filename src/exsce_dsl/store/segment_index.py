"""The segment index: every path-segment metric value once more, laid out for aggregation.

A run's metric values live on PROV entities
(``run_<uuid>:tiago1-task_01-subtask_001-w_001-distance_travelled``,
``prov:value``, ``prov:wasGeneratedBy`` the action, which ``prov:wasStartedBy`` the
pose it left and ``prov:wasEndedBy`` its goal).  Averaging one segment's metric over
many runs through that shape costs the store a few random index look-ups per value;
at ten thousand runs that is a fifth of a second.  So next to a run's bundles the
store writes, in the same transaction, a small graph per action, named by the
action's IRI, and one per path segment of the scenario, named by the segment:

    GRAPH segment:<scenario>/<start pose>/<goal pose> {        # the same from every run
        segment:<scenario>/<start pose>/<goal pose> a exsce:PathSegment ;
            exsce:startPose pose:<start pose> ;
            exsce:goalPose pose:<goal pose> ;
            exsce:segmentOf exsce:<scenario> .
    }
    GRAPH run_<uuid>:tiago1-task_01-subtask_001-w_001 {         # what one action observed
        segment:<scenario>/<start pose>/<goal pose> exsce:run "<uuid>" ;
            exsce:robot "tiago1" ;
            metric:distance_travelled 15.3 ;
            metric:task_duration 7.0 .
    }

The segment graph is found from its poses in a few look-ups; what each run
observed on it sits in that run's action graphs, so "the distance travelled from
A to B in every run of S" is a single range of one index
(``GRAPH ?g { <segment> metric:distance_travelled ?v }``), and no two drives
collapse into one statement even when their values are equal (each action has
its own graph).  The index is derived from the run's own statements
by :func:`segment_index`; it adds nothing they do not say.
"""

from __future__ import annotations

import re
from collections.abc import Collection, Iterable, Mapping, Sequence

from pyoxigraph import Literal, NamedNode, Quad

from exsce_dsl.prov import identifiers as ids
from exsce_dsl.prov.identifiers import PROV_NAMESPACE
from exsce_dsl.store.base import Store

__all__ = [
    "is_segment_index_graph",
    "orphan_segment_graphs",
    "segment_index",
    "segment_iri",
    "stale_index_graphs",
]

_RDF_TYPE = NamedNode(ids.RDF_TYPE)
_USED = f"{PROV_NAMESPACE}used"
_STARTED_BY = f"{PROV_NAMESPACE}wasStartedBy"
_ENDED_BY = f"{PROV_NAMESPACE}wasEndedBy"
_GENERATED_BY = f"{PROV_NAMESPACE}wasGeneratedBy"
_VALUE = f"{PROV_NAMESPACE}value"
_RUNS_PART = ids.Namespaces().fixed[ids.RUN].removeprefix(ids.DEFAULT_NAMESPACE)
_METRIC_TYPE_SUFFIX = f"{_RUNS_PART}{ids.METRIC_TYPE.local}"
"""``runs/metricType``: what the metric type's IRI adds to the project's base namespace."""
_ATTRIBUTE_ENDINGS = (_METRIC_TYPE_SUFFIX, f"/{ids.RUN_ATTR.local}", f"/{ids.ROBOT_ATTR.local}")


_ACTION_GRAPH = re.compile(r"/runs/run_[^/]+/[^/]+-task_\d+-subtask_\d+-w_\d+$")
_INDEX_GRAPH = re.compile(r"/segments/[^/]+/[^/]+/[^/]+$|" + _ACTION_GRAPH.pattern)


def is_segment_index_graph(name: str) -> bool:
    """True for the name of a graph of the segment index (a segment's or an action's)."""
    return _INDEX_GRAPH.search(name) is not None


def segment_iri(base: str, scenario_id: str, start_pose: str, goal_pose: str) -> str:
    """``segment:<scenario>/<start pose>/<goal pose>`` under the project's base namespace."""
    return f"{base}segments/{scenario_id}/{start_pose}/{goal_pose}"


def segment_index(graphs: Mapping[str, Sequence[Quad]]) -> dict[str, list[Quad]]:
    """The index graphs (action IRI → quads) for the segment metric values in ``graphs``.

    Empty when the graphs hold no segment metric values (a spec, an oracle).  A value
    whose action, poses or run's scenario the graphs do not state is left out: the
    index only repeats what the run's own statements say.
    """
    found = _Facts.of(quad for quads in graphs.values() for quad in quads)
    if found.base is None:
        return {}
    base = found.base
    run_type = base + ids.RUN_TYPE.local
    scenario_of_run: dict[str, str] = {}
    for run in found.typed.get(run_type, ()):
        uuid = found.run_of.get(run)
        scenarios = [
            iri[len(base) :]
            for iri in found.used.get(run, ())
            if iri.startswith(base) and "/" not in iri[len(base) :]
        ]
        if uuid is not None and len(scenarios) == 1:
            scenario_of_run[uuid] = scenarios[0]
    names = ids.Namespaces(base)
    metric_ns = names.fixed[ids.METRIC]
    exsce = names.fixed[ids.EXSCE]
    segment_type = NamedNode(exsce + ids.PATH_SEGMENT.local)
    start_p, goal_p = NamedNode(exsce + ids.START_POSE.local), NamedNode(exsce + ids.GOAL_POSE.local)
    of_p = NamedNode(exsce + ids.SEGMENT_OF.local)
    run_p, robot_p = NamedNode(exsce + ids.RUN_ATTR.local), NamedNode(exsce + ids.ROBOT_ATTR.local)
    index: dict[str, list[Quad]] = {}
    for entity, action in found.generated_by.items():
        metric, value = found.metric_of.get(entity), found.value_of.get(entity)
        start, goal = found.started_by.get(action), found.ended_by.get(action)
        uuid = found.run_of.get(action)
        scenario = scenario_of_run.get(uuid) if uuid is not None else None
        if None in (metric, value, start, goal, scenario):
            continue
        assert metric is not None and value is not None and start is not None and goal is not None
        assert scenario is not None and uuid is not None
        segment_name = segment_iri(base, scenario, _local(start), _local(goal))
        segment = NamedNode(segment_name)
        if segment_name not in index:
            index[segment_name] = [
                Quad(segment, _RDF_TYPE, segment_type, segment),
                Quad(segment, start_p, NamedNode(start), segment),
                Quad(segment, goal_p, NamedNode(goal), segment),
                Quad(segment, of_p, NamedNode(base + scenario), segment),
            ]
        quads = index.get(action)
        if quads is None:
            graph = NamedNode(action)
            quads = index[action] = [Quad(segment, run_p, Literal(uuid), graph)]
            robot = found.robot_of.get(entity)
            if robot is not None:
                quads.append(Quad(segment, robot_p, robot, graph))
        quads.append(Quad(segment, NamedNode(metric_ns + metric), value, quads[0].graph_name))
    return index


def stale_index_graphs(
    store: Store, graphs: Mapping[str, Sequence[Quad]], index: Mapping[str, Sequence[Quad]]
) -> list[str]:
    """Index graphs in ``store`` of the runs ``index`` is about that ``graphs`` and ``index`` lack:
    the actions an older version of a run had, and the segments only they drove (dropped when the
    run is replaced)."""
    from exsce_dsl.store.sparql import term_text

    runs: dict[str, Quad] = {}
    for quads in index.values():
        for quad in quads:
            if quad.predicate.value.endswith(f"/{ids.RUN_ATTR.local}") and isinstance(quad.object, Literal):
                runs.setdefault(quad.object.value, quad)
    if not runs:
        return []
    run_p = next(iter(runs.values())).predicate
    values = " ".join(term_text(Literal(uuid)) for uuid in runs)
    rows = store.select(
        f"SELECT DISTINCT ?g WHERE {{ VALUES ?run {{ {values} }} "
        f"GRAPH ?g {{ ?segment {term_text(run_p)} ?run }} }}"
    )
    found = {g.value for (g,) in rows.rows if isinstance(g, NamedNode)}
    stale = found - set(index) - set(graphs)
    orphans = orphan_segment_graphs(store, found, run_p.value, kept={*index, *graphs})
    return sorted(stale | set(orphans))


def orphan_segment_graphs(
    store: Store, rewritten: Collection[str], run_predicate: str, kept: Collection[str] = ()
) -> list[str]:
    """The segment graphs that only the action graphs ``rewritten`` observe (graphs a write drops
    or writes anew): once they are gone, no run drives the segment any more, and its graph would
    be left behind, an orphan (a run replaced by a version with fewer segments, or with other
    poses).  ``kept``: the graphs the write holds (a segment the new version still drives);
    ``run_predicate``: the IRI of ``exsce:run``."""
    from exsce_dsl.store.sparql import term_text

    actions = sorted(term_text(NamedNode(n)) for n in rewritten if _ACTION_GRAPH.search(n))
    if not actions:
        return []
    run_p = term_text(NamedNode(run_predicate))
    rows = store.select(
        f"SELECT DISTINCT ?segment WHERE {{ VALUES ?g {{ {' '.join(actions)} }} "
        f"GRAPH ?g {{ ?segment {run_p} ?run }} }}"
    )
    seen = {s.value for (s,) in rows.rows if isinstance(s, NamedNode)} - set(kept)
    if not seen:
        return []
    segments = " ".join(term_text(NamedNode(name)) for name in sorted(seen))
    rows = store.select(
        f"SELECT DISTINCT ?segment WHERE {{ VALUES ?segment {{ {segments} }} "
        f"GRAPH ?g {{ ?segment {run_p} ?run }} FILTER(?g NOT IN ({', '.join(actions)})) }}"
    )
    observed = {s.value for (s,) in rows.rows if isinstance(s, NamedNode)}
    return sorted(seen - observed)


def _local(iri: str) -> str:
    return iri.rsplit("/", 1)[-1]


class _Facts:
    """The few statements of a run document the index is made of, by subject."""

    def __init__(self) -> None:
        self.base: str | None = None
        self.typed: dict[str, list[str]] = {}
        self.used: dict[str, list[str]] = {}
        self.started_by: dict[str, str] = {}
        self.ended_by: dict[str, str] = {}
        self.generated_by: dict[str, str] = {}
        self.value_of: dict[str, Literal] = {}
        self.metric_of: dict[str, str] = {}
        self.run_of: dict[str, str] = {}
        self.robot_of: dict[str, Literal] = {}

    @classmethod
    def of(cls, quads: Iterable[Quad]) -> _Facts:
        facts = cls()
        literals: dict[str, dict[str, Literal]] = {}
        """Attributes with literal values whose predicate may be exsce:run, exsce:robot or
        run:metricType (the base namespace is known only once a metric type is seen)."""
        for quad in quads:
            s, p, o = quad.subject, quad.predicate.value, quad.object
            if not isinstance(s, NamedNode):
                continue
            subject = s.value
            if isinstance(o, Literal):
                if p == _VALUE:
                    facts.value_of[subject] = o
                elif p.endswith(_ATTRIBUTE_ENDINGS):
                    literals.setdefault(p, {})[subject] = o
            elif isinstance(o, NamedNode):
                if p == _GENERATED_BY:
                    facts.generated_by[subject] = o.value
                elif p == _STARTED_BY:
                    facts.started_by[subject] = o.value
                elif p == _ENDED_BY:
                    facts.ended_by[subject] = o.value
                elif p == _USED:
                    facts.used.setdefault(subject, []).append(o.value)
                elif p == _RDF_TYPE.value:
                    facts.typed.setdefault(o.value, []).append(subject)
        for predicate in literals:
            if predicate.endswith(_METRIC_TYPE_SUFFIX):
                facts.base = predicate[: -len(_METRIC_TYPE_SUFFIX)]
                break
        if facts.base is not None:
            base = facts.base
            facts.metric_of = {s: o.value for s, o in literals.get(base + _METRIC_TYPE_SUFFIX, {}).items()}
            facts.run_of = {s: o.value for s, o in literals.get(base + ids.RUN_ATTR.local, {}).items()}
            facts.robot_of = literals.get(base + ids.ROBOT_ATTR.local, {})
        return facts
