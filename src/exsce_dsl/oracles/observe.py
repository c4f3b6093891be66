"""What a run shows for an oracle: its value of the oracle's metric, for the robot and the
part of the run (window) the oracle looks at, read from the store in two queries per batch
of runs."""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass, field

from exsce_dsl.lang import metric_info, standard_metrics
from exsce_dsl.model import Scenario
from exsce_dsl.model.acceptance import Moment, Window
from exsce_dsl.model.metrics import Combine, ComputedFor
from exsce_dsl.store import Store, run_metric_values, run_segment_values

_ACTION = re.compile(r"/(?P<robot>[^/]+)-task_(?P<task>\d+)-subtask_(?P<subtask>\d+)-w_(?P<waypoint>\d+)$")
_WINDOW = re.compile(
    r"(?P<moment>during|before|after) (?:(?P<robot>\S+) reaches (?P<pose>\S+)|(?P<task>\S+))"
)


@dataclass(frozen=True)
class ActionValue:
    """One action's value of a metric, as the store holds it for a run."""

    action: str
    robot: str
    allocation: int
    """The robot's task it belongs to: 1 for its first task in the mission."""
    order: tuple[int, int, int]
    goal: str
    """The goal pose's name with its heading (``room-p3-R0.00_P0.00_Y0.00``)."""
    metric: str
    value: float


@dataclass
class RunValues:
    """One run's metric values: whole-run ones by (metric, robot), and per action."""

    run: str
    whole: dict[tuple[str, str | None], list[float]] = field(default_factory=dict)
    segments: list[ActionValue] = field(default_factory=list)
    violations: dict[str | None, set[str]] = field(default_factory=dict)
    """Robot (None: the mission) → the safety metrics whose violation durations the run has."""


def run_values(store: Store, runs: Sequence[str]) -> dict[str, RunValues]:
    """The metric values of ``runs`` (uuids), by run."""
    found = {run: RunValues(run) for run in runs}
    if not runs:
        return found
    for reading in run_metric_values(store, runs):
        if reading.run in found:
            found[reading.run].whole.setdefault((reading.metric, reading.robot), []).append(reading.value)
            if reading.safety is not None:
                found[reading.run].violations.setdefault(reading.robot, set()).add(reading.safety)
    for reading in run_segment_values(store, runs):
        parts = _ACTION.search(reading.action or "")
        if parts is None or reading.run not in found or reading.goal is None:
            continue
        numbers = (int(parts["task"]), int(parts["subtask"]), int(parts["waypoint"]))
        found[reading.run].segments.append(
            ActionValue(
                reading.action or "",
                parts["robot"],
                numbers[0],
                numbers,
                reading.goal,
                reading.metric,
                reading.value,
            )
        )
    return found


def parse_window(text: str | None) -> Window | None:
    """The window of an oracle as the store keeps it (``during delivery_a``), or None."""
    if text is None:
        return None
    match = _WINDOW.fullmatch(text)
    if match is None:
        raise ValueError(f"not a window: {text!r}")
    if match["task"] is not None:
        return Window(Moment(match["moment"]), "", task=match["task"])
    return Window(Moment(match["moment"]), match["robot"], pose=match["pose"])


def observe(
    values: RunValues, metric: str, robot: str | None, window: Window | None, scenario: Scenario
) -> tuple[float | None, str]:
    """The run's value for an oracle, or None and why there is none."""
    info = metric_info(metric, scenario)
    if window is None:
        found = values.whole.get((metric, robot))
        if not found:
            who = f" of robot '{robot}'" if robot else " of the mission"
            return None, f"run {values.run} has no value of '{metric}'{who}"
        if metric == "violation_duration":  # one value per safety metric: a clause says the total
            lacking = sorted(_safety_metrics(scenario, robot) - values.violations.get(robot, set()))
            if lacking:
                who = f" of robot '{robot}'" if robot else " of the mission"
                listed = ", ".join(f"'{m}'" for m in lacking)
                why = f"run {values.run} has no violation duration of {listed}{who}: the total is missing"
                return None, why
        return (sum(found) if len(found) > 1 else found[0]), ""
    if info is None or info.combine is None:
        return None, f"'{metric}' has no value per path segment"
    owner = robot or window.robot
    mine = [s for s in values.segments if s.robot == owner]
    picked = window_segments(values, robot, window, scenario)
    if not picked:
        return None, f"run {values.run} has no path segment of '{owner}' {window.text()}"
    found_values = {s.action: s.value for s in mine if s.metric == metric}
    without = [s for s in picked if s.action not in found_values]
    if without:
        return None, (
            f"run {values.run} has no value of '{metric}' for {len(without)} of the {len(picked)} "
            f"path segments of '{owner}' {window.text()}"
        )
    numbers = [found_values[s.action] for s in picked]
    if info.combine is Combine.SUM:
        return float(sum(numbers)), ""
    return float(max(numbers) if info.combine is Combine.MAX else min(numbers)), ""


def window_segments(
    values: RunValues, robot: str | None, window: Window, scenario: Scenario
) -> list[ActionValue]:
    """The path segments of ``window`` in a run, in their order, one per action.

    They are those the run has any value of: one without a value of a clause's metric makes the
    combination missing (the others' sum, min or max is not the window's)."""
    owner = robot or window.robot
    mine = [s for s in values.segments if s.robot == owner]
    segments = sorted({s.action: s for s in mine}.values(), key=lambda s: s.order)
    return _in_window(segments, window, scenario.mission.tasks_of(owner))


def _safety_metrics(scenario: Scenario, robot: str | None) -> set[str]:
    """The safety metrics whose violation durations make up a robot's (None: the mission's) total."""
    wanted = {ComputedFor.ROBOT} if robot is not None else {ComputedFor.MISSION, ComputedFor.PAIRS}
    return {m.name for m in (*standard_metrics(), *scenario.metrics) if m.safety and m.subject in wanted}


def _in_window(segments: list[ActionValue], window: Window, tasks: Sequence[str]) -> list[ActionValue]:
    if window.task is not None:
        indices = [k for k, task in enumerate(tasks, start=1) if task == window.task]
        if not indices:
            return []
        if window.moment is Moment.DURING:
            return [s for s in segments if s.allocation in indices]
        if window.moment is Moment.BEFORE:
            return [s for s in segments if s.allocation < indices[0]]
        return [s for s in segments if s.allocation > indices[-1]]
    reached = next(
        (n for n, s in enumerate(segments) if s.goal == window.pose or s.goal.startswith(f"{window.pose}-R")),
        None,
    )
    if reached is None:
        return []
    return segments[: reached + 1] if window.moment is Moment.BEFORE else segments[reached + 1 :]
