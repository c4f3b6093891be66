"""The segment index the store writes beside each run (exsce_dsl.store.segment_index).

One robot r1 in a corridor of three poses a, b, c: its task goes a → b → a → b, so
the run drives the segment a → b twice.  Values are chosen by hand.
"""

from __future__ import annotations

import datetime
from pathlib import Path

from pyoxigraph import Literal, NamedNode

from exsce_dsl.model import (
    Area,
    Assignment,
    Environment,
    Mission,
    MissionType,
    Orientation,
    Pose,
    Position,
    Robot,
    RobotType,
    Scenario,
    Subtask,
    Task,
)
from exsce_dsl.model.runs import Action, ActionId, Bag, MetricScope, MetricValue, Run, TaskExecution
from exsce_dsl.prov import compile_scenario
from exsce_dsl.prov.identifiers import DEFAULT_NAMESPACE
from exsce_dsl.prov.run import compile_run
from exsce_dsl.rdf import to_quads
from exsce_dsl.store import queries as q
from exsce_dsl.store.embedded import EmbeddedStore
from exsce_dsl.store.segment_index import segment_index, segment_iri
from exsce_dsl.store.writing import add_prov

from tests.support.cli import exscec_here


def pose(name: str, x: float) -> Pose:
    return Pose(name, Position(x, 0.0), Orientation(), "corridor")


A, B, C = pose("corridor-a", 0.0), pose("corridor-b", 5.0), pose("corridor-c", 9.0)
NAME = {p: f"{p.id}-R0.00_P0.00_Y0.00" for p in (A, B, C)}
BACK_AND_FORTH = Task("back_and_forth", (Subtask((B, A, B)),))
SCENARIO = Scenario(
    "corridor_runs",
    Environment("corridor_world", areas=(Area("corridor", (A, B, C)),)),
    (Robot("r1", RobotType("tiago", base="pmb2", torso=True), "r1", start_pose=A),),
    Mission("m", MissionType.SEQUENTIAL, (Assignment("r1", "back_and_forth"),)),
    (BACK_AND_FORTH,),
)
DIST = ("/r1/distance_travelled",)


def run(uuid: str, values: tuple[float, ...], *, hour: int = 9) -> Run:
    """A run of SCENARIO whose actions a→b, b→a, a→b (as many as values) travelled ``values``."""
    legs = ((A, B), (B, A), (A, B))[: len(values)]
    actions = tuple(Action(ActionId("r1", 1, 1, w), start, goal) for w, (start, goal) in enumerate(legs, 1))
    metrics = tuple(
        MetricValue("distance_travelled", MetricScope.SEGMENT, v, DIST, action=a.id)
        for a, v in zip(actions, values, strict=True)
    )
    start = datetime.datetime(2024, 6, 1, hour)
    return Run(
        uuid,
        SCENARIO.id,
        start,
        start + datetime.timedelta(minutes=5),
        Bag(f"{uuid}.bag", DIST),
        (TaskExecution("r1", 1, actions),),
        metrics,
    )


def graphs_of(document_run: Run) -> dict[str, list]:  # type: ignore[type-arg]
    graphs: dict[str, list] = {}  # type: ignore[type-arg]
    for quad in to_quads(compile_run(document_run, SCENARIO)):
        graphs.setdefault(quad.graph_name.value, []).append(quad)  # type: ignore[union-attr]
    return graphs


def test_each_segment_and_each_action_get_a_graph() -> None:
    index = segment_index(graphs_of(run("u-1", (5.0, 5.5, 4.5))))
    run_ns = f"{DEFAULT_NAMESPACE}runs/run_u-1/"
    exsce = DEFAULT_NAMESPACE
    a_to_b = segment_iri(DEFAULT_NAMESPACE, "corridor_runs", NAME[A], NAME[B])
    b_to_a = segment_iri(DEFAULT_NAMESPACE, "corridor_runs", NAME[B], NAME[A])
    assert a_to_b == f"{exsce}segments/corridor_runs/{NAME[A]}/{NAME[B]}"
    actions = [f"{run_ns}r1-task_01-subtask_001-w_00{w}" for w in (1, 2, 3)]
    assert sorted(index) == sorted([a_to_b, b_to_a, *actions])

    def triples(graph: str) -> set[tuple[object, str, object]]:
        assert all(quad.graph_name == NamedNode(graph) for quad in index[graph])
        return {(quad.subject, quad.predicate.value, quad.object) for quad in index[graph]}

    segment = NamedNode(a_to_b)
    assert triples(a_to_b) == {
        (segment, "http://www.w3.org/1999/02/22-rdf-syntax-ns#type", NamedNode(f"{exsce}PathSegment")),
        (segment, f"{exsce}startPose", NamedNode(f"{exsce}tasks/waypoints/{NAME[A]}")),
        (segment, f"{exsce}goalPose", NamedNode(f"{exsce}tasks/waypoints/{NAME[B]}")),
        (segment, f"{exsce}segmentOf", NamedNode(f"{exsce}corridor_runs")),
    }
    double = NamedNode("http://www.w3.org/2001/XMLSchema#double")
    for action, value in ((actions[0], "5.0"), (actions[2], "4.5")):
        assert triples(action) == {
            (segment, f"{exsce}run", Literal("u-1")),
            (segment, f"{exsce}robot", Literal("r1")),
            (segment, f"{exsce}metrics/distance_travelled", Literal(value, datatype=double)),
        }
    assert (
        NamedNode(b_to_a),
        f"{exsce}metrics/distance_travelled",
        Literal("5.5", datatype=double),
    ) in triples(actions[1])


def test_a_spec_has_no_index() -> None:
    graphs: dict[str, list] = {}  # type: ignore[type-arg]
    for quad in to_quads(compile_scenario(SCENARIO)):
        graphs.setdefault(quad.graph_name.value, []).append(quad)  # type: ignore[union-attr]
    assert segment_index(graphs) == {}


def test_two_drives_of_a_segment_with_equal_values_count_twice() -> None:
    store = EmbeddedStore(None)
    add_prov(store, compile_scenario(SCENARIO))
    add_prov(store, compile_run(run("u-1", (5.0, 6.0, 5.0)), SCENARIO))
    add_prov(store, compile_run(run("u-2", (7.0,), hour=10), SCENARIO))
    # a → b: 5.0 and 5.0 in u-1, 7.0 in u-2: mean 17/3
    found = q.segment_metric(store, "distance_travelled", A, B, scenario="corridor_runs")
    assert found is not None and found.count == 3 and abs(found.mean - 17 / 3) < 1e-12
    by_runs = q.segment_metric(store, "distance_travelled", A, B, runs=["u-1"])
    assert by_runs is not None and (by_runs.count, by_runs.mean, by_runs.std) == (2, 5.0, 0.0)
    back = q.segment_metric(store, "distance_travelled", B, A, scenario="corridor_runs")
    assert back is not None and (back.count, back.mean) == (1, 6.0)


def test_adding_a_run_again_writes_nothing_and_replacing_it_drops_actions_it_no_longer_has() -> None:
    store = EmbeddedStore(None)
    add_prov(store, compile_scenario(SCENARIO))
    add_prov(store, compile_run(run("u-1", (5.0, 6.0, 5.0)), SCENARIO))
    again = add_prov(store, compile_run(run("u-1", (5.0, 6.0, 5.0)), SCENARIO))
    assert not again.changed and again.statements == 0
    shorter = add_prov(store, compile_run(run("u-1", (4.0,)), SCENARIO), replace=True)
    assert shorter.revisions  # the run's own old graphs are kept as revisions ...
    assert not any(
        "w_00" in name and "revision" in name for name in store.graph_names()
    )  # ... its index is not
    found = q.segment_metric(store, "distance_travelled", A, B, scenario="corridor_runs")
    assert found is not None and (found.count, found.mean) == (1, 4.0)
    assert q.segment_metric(store, "distance_travelled", B, A, scenario="corridor_runs") is None


def test_store_graphs_and_info_set_the_index_apart(tmp_path: Path) -> None:
    with EmbeddedStore(tmp_path / ".exsce" / "store") as store:
        add_prov(store, compile_scenario(SCENARIO))
        add_prov(store, compile_run(run("u-1", (5.0, 6.0, 5.0)), SCENARIO))
    listed = exscec_here("store", "graphs", cwd=tmp_path)
    assert listed.returncode == 0, listed.stderr
    assert (
        "/segments/" not in listed.stdout
        and "w_001" not in listed.stdout
        and "run_u-1_bundle" in listed.stdout
    )
    # 2 segments, 3 actions; the run's summary, the keys of its scenario and its one metric
    assert "and 8 graphs of its indexes: --index lists them" in listed.stderr
    everything = exscec_here("store", "graphs", "--index", cwd=tmp_path)
    assert everything.stdout.count("/segments/corridor_runs/") == 2 and everything.stdout.count("-w_00") == 3
    info = exscec_here("store", "info", cwd=tmp_path)
    assert "+ 8 of its indexes)" in info.stdout


def test_the_values_of_runs_whole_and_by_action() -> None:
    store = EmbeddedStore(None)
    add_prov(store, compile_scenario(SCENARIO))
    add_prov(store, compile_run(run("u-1", (5.0, 6.0)), SCENARIO))
    add_prov(store, compile_run(run("u-2", (7.0,), hour=10), SCENARIO))
    assert q.run_metric_values(store, ["u-1", "u-2"]) == []  # these runs have segment values only
    found = sorted(
        (r.run, r.action.rsplit("/", 1)[-1] if r.action else None, r.goal, r.metric, r.value)
        for r in q.run_segment_values(store, ["u-1"])
    )
    assert found == [
        ("u-1", "r1-task_01-subtask_001-w_001", NAME[B], "distance_travelled", 5.0),
        ("u-1", "r1-task_01-subtask_001-w_002", NAME[A], "distance_travelled", 6.0),
    ]
    assert {r.robot for r in q.run_segment_values(store, ["u-1", "u-2"])} == {"r1"}
    assert q.run_segment_values(store, []) == [] and q.run_defects(store, "corridor_runs") == []
