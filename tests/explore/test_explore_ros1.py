"""Campaigns on a live ROS 1 graph (``exscec explore --executor ros1 --stand-in``): refused
without the stand-in, and stopped by SIGTERM mid-run with nothing left running.  The campaign
that finds, shrinks and writes the planted deadlock on the live graph is the explore chapter's
last ``--help`` example, checked in tests/cli/test_help_examples_explore.py."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from tests.support.ros1_graph import require_ros1

ROOT = Path(__file__).resolve().parents[2]
EXSCEC = str(Path(sys.executable).parent / "exscec")
SPEC = "examples/brsu_building_c/scenario_c.exsce"
DEADLOCK = "deadlock-start:tiago1:classroom_c025-w002"
"""Revealed by swapping the start poses of tiago1 and tiago2 (see exsce_dsl.sim.faults)."""


@pytest.fixture
def project(tmp_path: Path) -> Path:
    shutil.copytree(ROOT / "examples", tmp_path / "examples")
    return tmp_path


def _exscec(project: Path, *args: str) -> subprocess.CompletedProcess[str]:
    # no ROS_MASTER_URI: the campaign starts a roscore of its own and stops it at its end; the
    # run's cache folder stays (the suite leaves ~/.cache/exsce alone)
    env = {k: v for k, v in os.environ.items() if not k.startswith(("EXSCE_", "ROS_")) or k == "EXSCE_CACHE"}
    env["EXSCE_STORE"] = str(project / "store")
    return subprocess.run([EXSCEC, *args], cwd=project, env=env, capture_output=True, text=True, timeout=400)


@pytest.mark.parametrize(
    ("options", "said"),
    [
        (
            ["--executor", "ros1", "--fault", DEADLOCK],
            "plants the fault in exsce's stand-in robots: give --stand-in",
        ),
        (["--executor", "ros1"], "drives exsce's stand-in robots only, for now: give --stand-in"),
        (
            ["--stand-in", "--fault", DEADLOCK],
            "--stand-in, --start-master and --speed-up go with --executor ros1",  # (ros2 too)
        ),
        (
            ["--executor", "ros2"],
            "the ros2 executor drives exsce's stand-in robots only, for now: give --stand-in",
        ),
        (["--executor", "ros3"], "no executor 'ros3'; did you mean"),
    ],
)
def test_the_ros1_executor_without_its_stand_in_is_refused_before_anything_runs(
    project: Path, options: list[str], said: str
) -> None:
    refused = _exscec(project, "explore", SPEC, "-n", "1", "-k", "1", *options, "-o", "c")
    assert refused.returncode == 2, refused.stderr
    assert said in refused.stderr and "Traceback" not in refused.stderr
    assert not (project / "c").exists() and not (project / "store").exists()


def test_a_campaign_stopped_by_sigterm_mid_run_exits_130_and_leaves_no_ros_process(project: Path) -> None:
    require_ros1()
    env = {k: v for k, v in os.environ.items() if not k.startswith(("EXSCE_", "ROS_")) or k == "EXSCE_CACHE"}
    env |= {"EXSCE_STORE": str(project / "store"), "TMPDIR": str(project / "tmp")}  # roscore's home
    (project / "tmp").mkdir()
    command = [EXSCEC, "explore", SPEC, "--executor", "ros1", "--stand-in", "-n", "1", "-k", "1", "-o", "c"]
    process = subprocess.Popen(command, cwd=project, env=env, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 120
        while not list((project / "c" / "runs").rglob("*.bag.active")):  # recording the first run
            assert process.poll() is None and time.monotonic() < deadline, "no run started"
            time.sleep(0.2)
        process.send_signal(signal.SIGTERM)
        _, stderr = process.communicate(timeout=60)
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
    assert process.returncode == 130, stderr
    assert "interrupted" in stderr and "Traceback" not in stderr
    runs = project / "c" / "runs" / "scenario_c"
    assert not list(runs.glob("*.bag")) and not list(runs.rglob("*.active"))  # no run under its name
    assert list((runs / "incomplete").glob("*.bag"))  # the run cut short, kept apart
    left = subprocess.run(["ps", "-eo", "args"], capture_output=True, text=True, check=True).stdout
    assert str(project) not in left  # roscore, rosmaster, rosout, the nodes and recorder: all gone
