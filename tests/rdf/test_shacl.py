"""SHACL: the compiled examples conform to the shapes, and each kind of planted
violation is reported at the line and column of the DSL element it concerns.

The compiler only writes valid graphs, so violations are planted by compiling
a scenario and then removing or changing quads.
"""

from __future__ import annotations

import dataclasses
import textwrap
from collections.abc import Callable
from pathlib import Path

import pytest
from prov.model import ProvDocument
from pyoxigraph import DefaultGraph, Literal, NamedNode, Quad

from exsce_dsl.errors import Diagnostic
from exsce_dsl.lang import load_spec
from exsce_dsl.model import Scenario
from exsce_dsl.prov import compile_scenario, source_locations
from exsce_dsl.prov.identifiers import DEFAULT_NAMESPACE
from exsce_dsl.rdf import (
    as_dataset,
    check_scenario_shapes,
    check_spec_shapes,
    prefixes_of,
    to_dataset,
    to_quads,
    validate,
)
from exsce_dsl.rdf.shacl import shape_names, violation_diagnostics

from tests.support.cli import run_exscec
from tests.support.paths import EXAMPLES

E = DEFAULT_NAMESPACE
PROV = "http://www.w3.org/ns/prov#"
RDF_TYPE = NamedNode("http://www.w3.org/1999/02/22-rdf-syntax-ns#type")
HAD_MEMBER = NamedNode(PROV + "hadMember")
XSD = "http://www.w3.org/2001/XMLSchema#"

# Line numbers are part of the test: keep this text as it is.
SPEC = textwrap.dedent(
    """\
    robot type tiago { base pmb2 torso yes }

    environment lab {
      map lab_map from package "lab_maps" path "maps/"
      world lab_world from package "lab_sim" path "worlds/"
      area room {
        pose room-w001 at (1.0, 2.0)
        pose room-w002 at (3.0, 2.0) facing 1.5
      }
      obstacle crate model "box" at (2.0, 3.0) size (0.5, 0.5, 1.0)
    }

    task patrol {
      subtask {
        visit room-w002
        visit room-w001 facing 0.5
      }
    }

    scenario demo in lab {
      robots {
        r1: tiago namespace "r1" starts at room-w001
      }
      mission m1 sequential {
        r1 does patrol
      }
    }
    """
)


@pytest.fixture(scope="module")
def demo(tmp_path_factory: pytest.TempPathFactory) -> Scenario:
    path = tmp_path_factory.mktemp("shacl") / "demo.exsce"
    path.write_text(SPEC, encoding="utf-8")
    return load_spec(path).scenario()


def iri(local: str) -> NamedNode:
    return NamedNode(E + local)


def term(text: str) -> NamedNode:
    """``prefix:local`` for the few namespaces the plants need."""
    prefix, local = text.split(":", 1)
    namespaces = {
        "prov": PROV,
        "coord": "https://robot-schema.org/coordinates/",
        "angle": "https://robot-schema.org/rotation/",
        "geom": "https://robot-schema.org/",
        "ros": "http://wiki.ros.org/",
        "exsce": E,
    }
    return NamedNode(namespaces[prefix] + local)


POSE_W001 = iri("tasks/waypoints/room-w001-R0.00_P0.00_Y0.00")
POSE_W002 = iri("tasks/waypoints/room-w002-R0.00_P0.00_Y1.50")
POINT_W002 = iri("tasks/points/room-w002")
YAW_05 = iri("tasks/orientation/R0.00_P0.00_Y0.50")
PLAN = iri("missions/m1/r1-task_01")
ROBOT = iri("robots/r1")
MAP = iri("environments/lab/lab_map_map")
OBSTACLE = iri("environments/lab/crate")
START = iri("demo/r1-start-pose")
SUBTASK = iri("tasks/patrol-subtask_001")

Quads = list[Quad]


def without(predicate: str, subject: NamedNode | None = None, obj: NamedNode | None = None) -> Callable[[Quads], Quads]:
    def plant(quads: Quads) -> Quads:
        return [
            q
            for q in quads
            if not (
                q.predicate == term(predicate)
                and (subject is None or q.subject == subject)
                and (obj is None or q.object == obj)
            )
        ]

    return plant


def changed(predicate: str, subject: NamedNode, value: Literal) -> Callable[[Quads], Quads]:
    def plant(quads: Quads) -> Quads:
        return [
            Quad(q.subject, q.predicate, value, q.graph_name)
            if q.predicate == term(predicate) and q.subject == subject
            else q
            for q in quads
        ]

    return plant


def added(*triples: tuple[NamedNode, NamedNode, NamedNode | Literal]) -> Callable[[Quads], Quads]:
    def plant(quads: Quads) -> Quads:
        return quads + [Quad(s, p, o, DefaultGraph()) for s, p, o in triples]

    return plant


def two_maps() -> list[tuple[NamedNode, NamedNode, NamedNode | Literal]]:
    """A second, well-formed map of the environment (its own node has no DSL location)."""
    second = iri("environments/lab/second_map")
    return [
        (iri("environments/lab"), HAD_MEMBER, second),
        (second, RDF_TYPE, term("exsce:map")),
        (second, HAD_MEMBER, iri("environments/lab/occupancy_grid")),
        (second, HAD_MEMBER, iri("environments/lab/metadata")),
    ]


# (what is planted, the plant, where it must be reported, words of the message)
MATRIX: list[tuple[str, Callable[[Quads], Quads], tuple[int, int], str]] = [
    ("a point without x", without("coord:x", POINT_W002), (8, 10), "exactly one x coordinate"),
    ("a point with two x", added((POINT_W002, term("coord:x"), Literal("4.0", datatype=NamedNode(XSD + "double")))), (8, 10), "exactly one x coordinate"),
    ("a misspelt mission type", changed("exsce:missionType", iri("missions/m1"), Literal("parallell")), (24, 11), '"parallel" or "sequential"'),
    ("a scenario without mission", without("prov:hadMember", iri("demo"), iri("missions/m1")), (20, 10), "exactly one mission"),
    ("a pose with two points", added((POSE_W002, HAD_MEMBER, iri("tasks/points/room-w001"))), (8, 10), "exactly one point"),
    ("a pose without orientation", without("prov:hadMember", POSE_W001, iri("tasks/orientation/R0.00_P0.00_Y0.00")), (7, 10), "exactly one orientation"),
    ("a yaw that is text", changed("angle:yaw", YAW_05, Literal("half a radian")), (16, 11), "exactly one yaw"),
    ("a plan not derived from its task", without("prov:hadPrimarySource", PLAN), (25, 13), "allocated plan"),
    ("a subtask without waypoints", without("prov:wasDerivedFrom", SUBTASK), (14, 3), "derived from at least one waypoint"),
    ("a robot without software configuration", without("prov:hadMember", ROBOT, iri("robots/r1/software-config")), (22, 5), "software configuration"),
    ("a hardware configuration with a word for a torso", changed("exsce:torso", iri("robots/r1/hardware-config"), Literal("maybe")), (22, 5), "torso"),
    ("an invalid ROS namespace", changed("ros:namespace", iri("robots/r1/software-config"), Literal("1 bad")), (22, 5), "ROS namespace"),
    ("a start pose from no pose", without("prov:entity", START), (22, 40), "from exactly one pose"),
    ("an environment with two maps", added(*two_maps()), (3, 13), "at most one map"),
    ("a map without occupancy grid", without("prov:hadMember", MAP, iri("environments/lab/occupancy_grid")), (4, 3), "occupancy grid"),
    ("an obstacle from two poses", added((OBSTACLE, term("prov:wasDerivedFrom"), POSE_W001)), (10, 12), "exactly one pose"),
    ("an obstacle of odd size", changed("exsce:size", OBSTACLE, Literal("big")), (10, 12), "size"),
    ("a map file without its package", without("ros:pkg", MAP), (4, 3), "exactly one package"),
]


def diagnostics_of(scenario: Scenario, plant: Callable[[Quads], Quads]) -> list[Diagnostic]:
    document = compile_scenario(scenario)
    quads = plant(to_quads(document))
    return violation_diagnostics(
        validate(quads), source_locations(scenario), scenario.location, prefixes_of(document)
    )


def test_the_matrix_spec_conforms(demo: Scenario) -> None:
    assert check_scenario_shapes(demo) == []


@pytest.mark.parametrize(("what", "plant", "where", "words"), MATRIX, ids=[m[0] for m in MATRIX])
def test_a_planted_violation_is_reported_at_its_dsl_element(
    demo: Scenario, what: str, plant: Callable[[Quads], Quads], where: tuple[int, int], words: str
) -> None:
    found = diagnostics_of(demo, plant)
    assert found, what
    assert {(d.location.line, d.location.column) for d in found if d.location} == {where}, found
    assert all(d.code == "shacl" and d.severity == "error" for d in found)
    assert any(words in d.message for d in found), found
    assert all(d.location and d.location.file.endswith("demo.exsce") for d in found)


def test_the_reported_position_is_the_element_s_name(demo: Scenario) -> None:
    """Spot checks that the matrix's positions are what they claim to be."""
    lines = SPEC.splitlines()
    assert lines[7][9:].startswith("room-w002")
    assert lines[23][10:].startswith("m1")
    assert lines[24][12:].startswith("patrol")
    assert lines[21][39:].startswith("room-w001")
    assert lines[13][2:].startswith("subtask")
    assert lines[2][12:].startswith("lab")


def test_a_message_names_the_node_the_property_and_the_shape(demo: Scenario) -> None:
    (found,) = diagnostics_of(demo, changed("exsce:missionType", iri("missions/m1"), Literal("parallell")))
    assert str(found).endswith(
        'demo.exsce:24:11: error: mission:m1 exsce:missionType: a mission\'s type is "parallel" or '
        '"sequential" (SHACL shape exsce-sh:MissionShape; value "parallell")'
    )


def test_a_node_without_location_falls_back_to_the_scenario(demo: Scenario) -> None:
    stray = NamedNode("https://example.org/stray-point")
    (found,) = diagnostics_of(demo, added((stray, RDF_TYPE, term("geom:Point")), (stray, term("coord:y"), Literal("1.0", datatype=NamedNode(XSD + "double"))), (stray, term("coord:z"), Literal("1.0", datatype=NamedNode(XSD + "double")))))
    assert found.location is not None
    assert (found.location.line, found.location.column) == (20, 10)
    assert "<https://example.org/stray-point> coord:x" in found.message


def test_every_node_of_a_compiled_scenario_has_a_location(demo: Scenario) -> None:
    locations = source_locations(demo)
    subjects = {q.subject.value for q in to_quads(compile_scenario(demo)) if isinstance(q.subject, NamedNode)}
    assert subjects - set(locations) == set()


# -- the examples -------------------------------------------------------------------


EXAMPLE_SPECS = sorted(EXAMPLES.rglob("*.exsce"))


@pytest.mark.parametrize("path", EXAMPLE_SPECS, ids=[p.name for p in EXAMPLE_SPECS])
def test_every_example_conforms(path: Path) -> None:
    spec = load_spec(path)
    assert check_spec_shapes(spec) == []


def test_every_example_scenario_has_its_nodes_located() -> None:
    spec = load_spec(EXAMPLES / "brsu_building_c" / "scenario_c.exsce")
    scenario = spec.scenario()
    locations = source_locations(scenario)
    nodes = {
        node.value
        for q in to_quads(compile_scenario(scenario))
        for node in ((q.subject,) if q.predicate == RDF_TYPE else (q.subject, q.object))
        if isinstance(node, NamedNode) and node.value.startswith(E)
    }
    assert nodes - set(locations) == set()


def test_shapes_for_another_base_namespace() -> None:
    scenario = load_spec(EXAMPLES / "brsu_building_c" / "scenario_c.exsce").scenario()
    base = "https://example.org/lab/"
    assert check_scenario_shapes(scenario, base) == []
    document = compile_scenario(scenario, base)
    quads = [q for q in to_quads(document) if q.predicate.value != "https://robot-schema.org/coordinates/y"]
    violations = validate(quads, namespace=base)
    assert violations and {v.path for v in violations} == {"https://robot-schema.org/coordinates/y"}


def test_shacl_on_scenario_c_finds_nothing_twice() -> None:
    """Its time is bench/rdf.py's to measure (a timed unit test failed at 0.59 s on a loaded CI)."""
    scenario = load_spec(EXAMPLES / "brsu_building_c" / "scenario_c.exsce").scenario()
    assert check_scenario_shapes(scenario) == []
    assert check_scenario_shapes(scenario) == []  # the cached shapes give the same answer


def test_the_packaged_shapes() -> None:
    assert {"spec", "oracles", "derivations"} <= set(shape_names())


# -- oracles and derivations (hand-built, in the shapes of the method's listings) ----


def scenario_c_quads() -> Quads:
    """scenario_c's graphs, and those of scenario_new, a copy (standing for a derived scenario)."""
    scenario = load_spec(EXAMPLES / "brsu_building_c" / "scenario_c.exsce").scenario()
    copy = dataclasses.replace(scenario, id="scenario_new")
    return to_quads(compile_scenario(scenario)) + to_quads(compile_scenario(copy))


def oracle_document(**usage: object) -> ProvDocument:
    """An oracle of scenario_c on tiago1's max_velocity (Listing 17), its relation given by ``usage``."""
    document = ProvDocument()
    exsce = document.add_namespace("exsce", E)
    document.add_namespace("oracle", E + "oracles/")
    scenario = document.add_namespace("scenario_c", E + "scenario_c/")
    topic = document.add_namespace("topic", E + "topics/")
    bundle = document.bundle(exsce["scenario_c_oracles_bundle"])
    oracle = scenario["tiago1-max_velocity"]
    bundle.activity(
        oracle,
        other_attributes={"prov:type": exsce["oracle"], "oracle:metric": "max_velocity", "oracle:robot": "tiago1"},
    )
    relation = {"oracle:relationship": "below_max", "oracle:type": "baseline", "oracle:limit": 1.0}
    relation.update({f"oracle:{k}": v for k, v in usage.items()})
    bundle.usage(
        oracle,
        exsce["scenario_c"],
        identifier=scenario["tiago1-max_velocity-baseline"],
        other_attributes={k: v for k, v in relation.items() if v is not None},
    )
    bundle.usage(oracle, topic["/tiago1/nav_vel"], other_attributes={"prov:role": "topic"})
    return document


def shacl_messages(quads: Quads) -> list[str]:
    return [v.message for v in validate(quads)]


@pytest.mark.parametrize(
    "relation",
    [
        {},
        {"relationship": "invariant", "limit": None, "value": 97.606, "tolerance": 5.0},
        {"relationship": "invariant", "limit": None, "value": 3},
        {"relationship": "increasing", "type": "metamorphic", "limit": None, "value": 141.195, "delta": 43.59},
    ],
)
def test_oracles_in_the_method_s_shape_conform(relation: dict[str, object]) -> None:
    assert shacl_messages(scenario_c_quads() + to_quads(oracle_document(**relation))) == []


@pytest.mark.parametrize(
    ("relation", "words"),
    [
        ({"type": "basline"}, '"baseline" or "metamorphic"'),
        ({"limit": None}, "below_max or above_min has a limit"),
        ({"relationship": "increasing", "limit": None, "value": 1.0}, "also have a delta"),
        ({"relationship": "invariant", "limit": 0.1}, "any other has a value"),
        ({"value": "fast"}, "at most one value (oracle:value), a number"),
        ({"relationship": "below max"}, "names exactly one relation"),
    ],
)
def test_a_broken_oracle_is_named(relation: dict[str, object], words: str) -> None:
    messages = shacl_messages(scenario_c_quads() + to_quads(oracle_document(**relation)))
    assert any(words in m for m in messages), messages


def test_an_oracle_must_use_a_scenario() -> None:
    usage = iri("scenario_c/tiago1-max_velocity-baseline")
    quads = [q for q in to_quads(oracle_document()) if usage not in (q.subject, q.object)]
    quads = [q for q in quads if q.object != iri("scenario_c")]
    assert any("used at least one scenario" in m for m in shacl_messages(quads))


def derivation_document(chained: bool = True) -> ProvDocument:
    """scenario_new derived from scenario_c by removing tiago2 (Listing 31), as exsce types it."""
    document = ProvDocument()
    exsce = document.add_namespace("exsce", E)
    new = document.add_namespace("scenario_new", E + "scenario_new/")
    bundle = document.bundle(new["scenario_generation"])
    bundle.entity(exsce["scenario_new"], {"prov:type": exsce["ConcreteScenario"]})
    generation = new["generation"]
    bundle.activity(generation, other_attributes={"prov:type": exsce["generation"]})
    bundle.generation(exsce["scenario_new"], generation)
    bundle.usage(generation, exsce["scenario_c"])
    steps = [("remove_robot", "tiago2"), ("remove_task", "tiago2"), ("remove_start_pose", "tiago2")]
    ids = [new[f"{kind}-{robot}"] for kind, robot in steps]
    for identifier, (kind, robot) in zip(ids, steps, strict=True):
        attributes = {"prov:type": exsce["transform"], "exsce:transform": kind, "exsce:robot": robot}
        bundle.activity(identifier, other_attributes=attributes)
    for later, earlier in zip(ids[1:], ids[:-1], strict=True):
        if chained or later != ids[-1]:
            bundle.communication(later, earlier)
    bundle.start(generation, starter=ids[0])
    bundle.end(generation, ender=ids[-1])
    return document


def test_a_derivation_in_the_method_s_shape_conforms() -> None:
    assert shacl_messages(scenario_c_quads() + to_quads(derivation_document())) == []


def test_a_broken_chain_of_transformations_is_named() -> None:
    violations = validate(scenario_c_quads() + to_quads(derivation_document(chained=False)))
    assert {(v.focus, v.message) for v in violations} == {
        (
            E + "scenario_new/generation",
            "the steps of a generation form one chain: its last step is informed (prov:wasInformedBy), "
            "step by step, by its first",
        ),
        (
            E + "scenario_new",  # the same, seen from the scenario it generated
            "a derived scenario was generated by one generation: an activity that used the base scenario "
            "and was started by its first transformation and ended by its last",
        ),
    }


def test_a_generation_must_use_its_base_scenario() -> None:
    quads = [q for q in to_quads(derivation_document()) if q.predicate != term("prov:used")]
    messages = shacl_messages(scenario_c_quads() + quads)
    assert any("used exactly one base scenario" in m for m in messages), messages
    assert any("generated by one generation" in m for m in messages), messages


def test_a_transformation_has_one_kind() -> None:
    kind = term("exsce:transform")
    quads = [
        Quad(q.subject, q.predicate, Literal("Remove Robot"), q.graph_name) if q.predicate == kind else q
        for q in to_quads(derivation_document())
    ]
    messages = shacl_messages(scenario_c_quads() + quads)
    assert messages and all("names exactly one kind" in m for m in messages)


# -- exscec check --------------------------------------------------------------------


def test_exscec_check_validates_the_example() -> None:
    result = run_exscec("check", str(EXAMPLES / "brsu_building_c" / "scenario_c.exsce"))
    assert result.returncode == 0, result.stderr
    assert result.stderr.strip().endswith("scenario_c.exsce: ok (1 scenario)")


def test_exscec_check_reports_what_only_the_compiler_finds(in_tmp: Path) -> None:
    (in_tmp / "spec.exsce").write_text(
        textwrap.dedent(
            """\
            robot type tiago { base pmb2 torso yes }
            environment lab {
              area lab {
                pose lab-w001 at (1.0, 2.0)
              }
            }
            task t { visit lab-w001 }
            scenario s in lab {
              robots { r1: tiago starts at lab-w001 }
              mission m sequential { r1 does t }
            }
            """
        )
    )
    result = run_exscec("check", "spec.exsce")
    assert result.returncode == 2
    assert "spec.exsce:3:8: error: area 'lab' and environment 'lab' would both be written" in result.stderr
    assert "Traceback" not in result.stderr


def test_shapes_for_another_base_namespace_are_named_in_it() -> None:
    scenario = load_spec(EXAMPLES / "brsu_building_c" / "scenario_c.exsce").scenario()
    base = "https://example.org/lab/"
    document = compile_scenario(scenario, base)
    quads = [q for q in to_quads(document) if q.predicate.value != base + "missionType"]
    prefixes = {**prefixes_of(document), "exsce-sh": base + "shapes/"}
    found = violation_diagnostics(validate(quads, namespace=base), source_locations(scenario, base), None, prefixes)
    assert [d.message for d in found] == [
        "mission:mission_c exsce:missionType: a mission has exactly one type (exsce:missionType) "
        "(SHACL shape exsce-sh:MissionShape)"
    ]


def test_a_dataset_is_validated_as_the_union_of_its_graphs(demo: Scenario) -> None:
    """A dataset is validated as one graph: PROV relations cross its named graphs."""
    document = compile_scenario(demo)
    assert validate(to_dataset(document)) == []
    broken = without("coord:x", POINT_W002)(to_quads(document))
    assert [v.path for v in validate(as_dataset(broken))] == ["https://robot-schema.org/coordinates/x"]
