"""What the method's run recorder writes while a run goes on: task executions and actions, no metrics.

Both executors write it beside their bag as ``<bag name>.prov.json``: the kinematic executor
(:mod:`exsce_dsl.sim.run`) and the mission dispatcher on a live robot stack
(:mod:`exsce_dsl.execute.provenance`).  Each turns what it played into :class:`Action` records;
the grouping into task executions, the run and its PROV-JSON text are the same for both.
"""

from __future__ import annotations

import datetime as dt
from collections.abc import Iterable

from exsce_dsl.model import Scenario
from exsce_dsl.model.runs import Action, Bag, Run, RunStatus, TaskExecution
from exsce_dsl.prov.run import compile_run
from exsce_dsl.prov.serialize import serialize_prov

__all__ = ["recorded_prov_json", "recorded_run"]


def recorded_run(
    run_id: str,
    scenario: str,
    start: dt.datetime,
    end: dt.datetime,
    bag_file_name: str,
    actions: Iterable[Action],
    status: RunStatus = RunStatus.COMPLETED,
) -> Run:
    """The run ``run_id`` of ``scenario`` as its recorder saw it: ``actions`` grouped into one task
    execution per (robot, allocation entry), in the order of each group's first action."""
    grouped: dict[tuple[str, int], list[Action]] = {}
    for action in actions:
        grouped.setdefault((action.id.robot, action.id.allocation), []).append(action)
    tasks = tuple(TaskExecution(robot, n, tuple(acts)) for (robot, n), acts in grouped.items())
    return Run(run_id, scenario, start, end, Bag(bag_file_name), tasks, status=status)


def recorded_prov_json(run: Run, scenario: Scenario) -> str:
    """The PROV-JSON text of a recorded ``run`` of ``scenario`` (its ``.prov.json``)."""
    return serialize_prov(compile_run(run, scenario), "json")
