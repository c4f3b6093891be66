"""`derive NAME from BASE { ... }` in the language: every step form, the formatter, errors at
their lines, and the generation PROV compiled with the derived scenario."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from exsce_dsl.lang import analyse, format_spec_document, load_spec

from tests.support.cli import exscec_here
from tests.support.paths import EXAMPLES

DERIVED = """\
import "scenario_c.exsce"

derive every_step from scenario_c {
  add robot tiago3 like tiago1 at classroom_c022-w001 taking over tiago2
  swap tasks of tiago1 and tiago3
  swap start poses of tiago1 and tiago3
  reverse waypoints of delivery_a as delivery_a_back
  reverse task order of tiago1
  add task delivery_a to tiago1 at 1
  remove task navigate_home_1 from tiago3
  substitute task navigate_home_2 by navigate_home_1
  replace robot tiago1 by tiago4 at classroom_c069-w001
  remove robot tiago3 reassign to tiago4
  reallocate {
    tiago4 does delivery_a_back then delivery_b
  }
}

derive from_derived from every_step {
  add robot tiago5 like tiago4 at classroom_c018-w001
  add task navigate_home_1 to tiago5
  remove tasks of tiago5
  remove start pose of tiago5
}
"""


@pytest.fixture
def folder(in_tmp: Path) -> Path:
    shutil.copytree(EXAMPLES / "brsu_building_c", in_tmp / "c")
    (in_tmp / "c" / "derived.exsce").write_text(DERIVED)
    return in_tmp / "c"


def test_every_step_form_builds_and_prints_back(folder: Path) -> None:
    spec = load_spec(folder / "derived.exsce")
    every = spec.scenario("every_step")
    assert [r.id for r in every.robots] == ["tiago2", "tiago4"]  # tiago2 gave its tasks to tiago3
    assert every.robot("tiago4").start_pose.id == "classroom_c069-w001"  # type: ignore[union-attr]
    assert [(a.robot, a.task) for a in every.mission.allocation] == [("tiago4", "delivery_a_back"), ("tiago4", "delivery_b")]
    derived = {d.id: d for d in spec.derived}
    assert derived["every_step"].derivation is not None
    recorded = [s.transformation for s in derived["every_step"].derivation.steps]
    assert recorded == [
        "add_robot", "substitute_allocation", "swap_assignment", "swap_start_poses", "reverse_waypoint_order",
        "reverse_task_order", "add_task", "remove_task", "substitute_task",
        "add_robot", "substitute_allocation", "remove_robot",  # replace_robot, as its basic steps
        "remove_robot", "substitute_allocation",
    ]
    from_derived = spec.scenario("from_derived")
    assert [(a.robot, a.task) for a in from_derived.mission.allocation] == [
        ("tiago4", "delivery_a_back"), ("tiago4", "delivery_b")
    ]
    assert [(r.id, r.start_pose) for r in from_derived.robots][2] == ("tiago5", None)
    text = format_spec_document(spec)
    assert text == DERIVED  # the canonical form is how it is written
    (folder / "again.exsce").write_text(text)
    assert load_spec(folder / "again.exsce").derived == spec.derived


@pytest.mark.parametrize(
    ("old", "new", "line", "column", "words"),
    [
        ("from scenario_c {", "from scenario_x {", 3, 24, "unknown scenario 'scenario_x'"),
        ("remove robot tiago3 reassign to tiago4", "remove robot tiago3 reassign to tiago9", 13, 3, "has no robot 'tiago9'"),
        ("add task delivery_a to tiago1 at 1", "add task delivery_a to tiago1 at 7", 9, 3, "a new one goes at position 1 to"),
        ("derive from_derived", "derive every_step", 19, 8, "duplicate scenario 'every_step'"),
    ],
)
def test_a_step_that_cannot_apply_is_reported_at_its_line(folder: Path, old: str, new: str, line: int, column: int, words: str) -> None:
    (folder / "derived.exsce").write_text(DERIVED.replace(old, new, 1))
    analysis = analyse(folder / "derived.exsce")
    found = [(d.location, d.message) for d in analysis.errors]
    at = [m for loc, m in found if loc is not None and loc.file.endswith("derived.exsce") and (loc.line, loc.column) == (line, column)]
    assert analysis.spec is None and any(words in m for m in at), found


def test_compile_writes_the_generation_with_the_derived_scenario(folder: Path) -> None:
    compiled = exscec_here("compile", str(folder / "scenario_c_alone.exsce"), "-f", "provn")
    assert compiled.returncode == 0, compiled.stderr
    assert "bundle scenario_c_alone:scenario_generation" in compiled.stdout
    assert "used(scenario_c_alone:generation, exsce:scenario_c, -)" in compiled.stdout
    assert 'exsce:transform="reverse_waypoint_order", exsce:step=2' in compiled.stdout
    checked = exscec_here("check", str(folder / "derived.exsce"))
    assert checked.returncode == 0, checked.stdout + checked.stderr
