"""``simulate --simulator irsim``: scenario_c played by IR-SIM, written as Nav2's topics in an
MCAP bag, ingested; each robot's distance is the path of its odometry as rosbags reads it (over
the robot's goals, from the first goal executing to the last one ended, read from the bag's own
action status) and every waypoint is visited; the run's PROV names IR-SIM, its version and its
settings, in the ``.prov.json`` and in the store."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rosbags.highlevel import AnyReader

from exsce_dsl import api
from exsce_dsl.sim.irsim_play import irsim_version
from exsce_dsl.sim.run import SimulatedRun

from tests.support.paths import EXAMPLES

SPEC = EXAMPLES / "brsu_building_c" / "scenario_c.exsce"
ROBOTS = ("tiago1", "tiago2")
EXECUTING, TERMINAL = 2, (4, 5, 6)  # action_msgs/GoalStatus


@pytest.fixture(scope="module")
def played(tmp_path_factory: pytest.TempPathFactory) -> tuple[SimulatedRun, str]:
    folder = tmp_path_factory.mktemp("irsim")
    scenario = api.load(SPEC).scenario(None)
    [run] = api.simulate(
        scenario, folder / "runs", 1, format="mcap", convention="nav2", simulator="irsim", behaviour="rvo"
    )
    store = str(folder / "store")
    results, tally = api.ingest_files(store, scenario, [run.bag])
    assert tally.ingested == 1, results
    return run, store


def _odometry_path(bag: Path, robot: str) -> float:
    """Metres along /robot/odom from the first goal executing to the last goal ended."""
    with AnyReader([bag]) as reader:
        status = [c for c in reader.connections if c.topic == f"/{robot}/navigate_to_pose/_action/status"]
        executing: dict[bytes, int] = {}
        ended: dict[bytes, int] = {}
        for connection, stamp, raw in reader.messages(connections=status):
            status_array: Any = reader.deserialize(raw, connection.msgtype)
            for goal in status_array.status_list:
                key = bytes(goal.goal_info.goal_id.uuid)
                if goal.status == EXECUTING:
                    executing.setdefault(key, stamp)
                if goal.status in TERMINAL:
                    ended.setdefault(key, stamp)
        first, last = min(executing.values()), max(ended.values())
        odom = [c for c in reader.connections if c.topic == f"/{robot}/odom"]
        xy = []
        for connection, stamp, raw in reader.messages(connections=odom):
            if first <= stamp <= last:
                msg: Any = reader.deserialize(raw, connection.msgtype)
                xy.append((msg.pose.pose.position.x, msg.pose.pose.position.y))
    points = np.array(xy)
    return float(np.hypot(*np.diff(points, axis=0).T).sum())


def _values(store: str) -> dict[tuple[str, str], float]:
    listed = api.stored_runs(store, "scenario_c").rows
    assert listed is not None
    [run] = list(listed)
    answer = api.answer_query(store, "run_metric_values", {"run": [_text(run["run"])]})
    assert answer.rows is not None
    return {(_text(row["metric"]), _text(row["robot"])): float(_text(row["value"])) for row in answer.rows}


def _text(term: object) -> str:
    return "" if term is None else str(getattr(term, "value", term))


def test_each_robots_distance_is_its_odometry_path(played: tuple[SimulatedRun, str]) -> None:
    run, store = played
    values = _values(store)
    for robot in ROBOTS:
        expected = _odometry_path(run.bag, robot)
        assert expected > 40.0  # each robot crossed the building
        assert values[("distance_travelled", robot)] == pytest.approx(expected, rel=1e-6)


def test_every_waypoint_is_visited(played: tuple[SimulatedRun, str]) -> None:
    run, store = played
    values = _values(store)
    assert {robot: values[("waypoints_visited", robot)] for robot in ROBOTS} == {"tiago1": 3, "tiago2": 3}
    assert all(a.status.name == "SUCCEEDED" for a in run.execution.actions)


def test_the_runs_prov_names_irsim_its_version_and_settings(played: tuple[SimulatedRun, str]) -> None:
    run, store = played
    document = json.loads(run.bag.with_name(run.bag.name + ".prov.json").read_text())
    agents = [a for b in document["bundle"].values() for a in b.get("agent", {}).values()]
    [simulator] = [a for a in agents if a.get("exsce:simulator")]
    assert simulator["exsce:simulator"] == "irsim"
    assert simulator["exsce:simulator_version"] == irsim_version()
    assert "behaviour=rvo" in simulator["exsce:simulator_settings"]
    with api.open_store(store, read_only=True) as opened:
        found = api.sparql(
            opened,
            "PREFIX exsce: <https://www.sesame-project.org/scenarios/> "
            "PREFIX prov: <http://www.w3.org/ns/prov#> "
            "SELECT ?name ?version WHERE { GRAPH ?g { ?execution a exsce:execution ; "
            "prov:wasAssociatedWith ?agent . ?agent exsce:simulator ?name ; exsce:simulator_version ?version } }",
        )
    assert found.to_dict("records") == [{"name": "irsim", "version": irsim_version()}]


def test_the_runs_lineage_says_what_played_it(played: tuple[SimulatedRun, str]) -> None:
    _, store = played
    listed = api.stored_runs(store, "scenario_c").rows
    assert listed is not None
    [run] = list(listed)
    with api.open_store(store, read_only=True) as opened:
        text = api.run_lineage(opened, _text(run["run"])).text()
    assert f"  played by irsim {irsim_version()} (behaviour=rvo; scans=exsce; step_time=0.1;" in text
