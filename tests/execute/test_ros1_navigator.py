"""The mission core on a real roscore: exsce's dispatcher node against a real actionlib server.

The server (``tests/fixtures/ros1/move_base_server.py``, rospy) logs every goal and cancel it
gets; the expected poses are scenario_c's, written out by hand from environment.exsce.
"""

from __future__ import annotations

import json
import math
import time
from dataclasses import replace
from pathlib import Path

import pytest

from exsce_dsl.errors import RosGraphError
from exsce_dsl.execute.dispatcher import dispatch
from exsce_dsl.execute.mission import schedule
from exsce_dsl.execute.outcomes import GoalOutcome, MissionStatus
from exsce_dsl.execute.ros1.navigator import DispatcherNode, Ros1Navigator, RosClock, move_base_actions
from exsce_dsl.lang import load_spec
from exsce_dsl.model import MissionType

from tests.support.paths import EXAMPLES
from tests.support.ros1_graph import Graph, ros1_graph, start_server

# environment.exsce, by hand: x, y, yaw in degrees
P = {
    "c022-w001": (52.82560729980469, 32.562904357910156, 130.0),
    "c022-w002": (54.497589111328125, 31.52023696899414, 130.0),
    "c018-w001": (48.26420974731445, 24.618297576904297, -36.72),
    "c018-w002": (46.25560760498047, 21.586545944213867, -36.72),
    "c025-w001": (44.80387496948242, 37.15502166748047, 53.0),
    "c025-w002": (43.432926177978516, 38.493873596191406, 53.0),
}
TIAGO1 = ["c022-w001", "c018-w001", "c025-w001"]  # delivery_a, then navigate_home_1
TIAGO2 = ["c022-w002", "c018-w002", "c025-w002"]


@pytest.fixture(scope="module")
def scenario_c():
    return load_spec(EXAMPLES / "brsu_building_c" / "scenario_c.exsce").scenario("scenario_c")


def seen(log: Path) -> list[dict]:
    return [json.loads(line) for line in log.read_text().splitlines()]


def run_mission(graph: Graph, scenario, tmp_path: Path, **kwargs):
    node = DispatcherNode(move_base_actions(scenario), graph.uri, tmp_path / "dispatcher.log", 10.0)
    try:
        return dispatch(schedule(scenario, **kwargs), Ros1Navigator(node), RosClock(node))
    finally:
        node.close()


def test_goals_arrive_in_the_schedules_order_with_the_specs_poses(scenario_c, tmp_path: Path) -> None:
    log = tmp_path / "goals.jsonl"
    with ros1_graph(tmp_path / "ros", sim_time=False) as graph:
        start_server(graph, log, "tiago1,tiago2", "--duration", "0.3")
        run = run_mission(graph, scenario_c, tmp_path)
    assert run.status is MissionStatus.COMPLETED
    assert [r.outcome for r in run.records] == [GoalOutcome.SUCCEEDED] * 6
    goals = [e for e in seen(log) if e["event"] == "goal"]
    for robot, poses in (("tiago1", TIAGO1), ("tiago2", TIAGO2)):
        got = [g for g in goals if g["robot"] == robot]
        assert len(got) == 3
        for g, name in zip(got, poses, strict=True):
            x, y, yaw = P[name]
            assert (g["x"], g["y"], g["z"], g["frame"]) == (pytest.approx(x), pytest.approx(y), 0.0, "map")
            half = math.radians(yaw) / 2
            assert (g["qz"], g["qw"]) == (
                pytest.approx(math.sin(half), abs=1e-3),
                pytest.approx(math.cos(half), abs=1e-3),
            )
    # parallel: tiago2's first goal is sent before tiago1's first one ends
    ends = [e for e in seen(log) if e["event"] == "end"]
    first_end = min(e["wall"] for e in ends)
    assert sum(g["wall"] < first_end for g in goals) == 2


def test_a_sequential_mission_has_one_goal_active_at_a_time(scenario_c, tmp_path: Path) -> None:
    sequential = replace(scenario_c, mission=replace(scenario_c.mission, type=MissionType.SEQUENTIAL))
    log = tmp_path / "goals.jsonl"
    with ros1_graph(tmp_path / "ros", sim_time=False) as graph:
        start_server(graph, log, "tiago1,tiago2", "--duration", "0.2")
        run = run_mission(graph, sequential, tmp_path)
    assert [r.outcome for r in run.records] == [GoalOutcome.SUCCEEDED] * 6
    events = [e for e in seen(log) if e["event"] in ("goal", "end")]
    # allocation order: tiago1 delivery_a, tiago2 delivery_b, tiago1 home, tiago2 home
    order = [(g["robot"], g["x"]) for g in events if g["event"] == "goal"]
    expected = [("tiago1", P[p][0]) for p in TIAGO1[:2]] + [("tiago2", P[p][0]) for p in TIAGO2[:2]]
    expected += [("tiago1", P[TIAGO1[2]][0]), ("tiago2", P[TIAGO2[2]][0])]
    assert order == [(r, pytest.approx(x)) for r, x in expected]
    assert [e["event"] for e in events] == ["goal", "end"] * 6  # never two at once


def test_an_aborted_goal_is_skipped_and_the_next_one_sent(scenario_c, tmp_path: Path) -> None:
    log = tmp_path / "goals.jsonl"
    with ros1_graph(tmp_path / "ros", sim_time=False) as graph:
        start_server(graph, log, "tiago1,tiago2", "--duration", "0.2", "--aborts", "tiago1:1")
        run = run_mission(graph, scenario_c, tmp_path)
    tiago1 = [(r.pose.id, r.outcome, r.attempts) for r in run.records if r.robot == "tiago1"]
    assert tiago1 == [
        ("classroom_c022-w001", GoalOutcome.ABORTED, 1),
        ("classroom_c018-w001", GoalOutcome.SUCCEEDED, 1),
        ("classroom_c025-w001", GoalOutcome.SUCCEEDED, 1),
    ]
    xs = [g["x"] for g in seen(log) if g["event"] == "goal" and g["robot"] == "tiago1"]
    assert xs == [pytest.approx(P[p][0]) for p in TIAGO1]


def test_a_missing_action_server_is_named(scenario_c, tmp_path: Path) -> None:
    log = tmp_path / "goals.jsonl"
    with ros1_graph(tmp_path / "ros", sim_time=False) as graph:
        start_server(graph, log, "tiago1")
        started = time.monotonic()
        with pytest.raises(RosGraphError) as error:
            DispatcherNode(move_base_actions(scenario_c), graph.uri, tmp_path / "dispatcher.log", 2.0)
        assert time.monotonic() - started < 20
    assert "/tiago2/move_base" in str(error.value)
    assert "/tiago1/move_base" not in str(error.value)


def test_timeouts_run_on_simulated_time(scenario_c, tmp_path: Path) -> None:
    """/clock at 20x wall time: a 30 s timeout of the ROS clock passes in about 1.5 s of wall
    time; the silent goal is cancelled (the server saw it) and the next one sent."""
    log = tmp_path / "goals.jsonl"
    with ros1_graph(tmp_path / "ros", sim_time=True) as graph:
        args = ("--duration", "0.2", "--silent", "tiago1:1", "--clock", "20")
        start_server(graph, log, "tiago1,tiago2", *args)
        started = time.monotonic()
        run = run_mission(graph, scenario_c, tmp_path, timeout=30.0)
        took = time.monotonic() - started
    first = next(r for r in run.records if r.robot == "tiago1")
    assert (first.pose.id, first.outcome) == ("classroom_c022-w001", GoalOutcome.TIMED_OUT)
    assert first.end - first.start == pytest.approx(30.0, abs=1.0)  # ROS seconds
    assert took < 15  # wall seconds: far less than 30
    cancels = [e for e in seen(log) if e["event"] == "cancel"]
    assert [(c["robot"], c["n"]) for c in cancels] == [("tiago1", 1)]
    assert sum(r.outcome is GoalOutcome.SUCCEEDED for r in run.records) == 5
