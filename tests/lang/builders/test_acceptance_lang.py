"""Acceptance criteria in the DSL: what they build to, where their mistakes are
reported (a line-number matrix), and that the formatter prints them back."""

from __future__ import annotations

from pathlib import Path

import pytest

from exsce_dsl.lang import analyse, format_spec_document, load_spec
from exsce_dsl.model.acceptance import (
    AtStartPose,
    BaselineRuns,
    BasicRelation,
    Moment,
    Quantifier,
    Quantity,
    Subject,
    When,
    Window,
)

from tests.support.cli import exscec_here
from tests.support.map_files import write_map

SPEC = """\
robot type tiago {
  base pmb2
  torso yes
}

environment env1 {
  map env1 file "map.yaml"
  area room {
    pose room-p1 at (1.0, 1.0)
    pose room-p2 at (2.0, 1.0)
    pose room-p3 at (3.0, 3.0)
  }
}

task go_p3 {
  visit room-p3
}

task go_p1 {
  visit room-p1
}

scenario s1 in env1 {
  robots {
    r1: tiago starts at room-p1
    r2: tiago starts at room-p2
  }
  mission m1 parallel {
    r1 does go_p3 then go_p1
    r2 does go_p1
  }
}

scenario s2 in env1 {
  robots {
    r1: tiago starts at room-p2
  }
  mission m2 sequential {
    r1 does go_p3
  }
}

acceptance for s2 {
  scenario "faster alone" {
    given at least 5 baseline runs
    given each robot at its start pose
    when m2 runs
    then r1 task_duration is decreasing by 500 ms within 1 s of s1
     and r1 distance_travelled is invariant within 10 % of s1
     and r1 max_velocity stays below 90 cm/s before r1 reaches room-p3
  }
  scenario "on the way" {
    when r1 does go_p3
    then r1 distance_to_obstacles stays above 0.2 m during go_p3
     and r1 waypoints_visited is invariant around 1 within 0
     and mission_duration is increasing from 1 min by 6 s
  }
}
"""


@pytest.fixture
def spec_folder(in_tmp: Path) -> Path:
    write_map(in_tmp, occupied=(80, 80, 90, 90))
    (in_tmp / "spec.exsce").write_text(SPEC)
    return in_tmp


def test_the_criteria_build_to_the_model_in_si_units(spec_folder: Path) -> None:
    spec = load_spec("spec.exsce")
    acceptance = spec.acceptance_of("s2")
    assert acceptance is not None and spec.acceptance_of("s1") is None
    assert acceptance.baseline_runs == 5
    faster, on_the_way = acceptance.criteria
    assert faster.title == "faster alone"
    assert faster.givens == (BaselineRuns(5), AtStartPose(Subject(Quantifier.EACH_ROBOT)))
    assert faster.when == When(mission="m2")
    r1 = Subject(Quantifier.ROBOT, "r1")
    duration, distance, speed = faster.expectations
    assert (duration.subject, duration.metric, duration.relation, duration.against) == (
        r1, "task_duration", BasicRelation.DECREASING, "s1"
    )
    assert duration.delta == Quantity(0.5, "ms") and duration.tolerance == Quantity(1.0, "s")
    assert distance.relation is BasicRelation.INVARIANT and distance.tolerance == Quantity(10.0, "%")
    assert speed.relation is BasicRelation.BELOW_MAX and speed.limit == Quantity(0.9, "cm/s")
    assert speed.window == Window(Moment.BEFORE, "r1", pose="room-p3")
    obstacles, visited, mission = on_the_way.expectations
    assert on_the_way.when == When(robot="r1", task="go_p3")
    assert obstacles.window == Window(Moment.DURING, "r1", task="go_p3")
    assert visited.value == Quantity(1.0, None) and visited.tolerance == Quantity(0.0, None)
    assert mission.subject.quantifier is Quantifier.MISSION
    assert (mission.relation, mission.value, mission.delta) == (
        BasicRelation.INCREASING, Quantity(60.0, "min"), Quantity(6.0, "s")
    )
    assert mission.against is None


def test_the_formatter_prints_the_criteria_back(spec_folder: Path) -> None:
    spec = load_spec("spec.exsce")
    text = format_spec_document(spec)
    assert "    then r1 task_duration is decreasing by 500 ms within 1 s of s1\n" in text
    assert "     and r1 max_velocity stays below 90 cm/s before r1 reaches room-p3\n" in text
    assert "     and mission_duration is increasing from 1 min by 6 s\n" in text
    (spec_folder / "again.exsce").write_text(text)
    assert load_spec("again.exsce").acceptance == spec.acceptance


def test_fmt_diff_shows_and_writes_nothing(spec_folder: Path) -> None:
    messy = SPEC.replace("    then r1 task_duration", "  then   r1 task_duration")
    (spec_folder / "spec.exsce").write_text(messy)
    shown = exscec_here("fmt", "--diff", "spec.exsce", cwd=spec_folder)
    assert shown.returncode == 0 and "+    then r1 task_duration" in shown.stdout
    assert (spec_folder / "spec.exsce").read_text() == messy


# (id, text to replace, replacement, line, column, words the message must hold)
CASES = [
    ("unknown-scenario", "acceptance for s2", "acceptance for s3", 43, 16, "unknown scenario 's3'"),
    ("wrong-mission", "when m2 runs", "when m1 runs", 47, 10, "the mission of scenario 's2' is 'm2', not 'm1'"),
    ("robot-not-in-fleet", "then r1 task_duration", "then r2 task_duration", 48, 10, "robot 'r2' is not in the fleet"),
    ("unknown-metric", "r1 distance_travelled", "r1 distance_travel", 49, 13, "unknown metric 'distance_travel'; did you mean"),
    ("wrong-dimension", "below 90 cm/s", "below 90 cm", 50, 10, "'max_velocity' is a speed, in m/s; '90 cm' is a length"),
    ("relative-limit", "below 90 cm/s", "below 1 std", 50, 10, "'1 std' is relative"),
    ("mission-metric-of-robot", "and mission_duration", "and r1 mission_duration", 56, 10, "drop 'r1'"),
    ("robot-metric-of-mission", "and r1 waypoints_visited", "and waypoints_visited", 55, 10, "measured per robot"),
    ("own-scenario-as-base", "within 10 % of s1", "within 10 % of s2", 49, 60, "'of baseline', not 'of s2'"),
    ("changing-without-base", "within 1 s of s1", "within 1 s", 48, 10, "add 'of <scenario>'"),
    ("task-not-of-robot", "when r1 does go_p3", "when r1 does go_p1x", 53, 18, "does not give task 'go_p1x' to 'r1'"),
    ("pose-never-reached", "reaches room-p3", "reaches room-p2", 50, 64, "'r1' never goes to 'room-p2'"),
    ("window-on-mission-metric", "by 6 s", "by 6 s during go_p3", 56, 59, "no value per path segment"),
    ("no-baseline-runs", "at least 5 baseline", "at least 0 baseline", 45, 11, "at least 1 run"),
    ("duplicate-title", '"on the way"', '"faster alone"', 52, 3, 'two acceptance scenarios are called "faster alone"'),
    ("when-task-of-other-robot", "r1 distance_to_obstacles stays above 0.2 m during go_p3",
     "each robot distance_to_obstacles stays above 0.2 m", 54, 10,
     "'when r1 does go_p3' looks at r1's task"),
    ("syntax", "stays above 0.2 m", "stays over 0.2 m", 54, 41, "expected 'below' or 'above', found 'over'"),
]


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_each_mistake_is_reported_at_its_line_and_column(spec_folder: Path, case: tuple) -> None:  # type: ignore[type-arg]
    _, old, new, line, column, words = case
    assert old in SPEC, old
    (spec_folder / "spec.exsce").write_text(SPEC.replace(old, new, 1))
    analysis = analyse("spec.exsce")
    found = [(d.location, d.message) for d in analysis.errors]
    at = [m for loc, m in found if loc is not None and (loc.line, loc.column) == (line, column)]
    assert analysis.spec is None
    assert any(words in m for m in at), f"wanted {words!r} at {line}:{column}, got {found}"


def test_check_prints_acceptance_errors_as_file_line_col(spec_folder: Path) -> None:
    (spec_folder / "spec.exsce").write_text(SPEC.replace("r1 distance_travelled", "r1 distance_travel"))
    result = exscec_here("check", "spec.exsce", cwd=spec_folder)
    assert result.returncode == 2 and "Traceback" not in result.stderr
    assert "spec.exsce:49:13: error: unknown metric 'distance_travel'" in result.stdout + result.stderr
