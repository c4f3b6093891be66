"""A bag file and its scenario in, the run (actions, metrics, hotspots) out."""

from __future__ import annotations

import datetime as dt
import hashlib
import uuid
from dataclasses import dataclass, field
from pathlib import Path

from exsce_dsl.model import Scenario
from exsce_dsl.model.runs import Action, ActionId, ActionStatus, Bag, Run, TaskExecution
from exsce_dsl.runs.bagdata import BagError, read_bag
from exsce_dsl.runs.decode import FLOAT64, POSE, SCAN, TWIST
from exsce_dsl.runs.metrics import RobotSignals, SafetyLimits, compute_metrics, robot_topics
from exsce_dsl.runs.segments import SUCCEEDED, Segment, segments

_RUN_NAMESPACE = uuid.UUID("5b8f9a52-3f0c-4a8e-8f0e-2d6c1b7e4a90")
_TYPES = {"pose": POSE, "scan": SCAN, "vel": TWIST, "distance": FLOAT64, "feedback": "*", "result": "*"}


@dataclass(frozen=True)
class AnalysedRun:
    run: Run
    content_hash: str
    problems: list[str] = field(default_factory=list)


def content_hash(path: Path) -> str:
    """sha256 of the bag's bytes (all files of a ROS 2 bag folder, in name order)."""
    digest = hashlib.sha256()
    files = [path] if path.is_file() else sorted(p for p in path.rglob("*") if p.is_file())
    for file in files:
        with file.open("rb") as stream:
            for block in iter(lambda: stream.read(1 << 20), b""):
                digest.update(block)
    return digest.hexdigest()


def run_uuid(digest: str) -> str:
    """A run's id follows from its bag's content, so ingesting a bag twice is recognised."""
    return str(uuid.uuid5(_RUN_NAMESPACE, digest))


def analyse_bag(path: Path, scenario: Scenario, limits: SafetyLimits | None = None) -> AnalysedRun:
    limits = limits or SafetyLimits()
    digest = content_hash(path) if path.exists() else ""
    robots = [r for r in scenario.robots if r.start_pose is not None]
    wanted = {robot_topics(r.namespace)[k]: t for r in robots for k, t in _TYPES.items()}
    data = read_bag(path, wanted)
    problems = list(data.problems)
    actions: list[Segment] = []
    results: dict[str, int | None] = {}
    for robot in robots:
        topics = robot_topics(robot.namespace)
        updates = data.feedback.get(topics["feedback"])
        if updates is None:
            problems.append(f"topic {topics['feedback']} is missing: no path segments for '{robot.id}'")
            results[robot.id] = None
            continue
        actions.extend(segments(scenario, robot.id, updates))
        final = data.results.get(topics["result"])
        results[robot.id] = None if final is None else sum(s == SUCCEEDED for u in final for s in u.statuses)
    if not any(a.start is not None for a in actions):
        raise BagError(f"{path}: no waypoint goal of scenario '{scenario.id}' became active in this bag")
    signals = [RobotSignals.from_bag(r.id, r.namespace, data) for r in robots]
    metrics, hotspots = compute_metrics(signals, actions, results, limits, problems)
    run = Run(
        uuid=run_uuid(digest),
        scenario=scenario.id,
        start=_time(data.start),
        end=_time(data.end),
        bag=Bag(path.name, data.topics, str(path)),
        tasks=_task_executions(actions),
        metrics=tuple(metrics),
        hotspots=tuple(hotspots),
    )
    return AnalysedRun(run, digest, problems)


def _time(seconds: float) -> dt.datetime:
    return dt.datetime.fromtimestamp(seconds, tz=dt.timezone.utc)


def _task_executions(actions: list[Segment]) -> tuple[TaskExecution, ...]:
    started = [
        a
        for a in actions
        if a.start is not None and a.end is not None and a.status in ("SUCCEEDED", "ABORTED")
    ]
    started.sort(key=lambda a: (a.start or 0.0, a.robot))
    grouped: dict[tuple[str, int], list[Action]] = {}
    for a in started:
        grouped.setdefault((a.robot, a.allocation), []).append(
            Action(
                ActionId(a.robot, a.allocation, a.subtask, a.waypoint),
                a.start_pose,
                a.goal,
                ActionStatus(a.status),
                _time(a.start),  # type: ignore[arg-type]
                _time(a.end),  # type: ignore[arg-type]
            )
        )
    return tuple(TaskExecution(robot, n, tuple(acts)) for (robot, n), acts in grouped.items())
