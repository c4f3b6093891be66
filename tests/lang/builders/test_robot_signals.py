"""Where a robot's signals are: a robot type's convention and the sources it overrides.

Checked from the language's side: what the IR holds, the located errors, and
that the formatter prints what parses back to the same model.
"""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from exsce_dsl.codegen.ros_monitor import ros1_monitor_files
from exsce_dsl.errors import ExsceError, SpecError
from exsce_dsl.lang import comments, display_path, format_spec_document, load_spec
from exsce_dsl.model.conventions import (
    METHOD,
    MOVE_BASE,
    NAV2,
    Navigation,
    TfSource,
    Tolerance,
    TopicSource,
)

TURTLEBOT = """\
robot type turtlebot4 {
  base diff_drive
  convention nav2
  pose from tf map -> base_footprint
  pose on "/{ns}/odom" nav_msgs/msg/Odometry
  velocity on "/{ns}/cmd_vel_nav" geometry_msgs/msg/TwistStamped
  scan on "/{ns}/scan_filtered"
  navigation nav2 on "/{ns}/follow_waypoints"
  arrival within 30 cm and 10 deg
}
"""


def _types(tmp_path: Path, text: str) -> dict[str, object]:
    path = tmp_path / "robots.exsce"
    path.write_text(text)
    spec = load_spec(path)
    return {t.id: t for t in spec.robot_types}


def _error(tmp_path: Path, text: str) -> str:
    path = tmp_path / "robots.exsce"
    path.write_text(text)
    with pytest.raises(SpecError) as caught:
        load_spec(path)
    return str(caught.value)


def test_a_robot_type_that_says_nothing_follows_the_method(tmp_path: Path) -> None:
    (tiago,) = _types(tmp_path, "robot type tiago {\n  base pmb2\n}\n").values()
    assert tiago.declared_signals is None  # type: ignore[attr-defined]
    assert tiago.signals == METHOD  # type: ignore[attr-defined]
    assert METHOD.navigation is Navigation.DISPATCHER


@pytest.mark.parametrize("word, convention", [("nav2", NAV2), ("move_base", MOVE_BASE), ("method", METHOD)])
def test_a_convention_in_one_word(tmp_path: Path, word: str, convention: object) -> None:
    (robot,) = _types(tmp_path, f"robot type r {{\n  convention {word}\n}}\n").values()
    assert robot.signals == convention  # type: ignore[attr-defined]


def test_each_line_overrides_its_signal_and_keeps_the_rest(tmp_path: Path) -> None:
    (robot,) = _types(tmp_path, TURTLEBOT).values()
    signals = robot.signals  # type: ignore[attr-defined]
    assert signals.convention == "nav2"
    assert signals.pose == (
        TfSource("map", "base_footprint"),
        TopicSource("/{ns}/odom", "nav_msgs/msg/Odometry"),
    )
    assert signals.velocity == (TopicSource("/{ns}/cmd_vel_nav", "geometry_msgs/msg/TwistStamped"),)
    assert signals.scan == (TopicSource("/{ns}/scan_filtered"),)
    assert (signals.navigation, signals.actions) == (Navigation.NAV2, ("/{ns}/follow_waypoints",))
    assert signals.tolerance.position == pytest.approx(0.3)
    assert signals.tolerance.heading == pytest.approx(math.radians(10))
    assert signals.distance == NAV2.distance  # not said: the convention's


def test_navigation_without_actions_takes_its_interfaces_defaults(tmp_path: Path) -> None:
    (robot,) = _types(tmp_path, "robot type r {\n  navigation move_base\n}\n").values()
    signals = robot.signals  # type: ignore[attr-defined]
    assert signals.convention == "method"  # the rest is the method's
    assert (signals.navigation, signals.actions) == (Navigation.MOVE_BASE, ("/{ns}/move_base",))
    assert signals.pose == METHOD.pose


def test_arrival_defaults_to_nav2s_goal_tolerance_with_localisation_and_no_heading() -> None:
    assert Tolerance() == Tolerance(0.35, None)


@pytest.mark.parametrize(
    "line, column, message",
    [
        ('pose on "/{ns}/odom" sensor_msgs/msg/Imu', 8, "a pose is read from nav_msgs/msg/Odometry"),
        ('velocity on "/{ns}/cmd vel"', 12, "'/{ns}/cmd vel' is not a ROS topic name"),
        (
            'scan on "/{ns}/scan" sensor_msgs/msg/PointCloud2',
            8,
            "a laser scan is read from sensor_msgs/msg/LaserScan",
        ),
        ("arrival within 0 m", 3, "an arrival tolerance is a distance (and an angle) above zero"),
        ('navigation nav2 on "/{x}/go"', 3, "'/{x}/go' is not a ROS topic name"),
    ],
)
def test_a_wrong_source_is_a_located_error(tmp_path: Path, line: str, column: int, message: str) -> None:
    text = f"robot type r {{\n  convention nav2\n  {line}\n}}\n"
    error = _error(tmp_path, text)
    assert f"robots.exsce:3:{column}:" in error and message in error, error


@pytest.mark.parametrize(
    "lines, said",
    [
        (["convention nav2", "convention move_base"], "names its convention twice"),
        (["navigation nav2", "navigation none"], "states its navigation twice"),
        (["arrival within 1 m", "arrival within 2 m"], "states its arrival tolerance twice"),
    ],
)
def test_a_signal_said_twice_is_an_error_at_the_second(tmp_path: Path, lines: list[str], said: str) -> None:
    body = "".join(f"  {line}\n" for line in lines)
    error = _error(tmp_path, f"robot type r {{\n{body}}}\n")
    assert "robots.exsce:3:3:" in error and said in error, error


def test_an_unknown_convention_is_a_syntax_error_listing_the_choices(tmp_path: Path) -> None:
    error = _error(tmp_path, "robot type r {\n  convention ros2\n}\n")
    assert "robots.exsce:2:14" in error, error
    assert all(word in error for word in ("method", "nav2", "move_base")), error


@pytest.mark.parametrize(
    "body",
    [
        TURTLEBOT,
        "robot type r {\n  convention move_base\n}\n",
        "robot type r {\n  torso no\n  navigation none\n  arrival within 0.5 m\n}\n",
        'robot type r {\n  pose on "/{ns}/amcl_pose"\n  velocity on "/{ns}/odom" nav_msgs/msg/Odometry\n}\n',
    ],
)
def test_the_formatter_prints_what_parses_back_to_the_same_model(tmp_path: Path, body: str) -> None:
    path = tmp_path / "robots.exsce"
    path.write_text(body)
    spec = load_spec(path)
    source = display_path(path)
    printed = format_spec_document(spec, source, comments(body, source))
    again = load_spec(path, overlay={source: printed})
    assert again.root_document == spec.root_document
    assert [t.signals for t in again.robot_types] == [t.signals for t in spec.robot_types]
    assert format_spec_document(again, source, comments(printed, source)) == printed


def test_the_bags_pages_robot_types_check(tmp_path: Path) -> None:
    """The robot types docs/bags.md shows are valid, with the sources the page says."""
    page = (Path(__file__).resolve().parents[3] / "docs" / "bags.md").read_text()
    section = page[page.index("## Conventions") :]
    block = section.split("```")[1].removeprefix("exsce\n")
    robot_types = _types(tmp_path, block)
    husky = robot_types["husky"].signals  # type: ignore[attr-defined]
    assert husky.navigation is Navigation.MOVE_BASE and husky.tolerance.position == 0.5
    assert husky.velocity == (TopicSource("/{ns}/husky_velocity_controller/cmd_vel"),)
    assert robot_types["turtlebot4"].signals.pose == (TfSource("map", "base_footprint"),)  # type: ignore[attr-defined]
    assert robot_types["custom"].signals.navigation is Navigation.NONE  # type: ignore[attr-defined]


SCENE = """\
environment yard {
  area yard {
    pose yard-a at (0.0, 0.0)
    pose yard-b at (5.0, 0.0)
  }
}

robot type rover {
  base diff_drive
  convention nav2
}

task go {
  visit yard-b
}

scenario s in yard {
  robots {
    r1: rover starts at yard-a OVERRIDE
  }
  mission m parallel {
    r1 does go
  }
}
"""


def _robot(tmp_path: Path, override: str) -> object:
    path = tmp_path / "scene.exsce"
    path.write_text(SCENE.replace("OVERRIDE", override))
    return load_spec(path).scenario().robots[0]


def test_a_robot_overrides_its_types_sources_for_itself(tmp_path: Path) -> None:
    robot = _robot(tmp_path, '{\n      pose on "/{ns}/ground_truth" nav_msgs/msg/Odometry\n    }')
    signals = robot.signals  # type: ignore[attr-defined]
    assert signals.pose == (TopicSource("/{ns}/ground_truth", "nav_msgs/msg/Odometry"),)
    assert (signals.convention, signals.velocity) == ("nav2", NAV2.velocity)  # the rest is its type's
    assert robot.type.signals == NAV2  # type: ignore[attr-defined]  # the type is unchanged
    other = _robot(tmp_path, "{\n      convention move_base\n    }")
    assert other.signals == MOVE_BASE  # type: ignore[attr-defined]
    plain = _robot(tmp_path, "")
    assert plain.declared_signals is None and plain.signals == NAV2  # type: ignore[attr-defined]


def test_a_robots_override_is_formatted_back_to_the_same_model(tmp_path: Path) -> None:
    path = tmp_path / "scene.exsce"
    path.write_text(SCENE.replace("OVERRIDE", "{ arrival within 50 cm  navigation none }"))
    spec = load_spec(path)
    source = display_path(path)
    printed = format_spec_document(spec, source, comments(path.read_text(), source))
    assert (
        "    r1: rover starts at yard-a {\n      navigation none\n      arrival within 50 cm\n    }\n"
        in printed
    )
    again = load_spec(path, overlay={source: printed})
    assert again.root_document == spec.root_document
    assert again.scenario().robots[0].signals == spec.scenario().robots[0].signals


def test_a_robots_override_is_checked_at_its_place(tmp_path: Path) -> None:
    path = tmp_path / "scene.exsce"
    path.write_text(
        SCENE.replace("OVERRIDE", '{\n      velocity on "/{ns}/cmd_vel" std_msgs/msg/Float64\n    }')
    )
    with pytest.raises(SpecError) as caught:
        load_spec(path)
    assert "scene.exsce:20:16:" in str(caught.value) and "a velocity is read from" in str(caught.value)


SIGNAL_METRIC = """
metric furthest_east for SUBJECT {
  unit m
  reads pose: robot pose
  value max(pose.x)
}
"""


def test_a_metric_reading_a_signal_checks_its_fields_and_formats_back(tmp_path: Path) -> None:
    path = tmp_path / "scene.exsce"
    path.write_text(SCENE.replace("OVERRIDE", "") + SIGNAL_METRIC.replace("SUBJECT", "each robot"))
    spec = load_spec(path)
    (read,) = spec.metrics[0].reads
    assert (read.signal, read.msgtype, read.topic) == ("pose", "exsce_msgs/msg/RobotPose", "/{ns}/~pose")
    source = display_path(path)
    printed = format_spec_document(spec, source, comments(path.read_text(), source))
    assert "  reads pose: robot pose\n" in printed
    assert load_spec(path, overlay={source: printed}).root_document == spec.root_document
    path.write_text(
        SCENE.replace("OVERRIDE", "")
        + SIGNAL_METRIC.replace("SUBJECT", "each robot").replace("pose.x", "pose.heading")
    )
    with pytest.raises(SpecError, match=r"has no field 'heading'"):
        load_spec(path)


def test_a_signal_is_a_robots_not_the_missions(tmp_path: Path) -> None:
    path = tmp_path / "scene.exsce"
    path.write_text(SCENE.replace("OVERRIDE", "") + SIGNAL_METRIC.replace("SUBJECT", "mission"))
    with pytest.raises(SpecError, match="the robot's pose is read for each robot or each pair of robots"):
        load_spec(path)


def test_live_monitors_read_a_signal_from_the_methods_topic(tmp_path: Path) -> None:
    """A live node subscribes to the method's pose topic for ``robot pose`` (its values:
    tests/codegen/test_live_signals.py); a pose's yaw, computed at ingest, it refuses."""
    path = tmp_path / "scene.exsce"
    path.write_text(SCENE.replace("OVERRIDE", "") + SIGNAL_METRIC.replace("SUBJECT", "each robot"))
    files = ros1_monitor_files(load_spec(path), None)
    config = next(text for name, text in files.items() if str(name).endswith("config.py"))
    assert '"signals": ("/r1/~pose",)' in config
    path.write_text(path.read_text().replace("max(pose.x)", "max(pose.yaw)"))
    with pytest.raises(ExsceError, match="its yaw is computed at ingest only"):
        ros1_monitor_files(load_spec(path), None)
