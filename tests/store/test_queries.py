"""The query library on data whose answers are worked out by hand.

Two scenarios in one room of four poses (a, b, c, d):

* ``s``: robot r1 (a tiago) starts at a and does t1 (b, c) then t3 (a); robot r2 (a
  torso-less pmb2) starts at d and does t2 (c, b).  Three runs; on the segment a → b
  robot r1 travelled 10, 12 and 14 m, so the mean is 12 and the population standard
  deviation sqrt(8/3).
* ``s_rev``, derived from ``s``: r1 starts at b and goes to a.  One run, b → a: 100 m
  (the other direction of the same segment).

The data goes in through the real write path (compile_scenario, compile_run,
compile_oracles, compile_derivation, then add_prov), except for a hand-written graph
whose ids hold quotes, braces and ``#``.
"""

from __future__ import annotations

import dataclasses
import datetime
import json
import math
from collections.abc import Iterator
from pathlib import Path

import pytest
from pyoxigraph import Quad, RdfFormat, parse

from exsce_dsl.errors import ExsceError
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
from exsce_dsl.model.derivation import Derivation, TransformationStep
from exsce_dsl.model.oracles import Oracle, OracleType
from exsce_dsl.model.runs import Action, ActionId, Bag, Hotspot, MetricScope, MetricValue, Run, TaskExecution
from exsce_dsl.prov import compile_scenario
from exsce_dsl.prov.derivation import compile_derivation
from exsce_dsl.prov.identifiers import DEFAULT_NAMESPACE
from exsce_dsl.prov.oracle import compile_oracles
from exsce_dsl.prov.run import compile_run
from exsce_dsl.store import queries as q
from exsce_dsl.store.base import GraphSet, Store
from exsce_dsl.store.embedded import EmbeddedStore
from exsce_dsl.store.queries import MetricSource, PathSegment, RobotFacts, ValueStats, ViolationDuration
from exsce_dsl.store.remote import RemoteStore
from exsce_dsl.store.writing import add_prov

from tests.support.cli import exscec_here
from tests.support.store_servers import oxigraph_server, virtuoso_server

# -- the scenarios ---------------------------------------------------------------------------


def pose(name: str, x: float, y: float) -> Pose:
    return Pose(name, Position(x, y), Orientation(), "room")


A, B, C, D = pose("room-a", 0, 0), pose("room-b", 3, 4), pose("room-c", 6, 8), pose("room-d", 0, 8)
ROOM = Environment("house", areas=(Area("room", (A, B, C, D)),))
TIAGO = RobotType("tiago", base="pmb2", torso=True)
PMB2 = RobotType("pmb2", base="pmb2", torso=False)
T1 = Task("t1", (Subtask((B, C)),))
T2 = Task("t2", (Subtask((C, B)),))
T3 = Task("t3", (Subtask((A,)),))
T_BACK = Task("t_back", (Subtask((A,)),))

S = Scenario(
    "s",
    ROOM,
    (Robot("r1", TIAGO, "r1", start_pose=A), Robot("r2", PMB2, "r2", start_pose=D)),
    Mission(
        "m", MissionType.PARALLEL, (Assignment("r1", "t1"), Assignment("r2", "t2"), Assignment("r1", "t3"))
    ),
    (T1, T2, T3),
)
S_REV = Scenario(
    "s_rev",
    ROOM,
    (Robot("r1", TIAGO, "r1", start_pose=B),),
    Mission("m_rev", MissionType.PARALLEL, (Assignment("r1", "t_back"),)),
    (T_BACK,),
)

name = {p.id: f"{p.id}-R0.00_P0.00_Y0.00" for p in (A, B, C, D)}
A_, B_, C_, D_ = (name[p.id] for p in (A, B, C, D))

# -- the runs ----------------------------------------------------------------------------------

RUN_1, RUN_2, RUN_3, RUN_REV = "run-1", "run-2", "run-3", "run-rev"
DIST = "distance_travelled"


def topics(robot: str) -> tuple[str, ...]:
    return tuple(f"/{robot}/{t}" for t in ("distance_travelled", "nav_vel", "waypoint_dispatcher/feedback"))


def run_of_s(uuid: str, hour: int, a_to_b: float, mission: float, visited: float, violated: float) -> Run:
    def action(robot: str, allocation: int, waypoint: int, start: Pose, goal: Pose) -> Action:
        return Action(ActionId(robot, allocation, 1, waypoint), start, goal)

    r1 = (action("r1", 1, 1, A, B), action("r1", 1, 2, B, C))
    r1_home = (action("r1", 2, 1, C, A),)
    r2 = (action("r2", 1, 1, D, C), action("r2", 1, 2, C, B))
    dist1, dist2 = ("/r1/distance_travelled",), ("/r2/distance_travelled",)
    metrics = (
        MetricValue(DIST, MetricScope.SEGMENT, a_to_b, dist1, action=r1[0].id),
        MetricValue(DIST, MetricScope.SEGMENT, 5.0, dist1, action=r1[1].id),
        MetricValue(DIST, MetricScope.SEGMENT, 10.0, dist1, action=r1_home[0].id),
        MetricValue(DIST, MetricScope.SEGMENT, 1000.0, dist2, action=r2[1].id),  # c → b: not b → a
        MetricValue(DIST, MetricScope.ROBOT, a_to_b + 15.0, dist1, robot="r1", unit="m"),
        MetricValue(DIST, MetricScope.ROBOT, 70.0, dist2, robot="r2"),
        MetricValue(
            "task_duration",
            MetricScope.SEGMENT,
            999.0,
            ("/r1/waypoint_dispatcher/feedback",),
            action=r1[0].id,
        ),
        MetricValue("mission_duration", MetricScope.MISSION, mission, ("/r1/waypoint_dispatcher/feedback",)),
        MetricValue(
            "waypoints_visited", MetricScope.ROBOT, visited, ("/r1/waypoint_dispatcher/feedback",), robot="r1"
        ),
        MetricValue(
            "violation_duration",
            MetricScope.ROBOT,
            violated,
            ("/r1/nav_vel",),
            robot="r1",
            safety_metric="max_velocity",
        ),
    )
    return Run(
        uuid,
        "s",
        datetime.datetime(2024, 5, 1, hour),
        datetime.datetime(2024, 5, 1, hour, 30),
        Bag(f"{uuid}.bag", topics("r1") + topics("r2")),
        (TaskExecution("r1", 1, r1), TaskExecution("r2", 1, r2), TaskExecution("r1", 2, r1_home)),
        metrics,
    )


def hotspot(metric: str) -> Hotspot:
    return Hotspot(metric, Position(1.0, 2.0), 2, 0.5, robot="r1")


RUNS_OF_S = (
    # run 3 is the oldest: runs come back by start time.
    Run(
        **{
            **run_of_s(RUN_1, 10, 10.0, 90.0, 3.0, 1.0).__dict__,
            "hotspots": (hotspot("max_velocity"),) * 2 + (hotspot("distance_to_obstacles"),),
        }
    ),
    run_of_s(RUN_2, 11, 12.0, 100.0, 3.0, 2.0),
    Run(**{**run_of_s(RUN_3, 9, 14.0, 110.0, 2.0, 6.0).__dict__, "hotspots": (hotspot("max_velocity"),)}),
)
RUN_OF_S_REV = Run(
    RUN_REV,
    "s_rev",
    datetime.datetime(2024, 5, 2, 8),
    datetime.datetime(2024, 5, 2, 8, 10),
    Bag(f"{RUN_REV}.bag", topics("r1")),
    (TaskExecution("r1", 1, (Action(ActionId("r1", 1, 1, 1), B, A),)),),
    (
        MetricValue(
            DIST, MetricScope.SEGMENT, 100.0, ("/r1/distance_travelled",), action=ActionId("r1", 1, 1, 1)
        ),
    ),
)

# -- oracles and derivations -----------------------------------------------------------------------

BASELINE, METAMORPHIC = OracleType.BASELINE, OracleType.METAMORPHIC
FEEDBACK = ("/r1/waypoint_dispatcher/feedback", "/r2/waypoint_dispatcher/feedback")
ORACLES_OF_S = [
    Oracle("mission_duration", None, "invariant", BASELINE, "s", FEEDBACK, value=100.0, tolerance=10.0),
    Oracle(
        "task_duration",
        "r1",
        "invariant",
        BASELINE,
        "s",
        ("/r1/waypoint_dispatcher/feedback",),
        value=50.0,
        tolerance=5.0,
    ),
    Oracle(
        "max_velocity",
        "r1",
        "below_max",
        BASELINE,
        "s",
        ("/r1/nav_vel",),
        limit=1.0,
        package="exsce.metamorphic.relationships",
    ),
]
ORACLES_OF_S_REV = [
    Oracle(
        "task_duration",
        "r1",
        "invariant",
        BASELINE,
        "s_rev",
        ("/r1/waypoint_dispatcher/feedback",),
        value=40.0,
        tolerance=4.0,
    ),
    Oracle(
        "task_duration",
        "r1",
        "decreasing",
        METAMORPHIC,
        "s",
        ("/r1/waypoint_dispatcher/feedback",),
        value=40.0,
        delta=10.0,
        tolerance=0.0,
    ),
]
S_REV_FROM_S = Derivation(
    "s_rev",
    "s",
    (
        TransformationStep("remove_robot", (("robot", "r2"), ("keep_tasks", False))),
        TransformationStep(
            "add_task", (("robot", "r1"), ("task", "t_back"), ("position", 1), ("scale", 0.5))
        ),
    ),
)
S_REV2_FROM_S_REV = Derivation("s_rev2", "s_rev", (TransformationStep("reverse_task_order"),))

ODD_RUN = "odd.run-1"  # a run id is a name (exsce's run IRIs are made of it); the robot is odd
ODD_ROBOT = 'r"}#{'
ODD_TRIG = f"""
@prefix prov: <http://www.w3.org/ns/prov#> .
@prefix exsce: <{DEFAULT_NAMESPACE}> .
<{DEFAULT_NAMESPACE}runs/run_odd.run-1/max_velocity_bundle> {{
  <{DEFAULT_NAMESPACE}runs/run_odd.run-1/m> a exsce:output_metric ;
      <{DEFAULT_NAMESPACE}runs/metricType> "max_velocity" ;
      exsce:run "odd.run-1" ;
      exsce:robot "r\\"}}#{{" ;
      prov:value 7.5e0 ;
      prov:wasGeneratedBy <{DEFAULT_NAMESPACE}runs/run_odd.run-1> .
}}
<{DEFAULT_NAMESPACE}runs/run_odd.run-1_bundle> {{ <{DEFAULT_NAMESPACE}runs/run_odd.run-1> a exsce:run . }}
"""


def populate(store: Store) -> None:
    add_prov(store, compile_scenario(S))
    add_prov(store, compile_scenario(S_REV))
    for run in RUNS_OF_S:
        add_prov(store, compile_run(run, S))
    add_prov(store, compile_run(RUN_OF_S_REV, S_REV))
    add_prov(store, compile_oracles("s", ORACLES_OF_S))
    add_prov(store, compile_oracles("s_rev", ORACLES_OF_S_REV))
    add_prov(store, compile_derivation(S_REV_FROM_S))
    add_prov(store, compile_derivation(S_REV2_FROM_S_REV))
    graphs: dict[str, list[Quad]] = {}
    for quad in parse(ODD_TRIG, format=RdfFormat.TRIG):
        graphs.setdefault(quad.graph_name.value, []).append(quad)  # type: ignore[union-attr]
    store.write(GraphSet(graphs))


@pytest.fixture(scope="module")
def store_folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("queries") / "store"
    with EmbeddedStore(folder) as store:
        populate(store)
    return folder


@pytest.fixture
def store(store_folder: Path) -> Iterator[Store]:
    with EmbeddedStore(store_folder) as opened:
        yield opened


@pytest.fixture
def fresh_store() -> Store:
    """A store of its own, for the tests that change it."""
    store = EmbeddedStore(None)
    populate(store)
    return store


def close(a: ValueStats | None, mean: float, std: float, count: int) -> bool:
    return (
        a is not None
        and a.count == count
        and math.isclose(a.mean, mean)
        and math.isclose(a.std, std, abs_tol=1e-9)
    )


# -- runs and their metrics ----------------------------------------------------------------------


def test_the_runs_of_a_scenario_oldest_first(store: Store) -> None:
    found = q.runs(store, "s")
    assert [r.uuid for r in found] == [RUN_3, RUN_1, RUN_2]
    assert found[1].scenario == "s" and found[1].bag == f"{RUN_1}.bag"
    assert found[1].start == datetime.datetime(2024, 5, 1, 10) and found[1].end == datetime.datetime(
        2024, 5, 1, 10, 30
    )
    assert [r.uuid for r in q.runs(store, "s_rev")] == [RUN_REV]
    assert {r.uuid: r.scenario for r in q.runs(store)} == {
        RUN_1: "s",
        RUN_2: "s",
        RUN_3: "s",
        RUN_REV: "s_rev",
    }
    assert q.runs(store, "nothing") == []


def test_a_metric_of_a_run(store: Store) -> None:
    assert q.run_metric(store, RUN_1, DIST, "r1") == 25.0  # the whole run, not a segment
    assert q.run_metric(store, RUN_1, DIST, "r2") == 70.0
    assert q.run_metric(store, RUN_1, "max_velocity", "r1") is None
    assert q.mission_metric(store, RUN_2, "mission_duration") == 100.0
    assert q.mission_metric(store, RUN_2, DIST) is None


def test_a_segment_metric_over_runs_keeps_the_direction(store: Store) -> None:
    every = [RUN_1, RUN_2, RUN_3, RUN_REV]
    assert close(q.segment_metric(store, DIST, A, B, runs=every), 12.0, math.sqrt(8 / 3), 3)
    assert close(q.segment_metric(store, DIST, A_, B_, runs=every), 12.0, math.sqrt(8 / 3), 3)
    assert close(q.segment_metric(store, DIST, B, A, runs=every), 100.0, 0.0, 1)
    assert close(q.segment_metric(store, DIST, A, B, runs=[RUN_1, RUN_2]), 11.0, 1.0, 2)
    assert close(q.segment_metric(store, DIST, A, B, scenario="s"), 12.0, math.sqrt(8 / 3), 3)
    assert close(q.segment_metric(store, DIST, B, A, scenario="s_rev"), 100.0, 0.0, 1)
    assert q.segment_metric(store, DIST, A, B, scenario="s_rev") is None
    assert q.segment_metric(store, DIST, B, C, runs=[]) is None
    assert close(q.segment_metric(store, "task_duration", A, B, scenario="s"), 999.0, 0.0, 3)
    with pytest.raises(ExsceError, match="either runs or a scenario"):
        q.segment_metric(store, DIST, A, B)


def test_waypoints_visited_and_mission_duration_over_runs(store: Store) -> None:
    runs = [RUN_1, RUN_2, RUN_3]
    assert close(q.waypoints_visited(store, "r1", runs), 8 / 3, math.sqrt(2 / 9), 3)
    assert q.waypoints_visited(store, "r2", runs) is None
    assert close(q.mission_duration(store, runs), 100.0, math.sqrt(200 / 3), 3)
    assert close(q.mission_duration(store, [RUN_1]), 90.0, 0.0, 1)
    assert close(q.robot_metric_over_runs(store, DIST, "r1", runs), 27.0, math.sqrt(8 / 3), 3)
    assert q.mission_metric_over_runs(store, "mission_duration", []) is None


def test_where_a_metric_value_comes_from(store: Store) -> None:
    found = q.metric_sources(store, RUN_1, DIST)
    bag = f"{RUN_1}.bag"
    r1, r2 = ("/r1/distance_travelled",), ("/r2/distance_travelled",)
    assert sorted(found, key=lambda s: (s.robot or "", s.segment or "")) == [
        MetricSource("r1", None, 25.0, r1, bag),
        MetricSource("r1", "r1-task_01-subtask_001-w_001", 10.0, r1, bag),
        MetricSource("r1", "r1-task_01-subtask_001-w_002", 5.0, r1, bag),
        MetricSource("r1", "r1-task_02-subtask_001-w_001", 10.0, r1, bag),
        MetricSource("r2", None, 70.0, r2, bag),
        MetricSource("r2", "r2-task_01-subtask_001-w_002", 1000.0, r2, bag),
    ]
    (mission,) = q.metric_sources(store, RUN_2, "mission_duration")
    assert mission == MetricSource(None, None, 100.0, ("/r1/waypoint_dispatcher/feedback",), f"{RUN_2}.bag")


# -- safety ------------------------------------------------------------------------------------------


def test_violation_durations_per_run_and_their_mean(store: Store) -> None:
    assert q.violation_durations(store, "s", "max_velocity") == [
        ViolationDuration(RUN_1, "r1", 1.0),
        ViolationDuration(RUN_2, "r1", 2.0),
        ViolationDuration(RUN_3, "r1", 6.0),
    ]
    means = q.violation_duration(store, "s", "max_velocity")
    assert list(means) == ["r1"] and close(means["r1"], 3.0, math.sqrt(14 / 3), 3)
    assert q.violation_durations(store, "s", "distance_to_obstacles") == []


def test_hotspot_counts_per_run(store: Store) -> None:
    assert q.hotspot_counts(store, "s", "max_velocity") == {RUN_1: 2, RUN_2: 0, RUN_3: 1}
    assert q.hotspot_counts(store, "s", "distance_to_obstacles") == {RUN_1: 1, RUN_2: 0, RUN_3: 0}
    assert q.hotspot_counts(store, "s_rev", "max_velocity") == {RUN_REV: 0}


# -- scenarios -----------------------------------------------------------------------------------


def test_the_robots_of_a_scenario(store: Store) -> None:
    assert q.robots(store, "s") == [
        RobotFacts("r1", "tiago", "pmb2", True),
        RobotFacts("r2", "pmb2", "pmb2", False),
    ]
    assert q.robots(store, "s_rev") == [RobotFacts("r1", "tiago", "pmb2", True)]


def test_the_path_segments_of_a_scenario(store: Store) -> None:
    assert q.path_segments(store, "s") == [
        PathSegment("r1", A_, B_),
        PathSegment("r1", B_, C_),
        PathSegment("r1", C_, A_),  # across the robot's tasks
        PathSegment("r2", D_, C_),
        PathSegment("r2", C_, B_),
    ]
    assert q.path_segments(store, "s_rev") == [PathSegment("r1", B_, A_)]


def test_the_lineage_of_a_scenario(store: Store) -> None:
    assert q.derivation_of(store, "s") is None
    assert q.derivation_of(store, "s_rev") == Derivation(
        "s_rev",
        "s",
        (
            TransformationStep("remove_robot", (("keep_tasks", False), ("robot", "r2"))),
            TransformationStep(
                "add_task", (("position", 1), ("robot", "r1"), ("scale", 0.5), ("task", "t_back"))
            ),
        ),
    )
    lineage = q.lineage(store, "s_rev2")
    assert [(d.new, d.base) for d in lineage] == [("s_rev2", "s_rev"), ("s_rev", "s")]
    assert lineage[0].steps == (TransformationStep("reverse_task_order"),)
    assert q.lineage(store, "s") == []


# -- oracles --------------------------------------------------------------------------------------


def sorted_topics(oracle: Oracle) -> Oracle:
    return Oracle(**{**oracle.__dict__, "topics": tuple(sorted(oracle.topics))})


def test_the_oracles_of_a_scenario(store: Store) -> None:
    key = lambda o: (o.metric, o.robot or "", o.type.value)  # noqa: E731
    assert sorted(q.oracles(store, "s"), key=key) == sorted(map(sorted_topics, ORACLES_OF_S), key=key)
    assert sorted(q.oracles(store, "s_rev"), key=key) == sorted(ORACLES_OF_S_REV, key=key)
    assert q.oracles(store, "nothing") == []


def test_updating_a_baseline_changes_that_one_only(fresh_store: Store) -> None:
    q.update_baseline(fresh_store, "s", "task_duration", "r1", 55.0, 6.0)
    q.update_baseline(fresh_store, "s", "mission_duration", None, 101.0, 11.0)
    by_metric = {o.metric: o for o in q.oracles(fresh_store, "s")}
    assert (by_metric["task_duration"].value, by_metric["task_duration"].tolerance) == (55.0, 6.0)
    assert (by_metric["mission_duration"].value, by_metric["mission_duration"].tolerance) == (101.0, 11.0)
    assert by_metric["max_velocity"] == ORACLES_OF_S[2]
    # The same metric and robot in another scenario, baseline and metamorphic alike, is untouched.
    assert sorted(q.oracles(fresh_store, "s_rev"), key=lambda o: o.type.value) == ORACLES_OF_S_REV
    with pytest.raises(ExsceError, match="no baseline oracle of 'task_duration' for robot 'r2'"):
        q.update_baseline(fresh_store, "s", "task_duration", "r2", 1.0, 1.0)


def test_replaced_runs_leave_their_old_values_out(fresh_store: Store) -> None:
    faster = run_of_s(RUN_3, 9, 20.0, 110.0, 2.0, 6.0)
    report = add_prov(fresh_store, compile_run(faster, S), replace=True)
    assert report.revisions  # the old version is kept, as a revision graph
    assert close(q.segment_metric(fresh_store, DIST, A, B, scenario="s"), 14.0, math.sqrt(56 / 3), 3)
    assert close(
        q.segment_metric(fresh_store, DIST, A, B, runs=[RUN_1, RUN_2, RUN_3]), 14.0, math.sqrt(56 / 3), 3
    )
    assert [r.uuid for r in q.runs(fresh_store, "s")] == [RUN_3, RUN_1, RUN_2]
    assert q.run_metric(fresh_store, RUN_3, DIST, "r1") == 35.0


# -- parameters are terms, never text -----------------------------------------------------------------


def test_ids_with_quotes_braces_and_hashes_are_bound_as_terms(store: Store) -> None:
    assert q.run_metric(store, ODD_RUN, "max_velocity", ODD_ROBOT) == 7.5
    assert q.run_metric(store, ODD_RUN, "max_velocity", "r1") is None
    with pytest.raises(ExsceError, match="cannot be part of an identifier"):  # not a run id
        q.run_metric(store, '"} } UNION { ?s ?p ?o } #', DIST, "r1")
    assert q.oracles(store, 's" } ?x ?y ?z { #') == []
    assert q.runs(store, "s#x") == []  # a valid IRI, with a fragment: no such scenario
    with pytest.raises(ExsceError, match="cannot be part of an IRI"):
        q.runs(store, 's"}')
    with pytest.raises(ExsceError, match="cannot be part of an IRI"):
        q.segment_metric(store, DIST, "a> } #", B, scenario="s")


def test_the_library_checks_parameters(store: Store) -> None:
    with pytest.raises(ExsceError, match="needs metric, robot"):
        q.run_query(store, "run_metric", {"run": RUN_1})
    with pytest.raises(ExsceError, match="has no parameter 'colour'"):
        q.run_query(store, "runs", {"colour": "red"})
    with pytest.raises(ExsceError, match="takes one value"):
        q.run_query(store, "runs", {"scenario": ["s", "s_rev"]})
    with pytest.raises(ExsceError, match="did you mean 'runs'"):
        q.query("rusn")
    assert {"runs", "segment_metric", "oracles", "update_baseline", "path_segments"} <= set(q.query_names())
    assert all(q.query(n).description for n in q.query_names())


# -- the command line ---------------------------------------------------------------------------------


def test_exscec_query_prints_tables_json_and_csv(store_folder: Path) -> None:
    folder = str(store_folder)
    listed = exscec_here("query", "--list")
    assert listed.returncode == 0 and "segment_metric_of_scenario: Mean and variance" in listed.stdout
    as_json = exscec_here(
        "query",
        "segment_metric",
        "-p",
        f"metric={DIST}",
        "-p",
        f"start={A_}",
        "-p",
        f"goal={B_}",
        "-p",
        f"run={RUN_1}",
        "-p",
        f"run={RUN_2}",
        "-f",
        "json",
        "--store",
        folder,
    )
    assert as_json.returncode == 0, as_json.stderr
    answer = json.loads(as_json.stdout)
    assert answer["head"]["vars"] == ["count", "mean", "variance"]
    (row,) = answer["results"]["bindings"]
    assert row["count"] == {
        "type": "literal",
        "value": "2",
        "datatype": "http://www.w3.org/2001/XMLSchema#integer",
    }
    assert float(row["mean"]["value"]) == 11.0 and float(row["variance"]["value"]) == 1.0
    as_csv = exscec_here("runs", "s", "-f", "csv", "--store", folder)
    assert as_csv.returncode == 0, as_csv.stderr
    lines = as_csv.stdout.splitlines()  # (CRLF, read back as text)
    assert lines[0] == "run,scenario_id,start,end,bag,path,mission_status" and lines[1].startswith(
        f"{RUN_3},s,2024-05-01T09:00:00.000,"  # one precision (no zone: none made up)
    )
    table = exscec_here("query", "robots", "-p", "scenario=s", "--store", folder)
    assert table.stdout.splitlines() == [
        "robot  type   base  torso",
        "-----  -----  ----  -----",
        "r1     tiago  pmb2  true",
        "r2     pmb2   pmb2  false",
    ]


def test_exscec_sparql_reads_a_query_from_a_file(store_folder: Path, tmp_path: Path) -> None:
    query_file = tmp_path / "count.rq"
    query_file.write_text("SELECT (COUNT(*) AS ?n) WHERE { GRAPH ?g { ?run a exsce:run } }\n")
    answer = exscec_here("sparql", f"@{query_file}", "-f", "csv", "--store", str(store_folder))
    assert answer.returncode == 0, answer.stderr
    assert answer.stdout.splitlines() == ["n", "5"]  # four runs and the hand-written one


def test_csv_answers_end_lines_with_crlf_and_quote_as_rfc_4180() -> None:
    from pyoxigraph import Literal, NamedNode

    from exsce_dsl.api import results_csv
    from exsce_dsl.store.base import Rows

    rows = Rows(("a", "b"), ((Literal('say "hi", twice'), NamedNode("http://x/y")), (None, Literal("1"))))
    assert results_csv(rows) == 'a,b\r\n"say ""hi"", twice",http://x/y\r\n,1\r\n'


def test_exscec_query_reports_mistakes(store_folder: Path) -> None:
    missing = exscec_here("query", "run_metric", "-p", f"run={RUN_1}", "--store", str(store_folder))
    assert missing.returncode == 2 and "error: query 'run_metric' needs metric, robot" in missing.stderr
    unknown = exscec_here("query", "rnus", "--store", str(store_folder))
    assert unknown.returncode == 2 and "no query called 'rnus'; did you mean 'runs'?" in unknown.stderr
    malformed = exscec_here("query", "runs", "-p", "scenario", "--store", str(store_folder))
    assert malformed.returncode == 2 and "a parameter is NAME=VALUE" in malformed.stderr


# -- the same answers from a SPARQL 1.1 endpoint ------------------------------------------------------


def every_answer(store: Store) -> list[object]:
    """Each typed query once, on the data above."""
    every = [RUN_1, RUN_2, RUN_3, RUN_REV]
    return [
        q.runs(store, "s"),
        q.runs(store),
        q.run_metric(store, RUN_1, DIST, "r1"),
        q.mission_metric(store, RUN_2, "mission_duration"),
        q.segment_metric(store, DIST, A, B, runs=every),
        q.segment_metric(store, DIST, A, B, scenario="s"),
        q.waypoints_visited(store, "r1", every),
        q.mission_duration(store, every),
        sorted(q.metric_sources(store, RUN_1, DIST), key=repr),
        q.violation_durations(store, "s", "max_velocity"),
        q.violation_duration(store, "s", "max_velocity"),
        q.hotspot_counts(store, "s", "max_velocity"),
        q.robots(store, "s"),
        q.path_segments(store, "s"),
        q.lineage(store, "s_rev2"),
        sorted(q.oracles(store, "s"), key=repr),
        q.run_metric(store, ODD_RUN, "max_velocity", ODD_ROBOT),
    ]


def to_12_digits(answer: object) -> object:
    """``answer`` with every float to 12 significant digits: Virtuoso averages integers as
    decimals (2.666666666666667 where Oxigraph's double is 2.6666666666666665)."""
    if isinstance(answer, float):
        return float(f"{answer:.12g}")
    if dataclasses.is_dataclass(answer) and not isinstance(answer, type):
        return (type(answer), *[to_12_digits(getattr(answer, f.name)) for f in dataclasses.fields(answer)])
    if isinstance(answer, (list, tuple)):
        return [to_12_digits(a) for a in answer]
    if isinstance(answer, dict):
        return {k: to_12_digits(v) for k, v in answer.items()}
    return answer


@pytest.mark.parametrize("server_kind", ["oxigraph", "virtuoso"])
def test_a_sparql_endpoint_gives_the_same_answers(store: Store, tmp_path: Path, server_kind: str) -> None:
    expected = every_answer(store)
    started = oxigraph_server if server_kind == "oxigraph" else virtuoso_server
    with started(tmp_path / server_kind) as server:
        if server_kind == "oxigraph":
            remote = RemoteStore(f"{server.url}/query", update_url=f"{server.url}/update", timeout=20)
        else:
            remote = RemoteStore(f"{server.url}/sparql", timeout=20)
        populate(remote)
        if server_kind == "oxigraph":
            assert every_answer(remote) == expected
        else:
            assert to_12_digits(every_answer(remote)) == to_12_digits(expected)
        q.update_baseline(remote, "s", "task_duration", "r1", 55.0, 6.0)
        changed = {o.metric: o for o in q.oracles(remote, "s")}["task_duration"]
        assert (changed.value, changed.tolerance) == (55.0, 6.0)


def test_a_parameter_line_is_read_whole_and_an_unknown_kind_is_refused() -> None:
    from exsce_dsl.store.queries.library import _parse

    parsed = _parse(
        "x", "# About x.\n#\n# ?metric  metric_property  the metric\n# ?run run+ runs\nSELECT * {}", False
    )
    assert [(p.name, p.kind, p.many, p.description) for p in parsed.parameters] == [
        ("metric", "metric_property", False, "the metric"),
        ("run", "run", True, "runs"),
    ]
    with pytest.raises(ExsceError, match="unknown kind 'metrics'"):
        _parse("x", "# ?metric metrics the metric\nSELECT * {}", False)


def test_every_whole_run_value_of_some_runs(store: Store) -> None:
    found = {(r.run, r.metric, r.robot, r.value) for r in q.run_metric_values(store, [RUN_1])}
    assert found == {
        (RUN_1, DIST, "r1", 25.0),
        (RUN_1, DIST, "r2", 70.0),
        (RUN_1, "mission_duration", None, 90.0),
        (RUN_1, "waypoints_visited", "r1", 3.0),
        (RUN_1, "violation_duration", "r1", 1.0),
    }
    assert {r.run for r in q.run_metric_values(store, [RUN_1, RUN_REV])} == {
        RUN_1
    }  # run-rev has segment values only
