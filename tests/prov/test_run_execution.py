"""The run-time PROV read back into an execution, and written with the ingested run
(exsce_dsl.prov.run_execution): the dispatcher's run and the ingested one, tied by their bag."""

from __future__ import annotations

import datetime
import json
from dataclasses import replace

import pytest
from pyoxigraph import NamedNode

from exsce_dsl.lang import load_spec
from exsce_dsl.model import Scenario
from exsce_dsl.model.runs import Action, ActionId, ActionStatus, Run, RunStatus
from exsce_dsl.prov.recorder import recorded_prov_json, recorded_run
from exsce_dsl.prov.run import compile_run
from exsce_dsl.prov.run_execution import read_execution
from exsce_dsl.rdf import to_quads, validate

from tests.support.paths import EXAMPLES, FIXTURES

DISPATCHED = "21ecf7c2-0000-5000-8000-000000000001"
INGESTED = "017d5b08-0000-5000-8000-000000000002"
BASE = "https://www.sesame-project.org/scenarios/"
START = datetime.datetime(2026, 1, 1, tzinfo=datetime.timezone.utc)


@pytest.fixture(scope="module")
def scenario_c() -> Scenario:
    return load_spec(EXAMPLES / "brsu_building_c" / "scenario_c.exsce").scenario()


def dispatched_run(scenario: Scenario) -> Run:
    """What a dispatcher records: tiago1's first goal succeeded, its second timed out after two
    attempts; tiago2's first goal was rejected; the mission was then stopped."""
    env = scenario.environment

    def pose(pose_id: str) -> object:
        found = env.pose(pose_id)
        assert found is not None
        return found

    robots = {r.id: r for r in scenario.robots}
    at = [START + datetime.timedelta(seconds=s) for s in range(0, 80, 10)]
    actions = [
        Action(ActionId("tiago1", 1, 1, 1), robots["tiago1"].start_pose, pose("classroom_c022-w001"),  # type: ignore[arg-type]
               ActionStatus.SUCCEEDED, at[0], at[2]),
        Action(ActionId("tiago1", 1, 1, 2), pose("classroom_c022-w001"), pose("classroom_c018-w001"),  # type: ignore[arg-type]
               ActionStatus.ABORTED, at[2], at[5], "timed out", 2),
        Action(ActionId("tiago2", 1, 1, 1), robots["tiago2"].start_pose, pose("classroom_c022-w002"),  # type: ignore[arg-type]
               ActionStatus.ABORTED, at[1], at[1], "rejected"),
    ]  # fmt: skip
    return recorded_run(DISPATCHED, "scenario_c", at[0], at[6], "run.bag", actions, RunStatus.STOPPED)


def test_the_run_time_prov_reads_back_as_the_dispatchers_execution(scenario_c: Scenario) -> None:
    document = json.loads(recorded_prov_json(dispatched_run(scenario_c), scenario_c))
    execution = read_execution(document, "run.prov.json", "scenario_c")
    assert execution is not None
    assert (execution.run_id, execution.source, execution.bag_name) == (
        DISPATCHED,
        "run.prov.json",
        "run.bag",
    )
    assert (execution.start, execution.mission_status) == (START, "stopped")
    goals = {g.name: g for g in execution.goals}
    assert sorted(goals) == [
        "tiago1-task_01-subtask_001-w_001", "tiago1-task_01-subtask_001-w_002", "tiago2-task_01-subtask_001-w_001",
    ]  # fmt: skip
    second = goals["tiago1-task_01-subtask_001-w_002"]
    assert (second.robot, second.status, second.outcome, second.attempts) == (
        "tiago1",
        "ABORTED",
        "timed out",
        2,
    )
    assert second.goal_pose is not None and second.goal_pose.startswith("classroom_c018-w001-")
    assert second.start_pose is not None and second.start_pose.startswith("classroom_c022-w001-")
    assert goals["tiago2-task_01-subtask_001-w_001"].outcome == "rejected"
    assert goals["tiago1-task_01-subtask_001-w_001"].end == START + datetime.timedelta(seconds=20)


def test_the_methods_own_recorded_run_reads_back() -> None:
    """The published run 30af607a, written by the method's recorder (which names no scenario)."""
    path = FIXTURES / "runs" / "2023-06-26T21-47-04_scenario_c_run-30af607a.prov.json"
    execution = read_execution(json.loads(path.read_text(encoding="utf-8")), path.name, "scenario_c")
    assert execution is not None
    assert execution.run_id == "30af607a-145a-11ee-aa3d-0d574918902f"
    assert execution.bag_name == "2023-06-26T21-47-04_scenario_c_run-30af607a.bag"
    assert len(execution.goals) == 6
    assert {g.status for g in execution.goals} == {"SUCCEEDED"}


def test_a_run_time_prov_of_another_scenario_or_not_prov_is_no_execution(scenario_c: Scenario) -> None:
    document = json.loads(recorded_prov_json(dispatched_run(scenario_c), scenario_c))
    assert read_execution(document, "run.prov.json", "scenario_d") is None
    assert read_execution(["not", "prov"], "x", "scenario_c") is None
    assert read_execution({"bundle": {}}, "x", "scenario_c") is None


def ingested_with_execution(scenario: Scenario) -> Run:
    dispatched = dispatched_run(scenario)
    document = json.loads(recorded_prov_json(dispatched, scenario))
    execution = read_execution(document, "/exsce/prov", "scenario_c")
    return replace(dispatched, uuid=INGESTED, execution=execution)


def test_the_execution_is_stored_with_the_ingested_run_and_tied_to_it_by_its_bag(
    scenario_c: Scenario,
) -> None:
    quads = list(to_quads(compile_run(ingested_with_execution(scenario_c), scenario_c)))
    graph = NamedNode(f"{BASE}runs/run_{INGESTED}/execution_bundle")
    mine = {(q.subject, q.predicate, q.object) for q in quads if q.graph_name == graph}
    execution = NamedNode(f"{BASE}runs/run_{DISPATCHED}")
    prov = "http://www.w3.org/ns/prov#"
    ingested_bag = NamedNode(f"{BASE}runs/run_{INGESTED}/run.bag")
    dispatched_bag = NamedNode(f"{BASE}runs/run_{DISPATCHED}/run.bag")
    assert (ingested_bag, NamedNode(prov + "alternateOf"), dispatched_bag) in mine
    assert (dispatched_bag, NamedNode(prov + "wasGeneratedBy"), execution) in mine
    assert (execution, NamedNode(prov + "used"), NamedNode(BASE + "scenario_c")) in mine
    goal = NamedNode(f"{BASE}runs/run_{DISPATCHED}/tiago1-task_01-subtask_001-w_002")
    assert (goal, NamedNode(prov + "wasInformedBy"), execution) in mine
    outcomes = {str(o.value) for s, p, o in mine if s == goal and p == NamedNode(BASE + "goal_outcome")}
    assert outcomes == {"timed out"}
    types = {o for s, p, o in mine if p == NamedNode("http://www.w3.org/1999/02/22-rdf-syntax-ns#type")}
    assert NamedNode(BASE + "execution") in types and NamedNode(BASE + "dispatched_goal") in types
    assert NamedNode(BASE + "action") not in types  # the goals are not the run's actions


def test_a_run_with_its_execution_conforms_to_the_run_shapes(scenario_c: Scenario) -> None:
    assert validate(to_quads(compile_run(ingested_with_execution(scenario_c), scenario_c)), ["runs"]) == []


def test_a_run_without_run_time_prov_has_no_execution_bundle(scenario_c: Scenario) -> None:
    quads = to_quads(compile_run(replace(dispatched_run(scenario_c), uuid=INGESTED), scenario_c))
    assert not any(str(q.graph_name.value).endswith("/execution_bundle") for q in quads)  # type: ignore[union-attr]
