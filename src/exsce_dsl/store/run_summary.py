"""Run summaries: what the questions about a scenario's runs read, as ranges of one index.

A run's PROV (its activity, values, hotspots, verdicts) answers "which runs of S failed?" only
by joining every run's activity to its values: at ten thousand runs that took seconds to a
minute (``run_defects`` 54 s).  So beside a run's bundles the store writes, in the same
transaction, a small *summary* graph per run, and beside a verification's verdicts one per
verdicts bundle.  Their subjects are *keys* shared by every run of a scenario, each described
once in a graph of its own name (idempotent: every run writes the same):

    GRAPH summary:scenario/S { summary:scenario/S a exsce:ScenarioRuns ; exsce:summaryOf exsce:S }
    GRAPH summary:scenario/S/violations/max_velocity/tiago1 {
        ... a exsce:ViolationSeries ; exsce:summaryOf exsce:S ;
            exsce:summaryMetric "max_velocity" ; exsce:summaryRobot "tiago1" }   # "mission": no robot
    GRAPH summary:scenario/S/hotspots/max_velocity { ... a exsce:HotspotSeries ; ... }
    GRAPH summary:metric/distance_travelled { ... a exsce:MetricValues ; exsce:summaryMetric ... }

    GRAPH run:run_<uuid>/summary {                  # what the run's ingest said
        summary:scenario/S exsce:summaryRun "<uuid>" ; exsce:summaryStart ... ; exsce:summaryEnd ... ;
            exsce:summaryStatus "cancelled" ; exsce:summaryBag <bag> .  <bag> exsce:summaryBagPath "..." .
        summary:scenario/S/violations/max_velocity/tiago1 exsce:violationSeconds 1.3 .
        summary:scenario/S/hotspots/max_velocity exsce:hotspotCount 2 .
        summary:metric/distance_travelled exsce:summaryRun "<uuid>" .
        summary:run-ids/5e1a exsce:summaryRun "<uuid>" .          # the uuid's first four characters
        summary:scenario/S exsce:defect run:run_<uuid>/defect-0 .   # one per defect (none: good run)
        run:run_<uuid>/defect-0 a exsce:RunDefect ; exsce:summaryRun "<uuid>" ; exsce:defectKind ... }
    GRAPH run:run_<uuid>/verdicts_summary {         # its last verification's
        run:run_<uuid>/validation exsce:baselineRun "<uuid>" .  # a run its expectations came from
        ... its defects, as above }

"The mean violation time of max_velocity per robot" is then the key's values, one range of
the subject index (``GRAPH ?g { <key> exsce:violationSeconds ?s }``); "the runs a baseline may
not learn from" the scenario key's defects, as many rows as defects.  A summary is derived from
the run's own statements by :func:`run_summary`; it says nothing they do not.  Written in the
write of the run (its commit step on a server that writes in steps:
:mod:`exsce_dsl.store.run_commit`), replaced with it, and with its verdicts.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field

from pyoxigraph import Literal, NamedNode, Quad

from exsce_dsl.prov import identifiers as ids
from exsce_dsl.prov.identifiers import PROV_NAMESPACE, Namespaces

__all__ = ["RUN_ID_BUCKET", "is_summary_graph", "run_id_bucket", "run_summary", "summary_base"]

RUN_ID_BUCKET = 4
"""The characters of a uuid that name its run-id bucket (a run id is given with four or more)."""

_SUMMARY_GRAPH = re.compile(
    rf"/runs/run_[^/]+/(?:{ids.RUN_SUMMARY}|{ids.VERDICTS_SUMMARY})$|/summaries/(?:scenario|metric)/"
)
_RDF_TYPE = ids.RDF_TYPE
_USED = f"{PROV_NAMESPACE}used"
_GENERATED_BY = f"{PROV_NAMESPACE}wasGeneratedBy"
_STARTED = f"{PROV_NAMESPACE}startedAtTime"
_ENDED = f"{PROV_NAMESPACE}endedAtTime"
_VALUE = f"{PROV_NAMESPACE}value"
_DEFECT_OUTCOMES = ("failed", "inconclusive", "unjudged")
_READ = (
    *(
        f"/{t.local}"
        for t in (ids.RUN_ATTR, ids.METRIC_ATTR, ids.ROBOT_ATTR, ids.FILE_PATH, ids.MISSION_STATUS)
    ),
    *(
        f"/{t.local}"
        for t in (ids.METRIC_TYPE, ids.HOTSPOT_TYPE, ids.ORACLE_OUTCOME, ids.ORACLE_RELATIONSHIP)
    ),
    *(f"/{t.local}" for t in (ids.ORACLE_RUNS, ids.SCENARIO_ATTR)),
    _RDF_TYPE,
    _USED,
    _GENERATED_BY,
    _STARTED,
    _ENDED,
    _VALUE,
)
"""The endings of the predicates a summary reads."""


def is_summary_graph(name: str) -> bool:
    """True for the name of a graph of the run summaries (a run's, a verification's or a key's)."""
    return _SUMMARY_GRAPH.search(name) is not None


def summary_base(namespace: str) -> str:
    """Where the summaries' keys live: ``<base>summaries/``."""
    return f"{namespace}summaries/"


def run_id_bucket(namespace: str, uuid: str) -> str:
    """The key of the runs whose uuid starts like ``uuid``: ``summary:run-ids/<4 characters>``."""
    return f"{summary_base(namespace)}run-ids/{uuid[:RUN_ID_BUCKET]}"


@dataclass
class _Subjects:
    """The statements of a write, by subject and predicate (objects in order of appearance)."""

    facts: dict[str, dict[str, list[NamedNode | Literal]]] = field(default_factory=dict)
    graphs: dict[tuple[str, str, str], set[str]] = field(default_factory=dict)
    """Where each ``rdf:type`` and ``prov:wasGeneratedBy`` statement is: (s, p, o) → graph names."""
    by_type: dict[str, list[str]] = field(default_factory=dict)
    by_generator: dict[str, list[str]] = field(default_factory=dict)

    @classmethod
    def of(cls, quads: Iterable[Quad]) -> _Subjects:
        """The statements a summary is made of (a third of a run's: its predicates end so)."""
        found = cls()
        for quad in quads:
            s, o, predicate = quad.subject, quad.object, quad.predicate.value
            if not predicate.endswith(_READ) or not isinstance(s, NamedNode):
                continue
            if isinstance(o, NamedNode | Literal):
                found.facts.setdefault(s.value, {}).setdefault(predicate, []).append(o)
                if predicate == _RDF_TYPE or predicate == _GENERATED_BY:
                    key = (s.value, predicate, o.value)
                    if key not in found.graphs:
                        index = found.by_type if predicate == _RDF_TYPE else found.by_generator
                        index.setdefault(o.value, []).append(s.value)
                    found.graphs.setdefault(key, set()).add(str(quad.graph_name))
        return found

    def values(self, subject: str, predicate: str) -> list[NamedNode | Literal]:
        return self.facts.get(subject, {}).get(predicate, [])

    def text(self, subject: str, predicate: str) -> str | None:
        found = self.values(subject, predicate)
        return found[0].value if found else None

    def typed(self, iri: str) -> list[str]:
        return self.by_type.get(iri, [])

    def generated_by(self, activity: str) -> list[str]:
        return self.by_generator.get(activity, [])


def run_summary(graphs: Mapping[str, Sequence[Quad]]) -> dict[str, list[Quad]]:
    """The summary graphs (name → quads) of the runs and verifications in ``graphs``, with the
    descriptions of their keys.  Empty for anything else (a spec, an oracle)."""
    subjects = _Subjects.of(q for quads in graphs.values() for q in quads)
    out: dict[str, list[Quad]] = {}
    for base in _bases(subjects):
        _Summariser(subjects, Namespaces(base), out).summarise()
    return out


def _bases(subjects: _Subjects) -> list[str]:
    """The base namespaces of the runs and validations the statements hold."""
    bases = set()
    for facts in subjects.facts.values():
        for kind in facts.get(_RDF_TYPE, ()):
            for local in (ids.RUN_TYPE.local, ids.VALIDATION_TYPE.local):
                if kind.value.endswith(f"/{local}"):
                    base = kind.value[: -len(local)]
                    if base + ids.RUN_ATTR.local in facts:
                        bases.add(base)
    return sorted(bases)


class _Summariser:
    def __init__(self, subjects: _Subjects, names: Namespaces, out: dict[str, list[Quad]]) -> None:
        self.subjects, self.names, self.out = subjects, names, out
        self.base = names.fixed[ids.EXSCE]
        self.keys = summary_base(self.base)

    def p(self, term: ids.Term) -> NamedNode:
        return NamedNode(self.names.iri(term))

    def summarise(self) -> None:
        for activity in self.subjects.typed(self.names.iri(ids.RUN_TYPE)):
            uuid = self.subjects.text(activity, self.names.iri(ids.RUN_ATTR))
            if uuid is not None:
                self._run(activity, uuid)
        for validation in self.subjects.typed(self.names.iri(ids.VALIDATION_TYPE)):
            uuid = self.subjects.text(validation, self.names.iri(ids.RUN_ATTR))
            scenario = self.subjects.text(validation, self.names.iri(ids.SCENARIO_ATTR))
            if uuid is not None and scenario is not None:
                self._verdicts(validation, uuid, scenario)

    def _describe(self, key: str, kind: ids.Term, scenario: str | None, metric: str | None = None,
                  robot: str | None = None) -> NamedNode:  # fmt: skip
        node = NamedNode(key)
        if key not in self.out:
            quads = [Quad(node, NamedNode(_RDF_TYPE), self.p(kind), node)]
            if scenario is not None:
                quads.append(Quad(node, self.p(ids.SUMMARY_OF), NamedNode(self.base + scenario), node))
            if metric is not None:
                quads.append(Quad(node, self.p(ids.SUMMARY_METRIC), Literal(metric), node))
            if robot is not None:
                quads.append(Quad(node, self.p(ids.SUMMARY_ROBOT), Literal(robot), node))
            self.out[key] = quads
        return node

    def _scenarios(self, activity: str) -> list[str]:
        """The scenarios (ids) the run used: entities named right under the base namespace."""
        found = []
        for used in self.subjects.values(activity, _USED):
            local = used.value[len(self.base) :] if used.value.startswith(self.base) else ""
            if local and "/" not in local and ids.is_name(local):
                found.append(local)
        return sorted(set(found))

    def _run(self, activity: str, uuid: str) -> None:
        s, iri = self.subjects, self.names.iri
        graph = NamedNode(self.names.of_run(uuid) + ids.RUN_SUMMARY)
        run = Literal(uuid)
        made = s.generated_by(activity)
        violations = [e for e in made if s.text(e, iri(ids.METRIC_TYPE)) == "violation_duration"]
        hotspots = [h for h in made if s.values(h, iri(ids.HOTSPOT_TYPE))]
        # as the run's bundle says: the entities generated by the run there (its bag)
        home = s.graphs.get((activity, _RDF_TYPE, iri(ids.RUN_TYPE)), set())
        bags = [b for b in made if s.graphs.get((b, _GENERATED_BY, activity), set()) & home]
        status = s.values(activity, iri(ids.MISSION_STATUS))
        defects = [{ids.DEFECT_KIND: Literal("mission"), ids.DEFECT_SUBJECT: o} for o in status]
        defects += [self._violation_defect(e) for e in violations if self._seconds(e) > 0]
        defects += [
            self._hotspot_defect(h, kind) for h in hotspots for kind in s.values(h, iri(ids.HOTSPOT_TYPE))
        ]
        quads: list[Quad] = []
        for scenario in self._scenarios(activity):
            key = self._describe(f"{self.keys}scenario/{scenario}", ids.SCENARIO_RUNS, scenario)
            quads.append(Quad(key, self.p(ids.SUMMARY_RUN), run, graph))
            for term, predicate in ((ids.SUMMARY_START, _STARTED), (ids.SUMMARY_END, _ENDED)):
                quads += [Quad(key, self.p(term), o, graph) for o in s.values(activity, predicate)]
            quads += [Quad(key, self.p(ids.SUMMARY_STATUS), o, graph) for o in status]
            quads += [Quad(key, self.p(ids.SUMMARY_BAG), NamedNode(b), graph) for b in bags]
            for entity in violations:
                quads += self._violation(graph, scenario, entity)
            for metric in sorted({h.value for e in hotspots for h in s.values(e, iri(ids.HOTSPOT_TYPE))}):
                series = f"{self.keys}scenario/{scenario}/hotspots/{metric}"
                key_h = self._describe(series, ids.HOTSPOT_SERIES, scenario, metric)
                count = sum(
                    1 for h in hotspots if any(t.value == metric for t in s.values(h, iri(ids.HOTSPOT_TYPE)))
                )
                quads.append(Quad(key_h, self.p(ids.HOTSPOT_COUNT), Literal(count), graph))
            quads += self._defects(graph, key, run, defects)
        for bag in bags:
            quads += [
                Quad(NamedNode(bag), self.p(ids.SUMMARY_BAG_PATH), o, graph)
                for o in s.values(bag, iri(ids.FILE_PATH))
            ]
        for metric in self._metrics(activity, uuid):
            key_m = self._describe(f"{self.keys}metric/{metric}", ids.METRIC_VALUES, None, metric)
            quads.append(Quad(key_m, self.p(ids.SUMMARY_RUN), run, graph))
        quads.append(Quad(NamedNode(run_id_bucket(self.base, uuid)), self.p(ids.SUMMARY_RUN), run, graph))
        self.out[graph.value] = quads

    def _seconds(self, entity: str) -> float:
        found = self.subjects.values(entity, _VALUE)
        try:
            return float(found[0].value) if found else 0.0
        except ValueError:
            return 0.0

    def _violation(self, graph: NamedNode, scenario: str, entity: str) -> list[Quad]:
        s, iri = self.subjects, self.names.iri
        metric, robot = s.text(entity, iri(ids.METRIC_ATTR)), s.text(entity, iri(ids.ROBOT_ATTR))
        if metric is None:
            return []
        series = f"{self.keys}scenario/{scenario}/violations/{metric}/{robot or 'mission'}"
        key = self._describe(series, ids.VIOLATION_SERIES, scenario, metric, robot)
        return [Quad(key, self.p(ids.VIOLATION_SECONDS), o, graph) for o in s.values(entity, _VALUE)]

    def _violation_defect(self, entity: str) -> dict[ids.Term, NamedNode | Literal]:
        s, iri = self.subjects, self.names.iri
        defect: dict[ids.Term, NamedNode | Literal] = {ids.DEFECT_KIND: Literal("violation")}
        for term, found in ((ids.DEFECT_SUBJECT, s.values(entity, iri(ids.METRIC_ATTR))),
                            (ids.DEFECT_ROBOT, s.values(entity, iri(ids.ROBOT_ATTR))),
                            (ids.DEFECT_SECONDS, s.values(entity, _VALUE))):  # fmt: skip
            if found:
                defect[term] = found[0]
        return defect

    def _hotspot_defect(self, hotspot: str, kind: NamedNode | Literal) -> dict[ids.Term, NamedNode | Literal]:
        defect: dict[ids.Term, NamedNode | Literal] = {
            ids.DEFECT_KIND: Literal("hotspot"),
            ids.DEFECT_SUBJECT: kind,
            ids.DEFECT_HOTSPOT: NamedNode(hotspot),
        }
        robot = self.subjects.values(hotspot, self.names.iri(ids.ROBOT_ATTR))
        if robot:
            defect[ids.DEFECT_ROBOT] = robot[0]
        return defect

    def _defects(self, graph: NamedNode, key: NamedNode, run: Literal,
                 defects: Sequence[Mapping[ids.Term, NamedNode | Literal]]) -> list[Quad]:  # fmt: skip
        """The defects as resources ``<run>:<graph's name>-defect-<n>``, in an order of what they
        are about, never of their seconds (the same defects of two runs get the same names)."""
        quads: list[Quad] = []
        ordered = sorted(
            defects, key=lambda d: sorted((t.local, v.value) for t, v in d.items() if t != ids.DEFECT_SECONDS)
        )
        for number, defect in enumerate(ordered):
            node = NamedNode(f"{graph.value}-defect-{number}")
            quads += [Quad(key, self.p(ids.DEFECT), node, graph),
                      Quad(node, NamedNode(_RDF_TYPE), self.p(ids.RUN_DEFECT), graph),
                      Quad(node, self.p(ids.SUMMARY_RUN), run, graph)]  # fmt: skip
            quads += [Quad(node, self.p(term), value, graph) for term, value in defect.items()]
        return quads

    def _metrics(self, activity: str, uuid: str) -> list[str]:
        """The metric types of the run's values: entities of the run, or generated by it or one of
        its actions."""
        s, iri = self.subjects, self.names.iri
        metric_type, run_attr = iri(ids.METRIC_TYPE), iri(ids.RUN_ATTR)
        ours = {activity} | {
            a for a, p in s.facts.items() if any(o.value == uuid for o in p.get(run_attr, ()))
        }
        found: set[str] = set()
        for subject, facts in s.facts.items():
            if metric_type in facts and (
                subject in ours or any(o.value in ours for o in facts.get(_GENERATED_BY, ()))
            ):
                found.update(o.value for o in facts[metric_type])
        return sorted(found)

    def _verdicts(self, validation: str, uuid: str, scenario: str) -> None:
        s, iri = self.subjects, self.names.iri
        graph = NamedNode(self.names.of_run(uuid) + ids.VERDICTS_SUMMARY)
        defects = []
        for verdict in s.generated_by(validation):
            outcome, relation = (
                s.values(verdict, iri(ids.ORACLE_OUTCOME)),
                s.values(verdict, iri(ids.ORACLE_RELATIONSHIP)),
            )
            if not outcome or outcome[0].value not in _DEFECT_OUTCOMES or not relation:
                continue
            subject = Literal(_verdict_subject(verdict, relation[0].value))
            defects.append(
                {ids.DEFECT_KIND: outcome[0], ids.DEFECT_RELATION: relation[0], ids.DEFECT_SUBJECT: subject}
            )
        key = self._describe(f"{self.keys}scenario/{scenario}", ids.SCENARIO_RUNS, scenario)
        # the runs its expectations came from, one statement each (oracle:runs is one text)
        runs = sorted(
            {
                r
                for v in s.generated_by(validation)
                for o in s.values(v, iri(ids.ORACLE_RUNS))
                for r in o.value.split()
            }
        )
        baseline = [Quad(NamedNode(validation), self.p(ids.BASELINE_RUN), Literal(r), graph) for r in runs]
        self.out[graph.value] = baseline + self._defects(graph, key, Literal(uuid), defects)


def _verdict_subject(verdict: str, relation: str) -> str:
    """The oracle a verdict entity is of: ``<run>/verdict-<oracle>[-vs-<base>]-<relation>`` → oracle."""
    name = verdict.split("/verdict-", 1)[-1]
    name = name.removesuffix(f"-{relation}")
    return name.split("-vs-", 1)[0]
