"""The formatter: parse → print → parse gives an equal model, and printing is idempotent."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from exsce_dsl.lang import (
    analyse,
    comments,
    declared_poses,
    display_path,
    format_document,
    format_spec_document,
    load_spec,
)
from exsce_dsl.model import (
    Area,
    Assignment,
    Document,
    Environment,
    Mission,
    MissionType,
    Orientation,
    Pose,
    Position,
    Robot,
    RobotType,
    RosResource,
    Scenario,
    Subtask,
    Task,
)
from exsce_dsl.model.names import KEYWORDS

from tests.support.paths import EXAMPLES

EXAMPLE_FILES = sorted(EXAMPLES.rglob("*.exsce"))


def test_there_are_examples_to_check() -> None:
    names = {p.name for p in EXAMPLE_FILES}
    assert {"scenario_c.exsce", "environment.exsce", "orchard.exsce"} <= names


@pytest.mark.parametrize("path", EXAMPLE_FILES, ids=[str(p.relative_to(EXAMPLES)) for p in EXAMPLE_FILES])
def test_example_round_trips(path: Path) -> None:
    spec = load_spec(path)
    source = display_path(path)
    text = path.read_text()
    printed = format_spec_document(spec, source, comments(text, source))
    assert printed == text, "examples are kept in canonical form (run exscec fmt)"
    again = load_spec(path, overlay={source: printed})
    assert again.root_document == spec.root_document
    assert format_spec_document(again, source, comments(printed, source)) == printed


def test_formatting_keeps_comments_where_they_were(in_tmp: Path) -> None:
    messy = (
        "// the robots\n"
        "robot type tiago { base pmb2 // a PAL base\n"
        "  torso yes }\n"
        "environment e { area a {\n"
        "  /* the door */ pose a-p1 at (1, 2)\n"
        "  // second pose\n"
        "  pose a-p2 at (3, 4) } }\n"
    )
    (in_tmp / "x.exsce").write_text(messy)
    spec = load_spec("x.exsce")
    printed = format_spec_document(spec, "x.exsce", comments(messy, "x.exsce"))
    assert printed == (
        "// the robots\n"
        "robot type tiago {  // a PAL base\n"
        "  base pmb2\n"
        "  torso yes\n"
        "}\n"
        "\n"
        "environment e {\n"
        "  area a {\n"
        "    pose a-p1 at (1, 2)  /* the door */\n"
        "    // second pose\n"
        "    pose a-p2 at (3, 4)\n"
        "  }\n"
        "}\n"
    )


def test_units_are_kept_as_written(in_tmp: Path) -> None:
    (in_tmp / "u.exsce").write_text(
        "environment e { area a { pose a-p at (150 cm, 20 cm) facing 90 deg } }\n"
    )
    spec = load_spec("u.exsce")
    pose = spec.environments[0].areas[0].poses[0]
    assert (pose.position.x, pose.position.y) == (1.5, 0.2)
    assert pose.orientation.yaw == math.pi / 2
    printed = format_spec_document(spec, "u.exsce")
    assert "pose a-p at (150 cm, 20 cm) facing 90 deg" in printed


def test_timeouts_are_kept_as_written_and_read_in_seconds(in_tmp: Path) -> None:
    (in_tmp / "t.exsce").write_text(
        "robot type r { }\n"
        "environment e { area a { pose a-p at (1, 2) } }\n"
        "task t { timeout 2 min visit a-p }\n"
        "task u { visit a-p }\n"
        "scenario s in e { robots { r1: r starts at a-p } mission m parallel { timeout   90s r1 does t then u } }\n"
    )
    spec = load_spec("t.exsce")
    scenario = spec.scenario("s")
    assert (scenario.task("t").timeout, scenario.task("u").timeout, scenario.mission.timeout) == (
        120.0,
        None,
        90.0,
    )
    printed = format_spec_document(spec, "t.exsce")
    assert "task t {\n  timeout 2 min\n  visit a-p\n}" in printed
    assert "mission m parallel {\n    timeout 90 s\n    r1 does t then u\n  }" in printed
    assert "timeout" not in printed.split("task u {")[1].split("}")[0]


# ---------------------------------------------------------------- property test
_names = st.from_regex(r"[a-z][a-z0-9_]{0,6}(-[a-z0-9]{1,3})?", fullmatch=True).filter(
    lambda n: n not in KEYWORDS
)
_coordinates = st.floats(-1e5, 1e5, allow_nan=False, allow_infinity=False)
_degrees = st.integers(-3600, 3600).map(lambda tenths: tenths / 10)
_timeouts = st.none() | st.integers(1, 10**5).map(float) | st.floats(1e-3, 1e6, allow_nan=False)


@st.composite
def _orientations(draw: st.DrawFn) -> Orientation:
    if draw(st.booleans()):
        return Orientation(0.0, 0.0, math.radians(draw(_degrees)), "deg")
    values = draw(st.lists(st.floats(-3.2, 3.2, allow_nan=False), min_size=3, max_size=3))
    if draw(st.booleans()):
        values[0] = values[1] = 0.0
    return Orientation(*values)


@st.composite
def _positions(draw: st.DrawFn) -> Position:
    if draw(st.booleans()):
        x, y, z = (draw(st.integers(-(10**6), 10**6)) for _ in range(3))
        return Position(x * 0.01, y * 0.01, z * 0.01 if draw(st.booleans()) else 0.0, "cm")
    z = draw(_coordinates) if draw(st.booleans()) else 0.0
    return Position(draw(_coordinates), draw(_coordinates), z)


@st.composite
def documents(draw: st.DrawFn) -> Document:
    ids = draw(st.lists(_names, min_size=15, max_size=20, unique=True))
    area_ids, pose_ids, other = ids[:2], ids[2:7], ids[7:]
    poses = [
        Pose(p, draw(_positions()), draw(_orientations()), area_ids[i % 2]) for i, p in enumerate(pose_ids)
    ]
    areas = tuple(Area(a, tuple(p for p in poses if p.area == a)) for a in area_ids)
    env = Environment(other[0], areas=areas)
    rtype = RobotType(other[1], draw(st.none() | _names), draw(st.none() | st.booleans()))
    tasks = []
    for t in other[2:4]:
        subtasks = []
        for _ in range(draw(st.integers(1, 3))):
            chosen = draw(st.lists(st.sampled_from(poses), min_size=1, max_size=4))
            waypoints = tuple(
                p.with_orientation(draw(_orientations())) if draw(st.booleans()) else p for p in chosen
            )
            subtasks.append(Subtask(waypoints))
        source = RosResource(draw(_names), draw(st.none() | st.just("config/x.yaml")))
        tasks.append(
            Task(t, tuple(subtasks), source if draw(st.booleans()) else None, timeout=draw(_timeouts))
        )
    robots = (
        Robot(other[4], rtype, "ns_" + other[4].replace("-", "_"), poses[0]),
        Robot(
            other[5],
            rtype,
            "ns_" + other[5].replace("-", "_"),
            poses[1].with_orientation(Orientation(0, 0, 1.0)),
        ),
    )
    allocation = tuple(
        Assignment(
            draw(st.sampled_from([r.id for r in robots])),
            draw(st.sampled_from([t.id for t in tasks])),
        )
        for _ in range(draw(st.integers(1, 5)))
    ) + tuple(Assignment(r.id, tasks[0].id) for r in robots)
    first_use = list(dict.fromkeys(a.task for a in allocation))
    used = tuple(sorted((t for t in tasks if t.id in first_use), key=lambda t: first_use.index(t.id)))
    mission = Mission(other[6], draw(st.sampled_from(list(MissionType))), allocation, timeout=draw(_timeouts))
    scenario = Scenario(other[7], env, robots, mission, used)
    return Document("gen.exsce", (), (rtype, env, *tasks, scenario))


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(documents())
def test_print_then_parse_gives_the_same_model(document: Document) -> None:
    env = next(d for d in document.declarations if isinstance(d, Environment))
    text = format_document(document, declared_poses([env]))
    analysis = analyse("gen.exsce", overlay={"gen.exsce": text})
    assert analysis.errors == [], text
    assert analysis.spec is not None
    assert analysis.spec.root_document.declarations == document.declarations
    assert format_document(analysis.spec.root_document, declared_poses([env])) == text
