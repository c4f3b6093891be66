"""Deliberate faults the executor can plant, off unless named (``--fault NAME[:ARGS]``).

Two families.  The *plain* faults (``overspeed``, ``slow``, ``skip-waypoint``,
``near-collision``) show in every run of the scenario they are planted in: they test
that oracles catch what they should.  The *latent* faults behave like a real robot's
software bugs: each is triggered by a feature of the scenario the executor plays (it
sees that scenario only, never how it was derived), so a scenario without the feature
runs exactly as if the fault were not there (same seed, same trajectories), and only a
derived scenario that has the feature reveals it.  Planted against the shipped
``scenario_c`` (tiago1 and tiago2 start in classroom_c025, drive classroom_c022 →
classroom_c018, and go home):

- ``slow-area:AREA``: a robot whose leg (the drive to one waypoint) enters AREA's box (its
  poses' box, 1.5 m wider on each side) drives at 40 % from there to the waypoint, as a robot
  whose localisation is lost there and found again at the waypoint.  scenario_c never comes
  near classroom_c069; ``replace_robot --robot tiago2 --by tiago3 --start classroom_c069-w001``
  starts a robot there with tiago2's tasks: ``slow-area:classroom_c069`` reveals it.
- ``detour:FROM:TO``: a leg from a pose of area FROM to a pose of area TO (that way only)
  goes by way of the robot's start pose, as a planner reusing a stale route from home would
  (no detour when the start pose is within 1.5 m of either end).  scenario_c drives
  classroom_c022 → classroom_c018 only; ``reverse_waypoint_order --task delivery_a`` drives
  tiago1 the other way: ``detour:classroom_c018:classroom_c022`` reveals it.
- ``deadlock-start:ROBOT:POSE``: when ROBOT starts at POSE (a pose id), the fleet manager
  deadlocks: every robot stands 120 s with its first goal active, then a watchdog frees them.
  ``swap_start_poses --robot tiago1 --with tiago2`` starts tiago1 at classroom_c025-w002:
  ``deadlock-start:tiago1:classroom_c025-w002`` reveals it.
- ``overspeed-many-tasks:N``: a robot allocated more than N tasks ignores its speed limit
  (well over 1 m/s, as ``overspeed``).  scenario_c gives each robot 2 tasks; ``remove_robot
  --robot tiago2 --reassign tiago1`` gives tiago1 4: ``overspeed-many-tasks:2`` reveals it.
  30 % of random two-step derivations give some robot a third task: random draws find it as
  fast as covering ones (bench/explore.py measures it only when asked).
- ``overspeed-reassigned:TASK:ROBOT``: a robot other than ROBOT that is allocated TASK ignores
  its speed limit (well over 1 m/s), as a fleet manager would whose speed profiles are
  configured per task for the robot planned to do it, and lost when the task is reassigned.
  scenario_c gives delivery_a to tiago1; ``swap_assignment --robot tiago1 --with tiago2``
  gives it to tiago2: ``overspeed-reassigned:delivery_a:tiago1`` reveals it.

Latent faults never refuse a scenario for lacking their trigger (a derivation may have
removed ROBOT, and a TASK: the executor sees the tasks the scenario allocates, not those a
spec declares); they do refuse an AREA or POSE the environment does not have.
"""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass

import numpy as np

from exsce_dsl.errors import ExsceError
from exsce_dsl.model import Pose, Scenario
from exsce_dsl.sim.motion import DT, SampledMotion
from exsce_dsl.suggest import did_you_mean

OVERSPEED = 1.0 / 0.6 * 1.4 / 0.95
"""Speed factor of an overspeeding robot: well over 1 m/s whatever the seeded speed."""
SLOW = 0.5
SLOW_AREA = 0.4
"""Speed factor of a robot in ``slow-area``'s area, until it reaches its waypoint."""
AREA_MARGIN = 1.5
"""Metres round an area's poses that count as the area (its box, grown on each side)."""
DEADLOCK_WAIT = 120.0
"""Seconds the robots stand still in a ``deadlock-start`` before the watchdog frees them."""
RAMP = 1.2
"""Seconds to slow down from full speed to the area's speed (keeps accelerations bounded)."""


@dataclass(frozen=True)
class FaultKind:
    """One entry of the fault table: its name, its arguments (Fault fields, in order) and
    what it does."""

    name: str
    fields: tuple[str, ...]
    required: int
    usage: str
    summary: str
    latent: bool = False
    """Triggered by a feature of the scenario; never refuses a scenario without it."""


FAULT_KINDS: dict[str, FaultKind] = {
    k.name: k
    for k in (
        FaultKind("overspeed", ("robot",), 1, "overspeed:ROBOT", "ROBOT drives well over 1 m/s"),
        FaultKind("slow", ("robot",), 1, "slow:ROBOT", "ROBOT drives at half its speed"),
        FaultKind(
            "skip-waypoint", ("robot", "index"), 1, "skip-waypoint:ROBOT[:N]", "ROBOT's N-th waypoint aborts"
        ),
        FaultKind("near-collision", (), 0, "near-collision", "the second robot drives up to the first"),
        FaultKind(
            "slow-area",
            ("area",),
            1,
            "slow-area:AREA",
            "a robot entering AREA drives at 40 % until its next waypoint",
            latent=True,
        ),
        FaultKind(
            "detour",
            ("area", "to_area"),
            2,
            "detour:FROM:TO",
            "legs from area FROM to area TO (not back) go via the robot's start pose",
            latent=True,
        ),
        FaultKind(
            "deadlock-start",
            ("robot", "pose"),
            2,
            "deadlock-start:ROBOT:POSE",
            "when ROBOT starts at POSE every robot stands still 120 s",
            latent=True,
        ),
        FaultKind(
            "overspeed-many-tasks",
            ("index",),
            1,
            "overspeed-many-tasks:N",
            "a robot with more than N tasks drives well over 1 m/s",
            latent=True,
        ),
        FaultKind(
            "overspeed-reassigned",
            ("task", "robot"),
            2,
            "overspeed-reassigned:TASK:ROBOT",
            "a robot other than ROBOT allocated TASK drives well over 1 m/s",
            latent=True,
        ),
    )
}

_NOUNS = {
    "robot": "a robot",
    "index": "a number",
    "area": "an area",
    "to_area": "a second area",
    "pose": "a pose",
    "task": "a task",
}


@dataclass(frozen=True)
class Fault:
    """A deliberate fault, parsed from ``NAME[:ARGS]``; :data:`FAULT_KINDS` lists them.

    Plain faults show in every run: ``overspeed:ROBOT`` (well over 1 m/s), ``slow:ROBOT``
    (half speed), ``skip-waypoint:ROBOT[:N]`` (its N-th waypoint aborts), ``near-collision``
    (the second robot drives up to the first).  Latent faults show only when the played
    scenario has their trigger (see the module's table): ``slow-area:AREA``,
    ``detour:FROM:TO``, ``deadlock-start:ROBOT:POSE``, ``overspeed-many-tasks:N``,
    ``overspeed-reassigned:TASK:ROBOT``.
    """

    kind: str
    robot: str | None = None
    index: int = 1
    """skip-waypoint: the waypoint's number; overspeed-many-tasks: N."""
    area: str | None = None
    """slow-area: the area; detour: the area the leg starts in."""
    to_area: str | None = None
    """detour: the area the leg ends in."""
    pose: str | None = None
    """deadlock-start: the start pose that triggers it."""
    task: str | None = None
    """overspeed-reassigned: the task whose speed limit is lost with another robot."""

    KINDS = tuple(FAULT_KINDS)

    @classmethod
    def parse(cls, text: str) -> Fault:
        kind, *given = text.split(":")
        entry = FAULT_KINDS.get(kind)
        if entry is None:
            raise ExsceError(f"unknown fault '{kind}'; known faults: {', '.join(FAULT_KINDS)}")
        given = given if any(given) else []
        if len(given) < entry.required or any(not g for g in given[: entry.required]):
            needs = " and ".join(_NOUNS[f] for f in entry.fields[: entry.required])
            raise ExsceError(f"fault '{kind}' needs {needs}: {entry.usage}")
        if len(given) > len(entry.fields):
            raise ExsceError(f"fault '{text}' has too many arguments: {entry.usage}")
        values: dict[str, str | int] = {}
        for name, value in zip(entry.fields, given, strict=False):
            if name == "index":
                try:
                    values[name] = int(value) if value else 1
                except ValueError:
                    what = "a waypoint number" if kind == "skip-waypoint" else "a number of tasks"
                    raise ExsceError(f"fault '{text}': '{value}' is not {what}") from None
            elif value:
                values[name] = value
        return cls(kind, **values)  # type: ignore[arg-type]

    @property
    def latent(self) -> bool:
        return FAULT_KINDS[self.kind].latent

    @property
    def identity(self) -> str:
        """What tells runs with this fault from others (plain faults: kind and robot)."""
        if not self.latent:
            return self.kind + str(self.robot)
        values = (getattr(self, f) for f in FAULT_KINDS[self.kind].fields)
        return ":".join([self.kind, *(str(v) for v in values)])


def check_faults(scenario: Scenario, faults: tuple[Fault, ...]) -> None:
    """Refuse faults that name what the scenario cannot have: a plain fault's robot, any
    fault's area or pose (latent faults may name robots a derivation removed)."""
    robots = {r.id for r in scenario.robots}
    env = scenario.environment
    areas = {a.id for a in env.areas}
    poses = {p.id for p in env.poses()}
    for fault in faults:
        if not fault.latent and fault.robot is not None and fault.robot not in robots:
            raise ExsceError(
                f"fault '{fault.kind}' names robot '{fault.robot}', which is not in {scenario.id}"
            )
        for area in (fault.area, fault.to_area):
            if area is not None and area not in areas:
                raise ExsceError(
                    f"fault '{fault.kind}' names area '{area}', which is not in environment "
                    f"{env.id}{did_you_mean(area, areas)}"
                )
        if fault.pose is not None and fault.pose not in poses:
            raise ExsceError(
                f"fault '{fault.kind}' names pose '{fault.pose}', which is not in environment "
                f"{env.id}{did_you_mean(fault.pose, poses)}"
            )


def speed_factor(scenario: Scenario, robot: str, faults: tuple[Fault, ...]) -> float:
    """How much faster (or slower) than its seeded speed ``robot`` drives."""
    tasks = Counter(e.robot for e in scenario.mission.allocation)
    own_tasks = {e.task for e in scenario.mission.allocation if e.robot == robot}
    factor = 1.0
    for f in faults:
        if f.robot == robot and f.kind == "overspeed":
            factor *= OVERSPEED
        if f.robot == robot and f.kind == "slow":
            factor *= SLOW
        if f.kind == "overspeed-many-tasks" and tasks[robot] > f.index:
            factor *= OVERSPEED
        if f.kind == "overspeed-reassigned" and f.robot != robot and f.task in own_tasks:
            factor *= OVERSPEED
    return factor


def deadlocked(scenario: Scenario, faults: tuple[Fault, ...]) -> bool:
    """Whether a ``deadlock-start`` fault's robot starts at its pose in ``scenario``."""
    starts = {r.id: r.start_pose.id for r in scenario.robots if r.start_pose is not None}
    return any(f.kind == "deadlock-start" and starts.get(f.robot or "") == f.pose for f in faults)


def area_boxes(scenario: Scenario, faults: tuple[Fault, ...]) -> list[tuple[float, float, float, float]]:
    """The boxes (x0, y0, x1, y1) of the areas ``slow-area`` faults name."""
    named = {f.area for f in faults if f.kind == "slow-area"}
    boxes = []
    for area in scenario.environment.areas:
        if area.id in named and area.poses:
            xs = [p.position.x for p in area.poses]
            ys = [p.position.y for p in area.poses]
            boxes.append(
                (min(xs) - AREA_MARGIN, min(ys) - AREA_MARGIN, max(xs) + AREA_MARGIN, max(ys) + AREA_MARGIN)
            )
    return boxes


def slow_in_areas(leg: SampledMotion, boxes: list[tuple[float, float, float, float]]) -> SampledMotion:
    """``leg`` driven at SLOW_AREA of its speed from the first sample inside one of ``boxes``
    to its end (the same path, more samples); unchanged if it never enters one."""
    inside = np.zeros(len(leg), dtype=bool)
    for x0, y0, x1, y1 in boxes:
        inside |= (leg.x >= x0) & (leg.x <= x1) & (leg.y >= y0) & (leg.y <= y1)
    entered = np.flatnonzero(inside)
    if not len(entered):
        return leg
    first, last = int(entered[0]), len(leg) - 1
    step = DT / RAMP
    progress, rates = [], []
    p, rate = 0.0, 1.0
    while p < last:
        if p >= first:
            rate = max(rate - step, SLOW_AREA)
        p = min(p + rate, float(last))
        progress.append(p)
        rates.append(rate)
    at = np.asarray(progress)
    k = np.minimum(at.astype(np.int64), last)
    k1 = np.minimum(k + 1, last)
    f = at - k
    scale = np.asarray(rates)
    return SampledMotion(
        leg.x[k] + f * (leg.x[k1] - leg.x[k]),
        leg.y[k] + f * (leg.y[k1] - leg.y[k]),
        leg.yaw[k] + f * (leg.yaw[k1] - leg.yaw[k]),
        scale * leg.v[k1],
        scale * leg.w[k1],
    )


def detour_via(
    scenario: Scenario, robot: str, leaving: Pose | None, goal: Pose, faults: tuple[Fault, ...]
) -> tuple[float, float] | None:
    """Where a ``detour`` fault sends ``robot`` on its way from ``leaving`` to ``goal``: its
    start pose, when the leg goes from the fault's FROM area to its TO area; else None."""
    if leaving is None:
        return None
    homes = {r.id: r.start_pose for r in scenario.robots if r.start_pose is not None}
    area_of = {p.id: a.id for a in scenario.environment.areas for p in a.poses}
    start_area = leaving.area or area_of.get(leaving.id)
    goal_area = goal.area or area_of.get(goal.id)
    home = homes.get(robot)
    for f in faults:
        if f.kind == "detour" and (start_area, goal_area) == (f.area, f.to_area) and home is not None:
            via = (home.position.x, home.position.y)
            ends = ((leaving.position.x, leaving.position.y), (goal.position.x, goal.position.y))
            if all(math.dist(via, end) > AREA_MARGIN for end in ends):
                return via
    return None


__all__ = [
    "FAULT_KINDS",
    "Fault",
    "FaultKind",
    "area_boxes",
    "check_faults",
    "deadlocked",
    "detour_via",
    "slow_in_areas",
    "speed_factor",
]
