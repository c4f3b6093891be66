"""The scenario on a real parameter server as the method puts it, and the server dumped as
``rosparam dump`` dumps it: compared with the method's own scenario file (its published
``scenario_c.yaml``) and with what Debian's ``rosparam dump`` writes of the same server."""

from __future__ import annotations

import subprocess
from collections.abc import Iterator
from pathlib import Path

import pytest
import yaml

from exsce_dsl.errors import RosGraphError
from exsce_dsl.execute.ros1.graph import Master
from exsce_dsl.execute.ros1.parameters import SCENARIO_NAMESPACE, dump_parameters, load_scenario
from exsce_dsl.lang import load_spec
from exsce_dsl.model import Scenario

from tests.support.paths import EXAMPLES, FIXTURES
from tests.support.ros1_graph import Graph, ros1_graph

BUILDING = EXAMPLES / "brsu_building_c"
ROSLAUNCH = ("/run_id", "/rosdistro", "/rosversion", "/roslaunch/uris")


@pytest.fixture
def graph(tmp_path: Path) -> Iterator[Graph]:
    with ros1_graph(tmp_path / "ros", sim_time=False) as running:
        master = Master(running.uri)
        # roslaunch sets its parameters after the master answers: a dump before would lack them
        running.wait_until(lambda: all(master.has_param(p) for p in ROSLAUNCH), "roscore's parameters", 30)
        yield running


def scenario(name: str) -> Scenario:
    spec = load_spec(BUILDING / f"{name}.exsce")
    return next(s for s in spec.scenarios if s.id == name)


def test_scenario_c_round_trips_as_the_methods_scenario_file(graph: Graph, tmp_path: Path) -> None:
    master = Master(graph.uri)
    load_scenario(master, scenario("scenario_c"))
    dumped = tmp_path / "run.rosparams"
    dump_parameters(master, dumped)
    tree = yaml.safe_load(dumped.read_text(encoding="utf-8"))
    method = yaml.safe_load((FIXTURES / "scenarios" / "scenario_c.yaml").read_text(encoding="utf-8"))
    assert tree["scenario"] == method
    assert tree["scenario"]["environment"]["robots"]["tiago2"]["start_pose"]["x"] == 43.432926177978516
    assert "run_id" in tree and "rosdistro" in tree  # the whole server, as the method's .rosparams


def test_the_dump_is_what_rosparam_dump_writes(graph: Graph, tmp_path: Path) -> None:
    master = Master(graph.uri)
    load_scenario(master, scenario("scenario_c"))
    master.set_param("/exsce_test/flags", {"on": True, "count": 3, "ratio": 0.25, "list": [1, "two", 3.5]})
    ours, theirs = tmp_path / "ours.rosparams", tmp_path / "theirs.rosparams"
    dump_parameters(master, ours)
    done = subprocess.run(
        ["rosparam", "dump", str(theirs)], env=graph.env, capture_output=True, text=True, timeout=60
    )
    assert done.returncode == 0, done.stderr
    assert yaml.safe_load(ours.read_text()) == yaml.safe_load(theirs.read_text())
    assert yaml.safe_load(ours.read_text())["exsce_test"]["flags"]["list"] == [1, "two", 3.5]
    assert not list(tmp_path.glob(".*partial"))


def test_a_second_scenario_replaces_the_first(graph: Graph, tmp_path: Path) -> None:
    master = Master(graph.uri)
    load_scenario(master, scenario("scenario_c"))
    load_scenario(master, scenario("scenario_c_alone"))
    dumped = yaml.safe_load(dump_parameters_text(master, tmp_path / "p.rosparams"))
    placed = dumped["scenario"]
    assert placed["id"] == "scenario_c_alone"
    assert [r["robot_id"] for r in placed["robots"]] == ["tiago1"]
    assert list(placed["environment"]["robots"]) == ["tiago1"]  # nothing of tiago2 left over
    assert [a["robot"] for a in placed["mission"]["allocation"]] == ["tiago1"] * 4
    assert master.get_param(f"{SCENARIO_NAMESPACE}/id") == "scenario_c_alone"


def dump_parameters_text(master: Master, path: Path) -> str:
    dump_parameters(master, path)
    return path.read_text(encoding="utf-8")


def test_no_master_is_named(tmp_path: Path) -> None:
    master = Master("http://127.0.0.1:9")
    with pytest.raises(RosGraphError, match="no ROS master answers at http://127.0.0.1:9"):
        load_scenario(master, scenario("scenario_c"))
    with pytest.raises(RosGraphError, match="no ROS master answers"):
        dump_parameters(master, tmp_path / "p.rosparams")
    assert not list(tmp_path.iterdir())
