"""``exscec execute --ros1`` on a real roscore against the tests' move_base server (rospy,
actionlib), recorded by the real ``rosbag record``; the bags read back with rosbags, not exsce."""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml
from rosbags.rosbag1 import Reader
from rosbags.typesys import Stores, get_typestore

from tests.support.cli import run_exscec
from tests.support.paths import EXAMPLES
from tests.support.ros1_graph import on_graph, ros1_graph, start_server
from tests.support.shared_baseline import copy_of_baseline_project

SPEC = str(EXAMPLES / "brsu_building_c" / "scenario_c.exsce")
RUN_NAME = re.compile(r"^\d{4}-\d\d-\d\dT\d\d-\d\d-\d\d_scenario_c_run-[0-9a-f]{8}$")
"""The method's names: ``2023-06-13T15-48-07_scenario_c_run-e30df0b6``."""


def seen(log: Path) -> list[dict]:
    return [json.loads(line) for line in log.read_text().splitlines()] if log.exists() else []


def everything_under(folder: Path) -> list[str]:
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*") if ".exsce-execute" not in p.parts)


def test_a_run_leaves_the_methods_three_files_and_its_prov_is_in_the_bag(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    out = tmp_path / "live"
    with ros1_graph(tmp_path / "ros", sim_time=False) as graph:
        on_graph(graph, monkeypatch)
        start_server(
            graph, tmp_path / "goals.jsonl", "tiago1,tiago2", "--duration", "0.2", "--aborts", "tiago2:2"
        )
        done = run_exscec("execute", SPEC, "--ros1", "-o", str(out), "--runs", "2", timeout=90)
    assert done.returncode == 0, done.stderr
    names = everything_under(out)
    assert len(names) == 6, names
    stems = {n.split(".")[0] for n in names}
    assert len(stems) == 2 and all(RUN_NAME.match(s) for s in stems), names
    for stem in stems:
        assert sorted(p.name[len(stem) :] for p in out.glob(stem + ".*")) == [
            ".bag",
            ".prov.json",
            ".rosparams",
        ]
    assert done.stderr.count("(mission completed: 1 aborted, 5 succeeded)") == 1  # tiago2's 2nd goal, once
    assert done.stderr.count("(mission completed: 6 succeeded)") == 1
    store = get_typestore(Stores.ROS1_NOETIC)
    for bag in out.glob("*.bag"):  # each bag holds its own run's PROV, once (not the run before's)
        with Reader(bag) as reader:
            prov = [c for c in reader.connections if c.topic == "/exsce/prov"]
            assert [c.msgtype for c in prov] == ["std_msgs/msg/String"]
            texts = [
                store.deserialize_ros1(raw, "std_msgs/msg/String").data for _, _, raw in reader.messages(prov)
            ]
        assert texts == [bag.with_suffix(".prov.json").read_text()]
        parameters = yaml.safe_load(bag.with_suffix(".rosparams").read_text())
        assert "scenario" in parameters


def test_a_missing_action_server_exits_2_naming_it_and_leaves_no_bag(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    out = tmp_path / "live"
    with ros1_graph(tmp_path / "ros", sim_time=False) as graph:
        on_graph(graph, monkeypatch)
        start_server(graph, tmp_path / "goals.jsonl", "tiago1")
        done = run_exscec("execute", SPEC, "--ros1", "-o", str(out), "--server-timeout", "2", timeout=60)
    assert done.returncode == 2, done.stderr
    assert "/tiago2/move_base" in done.stderr and "/tiago1/move_base" not in done.stderr
    assert "Traceback" not in done.stderr
    assert everything_under(out) == [] if out.exists() else True
    assert not list(tmp_path.rglob("*.bag*"))


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_an_interruption_mid_mission_cancels_the_goals_and_keeps_the_run_apart(
    sig: signal.Signals, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    out = tmp_path / "live"
    log = tmp_path / "goals.jsonl"
    with ros1_graph(tmp_path / "ros", sim_time=False) as graph:
        on_graph(graph, monkeypatch)
        start_server(
            graph, log, "tiago1,tiago2", "--duration", "0.2", "--silent", "tiago1:1", "--silent", "tiago2:2"
        )
        exe = Path(sys.executable).with_name("exscec")
        execute = subprocess.Popen(
            [str(exe), "execute", SPEC, "--ros1", "-o", str(out)],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            env={**os.environ},
        )
        try:
            deadline = time.monotonic() + 60
            while (
                sum(e["event"] == "goal" for e in seen(log)) < 3
            ):  # tiago1 stuck on its first, tiago2 on its second
                assert execute.poll() is None and time.monotonic() < deadline, (
                    execute.stderr.read() if execute.stderr else ""
                )
                time.sleep(0.05)
            time.sleep(0.3)
            execute.send_signal(sig)
            _, stderr = execute.communicate(timeout=60)
        finally:
            if execute.poll() is None:
                execute.kill()
                execute.wait()
    assert execute.returncode == 130, stderr
    cancels = sorted((e["robot"], e["n"]) for e in seen(log) if e["event"] == "cancel")
    assert cancels == [("tiago1", 1), ("tiago2", 2)]
    assert not list(out.glob("*.bag")) and not list(out.glob("*.prov.json"))
    assert not list(tmp_path.rglob("*.active")) and not list(out.glob(".*.partial"))
    kept = sorted(p.name for p in (out / "incomplete").iterdir())
    assert len(kept) == 3 and RUN_NAME.match(kept[0].split(".")[0]), kept
    bag = next((out / "incomplete").glob("*.bag"))
    assert str(out / "incomplete") in stderr
    with Reader(bag) as reader:  # closed: it has its index
        assert "/exsce/prov" in {c.topic for c in reader.connections}
    assert "cancelled" in bag.with_suffix(".prov.json").read_text()


def test_verify_ingests_the_recorded_bag_and_judges_it_as_verify_does(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, tmp_path_factory: pytest.TempPathFactory
) -> None:
    """A baseline from three simulated runs (about 120 s of mission); the test server ends each
    goal after 0.2 s, so the live run's durations fail their oracles, while each robot's three
    goals SUCCEEDED (read from move_base's recorded result topic) pass waypoints_visited."""
    monkeypatch.chdir(copy_of_baseline_project(tmp_path_factory, tmp_path))
    with ros1_graph(tmp_path / "ros", sim_time=False) as graph:
        on_graph(graph, monkeypatch)
        start_server(graph, tmp_path / "goals.jsonl", "tiago1,tiago2", "--duration", "0.2")
        done = run_exscec("execute", SPEC, "--ros1", "-o", "live", "--verify", "--junit", "verdicts.xml")
    assert done.returncode == 1, done.stderr
    rows = {line.split()[1]: line for line in done.stdout.splitlines() if line.strip()}
    for robot in ("tiago1", "tiago2"):
        assert rows[f"{robot}-waypoints_visited"].split()[3:5] == ["3", "3"]
        assert "pass" in rows[f"{robot}-waypoints_visited"]
        assert "FAIL" in rows[f"{robot}-task_duration"]
    assert "FAIL" in rows["mission_duration"]
    assert "<failure" in (tmp_path / "verdicts.xml").read_text()


def test_interrupted_before_the_run_began_sends_nothing_and_writes_no_bag(tmp_path: Path) -> None:
    """From Python: ``execute_ros1`` with ``interrupted`` already saying yes."""
    from exsce_dsl.api import execute_ros1, load
    from exsce_dsl.errors import ExecutionInterrupted

    log = tmp_path / "goals.jsonl"
    with ros1_graph(tmp_path / "ros", sim_time=False) as graph:
        start_server(graph, log, "tiago1,tiago2")
        with pytest.raises(ExecutionInterrupted) as stop:
            execute_ros1(load(SPEC), tmp_path / "live", master_uri=graph.uri, interrupted=lambda: True)
    assert stop.value.incomplete is None and stop.value.complete == ()
    assert seen(log) == []
    assert not list(tmp_path.rglob("*.bag*"))
