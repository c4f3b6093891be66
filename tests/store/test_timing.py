"""The store's query timing (``exsce_dsl.store.timing``): what is counted, under which name, once."""

from __future__ import annotations

import pytest

from exsce_dsl.errors import StoreError
from exsce_dsl.lang import load_spec
from exsce_dsl.prov import compile_scenario
from exsce_dsl.store import EmbeddedStore, add_prov, run_query, timing_queries
from exsce_dsl.store.timing import ad_hoc_name

from tests.support.paths import EXAMPLES


@pytest.fixture(scope="module")
def store() -> EmbeddedStore:
    spec = load_spec(EXAMPLES / "brsu_building_c" / "scenario_c.exsce")
    store = EmbeddedStore()
    add_prov(store, compile_scenario(spec.scenario("scenario_c")))
    return store


def test_a_library_query_is_timed_once_under_its_name(store: EmbeddedStore) -> None:
    with timing_queries() as times:
        rows = run_query(store, "robots", {"scenario": "scenario_c"})
        run_query(store, "robots", {"scenario": "scenario_c"})
    assert list(times.by_name) == ["robots"]  # the store's own select inside is not counted again
    robots = times.by_name["robots"]
    assert robots.calls == 2 and robots.rows == 2 * len(rows) and len(rows) == 2
    assert 0 < robots.longest <= robots.total == times.total


def test_ad_hoc_text_is_named_by_its_first_words_after_its_prefixes(store: EmbeddedStore) -> None:
    text = "PREFIX exsce: <https://example.org/exsce#>\nSELECT ?g WHERE {\n GRAPH ?g { ?s ?p ?o } }"
    with timing_queries() as times:
        store.select(text)
        assert store.ask("ASK { GRAPH ?g { ?s ?p ?o } }")
    assert sorted(times.by_name) == ['SPARQL "ASK { GRAPH ?g { ?s…"', 'SPARQL "SELECT ?g WHERE { GRAPH ?g…"']
    assert times.by_name['SPARQL "ASK { GRAPH ?g { ?s…"'].rows == 1
    assert ad_hoc_name("ASK {}") == 'SPARQL "ASK {}"'


def test_a_failing_query_is_timed_with_no_rows(store: EmbeddedStore) -> None:
    with timing_queries() as times, pytest.raises(StoreError):
        store.select("SELECT ?x WHERE { nonsense")
    (only,) = times.by_name.values()
    assert only.calls == 1 and only.rows == 0


def test_nothing_is_collected_outside_the_block(store: EmbeddedStore) -> None:
    with timing_queries() as times:
        pass
    run_query(store, "robots", {"scenario": "scenario_c"})
    assert times.calls == 0 and times.lines()[-1].split() == ["all", "0", "0.00"]


def test_the_table_is_slowest_first_with_the_sum() -> None:
    with timing_queries() as times:
        times.add("fast", 0.001, 3)
        times.add("slow", 0.010, 1)
        times.add("fast", 0.002, 3)
    assert [line.split() for line in times.lines()] == [
        ["query", "calls", "total", "ms", "max", "ms", "rows"],
        ["slow", "1", "10.00", "10.00", "1"],
        ["fast", "2", "3.00", "2.00", "6"],
        ["all", "3", "13.00"],
    ]
