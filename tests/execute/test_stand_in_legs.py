"""The stand-in's legs without a ROS graph: planning, driving, the executor's faults, odometry.

A floor without a map (an open grid round the poses): every leg is the straight line, so
lengths and ends are hand calculations.
"""

from __future__ import annotations

import base64
import math
from pathlib import Path

import numpy as np
import pytest

from exsce_dsl.errors import ExsceError
from exsce_dsl.execute.stand_in.legs import FIELDS, Fleet, StandInLeg
from exsce_dsl.lang import load_spec
from exsce_dsl.maps.planning import planning_grid
from exsce_dsl.model import Scenario
from exsce_dsl.sim.faults import DEADLOCK_WAIT, Fault
from exsce_dsl.sim.localisation import SCALE_ERROR
from exsce_dsl.sim.motion import DT

FLOOR = """
environment floor {
  area hall {
    pose hall-a at (0.0, 0.0)
    pose hall-b at (5.0, 0.0)
    pose hall-c at (5.0, 4.0) facing 90.0 deg
  }
  area room {
    pose room-a at (10.0, 0.0)
  }
}

robot type rover {
  base diff_drive
  convention move_base
}

task go {
  visit hall-b
  visit room-a
}

scenario floor_run in floor {
  robots {
    rover: rover namespace "rover" starts at hall-a
    other: rover starts at hall-c
  }
  mission floor_mission parallel {
    rover does go
  }
}
"""


@pytest.fixture(scope="module")
def floor(tmp_path_factory: pytest.TempPathFactory) -> Scenario:
    spec = Path(tmp_path_factory.mktemp("floor")) / "floor.exsce"
    spec.write_text(FLOOR)
    return load_spec(spec).scenario(None)


def fleet(scenario: Scenario, *faults: str) -> Fleet:
    return Fleet(scenario, planning_grid(scenario), seed=3, faults=tuple(Fault.parse(f) for f in faults))


def length(leg: StandInLeg, frame: str = "truth") -> float:
    poses = getattr(leg, frame)
    return float(np.hypot(np.diff(poses.x), np.diff(poses.y)).sum())


def test_a_leg_drives_the_straight_line_to_the_goal_within_the_speed_limit(floor: Scenario) -> None:
    leg = fleet(floor).leg("rover", "g1", 5.0, 0.0, 0.0, 0.0)
    assert leg.succeeded
    assert (leg.truth.x[-1], leg.truth.y[-1]) == pytest.approx((5.0, 0.0), abs=1e-9)
    assert length(leg) == pytest.approx(5.0, abs=1e-3)  # from its first sample, a step off the start
    assert abs(length(leg, "odom") - 5.0) <= 5.0 * SCALE_ERROR[1] + 1e-6
    assert 0.5 < float(leg.command_v.max()) <= 0.6 + 1e-9  # the limit, seeded 90-100 % of 0.6 m/s
    assert leg.scans.shape == (math.ceil(len(leg) / 5), 720)


def test_odometry_goes_on_from_leg_to_leg_and_the_frames_compose_to_the_estimate(floor: Scenario) -> None:
    robots = fleet(floor)
    first = robots.leg("rover", "g1", 5.0, 0.0, 0.0, 0.0)
    second = robots.leg("rover", "g2", 5.0, 4.0, math.pi / 2, 20.0)
    step = math.hypot(second.odom.x[0] - first.odom.x[-1], second.odom.y[0] - first.odom.y[-1])
    assert step < 0.6 * DT * 1.1  # one sample's motion at most, no jump back to zero
    composed = second.correction.compose(second.odom)
    assert np.allclose(composed.x, second.estimate.x) and np.allclose(composed.y, second.estimate.y)
    assert np.hypot(second.estimate.x - second.truth.x, second.estimate.y - second.truth.y).max() < 0.1


def test_the_command_carries_every_sample(floor: Scenario) -> None:
    leg = fleet(floor).leg("rover", "g1", 5.0, 0.0, 0.0, 0.0)
    command = leg.command()
    values = np.frombuffer(base64.b64decode(command["poses"]), dtype="<f8").reshape(-1, FIELDS)
    assert command["samples"] == len(leg) == len(values)
    assert values[-1, 0] == leg.odom.x[-1] and values[-1, 11] == leg.command_v[-1]
    assert command["outcome"] == "succeeded" and command["goal"] == "g1"


def test_skip_waypoint_aborts_the_robots_nth_goal_where_it_stands(floor: Scenario) -> None:
    robots = fleet(floor, "skip-waypoint:rover:2")
    assert robots.leg("rover", "g1", 5.0, 0.0, 0.0, 0.0).succeeded
    aborted = robots.leg("rover", "g2", 10.0, 0.0, 0.0, 10.0)
    assert not aborted.succeeded and length(aborted) == 0.0
    assert (aborted.truth.x[0], aborted.truth.y[0]) == pytest.approx((5.0, 0.0), abs=1e-9)
    assert robots.leg("rover", "g3", 10.0, 0.0, 0.0, 20.0).succeeded


def test_speed_faults_change_the_robots_speed(floor: Scenario) -> None:
    fast = fleet(floor, "overspeed:rover").leg("rover", "g1", 5.0, 0.0, 0.0, 0.0)
    slow = fleet(floor, "slow:rover").leg("rover", "g1", 5.0, 0.0, 0.0, 0.0)
    many = fleet(floor, "overspeed-many-tasks:0").leg("rover", "g1", 5.0, 0.0, 0.0, 0.0)
    assert float(fast.command_v.max()) > 1.0 and float(many.command_v.max()) > 1.0
    assert float(slow.command_v.max()) <= 0.3 + 1e-9


def test_deadlock_start_holds_every_robot_before_its_first_goal_only(floor: Scenario) -> None:
    robots = fleet(floor, "deadlock-start:rover:hall-a")
    first = robots.leg("rover", "g1", 5.0, 0.0, 0.0, 0.0)
    standing = int(round(DEADLOCK_WAIT / DT))
    assert np.all(first.command_v[:standing] == 0.0) and first.command_v[standing:].max() > 0.5
    second = robots.leg("rover", "g2", 5.0, 4.0, 0.0, 200.0)
    assert second.command_v[: int(5 / DT)].max() > 0.0
    assert robots.leg("other", "h1", 5.0, 0.0, 0.0, 0.0).command_v[:standing].max() == 0.0


def test_detour_goes_by_way_of_the_start_pose_from_one_area_to_the_other(floor: Scenario) -> None:
    robots = fleet(floor, "detour:hall:room")
    robots.leg("rover", "g1", 5.0, 0.0, 0.0, 0.0)  # to hall-b: within the hall, no detour
    leg = robots.leg("rover", "g2", 10.0, 0.0, 0.0, 20.0)  # hall-b → room-a, by way of hall-a
    assert length(leg) == pytest.approx(5.0 + 10.0, abs=1e-3)
    assert np.hypot(leg.truth.x, leg.truth.y).min() < 1e-6


def test_slow_area_slows_the_leg_that_enters_the_area(floor: Scenario) -> None:
    plain = fleet(floor).leg("rover", "g1", 10.0, 0.0, 0.0, 0.0)
    slowed = fleet(floor, "slow-area:room").leg("rover", "g1", 10.0, 0.0, 0.0, 0.0)
    assert length(slowed) == pytest.approx(length(plain), abs=1e-3)
    assert len(slowed) > 1.2 * len(plain)


def test_a_stopped_goal_leaves_the_robot_where_the_node_stopped_it(floor: Scenario) -> None:
    robots = fleet(floor)
    leg = robots.leg("rover", "g1", 5.0, 0.0, 0.0, 0.0)
    robots.stopped("rover", "g1", 100)
    assert robots.robots["rover"].at.truth[:2] == pytest.approx((leg.truth.x[100], leg.truth.y[100]))
    again = robots.leg("rover", "g2", 5.0, 0.0, 0.0, 10.0)
    assert (again.truth.x[0], again.truth.y[0]) == pytest.approx(
        (leg.truth.x[100], leg.truth.y[100]), abs=0.02
    )
    robots.stopped("rover", "g2", -1)  # stopped before it moved: where it stood before the goal
    assert robots.robots["rover"].at.truth[:2] == pytest.approx((leg.truth.x[100], leg.truth.y[100]))


def test_faults_the_stand_in_cannot_play_or_that_name_nothing_are_refused(floor: Scenario) -> None:
    with pytest.raises(ExsceError, match="near-collision"):
        fleet(floor, "near-collision")
    with pytest.raises(ExsceError, match="robot 'robber'"):
        fleet(floor, "overspeed:robber")
