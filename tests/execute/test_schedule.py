"""The mission as a schedule of goals: lanes, order, poses and timeouts, against scenario_c written
out by hand (examples/brsu_building_c: scenario_c.exsce, tasks/*.exsce, environment.exsce)."""

from __future__ import annotations

import math
from dataclasses import replace

import pytest

from exsce_dsl.errors import ExsceError
from exsce_dsl.execute.mission import TIMEOUT_FLOOR, goal_timeout, schedule
from exsce_dsl.lang.build import load_spec
from exsce_dsl.model import MissionType

from conftest import EXAMPLES

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
