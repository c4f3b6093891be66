"""``store check`` and ``store migrate`` (issue 48): nothing found on a store the normal paths
wrote (ingest, ingest --replace, baseline, verify twice); a damaged store's orphan graphs,
dangling references and runs without their scenario found, and the orphans mended by --fix; an
old store, whose bag bundles were named by the bag's file, moved to bundles named by their run.

The old store is written in the test: a store the current code wrote, with each run's bag bundle
moved back to the name the code before issue 48 gave it (``exsce:<bag file>_bundle``, and
``<run>:<bag file>_bundle`` for a bag that was a run of a second scenario).  The graphs'
statements were the same then: only their names differ.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from pyoxigraph import Literal, NamedNode, Quad

from exsce_dsl import api
from exsce_dsl.lang import load_spec
from exsce_dsl.oracles.judging import verify_runs
from exsce_dsl.prov import DEFAULT_NAMESPACE
from exsce_dsl.runs.ingest import ingest_bags
from exsce_dsl.sim.run import simulate
from exsce_dsl.store.base import GraphSet, Store
from exsce_dsl.store.embedded import EmbeddedStore
from exsce_dsl.store.queries import runs

from tests.support.cli import exscec_here
from tests.support.paths import EXAMPLES

RUNS = f"{DEFAULT_NAMESPACE}runs/run_"
EXSCE_RUN = f"{DEFAULT_NAMESPACE}run"


@pytest.fixture(scope="module")
def project(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The example building (scenario_c wants one baseline run) and two runs of it."""
    folder = tmp_path_factory.mktemp("check")
    shutil.copytree(EXAMPLES / "brsu_building_c", folder / "bc")
    spec = folder / "bc" / "scenario_c.exsce"
    spec.write_text(spec.read_text(encoding="utf-8").replace("at least 3 baseline", "at least 1 baseline"))
    list(simulate(load_spec(spec).scenario(), folder / "bags", runs=2, seed=7))
    return folder


def _written(project: Path, where: Path) -> tuple[Store, list[str]]:
    """A store written by the normal paths: two runs ingested, baselines, verdicts (twice: a
    revision), one run replaced."""
    spec = load_spec(project / "bc" / "scenario_c.exsce")
    scenario = spec.scenario()
    bags = sorted((project / "bags").glob("*.bag"))
    store = EmbeddedStore(where)
    ingested = [r.run_id for r in ingest_bags(bags, scenario, store)]
    api.baseline(store, spec)
    verify_runs(store, scenario, ingested)  # type: ignore[arg-type]
    verify_runs(store, scenario, ingested)  # type: ignore[arg-type]
    ingest_bags(bags[:1], scenario, store, replace=True)
    return store, [r for r in ingested if r is not None]


def test_store_check_finds_nothing_on_a_store_written_by_the_normal_paths(
    project: Path, tmp_path: Path
) -> None:
    store, _ = _written(project, tmp_path / "store")
    assert store.graph_names()
    result = api.check_store(store)
    assert result.findings == () and result.clean
    store.close()
    done = exscec_here("store", "check", "--store", str(tmp_path / "store"))
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == f"{tmp_path / 'store'}: no problem found"


def test_store_check_finds_a_damaged_store_and_fix_removes_the_orphans(project: Path, tmp_path: Path) -> None:
    store, (kept, gone) = _written(project, tmp_path / "store")
    # damage: run `gone` loses its run bundle; a graph of a run that never was; a segment no run
    # observes; the scenario's own graph
    ghost = f"{RUNS}0000ghost/distance_travelled_bundle"
    segment = f"{DEFAULT_NAMESPACE}segments/scenario_c/nowhere/elsewhere"
    store.write(
        GraphSet(
            {
                ghost: [
                    Quad(
                        NamedNode(ghost + "#x"), NamedNode(EXSCE_RUN), Literal("0000ghost"), NamedNode(ghost)
                    )
                ],
                segment: [Quad(NamedNode(segment), NamedNode(EXSCE_RUN), Literal(gone), NamedNode(segment))],
            }
        )
    )
    store.remove_graphs([f"{RUNS}{gone}_bundle", f"{DEFAULT_NAMESPACE}scenario_c_bundle"])
    orphans_of_gone = sorted(g for g in store.graph_names() if f"run_{gone}" in g)
    assert orphans_of_gone

    result = api.check_store(store)
    by_kind: dict[str, set[str]] = {}
    for finding in result.findings:
        by_kind.setdefault(finding.kind, set()).add(finding.graph)
    assert by_kind["orphan graph"] == {ghost, segment, *orphans_of_gone}
    assert by_kind["run without scenario"] == {f"{RUNS}{kept}_bundle"}
    dangling = [f for f in result.findings if f.kind == "dangling reference"]
    assert any(gone in f.message and "build it again" in f.message for f in dangling)  # the baseline
    assert not result.clean
    store.close()

    cli = ["store", "check", "--store", str(tmp_path / "store")]
    done = exscec_here(*cli)
    assert done.returncode == 1
    assert f"<{ghost}>: orphan graph: a graph of run 0000ghost, which the store does not hold" in done.stdout
    assert "can be fixed with --fix" in done.stdout
    assert "(build it again: exscec baseline SPEC)" in done.stdout  # the remedy with its command

    fixed = exscec_here(*cli, "--fix")
    assert fixed.returncode == 1, fixed.stderr  # the dangling baseline and the missing scenario stay
    assert f"fixed: <{ghost}>: orphan graph" in fixed.stdout
    with EmbeddedStore(tmp_path / "store") as after:
        names = after.graph_names()
        assert not {ghost, segment, *orphans_of_gone} & names
        assert f"{RUNS}{kept}_bundle" in names  # the run that is whole stays
        left = api.check_store(after)
        assert {f.kind for f in left.findings} == {"run without scenario", "dangling reference"}
        assert [r.uuid for r in runs(after)] == [kept]


def _make_old(store: Store, second_scenario_run: str | None = None) -> dict[str, str]:
    """Move each run's bag bundle back to the name the code before issue 48 gave it; old → new."""
    moved = {}
    for run in runs(store):
        new = f"{RUNS}{run.uuid}/bag_bundle"
        if run.uuid == second_scenario_run:
            old = f"{RUNS}{run.uuid}/{run.bag}_bundle"  # a bag that was a run of a second scenario
        else:
            old = f"{DEFAULT_NAMESPACE}{run.bag}_bundle"
        quads = [Quad(q.subject, q.predicate, q.object, NamedNode(old)) for q in store.graph(new)]
        assert quads
        store.write(GraphSet({old: quads, new: []}), replace={old, new})
        moved[old] = new
    return moved


def test_store_migrate_moves_an_old_store_to_bag_bundles_named_by_their_run(
    project: Path, tmp_path: Path
) -> None:
    store, (first, second) = _written(project, tmp_path / "store")
    current = store.graph_sizes()
    listed = sorted(runs(store), key=lambda r: r.uuid)
    moved = _make_old(store, second_scenario_run=second)
    assert set(moved) & store.graph_names() == set(moved)
    old = api.check_store(store)
    assert {(f.kind, f.graph) for f in old.findings} == {("old bag bundle", name) for name in moved}
    assert all(f.fixable for f in old.findings)
    store.close()

    done = exscec_here("store", "migrate", "--store", str(tmp_path / "store"))
    assert done.returncode == 0, done.stderr
    for name, new in moved.items():
        assert f"{name} -> {new}" in done.stdout
    assert done.stdout.splitlines()[-1].endswith("bag bundles named by their run: 2")
    with EmbeddedStore(tmp_path / "store") as after:
        assert after.graph_sizes() == current  # as the current code writes it, graph by graph
        assert sorted(runs(after), key=lambda r: r.uuid) == listed  # bags and paths as before
        assert api.check_store(after).findings == ()
        again = api.migrate_store(after)
        assert again.moved == ()


def test_store_check_fix_renames_an_old_bag_bundle(project: Path, tmp_path: Path) -> None:
    store, _ = _written(project, tmp_path / "store")
    current = store.graph_sizes()
    _make_old(store)
    result = api.check_store(store, fix=True)
    assert result.clean and len(result.fixed) == 2
    assert store.graph_sizes() == current


def test_store_check_finds_the_same_on_an_oxigraph_server(project: Path, tmp_path: Path) -> None:
    """The checks are SPARQL 1.1: a server finds what the embedded store finds, and --fix mends
    it there in the same one write."""
    from exsce_dsl.store.open import open_store

    from tests.support.store_servers import oxigraph_server

    embedded, (_, gone) = _written(project, tmp_path / "store")
    embedded.remove_graphs([f"{RUNS}{gone}_bundle"])
    _make_old(embedded)
    expected = api.check_store(embedded)
    assert {f.kind for f in expected.findings} == {"orphan graph", "old bag bundle", "dangling reference"}
    contents = embedded.graphs(sorted(embedded.graph_names()))
    with (
        oxigraph_server(tmp_path / "served") as server,
        open_store(f"oxigraph+{server.url}", timeout=20) as remote,
    ):
        remote.write(GraphSet(contents))
        assert api.check_store(remote).findings == expected.findings
        api.check_store(remote, fix=True)
        api.check_store(embedded, fix=True)
        assert remote.graph_sizes() == embedded.graph_sizes()
        assert {f.kind for f in api.check_store(remote).findings} == {"dangling reference"}
