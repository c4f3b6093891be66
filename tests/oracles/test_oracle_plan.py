"""From acceptance criteria to oracles, and a run's value over a window, on hand-made data."""

from __future__ import annotations

import dataclasses
import math

import pytest

from exsce_dsl.model import (
    Area,
    Assignment,
    Environment,
    Mission,
    MissionType,
    Orientation,
    Pose,
    Position,
    Robot,
    RobotType,
    Scenario,
    Subtask,
    Task,
)
from exsce_dsl.model.acceptance import (
    Acceptance,
    BasicRelation,
    Criterion,
    Expectation,
    Moment,
    Quantifier,
    Quantity,
    Subject,
    When,
    Window,
)
from exsce_dsl.model.metrics import default_topics
from exsce_dsl.oracles.observe import ActionValue, RunValues, observe, parse_window
from exsce_dsl.oracles.plan import plan_oracles, tolerance_of

P = {name: Pose(f"room-{name}", Position(float(i), 0.0), Orientation(), "room") for i, name in enumerate("abcd")}
TIAGO = RobotType("tiago", base="pmb2", torso=True)
SCENARIO = Scenario(
    "s",
    Environment("house", areas=(Area("room", tuple(P.values())),)),
    (Robot("r1", TIAGO, "r1", start_pose=P["a"]), Robot("r2", TIAGO, "ns2", start_pose=P["d"])),
    Mission("m", MissionType.PARALLEL, (Assignment("r1", "t1"), Assignment("r1", "t2"), Assignment("r2", "t2"))),
    (Task("t1", (Subtask((P["b"], P["c"])),)), Task("t2", (Subtask((P["a"],)),))),
)
EACH, R1, MISSION = Subject(Quantifier.EACH_ROBOT), Subject(Quantifier.ROBOT, "r1"), Subject(Quantifier.MISSION)


def test_each_robot_is_an_oracle_per_robot_and_a_when_task_windows_segment_metrics() -> None:
    speed = Expectation(EACH, "max_velocity", BasicRelation.BELOW_MAX, limit=Quantity(1.0, "m/s"))
    r1_speed = Expectation(R1, "max_velocity", BasicRelation.BELOW_MAX, limit=Quantity(0.5, "m/s"))
    visited = Expectation(R1, "waypoints_visited", BasicRelation.INVARIANT)
    mission = Expectation(MISSION, "mission_duration", BasicRelation.INVARIANT)
    acceptance = Acceptance(
        "s",
        (
            Criterion("safe", (), When(mission="m"), (speed, mission)),
            Criterion("task", (), When(robot="r1", task="t1"), (r1_speed, visited)),
        ),
    )
    planned = [(p.criterion, p.metric, p.robot, p.window_text) for p in plan_oracles(acceptance, SCENARIO)]
    assert planned == [
        ("safe", "max_velocity", "r1", None),
        ("safe", "max_velocity", "r2", None),
        ("safe", "mission_duration", None, None),
        ("task", "max_velocity", "r1", "during t1"),  # the criterion's window
        ("task", "waypoints_visited", "r1", None),  # no value per segment: the whole run
    ]


def test_tolerances_in_std_percent_or_absolute_and_the_defaults() -> None:
    assert tolerance_of(Quantity(2.0, "std"), 10.0, 1.5, BasicRelation.INVARIANT) == 3.0
    assert tolerance_of(Quantity(10.0, "%"), -20.0, 1.5, BasicRelation.INVARIANT) == 2.0
    assert tolerance_of(Quantity(0.5, "s"), 10.0, 1.5, BasicRelation.INVARIANT) == 0.5
    assert tolerance_of(None, 10.0, 1.5, BasicRelation.INVARIANT) == 1.5
    assert tolerance_of(None, 10.0, 1.5, BasicRelation.INCREASING) == 0.0


def test_default_topics_follow_the_robot_namespace() -> None:
    assert default_topics(SCENARIO, "max_velocity", "r2") == ("/ns2/nav_vel",)
    assert default_topics(SCENARIO, "mission_duration", None) == (
        "/r1/waypoint_dispatcher/feedback", "/ns2/waypoint_dispatcher/feedback"
    )


def test_default_topics_of_a_robot_at_the_root_have_no_empty_level() -> None:
    """``exscec baseline`` of a robot with ``namespace ""`` failed on '//nav_vel'."""
    at_root = dataclasses.replace(SCENARIO, robots=(dataclasses.replace(SCENARIO.robots[0], namespace=""),))
    assert default_topics(at_root, "max_velocity", "r1") == ("/nav_vel",)
    assert default_topics(at_root, "violation_duration", None) == ("/robot_pose",)


def segment(allocation: int, waypoint: int, goal: str, value: float, metric: str = "distance_travelled") -> ActionValue:
    action = f"run/r1-task_{allocation:02d}-subtask_001-w_{waypoint:03d}"
    return ActionValue(action, "r1", allocation, (allocation, 1, waypoint), f"room-{goal}-R0.00_P0.00_Y0.00", metric, value)


# r1: t1 = a→b (2.0), b→c (3.0); t2 = c→a (5.0); max_velocity 0.5, 0.9, 0.7
VALUES = RunValues(
    "u",
    whole={("distance_travelled", "r1"): [10.0], ("violation_duration", "r1"): [1.0, 2.5]},
    violations={"r1": {"max_velocity", "distance_to_obstacles"}},
    segments=[
        segment(1, 1, "b", 2.0), segment(1, 2, "c", 3.0), segment(2, 1, "a", 5.0),
        segment(1, 1, "b", 0.5, "max_velocity"), segment(1, 2, "c", 0.9, "max_velocity"),
        segment(2, 1, "a", 0.7, "max_velocity"),
    ],
)


@pytest.mark.parametrize(
    ("metric", "window", "expected"),
    [
        ("distance_travelled", None, 10.0),
        ("violation_duration", None, 3.5),  # both safety metrics' seconds
        ("distance_travelled", Window(Moment.DURING, "r1", task="t1"), 5.0),
        ("distance_travelled", Window(Moment.AFTER, "r1", task="t1"), 5.0),
        ("distance_travelled", Window(Moment.BEFORE, "r1", task="t2"), 5.0),
        ("max_velocity", Window(Moment.DURING, "r1", task="t1"), 0.9),
        ("max_velocity", Window(Moment.BEFORE, "r1", pose="room-b"), 0.5),
        ("max_velocity", Window(Moment.AFTER, "r1", pose="room-b"), 0.9),
        ("distance_travelled", Window(Moment.AFTER, "r1", pose="room-c"), 5.0),
    ],
)
def test_a_run_s_value_over_a_window_combines_its_segments(metric: str, window: Window | None, expected: float) -> None:
    value, why = observe(VALUES, metric, "r1", window, SCENARIO)
    assert why == "" and value is not None and math.isclose(value, expected)


def test_an_empty_window_or_a_missing_value_says_why() -> None:
    assert observe(VALUES, "distance_travelled", "r1", Window(Moment.BEFORE, "r1", task="t1"), SCENARIO) == (
        None, "run u has no path segment of 'r1' before t1"
    )
    assert observe(VALUES, "max_velocity", "r2", None, SCENARIO) == (None, "run u has no value of 'max_velocity' of robot 'r2'")


def test_a_violation_total_without_one_safety_metric_is_missing_not_the_sum_of_the_others() -> None:
    without_scan = RunValues(
        "u", whole={("violation_duration", "r1"): [1.0]}, violations={"r1": {"max_velocity"}}
    )
    assert observe(without_scan, "violation_duration", "r1", None, SCENARIO) == (
        None, "run u has no violation duration of 'distance_to_obstacles' of robot 'r1': the total is missing"
    )


def test_a_window_with_a_segment_that_lacks_the_metric_is_missing_not_the_rest_combined() -> None:
    # r1's second segment of t1 (b→c) has a distance, but no max_velocity: its 0.9 might be the max
    lacking = RunValues("u", segments=[s for s in VALUES.segments if (s.metric, s.goal) != ("max_velocity", "room-c-R0.00_P0.00_Y0.00")])
    during_t1 = Window(Moment.DURING, "r1", task="t1")
    assert observe(lacking, "max_velocity", "r1", during_t1, SCENARIO) == (
        None, "run u has no value of 'max_velocity' for 1 of the 2 path segments of 'r1' during t1"
    )
    assert observe(lacking, "distance_travelled", "r1", during_t1, SCENARIO) == (5.0, "")
    assert observe(lacking, "max_velocity", "r1", Window(Moment.AFTER, "r1", task="t1"), SCENARIO) == (0.7, "")


def test_windows_read_back_from_their_text() -> None:
    assert parse_window("during t1") == Window(Moment.DURING, "", task="t1")
    assert parse_window("before r1 reaches room-b") == Window(Moment.BEFORE, "r1", pose="room-b")
    assert parse_window(None) is None
    with pytest.raises(ValueError):
        parse_window("sometime")
