"""The stand-in's robots as this process keeps them: where each stands, and the leg of each goal.

A goal arrives as a target pose; the robot's leg is planned from where it stands on the
scenario's occupancy grid and driven with its limits, as the kinematic executor drives a leg
(:mod:`exsce_dsl.sim.executor`), with the executor's faults (:mod:`exsce_dsl.sim.faults`):

- ``overspeed``, ``slow``, ``overspeed-many-tasks``, ``overspeed-reassigned``: the robot's speed
  limit, seeded as the executor seeds it, times :func:`~exsce_dsl.sim.faults.speed_factor`;
- ``skip-waypoint:ROBOT[:N]``: the robot's N-th goal (counted from 1, every goal it gets) is
  aborted after half a second, the robot standing still;
- ``slow-area``, ``detour``: as the executor (a goal within ``MATCH`` of a pose of the scenario
  is that pose, so its area is known);
- ``deadlock-start``: when it holds, every robot stands ``DEADLOCK_WAIT`` s before its first goal.

``near-collision`` is not played (it is a scripted drive inside the executor's mission, not an
answer to a goal), nor the executor's giving way between robots: here the robots drive their
legs whatever the other does.  The leg's samples (50 Hz) hold the odometry, which drifts and
goes on from leg to leg, the localiser's estimate, the correction ``map → odom``, the velocities
measured and commanded, and a scan every fifth sample against the map and the other robots
where they stood, or drove, when the goal came (:mod:`exsce_dsl.sim.localisation`,
:mod:`exsce_dsl.sim.scan`).
"""

from __future__ import annotations

import base64
import math
import random
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from exsce_dsl.errors import ExsceError, PlanningError
from exsce_dsl.maps.planning import PlanningGrid, Point
from exsce_dsl.model import Orientation, Pose, Position, Scenario
from exsce_dsl.remedies import SIMULATE_IT
from exsce_dsl.sim.faults import (
    DEADLOCK_WAIT,
    Fault,
    area_boxes,
    check_faults,
    deadlocked,
    detour_via,
    slow_in_areas,
    speed_factor,
)
from exsce_dsl.sim.laser import SCAN_EVERY, Laser
from exsce_dsl.sim.localisation import Odometry, PlanarPoses, localise
from exsce_dsl.sim.motion import DT, Limits, SampledMotion, drive
from exsce_dsl.sim.scan import ROBOT_RADIUS, scan_ranges

MATCH = 0.05
"""Metres: a goal this close to a pose of the scenario is that pose."""
ABORT_AFTER = 25
"""Samples a goal the robot aborts takes (0.5 s, as the executor's ``skip-waypoint``)."""
FIELDS = 13
CLEARANCE = 2 * ROBOT_RADIUS + 0.2
"""Metres between two robots' centres that a leg keeps: it waits until the other has gone by."""
WAIT_STEP, MAX_WAIT = 0.5, 60.0
"""Seconds: how a leg's start is put off to let another robot go by, and for how long at most
(then it goes anyway: the other stands in its way for good)."""
STANDING_RADIUS = 0.6
"""Metres round a robot standing in a leg's way that its path goes round (as the executor's)."""
END_ROOM = 0.3
"""Metres that such a disc keeps from the leg's start and goal (else the robot cannot get there)."""
"""Values per sample sent to the node, in this order: odometry x, y, yaw; estimate x, y, yaw;
correction x, y, yaw; measured speed and turn rate; commanded speed and turn rate."""


@dataclass
class Standing:
    """Where a robot is: its true pose and its odometry's pose (``odom → base_link``)."""

    truth: tuple[float, float, float]
    odom: tuple[float, float, float] = (0.0, 0.0, 0.0)
    previous: Pose | None = None
    """The last goal it reached (its start pose at first): where a leg leaves from, for ``detour``."""


@dataclass(frozen=True)
class StandInLeg:
    """One goal's drive, sample by sample (or a robot's start: one sample, no goal)."""

    robot: str
    goal: str | None
    succeeded: bool
    start: float
    """Simulated seconds when the goal came."""
    truth: PlanarPoses
    odom: PlanarPoses
    estimate: PlanarPoses
    correction: PlanarPoses
    v: np.ndarray
    w: np.ndarray
    command_v: np.ndarray
    command_w: np.ndarray
    scans: np.ndarray
    """One row of ranges (float32) per SCAN_EVERY samples."""

    def __len__(self) -> int:
        return len(self.truth.x)

    def standing(self, k: int, previous: Pose | None) -> Standing:
        """Where the robot stands after sample ``k`` (a negative ``k`` counts from the end)."""
        t, o = self.truth, self.odom
        return Standing(
            (float(t.x[k]), float(t.y[k]), float(t.yaw[k])),
            (float(o.x[k]), float(o.y[k]), float(o.yaw[k])),
            previous,
        )

    def rows(self) -> np.ndarray:
        """One row of :data:`FIELDS` values per sample (little-endian float64)."""
        return np.column_stack(
            [
                *(getattr(self.odom, a) for a in ("x", "y", "yaw")),
                *(getattr(self.estimate, a) for a in ("x", "y", "yaw")),
                *(getattr(self.correction, a) for a in ("x", "y", "yaw")),
                self.v,
                self.w,
                self.command_v,
                self.command_w,
            ]
        ).astype("<f8")

    def command(self) -> dict[str, Any]:
        """The ROS 1 node's ``leg`` command: the arrays base64-encoded, little-endian."""
        values = self.rows()
        return {
            "command": "leg",
            "robot": self.robot,
            "goal": self.goal,
            "outcome": "succeeded" if self.succeeded else "aborted",
            "samples": len(self),
            "poses": base64.b64encode(values.tobytes()).decode("ascii"),
            "beams": int(self.scans.shape[1]),
            "scans": base64.b64encode(self.scans.astype("<f4").tobytes()).decode("ascii"),
        }


@dataclass
class StandInRobot:
    name: str
    namespace: str
    limits: Limits
    drift: Odometry
    rng: np.random.Generator
    at: Standing
    goals: int = 0
    """How many goals it has had."""
    legs: dict[str, tuple[StandInLeg, Standing]] = field(default_factory=dict)
    """Each goal's leg and where the robot stood before it."""
    current: StandInLeg | None = None


class Fleet:
    """The scenario's robots, answering goals with legs."""

    def __init__(
        self,
        scenario: Scenario,
        grid: PlanningGrid,
        seed: int = 0,
        faults: tuple[Fault, ...] = (),
        limits: Limits | None = None,
        laser: Laser | None = None,
        run: int = 0,
    ) -> None:
        """``seed`` and ``run``: the robots' speed limits are those of run ``run`` of ``exscec
        simulate --seed SEED`` (their noise is seeded by both too)."""
        check_faults(scenario, faults)
        if any(f.kind == "near-collision" for f in faults):
            raise ExsceError("the stand-in does not play fault 'near-collision'", remedy=SIMULATE_IT)
        self.scenario, self.grid, self.faults = scenario, grid, faults
        self.laser = laser or Laser()
        limits = limits or Limits()
        unplaced = [r.id for r in scenario.robots if r.start_pose is None]
        if unplaced:
            raise ExsceError(f"robot '{unplaced[0]}' has no start pose: the stand-in cannot place it")
        speeds = _executor_speeds(scenario, seed, limits, faults, run)
        self.robots: dict[str, StandInRobot] = {}
        for index, robot in enumerate(scenario.robots):
            start = robot.start_pose
            assert start is not None
            speed = speeds[robot.id]
            rng = np.random.default_rng([seed, index] if run == 0 else [seed, index, run])
            self.robots[robot.id] = StandInRobot(
                robot.id,
                robot.namespace,
                Limits(speed, limits.max_accel, limits.max_turn_rate),
                Odometry.seeded(rng),
                rng,
                Standing((start.position.x, start.position.y, start.orientation.yaw), previous=start),
            )
        self.skip = {(f.robot, f.index) for f in faults if f.kind == "skip-waypoint"}
        self.boxes = area_boxes(scenario, faults)
        self.stuck = deadlocked(scenario, faults)
        self.poses = [*scenario.environment.poses(), *(w for t in scenario.tasks for w in t.waypoints())]

    def start_legs(self) -> list[StandInLeg]:
        """Each robot standing at its start: a leg of one sample without a goal."""
        legs = []
        for robot in self.robots.values():
            x, y, yaw = robot.at.truth
            legs.append(self._leg(robot, None, True, 0.0, SampledMotion.hold(x, y, yaw, 1)))
        return legs

    def leg(self, name: str, goal: str, x: float, y: float, yaw: float, time: float) -> StandInLeg:
        """The leg of goal ``goal`` (target ``x, y, yaw`` in the map) that ``name`` got at ``time``."""
        robot = self.robots.get(name)
        if robot is None:
            raise ExsceError(f"the stand-in has no robot '{name}'")
        robot.goals += 1
        target = self._pose(x, y, yaw)
        trajectory, succeeded = self._drive(robot, target)
        if succeeded:
            trajectory = self._let_pass(robot, trajectory, time)
        leg = self._leg(robot, goal, succeeded, time, trajectory)
        before = robot.at
        robot.legs[goal] = (leg, before)
        robot.at = leg.standing(-1, target if succeeded else before.previous)
        robot.current = leg
        return leg

    def stopped(self, name: str, goal: str, sample: int) -> None:
        """The node stopped ``name``'s goal after the leg's ``sample`` (-1: before it moved)."""
        robot = self.robots[name]
        found = robot.legs.get(goal)
        if found is None:
            return
        leg, before = found
        robot.at = before if sample < 0 else leg.standing(min(sample, len(leg) - 1), before.previous)
        robot.current = None

    def _pose(self, x: float, y: float, yaw: float) -> Pose:
        near = [p for p in self.poses if math.dist((p.position.x, p.position.y), (x, y)) <= MATCH]
        if near:
            found = min(near, key=lambda p: math.dist((p.position.x, p.position.y), (x, y)))
            return found.with_orientation(Orientation(yaw=yaw))
        return Pose("goal", Position(x, y), Orientation(yaw=yaw))

    def _drive(self, robot: StandInRobot, target: Pose) -> tuple[SampledMotion, bool]:
        x, y, yaw = robot.at.truth
        parts = []
        if self.stuck and robot.goals == 1:
            parts.append(SampledMotion.hold(x, y, yaw, int(round(DEADLOCK_WAIT / DT))))
        aborted = SampledMotion.concat([*parts, SampledMotion.hold(x, y, yaw, ABORT_AFTER)])
        if (robot.name, robot.goals) in self.skip:
            return aborted, False
        goal = (target.position.x, target.position.y)
        via = detour_via(self.scenario, robot.name, robot.at.previous, target, self.faults)
        try:
            if via is None:
                path = self._plan_round(robot, (x, y), goal)
                driven = drive(path, yaw, target.orientation.yaw, robot.limits)
            else:
                there, on = self.grid.plan((x, y), via), self.grid.plan(via, goal)
                heading = math.atan2(on[1][1] - on[0][1], on[1][0] - on[0][0]) if len(on) > 1 else yaw
                driven = SampledMotion.concat(
                    [
                        drive(there, yaw, heading, robot.limits),
                        drive(on, heading, target.orientation.yaw, robot.limits),
                    ]
                )
        except PlanningError:
            return aborted, False
        if self.boxes:
            driven = slow_in_areas(driven, self.boxes)
        parts.append(driven if len(driven) else SampledMotion.hold(x, y, yaw, 1))
        return SampledMotion.concat(parts), True

    def _plan_round(self, robot: StandInRobot, start: Point, goal: Point) -> list[Point]:
        """The grid's path, round the robots that stand in its way once their legs are done."""
        path = self.grid.plan(start, goal)
        discs = []
        for other in self.robots.values():
            if other is robot:
                continue
            spot = other.at.truth[:2]  # where its leg ends
            room = min(STANDING_RADIUS, math.dist(spot, start) - END_ROOM, math.dist(spot, goal) - END_ROOM)
            if room >= ROBOT_RADIUS and _distance_to(np.asarray(path), spot) < room + ROBOT_RADIUS:
                discs.append((spot[0], spot[1], room))
        if not discs:
            return path
        try:
            return self.grid.with_discs(tuple(discs)).plan(start, goal)
        except PlanningError:  # no way round: the plain path
            return path

    def _let_pass(self, robot: StandInRobot, trajectory: SampledMotion, time: float) -> SampledMotion:
        """``trajectory`` put off until it keeps CLEARANCE from the other robots as they drive their
        legs (by MAX_WAIT at most, then as it is)."""
        x, y, yaw = robot.at.truth
        for wait in np.arange(0.0, MAX_WAIT + WAIT_STEP, WAIT_STEP):
            held = int(round(wait / DT))
            times = time + (held + np.arange(len(trajectory))) * DT
            others = [self._where_over(o, times) for o in self.robots.values() if o is not robot]
            if all(np.hypot(trajectory.x - ox, trajectory.y - oy).min() >= CLEARANCE for ox, oy in others):
                return (
                    SampledMotion.concat([SampledMotion.hold(x, y, yaw, held), trajectory])
                    if held
                    else trajectory
                )
        return trajectory

    @staticmethod
    def _where_over(robot: StandInRobot, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Where ``robot`` is at each of ``times``: on its leg, else where it stands."""
        leg = robot.current
        if leg is None:
            return np.full(len(times), robot.at.truth[0]), np.full(len(times), robot.at.truth[1])
        k = np.clip(((times - leg.start) / DT).astype(np.int64), 0, len(leg) - 1)
        return leg.truth.x[k], leg.truth.y[k]

    def _leg(
        self, robot: StandInRobot, goal: str | None, succeeded: bool, time: float, trajectory: SampledMotion
    ) -> StandInLeg:
        x, y, yaw = robot.at.truth
        # the leg's frames from where the robot stands (sample 0, dropped): its odometry goes on
        frames = localise(
            SampledMotion.concat([SampledMotion.hold(x, y, yaw, 1), trajectory]), robot.rng, robot.drift
        )
        n = len(trajectory)
        ox, oy, oyaw = robot.at.odom
        standing = PlanarPoses(np.full(n, ox), np.full(n, oy), np.full(n, oyaw))
        odom = standing.compose(_tail(frames.odom))
        estimate = _tail(frames.estimate)
        idx = np.arange(0, n, SCAN_EVERY)
        others = [self._where_over(o, time + idx * DT) for o in self.robots.values() if o is not robot]
        scans = scan_ranges(
            self.grid,
            self.laser,
            trajectory.x[idx],
            trajectory.y[idx],
            trajectory.yaw[idx],
            others,
            ROBOT_RADIUS,
            robot.rng,
        )
        return StandInLeg(
            robot.name,
            goal,
            succeeded,
            time,
            PlanarPoses(trajectory.x, trajectory.y, trajectory.yaw),
            odom,
            estimate,
            estimate.compose(odom.inverse()),
            frames.v[1:],
            frames.w[1:],
            trajectory.v,
            trajectory.w,
            scans,
        )


def _executor_speeds(
    scenario: Scenario, seed: int, limits: Limits, faults: tuple[Fault, ...], run: int = 0
) -> dict[str, float]:
    """Each robot's speed limit as the executor draws it for run ``run`` of ``exscec simulate
    --seed``: its random numbers in its order (a start's wait per robot, then a speed per robot)."""
    draws = random.Random(seed * 1000 + run)
    for _ in scenario.robots:
        draws.uniform(0.5, 1.0)
    return {
        r.id: limits.max_speed * draws.uniform(0.9, 1.0) * speed_factor(scenario, r.id, faults)
        for r in scenario.robots
    }


def _distance_to(path: np.ndarray, point: Point) -> float:
    """The distance from ``point`` to the polyline ``path``."""
    if len(path) < 2:
        return math.dist(point, (float(path[0][0]), float(path[0][1])))
    a, b = path[:-1], path[1:]
    ab = b - a
    lengths = np.maximum((ab**2).sum(axis=1), 1e-12)
    f = np.clip(((np.asarray(point) - a) * ab).sum(axis=1) / lengths, 0.0, 1.0)
    nearest = a + f[:, None] * ab
    return float(np.hypot(*(nearest - np.asarray(point)).T).min())


def _tail(poses: PlanarPoses) -> PlanarPoses:
    return PlanarPoses(poses.x[1:], poses.y[1:], poses.yaw[1:])


__all__ = ["FIELDS", "Fleet", "StandInLeg", "Standing"]
