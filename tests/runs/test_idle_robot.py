"""A robot left without tasks (a derivation handed them to another) is still a robot of the
scenario: its run ingests, the mission's metrics over goals read only the robots that drove, and
standing by it is still measured (tests/derive/test_standing_robot.py)."""

from __future__ import annotations

from pathlib import Path

from rosbags.highlevel import AnyReader

from exsce_dsl.lang import load_spec
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
