"""Identities that cannot collide (issue 48): two recordings with one file name, in two folders,
are two runs of one store; a bag named like its scenario sits beside the scenario; a run whose
stored graphs differ from its analysis names the command that replaces a run.

Run ids are checked against the bag's sha256 as the ids were always made (uuid5 in exsce's run
namespace), not against exsce's own function.
"""

from __future__ import annotations

import dataclasses
import hashlib
import shutil
import uuid
from pathlib import Path

import pytest
from pyoxigraph import Literal, Quad

from exsce_dsl import api
from exsce_dsl.cli.common import REMEDIES
from exsce_dsl.errors import ExsceError, StoreConflictError
from exsce_dsl.lang import load_spec
from exsce_dsl.oracles.judging import verify_runs
from exsce_dsl.prov import DEFAULT_NAMESPACE, compile_scenario
from exsce_dsl.prov.run import compile_run
from exsce_dsl.runs.analyse import analyse_bag
from exsce_dsl.runs.ingest import IngestStatus, ingest_bags
from exsce_dsl.sim.run import simulate
from exsce_dsl.store.base import GraphSet
from exsce_dsl.store.embedded import EmbeddedStore
from exsce_dsl.store.queries import run_metric_values, runs
from exsce_dsl.store.writing import add_prov

from tests.support.cli import exscec_here
from tests.support.paths import EXAMPLES

RUN_NAMESPACE = uuid.UUID("5b8f9a52-3f0c-4a8e-8f0e-2d6c1b7e4a90")
RUNS = f"{DEFAULT_NAMESPACE}runs/run_"


@pytest.fixture(scope="module")
def project(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The example building, whose scenario_c wants one baseline run, and two recordings of it,
    both ``run1.bag``, in ``a/`` and ``b/``."""
    folder = tmp_path_factory.mktemp("same_name")
    shutil.copytree(EXAMPLES / "brsu_building_c", folder / "bc")
    spec = folder / "bc" / "scenario_c.exsce"
    spec.write_text(spec.read_text(encoding="utf-8").replace("at least 3 baseline", "at least 1 baseline"))
    played = [run.bag for run in simulate(load_spec(spec).scenario(), folder / "played", runs=2, seed=7)]
    for bag, where in zip(played, ("a", "b"), strict=True):
        (folder / where).mkdir()
        shutil.copyfile(bag, folder / where / "run1.bag")
    return folder


def _bag_id(bag: Path) -> str:
    return str(uuid.uuid5(RUN_NAMESPACE, hashlib.sha256(bag.read_bytes()).hexdigest()))


def test_two_bags_with_one_file_name_in_two_folders_are_two_runs(project: Path) -> None:
    spec = load_spec(project / "bc" / "scenario_c.exsce")
    scenario = spec.scenario()
    store = EmbeddedStore()
    first, second = project / "a" / "run1.bag", project / "b" / "run1.bag"
    [a] = ingest_bags([first], scenario, store)
    [b] = ingest_bags([second], scenario, store)
    assert (a.status, b.status) == (IngestStatus.INGESTED, IngestStatus.INGESTED), b.message
    assert (a.run_id, b.run_id) == (_bag_id(first), _bag_id(second))
    assert a.run_id != b.run_id
    listed = {r.uuid: r for r in runs(store, "scenario_c")}
    assert set(listed) == {a.run_id, b.run_id}
    assert {r.bag for r in listed.values()} == {"run1.bag"}
    assert {r.path for r in listed.values()} == {str(first), str(second)}
    # each bag's bundle is named by its run, none by the file
    graphs = store.graph_names()
    assert {f"{RUNS}{a.run_id}/bag_bundle", f"{RUNS}{b.run_id}/bag_bundle"} <= set(graphs)
    assert not [g for g in graphs if "run1.bag_bundle" in g]
    # both are queried: each has its own values (two recordings, two sets of numbers)
    values = {run: {(v.metric, v.robot): v.value for v in run_metric_values(store, [run])} for run in listed}
    assert values[a.run_id] and values[a.run_id].keys() == values[b.run_id].keys()
    assert values[a.run_id] != values[b.run_id]
    # and judged
    api.baseline(store, spec)
    verification = verify_runs(store, scenario, [a.run_id, b.run_id])  # type: ignore[list-item]
    assert {v.run for v in verification.verdicts} == {a.run_id, b.run_id}
    # again: skipped; with replace: replaced, the other run untouched
    [again] = ingest_bags([second], scenario, store)
    assert (again.status, again.run_id) == (IngestStatus.SKIPPED, b.run_id)
    kept = {q for q in store.quads() if b.run_id not in str(q.graph_name) and "_:" not in str(q)}
    [replaced] = ingest_bags([second], scenario, store, replace=True)
    assert (replaced.status, replaced.run_id) == (IngestStatus.REPLACED, b.run_id), replaced.message
    after = {q for q in store.quads() if b.run_id not in str(q.graph_name) and "_:" not in str(q)}
    assert {q for q in kept if "verdicts" not in str(q.graph_name)} <= after
    assert {r.uuid for r in runs(store)} == {a.run_id, b.run_id}


def test_the_cli_lists_two_runs_of_one_bag_file_name(project: Path, tmp_path: Path) -> None:
    store = str(tmp_path / "store")
    spec = str(project / "bc" / "scenario_c.exsce")
    for where in ("a", "b"):
        done = exscec_here("ingest", f"{where}/run1.bag", "--scenario", spec, "--store", store, cwd=project)
        assert done.returncode == 0, done.stderr
        assert done.stderr.splitlines()[-1] == "1 ingested, 0 skipped, 0 failed"
    listed = exscec_here("runs", "--store", store, cwd=project)
    assert listed.returncode == 0, listed.stderr
    for where in ("a", "b"):
        assert _bag_id(project / where / "run1.bag") in listed.stdout


def test_a_bag_named_like_its_scenario_is_stored_beside_it(project: Path) -> None:
    """A ROS 2 or MCAP bag is a folder without a suffix: one named ``scenario_c`` had its bundle
    named ``exsce:scenario_c_bundle``, the scenario's own graph."""
    scenario = load_spec(project / "bc" / "scenario_c.exsce").scenario()
    run = analyse_bag(project / "a" / "run1.bag", scenario).run
    named = dataclasses.replace(run, bag=dataclasses.replace(run.bag, file_name="scenario_c"))
    store = EmbeddedStore()
    add_prov(store, compile_scenario(scenario))
    scenario_graph = sorted(store.graph(f"{DEFAULT_NAMESPACE}scenario_c_bundle"), key=str)
    report = add_prov(store, compile_run(named, scenario))
    assert f"{RUNS}{run.uuid}/bag_bundle" in report.added
    assert sorted(store.graph(f"{DEFAULT_NAMESPACE}scenario_c_bundle"), key=str) == scenario_graph


def test_a_run_stored_with_other_content_names_ingest_replace(project: Path) -> None:
    """The same run (its id from the bag's content) whose stored graphs differ from a new
    analysis: the advice is to ingest the bag with --replace, not to compile a spec."""
    scenario = load_spec(project / "bc" / "scenario_c.exsce").scenario()
    run = analyse_bag(project / "a" / "run1.bag", scenario).run
    store = EmbeddedStore()
    add_prov(store, compile_scenario(scenario))
    add_prov(store, compile_run(run, scenario))
    graph = f"{RUNS}{run.uuid}/mission_duration_bundle"
    changed = [
        Quad(q.subject, q.predicate, Literal("1.0", datatype=q.object.datatype), q.graph_name)
        if isinstance(q.object, Literal) and q.predicate.value.endswith("#value")
        else q
        for q in store.graph(graph)
    ]
    store.write(GraphSet({graph: changed}), replace={graph})
    with pytest.raises(StoreConflictError) as raised:
        add_prov(store, compile_run(run, scenario))
    message = str(raised.value)
    assert f"run {run.uuid} with other content" in message
    assert "ingest its bag with replace" in message
    assert raised.value.remedied is not None  # what the command line says, with its option:
    assert "`exscec ingest BAG --scenario SPEC --replace`" in raised.value.remedied.said(REMEDIES)
    assert "exscec compile" not in raised.value.remedied.said(REMEDIES)
    assert isinstance(raised.value, ExsceError)
