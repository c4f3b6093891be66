"""A run's execution, as its dispatcher recorded it, stored with the run that ingestion made.

The run-time PROV (:mod:`exsce_dsl.prov.recorder`: ``exscec simulate``, ``exscec execute``, the
stand-in) names the run after the dispatcher's uuid, ``run:run_<D>``; ingestion names it after
the bag's content, ``run:run_<R>``, so that re-ingesting a bag finds its run and two different
recordings never share an id (one execution may be recorded twice, a bag may be cut or
filtered).  The two are tied here instead of merged: :func:`read_execution` reads the run-time
PROV (PROV-JSON, ours) back into an :class:`~exsce_dsl.model.executions.Execution`, and
:func:`write_execution` writes the bundle ``R:execution_bundle``:

* the execution activity ``run:run_<D>`` (``prov:type=exsce:execution``, ``exsce:dispatched_run``
  the dispatcher's uuid, ``exsce:run_time_prov`` where it was read, ``exsce:mission_status``
  when the mission did not complete, the dispatcher's start and end time), which used the
  scenario ``exsce:<scenario>`` and generated the bag as the dispatcher named it, ``D:<bag file>``;
* ``prov:alternateOf`` between the ingested run's bag ``R:<bag file>`` and ``D:<bag file>``: one
  recording, seen by the recorder and by ingestion (the link the query library follows);
* one activity ``D:<robot>-task_NN-subtask_NNN-w_NNN`` per goal sent
  (``prov:type=exsce:dispatched_goal``, ``exsce:robot``, ``exsce:status``, ``exsce:goal_outcome``,
  ``exsce:attempts``, times), informed by the execution, associated with the robot's agent,
  started by its start pose and ended by its goal pose (``prov:role="goal"``).

The goals' and the execution's IRIs are those of the ``.prov.json``, so either file's names find
them in the store.  The goals are not ``exsce:action``: the run's actions are what ingestion found
in the bag, and no query of actions counts a goal twice.
"""

from __future__ import annotations

import datetime as dt
import json
import re
from collections.abc import Iterator, Mapping
from typing import Any

from prov.constants import PROV_ROLE, PROV_TYPE

from exsce_dsl.model.executions import DispatchedGoal, Execution, SimulatorInfo
from exsce_dsl.model.runs import Run
from exsce_dsl.prov import identifiers as ids
from exsce_dsl.prov.records import Attributes, BundleWriter, DocumentWriter

__all__ = ["parse_document", "read_execution", "write_execution", "write_simulator"]

_ACTION = re.compile(r"^(?P<robot>.+)-task_\d+-subtask_\d+-w_\d+$")
_RUN_TYPE = "exsce:run"
_ACTION_TYPE = "exsce:action"


def read_execution(document: object, source: str, scenario: str) -> Execution | None:
    """The execution in a run-time PROV ``document`` (PROV-JSON, parsed), read from ``source``;
    None when it holds no run, or a run of another scenario than ``scenario`` (a run that names
    no scenario, as the method's own recorder writes it, is taken as one of ``scenario``)."""
    if not isinstance(document, Mapping):
        return None
    for bundle in _bundles(document):
        activities = _records(bundle, "activity")
        runs = [
            (k, v)
            for k, v in activities.items()
            if _type(v) == _RUN_TYPE and isinstance(v.get("exsce:run"), str)
        ]
        if len(runs) != 1:
            continue
        run_name, run = runs[0]
        used = {
            str(u.get("prov:entity"))
            for u in _records(bundle, "used").values()
            if u.get("prov:activity") == run_name
        }
        scenarios = {u for u in used if u.startswith("exsce:")}  # the method's recorder names none
        if scenarios and f"exsce:{scenario}" not in scenarios:
            continue
        bags = [g.get("prov:entity") for g in _records(bundle, "wasGeneratedBy").values()
                if g.get("prov:activity") == run_name]  # fmt: skip
        return Execution(
            run_id=str(run["exsce:run"]),
            source=source,
            bag_name=_local(bags[0]) if bags and isinstance(bags[0], str) else None,
            start=_time(run.get("prov:startTime")),
            end=_time(run.get("prov:endTime")),
            mission_status=_text(run.get("exsce:mission_status")),
            goals=tuple(_goals(bundle, activities)),
            simulator=_simulator(bundle, run_name),
        )
    return None


def _simulator(bundle: Mapping[str, Any], run_name: str) -> SimulatorInfo | None:
    """The software agent the run was associated with that names a simulator (None: none)."""
    agents = _records(bundle, "agent")
    for association in _records(bundle, "wasAssociatedWith").values():
        if association.get("prov:activity") != run_name:
            continue
        facts = agents.get(str(association.get("prov:agent")))
        name = _text(facts.get("exsce:simulator")) if isinstance(facts, Mapping) else None
        if name is None or not isinstance(facts, Mapping):
            continue
        said = _text(facts.get("exsce:simulator_settings")) or ""
        pairs = tuple(
            (k.strip(), v.strip()) for k, _, v in (p.partition("=") for p in said.split(";")) if k.strip()
        )
        return SimulatorInfo(name, _text(facts.get("exsce:simulator_version")) or "", pairs)
    return None


def write_simulator(w: BundleWriter, agent: Any, activity: Any, simulator: SimulatorInfo) -> None:
    """``agent``, the software that played the run, and ``wasAssociatedWith(activity, agent)``."""
    t = w.term
    w.agent(
        agent,
        {
            PROV_TYPE: t(ids.PROV_SOFTWARE_AGENT),
            t(ids.SIMULATOR): simulator.name,
            t(ids.SIMULATOR_VERSION): simulator.version,
            t(ids.SIMULATOR_SETTINGS): "; ".join(f"{k}={v}" for k, v in simulator.settings),
        },
    )
    w.associated(activity, agent)


def _goals(bundle: Mapping[str, Any], activities: Mapping[str, Any]) -> Iterator[DispatchedGoal]:
    ends = _triggers(bundle, "wasEndedBy")
    starts = _triggers(bundle, "wasStartedBy")
    for key, facts in sorted(
        activities.items(), key=lambda kv: (_time(kv[1].get("prov:startTime")) is None, kv[0])
    ):
        name = _local(key)
        found = _ACTION.match(name)
        if _type(facts) != _ACTION_TYPE or found is None:
            continue
        attempts = facts.get("exsce:attempts", 1)
        yield DispatchedGoal(
            name=name,
            robot=found["robot"],
            goal_pose=ends.get(key),
            start_pose=starts.get(key),
            status=_text(facts.get("exsce:status")) or "SUCCEEDED",
            outcome=_text(facts.get("exsce:goal_outcome")),
            attempts=int(_text(attempts) or 1),
            start=_time(facts.get("prov:startTime")),
            end=_time(facts.get("prov:endTime")),
        )


def write_execution(
    writer: DocumentWriter, run: Run, bag: str, robot_names: Mapping[str, str]
) -> None:
    """The bundle of ``run``'s execution (none when the run has no run-time PROV); ``bag``: the
    local name of the ingested run's bag entity in the run's namespace; ``robot_names``: each
    robot id's local name in ``robot:`` (:func:`~exsce_dsl.prov.identifiers.robot_name`)."""
    execution = run.execution
    if execution is None:
        return
    names = writer.names
    run_parts = writer.element_namespace(ids.run_prefix(run.uuid), names.of_run(run.uuid), "run")
    w = writer.bundle(run_parts[ids.EXECUTION_BUNDLE], "the bundle of the run's execution")
    t = w.term
    dispatched = w.of_element(ids.run_prefix(execution.run_id), names.of_run(execution.run_id), "run")
    activity = w.fixed(ids.RUN)[ids.run_local_name(execution.run_id)]
    writer.claim(activity, f"the execution of run {run.uuid}")
    facts: Attributes = {
        PROV_TYPE: t(ids.EXECUTION_TYPE),
        t(ids.DISPATCHED_RUN): execution.run_id,
        t(ids.RUN_TIME_PROV): execution.source,
    }
    if execution.mission_status is not None:
        facts[t(ids.MISSION_STATUS)] = execution.mission_status
    w.activity(activity, facts, execution.start, execution.end)
    w.used(activity, w.fixed(ids.EXSCE)[run.scenario])
    if execution.simulator is not None:
        write_simulator(w, dispatched[ids.SIMULATOR_AGENT], activity, execution.simulator)
    recorded = dispatched[execution.bag_name or bag]
    w.entity(recorded, {})
    w.generated(recorded, activity)
    w.alternate(w.of_element(ids.run_prefix(run.uuid), names.of_run(run.uuid), "run")[bag], recorded)
    pose_ns, status, goal_role = w.fixed(ids.POSE), t(ids.STATUS), {PROV_ROLE: ids.GOAL_ROLE}
    for goal in execution.goals:
        goal_id = dispatched[goal.name]
        writer.claim(goal_id, f"goal {goal.name} of the execution")
        goal_facts: Attributes = {
            PROV_TYPE: t(ids.DISPATCHED_GOAL_TYPE),
            t(ids.ROBOT_ATTR): goal.robot,
            status: goal.status,
        }
        if goal.outcome is not None:
            goal_facts[t(ids.GOAL_OUTCOME)] = goal.outcome
        if goal.attempts > 1:
            goal_facts[t(ids.ATTEMPTS)] = goal.attempts
        w.activity(goal_id, goal_facts, goal.start, goal.end)
        w.informed(goal_id, activity)
        robot_key = robot_names.get(goal.robot, goal.robot)
        robot_parts = w.of_element(goal.robot, names.of_robot(robot_key), "robot")
        w.associated(goal_id, robot_parts[ids.ROBOT_AGENT])
        if goal.start_pose is not None:
            w.started(goal_id, pose_ns[goal.start_pose])
        if goal.goal_pose is not None:
            w.ended(goal_id, pose_ns[goal.goal_pose], attributes=goal_role)


# -- reading PROV-JSON ---------------------------------------------------------------------


def _bundles(document: Mapping[str, Any]) -> Iterator[Mapping[str, Any]]:
    yield document
    for bundle in (document.get("bundle") or {}).values():
        if isinstance(bundle, Mapping):
            yield bundle


def _records(bundle: Mapping[str, Any], kind: str) -> dict[str, Any]:
    found = bundle.get(kind)
    return {k: v for k, v in found.items() if isinstance(v, Mapping)} if isinstance(found, Mapping) else {}


def _triggers(bundle: Mapping[str, Any], kind: str) -> dict[str, str]:
    """Activity → the local name of the pose that started (ended) it."""
    return {
        str(r["prov:activity"]): _local(str(r["prov:trigger"]))
        for r in _records(bundle, kind).values()
        if isinstance(r.get("prov:trigger"), str) and str(r["prov:trigger"]).startswith("pose:")
    }


def _type(facts: Mapping[str, Any]) -> str | None:
    return _text(facts.get("prov:type"))


def _text(value: object) -> str | None:
    if isinstance(value, Mapping):
        value = value.get("$")
    return None if value is None else str(value)


def _local(qualified: str) -> str:
    return qualified.split(":", 1)[1] if ":" in qualified else qualified


def _time(value: object) -> dt.datetime | None:
    text = _text(value)
    if text is None:
        return None
    try:
        return dt.datetime.fromisoformat(text)
    except ValueError:
        return None


def parse_document(text: str) -> object:
    """A PROV-JSON text as Python values; None when it is not JSON."""
    try:
        return json.loads(text)
    except ValueError:
        return None
