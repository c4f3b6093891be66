"""``exscec execute --ros1|--ros2``: a scenario's mission on a live ROS graph, as Python functions."""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Sequence
from pathlib import Path

from exsce_dsl.errors import ExsceError
from exsce_dsl.execute import (
    DEFAULT_POLICY,
    DEFAULT_SERVER_TIMEOUT,
    DEFAULT_SPEED_UP,
    LOGS,
    ExecutedRun,
    Interruption,
    Options,
    Policy,
    Ros2StandIn,
    execute_runs,
    execute_runs_ros2,
    start_stand_in,
)
from exsce_dsl.execute import master_uri as environment_master_uri
from exsce_dsl.execute import start_master as start_roscore
from exsce_dsl.model import Scenario
from exsce_dsl.model.document import Specification
from exsce_dsl.remedies import STAND_IN_FOR_FAULTS
from exsce_dsl.sim.faults import Fault

__all__ = ["ExecutedRun", "Policy", "execute_ros1", "execute_ros2"]


def execute_ros1(
    spec: Specification | Scenario,
    out_dir: str | Path,
    runs: int = 1,
    *,
    scenario: str | None = None,
    master_uri: str | None = None,
    start_master: bool = False,
    policy: Policy | str = DEFAULT_POLICY,
    server_timeout: float = DEFAULT_SERVER_TIMEOUT,
    timeout: float | None = None,
    interrupted: Callable[[], bool] | None = None,
    stand_in: bool = False,
    seed: int = 0,
    faults: Sequence[str] = (),
    speed_up: float = DEFAULT_SPEED_UP,
) -> list[ExecutedRun]:
    """``exscec execute --ros1``: run the scenario's mission ``runs`` times on a live ROS 1 graph
    (``master_uri``, else ``$ROS_MASTER_URI``; ``start_master``: a roscore of our own, stopped at
    the end), each run leaving ``<date>_<scenario>_run-<id>.bag``, ``.prov.json`` and
    ``.rosparams`` in ``out_dir``.  Failed goals go to ``policy`` (``skip-waypoint``,
    ``retry-once``, ``skip-task``, ``stop-mission``); ``timeout`` (ROS seconds) is the timeout of
    the goals whose task and mission give none (else one from the distance and speed limit).
    Ctrl-C and SIGTERM (or ``interrupted()`` saying yes, when given) cancel the goals and raise
    :class:`~exsce_dsl.errors.ExecutionInterrupted`, the run cut short kept in
    ``out_dir/incomplete``.  A missing action server is a
    :class:`~exsce_dsl.errors.RosGraphError` naming it, after ``server_timeout`` wall seconds.

    ``stand_in``: exsce's stand-in robots (``exscec stand-in``) serve the goals, started afresh
    for each run on simulated time ``speed_up`` times faster than wall time, run ``i`` driving as
    run ``i`` of ``exscec simulate --seed SEED`` does, with ``faults`` as on the command line."""
    chosen, out, options, planted = _prepared(
        spec, scenario, out_dir, (policy, server_timeout, timeout), stand_in, faults, seed
    )
    with contextlib.ExitStack() as stack:
        if interrupted is None:
            interrupted = stack.enter_context(Interruption())
        if start_master:
            uri = stack.enter_context(start_roscore(out / LOGS / "ros")).uri
        else:
            uri = master_uri or environment_master_uri()
        around_run = None
        if stand_in:

            def around_run(run: int) -> contextlib.AbstractContextManager[object]:
                logs = out / LOGS / "stand-in"
                return start_stand_in(
                    chosen, uri, seed=seed, faults=planted, speed_up=speed_up, log_dir=logs, run=run
                )

        return execute_runs(chosen, uri, out, runs, options, interrupted, around_run)


def execute_ros2(
    spec: Specification | Scenario,
    out_dir: str | Path,
    runs: int = 1,
    *,
    scenario: str | None = None,
    policy: Policy | str = DEFAULT_POLICY,
    server_timeout: float = DEFAULT_SERVER_TIMEOUT,
    timeout: float | None = None,
    interrupted: Callable[[], bool] | None = None,
    stand_in: bool = False,
    seed: int = 0,
    faults: Sequence[str] = (),
    speed_up: float = DEFAULT_SPEED_UP,
    use_sim_time: bool | None = None,
) -> list[ExecutedRun]:
    """``exscec execute --ros2``: run the scenario's mission ``runs`` times on the live ROS 2 graph
    of this process's environment (``ROS_DOMAIN_ID``) through each robot's Nav2
    (``NavigateToPose``), each run leaving the rosbag2 MCAP folder ``<date>_<scenario>_run-<id>``,
    ``.prov.json`` and ``.params.yaml`` in ``out_dir``.  ``use_sim_time``: None uses ``/clock``
    when something publishes it.  Policies, timeouts, interruption and a missing action server
    as :func:`execute_ros1`; ``stand_in``: exsce's Nav2 stand-in robots (``exscec stand-in
    --ros2``) serve the goals, started afresh for each run in this process, with ``faults``."""
    chosen, out, options, planted = _prepared(
        spec, scenario, out_dir, (policy, server_timeout, timeout), stand_in, faults, seed
    )
    with contextlib.ExitStack() as stack:
        if interrupted is None:
            interrupted = stack.enter_context(Interruption())
        around_run = None
        if stand_in:

            def around_run(run: int) -> contextlib.AbstractContextManager[object]:
                return Ros2StandIn(chosen, seed=seed, faults=planted, speed_up=speed_up, run=run)

        return execute_runs_ros2(chosen, out, runs, options, interrupted, around_run, use_sim_time)


def _prepared(
    spec: Specification | Scenario,
    scenario: str | None,
    out_dir: str | Path,
    how: tuple[Policy | str, float, float | None],
    stand_in: bool,
    faults: Sequence[str],
    seed: int,
) -> tuple[Scenario, Path, Options, tuple[Fault, ...]]:
    """What either graph's execution starts from: the scenario, the output folder, the options
    (``how``: policy, server timeout, goal timeout) and the faults, checked before anything runs."""
    chosen = spec if isinstance(spec, Scenario) else spec.scenario(scenario)
    policy, server_timeout, timeout = how
    if not stand_in and (faults or seed):
        raise ExsceError("faults and a seed are the stand-in's", remedy=STAND_IN_FOR_FAULTS)
    return (
        chosen,
        Path(out_dir),
        Options(Policy(policy), server_timeout, timeout),
        tuple(Fault.parse(f) for f in faults),
    )
