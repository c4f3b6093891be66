"""The whole loop on a live ROS 2 graph (issue 51, item 5): separate processes, Fast DDS on loopback,
a domain of the test's own.

``exscec demo --ros2`` executes scenario_c's mission through exsce's Nav2 stand-in robots, records
each run with exsce's recorder, ingests the bags, builds the baseline, and judges a new run (it
passes) and one whose tiago1 drives too fast (it fails).  The numbers judged are the bag's own:
tiago1's speed and distance in the faulty run are worked out here from the bag with rosbags and
numpy, and equal the stored values.  A goal the server aborts, a run cut short by Ctrl-C and a
missing action server behave as on ROS 1.  (``explore --executor ros2``: tests/explore/test_explore_ros2.py.)
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
import xml.etree.ElementTree as ET
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
from rosbags.highlevel import AnyReader

from exsce_dsl import api as exsce
from exsce_dsl.execute.outcomes import GoalOutcome

from tests.support.ros2_graph import ros2_domain

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
SCENARIO_C = EXAMPLES / "brsu_building_c" / "scenario_c.exsce"
EXSCEC = str(Path(sys.executable).with_name("exscec"))


def _exscec(
    *args: str, cwd: Path, env: dict[str, str], timeout: float = 600
) -> subprocess.CompletedProcess[str]:
    return subprocess.run([EXSCEC, *args], cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)


def _environment(domain: dict[str, str], store: Path | None = None) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if not k.startswith(("EXSCE_", "ROS_")) or k == "EXSCE_CACHE"}
    if store is not None:
        env["EXSCE_STORE"] = str(store)
    return env | domain


@pytest.fixture(scope="module")
def demo(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[Path, str]]:
    """The folder of ``exscec demo --ros2`` and what it said."""
    folder = tmp_path_factory.mktemp("live2") / "ros2-demo"
    with ros2_domain() as domain:
        done = _exscec("demo", str(folder), "--ros2", cwd=folder.parent, env=_environment(domain))
    assert "Traceback" not in done.stderr
    assert done.returncode == 0, done.stderr[-4000:]
    yield folder, done.stderr


def test_the_new_run_passes_and_the_over_speed_run_fails(demo: tuple[Path, str]) -> None:
    folder, said = demo
    assert "passed, as expected  new run of scenario_c on the live graph" in said, said[-2000:]
    assert "failed, as expected  live run with the over-speed fault" in said, said[-2000:]
    junit = ET.parse(folder / "verdicts-new.xml").getroot()
    assert junit.get("failures") == "0" and int(junit.get("tests", "0")) >= 10
    for runs in ("baseline", "new", "faulty"):
        bags = [p for p in (folder / "runs" / runs).iterdir() if p.is_dir() and not p.name.startswith(".")]
        assert bags and all((b / "metadata.yaml").is_file() for b in bags)
        assert all(b.with_name(b.name + ".prov.json").is_file() for b in bags)
        assert all(b.with_name(b.name + ".params.yaml").is_file() for b in bags)
        assert not (folder / "runs" / runs / "incomplete").exists()
        assert not [p for p in (folder / "runs" / runs).iterdir() if p.name.endswith(".partial")]


def _faulty_bag(folder: Path) -> Path:
    (bag,) = [p for p in (folder / "runs" / "faulty").iterdir() if p.is_dir() and not p.name.startswith(".")]
    return bag


def test_the_faulty_runs_speed_and_distance_are_the_bags_own(demo: tuple[Path, str]) -> None:
    """tiago1's max_velocity (Nav2's convention: the commanded speed on ``cmd_vel``) and
    distance_travelled (along its wheel odometry) in the faulty run, worked out from the bag by
    rosbags and numpy, equal the stored values; the speed breaks the 1 m/s limit."""
    folder, _ = demo
    bag = _faulty_bag(folder)
    speeds, xy = [], []
    with AnyReader([bag]) as reader:
        wanted = [c for c in reader.connections if c.topic in ("/tiago1/cmd_vel", "/tiago1/odom")]
        for connection, _, raw in reader.messages(connections=wanted):
            message = reader.deserialize(raw, connection.msgtype)
            if connection.topic == "/tiago1/cmd_vel":
                speeds.append(abs(message.linear.x))
            else:
                xy.append((message.pose.pose.position.x, message.pose.pose.position.y))
    path = np.asarray(xy)
    distance = float(np.hypot(*np.diff(path, axis=0).T).sum())
    with exsce.open_store(str(folder / ".exsce" / "store")) as store:
        runs = exsce.query(store, "runs", scenario="scenario_c")
        run = runs[runs.bag == bag.name].run.item()
        table = exsce.metrics(store, "scenario_c")
    mine = (
        table[(table.run == run) & (table.robot == "tiago1") & table.safety.isna()].set_index("metric").value
    )
    assert max(speeds) > 1.0
    assert mine["max_velocity"] == pytest.approx(max(speeds), rel=1e-6)
    assert mine["distance_travelled"] == pytest.approx(distance, rel=1e-6)


def test_a_goal_the_server_aborts_is_aborted_and_the_next_goal_goes(
    ros2_env: dict[str, str], tmp_path: Path
) -> None:
    spec = exsce.load(SCENARIO_C)
    [run] = exsce.execute_ros2(
        spec, tmp_path / "runs", stand_in=True, faults=["skip-waypoint:tiago1:1"], speed_up=10
    )
    records = [r for r in run.mission.records if r.robot == "tiago1"]
    assert [r.outcome for r in records] == [GoalOutcome.ABORTED, GoalOutcome.SUCCEEDED, GoalOutcome.SUCCEEDED]
    assert all(r.attempts == 1 for r in records)  # skip-waypoint: not sent again
    assert run.mission.status.value == "completed"
    assert (run.files.bag / "metadata.yaml").is_file()
    parameters = run.files.rosparams.read_text(encoding="utf-8")
    assert (
        "/exsce_dispatcher:" in parameters
        and "scenario_c" in parameters
        and "use_sim_time: true" in parameters
    )


def test_ctrl_c_cancels_the_goals_and_keeps_the_run_apart(ros2_env: dict[str, str], tmp_path: Path) -> None:
    process = subprocess.Popen(
        [EXSCEC, "execute", str(SCENARIO_C), "--ros2", "--stand-in", "-o", "runs"],
        cwd=tmp_path,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    try:
        deadline = time.monotonic() + 120
        recording = tmp_path / "runs"
        while not list(recording.glob(".*.partial/.*.recording")):  # the bag being recorded
            assert process.poll() is None and time.monotonic() < deadline, "no run started"
            time.sleep(0.2)
        time.sleep(3.0)  # goals on their way
        os.killpg(process.pid, signal.SIGINT)
        _, stderr = process.communicate(timeout=60)
    finally:
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGKILL)
            process.wait()
    assert process.returncode == 130, stderr
    assert "Traceback" not in stderr and "kept apart" in stderr
    runs = tmp_path / "runs"
    assert not [p for p in runs.iterdir() if not p.name.startswith(".") and p.name != "incomplete"]
    (kept,) = [p for p in (runs / "incomplete").iterdir() if p.is_dir()]
    assert (kept / "metadata.yaml").is_file()  # a whole bag, closed
    prov = json.loads(kept.with_name(kept.name + ".prov.json").read_text(encoding="utf-8"))
    assert "cancel" in json.dumps(prov).lower()


def test_a_missing_action_server_is_named_and_leaves_no_bag(ros2_env: dict[str, str], tmp_path: Path) -> None:
    done = _exscec(
        "execute", str(SCENARIO_C), "--ros2", "--server-timeout", "1", "-o", "runs",
        cwd=tmp_path, env=dict(os.environ),
    )  # fmt: skip
    assert done.returncode == 2, done.stderr
    assert "navigate_to_pose" in done.stderr and "Traceback" not in done.stderr
    assert not [p for p in (tmp_path / "runs").iterdir() if not p.name.startswith(".")]
