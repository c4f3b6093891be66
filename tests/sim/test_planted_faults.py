"""Latent faults: hidden in scenario_c's own runs, revealed by one derivation of it.

Each fault is planted in scenario_c and in the one-step derivation that should reveal it, and
played with the same seed with and without it.  Everything measured here comes from the
executor's output (the robots' sampled positions and the dispatcher's events), not from what
the fault code says it did.  Run-to-run noise, for the margins: a robot's seeded speed varies
by 10 % between seeds and its start by half a second; paths, hence distances, do not vary.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from exsce_dsl.errors import ExsceError
from exsce_dsl.lang import load_spec
from exsce_dsl.maps.planning import PlanningGrid, planning_grid
from exsce_dsl.model import Scenario
from exsce_dsl.sim.executor import Fault, GoalStatus, SimulatedExecution, execute
from exsce_dsl.sim.motion import DT
from exsce_dsl.sim.run import simulate
from exsce_dsl.transform.derivation import derive

from tests.support.paths import EXAMPLES

SEEDS = (1, 2)
C069 = (11.721145629882812, 53.50111770629883, 12.687057495117188, 55.12968444824219)
"""classroom_c069's poses (x0, y0, x1, y1), as environment.exsce declares them."""


@dataclass(frozen=True)
class Planted:
    fault: str
    step: tuple[str, dict[str, str]]


SLOW_AREA = Planted(
    "slow-area:classroom_c069",
    ("replace_robot", {"robot": "tiago2", "by": "tiago3", "start": "classroom_c069-w001"}),
)
DETOUR = Planted("detour:classroom_c018:classroom_c022", ("reverse_waypoint_order", {"task": "delivery_a"}))
DEADLOCK = Planted(
    "deadlock-start:tiago1:classroom_c025-w002", ("swap_start_poses", {"robot": "tiago1", "with": "tiago2"})
)
MANY_TASKS = Planted("overspeed-many-tasks:2", ("remove_robot", {"robot": "tiago2", "reassign": "tiago1"}))
REASSIGNED = Planted(
    "overspeed-reassigned:delivery_a:tiago1", ("swap_assignment", {"robot": "tiago1", "with": "tiago2"})
)
PLANTED = (SLOW_AREA, DETOUR, DEADLOCK, MANY_TASKS, REASSIGNED)


@pytest.fixture(scope="module")
def scenario_c() -> Scenario:
    return load_spec(EXAMPLES / "brsu_building_c" / "scenario_c.exsce").scenario()


@pytest.fixture(scope="module")
def grid(scenario_c: Scenario) -> PlanningGrid:
    return planning_grid(scenario_c)


@pytest.fixture(scope="module")
def plain_runs(scenario_c: Scenario, grid: PlanningGrid) -> dict[int, SimulatedExecution]:
    return {seed: execute(scenario_c, grid, seed) for seed in SEEDS}


def _derived(scenario_c: Scenario, planted: Planted) -> Scenario:
    return derive(scenario_c, [planted.step], "derived").scenario


def _played(
    scenario: Scenario, grid: PlanningGrid, planted: Planted, seed: int = 1
) -> tuple[SimulatedExecution, SimulatedExecution]:
    """``scenario`` played without, then with the planted fault."""
    return execute(scenario, grid, seed), execute(scenario, grid, seed, (Fault.parse(planted.fault),))


# What a run shows, from the robots' positions: distance, speed, when they move.


def _steps(execution: SimulatedExecution, robot: str) -> np.ndarray:
    tr = execution.trajectories[robot]
    return np.hypot(np.diff(tr.x), np.diff(tr.y))


def travelled(execution: SimulatedExecution, robot: str) -> float:
    return float(_steps(execution, robot).sum())


def top_speed(execution: SimulatedExecution, robot: str) -> float:
    return float(_steps(execution, robot).max() / DT)


def driving_time(execution: SimulatedExecution, robot: str) -> float:
    """Seconds in which the robot's position changes."""
    return float(np.count_nonzero(_steps(execution, robot) > 1e-9) * DT)


def first_move(execution: SimulatedExecution, robot: str) -> float:
    return float(np.flatnonzero(_steps(execution, robot) > 1e-9)[0] * DT)


def last_move(execution: SimulatedExecution) -> float:
    """When the last robot stops for good: the mission's end."""
    moved = (np.flatnonzero(_steps(execution, r) > 1e-9) for r in execution.trajectories)
    return max(float(m[-1] * DT) for m in moved if len(m))


def _same(a: SimulatedExecution, b: SimulatedExecution) -> bool:
    fields = ("x", "y", "yaw", "v", "w")
    return (
        a.trajectories.keys() == b.trajectories.keys()
        and all(
            np.array_equal(getattr(a.trajectories[r], f), getattr(b.trajectories[r], f))
            for r in a.trajectories
            for f in fields
        )
        and a.events == b.events
        and a.actions == b.actions
        and a.duration == b.duration
    )


@pytest.mark.parametrize("planted", PLANTED, ids=lambda p: p.fault)
@pytest.mark.parametrize("seed", SEEDS)
def test_scenario_c_runs_as_if_the_fault_were_not_there(
    planted: Planted,
    seed: int,
    scenario_c: Scenario,
    grid: PlanningGrid,
    plain_runs: dict[int, SimulatedExecution],
) -> None:
    faulty = execute(scenario_c, grid, seed, (Fault.parse(planted.fault),))
    assert _same(faulty, plain_runs[seed])  # identical, so within any run-to-run noise


def test_the_seeds_differ_so_identity_is_not_a_blind_comparison(
    plain_runs: dict[int, SimulatedExecution],
) -> None:
    assert not _same(plain_runs[SEEDS[0]], plain_runs[SEEDS[1]])


def test_slow_area_shows_when_a_robot_starts_in_the_area(scenario_c: Scenario, grid: PlanningGrid) -> None:
    derived = _derived(scenario_c, SLOW_AREA)
    without, with_fault = _played(derived, grid, SLOW_AREA)
    # the same path, much more slowly: the leg out of c069 (the whole drive to classroom_c022) at 40 %
    assert travelled(with_fault, "tiago3") == pytest.approx(travelled(without, "tiago3"), abs=0.05)
    assert driving_time(with_fault, "tiago3") > 1.5 * driving_time(without, "tiago3")
    assert last_move(with_fault) > last_move(without) + 60.0
    tr = with_fault.trajectories["tiago3"]
    x0, y0, x1, y1 = C069
    inside = (tr.x >= x0 - 1.5) & (tr.x <= x1 + 1.5) & (tr.y >= y0 - 1.5) & (tr.y <= y1 + 1.5)
    speed = np.hypot(np.diff(tr.x), np.diff(tr.y)) / DT
    assert inside.any() and speed[inside[1:]].max() < 0.45 * top_speed(without, "tiago3")
    # the other robots keep to what they did
    assert driving_time(with_fault, "tiago1") == pytest.approx(driving_time(without, "tiago1"), abs=1.0)


def test_detour_shows_when_delivery_a_is_driven_backwards(
    scenario_c: Scenario, grid: PlanningGrid, plain_runs: dict[int, SimulatedExecution]
) -> None:
    derived = _derived(scenario_c, DETOUR)
    without, with_fault = _played(derived, grid, DETOUR)
    base = travelled(plain_runs[1], "tiago1")
    # the metamorphic expectation: the same triangle of rooms driven the other way round
    assert travelled(without, "tiago1") == pytest.approx(base, rel=0.02)
    assert travelled(with_fault, "tiago1") > base * 1.1 + 3.0  # paths do not vary between runs
    assert driving_time(with_fault, "tiago1") > driving_time(without, "tiago1") + 10.0
    # tiago2's path is its own; only giving way to tiago1 (backing up, or going round where
    # tiago1 stands) may change its distance a little
    assert travelled(with_fault, "tiago2") == pytest.approx(travelled(without, "tiago2"), rel=0.1)


def test_deadlock_shows_when_the_start_poses_are_swapped(scenario_c: Scenario, grid: PlanningGrid) -> None:
    derived = _derived(scenario_c, DEADLOCK)
    without, with_fault = _played(derived, grid, DEADLOCK)
    for robot in ("tiago1", "tiago2"):
        assert first_move(without, robot) < 5.0
        active = min(e.t for e in with_fault.events if e.robot == robot and GoalStatus.ACTIVE in e.statuses)
        assert active < 5.0 and first_move(with_fault, robot) > 100.0  # stands with its first goal active
    assert last_move(with_fault) > last_move(without) + 100.0


def test_overspeed_shows_when_one_robot_takes_all_tasks(
    scenario_c: Scenario, grid: PlanningGrid, plain_runs: dict[int, SimulatedExecution]
) -> None:
    derived = _derived(scenario_c, MANY_TASKS)
    without, with_fault = _played(derived, grid, MANY_TASKS)
    limit = 0.6  # the executor's speed limit; the method's safety limit is 1.0 m/s
    assert max(top_speed(plain_runs[1], r) for r in ("tiago1", "tiago2")) < limit + 0.02
    assert top_speed(without, "tiago1") < limit + 0.02
    assert top_speed(with_fault, "tiago1") > 1.0
    assert travelled(with_fault, "tiago1") == pytest.approx(travelled(without, "tiago1"), abs=0.05)


def test_overspeed_shows_when_delivery_a_goes_to_the_other_robot(
    scenario_c: Scenario, grid: PlanningGrid, plain_runs: dict[int, SimulatedExecution]
) -> None:
    derived = _derived(scenario_c, REASSIGNED)
    assert ("tiago2", "delivery_a") in {(e.robot, e.task) for e in derived.mission.allocation}
    without, with_fault = _played(derived, grid, REASSIGNED)
    limit = 0.6  # the executor's speed limit
    assert top_speed(without, "tiago2") < limit + 0.02
    assert top_speed(with_fault, "tiago2") > 1.0
    assert top_speed(with_fault, "tiago1") < limit + 0.02  # delivery_b, not its own task, is no trigger
    # a task of the same name driven backwards is another task: no trigger either
    backwards = derive(
        scenario_c, [("reverse_waypoint_order", {"task": "delivery_a"}), REASSIGNED.step], "backwards"
    ).scenario
    fault = (Fault.parse(REASSIGNED.fault),)
    assert max(top_speed(execute(backwards, grid, 1, fault), r) for r in ("tiago1", "tiago2")) < limit + 0.02


@pytest.mark.parametrize("planted", PLANTED, ids=lambda p: p.fault)
def test_a_latent_fault_plays_the_same_twice(
    planted: Planted, scenario_c: Scenario, grid: PlanningGrid
) -> None:
    derived = _derived(scenario_c, planted)
    fault = (Fault.parse(planted.fault),)
    assert _same(execute(derived, grid, 5, fault), execute(derived, grid, 5, fault))


def _digest(bag: Path) -> list[str]:
    files = [bag] if bag.is_file() else sorted(bag.iterdir())
    return [hashlib.sha256(p.read_bytes()).hexdigest() for p in files]


def test_same_seed_same_bytes_and_the_arguments_name_the_run(scenario_c: Scenario, tmp_path: Path) -> None:
    derived = _derived(scenario_c, DETOUR)

    def one(folder: str, fault: str) -> Any:
        return next(iter(simulate(derived, tmp_path / folder, 1, seed=3, faults=(Fault.parse(fault),))))

    a, b = one("a", DETOUR.fault), one("b", DETOUR.fault)
    assert a.run_id == b.run_id and _digest(a.bag) == _digest(b.bag)
    other = one("c", "detour:classroom_c022:classroom_c018")
    assert other.run_id != a.run_id


def test_fault_arguments_are_checked(scenario_c: Scenario, grid: PlanningGrid) -> None:
    with pytest.raises(ExsceError, match=r"needs an area and a second area: detour:FROM:TO"):
        Fault.parse("detour:classroom_c018")
    with pytest.raises(ExsceError, match="'two' is not a number of tasks"):
        Fault.parse("overspeed-many-tasks:two")
    with pytest.raises(ExsceError, match="needs a task and a robot: overspeed-reassigned:TASK:ROBOT"):
        Fault.parse("overspeed-reassigned:delivery_a")
    with pytest.raises(ExsceError, match="too many arguments"):
        Fault.parse("slow-area:classroom_c069:classroom_c018")
    with pytest.raises(ExsceError, match="area 'classroom_c96'.*did you mean 'classroom_c069'"):
        execute(scenario_c, grid, 1, (Fault.parse("slow-area:classroom_c96"),))
    with pytest.raises(ExsceError, match="pose 'classroom_c025-w003'"):
        execute(scenario_c, grid, 1, (Fault.parse("deadlock-start:tiago1:classroom_c025-w003"),))
    # a latent fault's robot may be gone (a derivation removed it): no trigger, no error
    alone = derive(scenario_c, [("remove_robot", {"robot": "tiago1"})], "alone").scenario
    quiet = execute(alone, grid, 1, (Fault.parse("deadlock-start:tiago1:classroom_c025-w001"),))
    assert _same(quiet, execute(alone, grid, 1))
