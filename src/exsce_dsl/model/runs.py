"""Runs: one execution of a scenario, what each robot did, and the metrics of its bag.

A run is what ingestion of a bag file fills in and what :func:`exsce_dsl.prov.run.compile_run`
writes as PROV:

* the robots' **task executions**, one per entry of the mission's allocation that a
  robot started, numbered per robot from 1 as in the allocation
  (``tiago1-task_01``), each made of **actions**: one waypoint goal each, started at the
  robot's previous pose and ended at the goal pose;
* **metric values** computed from the bag's topics, for the whole mission, for each
  robot, and for each path segment (one action), so that segments can be queried and
  recombined later;
* **hotspots**: places where a safety metric's limit was violated.
"""

from __future__ import annotations

import datetime
import enum
import re
import uuid
from collections.abc import Iterator
from dataclasses import dataclass

from exsce_dsl.errors import ExsceError
from exsce_dsl.model.coverage import CoverageGap, TopicRate
from exsce_dsl.model.executions import Execution, SimulatorInfo
from exsce_dsl.model.geometry import Pose, Position
from exsce_dsl.model.names import NAME_PATTERN

RUN_NAMESPACE = uuid.UUID("5b8f9a52-3f0c-4a8e-8f0e-2d6c1b7e4a90")
"""The namespace of every run id minted from a key (:func:`run_uuid`); since the first release a
bag's run has uuid5 of its bag's sha256 under it, which stored runs depend on."""

RUN_NAME_TIME = "%Y-%m-%dT%H-%M-%S"
"""How a run's files write its start: ISO 8601 in UTC, with ``-`` for ``:`` (file-safe)."""


class ActionStatus(enum.Enum):
    """How a waypoint goal ended (the dispatcher's final goal status)."""

    SUCCEEDED = "SUCCEEDED"
    ABORTED = "ABORTED"


class RunStatus(enum.Enum):
    """How the mission of a run ended."""

    COMPLETED = "completed"
    """Every robot worked through its tasks (some goals may have been aborted and skipped)."""
    STOPPED = "stopped"
    """A failed goal stopped the mission: the goals after it were never sent."""
    CANCELLED = "cancelled"
    """The mission was cancelled (Ctrl-C, SIGTERM) before it completed."""


class MetricScope(enum.Enum):
    """What a metric value covers."""

    MISSION = "mission"
    """The whole run, all robots (``mission_duration``, ``distance_between_robots``)."""
    ROBOT = "robot"
    """One robot over the whole run (``task_duration``, ``waypoints_visited``...)."""
    SEGMENT = "segment"
    """One robot on one path segment: one action, from its start pose to its goal."""


@dataclass(frozen=True)
class ActionId:
    """Which action: the robot, its task (1-based per robot), the subtask and waypoint (1-based)."""

    robot: str
    allocation: int
    subtask: int
    waypoint: int

    def __post_init__(self) -> None:
        if min(self.allocation, self.subtask, self.waypoint) < 1:
            raise ExsceError(f"action numbers count from 1: {self}")


@dataclass(frozen=True)
class Action:
    """One waypoint goal of a robot: from ``start_pose`` (where it was) to ``goal_pose``."""

    id: ActionId
    start_pose: Pose
    goal_pose: Pose
    status: ActionStatus = ActionStatus.SUCCEEDED
    start: datetime.datetime | None = None
    """When the goal became active."""
    end: datetime.datetime | None = None
    """When the goal reached its final status."""
    outcome: str | None = None
    """Why an ABORTED goal ended when its stack did not abort it: ``rejected``, ``timed out`` (the
    dispatcher cancelled it) or ``cancelled`` (the mission was); in a simulated run, what the
    simulator saw: ``collided``, ``no progress`` (the progress checker gave up); None otherwise."""
    attempts: int = 1
    """How many times the goal was sent (a retried goal: 2)."""

    def __post_init__(self) -> None:
        if self.outcome is not None and self.status is not ActionStatus.ABORTED:
            raise ExsceError(f"action {self.id} {self.outcome} cannot have status {self.status.value}")
        if self.attempts < 1:
            raise ExsceError(f"action {self.id} was sent {self.attempts} times: at least once")

    @property
    def robot(self) -> str:
        return self.id.robot


@dataclass(frozen=True)
class TaskExecution:
    """A robot executing the ``allocation``-th task the mission gives it (1-based)."""

    robot: str
    allocation: int
    actions: tuple[Action, ...]
    segmented_by: str | None = None
    """What its actions were found from, when not the method's dispatcher (see ``runs.stack_runs``)."""

    def __post_init__(self) -> None:
        for action in self.actions:
            if action.id.robot != self.robot or action.id.allocation != self.allocation:
                raise ExsceError(
                    f"action {action.id} is not part of task {self.allocation} of robot '{self.robot}'"
                )


@dataclass(frozen=True)
class Bag:
    """The bag file a run recorded: its file name, where it was, and the topics it holds."""

    file_name: str
    topics: tuple[str, ...] = ()
    path: str | None = None


@dataclass(frozen=True)
class SourceCount:
    """How many samples of one source a value used, of the samples its window holds.

    ``topics``: the bag topics the series was read from (a pose from TF: ``/tf``; one series may
    come from several topics together); ``why``: why fewer than all were used, or what else a
    reader should know of how they were used (None: every sample, plainly)."""

    topics: tuple[str, ...]
    used: int
    in_window: int
    why: str | None = None
    tf_chain: str | None = None
    """For a series composed from TF on ``topics``: the frames composed, the fixed frame first
    (``map → odom → base_link``)."""


@dataclass(frozen=True)
class Accounting:
    """What a value used: its window (``start``, ``end``: seconds since the epoch on the run's
    wall clock, where its actions' times are) and ``reason`` (why the window is that one), the
    samples of each source, and the ``annotations`` (coverage findings) that touch it."""

    start: float
    end: float
    reason: str
    sources: tuple[SourceCount, ...] = ()
    annotations: tuple[str, ...] = ()


@dataclass(frozen=True)
class MetricValue:
    """One value of a metric, computed from ``topics`` of the run's bag.

    ``robot`` is ``None`` for mission values; a segment value names its ``action``
    (and its robot is the action's).  ``safety_metric`` says which safety metric a
    ``violation_duration`` is about (e.g. ``max_velocity``).
    """

    metric: str
    scope: MetricScope
    value: float
    topics: tuple[str, ...] = ()
    robot: str | None = None
    action: ActionId | None = None
    unit: str | None = None
    safety_metric: str | None = None
    estimated_from: str | None = None
    """What the value was estimated from where the bag lacked its signal (``pose``: a speed
    computed from the robot's positions, its bag having no velocity)."""
    accounting: Accounting | None = None
    """What the value used (None: not known, as for values made before accounting existed)."""

    def __post_init__(self) -> None:
        scope = self.scope
        if scope is MetricScope.SEGMENT:
            if self.action is None:
                raise ExsceError(f"the segment value of '{self.metric}' names no action")
            if self.robot is None:
                object.__setattr__(self, "robot", self.action.robot)
            elif self.robot != self.action.robot:
                raise ExsceError(
                    f"the segment value of '{self.metric}' is for robot '{self.robot}' "
                    f"but its action is robot '{self.action.robot}'s"
                )
        elif self.action is not None:
            raise ExsceError(f"a {scope.value} value of '{self.metric}' cannot name an action")
        if scope is MetricScope.ROBOT and self.robot is None:
            raise ExsceError(f"the robot value of '{self.metric}' names no robot")
        if scope is MetricScope.MISSION and self.robot is not None:
            raise ExsceError(f"the mission value of '{self.metric}' cannot be for robot '{self.robot}'")


@dataclass(frozen=True)
class Hotspot:
    """A place where the limit of a safety ``metric`` was violated: how often and how long."""

    metric: str
    position: Position
    violations: int
    duration: float
    """Seconds of violation there."""
    robot: str | None = None


@dataclass(frozen=True)
class RunClock:
    """The clock one source of a run's bag was timed by: ``log time``, ``header stamps`` or
    ``transform stamps``; simulated or the wall clock; its stamps' median offset to log time (s)."""

    topic: str
    clock: str
    simulated: bool
    offset: float = 0.0


@dataclass(frozen=True)
class Run:
    """One execution of scenario ``scenario``, identified by its ``uuid``."""

    uuid: str
    scenario: str
    start: datetime.datetime
    end: datetime.datetime
    bag: Bag
    tasks: tuple[TaskExecution, ...] = ()
    """In the order the robots started them."""
    metrics: tuple[MetricValue, ...] = ()
    hotspots: tuple[Hotspot, ...] = ()
    parameters: str | None = None
    """The file the run's ROS parameters were saved to, if any."""
    clocks: tuple[RunClock, ...] = ()
    """Which clock each of the bag's sources was timed by (the run's timeline)."""
    conventions: tuple[tuple[str, str, tuple[str, ...]], ...] = ()
    """(robot, convention, the topics it was detected from) of robots whose type names none."""
    status: RunStatus = RunStatus.COMPLETED
    """Whether the mission completed; a cancelled or stopped run is incomplete."""
    coverage: tuple[CoverageGap, ...] = ()
    """What the recording does not cover (cut short, gaps, thinned topics, clock jumps)."""
    topic_rates: tuple[TopicRate, ...] = ()
    """How densely each topic a metric reads was recorded."""
    problems: tuple[str, ...] = ()
    """What ingestion said of the run: the values it could not compute and why, topics it could
    not read (the run's warnings)."""
    dated: bool = True
    """Whether ``start``, ``end`` and the actions' times are dates; not when the recorder logged
    simulated time (they are then seconds after 1970 of simulated time, and no date is written)."""
    execution: Execution | None = None
    """What the dispatcher did, as the run-time PROV recorded with the bag says (None without it)."""
    simulator: SimulatorInfo | None = None
    """What played the run, in the run-time PROV a simulator writes (ingestion reads it back
    into :attr:`execution`)."""

    def actions(self) -> Iterator[Action]:
        for task in self.tasks:
            yield from task.actions


def run_uuid(*key: str) -> str:
    """A run's id, minted under :data:`RUN_NAMESPACE` from what identifies the run (the parts
    joined by a space): a bag's sha256, so that ingesting a bag twice is recognised; the sha256
    and a scenario's IRI, for the bag's run under a scenario other than the one the store first
    held it as; ``"simulated"`` and the scenario, seed, index and faults of a simulated run."""
    return str(uuid.uuid5(RUN_NAMESPACE, " ".join(key)))


def run_name(start: datetime.datetime, scenario: str, run_id: str) -> str:
    """The name the method gives a run's files, before their extension:
    ``<ISO date>_<scenario>_run-<first 8 of the run's uuid>``
    (``2023-06-13T15-48-07_scenario_c_run-e30df0b6``), the start in UTC.

    The scenario id must be written as the language writes ids (letters, digits, ``_`` and
    inner ``-``): such an id is safe in a file name; anything else (a path, spaces) is an :class:`ExsceError`,
    as is a run id that is not a uuid or a start without a time zone."""
    if not re.fullmatch(NAME_PATTERN, scenario):
        raise ExsceError(
            f"scenario id {scenario!r} cannot name a run's files: use letters, digits, '_' and '-'"
        )
    try:
        hexed = str(uuid.UUID(run_id))
    except ValueError:
        raise ExsceError(f"run id {run_id!r} is not a uuid") from None
    if start.tzinfo is None or start.utcoffset() is None:
        raise ExsceError(f"the start of run {hexed} has no time zone ({start.isoformat()})")
    return f"{start.astimezone(datetime.timezone.utc).strftime(RUN_NAME_TIME)}_{scenario}_run-{hexed[:8]}"
