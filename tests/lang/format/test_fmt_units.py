"""`exscec fmt` keeps every quantity as its author wrote it: the number and the unit
(`200 cm` stays `200 cm`, `90 deg` stays `90 deg`, a bare number stays bare), in each
place the grammar takes one (issue 19, stumble 4: lengths used to come out in metres)."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from exsce_dsl.lang import format_document, format_spec_document, load_spec
from exsce_dsl.model import Area, Document, Environment, Orientation, Pose, Position

from tests.support.cli import exscec_here

# Canonical text: `exscec fmt` must leave it as it is.
SPEC = """\
robot type rover {
  convention nav2
  arrival within 30 cm and 10 deg
}

environment yard {
  area north {
    pose a at (7 m, 200 cm) facing 90 deg
    pose b at (1.5, 250 mm, 0.5 m) rpy (0.1 rad, 5 deg, 1.5 rad)
    pose c at (3, 4)
  }

  obstacle box model "crate" at (2 m, 3 m) facing 45 deg size (50 cm, 0.5, 1 m)
}

task go {
  visit a facing 1.5 rad
  visit b
  visit (120 cm, 3 m) facing -30 deg
}

metric fast_time for each robot per segment {
  "seconds spent faster than 80 cm/s"
  unit s
  reads vel: geometry_msgs/msg/Twist on "/{ns}/nav_vel"
  value duration where norm(vel.linear.x, vel.linear.y) > 80 cm/s
}

metric top_speed for each robot per segment {
  "largest linear speed"
  unit m/s
  safe below 150 cm/s
  reads vel: geometry_msgs/msg/Twist on "/{ns}/nav_vel"
  value max(norm(vel.linear.x, vel.linear.y))
}

scenario s in yard {
  robots {
    r1: rover starts at a {
      arrival within 500 mm
    }
    r2: rover starts at c
  }
  mission m parallel {
    r1 does go
    r2 does go
  }
}

acceptance for s {
  scenario "safe" {
    then each robot max_velocity stays below 100 cm/s
     and each robot distance_to_obstacles stays above 10 cm
  }
  scenario "steady" {
    given at least 3 baseline runs
    then each robot task_duration is invariant around 2 min within 3 std
     and mission_duration is increasing from 1 min by 6 s within 500 ms
  }
}

derive s_moved from s {
  move obstacle box to (250 cm, 3.5 m)
}
"""

# (place, the line as it must be printed)
PLACES = [
    ("pose position and facing", "pose a at (7 m, 200 cm) facing 90 deg"),
    ("pose with z and rpy", "pose b at (1.5, 250 mm, 0.5 m) rpy (0.1 rad, 5 deg, 1.5 rad)"),
    ("bare numbers", "pose c at (3, 4)"),
    (
        "obstacle position, heading and size",
        'obstacle box model "crate" at (2 m, 3 m) facing 45 deg size (50 cm, 0.5, 1 m)',
    ),
    ("another heading for a pose", "visit a facing 1.5 rad"),
    ("coordinate waypoint", "visit (120 cm, 3 m) facing -30 deg"),
    ("robot type arrival tolerance", "arrival within 30 cm and 10 deg"),
    ("robot's own arrival tolerance", "arrival within 500 mm"),
    ("metric literal", "> 80 cm/s"),
    ("metric safety limit", "safe below 150 cm/s"),
    ("acceptance limit", "stays below 100 cm/s"),
    ("acceptance limit in a length", "stays above 10 cm"),
    ("acceptance around and within", "is invariant around 2 min within 3 std"),
    ("acceptance from, by and within", "is increasing from 1 min by 6 s within 500 ms"),
    ("derive move obstacle", "move obstacle box to (250 cm, 3.5 m)"),
]


@pytest.fixture
def spec_file(in_tmp: Path) -> Path:
    path = in_tmp / "units.exsce"
    path.write_text(SPEC)
    return path


@pytest.mark.parametrize(("place", "line"), PLACES, ids=[p for p, _ in PLACES])
def test_fmt_prints_the_quantity_as_written(spec_file: Path, place: str, line: str) -> None:
    assert line in SPEC, f"the specification lacks the {place}"
    printed = format_spec_document(load_spec(spec_file), "units.exsce")
    assert line in printed, f"{place}: {line!r} not printed as written:\n{printed}"


def test_exscec_fmt_leaves_a_file_with_units_unchanged(spec_file: Path) -> None:
    checked = exscec_here("fmt", "--check", "units.exsce", cwd=spec_file.parent)
    assert checked.returncode == 0, checked.stderr
    result = exscec_here("fmt", "units.exsce", cwd=spec_file.parent)
    assert result.returncode == 0, result.stderr
    assert spec_file.read_text() == SPEC


def test_exscec_fmt_puts_one_space_between_number_and_unit(spec_file: Path) -> None:
    messy = (
        SPEC.replace("(7 m, 200 cm) facing 90 deg", "(7m,200cm) facing 90deg")
        .replace("30 cm and 10 deg", "30cm and 10deg")
        .replace("size (50 cm, 0.5, 1 m)", "size (50cm,0.5,1m)")
        .replace("> 80 cm/s", "> 80cm/s")
        .replace("safe below 150 cm/s", "safe below 150cm/s")
        .replace("stays below 100 cm/s", "stays below 100cm/s")
        .replace("(250 cm, 3.5 m)", "(250cm,3.5m)")
    )
    assert messy != SPEC
    spec_file.write_text(messy)
    result = exscec_here("fmt", "units.exsce", cwd=spec_file.parent)
    assert result.returncode == 0, result.stderr
    assert spec_file.read_text() == SPEC


def test_the_model_holds_si_values_beside_the_written_text(spec_file: Path) -> None:
    spec = load_spec(spec_file)
    env = spec.environments[0]
    a, b, c = env.areas[0].poses
    assert (a.position.x, a.position.y) == (7.0, 2.0)
    assert a.orientation.yaw == math.pi / 2
    assert (b.position.y, b.position.z) == (0.25, 0.5)
    assert b.orientation.pitch == math.radians(5)
    assert (c.position.x, c.position.y) == (3.0, 4.0)
    assert env.obstacles[0].size == (0.5, 0.5, 1.0)
    rover = spec.robot_types[0]
    assert rover.signals is not None
    assert rover.signals.tolerance.position == pytest.approx(0.3)
    assert rover.signals.tolerance.heading == pytest.approx(math.radians(10))
    metric = next(m for m in spec.root_document.declarations if getattr(m, "name", None) == "top_speed")
    assert metric.safety.limit == pytest.approx(1.5)
    (derived,) = spec.derived
    assert derived.steps[0].argument("to") == "2.5,3.5"  # the transformation's argument, in metres


def test_parse_print_parse_gives_the_same_model(spec_file: Path) -> None:
    spec = load_spec(spec_file)
    printed = format_spec_document(spec, "units.exsce")
    again = load_spec(spec_file, overlay={"units.exsce": printed})
    assert again.root_document == spec.root_document


def test_a_value_changed_since_it_was_read_is_printed_from_the_value() -> None:
    # the written text rides along the model; a transformation that makes a new value must not
    # be printed with the old text
    stale = Pose(
        "p",
        Position(1.0, 2.0, 0.0, "cm", written=("7 m", "200 cm")),
        Orientation(yaw=0.5, unit="deg", written=("90 deg",)),
        "a",
    )
    text = format_document(Document("x.exsce", (), (Environment("e", areas=(Area("a", (stale,)),)),)), {})
    assert "pose p at (100.0 cm, 200.0 cm) facing 0.5" in text
    assert "7 m" not in text and "90 deg" not in text


_numbers = st.one_of(
    st.integers(-9999, 9999).map(str),
    st.tuples(st.integers(-999, 999), st.integers(0, 999)).map(lambda p: f"{p[0]}.{p[1]}"),
)


@settings(max_examples=60, deadline=None)
@given(
    x=_numbers,
    y=_numbers,
    length_units=st.tuples(*(st.sampled_from(["", " m", " cm", " mm"]) for _ in range(2))),
    yaw=_numbers,
    angle_unit=st.sampled_from(["", " deg", " rad"]),
)
def test_any_number_and_unit_is_printed_as_written(
    tmp_path_factory: pytest.TempPathFactory,
    x: str,
    y: str,
    length_units: tuple[str, str],
    yaw: str,
    angle_unit: str,
) -> None:
    assume(float(yaw) != 0.0)  # facing 0 is no heading at all, and is not printed
    line = f"pose p at ({x}{length_units[0]}, {y}{length_units[1]}) facing {yaw}{angle_unit}"
    path = tmp_path_factory.mktemp("units") / "p.exsce"
    path.write_text(f"environment e {{\n  area a {{\n    {line}\n  }}\n}}\n")
    spec = load_spec(path)
    assert f"    {line}\n" in format_spec_document(spec, spec.root_document.path)
