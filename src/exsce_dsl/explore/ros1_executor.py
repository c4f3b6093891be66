"""A campaign's scenarios run on a live ROS 1 graph (``exscec explore --executor ros1``).

:class:`Ros1Executor` runs each scenario as ``exscec execute --ros1 --stand-in`` does: the
scenario on the parameter server, each robot's waypoints sent as ``move_base`` goals by the
dispatcher node, ``rosbag record`` writing the run's bag (with its ``.prov.json`` and
``.rosparams``), and exsce's stand-in robots, started afresh for each run, serving the goals
with the faults planted.  Run ``i`` of a scenario executed with seed ``S`` drives as run ``i`` of
``exscec simulate --seed S``: the same campaign seed, the same stand-in runs.

:func:`ros1_executor` holds the graph for the whole campaign: the master at ``master_uri`` (else
``$ROS_MASTER_URI``), or a roscore it starts once and stops at the end (``start_master``, or
when no master is named at all: the stand-in needs nothing of the user's graph).

Only the stand-in is driven for now: a campaign runs each derived scenario from its own start
poses, which a real stack's robots (or its simulator) would have to be moved to between runs,
and exsce has no way yet to ask a stack for that.  A script that resets your simulator and
calls ``exscec execute --ros1`` is an ``--executor-command`` meanwhile.
"""

from __future__ import annotations

import os
import signal
import tempfile
import threading
from collections.abc import Iterator, Sequence
from contextlib import AbstractContextManager, ExitStack, contextmanager, nullcontext
from dataclasses import dataclass
from pathlib import Path

from exsce_dsl.errors import ExsceError
from exsce_dsl.execute import DEFAULT_SPEED_UP, LOGS, Interruption, execute_runs, start_stand_in
from exsce_dsl.execute import start_master as start_roscore
from exsce_dsl.model import Scenario
from exsce_dsl.remedies import FAULTS_NEED_THE_STAND_IN, STAND_IN_ONLY
from exsce_dsl.sim.faults import Fault


@dataclass(frozen=True)
class Ros1Executor:
    """Runs scenarios on the ROS 1 graph of ``master_uri`` against the stand-in robots, with
    ``faults`` planted in them, simulated time ``speed_up`` times faster than wall time."""

    master_uri: str
    faults: tuple[Fault, ...] = ()
    speed_up: float = DEFAULT_SPEED_UP

    def __post_init__(self) -> None:
        if not self.speed_up > 0:
            raise ExsceError(f"the stand-in's speed-up must be above 0, not {self.speed_up:g}")

    @property
    def name(self) -> str:
        """Where the runs were played and what was planted; not the master's address nor the
        speed-up, which give the same runs (simulated time)."""
        return stand_in_name("ros1", self.faults)

    def execute(
        self, scenario: Scenario, scenario_file: Path, out_dir: Path, runs: int, seed: int
    ) -> list[Path]:
        """``runs`` runs of ``scenario`` on the graph, each leaving the method's three files in
        ``out_dir`` (the logs of the nodes in its hidden ``.exsce-execute``).  Ctrl-C or SIGTERM
        cancels the goals and raises :class:`~exsce_dsl.errors.ExecutionInterrupted`."""
        logs = out_dir / LOGS / "stand-in"

        def around_run(run: int) -> AbstractContextManager[object]:
            return start_stand_in(
                scenario,
                self.master_uri,
                seed=seed,
                faults=self.faults,
                speed_up=self.speed_up,
                log_dir=logs,
                run=run,
            )

        main = threading.current_thread() is threading.main_thread()  # signals are the main thread's
        with Interruption() if main else nullcontext() as interruption:
            done = execute_runs(
                scenario, self.master_uri, out_dir, runs, None, interruption, around_run=around_run
            )
        return [run.files.bag for run in done]


def stand_in_name(graph: str, faults: Sequence[Fault]) -> str:
    """A live executor's name: its graph, the stand-in, and what was planted in it."""
    planted = " ".join(f"--fault {f.identity}" for f in faults)
    return f"{graph} --stand-in {planted}".strip()


@contextmanager
def ros1_executor(
    *,
    stand_in: bool,
    faults: Sequence[str] = (),
    speed_up: float = DEFAULT_SPEED_UP,
    master_uri: str | None = None,
    start_master: bool = False,
) -> Iterator[Ros1Executor]:
    """A :class:`Ros1Executor` for the block: on ``master_uri``, else ``$ROS_MASTER_URI``, else
    (or with ``start_master``) on a roscore started now and stopped when the block ends, also
    on an error or SIGTERM (which raises :class:`KeyboardInterrupt` meanwhile).  ``stand_in``
    must be True (see the module's docstring); ``faults`` as ``exscec simulate --fault``."""
    if faults and not stand_in:
        raise ExsceError(
            "the ros1 executor plants faults in exsce's stand-in robots", remedy=FAULTS_NEED_THE_STAND_IN
        )
    if not stand_in:
        raise ExsceError(
            "the ros1 executor drives exsce's stand-in robots only, for now", remedy=STAND_IN_ONLY
        )
    planted = tuple(Fault.parse(f) for f in faults)
    checked = Ros1Executor("unused", planted, speed_up)  # wrong options fail before a roscore starts
    with ExitStack() as stack:
        if threading.current_thread() is threading.main_thread():
            before = signal.signal(signal.SIGTERM, signal.default_int_handler)
            stack.callback(signal.signal, signal.SIGTERM, before)
        uri = master_uri or os.environ.get("ROS_MASTER_URI")
        if start_master or not uri:
            home = Path(stack.enter_context(tempfile.TemporaryDirectory(prefix="exsce-roscore-")))
            uri = stack.enter_context(start_roscore(home)).uri
        yield Ros1Executor(uri, checked.faults, checked.speed_up)
