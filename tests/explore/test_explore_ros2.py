"""A campaign on a live ROS 2 graph (``exscec explore --executor ros2 --stand-in``, issue 51 item 5):
it finds and shrinks the deadlock planted in the Nav2 stand-in, each run a rosbag2 MCAP folder
recorded by exsce's recorder.  Its own file, so that it runs beside the live loop's."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from tests.support.ros2_graph import ros2_domain

SCENARIO_C = Path(__file__).resolve().parents[2] / "examples" / "brsu_building_c" / "scenario_c.exsce"
EXSCEC = str(Path(sys.executable).with_name("exscec"))


def _environment(domain: dict[str, str], store: Path) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if not k.startswith(("EXSCE_", "ROS_")) or k == "EXSCE_CACHE"}
    return env | domain | {"EXSCE_STORE": str(store)}


def _exscec(*args: str, cwd: Path, env: dict[str, str]) -> subprocess.CompletedProcess[str]:
    return subprocess.run([EXSCEC, *args], cwd=cwd, env=env, capture_output=True, text=True, timeout=600)


def test_a_campaign_on_the_live_graph_finds_and_shrinks_the_planted_deadlock(tmp_path: Path) -> None:
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
    bags = [p for p in (tmp_path / "c" / "runs").rglob("metadata.yaml")]
    assert bags
