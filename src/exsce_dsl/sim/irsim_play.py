"""Play a scenario in IR-SIM: the dispatcher is ours, the driving is IR-SIM's.

What is ours: the mission (each robot's allocated tasks in order, in a parallel mission side by
side, in a sequential one an allocation entry only once every entry before it is done), one goal
per subtask and one leg per waypoint, exactly as the kinematic executor dispatches them; each
leg's global path, planned on the occupancy grid with room to spare; and the outcome of a leg,
judged as Nav2's navigator judges one: *succeeded* when IR-SIM says the robot arrived (within
:data:`~exsce_dsl.sim.irsim_world.GOAL_TOLERANCE` of the waypoint), *aborted* when IR-SIM stopped
the robot on a collision, when it has not moved :data:`PROGRESS_RADIUS` in
:data:`PROGRESS_TIME` (Nav2's progress checker) or when the leg outlives its timeout.

What is IR-SIM's: the motion between the path's points (its behaviour: ``dash``, ``rvo``,
``orca``, ``sfm``), the kinematics and their limits, the collisions (robot–robot and robot–map,
``collision_mode: stop``), the scans (with ``scans="irsim"``: its ``lidar2d``) and the clock (its
fixed step, :data:`STEP` unless told: IR-SIM's own default).  Every step of IR-SIM is one sample of
the run, and the bag's topics are written at the step's rate at most: nothing is interpolated.
"""

from __future__ import annotations

import contextlib
import io
import math
import random
import tempfile
from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from exsce_dsl.errors import ExsceError
from exsce_dsl.maps.planning import PlanningGrid, Point
from exsce_dsl.model import MissionType, Pose, Scenario
from exsce_dsl.model.goals import GoalStatus
from exsce_dsl.remedies import INSTALL_IRSIM
from exsce_dsl.sim.actions import GoalEvent, SimulatedAction
from exsce_dsl.sim.executor import SimulatedExecution
from exsce_dsl.sim.faults import Fault, check_faults, speed_factor
from exsce_dsl.sim.irsim_world import STEP, check_settings, world_file
from exsce_dsl.sim.laser import SCAN_PERIOD, Laser, RecordedScans
from exsce_dsl.sim.motion import Limits, SampledMotion
from exsce_dsl.sim.values import samples_per

PROGRESS_RADIUS = 0.5
PROGRESS_TIME = 10.0
"""Nav2's progress checker: a leg whose robot has not moved PROGRESS_RADIUS metres in
PROGRESS_TIME seconds is aborted."""
PATH_SPACING = 0.3
"""Metres between the points of a leg's global path that IR-SIM is given as goals: the planned
path through the middle of the free space, not one cut short at corners (IR-SIM's behaviours turn
wide, and a corner cut at the planner's clearance leaves them none)."""
FAULTS_PLAYED = ("overspeed", "slow", "overspeed-many-tasks", "overspeed-reassigned", "skip-waypoint")
"""The deliberate faults IR-SIM plays: those of a robot's speed limit (its ``vel_max``) and the
dispatcher's skipped waypoint; the others are planted in the kinematic executor's own driving."""


def irsim_module() -> Any:
    """IR-SIM, imported; a clear error when the ``irsim`` extra is not installed.  IR-SIM prints
    on standard output which of matplotlib's backends it could not use while it is imported:
    that goes nowhere (it draws nothing here), so that exscec's output stays its own."""
    try:
        with contextlib.redirect_stdout(io.StringIO()):
            import irsim
    except ImportError:
        raise ExsceError("IR-SIM is not installed", remedy=INSTALL_IRSIM) from None
    return irsim


def irsim_version() -> str:
    return str(irsim_module().__version__)


def play_in_irsim(
    scenario: Scenario,
    grid: PlanningGrid,
    seed: int,
    faults: tuple[Fault, ...] = (),
    behaviour: str = "rvo",
    scans: str = "exsce",
    limits: Limits | None = None,
    step: float = STEP,
) -> SimulatedExecution:
    """Play ``scenario`` once in IR-SIM.  ``scans``
    (:data:`~exsce_dsl.sim.irsim_world.SCAN_SOURCES`): who measures the robots' scans."""
    irsim = irsim_module()
    check_faults(scenario, faults)
    refused = sorted({f.kind for f in faults} - set(FAULTS_PLAYED))
    if refused:
        raise ExsceError(
            f"IR-SIM does not play the fault(s) {', '.join(refused)} (it plays {', '.join(FAULTS_PLAYED)}); "
            "the others are planted in exsce's kinematic executor"
        )
    check_settings(behaviour, scans)
    laser = Laser(noise=0.0) if scans == "irsim" else None
    limits = limits or Limits()
    rng = random.Random(seed)
    speeds = {
        r.id: limits.max_speed * rng.uniform(0.9, 1.0) * speed_factor(scenario, r.id, faults)
        for r in scenario.robots
    }
    with tempfile.TemporaryDirectory(prefix="exsce-irsim-") as folder:
        world = world_file(scenario, grid, Path(folder), behaviour, speeds, laser, limits, step)
        env = irsim.make(str(world), display=False, headless=True, seed=seed, log_level="CRITICAL")
    try:
        played = _Lockstep(env, scenario, grid, rng, faults, laser, step).run()
        return played if scans == "irsim" else replace(played, scans=None if scans == "exsce" else {})
    finally:
        env.end(0)


class _Lockstep:
    """One playing: every robot's dispatcher program advanced once per IR-SIM step, and every
    robot's state recorded after it."""

    def __init__(
        self,
        env: Any,
        scenario: Scenario,
        grid: PlanningGrid,
        rng: random.Random,
        faults: tuple[Fault, ...],
        laser: Laser | None,
        step: float,
    ) -> None:
        self.env, self.scenario, self.grid, self.rng, self.laser = env, scenario, grid, rng, laser
        self.dt = step
        self.scan_every = samples_per(SCAN_PERIOD, step)
        self.robots = {obj.name: obj for obj in env.robot_list}
        for obj in self.robots.values():  # IR-SIM gives a robot with no goal a default one: none
            obj.set_goal(None)
        for found in env.objects:
            if found.shape == "map":  # static: its geometry is indexed once, not at each test
                import shapely

                shapely.prepare(found._geometry)
        self.sensors = {name: list(obj.sensors) for name, obj in self.robots.items()}
        self.samples: dict[str, list[tuple[float, float, float, float, float]]] = {
            name: [self._state(obj, first=True)] for name, obj in self.robots.items()
        }
        self.scans: dict[str, list[tuple[int, np.ndarray]]] = {name: [] for name in self.robots}
        self.k = 0  # samples so far, after the first
        self.events: list[GoalEvent] = []
        self.actions: list[SimulatedAction] = []
        self.done: set[int] = set()
        self.skip = {(f.robot, f.index) for f in faults if f.kind == "skip-waypoint"}
        self.last_pose = {r.id: r.start_pose for r in scenario.robots if r.start_pose is not None}

    @property
    def now(self) -> float:
        return self.k * self.dt

    def run(self) -> SimulatedExecution:
        programs = {name: self._program(name) for name in self.robots}
        while programs:
            for name, program in list(programs.items()):
                if next(program, None) is None:  # the robot's dispatcher is done
                    del programs[name]
            if programs:
                self._step()
        for _ in range(int(round(1.0 / self.dt))):  # a second after the last robot is done
            self._step()
        trajectories = {name: _motion(rows) for name, rows in self.samples.items()}
        self.events.sort(key=lambda e: (e.t, e.robot))
        return SimulatedExecution(
            trajectories, self.events, self.actions, len(self.samples[next(iter(self.samples))]) * self.dt,
            self._recorded_scans(), self.dt,
        )  # fmt: skip

    def _step(self) -> None:
        self.k += 1
        scanning = self.laser is not None and self.k % self.scan_every == 0
        for name, obj in self.robots.items():
            obj.sensors = self.sensors[name] if scanning else []
        self.env.step()
        for name, obj in self.robots.items():
            self.samples[name].append(self._state(obj))
            if scanning and obj.sensors:
                self.scans[name].append((self.k, _ranges(obj.sensors[0])))

    @staticmethod
    def _state(obj: Any, first: bool = False) -> tuple[float, float, float, float, float]:
        state = obj.state[:, 0]
        v, w = (0.0, 0.0) if first else (float(obj.velocity[0, 0]), float(obj.velocity[1, 0]))
        return float(state[0]), float(state[1]), float(state[2]), v, w

    def _recorded_scans(self) -> dict[str, RecordedScans]:
        if self.laser is None:
            return {}
        return {
            name: RecordedScans(
                self.laser,
                np.array([k for k, _ in rows], dtype=np.int64),
                np.array([r for _, r in rows], dtype=np.float32).reshape(len(rows), self.laser.beams),
            )
            for name, rows in self.scans.items()
        }

    def _hold(self, seconds: float) -> Iterator[bool]:
        for _ in range(int(round(seconds / self.dt))):
            yield True

    def _program(self, robot: str) -> Iterator[bool]:
        """The dispatcher of one robot: each ``yield`` lets one step of IR-SIM pass."""
        yield from self._hold(self.rng.uniform(0.5, 1.0))
        entries = [(n, e.task) for n, e in enumerate(self.scenario.mission.allocation) if e.robot == robot]
        for task_number, (number, task_id) in enumerate(entries, start=1):
            if self.scenario.mission.type is MissionType.SEQUENTIAL:
                while not all(n in self.done for n in range(number)):
                    yield True
            task = self.scenario.task(task_id)
            assert task is not None
            for s_number, subtask in enumerate(task.subtasks, start=1):
                yield from self._subtask(robot, task_number, task_id, s_number, subtask.waypoints)
            self.done.add(number)

    def _subtask(
        self, robot: str, task_number: int, task_id: str, s_number: int, waypoints: tuple[Pose, ...]
    ) -> Iterator[bool]:
        """One dispatcher goal: accepted, then each waypoint active, driven to and recorded."""
        ids = tuple(w.id for w in waypoints)
        key = f"{robot}-task_{task_number:02d}-subtask_{s_number:03d}"
        statuses = [GoalStatus.PENDING] * len(ids)
        yield from self._hold(0.1)
        self.events.append(GoalEvent(self.now, robot, key, ids, tuple(statuses), False))  # accepted
        yield from self._hold(0.1)
        for w_number, goal in enumerate(waypoints, start=1):
            statuses[w_number - 1] = GoalStatus.ACTIVE
            start = self.now
            self.events.append(GoalEvent(start, robot, key, ids, tuple(statuses), False))
            leg = _Leg(robot, goal)
            yield from self._drive(leg)
            statuses[w_number - 1] = leg.status
            driven = leg.length if leg.status is GoalStatus.SUCCEEDED else 0.0
            self.actions.append(
                SimulatedAction(
                    robot, task_number, task_id, s_number, w_number, self.last_pose[robot], goal,
                    start, self.now, leg.status, driven, tuple(leg.path), leg.outcome,
                )  # fmt: skip
            )
            self.last_pose[robot] = goal
            self.events.append(GoalEvent(self.now, robot, key, ids, tuple(statuses), w_number == len(ids)))
            yield from self._hold(self.rng.uniform(0.2, 0.6))

    def _drive(self, leg: _Leg) -> Iterator[bool]:
        """Hand the leg's path to IR-SIM as the robot's goals and watch until it is decided."""
        obj = self.robots[leg.robot]
        here = (float(obj.state[0, 0]), float(obj.state[1, 0]))
        target = (leg.goal.position.x, leg.goal.position.y)
        leg.path = spaced(self.grid.cell_path(here, target))
        leg.count = self._count(leg.robot)
        if (leg.robot, leg.count) in self.skip or obj.stop_flag:
            yield from self._hold(0.5 if not obj.stop_flag else 0.0)
            leg.status = GoalStatus.ABORTED
            leg.outcome = "collided" if obj.stop_flag else None
            return
        ahead = leg.path[1:] or leg.path[-1:]  # the robot may stand on its goal already
        obj.set_goal([[x, y, leg.goal.orientation.yaw] for x, y in ahead])
        timeout = self.k + int((2.0 * leg.length / max(float(obj.vel_max[0, 0]), 0.05) + 60.0) / self.dt)
        anchor, since = here, self.k
        while True:
            yield True
            at = (float(obj.state[0, 0]), float(obj.state[1, 0]))
            if obj.arrive_flag and not obj.stop_flag:
                leg.status = GoalStatus.SUCCEEDED
                break
            if math.dist(at, anchor) >= PROGRESS_RADIUS:
                anchor, since = at, self.k
            stuck = (self.k - since) * self.dt > PROGRESS_TIME
            if obj.stop_flag or stuck or self.k > timeout:
                leg.status = GoalStatus.ABORTED
                leg.outcome = "collided" if obj.stop_flag else "no progress" if stuck else "timed out"
                break
        obj.set_goal(None)

    def _count(self, robot: str) -> int:
        return sum(1 for a in self.actions if a.robot == robot) + 1


class _Leg:
    """One waypoint goal being driven: its planned path and, once decided, its status."""

    def __init__(self, robot: str, goal: Pose) -> None:
        self.robot, self.goal = robot, goal
        self.path: list[Point] = []
        self.count = 0
        self.status = GoalStatus.PENDING
        self.outcome: str | None = None

    @property
    def length(self) -> float:
        return sum(math.dist(a, b) for a, b in zip(self.path, self.path[1:], strict=False))


def spaced(path: list[Point]) -> list[Point]:
    """The path's points PATH_SPACING apart along it, its ends kept."""
    kept, since = [path[0]], 0.0
    for a, b in zip(path, path[1:], strict=False):
        since += math.dist(a, b)
        if since >= PATH_SPACING:
            kept.append(b)
            since = 0.0
    if kept[-1] != path[-1]:
        kept.append(path[-1])
    return kept


def _ranges(lidar: Any) -> np.ndarray:
    """A scan as ROS writes one (REP 117): +inf where the beam hit nothing, -inf where it hit
    inside the minimum range."""
    ranges = np.array(lidar.range_data, dtype=np.float64)
    valid = np.asarray(lidar.valid, dtype=bool)
    blind = ~valid & (ranges <= lidar.range_min)
    return np.where(valid, ranges, np.where(blind, -np.inf, np.inf))


def _motion(rows: list[tuple[float, float, float, float, float]]) -> SampledMotion:
    a = np.array(rows, dtype=np.float64)
    return SampledMotion(a[:, 0], a[:, 1], a[:, 2], a[:, 3], a[:, 4])
