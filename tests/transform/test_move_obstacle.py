"""`move_obstacle`, the method's "move an obstacle" environment transformation: on the model, in a
`derive` block (errors at their lines, the formatter's round trip), in the generation PROV, and
through `exscec derive`, whose file must hold a derive block since the environment is a new one."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from exsce_dsl.errors import ExsceError
from exsce_dsl.lang import analyse, format_document, format_spec_document, load_spec
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
from exsce_dsl.model.derivation import TransformationStep
from exsce_dsl.model.derived import DerivedScenario, Step
from exsce_dsl.prov.derivation import compile_derivation
from exsce_dsl.transform.derivation import derive, derived_document

from tests.support.cli import exscec_here
from tests.support.map_files import write_map

YARD = """\
environment yard {
  map yard_map file "yard.yaml"

  area pad {
    pose pad-p1 at (1.0, 1.0)
    pose pad-p2 at (2.0, 1.0)
  }

  obstacle mast model "mast_2m" at (3.0, 3.0) facing 90.0 deg size (0.2, 0.2, 2.0)
  obstacle crate at (1.0, 4.0)
}

robot type quad {
  base quadrotor
  torso no
}

task hop {
  visit pad-p2
}

scenario yard_run in yard {
  robots {
    drone1: quad starts at pad-p1
  }
  mission hop_once sequential {
    drone1 does hop
  }
}
"""

MOVED = """\
import "yard.exsce"

derive yard_moved from yard_run {
  move obstacle mast to (4.0, 2.5)
}
"""


@pytest.fixture
def folder(tmp_path: Path) -> Path:
    write_map(tmp_path, "yard")  # 5 m by 5 m, all free
    (tmp_path / "yard.exsce").write_text(YARD)
    (tmp_path / "moved.exsce").write_text(MOVED)
    return tmp_path


@pytest.fixture
def base(folder: Path) -> Scenario:
    return load_spec(folder / "yard.exsce").scenario("yard_run")


def test_the_obstacle_moves_and_nothing_else_changes(base: Scenario) -> None:
    derived = derive(base, [("move_obstacle", {"obstacle": "mast", "to": "4, 2.5"})], "yard_moved")
    env, old = derived.scenario.environment, base.environment
    mast, crate = env.obstacles
    assert mast.pose.position == Position(4.0, 2.5, 0.0)
    assert mast.pose.orientation == Orientation(0.0, 0.0, 1.5707963267948966)  # 90 deg, kept
    assert (mast.id, mast.model, mast.size) == ("mast", "mast_2m", (0.2, 0.2, 2.0))
    # obstacle poses are named by the new environment (their IRIs must not clash with the base's)
    assert (mast.pose.id, crate.pose.id) == ("yard_moved_environment-mast", "yard_moved_environment-crate")
    assert replace(crate, pose=replace(crate.pose, id="crate")) == old.obstacles[1]
    assert env.id == "yard_moved_environment" and derived.environment_changed
    assert (env.map, env.world, env.areas) == (old.map, old.world, old.areas)  # poses keep their ids
    assert env == replace(old, id="yard_moved_environment", obstacles=(mast, crate))
    assert derived.scenario.robots == base.robots and derived.scenario.tasks == base.tasks
    assert derived.scenario.mission == replace(base.mission, id="yard_moved_mission")
    assert derived.derivation.steps == (
        TransformationStep("move_obstacle", (("obstacle", "mast"), ("to", "4.0,2.5"))),
    )
    assert derived.requests == (Step("move_obstacle", (("obstacle", "mast"), ("to", "4, 2.5"))),)


def test_a_height_is_recorded_only_when_there_is_one(base: Scenario) -> None:
    up = derive(base, [("move_obstacle", {"obstacle": "mast", "to": "4,2.5,1"})], "up")
    assert up.scenario.environment.obstacles[0].pose.position == Position(4.0, 2.5, 1.0)
    assert up.derivation.steps[0].parameters == (("obstacle", "mast"), ("to", "4.0,2.5,1.0"))
    flat = derive(base, [("move_obstacle", {"obstacle": "mast", "to": "4,2.5,0"})], "flat")
    assert flat.derivation.steps[0].parameters == (("obstacle", "mast"), ("to", "4.0,2.5"))


def test_the_default_id_is_deterministic_and_names_the_environment(base: Scenario) -> None:
    request = [("move_obstacle", {"obstacle": "crate", "to": "2,4"})]
    first, again = derive(base, request), derive(base, request)
    assert first.scenario == again.scenario and first.scenario.id.startswith("yard_run_")
    assert first.scenario.environment.id == f"{first.scenario.id}_environment"


def test_other_transformations_keep_the_environment_and_its_id(base: Scenario) -> None:
    derived = derive(base, [("reverse_task_order", {})], "same_place")
    assert derived.scenario.environment.id == "yard" and not derived.environment_changed


def test_moved_there_and_back_is_the_base_environment_again(base: Scenario) -> None:
    derived = derive(
        base,
        [("move_obstacle", {"obstacle": "mast", "to": "4,2.5"}), ("move_obstacle", {"obstacle": "mast", "to": "3,3"})],
        "back",
    )
    assert derived.scenario.environment == base.environment and not derived.environment_changed


@pytest.mark.parametrize(
    ("arguments", "words"),
    [
        ({"obstacle": "mats", "to": "4,2.5"}, "environment 'yard' has no obstacle 'mats'; did you mean 'mast'?"),
        ({"obstacle": "mast", "to": "3,3"}, r"obstacle 'mast' is at \(3.0, 3.0\) already"),
        ({"obstacle": "mast", "to": "3.0,3.0,0.0"}, "already"),
        ({"obstacle": "mast", "to": "4"}, "'4' is not a position: write x,y or x,y,z in metres"),
        ({"obstacle": "mast", "to": "1,2,3,4"}, "is not a position"),
        ({"obstacle": "mast", "to": "4,x"}, "'x' in position '4,x' is not a number of metres"),
        ({"obstacle": "mast", "to": "4,"}, "'' in position '4,' is not a number"),
        ({"obstacle": "mast", "to": "nan,1"}, "'nan' in position"),
        ({"obstacle": "mast", "to": "inf,1"}, "'inf' in position"),
        ({"obstacle": "mast", "to": "1e999,1"}, "'1e999' in position"),
        ({"obstacle": "mast", "to": "1_0,1"}, "'1_0' in position"),
        ({"obstacle": "mast", "to": "4 m,1"}, "'4 m' in position"),
        ({"obstacle": "mast"}, r"move_obstacle needs to \(it takes obstacle, to\)"),
    ],
)
def test_preconditions_fail_with_clear_errors(base: Scenario, arguments: dict[str, str], words: str) -> None:
    with pytest.raises(ExsceError, match=words):
        derive(base, [("move_obstacle", arguments)])


@settings(max_examples=50, deadline=None)
@given(
    st.floats(min_value=-1e6, max_value=1e6, allow_nan=False),
    st.floats(min_value=-1e6, max_value=1e6, allow_nan=False),
)
def test_the_record_gives_back_the_same_position(x: float, y: float) -> None:
    base = _plain_base()
    if (x, y) == (3.0, 3.0):
        return
    derived = derive(base, [("move_obstacle", {"obstacle": "mast", "to": f"{x!r},{y!r}"})], "moved")
    (recorded,) = derived.derivation.steps
    again = derive(base, [("move_obstacle", dict(recorded.parameters))], "moved")  # type: ignore[arg-type]
    assert again.scenario == derived.scenario
    assert derived.scenario.environment.obstacles[0].pose.position == Position(x, y)


def _plain_base() -> Scenario:
    """The yard scenario without its map (no files needed), for the property test."""
    p1, p2 = Pose("pad-p1", Position(1.0, 1.0), area="pad"), Pose("pad-p2", Position(2.0, 1.0), area="pad")
    mast = Obstacle("mast", Pose("mast", Position(3.0, 3.0)), "mast_2m", (0.2, 0.2, 2.0))
    env = Environment("yard", areas=(Area("pad", (p1, p2)),), obstacles=(mast,))
    robot = Robot("drone1", RobotType("quad", "quadrotor", False), "drone1", p1)
    hop = Task("hop", (Subtask((p2,)),))
    mission = Mission("hop_once", MissionType.SEQUENTIAL, (Assignment("drone1", "hop"),))
    return Scenario("yard_run", env, (robot,), mission, (hop,))


def test_the_derive_block_builds_the_moved_scenario_and_prints_back(folder: Path) -> None:
    (folder / "moved.exsce").write_text(MOVED.replace("(4.0, 2.5)", "(400 cm, 2.5 m, 0.5)"))
    spec = load_spec(folder / "moved.exsce")
    moved = spec.scenario("yard_moved")
    assert moved.environment.id == "yard_moved_environment"
    assert moved.environment.obstacles[0].pose.position == Position(4.0, 2.5, 0.5)
    (block,) = spec.derived
    assert block.steps == (Step("move_obstacle", (("obstacle", "mast"), ("to", "4.0,2.5,0.5"))),)
    assert block.derivation is not None and block.derivation.steps == (
        TransformationStep("move_obstacle", (("obstacle", "mast"), ("to", "4.0,2.5,0.5"))),
    )
    text = format_spec_document(spec)
    assert text == MOVED.replace("(4.0, 2.5)", "(400 cm, 2.5 m, 0.5)")  # as written
    (folder / "again.exsce").write_text(text)
    again = load_spec(folder / "again.exsce")
    assert again.derived == spec.derived and format_spec_document(again) == text


def test_the_canonical_text_is_how_it_is_written(folder: Path) -> None:
    assert format_spec_document(load_spec(folder / "moved.exsce")) == MOVED


@pytest.mark.parametrize(
    ("written", "line", "column", "words"),
    [
        ("move obstacle mats to (4.0, 2.5)", 4, 3, "environment 'yard' has no obstacle 'mats'; did you mean 'mast'?"),
        ("move obstacle mast to (3.0, 3.0)", 4, 3, "obstacle 'mast' is at (3.0, 3.0) already"),
        ("move obstacle mast to (7.0, 2.0)", 4, 3, "obstacle 'mast' is outside the map 'yard_map' (x from 0.00 to 5.00"),
        ("move obstacle mast to (4.0, 2.5)\n  move obstacle mast to (2.0, -1.0)", 5, 3, "obstacle 'mast' is outside"),
    ],
)
def test_a_move_that_cannot_apply_is_reported_at_its_line(folder: Path, written: str, line: int, column: int, words: str) -> None:
    (folder / "moved.exsce").write_text(MOVED.replace("move obstacle mast to (4.0, 2.5)", written))
    analysis = analyse(folder / "moved.exsce")
    found = [(d.location, d.message) for d in analysis.errors]
    at = [
        m for loc, m in found
        if loc is not None and loc.file.endswith("moved.exsce") and (loc.line, loc.column) == (line, column)
    ]
    assert analysis.spec is None and any(words in m for m in at) and len(found) == 1, found


def test_the_base_map_problem_is_not_reported_again_at_the_step(folder: Path) -> None:
    (folder / "yard.yaml").unlink()
    found = [(d.location, d.message) for d in analyse(folder / "moved.exsce").errors]
    assert found and all(loc is not None and loc.file.endswith("yard.exsce") for loc, _ in found), found


def test_the_generation_prov_has_the_step_and_its_arguments(base: Scenario) -> None:
    derived = derive(base, [("move_obstacle", {"obstacle": "mast", "to": "4,2.5"})], "yard_moved")
    records = {r.get_provn() for b in compile_derivation(derived.derivation).bundles for r in b.get_records()}
    assert records == {
        "activity(yard_moved:generation, -, -, [prov:type='exsce:generation'])",
        "wasGeneratedBy(exsce:yard_moved, yard_moved:generation, -)",
        "used(yard_moved:generation, exsce:yard_run, -)",
        "wasDerivedFrom(exsce:yard_moved, exsce:yard_run, yard_moved:generation, -, -)",
        "activity(yard_moved:step_01-move_obstacle, -, -, [prov:type='exsce:transform', "
        'exsce:transform="move_obstacle", exsce:step=1, exsce:obstacle="mast", exsce:to="4.0,2.5"])',
        "wasStartedBy(yard_moved:generation, -, yard_moved:step_01-move_obstacle, -)",
        "wasEndedBy(yard_moved:generation, -, yard_moved:step_01-move_obstacle, -)",
    }


def test_the_derived_document_is_a_derive_block_when_the_environment_changed(folder: Path, base: Scenario) -> None:
    target = folder / "sub" / "moved.exsce"
    moved = derive(
        base,
        [("move_obstacle", {"obstacle": "mast", "to": "4,2.5"}), ("reverse_waypoint_order", {"task": "hop"})],
        "yard_moved",
    )
    document = derived_document(moved, folder / "yard.exsce", target)
    assert [i.path for i in document.imports] == ["../yard.exsce"]
    (block,) = document.declarations
    assert isinstance(block, DerivedScenario) and block.scenario == moved.scenario
    assert format_document(document, {}) == (
        'import "../yard.exsce"\n\n'
        "derive yard_moved from yard_run {\n"
        "  move obstacle mast to (4.0, 2.5)\n"
        "  reverse waypoints of hop\n"
        "}\n"
    )
    still = derive(base, [("reverse_waypoint_order", {"task": "hop"})], "reversed")
    assert [type(d).__name__ for d in derived_document(still, folder / "yard.exsce", target).declarations] == [
        "Task", "Scenario"
    ]


def test_exscec_derive_writes_a_derive_block_that_checks_and_compiles(in_tmp: Path) -> None:
    write_map(in_tmp, "yard")
    (in_tmp / "yard.exsce").write_text(YARD)
    made = exscec_here(
        "derive", "yard.exsce", "-t", "move_obstacle", "--obstacle", "mast", "--to", "4,2.5",
        "--id", "yard_moved", "-o", "new.exsce", "--add-to-store",
    )
    assert made.returncode == 0, made.stderr
    assert (in_tmp / "new.exsce").read_text() == MOVED
    checked = exscec_here("check", "new.exsce")
    assert checked.returncode == 0, checked.stdout + checked.stderr
    compiled = exscec_here("compile", "new.exsce", "-f", "provn")
    assert compiled.returncode == 0, compiled.stderr
    assert "hadMember(exsce:yard_moved, env:yard_moved_environment)" in compiled.stdout
    assert 'exsce:to="4.0,2.5"' in compiled.stdout and "bundle yard_moved:scenario_generation" in compiled.stdout
    bad = exscec_here("derive", "yard.exsce", "-t", "move_obstacle", "--obstacle", "mats", "--to", "4,2.5")
    assert bad.returncode == 2 and "has no obstacle 'mats'; did you mean 'mast'?" in bad.stderr
    assert "Traceback" not in bad.stderr


def test_the_base_and_the_moved_scenario_validate_together(base: Scenario) -> None:
    """Both in one store: the moved obstacle's pose and point are not the base's with other numbers."""
    from exsce_dsl.prov import compile_scenario
    from exsce_dsl.rdf import to_quads, validate

    derived = derive(base, [("move_obstacle", {"obstacle": "mast", "to": "4,2.5"})], "yard_moved")
    quads = to_quads(compile_scenario(base)) + to_quads(compile_scenario(derived.scenario))
    assert validate(quads + to_quads(compile_derivation(derived.derivation))) == []
