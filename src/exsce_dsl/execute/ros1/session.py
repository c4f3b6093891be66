"""N runs of a scenario on a live ROS 1 graph, each leaving the method's three files.

For each run: the scenario goes on the parameter server; the dispatcher node starts (one per
run, before the recording: a missing action server stops the run before any bag exists, and
the PROV latched for one run never reaches the next one's bag); ``rosbag record`` starts on the
run's topics (:func:`~exsce_dsl.execute.recording.recorded_topics`) into the run's hidden
folder and returns once it receives them; the mission core dispatches the schedule through the
node; the run-time PROV is published on the PROV topic (recorded) and written to
``.prov.json``; the recorder is stopped (the bag closed); the parameters are dumped to
``.rosparams``; then the three files are moved into place, the bag last.

Interrupted (``interrupted()`` says yes: Ctrl-C or SIGTERM, see :class:`Interruption`): the
active goals are cancelled, the recording is closed, and the run's files go to
``out/incomplete/`` under the method's names (the PROV says the mission was cancelled), never
beside the whole runs; then :class:`~exsce_dsl.errors.ExecutionInterrupted` is raised.
"""

from __future__ import annotations

import datetime as dt
import os
import signal
import time
import uuid
from collections.abc import Callable, Mapping
from contextlib import AbstractContextManager, ExitStack, nullcontext
from dataclasses import dataclass
from pathlib import Path
from types import FrameType, TracebackType

from exsce_dsl.errors import ExecutionInterrupted
from exsce_dsl.execute.dispatcher import dispatch
from exsce_dsl.execute.mission import Schedule, schedule
from exsce_dsl.execute.outcomes import DEFAULT_POLICY, MissionRun, MissionStatus, Policy
from exsce_dsl.execute.provenance import mission_prov_json
from exsce_dsl.execute.recording import recorded_topics
from exsce_dsl.execute.ros1.graph import Master
from exsce_dsl.execute.ros1.navigator import DispatcherNode, Ros1Navigator, RosClock, move_base_actions
from exsce_dsl.execute.ros1.parameters import dump_parameters, load_scenario
from exsce_dsl.execute.ros1.recorder import Recorder
from exsce_dsl.execute.run_files import RunFiles
from exsce_dsl.model import Scenario
from exsce_dsl.runs import PROV_TOPIC

INCOMPLETE = "incomplete"
"""The folder of ``out`` that holds the runs cut short."""
LOGS = ".exsce-execute"
"""The hidden folder of ``out`` that holds the logs of the nodes and recorders."""
PROV_SETTLE = 0.5
"""Wall seconds between publishing the PROV and stopping the recorder (the message on its way)."""
DEFAULT_SERVER_TIMEOUT = 10.0


@dataclass(frozen=True)
class ExecutedRun:
    """One run: its files (in ``out``, or ``out/incomplete`` when cut short) and its mission."""

    run_id: str
    files: RunFiles
    mission: MissionRun

    @property
    def complete(self) -> bool:
        return self.mission.status is not MissionStatus.CANCELLED


@dataclass(frozen=True)
class Options:
    """How to run: the policy for failed goals, how long to wait for the action servers (wall
    seconds), a goal timeout replacing the default ones (ROS seconds), robots' speed limits."""

    policy: Policy = DEFAULT_POLICY
    server_timeout: float = DEFAULT_SERVER_TIMEOUT
    timeout: float | None = None
    speeds: Mapping[str, float] | None = None


class Interruption:
    """While the block runs, SIGINT and SIGTERM set a flag instead of ending the process (the
    handlers before are put back after); call the object to read the flag."""

    SIGNALS = (signal.SIGINT, signal.SIGTERM)

    def __init__(self) -> None:
        self.signal: int | None = None
        self._before: dict[int, object] = {}

    def __call__(self) -> bool:
        return self.signal is not None

    def _heard(self, number: int, frame: FrameType | None) -> None:
        self.signal = number

    def __enter__(self) -> Interruption:
        for number in self.SIGNALS:
            self._before[number] = signal.signal(number, self._heard)
        return self

    def __exit__(
        self, kind: type[BaseException] | None, error: BaseException | None, tb: TracebackType | None
    ) -> None:
        for number, handler in self._before.items():
            signal.signal(number, handler)  # type: ignore[arg-type]


def execute_runs(
    scenario: Scenario,
    master_uri: str,
    out: Path,
    runs: int = 1,
    options: Options | None = None,
    interrupted: Callable[[], bool] | None = None,
    around_run: Callable[[int], AbstractContextManager[object]] | None = None,
) -> list[ExecutedRun]:
    """Run ``scenario`` ``runs`` times on the graph of ``master_uri``; the runs' files in ``out``.
    A run cut short by ``interrupted`` raises :class:`ExecutionInterrupted` (its files in
    ``out/incomplete``); the runs before it are whole, in ``out``.  ``around_run(i)``, when given,
    is entered before run ``i`` (from 0) starts and left after it ended: the stand-in robots of
    that run, say."""
    options = options or Options()
    master = Master(master_uri)
    master.wait(5.0)
    logs = out / LOGS
    logs.mkdir(parents=True, exist_ok=True)
    plan = schedule(scenario, options.speeds, options.timeout)
    move_base_actions(scenario)  # a robot ROS 1 cannot send goals to: before anything starts
    return run_each(
        runs, interrupted, around_run, lambda: _one_run(scenario, master, out, plan, options, interrupted)
    )


def run_each(
    runs: int,
    interrupted: Callable[[], bool] | None,
    around_run: Callable[[int], AbstractContextManager[object]] | None,
    one_run: Callable[[], ExecutedRun],
) -> list[ExecutedRun]:
    """``runs`` runs of ``one_run``, each inside ``around_run(i)`` when given; a run cut short
    (or an interruption between two) raises :class:`ExecutionInterrupted`, the whole runs before
    it named.  The loop of either graph's session."""
    done: list[ExecutedRun] = []
    for _ in range(runs):
        if interrupted is not None and interrupted():
            raise ExecutionInterrupted(None, [r.files.bag for r in done])
        with around_run(len(done)) if around_run is not None else nullcontext():
            run = one_run()
        done.append(run)
        if not run.complete:
            raise ExecutionInterrupted(run.files.bag, [r.files.bag for r in done[:-1]])
    return done


def placed(run_id: str, files: RunFiles, staged: RunFiles, mission: MissionRun, out: Path) -> ExecutedRun:
    """The run's staged files moved into place, or into ``out/incomplete`` when it was cut short."""
    if mission.status is MissionStatus.CANCELLED:
        kept = RunFiles(out / INCOMPLETE, files.name, files.ros2)
        kept.folder.mkdir(parents=True, exist_ok=True)
        for source, target in zip(staged.all(), kept.all(), strict=True):
            if source.exists():
                os.replace(source, target)
        files.discard_staged()
        return ExecutedRun(run_id, kept, mission)
    files.put_in_place()
    return ExecutedRun(run_id, files, mission)


def _one_run(
    scenario: Scenario,
    master: Master,
    out: Path,
    plan: Schedule,
    options: Options,
    interrupted: Callable[[], bool] | None,
) -> ExecutedRun:
    run_id = str(uuid.uuid4())
    start = dt.datetime.now(dt.UTC)
    files = RunFiles.of(out, scenario.id, run_id, start)
    staged = files.staged()
    try:
        load_scenario(master, scenario)
        with ExitStack() as stack:
            # a node per run: its latched PROV must not reach the next run's bag
            logs = out / LOGS
            actions = move_base_actions(scenario)
            node = DispatcherNode(
                actions, master.uri, logs / f"dispatcher-{run_id[:8]}.log", options.server_timeout, PROV_TOPIC
            )
            stack.callback(node.close)
            bag, log = staged.bag, logs / f"record-{run_id[:8]}.log"
            recorder = stack.enter_context(Recorder(master.uri, recorded_topics(scenario), bag, log))
            recorder.start()
            navigator = Ros1Navigator(node, interrupted)
            mission = dispatch(plan, navigator, RosClock(node), options.policy, interrupted)
            prov = mission_prov_json(mission, scenario, run_id, start, files.bag.name)
            staged.prov.write_text(prov, encoding="utf-8")
            node.publish(prov)
            time.sleep(PROV_SETTLE)
            recorder.stop()
        dump_parameters(master, staged.rosparams)
    except BaseException:
        files.discard_staged()
        raise
    return placed(run_id, files, staged, mission, out)
