"""A robot left without tasks (a derivation handed them to another) is still a robot of the
scenario: its run ingests, the mission's metrics over goals read only the robots that drove, and
standing by it is still measured."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from rosbags.highlevel import AnyReader

from exsce_dsl.lang import load_spec
from exsce_dsl.model.runs import MetricScope
from exsce_dsl.runs.analyse import analyse_bag
from exsce_dsl.runs.ingest import ingest_bags
from exsce_dsl.sim.run import simulate
from exsce_dsl.store.open import open_store
from exsce_dsl.store.queries import metric_sources
from exsce_dsl.transform.derivation import derive

SPEC = Path(__file__).resolve().parents[2] / "examples" / "brsu_building_c" / "scenario_c.exsce"


def test_a_run_with_an_idle_robot_ingests_and_its_mission_reads_the_robots_that_drove(tmp_path: Path) -> None:
    spec = load_spec(SPEC)
    steps = [
        (
            "add_robot",
            {"robot": "r3", "like": "tiago1", "start": "classroom_c069-w001", "take_over": "tiago2"},
        )
    ]
    scenario = derive(spec.scenario("scenario_c"), steps, tasks={t.id: t for t in spec.tasks}).scenario
    assert {r.id for r in scenario.robots} == {"tiago1", "tiago2", "r3"}
    assert scenario.mission.tasks_of("tiago2") == ()
    (run,) = simulate(scenario, tmp_path, runs=1, seed=3)
    with AnyReader([run.bag]) as reader:  # the independent view: what the bag holds
        held = {c.topic for c in reader.connections}
    assert "/tiago2/waypoint_dispatcher/feedback" not in held
    with open_store("memory:") as store:
        (result,) = ingest_bags([run.bag], scenario, store)
        assert not result.failed, result.message
        assert result.run_id is not None
        sources = {s.topics for s in metric_sources(store, result.run_id, "mission_duration")}
    assert sources == {("/r3/waypoint_dispatcher/feedback", "/tiago1/waypoint_dispatcher/feedback")}


def test_a_robot_standing_by_is_measured_over_its_recording(tmp_path: Path) -> None:
    """Issue 50: tiago1, its tasks taken over and one removed, had no value of anything, so the
    base's safety limits on it were inconclusive.  Standing by, its velocity, scans and distance
    are recorded: they give its values (the reference read with rosbags and numpy); what it was
    given no goals for has none, and the run says so."""
    spec = load_spec(SPEC)
    steps = [
        (
            "add_robot",
            {"robot": "new_robot_1", "like": "tiago1", "start": "classroom_c069-w001", "take_over": "tiago1"},
        ),
        ("remove_task", {"task": "navigate_home_1"}),
    ]
    scenario = derive(spec.scenario("scenario_c"), steps, tasks={t.id: t for t in spec.tasks}).scenario
    assert scenario.mission.tasks_of("tiago1") == ()
    (run,) = simulate(scenario, tmp_path, runs=1, seed=3)
    speeds, distances, ranges = [], [], []
    with AnyReader([run.bag]) as reader:
        for connection, _, raw in reader.messages():
            if not connection.topic.startswith("/tiago1/"):
                continue
            message = reader.deserialize(raw, connection.msgtype)
            if connection.topic == "/tiago1/nav_vel":
                speeds.append(np.linalg.norm([message.linear.x, message.linear.y, message.linear.z]))
            elif connection.topic == "/tiago1/distance_travelled":
                distances.append(message.data)
            elif connection.topic == "/tiago1/scan":
                scan = np.asarray(message.ranges)
                ranges.append(scan[(scan >= message.range_min) & (scan <= message.range_max)].min())
    assert speeds and distances and ranges  # the bag records the robot standing by
    analysed = analyse_bag(run.bag, scenario)
    mine = {v.metric: v for v in analysed.run.metrics if v.robot == "tiago1" and v.scope is MetricScope.ROBOT}
    assert mine["max_velocity"].value == pytest.approx(max(speeds), abs=1e-12)
    assert mine["max_velocity"].value == 0.0  # standing still
    assert mine["distance_travelled"].value == pytest.approx(distances[-1] - distances[0], abs=1e-12)
    assert mine["distance_travelled"].topics == ("/tiago1/distance_travelled",)  # not its pose's jitter
    assert mine["distance_to_obstacles"].value == pytest.approx(min(ranges), rel=1e-6)
    assert {"fast_driving_time", "mean_turn_rate"} <= set(mine)
    assert "task_duration" not in mine and "waypoints_visited" not in mine
    assert any(
        "robot 'tiago1' has no tasks: task_duration, waypoints_visited not measured" in p
        for p in analysed.problems
    )
    between = next(v for v in analysed.run.metrics if v.metric == "distance_between_robots")
    assert "/tiago1/robot_pose" in between.topics  # the others must keep away from it too
    mission = next(v for v in analysed.run.metrics if v.metric == "mission_duration")
    # over goals, the mission reads the robots that drove: its recording does not widen the mission
    assert not any(t.startswith("/tiago1/") for t in mission.topics)
