"""A campaign on a live ROS 2 graph (``exscec explore --executor ros2 --stand-in``, issue 51 item 5):
it finds and shrinks the deadlock planted in the Nav2 stand-in, each run a rosbag2 MCAP folder
recorded by exsce's recorder.  Its own file, so that it runs beside the live loop's.

Only the derived scenario's run is played live: the base's three runs are simulated on Nav2's
topics and stored first, as the explore chapter's live campaign finds them stored by an earlier
campaign (tests/cli/test_help_examples_explore.py); scenario_c's live runs on ROS 2 are the live
loop's (tests/execute/test_ros2_live_loop.py), and three more here cost a minute and a half."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from exsce_dsl import api as exsce
from exsce_dsl.sim.run import simulate

from tests.support.ros2_graph import ros2_domain

SCENARIO_C = Path(__file__).resolve().parents[2] / "examples" / "brsu_building_c" / "scenario_c.exsce"
EXSCEC = str(Path(sys.executable).with_name("exscec"))


def _environment(domain: dict[str, str], store: Path) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if not k.startswith(("EXSCE_", "ROS_")) or k == "EXSCE_CACHE"}
    return env | domain | {"EXSCE_STORE": str(store)}


def _exscec(*args: str, cwd: Path, env: dict[str, str]) -> subprocess.CompletedProcess[str]:
    return subprocess.run([EXSCEC, *args], cwd=cwd, env=env, capture_output=True, text=True, timeout=600)


def _store_base_runs(store: Path, folder: Path) -> None:
    """scenario_c's three base runs, simulated on Nav2's topics as MCAP folders, in ``store``."""
    spec = exsce.load(SCENARIO_C)
    runs = simulate(spec.scenario("scenario_c"), folder, 3, fmt="mcap", seed=1, convention="nav2")
    with exsce.open_store(str(store)) as opened:
        ingested = exsce.ingest(opened, spec, [run.bag for run in runs], scenario="scenario_c")
    assert [r.failed for r in ingested] == [False] * 3, ingested


def test_a_campaign_on_the_live_graph_finds_and_shrinks_the_planted_deadlock(tmp_path: Path) -> None:
    _store_base_runs(tmp_path / "store", tmp_path / "base")
    with ros2_domain() as domain:
        done = _exscec(
            "explore", str(SCENARIO_C), "-n", "1", "-k", "1", "-t", "swap_start_poses",
            "--executor", "ros2", "--stand-in", "--fault", "deadlock-start:tiago1:classroom_c025-w002",
            "-o", "c", cwd=tmp_path, env=_environment(domain, tmp_path / "store"),
        )  # fmt: skip
    said = done.stdout + done.stderr
    assert done.returncode == 1, said[-3000:]
    assert "smallest derivation (1 step): swap_start_poses(robot=tiago1, with=tiago2)" in said
    assert "/*/ --scenario" in said  # the runs to verify again are bag folders
    assert not (tmp_path / "c" / "runs" / "scenario_c").exists()  # the base's runs were stored
    bags = [p for p in (tmp_path / "c" / "runs").rglob("metadata.yaml")]
    assert bags
