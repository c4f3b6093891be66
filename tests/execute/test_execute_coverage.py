"""``exscec execute --verify`` on a live ROS 1 graph never passes a run whose mission did not
complete: the stand-in aborts tiago1's second goal, the `stop-mission` policy stops the mission
there, and what the run met is inconclusive (exit 3), as ``verify`` would say of the same bag.

A baseline from three simulated runs of scenario_c makes the oracles; the live run is the
stand-in's (the kinematic executor on the graph, simulated time at 20×).
"""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from tests.support.cli import run_exscec
from tests.support.ros1_graph import require_ros1
from tests.support.shared_baseline import copy_of_baseline_project

SPEC = str(Path(__file__).resolve().parents[2] / "examples" / "brsu_building_c" / "scenario_c.exsce")


def test_a_stopped_mission_is_inconclusive_through_execute_verify(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, tmp_path_factory: pytest.TempPathFactory
) -> None:
    require_ros1()
    monkeypatch.chdir(copy_of_baseline_project(tmp_path_factory, tmp_path))
    done = run_exscec(
        "execute", SPEC, "--ros1", "--start-master", "--stand-in", "--fault", "skip-waypoint:tiago1:2",
        "--policy", "stop-mission", "-o", "live", "--verify", "--junit", "verdicts.xml",
        timeout=300,
    )  # fmt: skip
    assert done.returncode == 3, done.stdout + done.stderr
    suite = ET.parse(tmp_path / "verdicts.xml").getroot()
    cases = list(suite.iter("testcase"))
    assert len(cases) >= 10
    passed = [c.get("name") for c in cases if not list(c)]  # no <failure>, <error> or <skipped>
    assert not passed, passed
    skipped = [c.find("skipped") for c in cases if c.find("skipped") is not None]
    assert skipped and all("inconclusive: " in str(s.get("message")) for s in skipped if s is not None)
    # the bag says so on its own: verify of the stored run gives the same
    rows = json.loads(run_exscec("runs", "-f", "json").stdout)["results"]["bindings"]
    live = [r["run"]["value"] for r in rows if "/live/" in r["path"]["value"]]
    assert len(live) == 1, rows
    assert [r["mission_status"]["value"] for r in rows if "/live/" in r["path"]["value"]] == ["stopped"]
    again = run_exscec("verify", live[0], "--scenario", SPEC, "--json")
    assert again.returncode == 3, again.stderr
    verdicts = json.loads(again.stdout)
    assert {v["verdict"] for v in verdicts} <= {"inconclusive", "failed"}
    assert all("cut_short" in v["shortfalls"] for v in verdicts if v["verdict"] == "inconclusive")
