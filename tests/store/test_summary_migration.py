"""``exscec store migrate`` on a store written before the run summaries (issue 52): kept as
``tests/fixtures/stores/before_run_summaries.nq.gz`` (written by exsce at commit 9cea1bc).

The answers after the migration are checked against the store's PROV read with rdflib and
plain Python here (an independent path), not against the summaries' code."""

from __future__ import annotations

import gzip
import json
from pathlib import Path

import pytest
from rdflib import Dataset, Literal, URIRef
from rdflib.namespace import RDF

from exsce_dsl.store.embedded import EmbeddedStore

from tests.support.cli import exscec_here
from tests.support.paths import ROOT

OLD_STORE = ROOT / "tests" / "fixtures" / "stores" / "before_run_summaries.nq.gz"
BASE = "https://www.sesame-project.org/scenarios/"
PROV = "http://www.w3.org/ns/prov#"
ORACLE = BASE + "oracles/"


@pytest.fixture(scope="module")
def old_prov() -> Dataset:
    dataset = Dataset()
    dataset.parse(data=gzip.decompress(OLD_STORE.read_bytes()).decode(), format="nquads")
    return dataset


def _value(dataset: Dataset, subject: object, predicate: URIRef) -> object:
    """The one object of ``subject predicate`` in any graph of ``dataset`` (None: none)."""
    return next((o for _, _, o, _ in dataset.quads((subject, predicate, None, None))), None)


def _store(folder: Path) -> Path:
    store = folder / "store"
    with EmbeddedStore(store) as embedded:
        embedded.load_nquads(gzip.decompress(OLD_STORE.read_bytes()), bulk=True)
    return store


def _rows(folder: Path, store: Path, *args: str) -> list[dict[str, str]]:
    done = exscec_here("query", *args, "-f", "json", "--store", str(store), cwd=folder)
    assert done.returncode == 0, done.stderr
    bindings = json.loads(done.stdout)["results"]["bindings"]
    return [{name: term["value"] for name, term in row.items()} for row in bindings]


def test_a_store_from_before_the_summaries_is_refused_until_migrated_and_then_answers_as_its_prov_says(
    tmp_path: Path, old_prov: Dataset
) -> None:
    store = _store(tmp_path)
    refused = exscec_here("runs", "--store", str(store), cwd=tmp_path)
    assert refused.returncode == 2
    assert "without the run summaries" in refused.stderr and "exscec store migrate" in refused.stderr
    assert "Traceback" not in refused.stderr

    found = exscec_here("store", "check", "--store", str(store), cwd=tmp_path)
    assert found.returncode != 0 and found.stdout.count("run without summary") == 5, found.stdout

    migrated = exscec_here("store", "migrate", "--store", str(store), cwd=tmp_path)
    assert migrated.returncode == 0, migrated.stderr
    assert "runs given their summary: 5" in migrated.stdout
    again = exscec_here("store", "migrate", "--store", str(store), cwd=tmp_path)
    assert "nothing to migrate" in again.stdout

    # the runs, as their activities say
    activities = {
        str(a): str(_value(old_prov, a, URIRef(BASE + "run")))
        for a, _, _, _ in old_prov.quads((None, RDF.type, URIRef(BASE + "run"), None))
    }
    runs = _rows(tmp_path, store, "runs", "-p", "scenario=yard_run")
    assert sorted(r["run"] for r in runs) == sorted(set(activities.values()))
    for row in runs:
        activity = URIRef(next(a for a, run in activities.items() if run == row["run"]))
        started = _value(old_prov, activity, URIRef(PROV + "startedAtTime"))
        assert (
            started is not None
            and Literal(row["start"], datatype=started.datatype).toPython() == started.toPython()
        )
        assert row["path"].startswith("/data/yard/") and row["path"].endswith(row["bag"])

    # the failed verdicts, as the verdict entities say
    failed = {
        str(v) for v, _, _, _ in old_prov.quads((None, URIRef(ORACLE + "outcome"), Literal("failed"), None))
    }
    assert failed, "the fixture's verification failed the run over speed"
    defects = [
        d for d in _rows(tmp_path, store, "run_defects", "-p", "scenario=yard_run") if d["kind"] == "failed"
    ]
    assert len(defects) == len(failed)
    for defect in defects:
        assert any(f"run_{defect['run']}/verdict-{defect['subject']}-" in verdict for verdict in failed)

    # the time over the speed limit, as the violation_duration values say
    seconds = sorted(
        float(_value(old_prov, e, URIRef(PROV + "value")))
        for e, _, _, _ in old_prov.quads(
            (None, URIRef(BASE + "runs/metricType"), Literal("violation_duration"), None)
        )
        if str(_value(old_prov, e, URIRef(BASE + "metric"))) == "max_velocity"
        and str(_value(old_prov, e, URIRef(PROV + "wasGeneratedBy"))) in activities
    )
    durations = _rows(
        tmp_path, store, "violation_durations", "-p", "scenario=yard_run", "-p", "metric=max_velocity"
    )
    assert sorted(float(r["seconds"]) for r in durations) == pytest.approx(seconds, abs=1e-12)
    assert any(s > 0 for s in seconds)

    checked = exscec_here("store", "check", "--store", str(store), cwd=tmp_path)
    assert checked.returncode == 0, checked.stdout + checked.stderr
