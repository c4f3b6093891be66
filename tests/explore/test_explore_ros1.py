"""Campaigns on a live ROS 1 graph (``exscec explore --executor ros1 --stand-in``): a real roscore
the campaign starts and stops, the dispatcher's actionlib clients, the stand-in's move_base
servers and the real ``rosbag record``; the planted latent deadlock found, shrunk and written
as the minimal derivation, as the kinematic executor's campaign does
(tests/explore/test_campaign.py).  The bags are read back with rosbags, not with exsce."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_typestore

from exsce_dsl.store.open import open_store
from exsce_dsl.store.queries import derivation_of
from exsce_dsl.store.queries.campaigns import campaign_record, campaigns

from tests.support.ros1_graph import require_ros1

ROOT = Path(__file__).resolve().parents[2]
EXSCEC = str(Path(sys.executable).parent / "exscec")
SPEC = "examples/brsu_building_c/scenario_c.exsce"
DEADLOCK = "deadlock-start:tiago1:classroom_c025-w002"
"""Revealed by swapping the start poses of tiago1 and tiago2 (see exsce_dsl.sim.faults)."""
PREEMPTED, SUCCEEDED = 2, 3
"""actionlib_msgs/GoalStatus."""


@pytest.fixture
def project(tmp_path: Path) -> Path:
    shutil.copytree(ROOT / "examples", tmp_path / "examples")
    return tmp_path


def _exscec(project: Path, *args: str) -> subprocess.CompletedProcess[str]:
    # no ROS_MASTER_URI: the campaign starts a roscore of its own and stops it at its end
    env = {k: v for k, v in os.environ.items() if not k.startswith(("EXSCE_", "ROS_"))}
    env["EXSCE_STORE"] = str(project / "store")
    return subprocess.run([EXSCEC, *args], cwd=project, env=env, capture_output=True, text=True, timeout=400)


def _results(bag: Path, robot: str) -> list[tuple[int, float]]:
    """The move_base results of ``robot`` in ``bag``: (status, seconds since its goal's stamp)."""
    goals: dict[str, float] = {}
    found = []
    with AnyReader([bag], default_typestore=get_typestore(Stores.ROS1_NOETIC)) as reader:
        wanted = {f"/{robot}/move_base/goal", f"/{robot}/move_base/result"}
        connections = [c for c in reader.connections if c.topic in wanted]
        for connection, _, raw in reader.messages(connections=connections):
            message = reader.deserialize(raw, connection.msgtype)
            if connection.topic.endswith("/goal"):
                goals[message.goal_id.id] = message.header.stamp.sec + message.header.stamp.nanosec * 1e-9
            else:
                stamp = message.header.stamp.sec + message.header.stamp.nanosec * 1e-9
                found.append((message.status.status, stamp - goals[message.status.goal_id.id]))
    return found


def test_a_deadlock_planted_in_the_stand_in_is_found_on_the_live_graph_and_shrunk(project: Path) -> None:
    require_ros1()
    explored = _exscec(
        project, "explore", SPEC, "--executor", "ros1", "--stand-in", "--fault", DEADLOCK,
        "-n", "1", "-k", "1", "-t", "swap_start_poses",
        "-o", "explore/deadlock", "--junit", "campaign.xml",
    )  # fmt: skip
    assert explored.returncode == 1, explored.stdout + explored.stderr
    assert "Traceback" not in explored.stderr
    with open_store(str(project / "store")) as store:
        (plan,) = campaigns(store)
        assert plan.executor == f"ros1 --stand-in --fault {DEADLOCK}"
        record = campaign_record(store, plan.id)
        assert record is not None
        (trial,) = record.trials
        assert [name for name, _ in trial.steps] == ["swap_start_poses"]
        assert len(trial.runs) == 1
        # the deadlock's symptom: tiago1's tasks took far longer than their expected value
        assert any(r.text == "tiago1 task_duration invariant" for r in trial.violated)
        assert {s.relation for s in record.shrinkings} == set(trial.violated)
        for shrinking in record.shrinkings:
            assert [name for name, _ in shrinking.minimal_steps] == ["swap_start_poses"]
        minimal = record.shrinkings[0].minimal
        assert minimal == trial.scenario
        derivation = derivation_of(store, minimal)
        assert derivation is not None and [s.transformation for s in derivation.steps] == ["swap_start_poses"]
    file = project / "explore" / "deadlock" / "minimal" / f"{minimal}.exsce"
    assert file.is_file() and f"acceptance for {minimal}" in file.read_text()
    runs = project / "explore" / "deadlock" / "runs"
    base_bags = sorted((runs / "scenario_c").glob("*.bag"))
    (derived_bag,) = sorted((runs / minimal).glob("*.bag"))
    assert len(base_bags) == 3  # the base's three runs, then the trial's one
    assert not list(runs.rglob("*.active"))  # every recording closed
    for bag in [*base_bags, derived_bag]:
        assert bag.with_name(bag.stem + ".prov.json").is_file()
        assert bag.with_name(bag.stem + ".rosparams").is_file()
    # on the live graph: the base's goals all succeeded; in the derived scenario tiago1's first
    # goal stood until the dispatcher's timeout (60 s of simulated time) cancelled it
    for bag in base_bags:
        assert {status for status, _ in _results(bag, "tiago1")} == {SUCCEEDED}
    first, *rest = _results(derived_bag, "tiago1")
    assert first[0] == PREEMPTED and first[1] >= 59.0
    assert rest and all(status == SUCCEEDED for status, _ in rest)
    assert f"exscec verify explore/deadlock/runs/{minimal}/*.bag --scenario {file.relative_to(project)}" in (
        explored.stdout
    )
    again = _exscec(project, "verify", str(derived_bag), "--scenario", str(file))
    assert again.returncode == 1, again.stdout + again.stderr
    assert "task_duration" in again.stdout
    junit = (project / "campaign.xml").read_text()
    assert 'failures="1"' in junit and "swap_start_poses" in junit


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
            "--stand-in, --start-master and --speed-up go with --executor ros1",
        ),
        (["--executor", "ros2"], "no executor 'ros2'; did you mean 'ros1'?"),
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
    env = {k: v for k, v in os.environ.items() if not k.startswith(("EXSCE_", "ROS_"))}
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
