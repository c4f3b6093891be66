"""Compiling scenarios to PROV: the contract with the method's published models,
identifiers, and PROV-N/JSON/XML (the RDF mapping is tested in test_rdf.py)."""

from __future__ import annotations

import importlib.util
import json
import math
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st
from prov.model import ProvDocument
from rdflib import Namespace, URIRef

from exsce_dsl.errors import ExsceError
from exsce_dsl.lang import import_scenario_yaml
from exsce_dsl.model import (
    Area,
    Assignment,
    Environment,
    Mission,
    MissionType,
    Obstacle,
    Orientation,
    Pose,
    Position,
    Robot,
    RobotType,
    Scenario,
    Subtask,
    Task,
)
from exsce_dsl.prov import compile_scenario, serialize_prov
from exsce_dsl.prov.compile import _ScenarioCompiler
from exsce_dsl.prov.identifiers import (
    DEFAULT_NAMESPACE,
    Namespaces,
    PrefixTable,
    format_angle,
    is_valid_prefix,
    orientation_name,
    pose_name,
)
from exsce_dsl.rdf import FORMATS, serialize

from tests.support.prov_contract import differences, normalised_published, records
from tests.support.scenario_builders import (
    C022_W001,
    C025_W001,
    large_scenario,
    merged,
    scenario_c,
)

MODELS = Path(__file__).parents[1] / "fixtures" / "hbrs-sesame-models"
SCENARIOS = MODELS / "scenarios"

HAS_LXML = importlib.util.find_spec("lxml") is not None

EXSCE = Namespace(DEFAULT_NAMESPACE)
PROV = Namespace("http://www.w3.org/ns/prov#")
TASK = Namespace(DEFAULT_NAMESPACE + "tasks/")
POSE = Namespace(DEFAULT_NAMESPACE + "tasks/waypoints/")
POINT = Namespace(DEFAULT_NAMESPACE + "tasks/points/")
ENV = Namespace(DEFAULT_NAMESPACE + "environments/")
ROBOT = Namespace(DEFAULT_NAMESPACE + "robots/")
MISSION_C = Namespace(DEFAULT_NAMESPACE + "missions/mission_c/")
COORD = Namespace("https://robot-schema.org/coordinates/")
XSD_DOUBLE = URIRef("http://www.w3.org/2001/XMLSchema#double")
XSD_DATETIME = URIRef("http://www.w3.org/2001/XMLSchema#dateTime")


def through_json(document: ProvDocument) -> ProvDocument:
    return ProvDocument.deserialize(content=serialize_prov(document, "json"), format="json")


# -- the contract with the published models ------------------------------------


def test_scenario_c_has_the_records_of_the_published_model() -> None:
    scenario = scenario_c()
    ours = records(through_json(compile_scenario(scenario)))
    theirs = normalised_published(SCENARIOS / "scenario_c.prov.json", scenario)
    assert differences(ours, theirs) == []
    assert len(ours) == 11  # scenario, environment, 3 areas, 2 robots, 4 tasks


def test_the_published_scenario_bundle_alone_agrees_too() -> None:
    scenario = scenario_c()
    ours = records(through_json(compile_scenario(scenario)))
    theirs = normalised_published(SCENARIOS / "scenario_c_bundle.prov.json", scenario)
    (bundle,) = theirs
    assert differences({bundle: ours[bundle]}, theirs) == []


def bundle_provn(document: ProvDocument, bundle_iri: str) -> set[str]:
    bundles = [b for b in document.bundles if b.identifier and b.identifier.uri == str(bundle_iri)]
    (bundle,) = bundles
    return {r.get_provn() for r in bundle.get_records()}


def test_a_task_bundle_written_out_by_hand() -> None:
    document = compile_scenario(scenario_c())
    assert bundle_provn(document, TASK["delivery_a_bundle"]) == {
        "entity(task:delivery_a, [prov:type='prov:Plan', ros:pkg=\"metamorphic_testing\", "
        'ros:relative_path="config/tasks/delivery_a.yaml"])',
        "entity(task:delivery_a-subtask_001, [prov:type='prov:Plan'])",
        'wasDerivedFrom(task:delivery_a, task:delivery_a-subtask_001, -, -, -, [prov:role="subtask_001"])',
        "wasDerivedFrom(delivery_a-subtask_001:w_001; task:delivery_a-subtask_001, "
        'pose:classroom_c022-w001-R0.00_P0.00_Y2.269, -, -, -, [prov:role="waypoint"])',
        "wasDerivedFrom(delivery_a-subtask_001:w_002; task:delivery_a-subtask_001, "
        'pose:classroom_c018-w001-R0.00_P0.00_Y-0.641, -, -, -, [prov:role="waypoint"])',
    }


def test_a_robot_bundle_written_out_by_hand() -> None:
    document = compile_scenario(scenario_c())
    assert bundle_provn(document, ROBOT["tiago1_bundle"]) == {
        "entity(robot:tiago1, [prov:type='exsce:robot', exsce:robotType=\"tiago\"])",
        'entity(tiago1:software-config, [prov:type="software-config", ros:namespace="tiago1"])',
        'entity(tiago1:hardware-config, [prov:type="hardware-config", exsce:baseType="pmb2", '
        'exsce:torso="true" %% xsd:boolean])',
        "entity(tiago1:gazebo_model, [prov:type='ros:GazeboModel'])",
        "agent(tiago1:agent, [prov:type='prov:SoftwareAgent'])",
        "hadMember(robot:tiago1, tiago1:gazebo_model)",
        "hadMember(robot:tiago1, tiago1:software-config)",
        "hadMember(robot:tiago1, tiago1:hardware-config)",
    }


def test_an_area_bundle_holds_each_variant_of_its_poses_and_shares_points() -> None:
    document = compile_scenario(scenario_c())
    lines = bundle_provn(document, ENV["classroom_c025_bundle"])
    entities = sorted(line.split(",")[0] for line in lines if line.startswith("entity"))
    assert entities == [
        "entity(orientation:R0.00_P0.00_Y0.00",
        "entity(orientation:R0.00_P0.00_Y0.925",
        "entity(point:classroom_c025-w001",
        "entity(point:classroom_c025-w002",
        "entity(pose:classroom_c025-w001-R0.00_P0.00_Y0.00",
        "entity(pose:classroom_c025-w001-R0.00_P0.00_Y0.925",
        "entity(pose:classroom_c025-w002-R0.00_P0.00_Y0.00",
        "entity(pose:classroom_c025-w002-R0.00_P0.00_Y0.925",
    ]
    assert sum(line.startswith("hadMember") for line in lines) == 8


@pytest.mark.parametrize("name", ["scenario_c", "scenario_d", "scenario_e"])
def test_imported_yaml_scenarios_have_the_records_of_the_published_models(name: str) -> None:
    documents = import_scenario_yaml(SCENARIOS / f"{name}.yaml", [MODELS])
    (scenario,) = documents[0].declarations
    assert isinstance(scenario, Scenario)
    ours = records(through_json(compile_scenario(scenario)))
    theirs = normalised_published(SCENARIOS / f"{name}.prov.json", scenario)
    assert differences(ours, theirs) == []


def test_the_hand_written_ir_compiles_like_the_imported_one() -> None:
    documents = import_scenario_yaml(SCENARIOS / "scenario_c.yaml", [MODELS])
    (imported,) = documents[0].declarations
    assert isinstance(imported, Scenario)
    assert serialize_prov(compile_scenario(imported), "provn") == serialize_prov(
        compile_scenario(scenario_c()), "provn"
    )


# -- identifiers ---------------------------------------------------------------


@pytest.mark.parametrize(
    ("angle", "text"),
    [
        (0.0, "0.00"),
        (-0.0, "0.00"),
        (1.5, "1.50"),
        (2.27, "2.27"),
        (-0.64, "-0.64"),
        (3, "3.00"),
        (0.925, "0.925"),
        (2.269, "2.269"),
        (-0.641, "-0.641"),
        (0.005, "0.005"),
        (math.pi, "3.141592653589793"),
    ],
)
def test_angles_in_ids_have_two_decimals_only_where_that_is_exact(angle: float, text: str) -> None:
    assert format_angle(angle) == text


@given(st.floats(allow_nan=False, allow_infinity=False))
def test_an_angle_in_an_id_reads_back_as_the_same_number(angle: float) -> None:
    assert float(format_angle(angle)) == angle


def test_pose_ids_match_the_method_where_its_rounding_was_exact() -> None:
    assert pose_name(C025_W001) == "classroom_c025-w001-R0.00_P0.00_Y0.00"
    assert pose_name(C022_W001.with_orientation(Orientation(0.0, 0.0, 2.27))) == (
        "classroom_c022-w001-R0.00_P0.00_Y2.27"
    )
    assert orientation_name(Orientation(0.1, -0.25, 1.0)) == "R0.10_P-0.25_Y1.00"


def test_poses_the_method_merged_get_different_ids() -> None:
    # The method writes both as ...-Y2.27: one id for two poses.
    a = C022_W001.with_orientation(Orientation(0.0, 0.0, 2.269))
    b = C022_W001.with_orientation(Orientation(0.0, 0.0, 2.271))
    assert pose_name(a) == "classroom_c022-w001-R0.00_P0.00_Y2.269"
    assert pose_name(b) == "classroom_c022-w001-R0.00_P0.00_Y2.271"


def test_task_ids_are_the_dsl_ids() -> None:
    document = compile_scenario(scenario_c())
    text = serialize_prov(document, "provn")
    assert "task:delivery_a," in text
    assert ".yaml-subtask" not in text and "task:delivery_a.yaml" not in text


def prefix_of(document: ProvDocument, iri: str) -> set[str]:
    """The prefix names ``iri`` has in the document and its bundles."""
    found = set()
    for container in [document, *document.bundles]:
        for namespace in container.get_registered_namespaces():
            if namespace.uri == iri:
                found.add(namespace.prefix)
    return found


def renamed(scenario: Scenario, robot_ids: dict[str, str], scenario_id: str) -> Scenario:
    """``scenario`` with its robots renamed, each in the namespace of its new id (as the method's are)."""
    robots = tuple(Robot(robot_ids[r.id], r.type, robot_ids[r.id], r.start_pose) for r in scenario.robots)
    allocation = tuple(Assignment(robot_ids[a.robot], a.task) for a in scenario.mission.allocation)
    mission = Mission(scenario.mission.id, scenario.mission.type, allocation)
    return Scenario(scenario_id, scenario.environment, robots, mission, scenario.tasks)


def test_ids_that_collide_with_fixed_prefixes_get_other_prefix_names() -> None:
    scenario = renamed(scenario_c(), {"tiago1": "pose", "tiago2": "task"}, "scenario_c")
    document = compile_scenario(scenario)
    robots = DEFAULT_NAMESPACE + "robots/"
    assert prefix_of(document, robots + "pose/") == {"pose_robot"}
    assert prefix_of(document, robots + "task/") == {"task_robot"}
    assert prefix_of(document, DEFAULT_NAMESPACE + "tasks/waypoints/") == {"pose"}
    assert prefix_of(document, DEFAULT_NAMESPACE + "tasks/") == {"task"}
    # The IRIs are the robots' own, whatever the prefix names.
    graph = merged(document)
    model = URIRef(robots + "pose/gazebo_model")
    start = POSE["classroom_c025-w001-R0.00_P0.00_Y0.00"]
    assert (model, PROV.wasDerivedFrom, start) in graph
    assert (ROBOT["pose"], PROV.hadMember, model) in graph
    # Every format still reads back.
    for fmt in FORMATS:
        if fmt != "xml" or HAS_LXML:
            assert serialize(document, fmt)
    assert through_json(document) == document


def test_a_scenario_and_a_robot_with_one_id_get_two_prefix_names() -> None:
    scenario = renamed(scenario_c(), {"tiago1": "demo", "tiago2": "tiago2"}, "demo")
    document = compile_scenario(scenario)
    assert prefix_of(document, DEFAULT_NAMESPACE + "demo/") == {"demo"}
    assert prefix_of(document, DEFAULT_NAMESPACE + "robots/demo/") == {"demo_robot"}
    assert through_json(document) == document


def test_the_prefix_table() -> None:
    table = PrefixTable(Namespaces())
    assert table.prefix("tiago1", "https://x/tiago1/", "robot") == "tiago1"
    assert table.prefix("tiago1", "https://x/tiago1/", "robot") == "tiago1"
    assert table.prefix("tiago1", "https://y/tiago1/", "scenario") == "tiago1_scenario"
    assert table.prefix("geom", "https://x/geom/", "robot") == "geom_robot"
    assert table.prefix("prov", "https://x/prov/", "robot") == "prov_robot"
    assert table.prefix("_r1", "https://x/_r1/", "robot") == "robot__r1"
    assert table.prefix("xmlbot", "https://x/xmlbot/", "robot") == "robot_xmlbot"
    assert table.prefix("geom", "https://z/geom/", "robot") == "geom_robot2"
    assert not is_valid_prefix("a.") and not is_valid_prefix("_a") and is_valid_prefix("a-b.c")


def test_the_base_namespace_is_configurable() -> None:
    base = "https://example.org/lab/"
    document = compile_scenario(scenario_c(), namespace=base)
    ours = records(through_json(document))
    assert base + "scenario_c_bundle" in ours
    assert base + "tasks/waypoints/classroom_c025-w001-R0.00_P0.00_Y0.00" in serialize(document, "nq")
    assert "sesame-project" not in serialize(document, "nq")
    theirs = normalised_published(SCENARIOS / "scenario_c.prov.json", scenario_c())
    assert len(ours) == len(theirs)


@pytest.mark.parametrize("base", ["", "sesame", "https://example.org/lab", "https://a b/"])
def test_a_base_namespace_must_be_an_iri_ending_in_a_separator(base: str) -> None:
    with pytest.raises(ExsceError, match="namespace"):
        compile_scenario(scenario_c(), namespace=base)


# -- other shapes ------------------------------------------------------------


def small_scenario(**changes: object) -> Scenario:
    room = Area("lab", (Pose("lab-a", Position(1.0, 2.0), area="lab"),))
    environment = Environment("building", areas=(room,))
    loose = Pose("t1-w1", Position(3.0, 4.0), Orientation(yaw=1.5))
    t1 = Task("t1", (Subtask((room.poses[0], loose)),))
    robot = Robot("r1", RobotType("pmb2"), "r1", start_pose=Pose("start", Position(0.5, 0.5)))
    mission = Mission("m", MissionType.SEQUENTIAL, (Assignment("r1", "t1"),))
    fields: dict[str, object] = dict(
        id="small", environment=environment, robots=(robot,), mission=mission, tasks=(t1,)
    )
    fields.update(changes)
    return Scenario(**fields)  # type: ignore[arg-type]


def test_coordinate_waypoints_go_in_their_task_bundle() -> None:
    document = compile_scenario(small_scenario())
    lines = bundle_provn(document, TASK["t1_bundle"])
    assert "entity(pose:t1-w1-R0.00_P0.00_Y1.50, [prov:type='geom:Pose'])" in lines
    assert "hadMember(pose:t1-w1-R0.00_P0.00_Y1.50, point:t1-w1)" in lines
    assert not any("lab-a" in line and line.startswith("entity") for line in lines)
    assert "entity(pose:lab-a-R0.00_P0.00_Y0.00, [prov:type='geom:Pose'])" in bundle_provn(
        document, ENV["lab_bundle"]
    )


def test_a_start_pose_without_area_goes_in_the_scenario_bundle() -> None:
    document = compile_scenario(small_scenario())
    lines = bundle_provn(document, EXSCE["small_bundle"])
    assert "entity(pose:start-R0.00_P0.00_Y0.00, [prov:type='geom:Pose'])" in lines
    hardware = bundle_provn(document, ROBOT["r1_bundle"])
    assert 'entity(r1:hardware-config, [prov:type="hardware-config"])' in hardware


def test_a_sequential_mission_and_a_task_without_source() -> None:
    document = compile_scenario(small_scenario())
    scenario = bundle_provn(document, EXSCE["small_bundle"])
    assert "entity(mission:m, [prov:type='exsce:mission', exsce:missionType=\"sequential\"])" in (scenario)
    assert "entity(task:t1, [prov:type='prov:Plan'])" in bundle_provn(document, TASK["t1_bundle"])


def test_obstacles_are_members_of_the_environment_derived_from_their_pose() -> None:
    box = Obstacle("box1", Pose("box1", Position(1.0, 1.0), Orientation(yaw=0.3)), "box", (0.5, 0.5, 1.0))
    base = small_scenario()
    environment = Environment("building", areas=base.environment.areas, obstacles=(box,))
    document = compile_scenario(small_scenario(environment=environment))
    lines = bundle_provn(document, ENV["building_bundle"])
    assert (
        'entity(building:box1, [prov:type=\'exsce:obstacle\', exsce:model="box", exsce:size="0.5 0.5 1.0"])'
    ) in lines
    assert "hadMember(env:building, building:box1)" in lines
    assert (
        "wasDerivedFrom(building:box1-pose; building:box1, pose:box1-R0.00_P0.00_Y0.30, "
        '-, -, -, [prov:role="obstacle_pose"])'
    ) in lines
    assert "entity(pose:box1-R0.00_P0.00_Y0.30, [prov:type='geom:Pose'])" in lines


def test_an_area_named_like_its_environment_is_refused() -> None:
    room = Area("building", (Pose("building-a", Position(1.0, 2.0), area="building"),))
    environment = Environment("building", areas=(room,))
    with pytest.raises(ExsceError, match="env:building_bundle"):
        compile_scenario(small_scenario(environment=environment))


def test_one_pose_id_at_two_positions_is_refused() -> None:
    base = small_scenario()
    moved = Pose("lab-a", Position(9.0, 9.0), Orientation(yaw=1.0), area="lab")
    t2 = Task("t2", (Subtask((moved,)),))
    mission = Mission("m", MissionType.SEQUENTIAL, (Assignment("r1", "t1"), Assignment("r1", "t2")))
    with pytest.raises(ExsceError, match="'lab-a' is used at two positions"):
        compile_scenario(small_scenario(tasks=(*base.tasks, t2), mission=mission))


def test_an_allocation_of_an_unknown_task_is_refused() -> None:
    mission = Mission("m", MissionType.SEQUENTIAL, (Assignment("r1", "nope"),))
    with pytest.raises(ExsceError, match="allocates task 'nope'"):
        compile_scenario(small_scenario(mission=mission))


def test_allocation_entries_are_numbered_per_robot() -> None:
    document = compile_scenario(scenario_c())
    lines = bundle_provn(document, EXSCE["scenario_c_bundle"])
    assert (
        "wasDerivedFrom(mission_c:tiago2-task_02, task:navigate_home_2, -, -, -, "
        "[prov:type='prov:PrimarySource'])"
    ) in lines


def test_the_fast_record_path_makes_what_provs_api_makes() -> None:
    """compile builds prov records directly; prov's checking API must agree with it."""
    for scenario in (scenario_c(), large_scenario(robots=5, poses=100, tasks=20)):
        fast = _ScenarioCompiler(scenario, Namespaces()).compile()
        checked = _ScenarioCompiler(scenario, Namespaces(), checked=True).compile()
        assert fast == checked
        assert serialize_prov(fast, "json") == serialize_prov(checked, "json")
        assert serialize_prov(fast, "provn") == serialize_prov(checked, "provn")


# -- PROV-N, PROV-JSON, PROV-XML ------------------------------------------------


@pytest.mark.skipif(not HAS_LXML, reason="PROV-XML needs lxml (prov[xml])")
def test_prov_xml_reads_back() -> None:
    document = compile_scenario(scenario_c())
    again = ProvDocument.deserialize(content=serialize_prov(document, "xml"), format="xml")
    assert records(again) == records(document)


def test_prov_json_reads_back() -> None:
    document = compile_scenario(scenario_c())
    assert records(through_json(document)) == records(document)
    assert json.loads(serialize_prov(document, "json"))["bundle"]


# -- scale ---------------------------------------------------------------------


def test_a_large_scenario_compiles_and_reads_back() -> None:
    document = compile_scenario(large_scenario(robots=20, poses=500, tasks=100))
    found = records(document)
    assert len(found) == 1 + 1 + 50 + 20 + 100
    assert records(through_json(document)) == found
