"""``store migrate`` and ``store check --fix`` on a store whose robots are named the way exscec named
every robot before issue 48: by id alone (``robot:root_robot``, ``robots/root_robot/...``,
``robots/r1_bundle``), though the robot's namespace is not its id.

The old store is written in the test: the yard (``r1`` at the root, ``r2`` in ``/r2``) compiled,
run and ingested by the current code, then every IRI and graph name under ``robots/r1.<digest>``
rewritten, by the test's own string replacement, to ``robots/r1``.  Migrating must give back the current store quad for quad.
"""

from __future__ import annotations

from collections import Counter
from pathlib import Path

from pyoxigraph import BlankNode, NamedNode, Quad

from exsce_dsl import api
from exsce_dsl.lang import load_spec
from exsce_dsl.prov import DEFAULT_NAMESPACE
from exsce_dsl.runs.ingest import ingest_bags
from exsce_dsl.sim.run import simulate
from exsce_dsl.store.base import GraphSet
from exsce_dsl.store.embedded import EmbeddedStore
from exsce_dsl.store.queries.terms import run_query

from tests.support.cli import exscec_here
from tests.support.yard_spec import yard_text

ROBOTS = f"{DEFAULT_NAMESPACE}robots/"


def _quads(store: EmbeddedStore) -> Counter[tuple[str, ...]]:
    """The store's quads, blank nodes unlabelled (a graph written again gets new labels)."""
    return Counter(
        tuple(
            "_:" if isinstance(t, BlankNode) else str(t)
            for t in (q.subject, q.predicate, q.object, q.graph_name)
        )
        for q in store.quads()
    )


def _old(term: object, scoped: str) -> object:
    """``term`` as the code before issue 48 named it: ``r1.<digest>`` was ``r1``."""
    if isinstance(term, NamedNode) and term.value.startswith(ROBOTS + scoped):
        return NamedNode(ROBOTS + "r1" + term.value[len(ROBOTS + scoped) :])
    return term


def test_store_migrate_names_an_old_stores_robots_by_their_declaration(tmp_path: Path) -> None:
    spec = tmp_path / "yard.exsce"
    spec.write_text(yard_text("torso no").replace("area yard {", "area yard_area {"))
    scenario = load_spec(spec).scenario()
    bags = [run.bag for run in simulate(scenario, tmp_path / "bags", seed=7)]
    with EmbeddedStore(tmp_path / "store") as store:
        ingest_bags(bags, scenario, store)
        current = _quads(store)
        (scoped,) = {
            q.subject.value[len(ROBOTS) :].split("/")[0]
            for q in store.quads()
            if isinstance(q.subject, NamedNode) and q.subject.value.startswith(ROBOTS + "r1.")
        }
        assert any(
            q.subject.value == ROBOTS + "r2" for q in store.quads() if isinstance(q.subject, NamedNode)
        )
        old: dict[str, list[Quad]] = {}
        for quad in store.quads():
            graph = _old(quad.graph_name, scoped)
            assert isinstance(graph, NamedNode)
            old.setdefault(quad.graph_name.value, [])  # type: ignore[union-attr]
            old.setdefault(graph.value, []).append(
                Quad(_old(quad.subject, scoped), quad.predicate, _old(quad.object, scoped), graph)  # type: ignore[arg-type]
            )
        store.write(GraphSet(old), replace=set(old))
        assert f"{ROBOTS}r1_bundle" in store.graph_names()
        robots = run_query(store, "robots", {"scenario": scenario.id})
        assert [row[0].value for row in robots.rows] == ["r1", "r2"]  # the queries read the old names too
        found = api.check_store(store)
        assert [(f.kind, f.graph) for f in found.findings] == [("old robot name", f"{ROBOTS}r1_bundle")]

    done = exscec_here("store", "migrate", "--store", str(tmp_path / "store"))
    assert done.returncode == 0, done.stderr
    assert f"{ROBOTS}r1 -> {ROBOTS}{scoped}" in done.stdout
    assert done.stdout.splitlines()[-1].endswith("robots named by their declaration: 1")
    with EmbeddedStore(tmp_path / "store") as after:
        assert _quads(after) == current
        assert api.check_store(after).findings == ()
        assert api.migrate_store(after).robots == ()
