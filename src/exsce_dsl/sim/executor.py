"""Play a scenario: who drives where and when, as the waypoint dispatcher would.

Each robot's allocated tasks are run subtask by subtask (one dispatcher goal
per subtask, one status per waypoint).  In a ``parallel`` mission the robots
start together and each runs its own tasks in order; in a ``sequential``
mission an allocation entry starts when the previous one has finished.
The result keeps the ground truth (the path each robot drove), which tests
compare metrics against.
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass, field, replace

import numpy as np

from exsce_dsl.errors import ExsceError, PlanningError
from exsce_dsl.maps.planning import PlanningGrid, Point
from exsce_dsl.model import MissionType, Pose, Scenario
from exsce_dsl.model.goals import GoalStatus
from exsce_dsl.sim.actions import GoalEvent, SimulatedAction
from exsce_dsl.sim.conflicts import MAX_REPAIRS, LegId, Repair, conflict_repairs, meetings
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
from exsce_dsl.sim.give_way import distance_to_polyline, give_way
from exsce_dsl.sim.laser import RecordedScans
from exsce_dsl.sim.motion import DT, Limits, SampledMotion, drive
from exsce_dsl.sim.passing import Wait, head_on_wait


@dataclass
class RobotMotion:
    """A robot's motion and dispatcher events over the whole run."""

    robot: str
    parts: list[SampledMotion] = field(default_factory=list)
    samples: int = 0
    yaw: float = 0.0
    x: float = 0.0
    y: float = 0.0

    def append(self, part: SampledMotion) -> None:
        if len(part):
            self.parts.append(part)
            self.samples += len(part)
            self.x, self.y, self.yaw = float(part.x[-1]), float(part.y[-1]), float(part.yaw[-1])

    def wait_until(self, sample: int) -> None:
        if sample > self.samples:
            self.append(SampledMotion.hold(self.x, self.y, self.yaw, sample - self.samples))

    @property
    def now(self) -> float:
        return self.samples * DT


@dataclass(frozen=True)
class SimulatedExecution:
    """What the executor did: trajectories on one clock, events and ground truth."""

    trajectories: dict[str, SampledMotion]
    events: list[GoalEvent]
    actions: list[SimulatedAction]
    duration: float
    scans: dict[str, RecordedScans] | None = None
    """What the executor's own sensors measured, per robot; None: it has none (the bag writer
    ray-marches scans on the map)."""
    dt: float = DT
    """Seconds between two samples of the trajectories (the kinematic executor's DT; a
    simulator's own step)."""


def execute(
    scenario: Scenario,
    grid: PlanningGrid,
    seed: int,
    faults: tuple[Fault, ...] = (),
    limits: Limits | None = None,
) -> SimulatedExecution:
    """Play ``scenario``; where two robots would still touch after giving way, the whole run is
    played again (as a fleet manager repairs a plan), at most MAX_REPAIRS times: when they had
    stopped facing each other, the one with less right of way drives by way of a place beside the
    other's path, and if that is not enough waits there until the other has gone by
    (sim.passing); else the leg of the one driving into the other is planned again round the
    place where the other was (sim.conflicts).  ``near-collision`` is the fault of not doing so."""
    check_faults(scenario, faults)
    limits = limits or Limits()
    avoid: dict[LegId, tuple[Point, ...]] = {}
    waits: dict[LegId, Wait] = {}
    plans: Plans = {}  # the same leg, planned round the same robots, in every replay
    execution = _play(scenario, grid, seed, faults, limits, avoid, plans, waits)
    if any(f.kind == "near-collision" for f in faults):
        return execution
    order = [r.id for r in scenario.robots]
    for _ in range(MAX_REPAIRS):
        met = meetings(execution.trajectories, order)
        if not met:
            break
        wait = head_on_wait(execution.trajectories, execution.actions, order, grid, met[0])
        if wait is not None and wait.leg not in waits:
            waits[wait.leg] = replace(wait, until=None)  # by way of the place first: may be enough
        elif wait is not None and waits[wait.leg].until is None:
            waits[wait.leg] = wait
        else:
            repairs = conflict_repairs(execution.trajectories, execution.actions, order)
            new = [r for r in repairs if _can_go_round(r, execution.actions, avoid)]
            if not new:
                break
            avoid[new[0].leg] = avoid.get(new[0].leg, ()) + (new[0].place,)
        execution = _play(scenario, grid, seed, faults, limits, avoid, plans, waits)
    return execution


def _can_go_round(
    repair: Repair, actions: list[SimulatedAction], avoid: dict[LegId, tuple[Point, ...]]
) -> bool:
    """The repair would change its leg: the place is not tried yet (nor one near it) and not
    so near the leg's ends that its path cannot go round it."""
    if any(math.dist(repair.place, p) < TRIED for p in avoid.get(repair.leg, ())):
        return False
    robot, number = repair.leg
    leg = [a for a in actions if a.robot == robot][number - 1]
    ends = (leg.path[0], leg.path[-1]) if leg.path else ()
    return all(math.dist(repair.place, end) - END_ROOM >= MIN_RADIUS for end in ends)


def _play(
    scenario: Scenario,
    grid: PlanningGrid,
    seed: int,
    faults: tuple[Fault, ...],
    limits: Limits,
    avoid: dict[LegId, tuple[Point, ...]],
    plans: Plans,
    waits: dict[LegId, Wait],
) -> SimulatedExecution:
    """One playing of ``scenario``: each allocation entry's subtasks dispatched in turn, then the
    robots giving way to each other and all trajectories held to one end."""
    play = _Play(scenario, grid, random.Random(seed), faults, limits, avoid, plans, waits)
    for number, entry in enumerate(scenario.mission.allocation):
        play.run_entry(number, entry.robot, entry.task)
    return play.finish()


class _Play:
    """The state of one playing: every robot's timeline, the dispatcher's events and the actions
    so far, and what the faults and the repairs of earlier replays ask of each leg."""

    def __init__(
        self,
        scenario: Scenario,
        grid: PlanningGrid,
        rng: random.Random,
        faults: tuple[Fault, ...],
        limits: Limits,
        avoid: dict[LegId, tuple[Point, ...]],
        plans: Plans,
        waits: dict[LegId, Wait],
    ) -> None:
        self.scenario, self.grid, self.rng, self.faults, self.limits = scenario, grid, rng, faults, limits
        self.avoid, self.plans, self.waits = avoid, plans, waits
        self.timelines = _starting_timelines(scenario, rng)
        self.speed = {
            r: limits.max_speed * rng.uniform(0.9, 1.0) * speed_factor(scenario, r, faults)
            for r in self.timelines
        }
        self.skip = {(f.robot, f.index) for f in faults if f.kind == "skip-waypoint"}
        self.events: list[GoalEvent] = []
        self.actions: list[SimulatedAction] = []
        self.last_pose = {r.id: r.start_pose for r in scenario.robots if r.start_pose is not None}
        self.task_numbers: dict[str, int] = {}
        self.waypoint_counts: dict[str, int] = {}
        self.near_collision = any(f.kind == "near-collision" for f in faults)
        self.approach: dict[str, list[SampledMotion]] = {}
        if self.near_collision:
            self.approach = _near_collision(scenario, self.timelines, grid, limits)
        self.slow_boxes = area_boxes(scenario, faults)
        self.stuck = deadlocked(scenario, faults)
        self.last_entry = {entry.robot: n for n, entry in enumerate(scenario.mission.allocation)}
        self.parked: dict[str, tuple[float, float]] = {}
        """Where robots that have done all their tasks stand: later paths go round them."""

    def run_entry(self, number: int, robot: str, task_id: str) -> None:
        """Allocation entry ``number``: the robot runs the task's subtasks in order (in a
        sequential mission, once every robot before it has finished)."""
        tl = self.timelines[robot]
        if self.scenario.mission.type is MissionType.SEQUENTIAL:
            tl.wait_until(max(t.samples for t in self.timelines.values()))
        task = self.scenario.task(task_id)
        assert task is not None
        self.task_numbers[robot] = self.task_numbers.get(robot, 0) + 1
        for s_number, subtask in enumerate(task.subtasks, start=1):
            self.run_subtask(robot, task.id, s_number, subtask.waypoints)
        if self.last_entry[robot] == number:
            self.parked[robot] = (tl.x, tl.y)

    def run_subtask(self, robot: str, task_id: str, s_number: int, waypoints: tuple[Pose, ...]) -> None:
        """One dispatcher goal: accepted, then each waypoint active, advanced to and recorded."""
        tl = self.timelines[robot]
        ids = tuple(w.id for w in waypoints)
        key = f"{robot}-task_{self.task_numbers[robot]:02d}-subtask_{s_number:03d}"
        statuses = [GoalStatus.PENDING] * len(ids)
        tl.append(SampledMotion.hold(tl.x, tl.y, tl.yaw, 5))
        self.events.append(GoalEvent(tl.now, robot, key, ids, tuple(statuses), False))  # goal accepted
        tl.append(SampledMotion.hold(tl.x, tl.y, tl.yaw, 5))  # the dispatcher activates its first waypoint
        for w_number, goal in enumerate(waypoints, start=1):
            statuses[w_number - 1] = GoalStatus.ACTIVE
            start_t = tl.now
            self.events.append(GoalEvent(start_t, robot, key, ids, tuple(statuses), False))
            previous = self.last_pose[robot]
            path, status = self.advance(robot, goal)
            statuses[w_number - 1] = status
            length = _length(path) if status is GoalStatus.SUCCEEDED else 0.0
            number = self.task_numbers[robot]
            self.actions.append(
                SimulatedAction(
                    robot,
                    number,
                    task_id,
                    s_number,
                    w_number,
                    previous,
                    goal,
                    start_t,
                    tl.now,
                    status,
                    length,
                    tuple(path),
                )
            )
            last = w_number == len(ids)
            self.events.append(GoalEvent(tl.now, robot, key, ids, tuple(statuses), last))
            tl.append(SampledMotion.hold(tl.x, tl.y, tl.yaw, int(self.rng.uniform(0.2, 0.6) * 50)))

    def advance(self, robot: str, goal: Pose) -> tuple[list[Point], GoalStatus]:
        """The robot's next leg, to ``goal``: driven (by way of a detour or a head-on wait when
        asked), or given up at once when the skip-waypoint fault names it.  Its planned path and
        the waypoint's status."""
        tl = self.timelines[robot]
        self.waypoint_counts[robot] = count = self.waypoint_counts.get(robot, 0) + 1
        leg = (robot, count)
        if self.stuck and count == 1:  # deadlock-start: every robot waits
            tl.append(SampledMotion.hold(tl.x, tl.y, tl.yaw, int(round(DEADLOCK_WAIT / DT))))
        keep_clear = _standing(self.parked, self.avoid.get(leg, ()))
        if leg in self.skip:
            target = (goal.position.x, goal.position.y)
            path = _plan_around(self.grid, (tl.x, tl.y), target, keep_clear, self.plans)
            tl.append(SampledMotion.hold(tl.x, tl.y, tl.yaw, 25))
            return path, GoalStatus.ABORTED
        for part in self.approach.pop(robot, []):  # the near-collision fault, inside the mission
            tl.append(part)
        via = detour_via(self.scenario, robot, self.last_pose[robot], goal, self.faults)
        wait = self.waits.get(leg) if via is None else None
        if wait is not None:
            via = wait.place
        hold = wait.until if wait is not None else None
        until = int(round(hold / DT)) if hold is not None else None
        limits = Limits(self.speed[robot], self.limits.max_accel, self.limits.max_turn_rate)
        path, driven = _drive_to(self.grid, tl, goal, via, keep_clear, limits, self.plans, until)
        tl.append(slow_in_areas(driven, self.slow_boxes) if self.slow_boxes else driven)
        self.last_pose[robot] = goal
        return path, GoalStatus.SUCCEEDED

    def finish(self) -> SimulatedExecution:
        """The robots give way to each other (unless the near-collision fault forbids it) and
        every trajectory is held to one end, a second after the last robot stops."""
        trajectories = {r: SampledMotion.concat(t.parts) for r, t in self.timelines.items()}
        events, actions = self.events, self.actions
        if not self.near_collision:
            trajectories, events, actions = give_way(self.scenario, trajectories, events, actions)
        end = max(len(t) for t in trajectories.values()) + 50
        trajectories = {
            r: SampledMotion.concat(
                [t, SampledMotion.hold(float(t.x[-1]), float(t.y[-1]), float(t.yaw[-1]), end - len(t))]
            )
            for r, t in trajectories.items()
        }
        events.sort(key=lambda e: (e.t, e.robot))
        return SimulatedExecution(trajectories, events, actions, end * DT)


def _starting_timelines(scenario: Scenario, rng: random.Random) -> dict[str, RobotMotion]:
    """Each robot with a start pose, standing there for half a second to a second."""
    timelines: dict[str, RobotMotion] = {}
    for robot in scenario.robots:
        if robot.start_pose is None:
            continue
        tl = RobotMotion(robot.id)
        tl.x, tl.y, tl.yaw = (
            robot.start_pose.position.x,
            robot.start_pose.position.y,
            robot.start_pose.orientation.yaw,
        )
        tl.append(SampledMotion.hold(tl.x, tl.y, tl.yaw, int(rng.uniform(0.5, 1.0) * 50)))
        timelines[robot.id] = tl
    return timelines


def _drive_to(
    grid: PlanningGrid,
    tl: RobotMotion,
    goal: Pose,
    via: tuple[float, float] | None,
    parked: tuple[Point, ...],
    limits: Limits,
    plans: Plans,
    until: int | None = None,
) -> tuple[list[tuple[float, float]], SampledMotion]:
    """The path from where ``tl`` stands to ``goal`` (by way of ``via``, stopping there to turn:
    the detour fault; and waiting there until sample ``until``: a head-on wait) and the drive
    along it."""
    target = (goal.position.x, goal.position.y)
    if via is None:
        path = _plan_around(grid, (tl.x, tl.y), target, parked, plans)
        return path, drive(path, tl.yaw, goal.orientation.yaw, limits)
    there = _plan_around(grid, (tl.x, tl.y), via, parked, plans)
    on = _plan_around(grid, via, target, parked, plans)
    heading = math.atan2(on[1][1] - on[0][1], on[1][0] - on[0][0])
    first = drive(there, tl.yaw, heading, limits)
    second = drive(on, heading, goal.orientation.yaw, limits)
    parts = [first, second]
    if until is not None and until > tl.samples + len(first):
        end = first if len(first) else SampledMotion.hold(tl.x, tl.y, heading, 1)
        x, y, yaw = float(end.x[-1]), float(end.y[-1]), float(end.yaw[-1])
        parts.insert(1, SampledMotion.hold(x, y, yaw, until - tl.samples - len(first)))
    return there + on[1:], SampledMotion.concat(parts)


def _near_collision(
    scenario: Scenario, timelines: dict[str, RobotMotion], grid: PlanningGrid, limits: Limits
) -> dict[str, list[SampledMotion]]:
    """The second robot's first action starts with a drive to the first robot, which waits at its
    start until the second has come close and gone back: the legs, to insert in that action."""
    robots = [r for r in scenario.robots if r.id in timelines]
    if len(robots) < 2:
        raise ExsceError("fault 'near-collision' needs a scenario with two robots")
    first, second = timelines[robots[0].id], timelines[robots[1].id]
    path = grid.plan((second.x, second.y), (first.x, first.y))
    path[-1] = (first.x + 0.05, first.y)
    there = drive(path, second.yaw, second.yaw, limits)
    back = drive(list(reversed(path)), second.yaw, second.yaw, limits)
    first.wait_until(second.samples + 10 + len(there) + len(back) + 100)  # 10: the goal's acceptance
    return {robots[1].id: [there, back]}


def _plan_around(
    grid: PlanningGrid,
    start: tuple[float, float],
    goal: tuple[float, float],
    parked: tuple[Point, ...],
    plans: Plans,
) -> list[tuple[float, float]]:
    """A path that keeps clear of robots standing still (a real planner sees them in its costmap)."""
    key = (start, goal, tuple(sorted(parked)))
    if key not in plans:
        plans[key] = _plan_round(grid, start, goal, parked)
    return list(plans[key])


def _plan_round(
    grid: PlanningGrid, start: Point, goal: Point, parked: tuple[Point, ...]
) -> list[tuple[float, float]]:
    path = grid.plan(start, goal)
    points = np.array(path)
    room = {
        p: min(PARKED_RADIUS, math.dist(goal, p) - END_ROOM, math.dist(start, p) - END_ROOM) for p in parked
    }
    blockers = tuple(
        (x, y, room[x, y])
        for x, y in parked
        if distance_to_polyline(points, (x, y)) < room[x, y] + 0.3 and room[x, y] >= MIN_RADIUS
    )
    if not blockers:
        return path
    try:
        around = grid.with_discs(blockers).plan(start, goal)
    except PlanningError:  # no way round them: the plain path (the robot waits for them to move)
        return path
    # a fleet manager does not send a robot round the building to pass one that will move on
    return around if _length(around) <= ROUND_AT_MOST * _length(path) + ROUND_EXTRA else path


def _length(path: list[Point]) -> float:
    return sum(math.dist(path[i], path[i + 1]) for i in range(len(path) - 1))


Plans = dict[tuple[Point, Point, tuple[Point, ...]], list[Point]]
"""Paths planned in one execution, by start, goal and the places kept clear of."""
PARKED_RADIUS = 0.6  # metres: a robot standing still, with room to pass it
MIN_RADIUS = 0.4  # metres: smaller where it stands near a leg's start or goal, down to this
END_ROOM = 0.3  # metres a leg's start and goal keep from such a disc
ROUND_AT_MOST, ROUND_EXTRA = 1.5, 3.0  # a way round a robot may be this much longer (factor, metres)
TRIED = 0.3  # metres within which a repair's place counts as one tried for the leg already


def _standing(parked: dict[str, Point], avoid: tuple[Point, ...]) -> tuple[Point, ...]:
    """What a leg keeps clear of: robots parked for good, and the places a repair moved it from."""
    return tuple(parked.values()) + avoid


__all__ = ["SimulatedAction", "SimulatedExecution", "Fault", "GoalEvent", "GoalStatus", "execute", "np"]
