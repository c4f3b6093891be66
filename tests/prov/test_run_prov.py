"""Run PROV (compile_run), oracle PROV and derivation PROV: the contract with the method's
published run, hand-written expectations for what the method only shows in its report, the
SHACL shapes of run graphs, and the errors a run that does not fit its scenario raises."""

from __future__ import annotations

import datetime
from dataclasses import replace

import pytest
from prov.model import ProvDocument
from pyoxigraph import Literal, NamedNode, Quad

from exsce_dsl.errors import ExsceError
from exsce_dsl.lang import load_spec
from exsce_dsl.model import Position, Scenario
from exsce_dsl.model.derivation import Derivation, TransformationStep
from exsce_dsl.model.oracles import Oracle, OracleType
from exsce_dsl.model.runs import (
    Action,
    ActionId,
    ActionStatus,
    Bag,
    Hotspot,
    MetricScope,
    MetricValue,
    Run,
    TaskExecution,
)
from exsce_dsl.prov import identifiers as ids
from exsce_dsl.prov import serialize_prov
from exsce_dsl.prov.derivation import compile_derivation
from exsce_dsl.prov.oracle import compile_oracles
from exsce_dsl.prov.run import compile_run
from exsce_dsl.rdf import to_quads, validate

from tests.support.paths import EXAMPLES, FIXTURES
from tests.support.prov_contract import PROV, Record, Records, differences, normalised_published, records

RUN_FIXTURE = FIXTURES / "runs" / "2023-06-26T21-47-04_scenario_c_run-30af607a.prov.json"
UUID = "30af607a-145a-11ee-aa3d-0d574918902f"
BASE = ids.DEFAULT_NAMESPACE
RUN_NS = f"{BASE}runs/run_{UUID}/"
BAG = "2023-06-26T21-47-04_scenario_c_run-30af607a.bag"
RUNS_DIR = "/home/argen/projects/tiago/tiago_ws/src/metamorphic_testing/runs/"


@pytest.fixture(scope="module")
def scenario_c() -> Scenario:
    return load_spec(EXAMPLES / "brsu_building_c" / "scenario_c.exsce").scenario()


def fixture_run(scenario: Scenario, /, **changes: object) -> Run:
    """The published run 30af607a, written out from its run bundle: each robot does its two
    tasks, one action per waypoint, from its start pose on."""
    env = scenario.environment
    robots = {r.id: r for r in scenario.robots}

    def pose(pose_id: str, yaw: float | None = None) -> object:
        found = env.pose(pose_id)
        assert found is not None
        return found if yaw is None else found.with_orientation(replace(found.orientation, yaw=yaw))

    home = scenario.task("navigate_home_1")
    assert home is not None
    home_yaw = next(home.waypoints()).orientation.yaw
    plans = {
        "tiago1": [["classroom_c022-w001", "classroom_c018-w001"], ["classroom_c025-w001"]],
        "tiago2": [["classroom_c022-w002", "classroom_c018-w002"], ["classroom_c025-w002"]],
    }
    tasks = []
    last = {robot: robots[robot].start_pose for robot in plans}
    for allocation in (1, 2):
        for robot, task_poses in plans.items():
            actions = []
            for w, pose_id in enumerate(task_poses[allocation - 1], start=1):
                goal = pose(pose_id, home_yaw if allocation == 2 else None)
                actions.append(Action(ActionId(robot, allocation, 1, w), last[robot], goal))  # type: ignore[arg-type]
                last[robot] = goal  # type: ignore[assignment]
            tasks.append(TaskExecution(robot, allocation, tuple(actions)))
    run = Run(
        UUID,
        "scenario_c",
        datetime.datetime(2023, 6, 26, 21, 47, 9, 784105),
        datetime.datetime(2023, 6, 26, 21, 55, 23, 251216),
        Bag(BAG, path=RUNS_DIR + BAG),
        tuple(tasks),
        parameters=RUNS_DIR + "2023-06-26T21-47-04_scenario_c_run-30af607a.rosparams",
    )
    return replace(run, **changes)  # type: ignore[arg-type]


def through_json(document: ProvDocument) -> ProvDocument:
    return ProvDocument.deserialize(content=serialize_prov(document, "json"), format="json")


# -- the published run, record by record --------------------------------------------------

EXSCE_RUN = BASE + "run"
STATUS = BASE + "status"


def run_uses_its_scenario(found: Records, run_bundle: str) -> Records:
    """exsce's run activity also used the scenario's entity, which the method's queries
    (Listings 37-47) follow and its recorder did not write."""
    used = Record(
        "Usage",
        None,
        frozenset(
            {
                (PROV + "activity", ("iri", f"{BASE}runs/run_{UUID}")),
                (PROV + "entity", ("iri", BASE + "scenario_c")),
            }
        ),
    )
    return {**found, run_bundle: found[run_bundle] | {used}}


def goal_names_its_run(found: Records, run_bundle: str) -> Records:
    """The method's goal (wasEndedBy) carries exsce:runs; exsce writes exsce:run, as on
    every other record of a run."""

    def fix(r: Record) -> Record:
        return replace(
            r, attributes=frozenset(((EXSCE_RUN if n == BASE + "runs" else n), v) for n, v in r.attributes)
        )

    return {**found, run_bundle: frozenset(map(fix, found[run_bundle]))}


def actions_have_a_status(found: Records, run_bundle: str) -> Records:
    """exsce adds each action's final status (exsce:status), SUCCEEDED or ABORTED."""

    def add(r: Record) -> Record:
        if r.kind == "Activity" and (PROV + "type", ("iri", BASE + "action")) in r.attributes:
            return replace(r, attributes=r.attributes | {(STATUS, ("string", "SUCCEEDED"))})
        return r

    return {**found, run_bundle: frozenset(map(add, found[run_bundle]))}


RUN_DIFFERENCES = (run_uses_its_scenario, goal_names_its_run, actions_have_a_status)


def test_the_run_has_the_records_of_the_published_run(scenario_c: Scenario) -> None:
    ours = records(through_json(compile_run(fixture_run(scenario_c), scenario_c)))
    run_bundle = f"{BASE}runs/run_{UUID}_bundle"
    bag_bundle = f"{RUN_NS}bag_bundle"
    published = normalised_published(RUN_FIXTURE, scenario_c)
    # the bag's bundle is named by its run (the method named it by the bag's file: exsce:<file>_bundle,
    # which two recordings with one file name share); its records are the published ones
    theirs = {run_bundle: published[run_bundle], bag_bundle: published[f"{BASE}{BAG}_bundle"]}
    for normalise in RUN_DIFFERENCES:
        theirs = normalise(theirs, run_bundle)
    assert differences(ours, theirs) == []
    assert len(ours[run_bundle]) == len(published[run_bundle]) + 1  # the scenario's usage


def test_an_action_written_out_by_hand(scenario_c: Scenario) -> None:
    document = compile_run(fixture_run(scenario_c), scenario_c)
    (bundle,) = [b for b in document.bundles if b.identifier and b.identifier.localpart.startswith("run_")]
    action = "run_30af607a:tiago1-task_01-subtask_001-w_002"
    lines = {r.get_provn() for r in bundle.get_records() if action in r.get_provn().split(",")[0]}
    assert lines == {
        f"activity({action}, -, -, [prov:type='exsce:action', exsce:run=\"{UUID}\", exsce:status=\"SUCCEEDED\"])",
        f"wasEndedBy({action}, pose:classroom_c018-w001-R0.00_P0.00_Y-0.641, -, -, "
        f'[prov:role="goal", exsce:run="{UUID}"])',
        f"wasStartedBy({action}, pose:classroom_c022-w001-R0.00_P0.00_Y2.269, -, -)",
        f"wasAssociatedWith({action}, tiago1:agent, -)",
        f"wasInformedBy({action}, run_30af607a:tiago1-task_01-subtask_001-w_001)",
    }


# -- bag, metrics and hotspots: the report's Listings 13 and 15, by hand ------------------

T1_DISTANCE = "/tiago1/distance_travelled"
T1_NAV_VEL = "/tiago1/nav_vel"
SEGMENT_1 = ActionId("tiago1", 1, 1, 1)
SEGMENT_2 = ActionId("tiago1", 1, 1, 2)


def run_with_metrics(scenario: Scenario) -> Run:
    return fixture_run(
        scenario,
        bag=Bag(BAG, (T1_DISTANCE, T1_NAV_VEL)),
        metrics=(
            MetricValue("distance_travelled", MetricScope.ROBOT, 49.5234, (T1_DISTANCE,), robot="tiago1", unit="m"),
            MetricValue("distance_travelled", MetricScope.SEGMENT, 10.2956, (T1_DISTANCE,), action=SEGMENT_1),
            MetricValue("distance_travelled", MetricScope.SEGMENT, 19.5078, (T1_DISTANCE,), action=SEGMENT_2),
            MetricValue("mission_duration", MetricScope.MISSION, 97.606, ()),
            MetricValue(
                "violation_duration", MetricScope.ROBOT, 1.5, (T1_NAV_VEL,), robot="tiago1", safety_metric="max_velocity"
            ),
        ),
        hotspots=(Hotspot("max_velocity", Position(44.5, 37.25), 3, 1.5, robot="tiago1"),),
    )


def bundle_lines(document: ProvDocument, local: str) -> set[str]:
    (bundle,) = [b for b in document.bundles if b.identifier and b.identifier.localpart == local]
    return {r.get_provn() for r in bundle.get_records()}


def test_the_bag_bundle_holds_the_bag_and_its_topics(scenario_c: Scenario) -> None:
    document = compile_run(run_with_metrics(scenario_c), scenario_c)
    bag = f"run_30af607a:{BAG}"
    assert bundle_lines(document, "bag_bundle") == {
        f"entity({bag}, [prov:type='ros:Bags'])",
        "entity(topic:tiago1/distance_travelled, [prov:type='ros:Topics'])",
        "entity(topic:tiago1/nav_vel, [prov:type='ros:Topics'])",
        f"hadMember({bag}, topic:tiago1/distance_travelled)",
        f"hadMember({bag}, topic:tiago1/nav_vel)",
    }


def test_a_metric_bundle_written_out_by_hand(scenario_c: Scenario) -> None:
    document = compile_run(run_with_metrics(scenario_c), scenario_c)
    run = f"run:run_{UUID}"
    topics = "run_30af607a:tiago1-distance_travelled-topics"
    common = f"prov:type='exsce:output_metric', run:metricType=\"distance_travelled\", exsce:run=\"{UUID}\""
    w1 = "run_30af607a:tiago1-task_01-subtask_001-w_001"
    w2 = "run_30af607a:tiago1-task_01-subtask_001-w_002"
    assert bundle_lines(document, "distance_travelled_bundle") == {
        f"entity({topics}, [prov:type='exsce:topic'])",
        f"hadMember({topics}, topic:tiago1/distance_travelled)",
        f'entity(run_30af607a:tiago1-distance_travelled, [{common}, prov:value="49.5234" %% xsd:double, '
        'exsce:robot="tiago1", exsce:unit="m"])',
        f"wasDerivedFrom(run_30af607a:tiago1-distance_travelled, {topics}, -, -, -, [prov:type='prov:PrimarySource'])",
        f"wasGeneratedBy(run_30af607a:tiago1-distance_travelled, {run}, -)",
        f'entity({w1}-distance_travelled, [{common}, prov:value="10.2956" %% xsd:double, exsce:robot="tiago1"])',
        f"wasDerivedFrom({w1}-distance_travelled, {topics}, -, -, -, [prov:type='prov:PrimarySource'])",
        f"wasGeneratedBy({w1}-distance_travelled, {w1}, -)",
        f'entity({w2}-distance_travelled, [{common}, prov:value="19.5078" %% xsd:double, exsce:robot="tiago1"])',
        f"wasDerivedFrom({w2}-distance_travelled, {topics}, -, -, -, [prov:type='prov:PrimarySource'])",
        f"wasGeneratedBy({w2}-distance_travelled, {w2}, -)",
    }
    assert bundle_lines(document, "mission_duration_bundle") == {
        "entity(run_30af607a:mission_duration, [prov:type='exsce:output_metric', "
        f'run:metricType="mission_duration", exsce:run="{UUID}", prov:value="97.606" %% xsd:double])',
        f"wasGeneratedBy(run_30af607a:mission_duration, {run}, -)",
    }
    violation = bundle_lines(document, "violation_duration_bundle")
    assert (
        "entity(run_30af607a:tiago1-violation_duration-max_velocity, [prov:type='exsce:output_metric', "
        f'run:metricType="violation_duration", exsce:run="{UUID}", prov:value="1.5" %% xsd:double, '
        'exsce:robot="tiago1", exsce:metric="max_velocity"])'
    ) in violation


def test_hotspots_written_out_by_hand(scenario_c: Scenario) -> None:
    document = compile_run(run_with_metrics(scenario_c), scenario_c)
    hotspot = "run_30af607a:tiago1-max_velocity-hotspot_001"
    assert bundle_lines(document, "hotspots_bundle") == {
        f"entity({hotspot}, [prov:type='exsce:hotspot', hotspot:type=\"max_velocity\", exsce:run=\"{UUID}\", "
        'coord:x="44.5" %% xsd:double, coord:y="37.25" %% xsd:double, coord:z="0.0" %% xsd:double, '
        'exsce:violations=3, exsce:duration="1.5" %% xsd:double, exsce:robot="tiago1"])',
        f"wasGeneratedBy({hotspot}, run:run_{UUID}, -)",
    }


def test_action_times_and_status_are_written(scenario_c: Scenario) -> None:
    run = fixture_run(scenario_c)
    first = run.tasks[0]
    start, end = datetime.datetime(2023, 6, 26, 21, 47, 10), datetime.datetime(2023, 6, 26, 21, 48, 0)
    action = replace(first.actions[0], start=start, end=end, status=ActionStatus.ABORTED)
    run = replace(run, tasks=(replace(first, actions=(action, *first.actions[1:])), *run.tasks[1:]))
    lines = {r.get_provn() for b in compile_run(run, scenario_c).bundles for r in b.get_records()}
    assert (
        "activity(run_30af607a:tiago1-task_01-subtask_001-w_001, 2023-06-26T21:47:10, 2023-06-26T21:48:00, "
        f"[prov:type='exsce:action', exsce:run=\"{UUID}\", exsce:status=\"ABORTED\"])"
    ) in lines


def test_compiling_is_deterministic_and_the_fast_path_is_provs(scenario_c: Scenario) -> None:
    run = run_with_metrics(scenario_c)
    first = serialize_prov(compile_run(run, scenario_c), "json")
    assert serialize_prov(compile_run(run, scenario_c), "json") == first
    assert compile_run(run, scenario_c).get_provn() == compile_run(run, scenario_c, checked=True).get_provn()


# -- what does not fit ---------------------------------------------------------------------


def test_metric_values_say_what_they_cover() -> None:
    with pytest.raises(ExsceError, match="names no action"):
        MetricValue("task_duration", MetricScope.SEGMENT, 1.0)
    with pytest.raises(ExsceError, match="names no robot"):
        MetricValue("task_duration", MetricScope.ROBOT, 1.0)
    with pytest.raises(ExsceError, match="cannot be for robot"):
        MetricValue("mission_duration", MetricScope.MISSION, 1.0, robot="tiago1")
    with pytest.raises(ExsceError, match="cannot name an action"):
        MetricValue("task_duration", MetricScope.ROBOT, 1.0, robot="tiago1", action=SEGMENT_1)
    assert MetricValue("task_duration", MetricScope.SEGMENT, 1.0, action=SEGMENT_1).robot == "tiago1"


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"scenario": "scenario_d"}, "is a run of 'scenario_d', not of 'scenario_c'"),
        ({"uuid": "a b"}, "run uuid 'a b' cannot be part of an identifier"),
        ({"tasks": (TaskExecution("tiago9", 1, ()),)}, "robot 'tiago9', which is not in scenario 'scenario_c'"),
        ({"tasks": (TaskExecution("tiago1", 3, ()),)}, "allocates it 2 task"),
        (
            {"metrics": (MetricValue("max_velocity", MetricScope.ROBOT, 1.0, (T1_NAV_VEL,), robot="tiago1"),)},
            "comes from topic '/tiago1/nav_vel', which bag .* does not hold",
        ),
        (
            {"metrics": (MetricValue("max_velocity", MetricScope.SEGMENT, 1.0, action=ActionId("tiago1", 1, 1, 9)),)},
            "tiago1-task_01-subtask_001-w_009, which run .* does not have",
        ),
        (
            {"metrics": (MetricValue("m", MetricScope.MISSION, 1.0), MetricValue("m", MetricScope.MISSION, 2.0))},
            "the value of 'm' of the mission twice",
        ),
    ],
)
def test_a_run_that_does_not_fit_its_scenario_is_refused(
    scenario_c: Scenario, change: dict[str, object], message: str
) -> None:
    with pytest.raises(ExsceError, match=message):
        compile_run(fixture_run(scenario_c, **change), scenario_c)


def test_values_of_one_metric_and_robot_come_from_the_same_topics(scenario_c: Scenario) -> None:
    run = fixture_run(
        scenario_c,
        bag=Bag(BAG, (T1_DISTANCE, T1_NAV_VEL)),
        metrics=(
            MetricValue("distance_travelled", MetricScope.ROBOT, 1.0, (T1_DISTANCE,), robot="tiago1"),
            MetricValue("distance_travelled", MetricScope.SEGMENT, 1.0, (T1_NAV_VEL,), action=SEGMENT_1),
        ),
    )
    with pytest.raises(ExsceError, match="come from different topics"):
        compile_run(run, scenario_c)


# -- SHACL -----------------------------------------------------------------------------------


def test_compiled_runs_conform_to_the_run_shapes(scenario_c: Scenario) -> None:
    assert validate(to_quads(compile_run(run_with_metrics(scenario_c), scenario_c)), ["runs"]) == []


def test_a_run_with_its_segment_index_conforms_and_a_segment_without_poses_does_not(
    scenario_c: Scenario,
) -> None:
    from exsce_dsl.store.writing import stored_graphs

    graphs = stored_graphs(compile_run(run_with_metrics(scenario_c), scenario_c))
    quads = [quad for graph in graphs.values() for quad in graph]
    assert any(q.predicate.value.endswith("/startPose") for q in quads)
    assert validate(quads, ["runs"]) == []
    broken = [q for q in quads if not q.predicate.value.endswith("/startPose")]
    assert {v.message for v in validate(broken, ["runs"])} == {
        "a path segment starts at exactly one pose (exsce:startPose)"
    }


def test_the_run_shapes_catch_a_broken_metric(scenario_c: Scenario) -> None:
    quads = to_quads(compile_run(run_with_metrics(scenario_c), scenario_c))
    value = NamedNode(PROV + "value")
    metric = NamedNode(RUN_NS + "tiago1-distance_travelled")
    broken = [q for q in quads if not (q.subject == metric and q.predicate == value)]
    graph = next(q.graph_name for q in quads if q.subject == metric)
    broken.append(Quad(metric, NamedNode(BASE + "robot"), Literal("tiago2"), graph))
    violations = validate(broken, ["runs"])
    assert {(v.focus, v.path) for v in violations} == {
        (metric.value, PROV + "value"),
        (metric.value, BASE + "robot"),
    }


def test_the_run_shapes_catch_an_action_without_its_goal(scenario_c: Scenario) -> None:
    quads = to_quads(compile_run(fixture_run(scenario_c), scenario_c))
    action = NamedNode(RUN_NS + "tiago2-task_02-subtask_001-w_001")
    broken = [q for q in quads if not (q.subject == action and q.predicate.value == PROV + "wasEndedBy")]
    violations = validate(broken, ["runs"])
    assert [(v.focus, v.path) for v in violations] == [(action.value, PROV + "wasEndedBy")]


# -- oracles and derivations -------------------------------------------------------------------

BASELINE, METAMORPHIC = OracleType.BASELINE, OracleType.METAMORPHIC
FEEDBACK = ("/tiago1/waypoint_dispatcher/feedback", "/tiago2/waypoint_dispatcher/feedback")


def test_oracles_written_out_by_hand() -> None:
    oracles = [
        Oracle("mission_duration", None, "invariant", BASELINE, "scenario_x", FEEDBACK, value=141.195, tolerance=0.0),
        Oracle(
            "mission_duration", None, "increasing", METAMORPHIC, "scenario_c", FEEDBACK,
            value=141.195, delta=43.5891, tolerance=0.0, package="exsce.metamorphic.relationships",
        ),
        Oracle("max_velocity", "tiago1", "below_max", BASELINE, "scenario_x", (T1_NAV_VEL,), limit=1.0),
    ]
    document = compile_oracles("scenario_x", oracles)
    assert bundle_lines(document, "scenario_x_bundle") == {
        "activity(scenario_x:mission_duration, -, -, [prov:type='exsce:oracle', "
        'oracle:metric="mission_duration", exsce:scenario="scenario_x"])',
        "entity(topic:tiago1/waypoint_dispatcher/feedback, [prov:type='ros:Topics'])",
        "entity(topic:tiago2/waypoint_dispatcher/feedback, [prov:type='ros:Topics'])",
        'used(scenario_x:mission_duration, topic:tiago1/waypoint_dispatcher/feedback, -, [prov:role="topic"])',
        'used(scenario_x:mission_duration, topic:tiago2/waypoint_dispatcher/feedback, -, [prov:role="topic"])',
        "used(scenario_x:mission_duration-baseline; scenario_x:mission_duration, exsce:scenario_x, -, "
        '[oracle:relationship="invariant", oracle:type="baseline", oracle:value="141.195" %% xsd:double, '
        'oracle:tolerance="0.0" %% xsd:double])',
        "used(scenario_x:mission_duration-metamorphic; scenario_x:mission_duration, exsce:scenario_c, -, "
        '[oracle:relationship="increasing", oracle:type="metamorphic", oracle:value="141.195" %% xsd:double, '
        'oracle:delta="43.5891" %% xsd:double, oracle:tolerance="0.0" %% xsd:double, '
        'oracle:package="exsce.metamorphic.relationships"])',
        "activity(scenario_x:tiago1-max_velocity, -, -, [prov:type='exsce:oracle', "
        'oracle:metric="max_velocity", exsce:scenario="scenario_x", oracle:robot="tiago1"])',
        "entity(topic:tiago1/nav_vel, [prov:type='ros:Topics'])",
        'used(scenario_x:tiago1-max_velocity, topic:tiago1/nav_vel, -, [prov:role="topic"])',
        "used(scenario_x:tiago1-max_velocity-baseline; scenario_x:tiago1-max_velocity, exsce:scenario_x, -, "
        '[oracle:relationship="below_max", oracle:type="baseline", oracle:limit="1.0" %% xsd:double])',
    }
    assert document.get_provn() == compile_oracles("scenario_x", oracles, checked=True).get_provn()
    with pytest.raises(ExsceError, match="twice"):
        compile_oracles("scenario_x", [oracles[0], oracles[0]])


def test_a_derivation_written_out_by_hand() -> None:
    derivation = Derivation(
        "scenario_x",
        "scenario_c",
        (
            TransformationStep("remove_robot", (("robot", "tiago2"),)),
            TransformationStep("swap_assignment", (("robot", "tiago2"), ("to", "tiago1"))),
            TransformationStep("remove_start_pose", (("robot", "tiago2"),)),
        ),
    )
    document = compile_derivation(derivation)
    s1, s2, s3 = (
        "scenario_x:step_01-remove_robot",
        "scenario_x:step_02-swap_assignment",
        "scenario_x:step_03-remove_start_pose",
    )
    assert bundle_lines(document, "scenario_generation") == {
        "activity(scenario_x:generation, -, -, [prov:type='exsce:generation'])",
        "wasGeneratedBy(exsce:scenario_x, scenario_x:generation, -)",
        "used(scenario_x:generation, exsce:scenario_c, -)",
        "wasDerivedFrom(exsce:scenario_x, exsce:scenario_c, scenario_x:generation, -, -)",
        f"activity({s1}, -, -, [prov:type='exsce:transform', exsce:transform=\"remove_robot\", exsce:step=1, "
        'exsce:robot="tiago2"])',
        f"wasStartedBy(scenario_x:generation, -, {s1}, -)",
        f"activity({s2}, -, -, [prov:type='exsce:transform', exsce:transform=\"swap_assignment\", exsce:step=2, "
        'exsce:robot="tiago2", exsce:to="tiago1"])',
        f"wasInformedBy({s2}, {s1})",
        f"activity({s3}, -, -, [prov:type='exsce:transform', exsce:transform=\"remove_start_pose\", exsce:step=3, "
        'exsce:robot="tiago2"])',
        f"wasInformedBy({s3}, {s2})",
        f"wasEndedBy(scenario_x:generation, -, {s3}, -)",
    }
    assert document.get_provn() == compile_derivation(derivation, checked=True).get_provn()
    with pytest.raises(ExsceError, match="'step' cannot name an argument"):
        compile_derivation(Derivation("x", "y", (TransformationStep("t", (("step", 1),)),)))
