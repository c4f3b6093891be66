"""``exscec execute --ros1 --runs 2 --verify``: several live runs judged as one trial, through the
same table, exit status and JUnit as ``exscec verify --trial``.

As in test_ros1_execute's verify test: a baseline from three simulated runs (about 120 s of
mission), and the tests' move_base server ending each goal after 0.2 s, so both live runs fail
every duration clause and pass waypoints_visited (three goals SUCCEEDED per robot).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from scipy.stats import binomtest

from tests.support.cli import run_exscec
from tests.support.paths import EXAMPLES
from tests.support.ros1_graph import on_graph, ros1_graph, start_server
from tests.support.shared_baseline import copy_of_baseline_project

SPEC = str(EXAMPLES / "brsu_building_c" / "scenario_c.exsce")


def test_several_live_runs_with_verify_are_one_trial(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, tmp_path_factory: pytest.TempPathFactory
) -> None:
    monkeypatch.chdir(copy_of_baseline_project(tmp_path_factory, tmp_path))
    with ros1_graph(tmp_path / "ros", sim_time=False) as graph:
        on_graph(graph, monkeypatch)
        start_server(graph, tmp_path / "goals.jsonl", "tiago1,tiago2", "--duration", "0.2")
        done = run_exscec(
            "execute",
            SPEC,
            "--ros1",
            "-o",
            "live",
            "--runs",
            "2",
            "--verify",
            "--junit",
            "trial.xml",
            timeout=240,
        )
    assert done.returncode == 1, done.stderr  # the duration clauses failed
    lines = done.stdout.splitlines()
    assert lines[0].split()[:4] == ["clause", "passed", "failed", "inconclusive"]
    rows = {" ".join(line.split()[:3]): line.split() for line in lines[1:]}
    upper = binomtest(0, 2).proportion_ci(confidence_level=0.95, method="wilson").high  # 0.66 < 0.8
    for robot in ("tiago1", "tiago2"):
        duration = rows[f"{robot} task_duration invariant"]
        assert duration[3:6] == ["0", "2", "0"] and duration[-1] == "failed" and upper < 0.8
        assert rows[f"{robot} waypoints_visited invariant"][3:6] == ["2", "0", "0"]
    assert "trial of 2 runs" in done.stderr
    suite = ET.parse(tmp_path / "trial.xml").getroot().find("testsuite")
    assert suite is not None and suite.get("name") == "scenario_c trial of 2 runs"
