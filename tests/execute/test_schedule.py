"""The mission as a schedule of goals: lanes, order, poses and timeouts, against scenario_c written
out by hand (examples/brsu_building_c: scenario_c.exsce, tasks/*.exsce, environment.exsce)."""

from __future__ import annotations

import math
from dataclasses import replace

import pytest

from exsce_dsl.errors import ExsceError
from exsce_dsl.execute.mission import TIMEOUT_FLOOR, goal_timeout, schedule
from exsce_dsl.lang import load_spec
from exsce_dsl.model import MissionType

from tests.support.paths import EXAMPLES

# environment.exsce, by hand: (x, y, yaw as the task uses it)
POSES = {
    "classroom_c025-w001": (44.80387496948242, 37.15502166748047, 0.0),
    "classroom_c025-w002": (43.432926177978516, 38.493873596191406, 0.0),
    "classroom_c022-w001": (52.82560729980469, 32.562904357910156, 2.269),
    "classroom_c022-w002": (54.497589111328125, 31.52023696899414, 2.269),
    "classroom_c018-w001": (48.26420974731445, 24.618297576904297, -0.641),
    "classroom_c018-w002": (46.25560760498047, 21.586545944213867, -0.641),
}
HOME_YAW = 0.925  # navigation.exsce: "visit classroom_c025-w00N facing 0.925"

# scenario_c's allocation, by hand: (robot, task, task number, subtask, waypoint, pose)
TIAGO1 = [
    ("tiago1", "delivery_a", 1, 1, 1, "classroom_c022-w001"),
    ("tiago1", "delivery_a", 1, 1, 2, "classroom_c018-w001"),
    ("tiago1", "navigate_home_1", 2, 1, 1, "classroom_c025-w001"),
]
TIAGO2 = [
    ("tiago2", "delivery_b", 1, 1, 1, "classroom_c022-w002"),
    ("tiago2", "delivery_b", 1, 1, 2, "classroom_c018-w002"),
    ("tiago2", "navigate_home_2", 2, 1, 1, "classroom_c025-w002"),
]


@pytest.fixture(scope="module")
def scenario_c():
    return load_spec(EXAMPLES / "brsu_building_c" / "scenario_c.exsce").scenario("scenario_c")


def _rows(goals):
    return [(g.robot, g.task, g.task_number, g.subtask, g.waypoint, g.pose.id) for g in goals]


def test_a_parallel_mission_has_one_lane_per_robot_in_its_allocation_order(scenario_c):
    planned = schedule(scenario_c)
    assert planned.type is MissionType.PARALLEL
    assert [_rows(lane) for lane in planned.lanes] == [TIAGO1, TIAGO2]


def test_a_sequential_mission_is_one_lane_in_the_written_allocation_order(scenario_c):
    sequential = replace(scenario_c, mission=replace(scenario_c.mission, type=MissionType.SEQUENTIAL))
    planned = schedule(sequential)
    # scenario_c: tiago1 does delivery_a, tiago2 does delivery_b, tiago1 navigate_home_1, tiago2 navigate_home_2
    assert [_rows(lane) for lane in planned.lanes] == [TIAGO1[:2] + TIAGO2[:2] + TIAGO1[2:] + TIAGO2[2:]]


def test_the_goals_are_the_specs_waypoint_poses(scenario_c):
    for goal in schedule(scenario_c).goals:
        x, y, yaw = POSES[goal.pose.id]
        if goal.task.startswith("navigate_home"):
            yaw = HOME_YAW
        assert (goal.pose.position.x, goal.pose.position.y) == (x, y)
        assert goal.pose.orientation.yaw == pytest.approx(yaw, abs=1e-9)


def test_default_timeouts_come_from_the_straight_line_at_the_speed_limit_with_a_floor(scenario_c):
    goals = {(g.robot, g.pose.id): g.timeout for g in schedule(scenario_c).goals}
    # tiago1's first leg, c025-w001 → c022-w001: 9.24 m; 3 × 9.24 / 0.6 = 46.2 s, below the floor
    assert goals["tiago1", "classroom_c022-w001"] == TIMEOUT_FLOOR == 60.0
    # its way home, c018-w001 → c025-w001: 13.006 m; 3 × 13.006 / 0.6 = 65.03 s
    home = math.hypot(48.26420974731445 - 44.80387496948242, 24.618297576904297 - 37.15502166748047)
    assert home == pytest.approx(13.006, abs=1e-3)
    assert goals["tiago1", "classroom_c025-w001"] == pytest.approx(3 * home / 0.6)
    faster = {(g.robot, g.pose.id): g.timeout for g in schedule(scenario_c, speeds={"tiago1": 1.0}).goals}
    assert faster["tiago1", "classroom_c025-w001"] == 60.0  # 39 s: the floor
    assert faster["tiago2", "classroom_c025-w002"] == goals["tiago2", "classroom_c025-w002"] > 60.0


def test_a_given_timeout_replaces_every_default(scenario_c):
    assert {g.timeout for g in schedule(scenario_c, timeout=120.0).goals} == {120.0}


@pytest.mark.parametrize("bad", [0.0, -5.0])
def test_a_timeout_or_speed_not_above_zero_is_an_error(scenario_c, bad):
    with pytest.raises(ExsceError, match="timeout must be above 0 s"):
        schedule(scenario_c, timeout=bad)
    with pytest.raises(ExsceError, match="speed limit must be above 0 m/s"):
        goal_timeout(10.0, bad)


def _with_timeouts(scenario, task_timeouts, mission_timeout):
    tasks = tuple(replace(t, timeout=task_timeouts.get(t.id)) for t in scenario.tasks)
    return replace(scenario, tasks=tasks, mission=replace(scenario.mission, timeout=mission_timeout))


def test_a_tasks_timeout_wins_over_its_missions_and_the_missions_over_the_default(scenario_c):
    home = 3 * math.hypot(48.26420974731445 - 44.80387496948242, 24.618297576904297 - 37.15502166748047) / 0.6

    def timeouts(scenario, given=None):
        return {(g.robot, g.pose.id): g.timeout for g in schedule(scenario, timeout=given).goals}

    both = timeouts(_with_timeouts(scenario_c, {"delivery_a": 100.0}, 200.0))
    assert both == {
        ("tiago1", "classroom_c022-w001"): 100.0,
        ("tiago1", "classroom_c018-w001"): 100.0,
        ("tiago1", "classroom_c025-w001"): 200.0,
        ("tiago2", "classroom_c022-w002"): 200.0,
        ("tiago2", "classroom_c018-w002"): 200.0,
        ("tiago2", "classroom_c025-w002"): 200.0,
    }
    task_only = timeouts(_with_timeouts(scenario_c, {"delivery_a": 100.0}, None))
    assert task_only["tiago1", "classroom_c018-w001"] == 100.0
    assert task_only["tiago1", "classroom_c025-w001"] == pytest.approx(home)  # the default
    first = (
        3 * math.hypot(54.497589111328125 - 43.432926177978516, 31.52023696899414 - 38.493873596191406) / 0.6
    )
    assert (
        task_only["tiago2", "classroom_c022-w002"] == pytest.approx(first) == pytest.approx(65.39, abs=0.01)
    )
    # the caller's timeout replaces only the default
    given = timeouts(_with_timeouts(scenario_c, {"delivery_a": 100.0}, None), 120.0)
    assert given["tiago1", "classroom_c022-w001"] == 100.0 and given["tiago1", "classroom_c025-w001"] == 120.0
    assert timeouts(_with_timeouts(scenario_c, {}, 200.0), 120.0)["tiago2", "classroom_c025-w002"] == 200.0


def test_the_timeouts_written_in_the_spec_reach_the_schedule(tmp_path):
    (tmp_path / "s.exsce").write_text(
        "robot type r { }\n"
        "environment e { area a { pose a-p at (0, 0)  pose a-q at (300, 400) } }\n"
        "task out { timeout 2 min visit a-q }\n"
        "task back { visit a-p }\n"
        "task far { visit a-q }\n"
        "scenario s in e {\n"
        "  robots { r1: r starts at a-p  r2: r starts at a-q }\n"
        "  mission m parallel { r1 does out then back  r2 does far }\n"
        "}\n"
        "scenario s2 in e {\n"
        "  robots { r1: r starts at a-p }\n"
        "  mission m2 sequential { timeout 1.5 h  r1 does out then back }\n"
        "}\n"
    )
    spec = load_spec(tmp_path / "s.exsce")
    goals = [(g.robot, g.task, g.timeout) for g in schedule(spec.scenario("s")).goals]
    # back: 500 m at 0.6 m/s, three times over: 2500 s; far: a goal where r2 already is: the floor
    assert goals == [("r1", "out", 120.0), ("r1", "back", pytest.approx(2500.0)), ("r2", "far", 60.0)]
    assert [g.timeout for g in schedule(spec.scenario("s2")).goals] == [120.0, 5400.0]


def test_a_timeout_in_the_model_not_above_zero_is_an_error(scenario_c):
    with pytest.raises(ExsceError, match="goal timeout of task 'delivery_a' must be above 0 s, not -1"):
        schedule(_with_timeouts(scenario_c, {"delivery_a": -1.0}, None))
    with pytest.raises(ExsceError, match="goal timeout of mission 'mission_c' must be above 0 s, not 0"):
        schedule(_with_timeouts(scenario_c, {}, 0.0))
