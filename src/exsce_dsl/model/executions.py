"""What the dispatcher of a run did, as its run-time PROV says: the execution of a mission.

``exscec simulate``, ``exscec execute`` and the stand-in record the run-time PROV of each run
(on ``/exsce/prov`` inside the bag, and in the ``.prov.json`` beside it) under the dispatcher's
own run id.  Ingestion names the run after the bag's content instead, so it keeps what the
dispatcher said as an :class:`Execution` of the run (:attr:`~exsce_dsl.model.runs.Run.execution`):
the store then links the two (:mod:`exsce_dsl.prov.run_execution`).
"""

from __future__ import annotations

import datetime
from dataclasses import dataclass

__all__ = ["DispatchedGoal", "Execution"]


@dataclass(frozen=True)
class DispatchedGoal:
    """One waypoint goal the dispatcher sent (an action of its run-time PROV)."""

    name: str
    """``<robot>-task_NN-subtask_NNN-w_NNN``, as the dispatcher named it."""
    robot: str
    goal_pose: str | None
    """The local name of the goal's pose (``classroom_c022-w001-R0.00_P0.00_Y2.269``)."""
    start_pose: str | None
    status: str
    """``SUCCEEDED`` or ``ABORTED``."""
    outcome: str | None = None
    """Why an ABORTED goal that its stack did not abort ended: rejected, timed out, cancelled."""
    attempts: int = 1
    start: datetime.datetime | None = None
    end: datetime.datetime | None = None


@dataclass(frozen=True)
class SimulatorInfo:
    """The software that played a simulated run: its name (``kinematic``, ``irsim``), its version
    and the settings that decided how it played (``behaviour=rvo``)."""

    name: str
    version: str
    settings: tuple[tuple[str, str], ...] = ()


@dataclass(frozen=True)
class Execution:
    """The execution of a run's mission, as its dispatcher recorded it."""

    run_id: str
    """The dispatcher's uuid of the run (``run_<uuid>`` in its ``.prov.json``)."""
    source: str
    """Where it was read from: ``/exsce/prov`` (inside the bag) or the ``.prov.json`` file's name."""
    bag_name: str | None
    """The bag's local name in the dispatcher's run namespace (its file name, escaped as
    :func:`exsce_dsl.prov.identifiers.bag_name` does)."""
    start: datetime.datetime | None = None
    end: datetime.datetime | None = None
    mission_status: str | None = None
    """``cancelled`` or ``stopped`` when the mission did not complete."""
    goals: tuple[DispatchedGoal, ...] = ()
    """In the order they were sent."""
    simulator: SimulatorInfo | None = None
    """What played the run, when a simulator did (its run-time PROV names it)."""
