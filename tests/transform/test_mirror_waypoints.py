"""`mirror_waypoints`: a task's waypoints mirrored about the line through a pose along its heading,
as a new task in place of the old one (added as one record and this test: issue 49, item 2)."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import pytest

from exsce_dsl.errors import ExsceError
from exsce_dsl.explore.steps import applicable_steps
from exsce_dsl.lang import analyse, format_spec_document, load_spec
from exsce_dsl.model import MapModel, Scenario, Specification
from exsce_dsl.model.derivation import TaskOrigin, TransformationStep
from exsce_dsl.prov.derivation import compile_derivation
from exsce_dsl.transform.derivation import derive

YARD = """\
robot type rover {
  base diff
}

environment yard {
  area east {
    pose dock at (2.0, 1.0)
    pose gate at (5.0, 3.0) facing 0.5
    pose north at (2.0, 6.0) facing 90 deg
  }
}

task patrol {
  visit gate, (4.0, -1.0) facing 0.25
}

task on_the_axis {
  visit (7.0, 1.0), (9.0, 1.0)
}

scenario yard_day in yard {
  robots {
    r1: rover starts at dock
  }
  mission day parallel {
    r1 does patrol
  }
}
"""

DERIVED = """\
import "yard.exsce"

derive yard_mirrored from yard_day {
  mirror waypoints of patrol about dock as patrol_west
}
"""


@pytest.fixture
def spec(in_tmp: Path) -> Specification:
    (in_tmp / "yard.exsce").write_text(YARD)
    return load_spec(in_tmp / "yard.exsce")


@pytest.fixture
def base(spec: Specification) -> Scenario:
    return spec.scenario("yard_day")


def _reflect(x: float, y: float, x0: float, y0: float, heading: float) -> tuple[float, float]:
    """Reflection about the line through (x0, y0) at ``heading``, with complex numbers."""
    axis = complex(math.cos(heading), math.sin(heading))
    d = complex(x - x0, y - y0)
    m = axis * axis * d.conjugate()
    return x0 + m.real, y0 + m.imag


def test_waypoints_and_headings_are_mirrored_about_the_pose_s_line(base: Scenario, spec: Specification) -> None:
    tasks = {t.id: t for t in spec.tasks}
    derived = derive(base, [("mirror_waypoints", {"task": "patrol", "about": "north"})], "yard_n", tasks)
    (task,) = derived.new_tasks
    assert task.id == "patrol_mirrored" and [a.task for a in derived.scenario.mission.allocation] == [
        "patrol_mirrored"
    ]
    # north faces 90 deg: the line x = 2; gate (5, 3) facing 0.5 -> (-1, 3) facing pi - 0.5
    gate, corner = task.waypoints()
    assert (gate.position.x, gate.position.y) == pytest.approx((-1.0, 3.0), abs=1e-12)
    assert gate.orientation.yaw == pytest.approx(math.pi - 0.5)
    assert (corner.position.x, corner.position.y) == pytest.approx((0.0, -1.0), abs=1e-12)
    assert [w.id for w in task.waypoints()] == ["patrol_mirrored-w001", "patrol_mirrored-w002"]
    assert derived.derivation.steps == (
        TransformationStep("mirror_waypoints", (("task", "patrol"), ("about", "north"), ("to", "patrol_mirrored"))),
    )
    assert derived.derivation.origins == (TaskOrigin("patrol_mirrored", "patrol", 1),)


def test_about_a_slanted_pose_the_reflection_is_the_plain_formula(base: Scenario, spec: Specification) -> None:
    tasks = {t.id: t for t in spec.tasks}
    derived = derive(base, [("mirror_waypoints", {"task": "patrol", "about": "gate"})], "yard_g", tasks)
    mirrored = [c for w in derived.new_tasks[0].waypoints() for c in (w.position.x, w.position.y)]
    originals = [(5.0, 3.0), (4.0, -1.0)]  # gate is on its own line: it stays
    expected = [c for x, y in originals for c in _reflect(x, y, 5.0, 3.0, 0.5)]
    assert mirrored == pytest.approx(expected, abs=1e-12)


def test_mirroring_twice_about_one_pose_gives_the_waypoints_back(base: Scenario, spec: Specification) -> None:
    tasks = {t.id: t for t in spec.tasks}
    steps = [
        ("mirror_waypoints", {"task": "patrol", "about": "gate"}),
        ("mirror_waypoints", {"task": "patrol_mirrored", "about": "gate", "as": "patrol_again"}),
    ]
    twice = derive(base, steps, "yard_twice", tasks)
    again = twice.new_tasks[-1]
    (original,) = [t for t in spec.tasks if t.id == "patrol"]
    for back, first in zip(again.waypoints(), original.waypoints(), strict=True):
        assert back.position.distance_to(first.position) < 1e-9
        assert math.remainder(back.orientation.yaw - first.orientation.yaw, math.tau) == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize(
    ("arguments", "words"),
    [
        ({"task": "patrol", "about": "nowhere"}, "has no pose 'nowhere'"),
        ({"task": "lost", "about": "dock"}, "allocates no task 'lost'"),
        ({"task": "patrol", "about": "dock", "as": "on_the_axis"}, "there is a task 'on_the_axis' already"),
    ],
)
def test_preconditions_fail_with_clear_errors(
    base: Scenario, spec: Specification, arguments: dict[str, str], words: str
) -> None:
    tasks = {t.id: t for t in spec.tasks}
    with pytest.raises(ExsceError, match=words):
        derive(base, [("mirror_waypoints", arguments)], "yard_x", tasks)


def test_a_task_on_the_axis_is_refused_as_unchanged(base: Scenario, spec: Specification) -> None:
    tasks = {t.id: t for t in spec.tasks}
    steps = [("substitute_task", {"task": "patrol", "with": "on_the_axis"}),
             ("mirror_waypoints", {"task": "on_the_axis", "about": "dock"})]  # fmt: skip
    with pytest.raises(ExsceError, match="lies on the axis through 'dock'"):
        derive(base, steps, "yard_axis", tasks)


def test_a_derive_block_builds_prints_back_and_records_the_step(in_tmp: Path, spec: Specification) -> None:
    (in_tmp / "derived.exsce").write_text(DERIVED)
    loaded = load_spec(in_tmp / "derived.exsce")
    (block,) = loaded.derived
    assert [t.id for t in block.new_tasks] == ["patrol_west"]
    assert format_spec_document(loaded) == DERIVED
    assert block.derivation is not None
    document = compile_derivation(block.derivation)
    assert 'mirror_waypoints' in document.get_provn()


def test_an_unknown_pose_in_a_block_is_reported_at_its_step(in_tmp: Path, spec: Specification) -> None:
    (in_tmp / "derived.exsce").write_text(DERIVED.replace("about dock", "about dok"))
    analysis = analyse(in_tmp / "derived.exsce")
    found = [(d.location.line, d.location.column, d.message) for d in analysis.errors if d.location]
    assert (4, 3, "environment 'yard' has no pose 'dok'; did you mean 'dock'?") in found


def test_explore_proposes_it_where_there_is_no_map(base: Scenario, spec: Specification) -> None:
    tasks = {t.id: t for t in spec.tasks}
    proposed = [p.arguments for p in applicable_steps(base, tasks, {"mirror_waypoints"})]
    assert proposed == [(("task", "patrol"), ("about", "dock"))]
    mapped = replace(base, environment=replace(base.environment, map=MapModel("yard_grid")))
    assert applicable_steps(mapped, tasks, {"mirror_waypoints"}) == []  # walls: not proposed
