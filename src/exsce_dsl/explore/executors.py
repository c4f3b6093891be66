"""Who runs a campaign's scenarios: the step of a campaign a user can replace.

An :class:`Executor` is given a scenario (and the ``.exsce`` file that declares it) and hands
back bags, one per run; the campaign ingests and judges them.  Three kinds:

- :class:`SimulatorExecutor`, the default: exsce's kinematic executor (``exscec simulate``),
  with the deliberate faults named on the command line (``--fault``), in this process or, given
  a Dask scheduler's address, one run per task on the cluster's workers (``exscec simulate
  --cluster``: the campaign's folder must then be the same path on every worker);
- :class:`CommandExecutor`: any program, run once per scenario with its arguments filled in
  (``{scenario_file} {scenario} {runs} {seed} {out}``), which writes the bags into ``{out}``:
  a user's own simulator, or a script that drives a real robot;
- a built-in executor chosen by its name (:data:`BUILT_IN_EXECUTORS`): ``ros1`` runs the
  scenarios on a live ROS 1 graph against exsce's stand-in robots, faults planted in them
  (:mod:`exsce_dsl.explore.ros1_executor`), ``ros2`` on a live ROS 2 graph against the Nav2
  stand-in robots (:mod:`exsce_dsl.explore.ros2_executor`);
- a plug-in: a package registers a factory under the entry-point group ``exsce.executors``
  (called with no arguments, it returns an Executor), chosen by its name; the plug-ins are
  read by :mod:`exsce_dsl.plugins` (a built-in is never replaced, a broken plug-in is left
  out with a warning).

A command and a plug-in run where the campaign runs, whether or not the campaign's bags are
analysed on a cluster (``exscec explore --cluster``): exsce does not know what they need.

A resumed campaign does not run a scenario again whose bags are all in its folder and in the
store already (a run's uuid follows from its bag's content), whichever executor made them.
"""

from __future__ import annotations

import shlex
import subprocess
from collections.abc import Callable, Sequence
from contextlib import AbstractContextManager, nullcontext
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol, runtime_checkable

from exsce_dsl.errors import ExsceError
from exsce_dsl.execute import DEFAULT_SPEED_UP
from exsce_dsl.explore.ros1_executor import ros1_executor
from exsce_dsl.explore.ros2_executor import ros2_executor
from exsce_dsl.model import Scenario
from exsce_dsl.plugins import Registry
from exsce_dsl.remedies import BUILT_IN_OPTIONS, ONE_EXECUTOR, ROS1_OPTIONS
from exsce_dsl.runs import is_bag
from exsce_dsl.sim.faults import Fault
from exsce_dsl.sim.run import simulate
from exsce_dsl.sim.simulators import KINEMATIC, Simulator, simulator_named
from exsce_dsl.suggest import did_you_mean

PLACEHOLDERS = ("scenario_file", "scenario", "runs", "seed", "out")


@runtime_checkable
class Executor(Protocol):
    """Runs scenarios and hands back their bags."""

    @property
    def name(self) -> str:
        """What executed the runs, as the campaign's provenance records it."""
        ...

    def execute(
        self, scenario: Scenario, scenario_file: Path, out_dir: Path, runs: int, seed: int
    ) -> list[Path]:
        """Run ``scenario`` ``runs`` times (``seed``: the same seed, the same runs where the
        executor can) and return the bags, one per run, written under ``out_dir``."""
        ...


@dataclass(frozen=True)
class SimulatorExecutor:
    """exsce's kinematic executor, in the method's convention unless the robots name another;
    with ``dask_address`` (a Dask scheduler's address), each run is played by one of its workers, which
    write the bags under ``out_dir``: the same path on every worker (a shared filesystem)."""

    faults: tuple[Fault, ...] = ()
    format: str = "ros1"
    dask_address: str | None = None
    simulator: Simulator = KINEMATIC

    @classmethod
    def with_faults(
        cls,
        faults: Sequence[str],
        format: str = "ros1",
        dask_address: str | None = None,
        simulator: Simulator = KINEMATIC,
    ) -> SimulatorExecutor:
        return cls(tuple(Fault.parse(f) for f in faults), format, dask_address, simulator)

    @property
    def name(self) -> str:
        """The simulator (unless the kinematic executor) and the faults, not where the runs were
        played: a cluster writes the same bags."""
        sim = self.simulator
        played = (
            ""
            if sim.name == KINEMATIC.name
            else " " + " ".join([sim.name] + [f"{k}={v}" for k, v in sim.settings.items()])
        )
        planted = " ".join(f"--fault {f.identity}" for f in self.faults)
        return f"simulator{played} {planted}".strip()

    def execute(
        self, scenario: Scenario, scenario_file: Path, out_dir: Path, runs: int, seed: int
    ) -> list[Path]:
        played = simulate(
            scenario, out_dir, runs, self.format, seed, self.faults, dask_address=self.dask_address,
            simulator=self.simulator,
        )  # fmt: skip
        return [run.bag for run in played]


@dataclass(frozen=True)
class CommandExecutor:
    """A program run once per scenario: ``my-sim --scenario {scenario_file} --runs {runs}
    --seed {seed} --out {out}``.  The command is split as a shell would (no shell runs it) and
    each placeholder is filled in; it must exit 0 and leave ``runs`` bags in ``{out}``."""

    command: str
    timeout: float | None = None

    def __post_init__(self) -> None:
        try:
            words = shlex.split(self.command)
        except ValueError as error:
            raise ExsceError(f"executor command '{self.command}': {error}") from None
        if not words:
            raise ExsceError("the executor command is empty")
        for word in words:
            try:
                word.format(**{p: "" for p in PLACEHOLDERS})
            except (KeyError, IndexError, ValueError) as error:
                raise ExsceError(
                    f"executor command '{self.command}': '{word}' is not a known placeholder or has a stray "
                    f"brace ({error}); the placeholders are {', '.join('{' + p + '}' for p in PLACEHOLDERS)}"
                ) from None

    @property
    def name(self) -> str:
        return f"command: {self.command}"

    def execute(
        self, scenario: Scenario, scenario_file: Path, out_dir: Path, runs: int, seed: int
    ) -> list[Path]:
        out_dir.mkdir(parents=True, exist_ok=True)
        values = {
            "scenario_file": str(scenario_file),
            "scenario": scenario.id,
            "runs": str(runs),
            "seed": str(seed),
            "out": str(out_dir),
        }
        arguments = [word.format(**values) for word in shlex.split(self.command)]
        try:
            done = subprocess.run(
                arguments, capture_output=True, text=True, timeout=self.timeout, check=False
            )
        except (OSError, subprocess.TimeoutExpired) as error:
            raise ExsceError(
                f"the executor command could not run scenario '{scenario.id}': {error}"
            ) from None
        if done.returncode != 0:
            said = (done.stderr or done.stdout).strip().splitlines()[-5:]
            raise ExsceError(
                f"the executor command exited {done.returncode} on scenario '{scenario.id}'"
                + (":\n  " + "\n  ".join(said) if said else "")
            )
        bags = bags_in(out_dir)
        if len(bags) != runs:
            raise ExsceError(
                f"the executor command left {len(bags)} bag(s) in {out_dir} for scenario '{scenario.id}', "
                f"not the {runs} asked for"
            )
        return bags


def bags_in(folder: Path) -> list[Path]:
    """The bags in ``folder``, by name: files of a bag reader's formats and rosbag2 folders (not
    the ``.prov.json`` or ``.rosparams`` beside them, nor a hidden folder of logs)."""
    return sorted(p for p in folder.iterdir() if is_bag(p))


@dataclass(frozen=True)
class ExecutorOptions:
    """What the command line says of a named executor besides its name: faults to plant, the
    stand-in, the ROS master (an address, or one to start), the stand-in's speed-up."""

    faults: tuple[str, ...] = ()
    stand_in: bool = False
    start_master: bool = False
    master_uri: str | None = None
    speed_up: float | None = None
    simulator: str = "kinematic"
    behaviour: str | None = None
    scans: str | None = None


@dataclass(frozen=True)
class NamedExecutor:
    """An executor chosen by ``name`` (a built-in or a plug-in): ``start(options)`` gives it for a
    block (what it runs on is started when the block begins and stopped when it ends);
    ``takes_options``: it reads :class:`ExecutorOptions` (a plug-in takes none)."""

    name: str
    summary: str
    start: Callable[[ExecutorOptions], AbstractContextManager[Executor]]
    takes_options: bool = True


def _ros1(options: ExecutorOptions) -> AbstractContextManager[Executor]:
    speed_up = DEFAULT_SPEED_UP if options.speed_up is None else options.speed_up
    return ros1_executor(
        stand_in=options.stand_in,
        faults=options.faults,
        speed_up=speed_up,
        master_uri=options.master_uri,
        start_master=options.start_master,
    )


def _ros2(options: ExecutorOptions) -> AbstractContextManager[Executor]:
    if options.start_master or options.master_uri:
        raise ExsceError("a ROS 2 graph has no master: a master of its own goes with the ros1 executor")
    speed_up = DEFAULT_SPEED_UP if options.speed_up is None else options.speed_up
    return ros2_executor(stand_in=options.stand_in, faults=options.faults, speed_up=speed_up)


BUILT_IN_EXECUTORS: dict[str, NamedExecutor] = {
    e.name: e
    for e in (
        NamedExecutor("ros1", "a live ROS 1 graph, exsce's stand-in robots serving the goals", _ros1),
        NamedExecutor("ros2", "a live ROS 2 graph, exsce's Nav2 stand-in robots serving the goals", _ros2),
    )
}
"""The executors exsce ships, chosen by name."""


def _plugin(name: str, loaded: object) -> NamedExecutor | None:
    """A plug-in's factory as a named executor; what it makes is checked when it is chosen."""
    if not callable(loaded):
        return None
    source = f"{getattr(loaded, '__module__', '?')}:{getattr(loaded, '__qualname__', loaded)}"
    where = f"the executor plug-in '{name}' ({source})"
    return NamedExecutor(name, "a plug-in", lambda _: nullcontext(_made(where, loaded)), takes_options=False)


def _made(where: str, factory: Callable[[], object]) -> Executor:
    try:
        made = factory()
    except Exception as error:  # a third party's package: say which, whatever went wrong
        raise ExsceError(f"{where} cannot be made: {error!r}") from None
    if not isinstance(made, Executor):
        raise ExsceError(f"{where} did not give an Executor")
    return made


EXECUTORS: Registry[NamedExecutor] = Registry(
    "executor", BUILT_IN_EXECUTORS.items(), _plugin, "an executor factory"
)
"""The executors chosen by name: the built-ins, then the plug-ins (:mod:`exsce_dsl.plugins`)."""


def named_executor(name: str, options: ExecutorOptions | None = None) -> AbstractContextManager[Executor]:
    """The executor called ``name`` for a block: a built-in one, else a plug-in (which takes
    none of ``options``)."""
    options = options or ExecutorOptions()
    known = EXECUTORS.entries()
    if name not in known:
        plugins = ", ".join(n for n in known if n not in BUILT_IN_EXECUTORS) or "none is installed"
        raise ExsceError(
            f"no executor '{name}'{did_you_mean(name, list(known))} "
            f"(built in: {', '.join(BUILT_IN_EXECUTORS)}; plug-ins registered: {plugins})"
        )
    chosen = known[name]
    if options != ExecutorOptions() and not chosen.takes_options:
        raise ExsceError(
            f"the executor '{name}' is a plug-in",
            remedy=BUILT_IN_OPTIONS,
            about=f"({', '.join(BUILT_IN_EXECUTORS)}), not the plug-in '{name}'",
        )
    return chosen.start(options)


def chosen_executor(
    command: str | None,
    name: str | None,
    options: ExecutorOptions,
    dask_address: str | None = None,
) -> AbstractContextManager[Executor]:
    """What plays a campaign's scenarios: another program (``command``), the executor called
    ``name``, else exsce's simulator with ``options.faults`` (on the Dask cluster at
    ``dask_address`` when given).  The options must go together."""
    simulated = options.simulator != KINEMATIC.name or options.behaviour or options.scans
    if command and (options.faults or name or simulated):
        raise ExsceError("a campaign's runs are played by one executor", remedy=ONE_EXECUTOR)
    if name and simulated:
        raise ExsceError(
            f"the executor '{name}' plays its own robots; a simulator is chosen for the campaigns "
            "exsce's simulators play"
        )
    if (options.stand_in or options.start_master or options.speed_up is not None) and not name:
        raise ExsceError("no executor was named", remedy=ROS1_OPTIONS)
    if command:
        return nullcontext(CommandExecutor(command))
    if name:
        return named_executor(name, options)
    simulator = simulator_named(options.simulator, options.behaviour, options.scans)
    return nullcontext(
        SimulatorExecutor.with_faults(options.faults, dask_address=dask_address, simulator=simulator)
    )
