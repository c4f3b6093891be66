"""One live run from dispatch to verdict: ``exscec execute --ros1`` on a real roscore against the
tests' move_base server, then ``ingest`` and ``verify`` against scenario_c's baseline; the
run-time PROV is read from inside the bag (its ``.prov.json`` is removed first)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from tests.support.cli import run_exscec
from tests.support.paths import EXAMPLES
from tests.support.ros1_graph import on_graph, ros1_graph, start_server
from tests.support.shared_baseline import copy_of_baseline_project

SPEC = str(EXAMPLES / "brsu_building_c" / "scenario_c.exsce")


def rows(*args: str) -> list[dict[str, Any]]:
    done = run_exscec(*args, "-f", "json")
    assert done.returncode == 0, done.stderr
    return [{k: v["value"] for k, v in row.items()} for row in json.loads(done.stdout)["results"]["bindings"]]


def test_a_live_run_s_lineage_holds_its_dispatchers_goals_from_the_bag_its_values_and_verdicts(
    tmp_path_factory: pytest.TempPathFactory, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(copy_of_baseline_project(tmp_path_factory, tmp_path))
    with ros1_graph(tmp_path / "ros", sim_time=False) as graph:
        on_graph(graph, monkeypatch)
        start_server(
            graph, tmp_path / "goals.jsonl", "tiago1,tiago2", "--duration", "0.2", "--aborts", "tiago2:2"
        )
        done = run_exscec("execute", SPEC, "--ros1", "-o", "live", timeout=90)
    assert done.returncode == 0, done.stderr
    (beside,) = Path("live").glob("*.prov.json")
    (dispatched,) = [
        facts["exsce:run"]
        for bundle in json.loads(beside.read_text())["bundle"].values()
        for facts in bundle.get("activity", {}).values()
        if facts.get("prov:type", {}).get("$") == "exsce:run"
    ]
    beside.unlink()  # the bag's own /exsce/prov must say it
    (bag,) = Path("live").glob("*.bag")
    ingested = run_exscec("ingest", str(bag), "--scenario", SPEC)
    assert ingested.returncode == 0, ingested.stderr
    (run,) = [r["run"] for r in rows("runs") if r["path"] == str(bag.resolve())]
    judged = run_exscec("verify", run, "--scenario", SPEC)
    assert judged.returncode == 1, judged.stderr  # 0.2 s goals: the durations fail

    chain = rows("query", "run_lineage", "-p", f"run={run}")
    (execution,) = [r for r in chain if r["part"] == "execution"]
    assert (execution["item"], execution["detail"]) == (dispatched, "/exsce/prov")
    goals = {(g["robot"], g["item"]): g for g in chain if g["part"] == "goal"}
    assert len(goals) == 6
    assert goals[("tiago2", "tiago2-task_01-subtask_001-w_002")]["status"] == "ABORTED"  # its 2nd goal
    assert sum(g["status"] == "SUCCEEDED" for g in goals.values()) == 5
    (stored_bag,) = [r for r in chain if r["part"] == "bag"]
    assert stored_bag["item"] == bag.name
    assert any(r["part"] == "value" and r["metric"] == "mission_duration" for r in chain)
    verdicts = [r for r in chain if r["part"] == "verdict"]
    assert any(v["status"] == "failed" for v in verdicts)
    assert len([r for r in chain if r["part"] == "baseline"]) == 3

    printed = run_exscec("lineage", dispatched[:8])
    assert printed.returncode == 0, printed.stderr
    lines = printed.stdout.splitlines()
    assert lines[0] == f"run {run}"
    assert lines[2] == f"execution {dispatched} (the dispatcher's run, from /exsce/prov)"
    assert "  goal tiago2-task_01-subtask_001-w_002" in "\n".join(lines)
