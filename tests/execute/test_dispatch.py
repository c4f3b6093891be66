"""The dispatcher driving scenario_c through the kinematic navigator on a simulated clock.

Most tests run on open floor (scenario_c without its map: the grid is free space, so every path
is the straight line and every time is a hand calculation: distance / 0.5 m/s); the order tests
run on the building's real occupancy grid.
"""

from __future__ import annotations

import math
from dataclasses import replace

import pytest

from exsce_dsl.execute.dispatcher import dispatch
from exsce_dsl.execute.mission import schedule
from exsce_dsl.execute.navigator import SimulatedClock
from exsce_dsl.execute.outcomes import DEFAULT_POLICY, GoalOutcome, MissionStatus, Policy
from exsce_dsl.lang import load_spec
from exsce_dsl.maps.planning import planning_grid
from exsce_dsl.model import MissionType

from tests.support.kinematic_navigator import ABORT_AFTER, KinematicNavigator
from tests.support.paths import EXAMPLES

# environment.exsce, by hand
P = {
    "c025-w001": (44.80387496948242, 37.15502166748047),
    "c025-w002": (43.432926177978516, 38.493873596191406),
    "c022-w001": (52.82560729980469, 32.562904357910156),
    "c022-w002": (54.497589111328125, 31.52023696899414),
    "c018-w001": (48.26420974731445, 24.618297576904297),
    "c018-w002": (46.25560760498047, 21.586545944213867),
}
V = 0.5  # m/s, the speed both robots drive at in these tests
S, A, T, C = (GoalOutcome.SUCCEEDED, GoalOutcome.ABORTED, GoalOutcome.TIMED_OUT, GoalOutcome.CANCELLED)
FIRST = ("tiago1", "classroom_c022-w001")  # tiago1's first goal: the one the tests make fail


def leg(a: str, b: str) -> float:
    """Seconds to drive from pose ``a`` to pose ``b`` in a straight line at V."""
    return math.dist(P[a], P[b]) / V


def tiago2_untouched() -> list[tuple]:
    t1 = leg("c025-w002", "c022-w002")
    t2 = t1 + leg("c022-w002", "c018-w002")
    t3 = t2 + leg("c018-w002", "c025-w002")
    return [
        ("tiago2", "delivery_b", 1, 1, 1, "c022-w002", 0.0, t1, S, 1),
        ("tiago2", "delivery_b", 1, 1, 2, "c018-w002", t1, t2, S, 1),
        ("tiago2", "navigate_home_2", 2, 1, 1, "c025-w002", t2, t3, S, 1),
    ]


@pytest.fixture(scope="module")
def scenario_c():
    return load_spec(EXAMPLES / "brsu_building_c" / "scenario_c.exsce").scenario("scenario_c")


@pytest.fixture(scope="module")
def open_floor(scenario_c):
    scenario = replace(scenario_c, environment=replace(scenario_c.environment, map=None))
    return scenario, planning_grid(scenario)


def _run(open_floor, policy=DEFAULT_POLICY, aborts=None, silent=(), cancelled=None, timeout=None):
    scenario, grid = open_floor
    clock = SimulatedClock()
    speeds = {"tiago1": V, "tiago2": V}
    nav = KinematicNavigator(scenario, grid, clock, speeds, aborts, silent)
    when = (lambda: cancelled(clock)) if cancelled else None
    run = dispatch(schedule(scenario, speeds, timeout), nav, clock, policy, when)
    return run, nav


def _rows(run) -> list[tuple]:
    return sorted(
        (
            (r.robot, r.task, r.task_number, r.subtask, r.waypoint, r.pose.id.removeprefix("classroom_"))
            + (pytest.approx(r.start, abs=1e-6), pytest.approx(r.end, abs=1e-6), r.outcome, r.attempts)
            for r in run.records
        ),
        key=lambda row: (row[0], row[6].expected),
    )


def test_without_failures_every_goal_succeeds_in_hand_calculated_time(open_floor):
    run, _ = _run(open_floor)
    t1 = leg("c025-w001", "c022-w001")
    t2 = t1 + leg("c022-w001", "c018-w001")
    t3 = t2 + leg("c018-w001", "c025-w001")
    assert (
        _rows(run)
        == [
            ("tiago1", "delivery_a", 1, 1, 1, "c022-w001", 0.0, t1, S, 1),
            ("tiago1", "delivery_a", 1, 1, 2, "c018-w001", t1, t2, S, 1),
            ("tiago1", "navigate_home_1", 2, 1, 1, "c025-w001", t2, t3, S, 1),
        ]
        + tiago2_untouched()
    )
    assert (run.status, run.not_sent, run.start) == (MissionStatus.COMPLETED, 0, 0.0)
    assert run.end == pytest.approx(max(t3, tiago2_untouched()[-1][7]))


def test_the_default_policy_is_the_method_dispatchers_skip_the_waypoint():
    assert DEFAULT_POLICY is Policy.SKIP_WAYPOINT


def test_retry_once_then_succeed(open_floor):
    run, _ = _run(open_floor, Policy.RETRY_ONCE, aborts={FIRST: 1})
    t1 = ABORT_AFTER + leg("c025-w001", "c022-w001")
    t2 = t1 + leg("c022-w001", "c018-w001")
    t3 = t2 + leg("c018-w001", "c025-w001")
    assert (
        _rows(run)
        == [
            ("tiago1", "delivery_a", 1, 1, 1, "c022-w001", 0.0, t1, S, 2),
            ("tiago1", "delivery_a", 1, 1, 2, "c018-w001", t1, t2, S, 1),
            ("tiago1", "navigate_home_1", 2, 1, 1, "c025-w001", t2, t3, S, 1),
        ]
        + tiago2_untouched()
    )
    assert run.status is MissionStatus.COMPLETED


def test_retry_once_that_fails_again_skips_the_waypoint(open_floor):
    run, _ = _run(open_floor, Policy.RETRY_ONCE, aborts={FIRST: 2})
    t1 = 2 * ABORT_AFTER
    t2 = t1 + leg("c025-w001", "c018-w001")  # it never left its start
    t3 = t2 + leg("c018-w001", "c025-w001")
    assert _rows(run)[:3] == [
        ("tiago1", "delivery_a", 1, 1, 1, "c022-w001", 0.0, t1, A, 2),
        ("tiago1", "delivery_a", 1, 1, 2, "c018-w001", t1, t2, S, 1),
        ("tiago1", "navigate_home_1", 2, 1, 1, "c025-w001", t2, t3, S, 1),
    ]


def test_skip_the_waypoint(open_floor):
    run, nav = _run(open_floor, Policy.SKIP_WAYPOINT, aborts={FIRST: 1})
    t1 = ABORT_AFTER
    t2 = t1 + leg("c025-w001", "c018-w001")
    t3 = t2 + leg("c018-w001", "c025-w001")
    assert (
        _rows(run)
        == [
            ("tiago1", "delivery_a", 1, 1, 1, "c022-w001", 0.0, t1, A, 1),
            ("tiago1", "delivery_a", 1, 1, 2, "c018-w001", t1, t2, S, 1),
            ("tiago1", "navigate_home_1", 2, 1, 1, "c025-w001", t2, t3, S, 1),
        ]
        + tiago2_untouched()
    )
    assert (run.status, run.not_sent, len(nav.sent)) == (MissionStatus.COMPLETED, 0, 6)


def test_skip_the_task(open_floor):
    run, nav = _run(open_floor, Policy.SKIP_TASK, aborts={FIRST: 1})
    # delivery_a's second waypoint is never sent; navigate_home_1 starts where tiago1 stands: 0 m
    assert (
        _rows(run)
        == [
            ("tiago1", "delivery_a", 1, 1, 1, "c022-w001", 0.0, ABORT_AFTER, A, 1),
            ("tiago1", "navigate_home_1", 2, 1, 1, "c025-w001", ABORT_AFTER, ABORT_AFTER, S, 1),
        ]
        + tiago2_untouched()
    )
    assert (run.status, run.not_sent) == (MissionStatus.COMPLETED, 1)
    assert "classroom_c018-w001" not in [pose.id for _, robot, pose, _ in nav.sent if robot == "tiago1"]


def test_stop_the_mission_cancels_the_other_robots_goal(open_floor):
    run, nav = _run(open_floor, Policy.STOP_MISSION, aborts={FIRST: 1})
    assert _rows(run) == [
        ("tiago1", "delivery_a", 1, 1, 1, "c022-w001", 0.0, ABORT_AFTER, A, 1),
        ("tiago2", "delivery_b", 1, 1, 1, "c022-w002", 0.0, ABORT_AFTER, C, 1),
    ]
    assert (run.status, run.not_sent, len(nav.sent), nav.active) == (MissionStatus.STOPPED, 4, 2, {})
    # tiago2 stopped where it was after 2 s on its straight way to c022-w002
    (x0, y0), (x1, y1) = P["c025-w002"], P["c022-w002"]
    f = ABORT_AFTER * V / math.dist(P["c025-w002"], P["c022-w002"])
    assert nav.where["tiago2"] == pytest.approx((x0 + f * (x1 - x0), y0 + f * (y1 - y0)))


def test_a_goal_never_answered_times_out_and_is_cancelled(open_floor):
    run, nav = _run(open_floor, silent=[FIRST])
    timeout = 60.0  # 3 × 9.24 m / 0.5 m/s = 55.4 s: the floor
    t2 = timeout + leg("c025-w001", "c018-w001")
    t3 = t2 + leg("c018-w001", "c025-w001")
    assert (
        _rows(run)
        == [
            ("tiago1", "delivery_a", 1, 1, 1, "c022-w001", 0.0, timeout, T, 1),
            ("tiago1", "delivery_a", 1, 1, 2, "c018-w001", timeout, t2, S, 1),
            ("tiago1", "navigate_home_1", 2, 1, 1, "c025-w001", t2, t3, S, 1),
        ]
        + tiago2_untouched()
    )
    assert nav.sent[0][2].id == FIRST[1] and nav.active == {}  # the silent goal was cancelled


def test_a_given_timeout_with_retry_once_times_out_twice(open_floor):
    run, _ = _run(open_floor, Policy.RETRY_ONCE, silent=[FIRST], timeout=25.0)
    first = [r for r in run.records if r.pose.id == "classroom_c022-w001"]
    assert [(r.start, r.end, r.outcome, r.attempts) for r in first] == [(0.0, 50.0, T, 2)]


def test_cancelling_mid_mission_cancels_every_active_goal(open_floor):
    run, nav = _run(open_floor, cancelled=lambda clock: clock.now() >= 5.0)
    assert _rows(run) == [
        ("tiago1", "delivery_a", 1, 1, 1, "c022-w001", 0.0, 5.0, C, 1),
        ("tiago2", "delivery_b", 1, 1, 1, "c022-w002", 0.0, 5.0, C, 1),
    ]
    assert (run.status, run.not_sent, run.end, nav.active) == (MissionStatus.CANCELLED, 4, 5.0, {})
    (x0, y0), (x1, y1) = P["c025-w001"], P["c022-w001"]
    f = 5.0 * V / math.dist(P["c025-w001"], P["c022-w001"])  # 2.5 m along its 9.24 m
    assert nav.where["tiago1"] == pytest.approx((x0 + f * (x1 - x0), y0 + f * (y1 - y0)))


@pytest.fixture(scope="module")
def building(scenario_c):
    return planning_grid(scenario_c)


def _on_the_map(scenario, grid):
    clock = SimulatedClock()
    nav = KinematicNavigator(scenario, grid, clock)
    return dispatch(schedule(scenario), nav, clock), nav


def test_parallel_on_the_map_robots_go_side_by_side_each_through_its_allocation(scenario_c, building):
    run, nav = _on_the_map(scenario_c, building)
    assert run.status is MissionStatus.COMPLETED
    assert {r.outcome for r in run.records} == {S}
    sent = [(robot, pose.id.removeprefix("classroom_")) for _, robot, pose, _ in nav.sent]
    assert sent[:2] == [("tiago1", "c022-w001"), ("tiago2", "c022-w002")]  # both at once
    assert [nav.sent[0][3], nav.sent[1][3]] == [0.0, 0.0]
    for robot, poses in (
        ("tiago1", ["c022-w001", "c018-w001", "c025-w001"]),
        ("tiago2", ["c022-w002", "c018-w002", "c025-w002"]),
    ):
        assert [p for r, p in sent if r == robot] == poses
        mine = sorted((r for r in run.records if r.robot == robot), key=lambda r: r.start)
        assert all(
            a.end == b.start for a, b in zip(mine, mine[1:], strict=False)
        )  # one goal at a time, no gap
        for r in mine:  # a grid path is at least the straight line, at most twice it here
            straight = math.dist(_from(scenario_c, mine, r), (r.pose.position.x, r.pose.position.y))
            assert straight / 0.6 - 1e-9 <= r.end - r.start <= 2.5 * straight / 0.6


def _from(scenario, mine, record):
    before = [r for r in mine if r.end <= record.start]
    pose = before[-1].pose if before else scenario.robot(record.robot).start_pose
    return pose.position.x, pose.position.y


def test_sequential_on_the_map_one_robot_at_a_time_in_allocation_order(scenario_c, building):
    sequential = replace(scenario_c, mission=replace(scenario_c.mission, type=MissionType.SEQUENTIAL))
    run, nav = _on_the_map(sequential, building)
    sent = [(robot, pose.id.removeprefix("classroom_")) for _, robot, pose, _ in nav.sent]
    assert sent == [
        ("tiago1", "c022-w001"),
        ("tiago1", "c018-w001"),
        ("tiago2", "c022-w002"),
        ("tiago2", "c018-w002"),
        ("tiago1", "c025-w001"),
        ("tiago2", "c025-w002"),
    ]
    assert [r.pose.id.removeprefix("classroom_") for r in run.records] == [p for _, p in sent]
    assert all(
        a.end == b.start for a, b in zip(run.records, run.records[1:], strict=False)
    )  # never two at once
    assert run.status is MissionStatus.COMPLETED and {r.outcome for r in run.records} == {S}


def test_a_rejected_goal_is_skipped_by_the_default_policy(open_floor):
    scenario, grid = open_floor
    clock = SimulatedClock()
    nav = KinematicNavigator(scenario, grid, clock, {"tiago1": V, "tiago2": V}, rejects=[FIRST])
    run = dispatch(schedule(scenario), nav, clock)
    t2 = leg("c025-w001", "c018-w001")
    assert _rows(run)[:2] == [
        ("tiago1", "delivery_a", 1, 1, 1, "c022-w001", 0.0, 0.0, GoalOutcome.REJECTED, 1),
        ("tiago1", "delivery_a", 1, 1, 2, "c018-w001", 0.0, t2, S, 1),
    ]


def test_a_mission_cancelled_before_it_starts_sends_nothing(open_floor):
    run, nav = _run(open_floor, cancelled=lambda clock: True)
    assert (run.status, run.records, run.not_sent, nav.sent) == (MissionStatus.CANCELLED, (), 6, [])
