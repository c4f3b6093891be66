"""``is invariant at 95 %`` on the executor's runs: the stored oracle's tolerance is the half-width of
Student's prediction interval for one new run, computed here with numpy and scipy from the values
read out of the store by a SPARQL query of this test; and the confidence and n are in its PROV."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from prov.model import ProvDocument
from pyoxigraph import Literal, NamedNode
from scipy import stats

from exsce_dsl.errors import NotEnoughRuns
from exsce_dsl.lang import load_spec
from exsce_dsl.model import Scenario
from exsce_dsl.model.acceptance import Acceptance
from exsce_dsl.oracles.baseline import baseline_oracles
from exsce_dsl.prov.oracle import compile_oracles
from exsce_dsl.rdf import to_quads
from exsce_dsl.rdf.shacl import validate
from exsce_dsl.runs.ingest import ingest_bags
from exsce_dsl.sim.run import simulate
from exsce_dsl.store.embedded import EmbeddedStore
from exsce_dsl.store.queries import oracles as stored_oracles
from exsce_dsl.store.queries.library import prologue, standard_prefixes
from exsce_dsl.store.writing import add_prov

from tests.support.map_files import write_map
from tests.support.yard_spec import YARD_SPEC

CRITERIA = """\
  scenario "performs as before" {
    given at least 4 baseline runs
    when yard_mission runs
    then each robot waypoints_visited is invariant within 0
     and each robot task_duration is invariant within 20 %
     and each robot distance_travelled is invariant within 10 %
  }"""
AT_CONFIDENCE = """\
  scenario "performs as before" {
    given at least 1 baseline runs
    when yard_mission runs
    then r1 task_duration is invariant at 95 %
     and r2 task_duration is invariant at 99 %
     and r1 max_velocity is invariant
  }"""
RUNS = 7

# every run's value of a robot's metric, read straight from the run graphs the ingest wrote
VALUES = """
SELECT ?run ?value WHERE {
  GRAPH ?g {
    ?entity prov:wasGeneratedBy ?run ; run:metricType ?metric ; exsce:robot ?robot ; prov:value ?value .
  }
  FILTER(!CONTAINS(STR(?g), "revision="))
}"""


@pytest.fixture(scope="module")
def yard(tmp_path_factory: pytest.TempPathFactory) -> tuple[EmbeddedStore, Scenario, Acceptance, list[str]]:
    """A store holding seven clean runs of the yard, and criteria written at a confidence."""
    folder = tmp_path_factory.mktemp("yard")
    write_map(folder, size=200)
    assert CRITERIA in YARD_SPEC
    (folder / "spec.exsce").write_text(YARD_SPEC.replace(CRITERIA, AT_CONFIDENCE))
    spec = load_spec(folder / "spec.exsce")
    scenario = spec.scenario()
    acceptance = spec.acceptance_of(scenario.id)
    assert acceptance is not None
    store = EmbeddedStore(folder / "store")
    bags = [run.bag for run in simulate(scenario, folder / "runs", RUNS, seed=3)]
    results = ingest_bags(bags, scenario, store)
    assert not any(r.failed for r in results)
    return store, scenario, acceptance, [r.run_id for r in results if r.run_id]


def stored_values(store: EmbeddedStore, metric: str, robot: str, runs: list[str]) -> np.ndarray:
    """The values of ``robot``'s ``metric`` in ``runs``, in their order."""
    found = []
    for run in runs:
        activity = NamedNode(standard_prefixes()["run"] + f"run_{run}")
        bindings = {"metric": Literal(metric), "robot": Literal(robot), "run": activity}
        rows = list(store.select(prologue() + VALUES, bindings))
        assert len(rows) == 1, (run, rows)
        found.append(float(rows[0]["value"].value))  # type: ignore[union-attr]
    return np.array(found)


def confidence_violations(document: ProvDocument) -> list[str]:
    """The SHACL violations about a confidence (the oracle bundle alone lacks the scenario's
    records, which other shapes want)."""
    return [
        v.message
        for v in validate(to_quads(document), ["oracles"])
        if "confidence" in v.message or "sample size" in v.message
    ]


def half_width(values: np.ndarray, confidence: float) -> float:
    n = len(values)
    return float(stats.t.ppf((1 + confidence) / 2, n - 1) * np.std(values, ddof=1) * np.sqrt(1 + 1 / n))


def test_the_tolerance_is_the_prediction_interval_of_the_runs(
    yard: tuple[EmbeddedStore, Scenario, Acceptance, list[str]],
) -> None:
    store, scenario, acceptance, runs = yard
    oracles = {o.name: o for o in baseline_oracles(store, acceptance, scenario)}
    duration = stored_values(store, "task_duration", "r1", runs)
    other = stored_values(store, "task_duration", "r2", runs)
    speed = stored_values(store, "max_velocity", "r1", runs)
    assert min(np.std(duration), np.std(other), np.std(speed)) > 0  # bands of some width
    r1 = oracles["r1-task_duration"]
    assert (r1.value, r1.confidence, len(r1.sources)) == (pytest.approx(duration.mean()), 0.95, RUNS)
    assert r1.tolerance == pytest.approx(half_width(duration, 0.95), rel=1e-9)
    r2 = oracles["r2-task_duration"]
    assert r2.tolerance == pytest.approx(half_width(other, 0.99), rel=1e-9)
    # the method's default stays one population standard deviation, and has no confidence
    default = oracles["r1-max_velocity"]
    assert default.confidence is None
    assert default.tolerance == pytest.approx(np.std(speed), rel=1e-9)


def test_a_baseline_of_chosen_runs_uses_only_those(
    yard: tuple[EmbeddedStore, Scenario, Acceptance, list[str]],
) -> None:
    store, scenario, acceptance, runs = yard
    chosen = runs[2:5]
    (r1,) = [
        o for o in baseline_oracles(store, acceptance, scenario, runs=chosen) if o.name == "r1-task_duration"
    ]
    duration = stored_values(store, "task_duration", "r1", chosen)
    assert set(r1.sources) == set(chosen)
    assert r1.tolerance == pytest.approx(half_width(duration, 0.95), rel=1e-9)


def test_one_run_is_not_enough_for_a_confidence(
    yard: tuple[EmbeddedStore, Scenario, Acceptance, list[str]],
) -> None:
    store, scenario, acceptance, runs = yard
    with pytest.raises(
        NotEnoughRuns, match=r"'task_duration' of robot 'r1' at 95 % confidence needs .* at least 2 runs"
    ):
        baseline_oracles(store, acceptance, scenario, runs=runs[:1])


def test_the_confidence_and_n_are_in_the_oracles_prov_and_read_back(
    yard: tuple[EmbeddedStore, Scenario, Acceptance, list[str]],
) -> None:
    store, scenario, acceptance, runs = yard
    built = baseline_oracles(store, acceptance, scenario)
    document = compile_oracles(scenario.id, built, checked=True)
    assert confidence_violations(document) == []
    wrong = replace(built[0], confidence=1.0, sources=built[0].sources[:1])
    found = confidence_violations(compile_oracles(scenario.id, [wrong, *built[1:]]))
    assert any("strictly between 0.5 and 1" in m for m in found), found
    assert any("sample size (oracle:sampleSize), an integer of at least 2" in m for m in found), found
    add_prov(store, document, replace=True)
    rows = list(
        store.select(
            prologue()
            + "SELECT ?c ?n ?t WHERE { GRAPH ?g { ?u oracle:confidence ?c ; oracle:sampleSize ?n ; oracle:tolerance ?t } }"
        )
    )
    assert sorted((float(r["c"].value), int(r["n"].value)) for r in rows) == [(0.95, RUNS), (0.99, RUNS)]
    again = {o.name: o for o in stored_oracles(store, scenario.id)}
    assert again["r1-task_duration"].confidence == 0.95
    assert again["r2-task_duration"].confidence == 0.99
    assert again["r1-max_velocity"].confidence is None
    assert again["r1-task_duration"].tolerance == pytest.approx(
        {o.name: o for o in built}["r1-task_duration"].tolerance
    )
