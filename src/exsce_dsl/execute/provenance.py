"""The run-time PROV of a mission run: what the method's recorder writes (task executions, one
action per goal), built from what the dispatcher did (:class:`~.outcomes.MissionRun`).

* One action per goal the dispatcher sent, ``<robot>-task_NN-subtask_NNN-w_NNN`` as the
  schedule numbers it; a goal retried (``Policy.RETRY_ONCE``) is one action, from its first
  attempt's start to its last attempt's end, with ``exsce:attempts 2``.  Goals never sent
  (after a skipped task, a stopped or cancelled mission) do not appear at all; a task execution
  none of whose goals was sent does not appear either.
* An action starts at the pose where its robot was: the goal of its last action that
  SUCCEEDED, else the robot's start pose (a goal that failed leaves the robot short of it, as
  the kinematic executor records it).
* Status: SUCCEEDED, or ABORTED for every goal that did not succeed (the method's two); an
  ABORTED action that its stack did not abort says why in ``exsce:goal_outcome``: ``rejected``,
  ``timed out`` (the dispatcher cancelled it after its timeout) or ``cancelled`` (the mission
  was cancelled or stopped while it was active).
* A run whose mission was cancelled or stopped carries ``exsce:mission_status`` on its run
  activity: it is incomplete.
* Times: the run starts at ``start`` (the mission's start on its clock) and ends as much later
  as the mission did; each action likewise.
"""

from __future__ import annotations

import datetime as dt

from exsce_dsl.errors import ExsceError
from exsce_dsl.execute.outcomes import GoalOutcome, GoalRecord, MissionRun
from exsce_dsl.model import Pose, Scenario
from exsce_dsl.model.runs import Action, ActionId, ActionStatus, Run, RunStatus
from exsce_dsl.prov.recorder import recorded_prov_json, recorded_run

__all__ = ["mission_prov_json", "mission_run_record"]


def mission_run_record(
    mission: MissionRun, scenario: Scenario, run_id: str, start: dt.datetime, bag_file_name: str
) -> Run:
    """The recorder's :class:`Run` of ``mission``, a run of ``scenario`` that began at ``start``
    and was recorded into ``bag_file_name``: task executions and actions, no metrics."""

    def at(seconds: float) -> dt.datetime:
        return start + dt.timedelta(seconds=seconds - mission.start)

    where: dict[str, Pose | None] = {r.id: r.start_pose for r in scenario.robots}
    actions: list[Action] = []
    for record in sorted(mission.records, key=lambda r: r.start):
        if record.robot not in where:
            raise ExsceError(
                f"run {run_id} sent a goal to robot '{record.robot}', "
                f"which is not in scenario '{scenario.id}'"
            )
        before = where[record.robot]
        if before is None:
            raise ExsceError(
                f"robot '{record.robot}' of scenario '{scenario.id}' has no start pose: its first "
                "action cannot say where it started"
            )
        actions.append(_action(record, before, at(record.start), at(record.end)))
        if record.outcome is GoalOutcome.SUCCEEDED:
            where[record.robot] = record.pose
    status = RunStatus(mission.status.value)
    return recorded_run(run_id, scenario.id, start, at(mission.end), bag_file_name, actions, status)


def mission_prov_json(
    mission: MissionRun, scenario: Scenario, run_id: str, start: dt.datetime, bag_file_name: str
) -> str:
    """The PROV-JSON text (the run's ``.prov.json``) of :func:`mission_run_record`."""
    run = mission_run_record(mission, scenario, run_id, start, bag_file_name)
    return recorded_prov_json(run, scenario)


def _action(record: GoalRecord, start_pose: Pose, start: dt.datetime, end: dt.datetime) -> Action:
    succeeded = record.outcome is GoalOutcome.SUCCEEDED
    return Action(
        ActionId(record.robot, record.task_number, record.subtask, record.waypoint),
        start_pose,
        record.pose,
        ActionStatus.SUCCEEDED if succeeded else ActionStatus.ABORTED,
        start,
        end,
        None if succeeded or record.outcome is GoalOutcome.ABORTED else record.outcome.value,
        record.attempts,
    )
