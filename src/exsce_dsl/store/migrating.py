"""Moving an old store to the current identities: a run's bag bundle named by the run, and each
robot by :func:`~exsce_dsl.prov.identifiers.robot_name` (:mod:`.robot_renaming`).

Before issue 48 a run's bag bundle was named by the bag's file, ``exsce:<bag file>_bundle`` (or,
for a bag that was a run of a second scenario too, ``<run>:<bag file>_bundle``), so two
recordings with one file name could not share a store.  Now it is ``<run>:bag_bundle``
(``<base>runs/run_<uuid>/bag_bundle``).  :func:`old_bag_bundles` finds the graphs still named
the old way, with the run whose bag each describes; :func:`migrate_store` renames them, in one
write.  The bag entity and its statements do not change: only the graph's name.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from pyoxigraph import Literal, NamedNode, Quad

from exsce_dsl.prov import identifiers as ids
from exsce_dsl.prov.identifiers import DEFAULT_NAMESPACE, PROV_NAMESPACE, Namespaces
from exsce_dsl.store.base import GraphSet, Store
from exsce_dsl.store.robot_renaming import RobotRename, old_robot_names, renamed_robot_graphs
from exsce_dsl.store.sparql import term_text
from exsce_dsl.store.summary_migration import runs_without_summary, write_summaries

__all__ = ["BagBundleMove", "MigrationReport", "migrate_store", "old_bag_bundles", "renamed_graphs"]


@dataclass(frozen=True)
class BagBundleMove:
    """A bag bundle under its old name, and the name it has now."""

    old: str
    new: str
    run: str
    """The uuid of the run that generated the bag."""


@dataclass(frozen=True)
class MigrationReport:
    """What :func:`migrate_store` did."""

    location: str
    moved: tuple[BagBundleMove, ...] = ()
    robots: tuple[RobotRename, ...] = ()
    """The robots renamed (each in every graph that names it)."""
    summarised: int = 0
    """The runs given the summary the scenario-wide queries read (:mod:`.run_summary`)."""

    def summary(self) -> str:
        """One line per graph or robot moved, then a count."""
        lines = [f"{m.old} -> {m.new}" for m in self.moved] + [f"{r.old} -> {r.new}" for r in self.robots]
        done = [f"bag bundles named by their run: {len(self.moved)}"] if self.moved else []
        done += [f"robots named by their declaration: {len(self.robots)}"] if self.robots else []
        done += [f"runs given their summary: {self.summarised}"] if self.summarised else []
        if done:
            lines.append(f"{self.location}: {'; '.join(done)}")
        else:
            lines.append(
                f"{self.location}: nothing to migrate "
                "(every bag bundle is named by its run, every robot by its declaration, every run has "
                "its summary)"
            )
        return "\n".join(lines)


def bag_bundle_name(run: str, namespace: str = DEFAULT_NAMESPACE) -> str:
    """The name of run ``run``'s bag bundle: ``<base>runs/run_<uuid>/bag_bundle``."""
    return Namespaces(namespace).of_run(run) + ids.BAG_BUNDLE


def old_bag_bundles(store: Store, namespace: str = DEFAULT_NAMESPACE) -> list[BagBundleMove]:
    """The graphs describing a stored run's bag that are not named by the run, sorted."""
    names = Namespaces(namespace)
    rows = store.select(
        "SELECT DISTINCT ?g ?run WHERE {\n"
        f"  GRAPH ?g {{ ?bag a {term_text(NamedNode(names.iri(ids.ROS_BAGS)))} }}\n"
        f"  GRAPH ?r {{ ?bag {term_text(NamedNode(PROV_NAMESPACE + 'wasGeneratedBy'))} ?activity .\n"
        f"    ?activity a {term_text(NamedNode(names.iri(ids.RUN_TYPE)))} ;\n"
        f"      {term_text(NamedNode(names.iri(ids.RUN_ATTR)))} ?run }}\n"
        '  FILTER(!CONTAINS(STR(?g), "revision=") && !CONTAINS(STR(?r), "revision="))\n'
        "}"
    )
    moves = []
    for graph, run in rows.rows:
        if not isinstance(graph, NamedNode) or not isinstance(run, Literal):
            continue
        new = bag_bundle_name(run.value, namespace)
        if graph.value != new:
            moves.append(BagBundleMove(graph.value, new, run.value))
    return sorted(moves, key=lambda m: (m.old, m.run))


def renamed_graphs(store: Store, moves: Sequence[BagBundleMove]) -> dict[str, list[Quad]]:
    """The writes that rename ``moves``: each old graph emptied, its quads under the new name."""
    old = store.graphs([m.old for m in moves])
    writes: dict[str, list[Quad]] = {}
    for move in moves:
        target = NamedNode(move.new)
        writes.setdefault(move.new, []).extend(
            Quad(q.subject, q.predicate, q.object, target) for q in old[move.old]
        )
        writes.setdefault(move.old, [])
    return writes


def migrate_store(store: Store, namespace: str = DEFAULT_NAMESPACE) -> MigrationReport:
    """Rename every old-scheme bag bundle of ``store`` to its run's name, in one write, then every
    robot named the old way (:mod:`.robot_renaming`), in another, then write the run summaries
    the store lacks (:mod:`.summary_migration`), a batch of runs a write."""
    moves = old_bag_bundles(store, namespace)
    if moves:
        writes = renamed_graphs(store, moves)
        store.write(GraphSet(writes), replace=set(writes))
    renames = old_robot_names(store, namespace)
    if renames:
        robot_writes = renamed_robot_graphs(store, renames)
        store.write(GraphSet(robot_writes), replace=set(robot_writes))
    names = store.graph_names()
    summarised = write_summaries(store, runs_without_summary(names), names, namespace)
    return MigrationReport(store.location, tuple(moves), tuple(renames), summarised)
