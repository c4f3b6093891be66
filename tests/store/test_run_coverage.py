"""The coverage ingestion finds goes into the run's PROV and comes back from the store as it was:
an executor bag of scenario_c cut at 60 % and with a scan silent for 10 s, ingested into the
embedded store, read back with :func:`run_coverage` and :func:`run_topic_rates`; the run PROV with
its gaps conforms to the run shapes."""

from __future__ import annotations

from pathlib import Path

import pytest

from exsce_dsl.lang import load_spec
from exsce_dsl.model.coverage import Shortfall
from exsce_dsl.prov.run import compile_run
from exsce_dsl.rdf import to_quads, validate
from exsce_dsl.runs.analyse import AnalysedRun, analyse_bag
from exsce_dsl.runs.ingest import ingest_bags
from exsce_dsl.sim.run import simulate
from exsce_dsl.store.embedded import EmbeddedStore
from exsce_dsl.store.queries import run_coverage, run_topic_rates

from tests.support.bag_surgery import cut, drop

SPEC = Path(__file__).resolve().parents[2] / "examples" / "brsu_building_c" / "scenario_c.exsce"


@pytest.fixture(scope="module")
def ingested(tmp_path_factory: pytest.TempPathFactory) -> tuple[EmbeddedStore, list[AnalysedRun]]:
    folder = tmp_path_factory.mktemp("coverage")
    scenario = load_spec(SPEC).scenario("scenario_c")
    (run,) = simulate(scenario, folder / "clean", fmt="mcap", seed=4)
    silent = drop(run.bag, folder / "silent", "mcap", "/tiago1/scan", 30.0, 40.0)
    bags = [run.bag, cut(silent, folder / "cut", "mcap", 0.6)]
    store = EmbeddedStore(folder / "store")
    results = ingest_bags(bags, scenario, store)
    assert [r.failed for r in results] == [False, False]
    assert "does not cover all of it: 3 gaps (cut short, gap)" in results[1].message
    assert any(p.startswith("coverage: gap: /tiago1/scan") for p in results[1].problems)
    return store, [analyse_bag(bag, scenario) for bag in bags]


def test_the_gaps_come_back_from_the_store_as_ingested(
    ingested: tuple[EmbeddedStore, list[AnalysedRun]],
) -> None:
    store, (clean, partial) = ingested
    found = run_coverage(store, [clean.run.uuid, partial.run.uuid, "not-a-run"])
    assert found[clean.run.uuid] == [] and found["not-a-run"] == []
    gaps = found[partial.run.uuid]
    assert [g.kind for g in partial.run.coverage] == [Shortfall.CUT_SHORT, Shortfall.CUT_SHORT, Shortfall.GAP]
    assert {(g.kind, g.robot, g.topic, g.metrics, g.reason) for g in gaps} == {
        (g.kind, g.robot, g.topic, g.metrics, g.reason) for g in partial.run.coverage
    }
    assert [g.kind for g in gaps] == [g.kind for g in partial.run.coverage]  # in the order found
    for stored, analysed in zip(gaps, partial.run.coverage, strict=True):
        assert stored.start is not None and analysed.start is not None
        assert stored.end is not None and analysed.end is not None
        assert abs((stored.start - analysed.start).total_seconds()) < 1e-3
        assert abs((stored.end - analysed.end).total_seconds()) < 1e-3


def test_the_topic_rates_come_back_from_the_store(ingested: tuple[EmbeddedStore, list[AnalysedRun]]) -> None:
    store, (clean, partial) = ingested
    found = run_topic_rates(store, [clean.run.uuid, partial.run.uuid])
    for analysed in (clean, partial):
        stored = found[analysed.run.uuid]
        assert len(stored) == len(analysed.run.topic_rates) >= 8
        for back, rate in zip(stored, analysed.run.topic_rates, strict=True):
            assert (back.topic, back.robot, back.messages, back.metrics) == (
                rate.topic,
                rate.robot,
                rate.messages,
                rate.metrics,
            )
            assert back.rate == pytest.approx(rate.rate, rel=1e-12)
    assert run_topic_rates(store, []) == {}


def test_a_run_with_gaps_conforms_to_the_run_shapes(
    ingested: tuple[EmbeddedStore, list[AnalysedRun]],
) -> None:
    _, (_, partial) = ingested
    scenario = load_spec(SPEC).scenario("scenario_c")
    quads = list(to_quads(compile_run(partial.run, scenario, checked=True)))
    assert validate(quads, ["runs"]) == []
    shortfalls = {q.object.value for q in quads if q.predicate.value.endswith("/shortfall")}
    assert shortfalls == {"cut_short", "gap"}
