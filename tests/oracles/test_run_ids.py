"""Run ids as they are printed: every command and API function that takes a run takes any unique
prefix of its uuid (the eight characters tables print), the whole uuid or the run's IRI; a prefix
two runs share is an error listing both, an unknown one an error with the closest ids.

The runs are the executor's, in the yard of tests/oracles/test_verify_e2e; the uuids the tests
expect are read from `exscec runs -f json`, not from the resolver.
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import pytest
from prov.model import ProvDocument

from exsce_dsl import api
from exsce_dsl.lang import load_spec
from exsce_dsl.mcp_server.store_tools import stored_run
from exsce_dsl.prov.run import compile_run
from exsce_dsl.runs.analyse import analyse_bag
from exsce_dsl.sim.run import simulate
from exsce_dsl.store.base import Store
from exsce_dsl.store.open import open_store
from exsce_dsl.store.queries import AmbiguousRunError, UnknownRunError, resolve_run
from exsce_dsl.store.remote import RemoteStore
from exsce_dsl.store.writing import add_prov

from tests.support.cli import exscec_here
from tests.support.map_files import write_map
from tests.support.store_servers import virtuoso_server
from tests.support.yard_spec import YARD_SPEC

RUN_IRI = "https://www.sesame-project.org/scenarios/runs/run_{}"


def _stored_runs(folder: Path) -> dict[str, str]:
    """Bag file name → run uuid, as `exscec runs -f json` lists them."""
    listed = exscec_here("runs", "-f", "json", cwd=folder)
    assert listed.returncode == 0, listed.stderr
    rows = json.loads(listed.stdout)["results"]["bindings"]
    return {row["bag"]["value"]: row["run"]["value"] for row in rows}


@pytest.fixture(scope="module")
def yard(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """The project folder with four runs ingested and the baseline built from them, and a fifth
    clean bag, not ingested."""
    folder = tmp_path_factory.mktemp("yard_ids")
    write_map(folder, size=200)
    (folder / "spec.exsce").write_text(YARD_SPEC)
    scenario = load_spec(folder / "spec.exsce").scenario()
    bags = [run.bag for run in simulate(scenario, folder / "runs", 5, seed=1)]
    ingested = exscec_here("ingest", *map(str, bags[:4]), "--scenario", "spec.exsce", cwd=folder)
    assert ingested.returncode == 0, ingested.stderr
    built = exscec_here("baseline", "spec.exsce", cwd=folder)
    assert built.returncode == 0, built.stderr
    return folder, bags[4]


def test_verify_takes_the_eight_characters_tables_print(yard: tuple[Path, Path]) -> None:
    folder, new_bag = yard
    first = exscec_here("verify", str(new_bag), "--scenario", "spec.exsce", "--no-record", cwd=folder)
    assert first.returncode == 0, first.stdout + first.stderr
    printed = {line.split()[0] for line in first.stdout.splitlines()[1:]}  # the table's run column
    assert len(printed) == 1
    eight = printed.pop()
    uuid = _stored_runs(folder)[new_bag.name]
    assert len(eight) == 8 and uuid.startswith(eight)

    again = exscec_here("verify", eight, "--scenario", "spec.exsce", "--json", "--no-record", cwd=folder)
    assert again.returncode == 0, again.stderr
    assert "no run" not in again.stderr
    judged = json.loads(again.stdout)
    assert len(judged) == 11 and {v["run"] for v in judged} == {uuid}

    by_iri = exscec_here("verify", RUN_IRI.format(uuid), "--scenario", "spec.exsce", "--json", cwd=folder)
    assert by_iri.returncode == 0, by_iri.stderr
    assert {v["run"] for v in json.loads(by_iri.stdout)} == {uuid}

    values = exscec_here("query", "run_metric_values", "-p", f"run={eight}", "-f", "json", cwd=folder)
    assert values.returncode == 0, values.stderr
    rows = json.loads(values.stdout)["results"]["bindings"]
    assert rows and {row["run"]["value"] for row in rows} == {uuid}
    one = exscec_here(
        "query", "run_metric", "-p", f"run={eight.upper()}", "-p", "metric=distance_travelled", "-p", "robot=r1",
        cwd=folder,
    )  # fmt: skip
    assert one.returncode == 0 and len(one.stdout.splitlines()) == 3, one.stdout + one.stderr

    with api.open_store(str(folder / ".exsce" / "store")) as store:
        table = api.metrics(store, runs=[eight])
        assert set(table["run"]) == {uuid} and set(table["scenario"]) == {"yard_run"}
        assert {
            r.run for r in api.verify(store, load_spec(folder / "spec.exsce"), [eight], record=False).verdicts
        } == {uuid}
        assert stored_run(store, eight).uuid == uuid  # the MCP server's tools and resources


@pytest.fixture(scope="module")
def twin_runs(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, str], list[ProvDocument]]:
    """A store holding three runs of two bags whose uuids share their first four characters
    (``abcd``, and ``abcd1``): real analyses of the executor's bags, stored under chosen uuids."""
    folder = tmp_path_factory.mktemp("twins")
    write_map(folder, size=200)
    (folder / "spec.exsce").write_text(YARD_SPEC)
    scenario = load_spec(folder / "spec.exsce").scenario()
    bags = [run.bag for run in simulate(scenario, folder / "runs", 3, seed=4)]
    uuids = {
        bags[0].name: "abcd1234-0000-4000-8000-000000000001",
        bags[1].name: "abcd1299-0000-4000-8000-000000000002",
        bags[2].name: "abcd5678-0000-4000-8000-000000000003",
    }
    documents = [
        compile_run(dataclasses.replace(analyse_bag(bag, scenario).run, uuid=uuids[bag.name]), scenario)
        for bag in bags
    ]
    with open_store(str(folder / ".exsce" / "store")) as store:
        for document in documents:
            add_prov(store, document)
    return folder, uuids, documents


@pytest.fixture(scope="module")
def twins(twin_runs: tuple[Path, dict[str, str], list[ProvDocument]]) -> tuple[Path, dict[str, str]]:
    return twin_runs[0], twin_runs[1]


def test_an_ambiguous_run_prefix_lists_the_candidates(twins: tuple[Path, dict[str, str]]) -> None:
    folder, uuids = twins
    assert _stored_runs(folder) == uuids  # stored as chosen

    ambiguous = exscec_here("query", "run_metric_values", "-p", "run=abcd", cwd=folder)
    assert ambiguous.returncode == 2, ambiguous.stderr
    said = ambiguous.stderr
    assert "run id 'abcd' is ambiguous: 3 runs start with it" in said and "Traceback" not in said
    for bag, uuid in uuids.items():  # each candidate on its line, with its scenario and bag
        assert any(uuid in line and "yard_run" in line and bag in line for line in said.splitlines()), said
    two = exscec_here("verify", "abcd12", "--scenario", "spec.exsce", cwd=folder)
    assert two.returncode == 2 and "2 runs start with it" in two.stderr and "abcd5678" not in two.stderr

    one = exscec_here("query", "run_metric_values", "-p", "run=abcd5", "-f", "json", cwd=folder)
    assert one.returncode == 0, one.stderr
    assert {r["run"]["value"] for r in json.loads(one.stdout)["results"]["bindings"]} == {
        "abcd5678-0000-4000-8000-000000000003"
    }

    unknown = exscec_here("query", "run_metric_values", "-p", "run=abce12", cwd=folder)
    assert unknown.returncode == 2, unknown.stderr
    assert "the store holds no run abce12; the closest ids" in unknown.stderr
    assert "abcd1234-0000-4000-8000-000000000001" in unknown.stderr  # shares 'abc', as all three do

    short = exscec_here("verify", "abc", "--scenario", "spec.exsce", cwd=folder)
    assert short.returncode == 2 and "run id 'abc' is too short: give at least 4 characters" in short.stderr
    pasted = exscec_here("query", "run_metric_values", "-p", 'run=abcd" } UNION { ?s ?p ?o', cwd=folder)
    assert pasted.returncode == 2 and "is not a run id" in pasted.stderr, pasted.stderr

    with api.open_store(str(folder / ".exsce" / "store")) as store:
        with pytest.raises(api.AmbiguousRunError) as raised:
            api.metrics(store, runs=["abcd1"])
        assert {c.uuid for c in raised.value.candidates} == set(list(uuids.values())[:2])
        with pytest.raises(api.UnknownRunError):
            api.query(store, "run_metric_values", run="ffff")


def test_verifying_a_run_of_the_baseline_warns(yard: tuple[Path, Path]) -> None:
    """The baseline was built from the four runs ingested first (A); the fifth (B) is new."""
    folder, new_bag = yard
    stored = _stored_runs(folder)
    a = next(uuid for bag, uuid in sorted(stored.items()) if bag != new_bag.name)
    b = stored[new_bag.name]
    own = exscec_here("verify", a[:8], "--scenario", "spec.exsce", "--no-record", cwd=folder)
    assert own.returncode == 0, own.stderr  # it passes, as a run of its own mean does
    warned = [line for line in own.stderr.splitlines() if line.startswith("warning:")]
    assert warned == [
        f"warning: run {a[:8]} is one of the 4 runs the baseline of 'yard_run' was built from: "
        "its verdicts against that baseline say little (judge runs the baseline did not use)"
    ]
    new = exscec_here("verify", b, "--scenario", "spec.exsce", "--no-record", cwd=folder)
    assert new.returncode == 0 and "warning" not in new.stderr, new.stderr

    with api.open_store(str(folder / ".exsce" / "store")) as store:
        spec = load_spec(folder / "spec.exsce")
        both = api.verify(store, spec, [a, b], record=False)
        assert len(both.warnings) == 1 and both.warnings[0].startswith(f"run {a[:8]} is one of the 4 runs")
        assert api.verify(store, spec, [b], record=False).warnings == ()


def test_virtuoso_resolves_run_prefixes_as_the_embedded_store_does(
    twin_runs: tuple[Path, dict[str, str], list[ProvDocument]], tmp_path: Path
) -> None:
    folder, uuids, documents = twin_runs
    with open_store(str(folder / ".exsce" / "store")) as store:
        embedded = _resolutions(store)
    with virtuoso_server(tmp_path / "virtuoso") as server:
        remote = RemoteStore(f"{server.url}/sparql", timeout=20)
        for document in documents:
            add_prov(remote, document)
        assert _resolutions(remote) == embedded
    assert embedded[0] == "abcd5678-0000-4000-8000-000000000003" == embedded[1]
    assert embedded[2] == sorted(uuids.values()) and embedded[3] == sorted(uuids.values())[:2]


def _resolutions(store: Store) -> tuple[object, ...]:
    """What the resolver makes of a unique prefix, an IRI, an ambiguous prefix, a wrong one."""
    with pytest.raises(AmbiguousRunError) as ambiguous:
        resolve_run(store, "abcd")
    with pytest.raises(UnknownRunError) as unknown:
        resolve_run(store, "abce")
    return (
        resolve_run(store, "ABCD5"),
        resolve_run(store, RUN_IRI.format("abcd5678-0000-4000-8000-000000000003")),
        sorted(c.uuid for c in ambiguous.value.candidates),
        sorted(c.uuid for c in unknown.value.closest)[:2],
    )
