"""Many runs written in group commits (``RunWriter``): the same store as one ``add_prov`` per run,
each run wholly or not at all when the writer is killed."""

from __future__ import annotations

import pickle
import random
import signal
import subprocess
import sys
import textwrap
from dataclasses import replace
from pathlib import Path

import pytest
from prov.model import ProvDocument
from pyoxigraph import BlankNode, CanonicalizationAlgorithm, Dataset

from exsce_dsl.errors import StoreError
from exsce_dsl.lang import load_spec
from exsce_dsl.model import Scenario
from exsce_dsl.prov import compile_scenario
from exsce_dsl.prov.run import compile_run
from exsce_dsl.rdf import to_quads
from exsce_dsl.runs.analyse import analyse_bag
from exsce_dsl.sim.run import simulate
from exsce_dsl.store.base import Store
from exsce_dsl.store.batch_writing import RunWriter, Written
from exsce_dsl.store.embedded import EmbeddedStore
from exsce_dsl.store.remote import RemoteStore
from exsce_dsl.store.writing import add_prov, stored_graphs

from tests.support.paths import EXAMPLES
from tests.support.store_servers import oxigraph_server

SPEC = EXAMPLES / "brsu_building_c" / "scenario_c.exsce"
RUNS = 5


@pytest.fixture(scope="module")
def scenario() -> Scenario:
    return load_spec(SPEC).scenario("scenario_c")


@pytest.fixture(scope="module")
def documents(scenario: Scenario, tmp_path_factory: pytest.TempPathFactory) -> list[ProvDocument]:
    """The PROV of five runs of scenario_c, from the executor's bags."""
    folder = tmp_path_factory.mktemp("batch")
    bags = [run.bag for run in simulate(scenario, folder, RUNS, seed=9)]
    return [compile_run(analyse_bag(bag, scenario).run, scenario) for bag in bags]


def _with_scenario(store: Store, scenario: Scenario) -> Store:
    add_prov(store, compile_scenario(scenario))
    return store


def _canonical(store: Store) -> Dataset:
    dataset = Dataset(store.quads())
    dataset.canonicalize(CanonicalizationAlgorithm.UNSTABLE)
    return dataset


def _write_all(store: Store, documents: list[ProvDocument]) -> list[Written]:
    told: list[Written] = []
    with RunWriter(store, told.append) as writer:
        for number, document in enumerate(documents):
            writer.add(document, number)
    return told


def test_group_commits_store_what_one_add_prov_per_run_stores(
    scenario: Scenario, documents: list[ProvDocument], tmp_path: Path
) -> None:
    one_by_one = _with_scenario(EmbeddedStore(tmp_path / "one-by-one"), scenario)
    reports = [add_prov(one_by_one, document) for document in documents]
    grouped = _with_scenario(EmbeddedStore(tmp_path / "grouped"), scenario)
    told = _write_all(grouped, documents)
    assert [w.key for w in told] == list(range(RUNS))  # told once each, in the order given
    assert all(w.error is None for w in told)
    # the same graphs added, the same statements counted
    assert [w.report and replace(w.report, location=one_by_one.location) for w in told] == reports
    assert _canonical(grouped) == _canonical(one_by_one)
    assert 0 < len(grouped.graph_names()) == len(one_by_one.graph_names())


def test_the_blank_nodes_of_two_runs_stay_apart(documents: list[ProvDocument]) -> None:
    store = EmbeddedStore()
    _write_all(store, documents)
    own = [{t for q in to_quads(d) for t in (q.subject, q.object) if isinstance(t, BlankNode)} for d in documents]
    stored = {t for q in store.quads() for t in (q.subject, q.object) if isinstance(t, BlankNode)}
    assert min(map(len, own)) > 0
    assert len(stored) == sum(map(len, own))  # one label per document would merge them


def test_a_run_the_store_holds_already_follows_the_rules_of_add_prov(
    scenario: Scenario, documents: list[ProvDocument], tmp_path: Path
) -> None:
    store = _with_scenario(EmbeddedStore(tmp_path / "store"), scenario)
    add_prov(store, documents[0])
    before = _canonical(store)
    told = _write_all(store, [documents[0], documents[1], documents[1]])
    first, second, again = (w.report for w in told)
    assert first is not None and second is not None and again is not None
    assert not first.changed and len(first.unchanged) == len(documents[0].bundles)
    assert second.added and second.statements > 1000
    assert not again.changed  # given twice in one writer: written once
    assert _canonical(store) != before
    assert len(store.quads()) == len(before) + second.statements


def test_statements_outside_bundles_are_refused_as_add_prov_refuses_them(tmp_path: Path) -> None:
    document = ProvDocument()
    document.add_namespace("ex", "https://example.org/")
    document.entity("ex:loose")
    bundle = document.bundle("ex:bundle")
    bundle.entity("ex:inside")
    store = EmbeddedStore(tmp_path / "store")
    (told,) = _write_all(store, [document])
    assert told.report is None and isinstance(told.error, StoreError)
    assert "outside any bundle" in told.error.message
    assert store.quads() == []


def test_a_sparql_endpoint_gets_one_write_per_run(
    scenario: Scenario, documents: list[ProvDocument], tmp_path: Path
) -> None:
    embedded = _with_scenario(EmbeddedStore(tmp_path / "embedded"), scenario)
    for document in documents[:2]:
        add_prov(embedded, document)
    with oxigraph_server(tmp_path / "served") as server:
        remote = _with_scenario(RemoteStore(f"{server.url}/query", update_url=f"{server.url}/update"), scenario)
        told = _write_all(remote, documents[:2])
        assert all(w.report is not None and w.report.added for w in told)
        assert _canonical(remote) == _canonical(embedded)


WRITER = textwrap.dedent(
    """
    import pickle, sys
    from exsce_dsl.store.batch_writing import RunWriter
    from exsce_dsl.store.embedded import EmbeddedStore
    documents = pickle.loads(open(sys.argv[1], "rb").read())
    store = EmbeddedStore(sys.argv[2])
    store.graph_names()
    print("ready", flush=True)
    with RunWriter(store, bulk_from=int(sys.argv[3])) as writer:
        for document in documents:
            writer.add(document)
    print("done", flush=True)
    """
)


@pytest.mark.parametrize("bulk_from", [1, 10**9], ids=["bulk-loads", "transactions"])
def test_a_writer_killed_at_random_points_leaves_each_run_wholly_or_not_at_all(
    scenario: Scenario, documents: list[ProvDocument], tmp_path: Path, bulk_from: int
) -> None:
    given = tmp_path / "documents.pickle"
    given.write_bytes(pickle.dumps(documents))
    expected = [
        {
            name: len(quads)
            for name, quads in stored_graphs(d).items()
            if "/segments/" not in name and "/summaries/" not in name  # shared by the runs
        }
        for d in documents
    ]
    chance = random.Random(7)
    counts = []
    for attempt in range(12):
        folder = tmp_path / f"killed-{attempt}"
        with EmbeddedStore(folder) as store:
            _with_scenario(store, scenario)
        writer = subprocess.Popen(
            [sys.executable, "-c", WRITER, str(given), str(folder), str(bulk_from)], stdout=subprocess.PIPE, text=True
        )
        assert writer.stdout is not None and writer.stdout.readline() == "ready\n"
        # five runs take a tenth of a second or a few to write: kill anywhere in that time
        signal_after = chance.uniform(0.0, 0.25 if bulk_from > 1 else 0.4)
        try:
            writer.wait(timeout=signal_after)
        except subprocess.TimeoutExpired:
            writer.send_signal(signal.SIGKILL)
        writer.communicate(timeout=30)
        with EmbeddedStore(folder) as store:
            sizes = store.graph_sizes()
        whole = []
        for run in expected:
            present = {name: sizes[name] for name in run if name in sizes}
            assert present in ({}, run), "a run stored in part"
            whole.append(bool(present))
        stored = sum(whole)
        assert whole == [True] * stored + [False] * (RUNS - stored), "runs are committed in order"
        counts.append(stored)
    print(f"runs stored after each of 12 kills: {counts}")
    assert len(set(counts)) >= 2, "the kills should fall at different points of the writes"


def test_a_name_rdf_cannot_hold_is_told_for_its_document_and_the_others_still_go_in(
    documents: list[ProvDocument],
) -> None:
    document = ProvDocument()
    document.add_namespace("ex", "relative/")
    document.bundle("ex:bundle").entity("ex:inside")
    store = EmbeddedStore()
    first, bad, last = _write_all(store, [documents[0], document, documents[1]])
    assert first.report is not None and last.report is not None
    assert bad.report is None and bad.error is not None and "not an absolute IRI" in bad.error.message
    assert len(store.quads()) == first.report.statements + last.report.statements
