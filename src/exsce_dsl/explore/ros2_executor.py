"""A campaign's scenarios run on a live ROS 2 graph (``exscec explore --executor ros2``).

:class:`Ros2Executor` runs each scenario as ``exscec execute --ros2 --stand-in`` does: the
dispatcher node sending each robot's waypoints as Nav2 ``NavigateToPose`` goals, exsce's recorder
writing the run's rosbag2 MCAP folder (with its ``.prov.json`` and ``.params.yaml``), and exsce's
Nav2 stand-in robots, started afresh for each run in this process, serving the goals with the
faults planted.  Run ``i`` of a scenario executed with seed ``S`` drives as run ``i`` of
``exscec simulate --seed S``.  The graph is the domain of this process's environment
(``ROS_DOMAIN_ID``).  Only the stand-in is driven, for the reason :mod:`.ros1_executor` gives.
"""

from __future__ import annotations

import signal
import threading
from collections.abc import Iterator, Sequence
from contextlib import AbstractContextManager, ExitStack, contextmanager, nullcontext
from dataclasses import dataclass
from pathlib import Path

from exsce_dsl.errors import ExsceError
from exsce_dsl.execute import DEFAULT_SPEED_UP, Interruption, Ros2StandIn, execute_runs_ros2
from exsce_dsl.explore.ros1_executor import stand_in_name
from exsce_dsl.model import Scenario
from exsce_dsl.remedies import FAULTS_NEED_THE_STAND_IN, STAND_IN_ONLY
from exsce_dsl.sim.faults import Fault


@dataclass(frozen=True)
class Ros2Executor:
    """Runs scenarios on this process's ROS 2 graph against the stand-in robots, with ``faults``
    planted in them, simulated time ``speed_up`` times faster than wall time."""

    faults: tuple[Fault, ...] = ()
    speed_up: float = DEFAULT_SPEED_UP

    def __post_init__(self) -> None:
        if not self.speed_up > 0:
            raise ExsceError(f"the stand-in's speed-up must be above 0, not {self.speed_up:g}")

    @property
    def name(self) -> str:
        """Where the runs were played and what was planted (not the speed-up: simulated time)."""
        return stand_in_name("ros2", self.faults)

    def execute(
        self, scenario: Scenario, scenario_file: Path, out_dir: Path, runs: int, seed: int
    ) -> list[Path]:
        """``runs`` runs of ``scenario`` on the graph, each leaving its bag folder, ``.prov.json``
        and ``.params.yaml`` in ``out_dir``.  Ctrl-C or SIGTERM cancels the goals and raises
        :class:`~exsce_dsl.errors.ExecutionInterrupted`."""

        def around_run(run: int) -> AbstractContextManager[object]:
            return Ros2StandIn(scenario, seed=seed, faults=self.faults, speed_up=self.speed_up, run=run)

        main = threading.current_thread() is threading.main_thread()  # signals are the main thread's
        with Interruption() if main else nullcontext() as interruption:
            done = execute_runs_ros2(scenario, out_dir, runs, None, interruption, around_run, True)
        return [run.files.bag for run in done]


@contextmanager
def ros2_executor(
    *, stand_in: bool, faults: Sequence[str] = (), speed_up: float = DEFAULT_SPEED_UP
) -> Iterator[Ros2Executor]:
    """A :class:`Ros2Executor` for the block (SIGTERM raises :class:`KeyboardInterrupt` meanwhile);
    ``stand_in`` must be True; ``faults`` as ``exscec simulate --fault``."""
    if faults and not stand_in:
        raise ExsceError(
            "the ros2 executor plants faults in exsce's stand-in robots", remedy=FAULTS_NEED_THE_STAND_IN
        )
    if not stand_in:
        raise ExsceError(
            "the ros2 executor drives exsce's stand-in robots only, for now", remedy=STAND_IN_ONLY
        )
    executor = Ros2Executor(tuple(Fault.parse(f) for f in faults), speed_up)
    with ExitStack() as stack:
        if threading.current_thread() is threading.main_thread():
            before = signal.signal(signal.SIGTERM, signal.default_int_handler)
            stack.callback(signal.signal, signal.SIGTERM, before)
        yield executor
