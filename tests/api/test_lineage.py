"""One run from dispatch to verdict: ``exscec simulate`` (the kinematic executor), ``ingest``,
``baseline``, ``verify``, then the library's ``run_lineage`` query and ``exscec lineage RUN``.

The dispatcher's run id is read from the ``.prov.json`` that ``simulate`` wrote, with ``json``
alone; the run the store holds under the bag's content id and the dispatcher's run are one run.
"""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path
from typing import Any

import pytest

from tests.support.cli import exscec_here
from tests.support.paths import EXAMPLES
from tests.support.shared_baseline import copy_of_baseline_project

SPEC = str(EXAMPLES / "brsu_building_c" / "scenario_c.exsce")
BASE = "https://www.sesame-project.org/scenarios/"
INGESTED = re.compile(r": run ([0-9a-f-]{36}) \(")


def ok(*args: str, cwd: Path) -> str:
    done = exscec_here(*args, cwd=cwd)
    assert done.returncode == 0, done.stdout + done.stderr
    return done.stdout + done.stderr


def rows(*args: str, cwd: Path) -> list[dict[str, Any]]:
    answer = json.loads(ok(*args, "-f", "json", cwd=cwd))
    return [{k: v["value"] for k, v in row.items()} for row in answer["results"]["bindings"]]


@pytest.fixture(scope="module")
def judged(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, str, dict[str, Any]]:
    """A project with scenario_c's baseline and one more simulated run, ingested and verified:
    (the project, the run's stored id, its run-time PROV as written beside the bag)."""
    project = copy_of_baseline_project(tmp_path_factory, tmp_path_factory.mktemp("lineage"))
    ok("simulate", SPEC, "--runs", "1", "--seed", "5", "-o", "new", cwd=project)
    (bag,) = sorted((project / "new").glob("*.bag"))
    said = ok("ingest", str(bag), "--scenario", SPEC, cwd=project)
    found = INGESTED.search(said)
    assert found is not None, said
    judged = exscec_here("verify", found[1], "--scenario", SPEC, cwd=project)
    assert judged.returncode in (0, 1, 3), judged.stderr
    recorded = json.loads(bag.with_suffix(".prov.json").read_text(encoding="utf-8"))
    return project, found[1], recorded


def dispatched_id(recorded: dict[str, Any]) -> str:
    """The run id of the run-time PROV: its one activity typed exsce:run."""
    (run,) = [
        facts["exsce:run"]
        for bundle in recorded["bundle"].values()
        for facts in bundle.get("activity", {}).values()
        if facts.get("prov:type", {}).get("$") == "exsce:run"
    ]
    return str(run)


def test_one_library_query_returns_the_dispatchers_goals_the_bag_the_values_and_the_verdicts(
    judged: tuple[Path, str, dict[str, Any]],
) -> None:
    project, run, recorded = judged
    chain = rows("query", "run_lineage", "-p", f"run={run}", cwd=project)
    parts = [row["part"] for row in chain]
    assert parts == sorted(
        parts, key=["execution", "simulator", "goal", "bag", "value", "verdict", "baseline"].index
    )
    (execution,) = [r for r in chain if r["part"] == "execution"]
    (simulator,) = [r for r in chain if r["part"] == "simulator"]  # the run-time PROV names what played it
    assert (simulator["item"], simulator["detail"]) == ("kinematic", "")
    assert execution["item"] == dispatched_id(recorded)
    assert execution["detail"].endswith(".prov.json")  # simulate records it beside the bag
    goals = [r for r in chain if r["part"] == "goal"]
    assert [(g["robot"], g["item"]) for g in goals] == [
        ("tiago1", "tiago1-task_01-subtask_001-w_001"), ("tiago1", "tiago1-task_01-subtask_001-w_002"),
        ("tiago1", "tiago1-task_02-subtask_001-w_001"), ("tiago2", "tiago2-task_01-subtask_001-w_001"),
        ("tiago2", "tiago2-task_01-subtask_001-w_002"), ("tiago2", "tiago2-task_02-subtask_001-w_001"),
    ]  # fmt: skip
    assert {g["status"] for g in goals} == {"SUCCEEDED"}
    assert goals[0]["pose"].startswith("classroom_c022-w001-")
    (bag,) = [r for r in chain if r["part"] == "bag"]
    assert Path(bag["path"]).name == bag["item"] and Path(bag["path"]).parent.name == "new"
    values = [r for r in chain if r["part"] == "value"]
    whole = rows("query", "run_metric_values", "-p", f"run={run}", cwd=project)
    segments = rows("query", "run_segment_values", "-p", f"run={run}", cwd=project)
    assert len(values) == len(whole) + len(segments)
    assert {"tiago1", "tiago2"} <= {v.get("robot") for v in values}
    verdicts = [r for r in chain if r["part"] == "verdict"]
    assert len(verdicts) == len([v for v in rows("query", "verdicts", cwd=project) if v["run"] == run])
    assert {v["status"] for v in verdicts} <= {"passed", "failed", "inconclusive"}
    used = {u for v in verdicts for u in v.get("runs", "").split()}
    baseline = {r["item"] for r in chain if r["part"] == "baseline"}
    stored = {r["run"] for r in rows("runs", cwd=project)}
    assert baseline == used & stored and len(baseline) == 3 and run not in baseline


def test_the_run_time_prov_s_run_and_the_ingested_run_are_one(
    judged: tuple[Path, str, dict[str, Any]],
) -> None:
    """The run-time PROV's run IRI is in the store, and its bag is the ingested run's bag."""
    project, run, recorded = judged
    dispatched = dispatched_id(recorded)
    ask = (
        "PREFIX prov: <http://www.w3.org/ns/prov#> "
        f"ASK {{ GRAPH ?g {{ ?bag prov:alternateOf ?recorded . ?recorded prov:wasGeneratedBy <{BASE}runs/run_{dispatched}> }} "
        f"GRAPH ?r {{ ?bag prov:wasGeneratedBy <{BASE}runs/run_{run}> }} }}"
    )
    assert "true" in ok("sparql", ask, cwd=project).lower()
    # the stored id and the dispatcher's (or a prefix of it) name the same run
    by_dispatch = ok("lineage", dispatched[:8], cwd=project)
    assert by_dispatch == ok("lineage", run, cwd=project)
    assert by_dispatch.splitlines()[0] == f"run {run}"


def test_exscec_lineage_run_prints_the_chain(judged: tuple[Path, str, dict[str, Any]]) -> None:
    project, run, recorded = judged
    lines = ok("lineage", run[:8], cwd=project).splitlines()
    assert lines[:3] == [
        f"run {run}",
        "scenario scenario_c",
        f"execution {dispatched_id(recorded)} (the dispatcher's run, from {recorded_name(project)})",
    ]
    assert sum(line.startswith("  goal ") for line in lines) == 6
    assert any(line.startswith("bag ") and "/new/" in line for line in lines)
    assert any(line.startswith("  distance_travelled of tiago1 = ") for line in lines)
    assert any(line.startswith("    window: ") for line in lines)  # each value with what it used
    assert any(re.match(r"^verdicts \(\d+\)$", line) for line in lines)
    at = lines.index("baseline runs the verdicts used")
    assert len(lines[at + 1 :]) == 3


def recorded_name(project: Path) -> str:
    (prov,) = (project / "new").glob("*.prov.json")
    return prov.name


def test_reingesting_the_bag_is_still_skipped_under_the_same_run(
    judged: tuple[Path, str, dict[str, Any]],
) -> None:
    project, run, _ = judged
    (bag,) = sorted((project / "new").glob("*.bag"))
    said = ok("ingest", str(bag), "--scenario", SPEC, cwd=project)
    assert f"already a run of scenario 'scenario_c' (run {run})" in said


def test_a_replaced_run_keeps_its_execution_and_loses_it_with_its_run_time_prov(tmp_path: Path) -> None:
    """``ingest --replace`` writes the execution again (no conflict with the stored one); the
    .prov.json removed (simulate records no /exsce/prov in the bag), the run has none."""
    ok("simulate", SPEC, "--runs", "1", "--seed", "9", "-o", "sim", cwd=tmp_path)
    (bag,) = (tmp_path / "sim").glob("*.bag")
    found = INGESTED.search(ok("ingest", str(bag), "--scenario", SPEC, cwd=tmp_path))
    assert found is not None
    again = ok("ingest", str(bag), "--scenario", SPEC, "--replace", cwd=tmp_path)
    assert f"run {found[1]} analysed again" in again
    lines = ok("lineage", found[1], cwd=tmp_path).splitlines()
    assert lines[2].startswith("execution ") and sum(line.startswith("  goal ") for line in lines) == 6
    bag.with_suffix(".prov.json").unlink()
    ok("ingest", str(bag), "--scenario", SPEC, "--replace", cwd=tmp_path)
    lines = ok("lineage", found[1], cwd=tmp_path).splitlines()
    assert "execution: no run-time PROV came with the bag" in lines
    assert not any(line.startswith("  goal ") for line in lines)
    assert "verdicts: none (exscec verify RUN)" in lines


def test_the_chain_of_a_derived_scenario_s_run_starts_at_its_base(tmp_path: Path) -> None:
    shutil.copytree(EXAMPLES / "brsu_building_c", tmp_path / "c")
    ok("derive", "c/scenario_c.exsce", "-t", "remove_robot", "--robot", "tiago2", "--reassign", "tiago1",
       "--id", "c_one", "-o", "c/c_one.exsce", "--add-to-store", cwd=tmp_path)  # fmt: skip
    ok("simulate", "c/c_one.exsce", "--runs", "1", "-o", "sim", cwd=tmp_path)
    said = ok(
        "ingest", *map(str, (tmp_path / "sim").glob("*.bag")), "--scenario", "c/c_one.exsce", cwd=tmp_path
    )
    found = INGESTED.search(said)
    assert found is not None, said
    chain = rows("query", "run_lineage", "-p", f"run={found[1]}", cwd=tmp_path)
    assert [(r["part"], r.get("item")) for r in chain][:1] == [("derived_from", "scenario_c")]
    assert {r["scenario"] for r in chain} == {"c_one"}
    assert {r["robot"] for r in chain if r["part"] == "goal"} == {"tiago1"}  # tiago2's tasks reassigned
    lines = ok("lineage", found[1], cwd=tmp_path).splitlines()
    assert lines[1:3] == ["scenario c_one", "  derived from scenario_c by remove_robot"]
