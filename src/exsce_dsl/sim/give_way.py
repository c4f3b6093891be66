"""Right of way between robots, replayed on their trajectories: paths stay, clocks warp.

Each robot's trajectory is planned alone; :func:`give_way` then replays all of them together,
each robot advancing along its own at a rate that changes gradually, so that robots wait for,
back away from and never drive on into each other where they can.  Where they still meet, the
executor plans a leg again (:mod:`exsce_dsl.sim.conflicts`).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from exsce_dsl.model import Scenario
from exsce_dsl.sim.actions import GoalEvent, SimulatedAction
from exsce_dsl.sim.conflicts import CLEARANCE
from exsce_dsl.sim.motion import DT, SampledMotion

SAFE_DISTANCE = 1.5  # metres between robot centres that robots keep when they can
MAX_WAIT = 10.0  # seconds a robot waits before it goes on (a real planner would detour)
STANDING_WAIT = 30.0  # seconds a robot waits for one that stands in its way to leave
GOAL_TAKEN = 0.5  # metres from a robot's goal within which a robot standing there takes it
GOAL_WAIT = 1.1  # metres from a robot on its goal at which a robot waits for it to leave
RAMP = 1.2  # seconds to go from full progress to standing still (keeps accelerations bounded)
STEP = DT / RAMP  # the most a robot's rate changes in one sample


def give_way(
    scenario: Scenario,
    trajectories: dict[str, SampledMotion],
    events: list[GoalEvent],
    actions: list[SimulatedAction],
) -> tuple[dict[str, SampledMotion], list[GoalEvent], list[SimulatedAction]]:
    """Right of way by fleet order, replayed on the trajectories (paths unchanged, clocks warped).

    Each robot advances along its own trajectory at a rate between -1 (backing up
    the way it came) and 1 (as planned); the rate changes gradually.  A robot about
    to come closer than SAFE_DISTANCE to a robot listed before it slows to a stop;
    a robot that a robot with right of way drives towards backs up.
    """
    order = [r.id for r in scenario.robots if r.id in trajectories]
    if len(order) < 2:
        return trajectories, events, actions
    shown = _Replay(trajectories, order, actions).run()
    new_index = {}
    for r in order:
        trajectories[r], new_index[r] = _warped(trajectories[r], np.asarray(shown[r]))

    def moved(robot: str, t: float) -> float:
        k = min(int(round(t / DT)), len(new_index[robot]) - 1)
        return float(new_index[robot][k]) * DT

    events = [
        GoalEvent(moved(e.robot, e.t), e.robot, e.goal_key, e.waypoint_ids, e.statuses, e.final)
        for e in events
    ]
    actions = [replace(a, start=moved(a.robot, a.start), end=moved(a.robot, a.end)) for a in actions]
    return trajectories, events, actions


class _Replay:
    """All robots replayed together, one sample at a time: where each stands along its own
    trajectory (a fractional sample index), at what rate it advances, and how long it has waited."""

    def __init__(
        self, trajectories: dict[str, SampledMotion], order: list[str], actions: list[SimulatedAction]
    ) -> None:
        self.trajectories, self.order = trajectories, order
        # plain floats: at() runs a million times a replay, and numpy scalars cost thrice as much
        self.xs = {r: trajectories[r].x.tolist() for r in order}
        self.ys = {r: trajectories[r].y.tolist() for r in order}
        self.position = {r: 0.0 for r in order}  # fractional sample index along the robot's own trajectory
        self.rate = {r: 1.0 for r in order}
        self.waited = {r: 0 for r in order}
        self.still = {r: True for r in order}
        self.last = {r: len(trajectories[r]) - 1 for r in order}
        self.shown: dict[str, list[float]] = {r: [] for r in order}
        self.previous: dict[str, tuple[float, float]] = {}
        self.moving = {r: _last_move(trajectories[r]) for r in order}
        """After this sample a robot stands still for good: others pass it on paths planned round it."""
        self.leg_ends = {
            r: sorted((int(round(a.end / DT)), a.goal) for a in actions if a.robot == r) for r in order
        }

    def run(self) -> dict[str, list[float]]:
        """Each robot's position along its own trajectory, sample by sample of the replay."""
        for _ in range(10 * sum(self.last.values()) + 10):  # bounded: robots finish or stop waiting
            if all(self.position[r] >= self.last[r] for r in self.order):
                break
            placed: dict[str, tuple[float, float]] = {}
            braking: dict[str, tuple[float, float]] = {}
            for r in self.order:
                self.advance(r, placed, braking)
            self.previous = placed
        return self.shown

    def advance(
        self, r: str, placed: dict[str, tuple[float, float]], braking: dict[str, tuple[float, float]]
    ) -> None:
        """One sample of robot ``r``: its rate eased towards the target that right of way sets,
        its new place added to ``placed`` and where braking from there would end to ``braking``."""
        target = self.target(r, placed, braking)
        rate = self.rate[r]
        self.rate[r] = rate = min(rate + STEP, target) if target > rate else max(rate - STEP, target)
        before = self.position[r]
        self.position[r] = min(max(self.position[r] + rate, 0.0), float(self.last[r]))
        self.still[r] = math.dist(self.at(r, before), self.at(r, self.position[r])) < 1e-9
        self.shown[r].append(self.position[r])
        placed[r] = self.at(r, self.position[r])
        braking[r] = self.at(r, min(self.position[r] + 1.0 + 2 * max(rate, 0.0) * RAMP / DT, self.last[r]))

    def target(
        self, r: str, placed: dict[str, tuple[float, float]], braking: dict[str, tuple[float, float]]
    ) -> float:
        """The rate ``r`` should reach: 1 when nothing is in its way (or it has waited long
        enough), 0 to wait, -1 to back away from a robot with right of way coming at it."""
        position = self.position[r]
        here = self.at(r, position)
        look = self.at(
            r, min(position + 1.0 + self.rate[r] * RAMP / DT / 2, self.last[r])
        )  # where braking would end
        if self._nobody_near(r, here, look, placed):
            self.waited[r] = 0
            return 1.0
        # robots before r that drive, and every robot that stands (waiting, parked or not started)
        active = {h: p for h, p in placed.items() if self.position[h] < self.moving[h] and not self.still[h]}
        threats = [  # robots with right of way coming at r: where they would stop is too close
            p
            for h, p in active.items()
            if math.dist(p, here) < SAFE_DISTANCE
            and math.dist(p, here) < math.dist(self.previous.get(h, p), here)
            and distance_to_polyline(np.array([p, braking[h]]), here) < CLEARANCE + 0.1
        ]
        # driving on away from them is giving way too (a robot followed does not stop)
        threatened = any(math.dist(look, p) <= math.dist(here, p) + 0.01 for p in threats)
        # robots r must not drive into: standing ones, and any without right of way over r
        # (they should yield, but may be unable to: at their start, or with nowhere to go)
        standing = [
            p for h, p in (self.previous | placed).items() if h != r and (self.still[h] or h not in active)
        ]
        blocked = any(
            math.dist(look, p) < SAFE_DISTANCE and math.dist(look, p) < math.dist(here, p)
            for p in active.values()
        )
        bumping = any(  # into a robot that stands, whatever its right of way: it may leave
            min(math.dist(look, p) + 0.08, math.dist(here, p)) < self.keep_from(r, p)
            and math.dist(look, p) < math.dist(here, p)
            for p in standing
        )
        if not (threatened or blocked or bumping):
            self.waited[r] = 0
            return 1.0
        if self.waited[r] >= (STANDING_WAIT if bumping else MAX_WAIT) / DT:
            return 1.0  # waited long enough: go on until the conflict is over
        self.waited[r] += 1  # give way
        behind = self.at(r, max(position - 1.0, 0.0))  # backing up must take r away from them
        away = all(
            math.dist(behind, braking[h]) > math.dist(here, braking[h]) for h in active if h in braking
        )
        return -1.0 if threatened and position > 0 and away else 0.0

    def _nobody_near(
        self,
        r: str,
        here: tuple[float, float],
        look: tuple[float, float],
        placed: dict[str, tuple[float, float]],
    ) -> bool:
        """No other robot, where it was or is now, within SAFE_DISTANCE of ``here`` or ``look``: then
        none threatens, blocks or is bumped into, as each of those needs one nearer (a robot keeps
        at most GOAL_WAIT or CLEARANCE + 0.1 from one standing, both below SAFE_DISTANCE)."""
        for where in (placed, self.previous):
            for h, p in where.items():
                if h != r and (math.dist(here, p) < SAFE_DISTANCE or math.dist(look, p) < SAFE_DISTANCE):
                    return False
        return True

    def keep_from(self, r: str, p: tuple[float, float]) -> float:
        """How near r comes to a robot standing at p: farther when p is r's goal, so that the
        robot there has room to leave round r."""
        goal = next((g for end, g in self.leg_ends[r] if end >= self.position[r]), None)
        if goal is not None and math.dist(p, (goal.position.x, goal.position.y)) < GOAL_TAKEN:
            return GOAL_WAIT
        return CLEARANCE + 0.1

    def at(self, r: str, p: float) -> tuple[float, float]:
        """Where ``r`` is at fractional sample ``p`` of its own trajectory."""
        xs, ys, last = self.xs[r], self.ys[r], self.last[r]
        k = min(int(p), last)
        k1, f = min(k + 1, last), p - k
        return (xs[k] + f * (xs[k1] - xs[k]), ys[k] + f * (ys[k1] - ys[k]))


def _warped(tr: SampledMotion, p: np.ndarray) -> tuple[SampledMotion, np.ndarray]:
    """``tr`` resampled at the fractional positions ``p`` the replay showed, and for each of its
    original samples the first new sample that reached it."""
    last = len(tr) - 1
    k = np.minimum(p.astype(np.int64), last)
    k1 = np.minimum(k + 1, last)
    f = p - k
    speed_scale = np.diff(p, prepend=0.0)  # progress per sample: -1..1
    warped = SampledMotion(
        tr.x[k] + f * (tr.x[k1] - tr.x[k]),
        tr.y[k] + f * (tr.y[k1] - tr.y[k]),
        tr.yaw[k] + f * (tr.yaw[k1] - tr.yaw[k]),
        speed_scale * tr.v[k1],
        speed_scale * tr.w[k1],
    )
    first = np.searchsorted(np.maximum.accumulate(p), np.arange(last + 2), side="left")
    return warped, np.minimum(first, len(p))


def _last_move(trajectory: SampledMotion) -> int:
    """The last sample at which the robot is still moving (0 if it never moves)."""
    moved = np.flatnonzero((np.abs(np.diff(trajectory.x)) > 1e-9) | (np.abs(np.diff(trajectory.y)) > 1e-9))
    return int(moved[-1]) + 1 if len(moved) else 0


def distance_to_polyline(points: np.ndarray, p: tuple[float, float]) -> float:
    a, b = points[:-1], points[1:]
    ab = b - a
    length2 = np.maximum((ab**2).sum(axis=1), 1e-12)
    t = np.clip(((np.array(p) - a) * ab).sum(axis=1) / length2, 0.0, 1.0)
    closest = a + t[:, None] * ab
    return float(np.min(np.hypot(closest[:, 0] - p[0], closest[:, 1] - p[1]))) if len(a) else math.inf
