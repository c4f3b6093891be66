"""Expected values of a scenario's metrics from stored path segments, estimated where no run
drove a segment (the method's §4.2.1, with the proportion the right way round).

A robot's expected ``distance_travelled`` or ``task_duration`` is the sum over the
segments of its path (start pose, then its tasks' waypoints) of the segment's mean
over the good stored runs of any scenario (:mod:`exsce_dsl.oracles.good_runs`: not failed nor
inconclusive when verified, mission completed, no safety limit broken; every run when asked), in
the task's direction or else the other way, between the same two positions whatever the
headings (what a drive costs hardly depends on the heading it ends with, and a task may name a
pose with another heading).  A segment no run drove is estimated from the nearest poses p3, p4 of the same
area to its ends p1, p2: from each of (p3, p2), (p1, p4), (p3, p4) that has data,
``m_ij * dist(p1, p2) / dist(p_i, p_j)``, averaged.  (The method's report writes
the ratio upside down, which makes a longer neighbour segment give a *longer*
estimate for a shorter one; scaling by the distance ratio this way keeps the unit
"per metre".)  ``dist`` is the length of the shortest path on the environment's
occupancy grid (round walls, through doorways: :mod:`exsce_dsl.derive.grid_lengths`) when the
environment declares a map file that can be read and joins the poses, else the straight-line
distance; the segment's ``how`` says which.  Without neighbour data, the fallback is the
segment's length (measured the same way) times the robot's value per metre of such length on its
segments that have a value (observed or estimated); with no value anywhere, there is no expected
value.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

from exsce_dsl.derive.grid_lengths import grid_lengths
from exsce_dsl.derive.kept_clauses import safety_clauses, standing_note
from exsce_dsl.derive.waiting import Waiting, waiting_for, waiting_note
from exsce_dsl.errors import ExsceError
from exsce_dsl.model import Pose, Scenario
from exsce_dsl.model.acceptance import (
    Acceptance,
    BasicRelation,
    Criterion,
    Expectation,
    Quantifier,
    Quantity,
    Subject,
    When,
)
from exsce_dsl.oracles import good_runs_of
from exsce_dsl.store import Store, ValueStats, robot_metric_over_runs, segment_metric_between

SUMMED = ("distance_travelled", "task_duration")
"""The metrics a robot's value of is the sum of its segments' values."""

DISTANCE = "distance_travelled"

DETOUR = 0.2
"""A neighbour segment driven more than this fraction longer than its path on the grid was not
a plain drive (the robot gave way, waited, went round another robot): an estimate from it scales
by the distance driven on it, not by its grid path length (the grid knows walls, not robots)."""


@dataclass(frozen=True)
class PathSegmentValue:
    """A path segment's expected value of a metric: observed on stored runs, or estimated."""

    start: str
    goal: str
    value: float | None
    how: str
    """``observed``, ``observed the other way``, ``estimated from ...`` or ``no data``."""
    runs: int = 0


@dataclass(frozen=True)
class ExpectedValue:
    """A robot's expected value of a metric, with the values of its path's segments it came from."""

    robot: str
    metric: str
    value: float | None
    segments: tuple[PathSegmentValue, ...]


def robot_path(scenario: Scenario, robot_id: str) -> list[tuple[Pose, Pose]]:
    """The robot's path segments: from its start pose through its tasks' waypoints."""
    robot = scenario.robot(robot_id)
    if robot is None or robot.start_pose is None:
        return []
    poses = [robot.start_pose]
    for task_id in scenario.mission.tasks_of(robot_id):
        task = scenario.task(task_id)
        if task is not None:
            poses.extend(task.waypoints())
    return list(zip(poses, poses[1:], strict=False))


def learning_runs(store: Store, include_all: bool = False) -> tuple[str, ...]:
    """The runs whose drives expected values and estimates learn from: the good runs of every
    scenario (:mod:`exsce_dsl.oracles.good_runs`), or every stored run with ``include_all``."""
    return good_runs_of(store, include_all=include_all).used


def _either_way(
    store: Store,
    metric: str,
    start: Pose,
    goal: Pose,
    held_out: frozenset[frozenset[str]],
    runs: Sequence[str],
) -> tuple[ValueStats | None, bool]:
    if frozenset((start.id, goal.id)) in held_out:
        return None, False
    found = segment_metric_between(store, metric, start, goal, runs=runs)
    if found is not None:
        return found, False
    return segment_metric_between(store, metric, goal, start, runs=runs), True


def segment_value(
    store: Store,
    scenario: Scenario,
    metric: str,
    start: Pose,
    goal: Pose,
    held_out: frozenset[frozenset[str]] = frozenset(),
    on_grid: bool = True,
    detour: float = DETOUR,
    *,
    runs: Sequence[str] | None = None,
) -> PathSegmentValue:
    """One segment's value; ``held_out`` pairs of pose ids are treated as never driven (either way),
    to measure the estimate against what was driven (bench/estimate.py).  An estimate scales by
    path lengths on the environment's occupancy grid when it declares one (and ``on_grid``), else
    by straight-line lengths; its ``how`` says which.  On the grid, a neighbour driven more than
    ``detour`` (a fraction) longer than its grid path is scaled by the distance driven instead
    (see :data:`DETOUR`; ``math.inf``: never).  Only the drives of ``runs`` count (default: the
    good runs of every scenario, :func:`learning_runs`)."""
    if runs is None:
        runs = learning_runs(store)
    names = (start.id, goal.id)
    found, reverse = _either_way(store, metric, start, goal, held_out, runs)
    if found is not None:
        return PathSegmentValue(
            *names, found.mean, "observed the other way" if reverse else "observed", found.count
        )
    near_start, near_goal = _area_poses(scenario, start, names), _area_poses(scenario, goal, names)
    if not near_start or not near_goal or math.dist(_xy(start), _xy(goal)) == 0:
        return PathSegmentValue(*names, None, "no data, and no pose near it to estimate from")
    p3 = min(near_start, key=lambda p: math.dist(_xy(p), _xy(start)))  # in p1's area
    p4 = min(near_goal, key=lambda p: math.dist(_xy(p), _xy(goal)))  # in p2's area
    neighbours = []
    for i, j in ((p3, goal), (start, p4), (p3, p4)):
        near, _ = _either_way(store, metric, i, j, held_out, runs)
        if near is not None:
            neighbours.append((i, j, near))
    if not neighbours:
        return PathSegmentValue(*names, None, f"no data, nor for {p3.id} and {p4.id} near its ends")
    lengths = _lengths(scenario, on_grid, [(start, goal)] + [(i, j) for i, j, _ in neighbours])
    estimates, used, notes, drives = [], [], [], 0
    for i, j, near in neighbours:
        length = lengths.of(i, j)
        if length == 0:
            continue
        if lengths.on_grid:  # a detour the grid does not know: scale by the distance driven instead
            driven = near if metric == DISTANCE else _either_way(store, DISTANCE, i, j, held_out, runs)[0]
            if driven is not None and driven.mean > (1.0 + detour) * length:
                longer = driven.mean / length - 1.0
                notes.append(f"{i.id}–{j.id} per metre driven, {longer:.0%} longer than its grid path")
                length = driven.mean
        estimates.append(near.mean * lengths.of(start, goal) / length)
        used.append(f"{i.id}–{j.id}")
        drives += near.count
    if not estimates:
        return PathSegmentValue(*names, None, f"no data, nor for {p3.id} and {p4.id} near its ends")
    return PathSegmentValue(
        *names,
        math.fsum(estimates) / len(estimates),
        f"estimated from {', '.join(used)} ({'; '.join([lengths.words, *notes])})",
        drives,
    )


@dataclass(frozen=True)
class _Lengths:
    """Lengths between poses (by id), measured one way for a whole estimate (ratios of lengths
    measured differently would mean nothing): on the occupancy grid, or in straight lines."""

    measured: dict[tuple[str, str], float]
    on_grid: bool
    why: str = ""
    """Why not on the grid, when the environment declares one."""

    def of(self, a: Pose, b: Pose) -> float:
        return self.measured[(a.id, b.id)]

    @property
    def words(self) -> str:
        return (
            "grid path lengths"
            if self.on_grid
            else "straight-line lengths" + (f": {self.why}" if self.why else "")
        )


def _lengths(scenario: Scenario, on_grid: bool, pairs: list[tuple[Pose, Pose]]) -> _Lengths:
    """Path lengths on the environment's occupancy grid when it has one and every pair is joined on
    it, else straight-line lengths, with the reason when a declared grid could not be used."""
    straight = {(a.id, b.id): math.dist(_xy(a), _xy(b)) for a, b in pairs}
    if not on_grid:
        return _Lengths(straight, False)
    try:
        grid = grid_lengths(scenario)
    except ExsceError as error:
        return _Lengths(straight, False, f"its grid cannot be used ({error})")
    if grid is None:
        return _Lengths(straight, False)
    on_map = {(a.id, b.id): grid.length(_xy(a), _xy(b)) for a, b in pairs}
    for (a, b), length in on_map.items():
        if length is None:
            return _Lengths(straight, False, f"no path from {a} to {b} on its grid")
    return _Lengths({k: v for k, v in on_map.items() if v is not None}, True)


def expected_metric(
    store: Store,
    scenario: Scenario,
    robot: str,
    metric: str,
    *,
    include_all: bool = False,
    runs: Sequence[str] | None = None,
) -> ExpectedValue:
    """The robot's expected value of a summed metric (see the module's description), from the
    good runs of every scenario (every stored run with ``include_all``; exactly ``runs`` when
    given)."""
    if metric not in SUMMED:
        raise ValueError(f"'{metric}' is not a sum over path segments")
    if runs is None:
        runs = learning_runs(store, include_all)
    path = robot_path(scenario, robot)
    parts = tuple(segment_value(store, scenario, metric, a, b, runs=runs) for a, b in path)
    if any(p.value is None for p in parts):
        parts = _fall_back(parts, path, _lengths(scenario, True, path))
    values = [p.value for p in parts]
    total = math.fsum(v for v in values if v is not None) if parts and None not in values else None
    return ExpectedValue(robot, metric, total, parts)


def _area_poses(scenario: Scenario, pose: Pose, leave_out: tuple[str, ...]) -> list[Pose]:
    """The other poses of the area ``pose`` is in (none if it is in no area)."""
    area = next((a for a in scenario.environment.areas if any(p.id == pose.id for p in a.poses)), None)
    return [p for p in area.poses if p.id not in leave_out] if area is not None else []


def _fall_back(
    parts: tuple[PathSegmentValue, ...], path: list[tuple[Pose, Pose]], lengths: _Lengths
) -> tuple[PathSegmentValue, ...]:
    """Segments with no value and no neighbour data: their length (on the grid, or straight) times
    the robot's value per metre of such length over the segments that have a value."""
    known = [
        (p.value, lengths.of(a, b)) for p, (a, b) in zip(parts, path, strict=True) if p.value is not None
    ]
    metres = math.fsum(d for _, d in known)
    if not known or metres == 0:
        return parts
    rate = math.fsum(v for v, _ in known) / metres
    length = "grid path length" if lengths.on_grid else "straight length"
    return tuple(
        p
        if p.value is not None
        else replace(
            p,
            value=rate * lengths.of(a, b),
            how=f"{p.how}: its {length} × {rate:.3g} per metre, as on the robot's other segments",
        )
        for p, (a, b) in zip(parts, path, strict=True)
    )


def _xy(pose: Pose) -> tuple[float, float]:
    return (pose.position.x, pose.position.y)


RELATIVE_TOLERANCE = 10.0
"""Percent of the expected change a derived scenario's performance clause allows, by default."""

OBSERVED_DISTANCE = 10.0
"""Percent of an observed segment's distance a run may differ by at most: between the same poses
a path hardly varies, but a robot may go round another (the simulator's repairs add up to a few
metres to a leg, a real planner as much)."""


@dataclass(frozen=True)
class DerivedCriteria:
    """A derived scenario's acceptance criteria, and a note for each clause the base would give it
    that they leave out, saying why (nothing is left out silently)."""

    acceptance: Acceptance
    notes: tuple[str, ...] = ()


def derived_criteria(
    store: Store,
    base: Scenario,
    derived: Scenario,
    base_acceptance: Acceptance | None,
    tolerance_percent: float = RELATIVE_TOLERANCE,
    *,
    include_all: bool = False,
) -> DerivedCriteria:
    """The acceptance criteria of a derived scenario, as the method's Listing 35 makes them: the
    base's safety clauses (every limit the user wrote, ``stays below`` or ``stays above``, on any
    metric: a peak, a mean, a total; over the whole run, about robots it still has; a clause
    between robots is dropped when one robot is left), and per robot, for distance travelled,
    task duration and waypoints visited,

    * the expected value itself, as the new scenario's own baseline (``is invariant around E
      within P %``): a run far from it either way fails, so a slow-down or a detour is caught;
    * the relation to the base's runs the expected value implies: ``is increasing|decreasing by
      |E - B| within A of BASE`` (B the base's mean, A = P % of E), or, when the change is
      within that allowance, ``is invariant within A + |E - B| of BASE`` (what a run within A
      of E may differ from B).

    P is ``tolerance_percent`` (for distance, at most OBSERVED_DISTANCE % on the segments stored
    runs observed: see :func:`_allowance`); waypoints are counted, so exactly.  A robot the base does not
    have (``add_robot``, ``replace_robot``) gets its own-baseline clauses only: a slow-down of the
    new robot is caught, and there is nothing of the base to relate it to.  Without an expected
    value, or for a robot the base's runs do not show, there is no performance clause.  A robot
    given no tasks (``add_robot ... taking over``, ``remove_task``) has no performance clause,
    and a note says why (:func:`~exsce_dsl.derive.kept_clauses.standing_note`); the safety
    clauses judge it standing by.  A robot that shares the derived scenario's runs with other
    robots may give way to them: its task_duration clauses allow that time more, on the slow
    side only, and a note says so (:mod:`exsce_dsl.derive.waiting`).  A tolerance is written
    rounded up past the rounding of the change it goes with.

    E and B come from good runs only (every stored run with ``include_all``): a run that failed,
    was inconclusive, did not complete its mission or broke a safety limit would teach the
    expectation its fault (:mod:`exsce_dsl.oracles.good_runs`)."""
    safety, notes = safety_clauses(derived, base_acceptance)
    chosen = good_runs_of(store, base.id, include_all=include_all, scenario=base)
    base_runs = list(chosen.require_some(f"'{base.id}' to expect from").used)
    learning = learning_runs(store, include_all)
    performance: list[Expectation] = []
    waits: dict[str, float] = {}
    for robot in derived.robots:
        if not derived.mission.tasks_of(robot.id):
            if robot.start_pose is not None:  # one without is in no run: its note is said above
                notes.append(standing_note(robot.id, derived.id))
            continue
        subject = Subject(Quantifier.ROBOT, robot.id)
        in_base = base.robot(robot.id) is not None
        for metric in SUMMED:
            estimate = expected_metric(store, derived, robot.id, metric, runs=learning)
            expected = estimate.value
            if expected is None:
                continue
            before = robot_metric_over_runs(store, metric, robot.id, base_runs) if in_base else None
            unit = "m" if metric == "distance_travelled" else "s"
            allowance = _allowance(estimate, tolerance_percent)
            waiting = Waiting(expected, allowance, waiting_for(derived, robot.id, metric))
            if waiting.waiting:
                waits[robot.id] = waiting.waiting
            performance.extend(
                _expected_clauses(subject, metric, waiting.centre, before, waiting.half_width, unit, base.id)
            )
        waypoints = len(robot_path(derived, robot.id))
        before = robot_metric_over_runs(store, "waypoints_visited", robot.id, base_runs) if in_base else None
        if in_base and before is None:
            continue  # the base's runs do not count this robot's waypoints: nothing to expect
        performance.extend(
            _expected_clauses(subject, "waypoints_visited", waypoints, before, 0.0, None, base.id)
        )
    if waits:
        notes.append(waiting_note(derived, waits))
    when = When(mission=derived.mission.id)  # empty criteria are left out: an empty block is an error
    criteria = []
    if safety:
        criteria.append(Criterion(f"as safe as {base.id}", (), when, tuple(safety)))
    if performance:
        criteria.append(Criterion(f"as expected from {base.id}", (), when, tuple(performance)))
    return DerivedCriteria(Acceptance(derived.id, tuple(criteria)), tuple(notes))


def _allowance(expected: ExpectedValue, tolerance_percent: float) -> float:
    """What a run may differ from ``expected`` by: ``tolerance_percent`` of it, but for distance
    at most OBSERVED_DISTANCE percent of the segments observed in stored runs (the estimate's
    error is in the estimated segments; a path between two poses hardly varies)."""
    if expected.metric != DISTANCE:
        return abs(expected.value or 0.0) * tolerance_percent / 100.0
    observed = min(tolerance_percent, OBSERVED_DISTANCE)
    return math.fsum(
        abs(s.value) * (observed if s.how.startswith("observed") else tolerance_percent) / 100.0
        for s in expected.segments
        if s.value is not None
    )


def _expected_clauses(
    subject: Subject,
    metric: str,
    expected: float,
    before: ValueStats | None,
    allowance: float,
    unit: str | None,
    base: str,
) -> list[Expectation]:
    """The own-baseline clause and the metamorphic one for one expected value (see above); a
    robot the base does not have (``before`` None) has no relation to the base, only its own."""

    def quantity(value: float) -> Quantity:
        return Quantity(round(value, 3), unit)

    def allowing(value: float, written: float = 0.0) -> Quantity:
        """A tolerance as written: what rounding ``written`` (the clause's other value) to 3
        decimals takes off it added, rounded up (a run within the allowance of the unrounded
        value must not fail by a rounding: with an allowance of 0 m it did)."""
        slack = abs(written - round(written, 3))
        return Quantity(math.ceil(round((value + slack) * 1000.0, 6)) / 1000.0, unit)

    own = Expectation(
        subject,
        metric,
        BasicRelation.INVARIANT,
        value=quantity(expected),
        tolerance=Quantity(round(100.0 * allowance / abs(expected), 3), "%") if expected else quantity(0.0),
    )
    if before is None:
        return [own]
    change = expected - before.mean
    if abs(change) <= allowance:
        # the run is expected within the allowance of E, which is up to |E - B| from B: the
        # relation to the base must allow both, or a run that meets its own clause fails this one
        same = Expectation(
            subject,
            metric,
            BasicRelation.INVARIANT,
            tolerance=allowing(allowance + abs(change)),
            against=base,
        )
        return [own, same]
    direction = BasicRelation.INCREASING if change > 0 else BasicRelation.DECREASING
    moved = Expectation(
        subject,
        metric,
        direction,
        delta=quantity(abs(change)),
        tolerance=allowing(allowance, abs(change)),
        against=base,
    )
    return [own, moved]
