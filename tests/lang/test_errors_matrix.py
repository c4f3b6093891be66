"""A line-number matrix: each planted mistake, in each construct, is reported
at its own file, line and column (and the others still parse)."""

from __future__ import annotations

from pathlib import Path

import pytest

from exsce_dsl.errors import SourceLocation
from exsce_dsl.lang import analyse

from tests.support.map_files import write_map

SCENARIO = """\
import "env.exsce"
import "tasks.exsce"

robot type tiago {
  base pmb2
  torso yes
}

scenario s1 in env1 {
  robots {
    r1: tiago namespace "r1" starts at room_a-p1
    r2: tiago starts at room_a-p2
  }
  mission m1 parallel {
    r1 does go_b then go_home_1
    r2 does go_b
  }
}
"""

ENV = """\
environment env1 {
  map env1 file "map.yaml"

  area room_a {
    pose room_a-p1 at (1.0, 1.0)
    pose room_a-p2 at (2.0, 1.0)
  }

  area room_b {
    pose room_b-p1 at (3.0, 3.0) facing 1.57
  }
}
"""

TASKS = """\
import "env.exsce"

task go_b {
  visit room_b-p1
}

task go_home_1 {
  visit room_a-p1 facing 0.5
}
"""

FILES = {"scenario.exsce": SCENARIO, "env.exsce": ENV, "tasks.exsce": TASKS}

# (id, file, text to replace, replacement, line, column, words the message must hold)
CASES = [
    ("syntax-missing-colon", "scenario.exsce", "r1: tiago", "r1 tiago", 11, 8, "expected ':'"),
    (
        "syntax-missing-angle",
        "tasks.exsce",
        "facing 0.5",
        "facing",
        9,
        1,
        "expected an angle (a number, in rad unless followed by deg), found '}'",
    ),
    (
        "syntax-bad-keyword",
        "env.exsce",
        "area room_b",
        "aera room_b",
        9,
        3,
        "found 'aera'; did you mean 'area'?",
    ),
    (
        "syntax-keyword-read-as-a-name",
        "scenario.exsce",
        "r2: tiago starts",
        "r2: tiago start",
        12,
        15,
        "expected 'starts', found 'start'; did you mean 'starts'?",
    ),
    (
        "unknown-angle-unit",
        "tasks.exsce",
        "facing 0.5",
        "facing 0.5 degs",
        8,
        30,
        "unknown unit 'degs'; expected deg or rad; did you mean 'deg'?",
    ),
    (
        "unknown-length-unit",
        "env.exsce",
        "(2.0, 1.0)",
        "(2.0 mtr, 1.0)",
        6,
        28,
        "unknown unit 'mtr'; expected m, cm or mm; did you mean 'm'?",
    ),
    (
        "task-of-a-file-not-imported",
        "scenario.exsce",
        'import "tasks.exsce"\n',
        "",
        14,
        13,
        "unknown task 'go_b' (declared in tasks.exsce, which this file does not import)",
    ),
    (
        "unknown-robot-type",
        "scenario.exsce",
        "r2: tiago",
        "r2: tiagp",
        12,
        9,
        "unknown robot type 'tiagp'; did you mean 'tiago'?",
    ),
    (
        "unknown-start-pose",
        "scenario.exsce",
        "at room_a-p2",
        "at room_a-p3",
        12,
        25,
        "unknown pose 'room_a-p3'; did you mean",
    ),
    (
        "unknown-task",
        "scenario.exsce",
        "then go_home_1",
        "then go_hom_1",
        15,
        23,
        "unknown task 'go_hom_1'; did you mean 'go_home_1'?",
    ),
    (
        "robot-not-in-fleet",
        "scenario.exsce",
        "r2 does go_b",
        "r3 does go_b",
        16,
        5,
        "robot 'r3' is not in the fleet of scenario 's1' (its robots: 'r1', 'r2')",
    ),
    (
        "unknown-environment",
        "scenario.exsce",
        "in env1",
        "in env2",
        9,
        16,
        "unknown environment 'env2'; did you mean 'env1'?",
    ),
    ("duplicate-robot", "scenario.exsce", "r2: tiago", "r1: tiago", 12, 5, "duplicate robot 'r1'"),
    (
        "no-start-pose",
        "scenario.exsce",
        "r2: tiago starts at room_a-p2",
        "r2: tiago",
        12,
        5,
        "robot 'r2' has tasks in mission 'm1' but no start pose",
    ),
    (
        "shared-namespace",
        "scenario.exsce",
        "r2: tiago starts",
        'r2: tiago namespace "r1" starts',
        12,
        5,
        "share the namespace 'r1'",
    ),
    (
        "same-start-pose",
        "scenario.exsce",
        "at room_a-p2",
        "at room_a-p1",
        12,
        25,
        "both start at 'room_a-p1'",
    ),
    (
        "empty-mission",
        "scenario.exsce",
        "    r1 does go_b then go_home_1\n    r2 does go_b\n",
        "",
        14,
        11,
        "mission 'm1' allocates no task",
    ),
    (
        "duplicate-robot-type",
        "scenario.exsce",
        "scenario s1",
        "robot type tiago { }\n\nscenario s1",
        9,
        12,
        "duplicate robot type 'tiago' (first declared at scenario.exsce:4:12)",
    ),
    (
        "invalid-namespace",
        "scenario.exsce",
        'namespace "r1"',
        'namespace "r 1"',
        11,
        5,
        "not a valid ROS name",
    ),
    (
        "duplicate-pose",
        "env.exsce",
        "pose room_a-p2",
        "pose room_a-p1",
        6,
        10,
        "duplicate pose 'room_a-p1' in environment 'env1' (first declared at env.exsce:5:10)",
    ),
    ("duplicate-area", "env.exsce", "area room_b", "area room_a", 9, 8, "duplicate area 'room_a'"),
    (
        "pose-outside-map",
        "env.exsce",
        "(3.0, 3.0)",
        "(30.0, 3.0)",
        10,
        10,
        "pose 'room_b-p1' at (30, 3) is outside the map 'env1' (x from 0.00 to 5.00",
    ),
    (
        "pose-in-occupied-cell",
        "env.exsce",
        "(3.0, 3.0)",
        "(4.2, 4.2)",
        10,
        10,
        "is in occupied space of the map 'env1'",
    ),
    ("missing-map-file", "env.exsce", '"map.yaml"', '"nomap.yaml"', 2, 3, "cannot read map file"),
    (
        "unknown-waypoint",
        "tasks.exsce",
        "visit room_b-p1",
        "visit room_b-p9",
        4,
        9,
        "unknown pose 'room_b-p9'; did you mean 'room_b-p1'?",
    ),
    (
        "empty-task",
        "tasks.exsce",
        "  visit room_a-p1 facing 0.5\n",
        "",
        7,
        6,
        "task 'go_home_1' has no waypoints",
    ),
    (
        "empty-subtask",
        "tasks.exsce",
        "  visit room_b-p1\n",
        "  subtask { visit room_b-p1 }\n  subtask { }\n",
        5,
        3,
        "subtask 2 of task 'go_b' has no waypoints",
    ),
    (
        "timeout-without-unit",
        "tasks.exsce",
        "task go_b {\n",
        "task go_b {\n  timeout 120\n",
        4,
        11,
        "the timeout of task 'go_b' has no unit; write '120 s' or '120 min'",
    ),
    (
        "timeout-not-above-zero",
        "scenario.exsce",
        "  mission m1 parallel {\n",
        "  mission m1 parallel {\n    timeout -2 min\n",
        15,
        13,
        "the timeout of mission 'm1' must be above 0 s, not -2 min",
    ),
    (
        "timeout-zero",
        "tasks.exsce",
        "task go_home_1 {\n",
        "task go_home_1 {\n  timeout 0s\n",
        8,
        11,
        "the timeout of task 'go_home_1' must be above 0 s, not 0 s",
    ),
    (
        "duplicate-task",
        "tasks.exsce",
        "task go_home_1",
        "task go_b",
        7,
        6,
        "duplicate task 'go_b' (first declared at tasks.exsce:3:6)",
    ),
    (
        "missing-import",
        "scenario.exsce",
        '"tasks.exsce"',
        '"taskz.exsce"',
        2,
        1,
        "imported file 'taskz.exsce' not found (looked for taskz.exsce); did you mean 'tasks.exsce'?",
    ),
    (
        "window-stated-twice",
        "scenario.exsce",
        "  torso yes\n",
        "  torso yes\n  window goals\n  window whole recording\n",
        8,
        3,
        "robot type 'tiago' states its window twice",
    ),
    (
        "motion-stated-twice",
        "scenario.exsce",
        "  torso yes\n",
        "  torso yes\n  motion 3d\n  motion planar\n",
        8,
        3,
        "robot type 'tiago' states its motion twice",
    ),
    (
        "unknown-motion",
        "scenario.exsce",
        "  torso yes\n",
        "  torso yes\n  motion flying\n",
        7,
        10,
        "expected 'planar' or '3d', found 'flying'",
    ),
]


def _plant(folder: Path, file: str, old: str, new: str) -> None:
    write_map(folder, occupied=(80, 80, 90, 90))
    for name, text in FILES.items():
        if name == file:
            assert old in text, f"the base text of {name} lacks {old!r}"
            text = text.replace(old, new, 1)
        (folder / name).write_text(text)


def test_base_specification_is_clean(in_tmp: Path) -> None:
    _plant(in_tmp, "", "", "")
    analysis = analyse("scenario.exsce")
    assert analysis.errors == []
    assert analysis.spec is not None


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_error_is_reported_at_its_line_and_column(in_tmp: Path, case: tuple) -> None:
    _, file, old, new, line, column, words = case
    _plant(in_tmp, file, old, new)
    analysis = analyse("scenario.exsce")
    assert analysis.spec is None
    found = [(d.location, d.message) for d in analysis.errors]
    at = [
        msg
        for loc, msg in found
        if loc is not None and (loc.file, loc.line, loc.column) == (file, line, column)
    ]
    assert any(words in msg for msg in at), f"wanted {words!r} at {file}:{line}:{column}, got {found}"


def test_every_error_is_reported_not_only_the_first(in_tmp: Path) -> None:
    _plant(in_tmp, "scenario.exsce", "r2: tiago starts at room_a-p2", "r2: tiagp starts at room_a-p9")
    (in_tmp / "tasks.exsce").write_text(TASKS.replace("visit room_b-p1", "visit room_b-p7"))
    analysis = analyse("scenario.exsce")
    messages = [(str(d.location), d.message.split(";")[0]) for d in analysis.errors]
    assert ("scenario.exsce:12:9", "unknown robot type 'tiagp'") in messages
    assert ("scenario.exsce:12:25", "unknown pose 'room_a-p9'") in messages
    assert ("tasks.exsce:4:9", "unknown pose 'room_b-p7'") in messages


def test_a_syntax_error_in_one_file_does_not_hide_errors_in_another(in_tmp: Path) -> None:
    _plant(in_tmp, "tasks.exsce", "task go_b {", "task go_b")
    (in_tmp / "scenario.exsce").write_text(SCENARIO.replace("r2: tiago", "r2: tiagp"))
    locations = {str(d.location) for d in analyse("scenario.exsce").errors}
    assert "scenario.exsce:12:9" in locations
    assert any(loc.startswith("tasks.exsce:4:") for loc in locations)


def test_reference_errors_carry_the_span_of_the_name(in_tmp: Path) -> None:
    _plant(in_tmp, "scenario.exsce", "then go_home_1", "then go_hom_1")
    [error] = [d for d in analyse("scenario.exsce").errors if "go_hom_1" in d.message]
    assert error.location == SourceLocation("scenario.exsce", 15, 23, 15, 31)
