"""Robots do not drive into each other: giving way, then repairing the plan where they still meet.

Distances are measured here on the executor's sampled positions (numpy, every pair, every
sample), not taken from what the repair code says it did.  The derivations are ones in which,
before repairs, robots drove through each other (the campaign's false alarms: a safety limit
of 0.1 m between robots failed on a fault-free executor).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
import pytest

from exsce_dsl.lang import load_spec
from exsce_dsl.maps.planning import PlanningGrid, planning_grid
from exsce_dsl.model import Scenario, Task
from exsce_dsl.sim.conflicts import CLEARANCE, conflict_repairs
from exsce_dsl.sim.executor import Fault, SimulatedExecution, execute
from exsce_dsl.sim.motion import DT, SampledMotion
from exsce_dsl.transform.derivation import derive

from tests.support.paths import EXAMPLES

MET_BEFORE = {
    "a new robot for tiago1, tiago2 on another delivery": (
        ("substitute_task", {"task": "delivery_b", "with": "delivery_d"}),
        ("replace_robot", {"by": "new_robot_1", "robot": "tiago1"}),
    ),
    "a robot from classroom_c018 does tiago2's tasks": (
        (
            "add_robot",
            {"like": "tiago1", "robot": "new_robot_1", "start": "classroom_c018-w001", "take_over": "tiago2"},
        ),
        ("remove_start_pose", {"robot": "tiago2"}),
    ),
    # their first legs swap places 1.9 m apart: each robot's goal is where the other stands
    "tiago1 and tiago2 swap places in classroom_c025": (
        ("reverse_task_order", {}),
        ("swap_start_poses", {"robot": "tiago1", "with": "tiago2"}),
    ),
}


@pytest.fixture(scope="module")
def spec_tasks() -> tuple[Scenario, dict[str, Task]]:
    spec = load_spec(EXAMPLES / "brsu_building_c" / "scenario_c.exsce")
    return spec.scenario(), {d.id: d for d in spec.declarations() if isinstance(d, Task)}


@pytest.fixture(scope="module")
def grid(spec_tasks: tuple[Scenario, dict[str, Task]]) -> PlanningGrid:
    return planning_grid(spec_tasks[0])


def closest(execution: SimulatedExecution) -> float:
    """The smallest distance between two robots' centres over the run, in metres."""
    tr = execution.trajectories
    return min(
        float(np.hypot(tr[a].x - tr[b].x, tr[a].y - tr[b].y).min()) for a, b in itertools.combinations(tr, 2)
    )


@pytest.mark.parametrize("name", sorted(MET_BEFORE))
def test_robots_keep_clear_where_they_used_to_meet(
    name: str, spec_tasks: tuple[Scenario, dict[str, Task]], grid: PlanningGrid
) -> None:
    base, tasks = spec_tasks
    scenario = derive(base, MET_BEFORE[name], tasks=tasks).scenario
    for seed in (1, 2, 3):
        execution = execute(scenario, grid, seed)
        assert closest(execution) >= CLEARANCE, (name, seed)
        assert {a.status.name for a in execution.actions} == {"SUCCEEDED"}  # nobody gave a goal up


def test_the_shipped_scenario_keeps_clear(
    spec_tasks: tuple[Scenario, dict[str, Task]], grid: PlanningGrid
) -> None:
    for seed in (1, 2, 3):
        assert closest(execute(spec_tasks[0], grid, seed)) >= CLEARANCE


def test_the_near_collision_fault_is_not_repaired(
    spec_tasks: tuple[Scenario, dict[str, Task]], grid: PlanningGrid
) -> None:
    assert closest(execute(spec_tasks[0], grid, 1, (Fault.parse("near-collision"),))) < 0.2


@dataclass(frozen=True)
class Drive:
    robot: str
    start: float
    end: float


def test_the_robot_that_drives_into_one_that_stands_goes_round_it() -> None:
    n = 200
    line = np.linspace(0.0, 4.0, n)
    still = np.zeros(n)
    trajectories = {
        "first": SampledMotion(still + 2.0, still + 0.1, still, still, still),  # stands on the way
        "second": SampledMotion(line, still, still, still + 0.5, still),  # drives through it
    }
    actions = [Drive("first", 0.0, 0.0), Drive("second", 0.0, n * DT), Drive("second", n * DT, n * DT)]
    [first, *rest] = conflict_repairs(trajectories, actions, ["first", "second"])
    assert first.leg == ("second", 1)
    assert first.place == pytest.approx((2.0, 0.1))
    assert [r.leg for r in rest] == [("first", 1)]  # the one that stands comes after

    apart = {**trajectories, "first": SampledMotion(still + 2.0, still + 2.0, still, still, still)}
    assert conflict_repairs(apart, actions, ["first", "second"]) == []


def test_a_later_meeting_is_offered_after_the_first() -> None:
    """When the first meeting cannot be repaired (say, at a leg's goal), the next one still can."""
    n = 400
    still = np.zeros(n)
    there_and_back = np.concatenate([np.linspace(0.0, 4.0, n // 2), np.linspace(4.0, 0.0, n // 2)])
    trajectories = {
        "first": SampledMotion(still + 2.0, still + 0.1, still, still, still),
        "second": SampledMotion(there_and_back, still, still, still + 0.5, still),  # passes it twice
    }
    actions = [
        Drive("first", 0.0, 0.0),
        Drive("second", 0.0, n / 2 * DT),
        Drive("second", n / 2 * DT, n * DT),
    ]
    repairs = conflict_repairs(trajectories, actions, ["first", "second"])
    assert [r.leg for r in repairs] == [("second", 1), ("first", 1), ("second", 2), ("first", 1)]


def test_a_robot_farther_than_the_safe_distance_never_makes_another_give_way() -> None:
    """give_way skips its checks when no robot is within SAFE_DISTANCE: that holds only while the
    nearest a robot keeps from one standing (GOAL_WAIT, CLEARANCE + 0.1) is below it."""
    from exsce_dsl.sim import give_way

    assert give_way.GOAL_WAIT < give_way.SAFE_DISTANCE
    assert give_way.CLEARANCE + 0.1 < give_way.SAFE_DISTANCE
