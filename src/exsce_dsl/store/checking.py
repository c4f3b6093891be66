"""``store check``: what in a store no longer hangs together, and mending what is safe to mend.

Findings, by kind:

* ``orphan graph`` — a graph of a run (named ``<base>runs/run_<uuid>...``: its bundles,
  verdicts, action graphs) whose run activity the store no longer holds; a bag's bundle whose
  bag no stored run generated; a segment graph (``<base>segments/...``) that no stored run's
  action observes (left after ``--replace`` when the run's segments changed).  Nothing reaches
  them: ``--fix`` removes them.
* ``old bag bundle`` — a run's bag bundle named by the bag's file (``exsce:<bag file>_bundle``,
  the scheme before runs named their bag bundles).  ``--fix`` (and ``store migrate``) renames it
  ``<run>:bag_bundle``.
* ``old robot name`` — a robot whose namespace is not its id, named by its id alone (the scheme
  before issue 48; :func:`~exsce_dsl.prov.identifiers.robot_name`).  ``--fix`` (and ``store
  migrate``) renames it, its parts and its bundle in every graph that names them.
* ``run without summary`` — a run whose summary graph (:mod:`.run_summary`) is missing: written
  by an exsce before the summaries, the scenario-wide queries do not see it.  ``--fix`` (and
  ``store migrate``) writes it from the run's own statements.
* ``dangling reference`` — a graph naming something in the runs' namespace that no graph
  describes (a verdict of a metric value gone), or a baseline that learnt from runs the store no
  longer holds.  Not mended: which record is wrong is a judgement (build the baselines again with
  ``exscec baseline SPEC``, judge the runs again with ``exscec verify``).
* ``run without scenario`` — a run whose scenario's graphs are not in the store.  Not mended:
  add the scenario (``exscec compile SPEC --store``).

Revision graphs (``...?revision=N``) are history: they are not checked, except that a run's
revisions go with the run.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

from pyoxigraph import Literal, NamedNode

from exsce_dsl.errors import Remedied
from exsce_dsl.prov import identifiers as ids
from exsce_dsl.prov.identifiers import DEFAULT_NAMESPACE, PROV_NAMESPACE, Namespaces
from exsce_dsl.remedies import FIX_THE_STORE, REBUILD_THE_BASELINE, STORE_THE_SCENARIO
from exsce_dsl.store.base import GraphSet, Store
from exsce_dsl.store.graph_owners import graph_run
from exsce_dsl.store.migrating import old_bag_bundles, renamed_graphs
from exsce_dsl.store.robot_renaming import old_robot_names, renamed_robot_graphs
from exsce_dsl.store.sparql import term_text
from exsce_dsl.store.summary_migration import runs_without_summary, write_summaries

__all__ = ["StoreCheck", "StoreFinding", "check_store"]

ORPHAN = "orphan graph"
OLD_BAG_BUNDLE = "old bag bundle"
OLD_ROBOT_NAME = "old robot name"
DANGLING = "dangling reference"
NO_SCENARIO = "run without scenario"
NO_SUMMARY = "run without summary"


@dataclass(frozen=True)
class StoreFinding:
    """One thing that does not hang together."""

    kind: str
    graph: str
    """The graph it is in (or is)."""
    message: str
    fixable: bool = False
    """Whether ``check_store(fix=True)`` mends it."""
    remedied: Remedied | None = field(default=None, compare=False)
    """The message as a problem and its remedy, when it has one."""

    def line(self, wording: Mapping[str, str] | None = None) -> str:
        """``<graph>: kind: message``, its remedy in ``wording`` (the command line's) if given."""
        message = self.remedied.said(wording) if self.remedied else self.message
        return f"<{self.graph}>: {self.kind}: {message}"


@dataclass(frozen=True)
class StoreCheck:
    """What :func:`check_store` found, and what it mended (with ``fix``)."""

    location: str
    findings: tuple[StoreFinding, ...] = ()
    fixed: tuple[StoreFinding, ...] = field(default=())

    @property
    def clean(self) -> bool:
        """Nothing is left to mend: no finding, or every one fixed."""
        return len(self.fixed) == len(self.findings)

    def summary(self, wording: Mapping[str, str] | None = None) -> str:
        """One line per finding (``fixed:`` before those mended), then a count; remedies in
        ``wording`` (the command line's, ``cli.common.REMEDIES``) when given, else in words."""
        fixed = set(self.fixed)
        lines = [("fixed: " if f in fixed else "") + f.line(wording) for f in self.findings]
        count = len(self.findings)
        if not count:
            lines.append(f"{self.location}: no problem found")
            return "\n".join(lines)
        tail = f"{self.location}: {count} problem{'s' if count != 1 else ''} found"
        if self.fixed:
            tail += f", {len(self.fixed)} fixed"
        elif any(f.fixable for f in self.findings):
            fixable = str(sum(f.fixable for f in self.findings))
            tail = Remedied(tail, FIX_THE_STORE, fixable).said(wording)
        lines.append(tail)
        return "\n".join(lines)


def check_store(store: Store, namespace: str = DEFAULT_NAMESPACE, *, fix: bool = False) -> StoreCheck:
    """Look for orphan graphs, old-scheme bag bundles and robot names, dangling references and runs
    without their scenario in ``store``; with ``fix``, remove the orphans and rename the bag
    bundles in one write, then the robots in another (the other findings are left for a person:
    the module says why)."""
    names = Namespaces(namespace)
    graphs = sorted(store.graph_names())
    runs = _stored_runs(store, names)
    moves = old_bag_bundles(store, namespace)
    findings: list[StoreFinding] = []
    findings += _orphan_run_graphs(graphs, runs)
    findings += _orphan_bag_graphs(store, names, runs)
    findings += _orphan_segment_graphs(store, names, graphs, runs)
    findings += [
        StoreFinding(OLD_BAG_BUNDLE, m.old, f"the bag of run {m.run}, to be named <{m.new}>", fixable=True)
        for m in moves
    ]
    renames = old_robot_names(store, namespace)
    findings += [
        StoreFinding(
            OLD_ROBOT_NAME, r.old + "_bundle", f"robot <{r.old}>, to be named <{r.new}>", fixable=True
        )
        for r in renames
    ]
    unsummarised = [run for run in runs_without_summary(graphs) if run in runs]
    findings += [
        StoreFinding(
            NO_SUMMARY,
            names.of_run(run)[:-1] + "_bundle",
            f"run {run}, which the scenario-wide questions do not see",
            fixable=True,
        )
        for run in unsummarised
    ]
    findings += _dangling(store, names, runs)
    findings += _runs_without_scenario(store, names)
    if not fix or not any(f.fixable for f in findings):
        return StoreCheck(store.location, tuple(findings))
    removed = {f.graph for f in findings if f.fixable and f.kind == ORPHAN}
    writes = renamed_graphs(store, [m for m in moves if m.old not in removed])
    writes.update({name: [] for name in removed})
    store.write(GraphSet(writes), replace=set(writes))
    robot_writes = renamed_robot_graphs(store, renames)  # the orphans are gone by now
    if robot_writes:
        store.write(GraphSet(robot_writes), replace=set(robot_writes))
    if unsummarised:
        write_summaries(store, unsummarised, store.graph_names(), namespace)
    return StoreCheck(store.location, tuple(findings), tuple(f for f in findings if f.fixable))


def _not_revision(variable: str) -> str:
    return f'FILTER(!CONTAINS(STR(?{variable}), "revision="))'


def _iri(names: Namespaces, term: ids.Term) -> str:
    return term_text(NamedNode(names.iri(term)))


def _stored_runs(store: Store, names: Namespaces) -> set[str]:
    rows = store.select(
        f"SELECT DISTINCT ?run WHERE {{ GRAPH ?g {{ ?a a {_iri(names, ids.RUN_TYPE)} ; "
        f"{_iri(names, ids.RUN_ATTR)} ?run }} {_not_revision('g')} }}"
    )
    return {run.value for (run,) in rows.rows if isinstance(run, Literal)}


def _orphan_run_graphs(graphs: Sequence[str], runs: set[str]) -> list[StoreFinding]:
    found = []
    for graph in graphs:
        run = graph_run(graph)
        if run is not None and run not in runs:
            found.append(
                StoreFinding(ORPHAN, graph, f"a graph of run {run}, which the store does not hold", True)
            )
    return found


def _orphan_bag_graphs(store: Store, names: Namespaces, runs: set[str]) -> list[StoreFinding]:
    """Bag bundles outside any run's namespace whose bag no stored run generated."""
    rows = store.select(
        f"SELECT DISTINCT ?g ?bag WHERE {{ GRAPH ?g {{ ?bag a {_iri(names, ids.ROS_BAGS)} }}\n"
        f"  {_not_revision('g')}\n"
        f"  FILTER NOT EXISTS {{ GRAPH ?r {{ ?bag <{PROV_NAMESPACE}wasGeneratedBy> ?a . "
        f"?a a {_iri(names, ids.RUN_TYPE)} }} }} }}"
    )
    found = []
    for graph, bag in rows.rows:
        if isinstance(graph, NamedNode) and isinstance(bag, NamedNode) and graph_run(graph.value) is None:
            message = f"the bundle of bag <{bag.value}>, which no stored run generated"
            found.append(StoreFinding(ORPHAN, graph.value, message, True))
    return found


def _orphan_segment_graphs(
    store: Store, names: Namespaces, graphs: Sequence[str], runs: set[str]
) -> list[StoreFinding]:
    """Segment graphs that no action graph of a stored run observes."""
    prefix = names.base + "segments/"
    segments = [g for g in graphs if g.startswith(prefix) and "revision=" not in g]
    if not segments:
        return []
    rows = store.select(
        f"SELECT DISTINCT ?segment ?run WHERE {{ GRAPH ?g {{ ?segment {_iri(names, ids.RUN_ATTR)} ?run }}\n"
        f"  FILTER(?g != ?segment && STRSTARTS(STR(?segment), {term_text(Literal(prefix))})) }}"
    )
    observed = {
        s.value
        for s, r in rows.rows
        if isinstance(s, NamedNode) and isinstance(r, Literal) and r.value in runs
    }
    return [
        StoreFinding(ORPHAN, g, "a path segment that no stored run's action observes", True)
        for g in segments
        if g not in observed
    ]


def _dangling(store: Store, names: Namespaces, runs: set[str]) -> list[StoreFinding]:
    """IRIs of the runs' namespace that no graph describes, and baselines of runs not stored."""
    run_ns = names.fixed[ids.RUN]
    rows = store.select(
        "SELECT DISTINCT ?g ?o WHERE { GRAPH ?g { ?s ?p ?o }\n"
        f"  FILTER(isIRI(?o) && STRSTARTS(STR(?o), {term_text(Literal(run_ns))})) {_not_revision('g')}\n"
        "  FILTER NOT EXISTS { GRAPH ?h { ?o ?p2 ?o2 } } }"
    )
    found = []
    for graph, target in rows.rows:
        if not isinstance(graph, NamedNode) or not isinstance(target, NamedNode):
            continue
        owner = graph_run(graph.value)
        if owner is not None and owner not in runs:
            continue  # an orphan graph: said once, as that
        found.append(StoreFinding(DANGLING, graph.value, f"names <{target.value}>, which no graph describes"))
    learnt = store.select(
        f"SELECT DISTINCT ?g ?runs WHERE {{ GRAPH ?g {{ ?s {_iri(names, ids.ORACLE_RUNS)} ?runs }} "
        f"{_not_revision('g')} }}"
    )
    for graph, listed in learnt.rows:
        if not isinstance(graph, NamedNode) or not isinstance(listed, Literal):
            continue
        owner = graph_run(graph.value)
        if owner is not None and owner not in runs:
            continue
        missing = sorted({r for r in listed.value.split() if r not in runs})
        if missing:
            shown = ", ".join(missing[:3]) + (f" and {len(missing) - 3} more" if len(missing) > 3 else "")
            remedied = Remedied(
                f"learnt from run {shown}, which the store does not hold", REBUILD_THE_BASELINE
            )
            found.append(StoreFinding(DANGLING, graph.value, remedied.said(), remedied=remedied))
    return sorted(set(found), key=lambda f: (f.graph, f.message))


def _runs_without_scenario(store: Store, names: Namespaces) -> list[StoreFinding]:
    run_ns, base = names.fixed[ids.RUN], names.base
    rows = store.select(
        f"SELECT DISTINCT ?g ?run ?scenario WHERE {{ GRAPH ?g {{ ?a a {_iri(names, ids.RUN_TYPE)} ; "
        f"{_iri(names, ids.RUN_ATTR)} ?run ; <{PROV_NAMESPACE}used> ?scenario }} {_not_revision('g')}\n"
        f"  FILTER(isIRI(?scenario) && STRSTARTS(STR(?scenario), {term_text(Literal(base))}) "
        f"&& !STRSTARTS(STR(?scenario), {term_text(Literal(run_ns))}))\n"
        "  FILTER NOT EXISTS { GRAPH ?h { ?scenario a ?type } } }"
    )
    found = []
    for graph, run, scenario in rows.rows:
        if not all(isinstance(t, NamedNode | Literal) for t in (graph, run, scenario)):
            continue
        assert graph is not None and run is not None and scenario is not None
        if "/" in scenario.value[len(base) :]:
            continue  # not a scenario's entity
        problem = f"run {run.value} is a run of <{scenario.value}>, which the store does not hold"
        remedied = Remedied(problem, STORE_THE_SCENARIO)
        found.append(StoreFinding(NO_SCENARIO, graph.value, remedied.said(), remedied=remedied))
    return found
