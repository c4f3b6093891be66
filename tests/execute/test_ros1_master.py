"""The live graph as exsce meets it: rospy's Python found or refused, a master started, asked
over XML-RPC and stopped, a master that is not there named (a real roscore; no rospy here)."""

from __future__ import annotations

import os
import signal
import sys
import time
from pathlib import Path

import pytest

from exsce_dsl.cli.common import REMEDIES
from exsce_dsl.errors import RosGraphError
from exsce_dsl.execute.ros1.channel import NodeChannel
from exsce_dsl.execute.ros1.graph import (
    DEFAULT_ROS_PYTHON,
    ROS_PYTHON_VARIABLE,
    Master,
    check_ros_python,
    free_port,
    master_uri,
    node_environment,
    ros_python,
    start_master,
)
from exsce_dsl.remedies import START_A_MASTER

from tests.support.ros1_graph import gone, require_ros1


def test_a_started_master_answers_keeps_parameters_and_is_gone_after(tmp_path: Path) -> None:
    require_ros1()
    with start_master(tmp_path / "ros") as started:
        master = Master(started.uri)
        assert master.reachable()
        master.set_param("/exsce_test/answer", {"value": 42, "unit": "m"})
        assert master.get_param("/exsce_test/answer") == {"value": 42, "unit": "m"}
        assert master.has_param("/exsce_test/answer/unit")
        master.delete_param("/exsce_test/answer")
        assert not master.has_param("/exsce_test/answer")
        process = started.process
    assert process.poll() is not None
    assert not Master(started.uri).reachable()


def test_a_master_whose_roscore_died_is_stopped_whole(tmp_path: Path) -> None:
    """roslaunch starts rosmaster and rosout in sessions of their own: with roscore gone (killed,
    as stop() kills one that takes over 15 s to shut down), a signal to its group no longer
    reaches them; stop() ends them by the pids it noted when the master came up."""
    require_ros1()
    with start_master(tmp_path / "ros") as started:
        below = dict(started.below)
        words = {w.decode() for pid in below for w in Path(f"/proc/{pid}/cmdline").read_bytes().split(b"\0")}
        assert {"/usr/bin/rosmaster", "/usr/lib/rosout/rosout"} <= words
        os.kill(started.process.pid, signal.SIGKILL)
        started.process.wait(10)
        assert Master(started.uri).reachable()  # the orphans still answer
    assert not Master(started.uri).reachable()
    deadline = time.monotonic() + 10
    while not all(gone(pid) for pid in below) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert all(gone(pid) for pid in below)


def test_no_master_is_named_with_its_uri() -> None:
    uri = f"http://127.0.0.1:{free_port()}"
    with pytest.raises(RosGraphError, match=f"no ROS master answers at {uri}"):
        Master(uri).wait(0.3)
    with pytest.raises(RosGraphError, match="no ROS master answers"):
        Master(uri).get_param("/anything")


def test_the_master_uri_comes_from_the_environment(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ROS_MASTER_URI", "http://127.0.0.1:11399")
    assert master_uri() == "http://127.0.0.1:11399"
    monkeypatch.delenv("ROS_MASTER_URI")
    with pytest.raises(RosGraphError, match="ROS_MASTER_URI is not set") as raised:
        master_uri()
    assert raised.value.remedy == START_A_MASTER  # the command line says it as --start-master
    assert "--start-master" in REMEDIES[START_A_MASTER]


def test_a_python_without_rospy_is_refused_with_how_to_install(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(ROS_PYTHON_VARIABLE, "/nonexistent/python3")
    with pytest.raises(RosGraphError, match="no Python for ROS 1 at /nonexistent/python3"):
        ros_python()
    with pytest.raises(RosGraphError, match="cannot run exsce's ROS 1 nodes .*install ROS 1"):
        check_ros_python(Path(sys.executable))  # the venv's Python: no rospy
    check_ros_python(DEFAULT_ROS_PYTHON)  # Debian's has what the nodes import


def test_the_node_environment_drops_the_venv_and_names_the_master(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("PYTHONPATH", "/somewhere/src")
    monkeypatch.setenv("VIRTUAL_ENV", "/somewhere/.venv")
    monkeypatch.delenv("ROS_IP", raising=False)
    monkeypatch.delenv("ROS_HOSTNAME", raising=False)
    env = node_environment("http://127.0.0.1:11400", Path("/tmp/ros-home"))
    assert "PYTHONPATH" not in env and "VIRTUAL_ENV" not in env
    assert env["ROS_MASTER_URI"] == "http://127.0.0.1:11400"
    assert env["ROS_IP"] == "127.0.0.1"
    assert env["ROS_LOG_DIR"] == "/tmp/ros-home/log"


def test_a_node_that_is_not_shipped_is_named(tmp_path: Path) -> None:
    with pytest.raises(RosGraphError, match="node 'no_such' is not installed"):
        NodeChannel("no_such", [], "http://127.0.0.1:1", tmp_path / "no_such.log")
