"""Path segments from navigation goals and from arrival, on scenario_c's plan for tiago1.

tiago1 starts at S = classroom_c025-w001 and is to visit W1 = classroom_c022-w001 and
W2 = classroom_c018-w001 (delivery_a), then W3 = classroom_c025-w001 facing 0.925 (navigate_home_1):
W3 is where it starts.  Goals and tracks are built by hand; the expected times are read off them.
"""

from __future__ import annotations

import math
from operator import attrgetter

import numpy as np
import pytest

from exsce_dsl.errors import SegmentError
from exsce_dsl.lang import load_spec
from exsce_dsl.model import Pose, Position, Scenario
from exsce_dsl.model.conventions import Tolerance
from exsce_dsl.runs.segments.arrival import arrival_segments
from exsce_dsl.runs.segments.goals import goal_segments
from exsce_dsl.runs.segments.track import Segmentation, Track, near, planned_waypoints
from exsce_dsl.runs.signals.navigation_goals import RecordedGoal

from tests.support.paths import EXAMPLES

R = "tiago1"
S_ID = W3_ID = "classroom_c025-w001"
W1_ID, W2_ID = "classroom_c022-w001", "classroom_c018-w001"
ROW = ("robot", "allocation", "task", "subtask", "waypoint", "start_pose.id", "goal.id", "start", "end", "status")


@pytest.fixture(scope="module")
def scenario() -> Scenario:
    return load_spec(EXAMPLES / "brsu_building_c" / "scenario_c.exsce").scenario()


@pytest.fixture(scope="module")
def poses(scenario: Scenario) -> tuple[Pose, Pose, Pose, Pose]:
    start = scenario.robot(R).start_pose
    w1, w2, w3 = (p.pose for p in planned_waypoints(scenario, R))
    return start, w1, w2, w3


def xyyaw(pose: Pose, dx: float = 0.0, dy: float = 0.0, dyaw: float = 0.0) -> tuple[float, float, float]:
    return pose.position.x + dx, pose.position.y + dy, pose.orientation.yaw + dyaw


def track(*samples: tuple[float, tuple[float, float, float]]) -> Track:
    times = [t for t, _ in samples]
    x, y, yaw = zip(*(p for _, p in samples), strict=True)
    return Track(np.array(times), np.array(x), np.array(y), np.array(yaw))


def route(poses, away: tuple[float, float] = (0.0, 0.0)) -> Track:
    """At S (moved by ``away``) until 11, at W1 from 30 to 32, at W2 from 50 to 52, at W3 at 70."""
    s, w1, w2, w3 = poses
    s0 = xyyaw(s, *away)
    w1, w2, w3 = xyyaw(w1), xyyaw(w2), xyyaw(w3)
    return track((0, s0), (11, s0), (30, w1), (32, w1), (50, w2), (52, w2), (70, w3))


def rows(result: Segmentation, *fields: str) -> list[object]:
    """Each segment's ``fields`` (a tuple, or the value of a single one); all of `ROW` by default."""
    getter = attrgetter(*(fields or ROW))
    return [getter(g) for g in result.segments]


def in_order(poses) -> list[RecordedGoal]:
    _, w1, w2, w3 = poses
    return [
        RecordedGoal("g1", 10.0, 11.0, 30.0, "SUCCEEDED", xyyaw(w1)),
        RecordedGoal("g2", 31.0, 32.0, 50.0, "SUCCEEDED", xyyaw(w2, dx=0.1)),
        RecordedGoal("g3", 51.0, 52.0, 70.0, "SUCCEEDED", xyyaw(w3)),
    ]


def test_the_plan_of_tiago1(scenario) -> None:
    plan = planned_waypoints(scenario, R)
    assert [(p.allocation, p.task, p.subtask, p.waypoint, p.pose.id) for p in plan] == [
        (1, "delivery_a", 1, 1, W1_ID),
        (1, "delivery_a", 1, 2, W2_ID),
        (2, "navigate_home_1", 1, 1, W3_ID),
    ]
    with pytest.raises(SegmentError, match="robot 'nobody' is not in scenario 'scenario_c'"):
        planned_waypoints(scenario, "nobody")


# --- goals ------------------------------------------------------------------------------------------


def test_goals_in_order_are_the_segments_whatever_order_they_come_in(scenario, poses) -> None:
    g1, g2, g3 = in_order(poses)
    result = goal_segments(scenario, R, [g3, g1, g2], route(poses), Tolerance())
    assert rows(result) == [
        (R, 1, "delivery_a", 1, 1, S_ID, W1_ID, 11.0, 30.0, "SUCCEEDED"),
        (R, 1, "delivery_a", 1, 2, W1_ID, W2_ID, 32.0, 50.0, "SUCCEEDED"),
        (R, 2, "navigate_home_1", 1, 1, W2_ID, W3_ID, 52.0, 70.0, "SUCCEEDED"),
    ]
    assert result.segments[2].goal.orientation.yaw == 0.925  # the planned pose, not the start pose
    assert result.warnings == ()


def test_a_skipped_waypoint_is_a_skipped_segment_and_a_warning(scenario, poses) -> None:
    s, w1, _, w3 = poses
    g1, _, g3 = in_order(poses)
    trk = track((0, xyyaw(s)), (11, xyyaw(s)), (30, xyyaw(w1)), (52, xyyaw(w1)), (70, xyyaw(w3)))
    result = goal_segments(scenario, R, [g1, g3], trk, Tolerance())
    assert rows(result) == [
        (R, 1, "delivery_a", 1, 1, S_ID, W1_ID, 11.0, 30.0, "SUCCEEDED"),
        (R, 1, "delivery_a", 1, 2, W1_ID, W2_ID, None, None, "SKIPPED"),
        (R, 2, "navigate_home_1", 1, 1, W1_ID, W3_ID, 52.0, 70.0, "SUCCEEDED"),  # from W1: it left from there
    ]
    [warning] = result.warnings
    assert "skipped classroom_c018-w001 (delivery_a subtask 1 waypoint 2)" in warning
    assert "goal g3 went on to" in warning


def test_a_goal_off_the_plan_is_a_warning_not_a_segment(scenario, poses) -> None:
    g1, g2, g3 = in_order(poses)
    _, _, w2, _ = poses
    off = RecordedGoal("gx", 30.5, 30.6, 30.9, "ABORTED", (0.0, 0.0, 0.0))
    near = RecordedGoal("gnear", 31.0, 31.5, 45.0, "SUCCEEDED", xyyaw(w2, dx=0.5))  # 0.5 m > 0.35 m
    late = RecordedGoal("g2", 46.0, 47.0, 50.0, "SUCCEEDED", g2.target)
    result = goal_segments(scenario, R, [g1, off, near, late, g3], route(poses), Tolerance())
    assert rows(result, "goal.id", "start", "end", "status") == [
        (W1_ID, 11.0, 30.0, "SUCCEEDED"),
        (W2_ID, 47.0, 50.0, "SUCCEEDED"),  # not gnear's 31.5: a near miss is never attached
        (W3_ID, 52.0, 70.0, "SUCCEEDED"),
    ]
    assert result.warnings == (
        "goal gx to (0.00, 0.00) is not in the plan of robot tiago1",
        "goal gnear to (48.76, 24.62) is not in the plan of robot tiago1",
    )


def test_a_retry_replaces_the_aborted_attempt_and_keeps_its_start(scenario, poses) -> None:
    _, g2, g3 = in_order(poses)
    _, w1, _, _ = poses
    first = RecordedGoal("g1a", 10.0, 11.0, 20.0, "ABORTED", xyyaw(w1))
    retry = RecordedGoal("g1b", 21.0, 22.0, 30.0, "SUCCEEDED", xyyaw(w1, dy=-0.2))
    result = goal_segments(scenario, R, [first, retry, g2, g3], route(poses), Tolerance())
    assert rows(result)[:2] == [
        (R, 1, "delivery_a", 1, 1, S_ID, W1_ID, 11.0, 30.0, "SUCCEEDED"),
        (R, 1, "delivery_a", 1, 2, W1_ID, W2_ID, 32.0, 50.0, "SUCCEEDED"),
    ]
    [warning] = result.warnings
    assert warning.startswith("goal g1b retries classroom_c022-w001") and "after ABORTED" in warning


def test_after_a_detour_off_the_plan_the_next_segment_starts_where_the_robot_is(scenario, poses) -> None:
    s, w1, w2, w3 = poses
    g1, _, g3 = in_order(poses)
    detour = RecordedGoal("gx", 30.5, 31.0, 40.0, "SUCCEEDED", (50.0, 35.0, 0.0))
    g2 = RecordedGoal("g2", 41.0, 42.0, 50.0, "SUCCEEDED", xyyaw(w2))
    trk = track((0, xyyaw(s)), (30, xyyaw(w1)), (40, (50.0, 35.0, 0.0)), (50, xyyaw(w2)), (70, xyyaw(w3)))
    result = goal_segments(scenario, R, [g1, detour, g2, g3], trk, Tolerance())
    assert rows(result, "start_pose.id") == [S_ID, "tiago1@42.000", W2_ID]
    assert result.warnings == (
        "goal gx to (50.00, 35.00) is not in the plan of robot tiago1",
        "robot tiago1 was at (50.00, 35.00) at 42.000, 3.73 m from the waypoint it last reached "
        "classroom_c022-w001: its segment to classroom_c018-w001 starts there",
    )


def test_after_an_aborted_goal_the_next_segment_starts_where_the_robot_stopped(scenario, poses) -> None:
    s, w1, w2, w3 = poses
    stopped = (50.0, 35.0, 1.0)
    trk = track((0, xyyaw(s)), (11, xyyaw(s)), (20, stopped), (22, stopped), (50, xyyaw(w2)), (70, xyyaw(w3)))
    _, _, g3 = in_order(poses)
    goals = [RecordedGoal("g1", 10.0, 11.0, 20.0, "ABORTED", xyyaw(w1)), RecordedGoal("g2", 21.0, 22.0, 50.0, "SUCCEEDED", xyyaw(w2))]
    result = goal_segments(scenario, R, [*goals, g3], trk, Tolerance())
    assert rows(result) == [
        (R, 1, "delivery_a", 1, 1, S_ID, W1_ID, 11.0, 20.0, "ABORTED"),
        (R, 1, "delivery_a", 1, 2, "tiago1@22.000", W2_ID, 22.0, 50.0, "SUCCEEDED"),
        (R, 2, "navigate_home_1", 1, 1, W2_ID, W3_ID, 52.0, 70.0, "SUCCEEDED"),
    ]
    start = result.segments[1].start_pose
    assert (start.position.x, start.position.y, start.orientation.yaw, start.area) == (50.0, 35.0, 1.0, None)
    assert result.warnings == ()


def test_a_goal_back_to_a_reached_waypoint_is_not_a_retry(scenario, poses) -> None:
    g1, _, g3 = in_order(poses)
    _, w1, w2, _ = poses
    again = RecordedGoal("again", 30.5, 30.6, 31.0, "SUCCEEDED", xyyaw(w1))
    g2 = RecordedGoal("g2", 36.0, 37.0, 50.0, "SUCCEEDED", xyyaw(w2))
    result = goal_segments(scenario, R, [g1, again, g2, g3], route(poses), Tolerance())
    assert rows(result, "start", "end") == [(11.0, 30.0), (37.0, 50.0), (52.0, 70.0)]
    assert result.warnings == ("goal again to (52.83, 32.56) is not in the plan of robot tiago1",)


def test_canceled_and_still_active_goals(scenario, poses) -> None:
    g1, _, _ = in_order(poses)
    _, _, w2, w3 = poses
    canceled = RecordedGoal("g2", 31.0, None, 40.0, "CANCELED", xyyaw(w2))  # never active: starts when accepted
    active = RecordedGoal("g3", 41.0, 42.0, 99.0, "ACTIVE", xyyaw(w3))  # last seen at 99 s, never ended
    result = goal_segments(scenario, R, [g1, canceled, active], route(poses), Tolerance())
    assert rows(result) == [
        (R, 1, "delivery_a", 1, 1, S_ID, W1_ID, 11.0, 30.0, "SUCCEEDED"),
        (R, 1, "delivery_a", 1, 2, W1_ID, W2_ID, 31.0, 40.0, "CANCELED"),
        (R, 2, "navigate_home_1", 1, 1, "tiago1@42.000", W3_ID, 42.0, None, "ACTIVE"),
    ]
    # the track's last sample at or before 42 s is W1's, at 32 s
    assert result.segments[2].start_pose.position == result.segments[0].goal.position


def test_a_goal_without_a_target_is_where_the_robot_was_when_it_succeeded(scenario, poses) -> None:
    s, w1, _, w3 = poses
    stopped = (50.0, 35.0, 0.0)
    trk = track((0, xyyaw(s)), (11, xyyaw(s)), (30, xyyaw(w1)), (40, stopped), (52, stopped), (70, xyyaw(w3)))
    goals = [
        RecordedGoal("g1", 10.0, 11.0, 30.0, "SUCCEEDED"),  # the track is at W1 at 30 s
        RecordedGoal("g2", 31.0, 32.0, 40.0, "ABORTED"),  # failed somewhere: no telling where it was going
        RecordedGoal("g3", 51.0, 52.0, 70.0, "SUCCEEDED"),  # the track is at W3 at 70 s
    ]
    result = goal_segments(scenario, R, goals, trk, Tolerance())
    assert rows(result, "start_pose.id", "goal.id", "start", "end", "status") == [
        (S_ID, W1_ID, 11.0, 30.0, "SUCCEEDED"),
        (W1_ID, W2_ID, None, None, "SKIPPED"),
        ("tiago1@52.000", W3_ID, 52.0, 70.0, "SUCCEEDED"),  # where g2 left it, not W1
    ]
    assert result.warnings[0] == "goal g2 (ABORTED) has no target: cannot tell its waypoint; ignored"
    assert "skipped classroom_c018-w001" in result.warnings[1]
    assert result.warnings[2].startswith("robot tiago1 was at (50.00, 35.00) at 52.000")
    assert len(result.warnings) == 3


@pytest.mark.parametrize(
    ("dyaw", "heading", "matched"),
    [(1.0, None, True), (1.0, 0.3, False), (0.2, 0.3, True), (2 * math.pi - 0.1, 0.3, True)],  # yaw wraps
)
def test_heading_tolerance_on_goals(scenario, poses, dyaw: float, heading: float | None, matched: bool) -> None:
    g1, g2, g3 = in_order(poses)
    turned = RecordedGoal("g1", 10.0, 11.0, 30.0, "SUCCEEDED", xyyaw(poses[1], dyaw=dyaw))
    result = goal_segments(scenario, R, [turned, g2, g3], route(poses), Tolerance(heading=heading))
    assert result.segments[0].status == ("SUCCEEDED" if matched else "SKIPPED")
    assert any("goal g1 to" in w for w in result.warnings) is not matched


def test_a_robot_not_at_its_start_pose_starts_where_it_is(scenario, poses) -> None:
    result = goal_segments(scenario, R, in_order(poses), route(poses, away=(2.0, 0.0)), Tolerance())
    start = result.segments[0].start_pose
    assert (start.id, start.position.x) == ("tiago1@11.000", poses[0].position.x + 2.0)
    assert result.warnings == (
        "robot tiago1 was at (46.80, 37.16) at 11.000, 2.00 m from its start pose classroom_c025-w001: "
        "its segment to classroom_c022-w001 starts there",
    )


def test_no_goals_or_none_in_the_plan_give_no_segments(scenario, poses) -> None:
    expected = Segmentation((), ("robot tiago1 has no navigation goals: no segments from goals",))
    assert goal_segments(scenario, R, [], route(poses), Tolerance()) == expected
    timeless = RecordedGoal("t", None, None, None, "ACTIVE", xyyaw(poses[1]))
    elsewhere = RecordedGoal("gx", 5.0, 6.0, 7.0, "SUCCEEDED", (1.0, 2.0, 0.0))
    result = goal_segments(scenario, R, [timeless, elsewhere], route(poses), Tolerance())
    assert result.segments == ()
    assert result.warnings == (
        "goal t has no time at all: ignored",
        "goal gx to (1.00, 2.00) is not in the plan of robot tiago1",
        "robot tiago1: none of its 2 navigation goals reached a planned waypoint by pose: no segments from goals",
    )


# --- follow_waypoints -------------------------------------------------------------------------------


def follow(poses, progress, status="SUCCEEDED", ended=70.0, targets=True, missed=()) -> RecordedGoal:
    given = tuple(xyyaw(p) for p in poses[1:]) if targets else ()
    return RecordedGoal("fw", 10.0, 11.0, ended, status, None, tuple(progress), given, tuple(missed))


@pytest.mark.parametrize("targets", [True, False], ids=["targets", "track"])
def test_follow_waypoints_one_segment_per_index(scenario, poses, targets: bool) -> None:
    progress = [(0, 11.0), (0, 12.0), (1, 30.0), (2, 50.0)]  # repeated feedback: the first time counts
    result = goal_segments(scenario, R, [follow(poses, progress, targets=targets)], route(poses), Tolerance())
    assert rows(result) == [
        (R, 1, "delivery_a", 1, 1, S_ID, W1_ID, 11.0, 30.0, "SUCCEEDED"),
        (R, 1, "delivery_a", 1, 2, W1_ID, W2_ID, 30.0, 50.0, "SUCCEEDED"),
        (R, 2, "navigate_home_1", 1, 1, W2_ID, W3_ID, 50.0, 70.0, "SUCCEEDED"),
    ]
    assert result.warnings == ()


def test_follow_waypoints_missed_waypoint_is_aborted(scenario, poses) -> None:
    goal = follow(poses, [(0, 11.0), (1, 30.0), (2, 50.0)], missed=[1])
    result = goal_segments(scenario, R, [goal], route(poses), Tolerance())
    assert rows(result, "start_pose.id", "start", "end", "status") == [
        (S_ID, 11.0, 30.0, "SUCCEEDED"),
        (W1_ID, 30.0, 50.0, "ABORTED"),
        ("tiago1@50.000", 50.0, 70.0, "SUCCEEDED"),
    ]


def test_follow_waypoints_feedback_that_jumps_or_goes_back(scenario, poses) -> None:
    goal = follow(poses, [(0, 11.0), (2, 50.0), (1, 55.0)])
    result = goal_segments(scenario, R, [goal], route(poses), Tolerance())
    assert rows(result, "start", "end", "status") == [
        (11.0, 50.0, "SUCCEEDED"),
        (50.0, 50.0, "SUCCEEDED"),  # never reported: no duration
        (50.0, 70.0, "SUCCEEDED"),
    ]
    assert result.warnings == (
        "goal fw went back from waypoint 2 to 1: ignored",
        "goal fw: the feedback jumped from waypoint 0 to 2; waypoints 1 get segments of no duration",
        # by then the robot had been to W1 and W2: the track says so
        "robot tiago1 was at (48.26, 24.62) at 50.000, 9.16 m from the waypoint it last reached "
        "classroom_c022-w001: its segment to classroom_c018-w001 starts there",
    )


def test_follow_waypoints_jump_without_targets_places_only_the_last_jumped_over(scenario, poses) -> None:
    goal = follow(poses, [(0, 11.0), (2, 50.0)], targets=False)
    result = goal_segments(scenario, R, [goal], route(poses), Tolerance())
    assert rows(result, "goal.id", "start", "end", "status") == [
        (W1_ID, None, None, "SKIPPED"),  # the track at 50 s is where waypoint 1 was done, not 0
        (W2_ID, 50.0, 50.0, "SUCCEEDED"),
        (W3_ID, 50.0, 70.0, "SUCCEEDED"),
    ]
    assert result.warnings[:2] == (
        "goal fw: the feedback jumped from waypoint 0 to 2; waypoints 1 get segments of no duration",
        "goal fw[0] (SUCCEEDED) has no target: cannot tell its waypoint; ignored",
    )
    assert result.warnings[2].startswith("robot tiago1 skipped classroom_c022-w001")
    assert result.warnings[3].startswith("robot tiago1 was at (48.26, 24.62) at 50.000, 13.01 m from its start pose")
    assert len(result.warnings) == 4


def test_follow_waypoints_aborted_on_the_way(scenario, poses) -> None:
    goal = follow(poses, [(0, 11.0), (1, 30.0)], status="ABORTED", ended=40.0, targets=False)
    result = goal_segments(scenario, R, [goal], route(poses), Tolerance())
    assert rows(result, "goal.id", "start", "end", "status") == [
        (W1_ID, 11.0, 30.0, "SUCCEEDED"),  # the feedback moved on at 30 s, where the track is at W1
        (W2_ID, None, None, "NOT_STARTED"),
        (W3_ID, None, None, "NOT_STARTED"),
    ]
    assert result.warnings == ("goal fw[1] (ABORTED) has no target: cannot tell its waypoint; ignored",)


# --- arrival ----------------------------------------------------------------------------------------


def wander(poses, still: tuple[float, float, float] = (0.005, 0.0, 0.0)) -> Track:
    s, w1, w2, w3 = poses
    return track(
        (0, xyyaw(s)), (1, xyyaw(s, *still)),
        (2, xyyaw(s, dx=1.0)),  # set off
        (3, xyyaw(w2)),  # W2 before W1: does not count
        (4, xyyaw(w1, dx=0.3)),  # passing within 0.3 m of W1: arrived
        (5, xyyaw(w1, dx=2.0)), (6, xyyaw(w2, dy=0.5)),  # 0.5 m from W2: not yet
        (7, xyyaw(w2, dy=0.2)), (8, (47.0, 30.0, 0.0)),
        (9, xyyaw(w3, dx=0.1, dy=0.1)),  # 0.14 m
    )


def test_arrival_in_order(scenario, poses) -> None:
    result = arrival_segments(scenario, R, wander(poses), Tolerance())
    assert rows(result) == [
        (R, 1, "delivery_a", 1, 1, S_ID, W1_ID, 1.0, 4.0, "SUCCEEDED"),
        (R, 1, "delivery_a", 1, 2, W1_ID, W2_ID, 4.0, 7.0, "SUCCEEDED"),
        (R, 2, "navigate_home_1", 1, 1, W2_ID, W3_ID, 7.0, 9.0, "SUCCEEDED"),
    ]
    assert result.warnings == ()


@pytest.mark.parametrize(
    ("still", "start"),
    [((0.005, 0.0, 0.0), 1.0), ((0.02, 0.0, 0.0), 0.0), ((0.0, 0.0, 0.05), 0.0)],
    ids=["noise", "creeping", "turning"],
)
def test_arrival_starts_when_the_robot_set_off(scenario, poses, still, start: float) -> None:
    assert arrival_segments(scenario, R, wander(poses, still), Tolerance()).segments[0].start == start


def test_arrival_a_waypoint_never_reached(scenario, poses) -> None:
    s, w1, _, w3 = poses
    trk = track((0, xyyaw(s)), (1, xyyaw(s)), (2, xyyaw(w1)), (3, xyyaw(w1, dx=3.0)), (4, xyyaw(w3)))
    result = arrival_segments(scenario, R, trk, Tolerance())
    assert rows(result) == [
        (R, 1, "delivery_a", 1, 1, S_ID, W1_ID, 1.0, 2.0, "SUCCEEDED"),
        (R, 1, "delivery_a", 1, 2, W1_ID, W2_ID, None, None, "NOT_REACHED"),
        (R, 2, "navigate_home_1", 1, 1, W1_ID, W3_ID, None, None, "NOT_REACHED"),  # though it went home
    ]
    assert result.warnings == (
        "robot tiago1 never reached classroom_c018-w001 (delivery_a subtask 1 waypoint 2) after 2.000; "
        "it and the 1 waypoint after it are NOT_REACHED",
    )


def test_arrival_a_robot_that_never_moved(scenario, poses) -> None:
    s = poses[0]
    trk = track((0, xyyaw(s)), (5, xyyaw(s, dx=0.2)), (9, xyyaw(s, dy=-0.3)))
    result = arrival_segments(scenario, R, trk, Tolerance())
    assert rows(result, "start_pose.id", "start", "end", "status") == [(S_ID, None, None, "NOT_STARTED")] * 3
    assert result.warnings == ("robot tiago1 never moved: it stayed within 0.35 m of (44.80, 37.16)",)


def test_arrival_an_empty_track(scenario) -> None:
    expected = Segmentation((), ("robot tiago1 has an empty pose track: no segments by arrival",))
    assert arrival_segments(scenario, R, Track.empty(), Tolerance()) == expected


@pytest.mark.parametrize(("heading", "end"), [(None, 2.0), (0.3, 3.0)])
def test_heading_tolerance_on_arrival(scenario, poses, heading: float | None, end: float) -> None:
    s, w1, w2, w3 = poses
    trk = track((0, xyyaw(s)), (2, xyyaw(w1, dyaw=1.0)), (3, xyyaw(w1)), (4, xyyaw(w2)), (5, xyyaw(w3)))
    result = arrival_segments(scenario, R, trk, Tolerance(heading=heading))
    assert [(g.start, g.end) for g in result.segments] == [(0.0, end), (end, 4.0), (4.0, 5.0)]


# --- the shared types -------------------------------------------------------------------------------


def test_tracks_and_tolerances_are_checked() -> None:
    with pytest.raises(SegmentError, match="of one length"):
        Track(np.zeros(3), np.zeros(2), np.zeros(3), np.zeros(3))
    with pytest.raises(SegmentError, match="must not decrease"):
        track((0, (0, 0, 0)), (2, (0, 0, 0)), (1, (0, 0, 0)))
    with pytest.raises(SegmentError, match="positive"):  # the language refuses them; Python callers too
        near(Tolerance(position=0.0), Pose("p", Position(0.0, 0.0)), np.zeros(1), np.zeros(1), np.zeros(1))
    assert Tolerance() == Tolerance(0.35, None)
