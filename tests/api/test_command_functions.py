"""The functions the commands of ``exscec`` are made of, called from Python (issue 49, item 3):
each command is an ``api`` function first, with a typed result, and the command only prints it.

One simulated run of scenario_c is ingested into a store folder once for the module; each test
checks a function's result against what is known independently (the N-Quads export has a line
per statement, the run ingested is the one the store lists, a file formatted twice is unchanged).
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from exsce_dsl import api
from exsce_dsl.errors import ExsceError, StoreError
from exsce_dsl.remedies import REPLACE_FILES, SELECT_OR_ASK

from tests.support.paths import EXAMPLES

SPEC = EXAMPLES / "brsu_building_c" / "scenario_c.exsce"


@pytest.fixture(scope="module")
def project(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, str, Path]:
    """A folder with one simulated run of scenario_c, ingested into its store: (folder, store, bag)."""
    folder = tmp_path_factory.mktemp("commands")
    scenario = api.load_cached(SPEC).scenario(None)
    [run] = list(api.simulating(scenario, folder / "sim", 1, seed=3))
    store = str(folder / "store")
    results, tally = api.ingest_files(store, scenario, [run.bag])
    assert tally == api.IngestTally(ingested=1, replaced=0, skipped=0, failed=0), results
    return folder, store, Path(run.bag)


def test_ingest_files_skips_a_bag_it_holds(project: tuple[Path, str, Path]) -> None:
    _, store, bag = project
    _, tally = api.ingest_files(store, api.load(SPEC).scenario(None), [bag])
    assert (tally.ingested, tally.skipped, tally.failed) == (0, 1, 0)


def test_stored_runs_lists_the_run_and_warns_of_an_unknown_scenario(project: tuple[Path, str, Path]) -> None:
    _, store, _ = project
    listed = api.stored_runs(store, "scenario_c")
    assert listed.rows is not None and len(listed.rows) == 1 and listed.warnings == ()
    unknown = api.stored_runs(store, "scenario_cc")
    assert unknown.rows is not None and len(unknown.rows) == 0
    assert len(unknown.warnings) == 1 and "scenario_c" in unknown.warnings[0]


def test_answer_query_and_its_text(project: tuple[Path, str, Path]) -> None:
    _, store, _ = project
    answer = api.answer_query(store, "runs", {"scenario": ["scenario_c"]})
    assert answer.rows is not None and len(answer.rows) == 1
    csv = api.answer_text(answer.rows, "csv")
    header, row, end = csv.split("\r\n")
    assert header.split(",") == list(answer.rows.variables) and row and end == ""
    assert "runs" in {q.name for q in api.library_queries()}


def test_answer_sparql_asks_and_refuses_a_construct(project: tuple[Path, str, Path]) -> None:
    _, store, _ = project
    assert api.answer_sparql(store, "ASK { GRAPH ?g { ?r a exsce:run } }") is True
    assert api.answer_sparql(store, "ASK { GRAPH ?g { ?r a exsce:no_such_class } }") is False
    with pytest.raises(ExsceError, match="neither a SELECT nor an ASK query") as refused:
        api.answer_sparql(store, "CONSTRUCT { ?s ?p ?o } WHERE { ?s ?p ?o }")
    assert refused.value.remedy == SELECT_OR_ASK and "exscec" not in refused.value.message


def test_store_info_graphs_and_export_agree(project: tuple[Path, str, Path]) -> None:
    _, store, _ = project
    info = api.store_info(store)
    assert info.kind == "embedded Oxigraph" and info.statements > 0 and info.index_graphs > 0
    every = api.store_graphs(store, with_index=True)
    shown = api.store_graphs(store)
    assert sum(every.sizes.values()) == info.statements and every.hidden_index == 0
    assert shown.hidden_index == info.index_graphs == len(every.sizes) - len(shown.sizes)
    assert len(shown.sizes) == info.graphs + info.revisions
    quads = [line for line in api.export_store(store, "nq").splitlines() if line.strip()]
    assert len(quads) == info.statements  # N-Quads: one statement a line


def test_add_to_store_then_clear_store(tmp_path: Path) -> None:
    store = str(tmp_path / "store")
    document = api.compile_prov(api.load(SPEC))
    assert not isinstance(document, str)
    report = api.add_to_store(document, store)
    graphs = len(api.store_graphs(store, with_index=True).sizes)
    assert graphs == len(report.added) > 0 and report.statements == api.store_info(store).statements
    cleared = api.clear_store(store)
    assert cleared.removed == graphs and api.store_info(store).statements == 0


def test_lineage_of_a_scenario_and_of_a_run(project: tuple[Path, str, Path]) -> None:
    _, store, _ = project
    with api.open_store(store, read_only=True) as opened:
        scenario = api.lineage_of(opened, "scenario_c")
        assert isinstance(scenario, api.ScenarioLineage)
        assert scenario.ancestry == () and scenario.descendants == ()
        assert scenario.text() == "scenario_c  (this one)"
        listed = api.stored_runs(store).rows
        assert listed is not None and len(listed) == 1
        term = listed.rows[0][listed.variables.index("run")]
        assert term is not None
        uuid = term.value
        run = api.lineage_of(opened, uuid[:8])
        assert isinstance(run, api.RunLineage) and run.chain.scenario == "scenario_c"


def test_update_token_is_minted_or_checked() -> None:
    minted = api.update_token(None)
    assert minted.minted and len(minted.text) >= 16 and minted.text != api.update_token(None).text
    assert api.update_token("x" * 20) == api.UpdateToken("x" * 20, minted=False)
    with pytest.raises(StoreError):
        api.update_token("short")
    assert api.is_loopback("127.0.0.1") and api.is_loopback("localhost") and not api.is_loopback("8.8.8.8")


def test_format_file_changes_an_untidy_file_once(tmp_path: Path) -> None:
    folder = tmp_path / "spec"
    shutil.copytree(SPEC.parent, folder)
    spec = folder / "scenario_c.exsce"
    assert not api.format_file(spec).changed  # the example is canonical
    spec.write_text(spec.read_text(encoding="utf-8").replace("\n", "\n\n\n"), encoding="utf-8")
    untidy = api.format_file(spec)
    assert untidy.changed and untidy.diff().startswith(f"--- {spec}\n")
    untidy.write()
    assert not api.format_file(spec).changed


def test_export_then_import_the_method_s_yaml(tmp_path: Path) -> None:
    written = api.export_spec(SPEC, "yaml", tmp_path / "yaml")
    [scenario_file] = [p for p in written if p.name == "scenario_c.yaml"]
    assert all(p.exists() for p in written) and not api.is_oracle_file(scenario_file)
    tasks = [p.parent for p in written if p != scenario_file][:1]
    imported = api.import_scenario_file(scenario_file, tmp_path / "back", tasks)
    assert imported and all(p.suffix == ".exsce" and p.exists() for p in imported)
    with pytest.raises(ExsceError, match="no acceptance criteria|cannot be written|baseline"):
        api.export_spec(SPEC, "oracle-yaml", tmp_path / "oracles")


def test_generate_writes_a_target_s_files(tmp_path: Path) -> None:
    paths = api.generate("dispatcher-config", SPEC, tmp_path / "out")
    assert paths and all(p.exists() and tmp_path / "out" in p.parents for p in paths)
    assert api.generate("dispatcher-config", SPEC, tmp_path / "out", force=True) == paths


def test_files_in_the_way_are_said_without_a_flag(tmp_path: Path) -> None:
    """The library says what to do in words; only the command line names its option (--force)."""
    api.generate("dispatcher-config", SPEC, tmp_path)
    with pytest.raises(ExsceError) as refused:
        api.generate("dispatcher-config", SPEC, tmp_path)
    assert refused.value.remedy == REPLACE_FILES and "--" not in refused.value.message
    assert refused.value.message.startswith("would overwrite ")


def test_describe_bags_and_prov_text(project: tuple[Path, str, Path]) -> None:
    _, _, bag = project
    [info] = api.describe_bags([bag])
    assert isinstance(info, api.BagInfo) and info.path and info.topics
    document = api.compile_prov(api.load(SPEC))
    assert not isinstance(document, str)
    assert api.prov_text(document, "provn").startswith("document")


def test_gather_and_write_report(project: tuple[Path, str, Path], tmp_path: Path) -> None:
    _, store, _ = project
    contents = api.gather_report(store, [SPEC])
    assert [s.id for s in contents.scenarios] == ["scenario_c"] and len(contents.scenarios[0].runs) == 1
    drawn: list[int] = []
    index = api.write_report(contents, tmp_path / "report", drawn.append)
    assert index.exists() and index.suffix == ".html" and sum(drawn) == 1
