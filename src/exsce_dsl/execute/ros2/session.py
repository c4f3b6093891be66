"""N runs of a scenario on a live ROS 2 graph, each leaving the method's files, as on ROS 1.

For each run (:func:`execute_runs_ros2`): the dispatcher node starts with the scenario as its
parameters and a ``NavigateToPose`` client per robot (a missing action server stops the run
before any bag exists); the recorder (:class:`~.recorder.Ros2Recorder`, a process of its own)
starts on the run's topics (:func:`~exsce_dsl.execute.recording.recorded_topics`) into the run's
hidden folder and returns once it is subscribed to each of them that has a publisher; the mission
core dispatches the schedule through the node; the run-time PROV is published on the PROV topic
(recorded) and written to ``.prov.json``; the recorder is stopped (the bag closed); the node's
parameters are written to ``.params.yaml``; then the files are moved into place, the bag folder
last.  Interrupted, the run goes to ``out/incomplete/`` (its PROV says cancelled), as on ROS 1.
"""

from __future__ import annotations

import datetime as dt
import uuid
from collections.abc import Callable
from contextlib import AbstractContextManager
from pathlib import Path

from exsce_dsl.execute.dispatcher import dispatch
from exsce_dsl.execute.mission import Schedule, schedule
from exsce_dsl.execute.provenance import mission_prov_json
from exsce_dsl.execute.recording import recorded_topics
from exsce_dsl.execute.ros1.session import LOGS, PROV_SETTLE, ExecutedRun, Options, placed, run_each
from exsce_dsl.execute.ros2.dispatcher_node import Ros2DispatcherNode
from exsce_dsl.execute.ros2.nav2 import nav2_actions
from exsce_dsl.execute.ros2.recorder import Ros2Recorder
from exsce_dsl.execute.run_files import RunFiles
from exsce_dsl.model import Scenario

CLOCK_WAIT = 10.0
"""Wall seconds the node may wait for its first time (simulated time: the first ``/clock``)."""


def execute_runs_ros2(
    scenario: Scenario,
    out: Path,
    runs: int = 1,
    options: Options | None = None,
    interrupted: Callable[[], bool] | None = None,
    around_run: Callable[[int], AbstractContextManager[object]] | None = None,
    use_sim_time: bool | None = None,
) -> list[ExecutedRun]:
    """Run ``scenario`` ``runs`` times on the ROS 2 graph of this process's environment; the runs'
    files in ``out``.  ``use_sim_time``: None decides by whether ``/clock`` has a publisher.  A
    run cut short by ``interrupted`` raises :class:`ExecutionInterrupted` (its files in
    ``out/incomplete``); ``around_run(i)``, when given, is entered before run ``i`` starts and
    left after it ended: the stand-in robots of that run, say."""
    options = options or Options()
    (out / LOGS).mkdir(parents=True, exist_ok=True)
    plan = schedule(scenario, options.speeds, options.timeout)
    robots = {g.robot for g in plan.goals}
    actions = {r.id: nav2_actions(r).navigate_to_pose for r in scenario.robots if r.id in robots}
    return run_each(
        runs,
        interrupted,
        around_run,
        lambda: _one_run(scenario, out, plan, actions, options, interrupted, use_sim_time),
    )


def _one_run(
    scenario: Scenario,
    out: Path,
    plan: Schedule,
    actions: dict[str, str],
    options: Options,
    interrupted: Callable[[], bool] | None,
    use_sim_time: bool | None,
) -> ExecutedRun:
    run_id = str(uuid.uuid4())
    start = dt.datetime.now(dt.UTC)
    files = RunFiles.of(out, scenario.id, run_id, start, ros2=True)
    staged = files.staged()
    try:
        with Ros2DispatcherNode(scenario, run_id, actions, use_sim_time) as node:
            node.wait_for_servers(options.server_timeout)
            node.wait_for_clock(CLOCK_WAIT)
            log = out / LOGS / f"record-{run_id[:8]}.log"
            topics = recorded_topics(scenario)
            with Ros2Recorder(staged.bag, topics, node.use_sim_time, log=log) as recorder:
                recorder.wait_subscribed(options.server_timeout, node.published(topics))
                navigator = node.navigator()
                try:
                    mission = dispatch(plan, navigator, node.clock, options.policy, interrupted)
                except BaseException:
                    navigator.cancel_active()  # no robot drives on after we stop
                    raise
                prov = mission_prov_json(mission, scenario, run_id, start, files.bag.name)
                staged.prov.write_text(prov, encoding="utf-8")
                node.publish(prov)
                node.spin_for(PROV_SETTLE)
                recorder.stop()
            node.dump_parameters(staged.rosparams)
    except BaseException:
        files.discard_staged()
        raise
    return placed(run_id, files, staged, mission, out)
