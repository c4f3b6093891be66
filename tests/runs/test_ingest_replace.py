"""Ingesting a bag again: ``--replace`` analyses a stored run anew under the current spec and swaps
its graphs in one write; the same bag is a run of each scenario it is ingested under; the skip
message says which scenario holds the run and how to replace it.

Reference values come from elsewhere than the code under test: the run id from the bag's
sha256 as the ids were always made (uuid5 in exsce's run namespace), the new metric's values
from rosbags' own reading of the bag, message by message.
"""

from __future__ import annotations

import datetime
import hashlib
import shutil
import uuid
from pathlib import Path

import numpy as np
import pytest
from rosbags.highlevel import AnyReader

from exsce_dsl import api
from exsce_dsl.cli.common import REMEDIES
from exsce_dsl.errors import ExsceError
from exsce_dsl.lang import load_spec
from exsce_dsl.oracles.judging import verify_runs
from exsce_dsl.oracles.verify import judge_runs
from exsce_dsl.runs.analyse import analyse_bag
from exsce_dsl.runs.ingest import IngestStatus, ingest_bags
from exsce_dsl.sim.run import simulate
from exsce_dsl.store.base import Store
from exsce_dsl.store.embedded import EmbeddedStore
from exsce_dsl.store.queries import run_metric_values, run_query, runs

from tests.support.cli import exscec_here
from tests.support.paths import EXAMPLES

RUN_NAMESPACE = uuid.UUID("5b8f9a52-3f0c-4a8e-8f0e-2d6c1b7e4a90")
"""The namespace of run ids since the first release: a run's id is uuid5 of its bag's sha256."""

NEW_METRIC = """
metric mean_forward_speed for each robot {
  "mean forward speed"
  unit m/s
  reads vel: geometry_msgs/msg/Twist on "/{ns}/nav_vel"
  value mean(abs(vel.linear.x))
}
"""

SECOND_SCENARIO = """import "environment.exsce"
import "robots.exsce"
import "tasks/deliveries.exsce"
import "tasks/navigation.exsce"
import "metrics.exsce"

// scenario_c's robots and mission under another name: the same bag is a run of either
scenario scenario_c2 in brsu_building_c_with_doors {
  robots {
    tiago1: tiago starts at classroom_c025-w001
    tiago2: tiago starts at classroom_c025-w002
  }
  mission mission_c2 parallel {
    tiago1 does delivery_a
    tiago2 does delivery_b
    tiago1 does navigate_home_1
    tiago2 does navigate_home_2
  }
}
"""


@pytest.fixture(scope="module")
def bags(tmp_path_factory: pytest.TempPathFactory) -> list[Path]:
    """Two runs of scenario_c, as ROS 1 bags."""
    scenario = load_spec(EXAMPLES / "brsu_building_c" / "scenario_c.exsce").scenario()
    out = tmp_path_factory.mktemp("bags")
    return [run.bag for run in simulate(scenario, out, runs=2, seed=7)]


@pytest.fixture
def project(tmp_path: Path) -> Path:
    """A copy of the example building, with scenario_c2 beside scenario_c (whose baseline wants
    one run)."""
    folder = tmp_path / "bc"
    shutil.copytree(EXAMPLES / "brsu_building_c", folder)
    (folder / "scenario_c2.exsce").write_text(SECOND_SCENARIO, encoding="utf-8")
    spec = folder / "scenario_c.exsce"  # a baseline from one run, for the tests of verdicts
    spec.write_text(spec.read_text(encoding="utf-8").replace("at least 3 baseline", "at least 1 baseline"))
    return folder


def _add_a_metric(project: Path) -> None:
    metrics = project / "metrics.exsce"
    metrics.write_text(metrics.read_text(encoding="utf-8") + NEW_METRIC, encoding="utf-8")


def _scenario(project: Path, name: str = "scenario_c"):
    return load_spec(project / f"{name}.exsce").scenario()


def _bag_id(bag: Path) -> str:
    return str(uuid.uuid5(RUN_NAMESPACE, hashlib.sha256(bag.read_bytes()).hexdigest()))


def _values(store: Store, run: str) -> dict[tuple[str, str | None, str | None], float]:
    """The run's whole-run values: (metric, robot, safety metric) → value."""
    return {(v.metric, v.robot, v.safety): v.value for v in run_metric_values(store, [run])}


def _contents(store: Store, but: str | None = None) -> dict[str, set[str]]:
    """Every graph's statements as text (blank nodes left out), but the graphs naming run ``but``."""
    found: dict[str, set[str]] = {}
    for quad in store.quads():
        graph = quad.graph_name.value  # type: ignore[union-attr]
        if but is None or f"run_{but}" not in graph:
            if "_:" not in str(quad):
                found.setdefault(graph, set()).add(str(quad))
    return found


def _mean_forward_speed(bag: Path, robot: str, start: float, end: float) -> float:
    """mean |linear.x| of the robot's /nav_vel between its first goal and its last, by rosbags."""
    speeds = []
    with AnyReader([bag]) as reader:
        connections = [c for c in reader.connections if c.topic == f"/{robot}/nav_vel"]
        for connection, timestamp, raw in reader.messages(connections=connections):
            if start <= timestamp / 1e9 <= end:
                speeds.append(abs(reader.deserialize(raw, connection.msgtype).linear.x))
    return float(np.mean(speeds))


def test_ingest_again_after_a_new_metric_keeps_the_old_run_until_replace(bags, project) -> None:
    store = EmbeddedStore()
    bag, other = bags
    first = ingest_bags([bag, other], _scenario(project), store)
    assert [r.status for r in first] == [IngestStatus.INGESTED] * 2
    run = first[0].run_id
    assert run == _bag_id(bag)
    before = _values(store, run)
    untouched = _contents(store, but=run)
    _add_a_metric(project)
    newer = _scenario(project)

    [again] = ingest_bags([bag], newer, store)
    assert again.status is IngestStatus.SKIPPED and again.run_id == run
    assert _values(store, run) == before  # the new metric is not there: nothing was analysed
    assert not any(key[0] == "mean_forward_speed" for key in before)

    [replaced] = ingest_bags([bag], newer, store, replace=True)
    assert replaced.status is IngestStatus.REPLACED, replaced.message
    assert replaced.run_id == run  # the run keeps its id
    assert f"run {run} analysed again" in replaced.message
    after = _values(store, run)
    added = {key for key in after if key not in before}
    assert added == {("mean_forward_speed", "tiago1", None), ("mean_forward_speed", "tiago2", None)}
    assert {key: after[key] for key in before} == before  # every other value as it was
    analysed = analyse_bag(bag, newer)  # only for the robots' windows
    for robot in ("tiago1", "tiago2"):
        actions = [a for task in analysed.run.tasks if task.robot == robot for a in task.actions]
        start, end = min(a.start for a in actions).timestamp(), max(a.end for a in actions).timestamp()
        expected = _mean_forward_speed(bag, robot, start, end)
        assert after[("mean_forward_speed", robot, None)] == pytest.approx(expected, rel=1e-9)
    # nothing but the run changed: the other run, the scenario, the shared segment graphs; the
    # run summaries' key of the new metric is new (every run with values of it shares it)
    now = _contents(store, but=run)
    key = "https://www.sesame-project.org/scenarios/summaries/metric/mean_forward_speed"
    assert set(now) - set(untouched) == {key} and "mean_forward_speed" in " ".join(now[key])
    assert {name: statements for name, statements in now.items() if name != key} == untouched
    assert {r.uuid for r in runs(store)} == {run, first[1].run_id}


def test_replace_of_a_bag_the_store_lacks_ingests_it(bags, project) -> None:
    store = EmbeddedStore()
    [result] = ingest_bags([bags[0]], _scenario(project), store, replace=True)
    assert result.status is IngestStatus.INGESTED and result.run_id == _bag_id(bags[0])
    assert len(runs(store)) == 1


def test_a_replaced_run_loses_its_verdicts_and_is_verified_again(bags, project) -> None:
    store = EmbeddedStore()
    spec = load_spec(project / "scenario_c.exsce")
    [result] = ingest_bags([bags[0]], spec.scenario(), store)
    run = result.run_id
    assert run is not None
    api.baseline(store, spec)
    verify_runs(
        store, spec.scenario(), [run], now=datetime.datetime(2026, 1, 9, tzinfo=datetime.timezone.utc)
    )
    later = datetime.datetime(2026, 1, 10, tzinfo=datetime.timezone.utc)
    verify_runs(store, spec.scenario(), [run], now=later)  # again: the first verdicts become a revision
    graphs = store.graph_names()
    assert any(g.endswith(f"run_{run}/verdicts_bundle") for g in graphs)
    assert any(f"run_{run}/verdicts_bundle?revision=" in g for g in graphs)
    assert len(run_query(store, "verdicts", {})) > 0

    [replaced] = ingest_bags([bags[0]], spec.scenario(), store, replace=True)
    assert replaced.status is IngestStatus.REPLACED
    assert "its verdicts were dropped" in replaced.message
    assert "its verdicts were dropped (exscec verify judges it again)" in replaced.said(REMEDIES)  # the CLI's
    assert not any("verdicts_bundle" in g for g in store.graph_names())
    assert len(run_query(store, "verdicts", {})) == 0
    assert run_query(store, "oracles", {"scenario": "scenario_c"})  # the baseline stays
    verification = verify_runs(store, spec.scenario(), [run])
    assert {v.run for v in verification.verdicts} == {run}
    assert len(run_query(store, "verdicts", {})) == len(verification.verdicts)


def test_the_same_bag_is_a_run_of_two_scenarios(bags, project) -> None:
    store = EmbeddedStore()
    bag = bags[0]
    [of_c] = ingest_bags([bag], _scenario(project), store)
    [of_c2] = ingest_bags([bag], _scenario(project, "scenario_c2"), store)
    assert of_c.status is of_c2.status is IngestStatus.INGESTED, of_c2.message
    assert of_c.run_id == _bag_id(bag)  # the one-scenario id, as before
    assert of_c2.run_id not in (None, of_c.run_id)
    assert "the bag is also a run of scenario 'scenario_c'" in of_c2.message
    stored = {r.uuid: r.scenario for r in runs(store)}
    assert stored == {of_c.run_id: "scenario_c", of_c2.run_id: "scenario_c2"}
    assert [r.uuid for r in runs(store, "scenario_c2")] == [of_c2.run_id]
    assert {r.bag for r in runs(store)} == {bag.name}
    # each run has its own values, and they agree: one bag, the same robots and mission
    assert _values(store, of_c.run_id) == _values(store, of_c2.run_id)  # type: ignore[arg-type]
    # ingested again under either scenario: skipped, each naming its own
    again_c, again_c2 = (
        ingest_bags([bag], _scenario(project, s), store)[0] for s in ("scenario_c", "scenario_c2")
    )
    assert (again_c.status, again_c.run_id) == (IngestStatus.SKIPPED, of_c.run_id)
    assert (again_c2.status, again_c2.run_id) == (IngestStatus.SKIPPED, of_c2.run_id)
    assert "already a run of scenario 'scenario_c2'" in again_c2.message
    # a replace under scenario_c2 leaves scenario_c's run as it was
    kept = _contents(store, but=of_c2.run_id)
    [replaced] = ingest_bags([bag], _scenario(project, "scenario_c2"), store, replace=True)
    assert (replaced.status, replaced.run_id) == (IngestStatus.REPLACED, of_c2.run_id)
    assert _contents(store, but=of_c2.run_id) == kept
    assert len(runs(store)) == 2
    # a run is judged as a run of its own scenario only
    spec = load_spec(project / "scenario_c.exsce")
    api.baseline(store, spec)
    assert {v.run for v in judge_runs(store, [of_c.run_id], spec.scenario())} == {of_c.run_id}  # type: ignore[list-item]
    with pytest.raises(ExsceError, match="is a run of 'scenario_c2', not of 'scenario_c'"):
        judge_runs(store, [of_c2.run_id], spec.scenario())  # type: ignore[list-item]


def test_the_first_scenario_a_store_sees_a_bag_under_gets_its_own_id(bags, project) -> None:
    store = EmbeddedStore()
    [of_c2] = ingest_bags([bags[0]], _scenario(project, "scenario_c2"), store)
    [of_c] = ingest_bags([bags[0]], _scenario(project), store)
    assert of_c2.run_id == _bag_id(bags[0]) != of_c.run_id
    assert {r.scenario for r in runs(store)} == {"scenario_c", "scenario_c2"}


def test_the_skip_message_names_the_scenario_and_replace(bags, project) -> None:
    bag = project.parent / "a.bag"
    shutil.copyfile(bags[0], bag)
    store = str(project.parent / "store")
    spec = "bc/scenario_c.exsce"
    first = exscec_here("ingest", "a.bag", "--scenario", spec, "--store", store, cwd=project.parent)
    assert first.returncode == 0, first.stderr
    second = exscec_here("ingest", "a.bag", "--scenario", spec, "--store", store, cwd=project.parent)
    assert second.returncode == 0, second.stderr
    run = _bag_id(bag)
    assert second.stderr.splitlines() == [
        f"a.bag: already a run of scenario 'scenario_c' (run {run}); "
        "pass --replace to analyse it again under this spec",
        "0 ingested, 1 skipped, 0 failed",
    ]
    replaced = exscec_here(
        "ingest", "--replace", "a.bag", "--scenario", spec, "--store", store, cwd=project.parent
    )
    assert replaced.returncode == 0, replaced.stderr
    assert f"a.bag: run {run} analysed again" in replaced.stderr
    assert replaced.stderr.splitlines()[-1] == "0 ingested, 1 replaced, 0 skipped, 0 failed"
    listed = exscec_here("runs", "--store", store, cwd=project.parent)
    assert listed.stdout.count(run) == 1 and "scenario_c" in listed.stdout


@pytest.mark.parametrize("server", ["oxigraph", "virtuoso"])
def test_a_run_is_replaced_on_a_sparql_server_as_in_the_embedded_store(
    bags, project, tmp_path: Path, server: str
) -> None:
    from exsce_dsl.store.open import open_store

    from tests.support.store_servers import oxigraph_server, virtuoso_server

    bag = bags[0]
    embedded = EmbeddedStore()
    serve = oxigraph_server if server == "oxigraph" else virtuoso_server
    with serve(tmp_path / server) as running, open_store(f"{server}+{running.url}", timeout=20) as remote:
        for store in (embedded, remote):
            ingest_bags([bag], _scenario(project), store)
        _add_a_metric(project)
        newer = _scenario(project)
        before = _values(remote, _bag_id(bag))
        for store in (embedded, remote):
            [replaced] = ingest_bags([bag], newer, store, replace=True)
            assert replaced.status is IngestStatus.REPLACED, replaced.message
        after = _values(remote, _bag_id(bag))
        assert {key[0] for key in after} - {key[0] for key in before} == {"mean_forward_speed"}
        assert after == pytest.approx(_values(embedded, _bag_id(bag)), rel=1e-12)
        assert remote.graph_sizes() == embedded.graph_sizes()
        assert [r.uuid for r in runs(remote)] == [_bag_id(bag)]


def _segment_graphs(store: Store) -> set[str]:
    return {g for g in store.graph_names() if "/segments/" in g}


def _driven_segments(store: Store) -> set[str]:
    """The segments some run's action graph says it drove (``?segment exsce:run ?run``)."""
    rows = store.select(
        "SELECT DISTINCT ?segment WHERE { GRAPH ?g { ?segment ?p ?run } "
        'FILTER(STRENDS(STR(?p), "/run") && CONTAINS(STR(?segment), "/segments/") '
        '&& CONTAINS(STR(?g), "/runs/run_")) }'
    )
    return {segment.value for (segment,) in rows.rows}


@pytest.mark.parametrize("how", ["replace_run", "add_prov"])
def test_a_segment_graph_left_without_its_run_after_replace_is_pruned(bags, project, how) -> None:
    """Issue 48: a run replaced by a version that drives fewer path segments left the segment
    graphs only its old version drove in the store, naming no run (``ingest --replace`` writes
    through ``replace_run``, ``add_prov(..., replace=True)`` is what ``compile --replace`` does)."""
    from dataclasses import replace

    from exsce_dsl.model.runs import MetricScope
    from exsce_dsl.prov.run import compile_run
    from exsce_dsl.store.run_replacing import replace_run
    from exsce_dsl.store.writing import add_prov

    store = EmbeddedStore()
    scenario = _scenario(project)
    [first] = ingest_bags([bags[0]], scenario, store)
    assert first.run_id is not None
    before = _segment_graphs(store)
    assert before and before == _driven_segments(store)
    old = analyse_bag(bags[0], scenario).run
    # the new version: tiago1's second task (its drive home) is not in it, nor its segments' values
    kept = tuple(t for t in old.tasks if not (t.robot == "tiago1" and t.allocation == 2))
    gone = {a.id for t in old.tasks if t not in kept for a in t.actions}
    assert gone
    values = tuple(v for v in old.metrics if not (v.scope is MetricScope.SEGMENT and v.action in gone))
    fewer = replace(old, uuid=first.run_id, tasks=kept, metrics=values)
    document = compile_run(fewer, scenario)
    if how == "replace_run":
        replace_run(store, document, first.run_id)
    else:
        add_prov(store, document, replace=True)
    after = _segment_graphs(store)
    driven = {(a.start_pose, a.goal_pose) for t in kept for a in t.actions}
    assert len(after) == len(driven) < len(before)  # the drive home's segments are gone ...
    assert after == _driven_segments(store)  # ... and no segment graph is left without its run
