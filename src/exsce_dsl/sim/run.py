"""``simulate``: scenario in, bag files out (one per run), deterministic per seed.

Each run is played by :func:`play_run` from what every run of the call shares (:class:`RunPlan`)
and its index: the run's seed, start, id and bag name follow from those alone, so a run gives the
same bytes wherever it is played.  :func:`simulate` plays the runs one after the other in this
process, or each as one task on a Dask cluster's workers (``exscec simulate --cluster``), which
write the bags into the output folder themselves: that folder must be the same path on every
worker (a shared filesystem), as must the map files the scenario names.  A bag is written in a
hidden folder beside its place and moved there when it is whole, so a worker killed half-way
leaves no truncated bag under a run's name: the run's task goes to another worker, which writes
it again.
"""

from __future__ import annotations

import datetime as dt
import os
import shutil
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

from exsce_dsl.errors import ExsceError
from exsce_dsl.maps.planning import PlanningGrid, planning_grid
from exsce_dsl.model import Scenario
from exsce_dsl.model.conventions import Signals
from exsce_dsl.model.executions import SimulatorInfo
from exsce_dsl.model.runs import Action, ActionId, ActionStatus, Run, run_name, run_uuid
from exsce_dsl.parallel.dask_client import dask_map
from exsce_dsl.prov.recorder import recorded_prov_json, recorded_run
from exsce_dsl.remedies import CHOOSE_A_CONVENTION
from exsce_dsl.runs import ROS1_BAG
from exsce_dsl.sim.bag import write_bag
from exsce_dsl.sim.conventions import convention_writer
from exsce_dsl.sim.executor import Fault, GoalStatus, SimulatedExecution
from exsce_dsl.sim.simulators import KINEMATIC, Simulator

FORMATS = ("ros1", "ros2", "mcap")
#: Runs of seed S start at this instant plus S days (modulo SEED_DAYS), one hour apart (no wall clock:
#: same seed, same bytes).  Some ROS 1 message fields are signed 32-bit seconds, so every start stays
#: well before 2038-01-19.
EPOCH = dt.datetime(2026, 1, 1, tzinfo=dt.timezone.utc)
SEED_DAYS = 4_000


@dataclass(frozen=True)
class SimulatedRun:
    run_id: str  # a uuid
    bag: Path
    start: dt.datetime
    seed: int
    execution: SimulatedExecution
    messages: int


@dataclass(frozen=True)
class RunPlan:
    """What every run of one ``simulate`` call shares; with a run's index, all a run needs."""

    scenario: Scenario
    out_dir: Path
    fmt: str
    seed: int
    faults: tuple[Fault, ...]
    convention: Signals | str
    twist_stamped: bool
    simulator: Simulator = KINEMATIC

    @classmethod
    def of(
        cls,
        scenario: Scenario,
        out_dir: Path,
        fmt: str = "ros1",
        seed: int = 0,
        faults: Sequence[Fault] = (),
        convention: Signals | str | None = None,
        twist_stamped: bool = False,
        simulator: Simulator = KINEMATIC,
    ) -> RunPlan:
        """The plan of ``simulate``'s arguments: the format checked, the convention chosen."""
        if fmt not in FORMATS:
            raise ExsceError(f"unknown bag format '{fmt}'; use one of {', '.join(FORMATS)}")
        chosen = convention or scenario_convention(scenario)
        return cls(scenario, out_dir, fmt, seed, tuple(faults), chosen, twist_stamped, simulator)

    @property
    def variant(self) -> str:
        """What the run ids of another convention than the method's add, so that their bags can
        share a folder with the method's."""
        written = convention_writer(self.convention).name
        stamped = "/stamped" if self.twist_stamped else ""
        return self.played_by + ("" if written == "method" else f"/{written}{stamped}")

    @property
    def played_by(self) -> str:
        """What the run ids of another simulator than the kinematic executor add: its name and
        settings (a run of IR-SIM is never one of the kinematic executor)."""
        sim = self.simulator
        if sim.name == KINEMATIC.name:
            return ""
        return f"/{sim.name}" + "".join(f"/{k}={v}" for k, v in sim.settings.items())


def simulate(
    scenario: Scenario,
    out_dir: Path,
    runs: int = 1,
    fmt: str = "ros1",
    seed: int = 0,
    faults: Sequence[Fault] = (),
    convention: Signals | str | None = None,
    twist_stamped: bool = False,
    dask_address: str | None = None,
    simulator: Simulator = KINEMATIC,
) -> Iterator[SimulatedRun]:
    """Play ``scenario`` ``runs`` times and write one bag per run into ``out_dir``, in run order.

    ``convention`` (a name or a robot type's :class:`Signals`) says which topics the robots
    publish: the method's, Nav2's or move_base's; None: the one the robots' types name (the
    method's if they name none); ``twist_stamped`` makes the
    navigation stacks' ``cmd_vel`` a TwistStamped (Nav2 from Jazzy on).  ``simulator`` plays
    each run (:mod:`exsce_dsl.sim.simulators`): the kinematic executor unless told.  Runs in another
    convention than the method's get other run ids, so their bags can share a folder.

    With ``dask_address`` (a Dask scheduler's address) each run is one task on the cluster's workers,
    with the same run ids and the same bytes.  The workers write the bags: ``out_dir`` (made
    absolute here) and the scenario's map file must be the same paths on every worker (a shared
    filesystem).  A task is tried twice, and a killed worker's task goes to another worker; a run
    that failed even so does not stop the others: when they are done, an :class:`ExsceError`
    names each failed run by its index."""
    if dask_address is not None:
        shared = _with_absolute_map(scenario)
        plan = RunPlan.of(shared, out_dir.absolute(), fmt, seed, faults, convention, twist_stamped, simulator)
        plan.out_dir.mkdir(parents=True, exist_ok=True)
        return _on_dask(dask_address, plan, runs, out_dir)
    plan = RunPlan.of(scenario, out_dir, fmt, seed, faults, convention, twist_stamped, simulator)
    out_dir.mkdir(parents=True, exist_ok=True)
    return _here(plan, runs)


def _here(plan: RunPlan, runs: int) -> Iterator[SimulatedRun]:
    grid = planning_grid(plan.scenario)
    for index in range(runs):
        yield play_run(plan, index, grid)


def _on_dask(address: str, plan: RunPlan, runs: int, out_dir: Path) -> Iterator[SimulatedRun]:
    failed: list[str] = []
    with dask_map(address) as mapper:
        for index, played in enumerate(mapper(_play_task, [(plan, index) for index in range(runs)])):
            if isinstance(played, SimulatedRun):
                yield replace(played, bag=out_dir / played.bag.name)
            else:
                why = played.message if isinstance(played, ExsceError) else str(played)
                failed.append(f"run {index} (seed {plan.seed * 1000 + index}): {why}")
    if failed:
        verb = "was" if len(failed) == 1 else "were"
        raise ExsceError(
            f"{len(failed)} of {runs} runs of scenario '{plan.scenario.id}' {verb} not written on the "
            "cluster (the others were):\n  " + "\n  ".join(failed)
        )


def _with_absolute_map(scenario: Scenario) -> Scenario:
    """``scenario`` with its map file named from the root: a worker's working folder is its own."""
    env = scenario.environment
    if env.map is None or env.map.file is None:
        return scenario
    found = replace(env.map, file=str(Path(env.map.file).absolute()))
    return replace(scenario, environment=replace(env, map=found))


def _play_task(task: tuple[RunPlan, int]) -> SimulatedRun:
    """One run on a cluster's worker (a map file's planning grid is read once per worker process)."""
    plan, index = task
    return play_run(plan, index)


def play_run(plan: RunPlan, index: int, grid: PlanningGrid | None = None) -> SimulatedRun:
    """Play run ``index`` of ``plan`` and write its bag and its ``.prov.json`` into the plan's
    folder (a bag already there under the run's name is replaced); ``grid``: the scenario's
    planning grid, when the caller has it already."""
    scenario = plan.scenario
    run_seed = plan.seed * 1000 + index
    # days wrap so that every seed gives a time ROS 1 can stamp (see SEED_DAYS)
    start = EPOCH + dt.timedelta(days=plan.seed % SEED_DAYS, hours=index)
    faults = ",".join(f.identity for f in plan.faults)
    run_id = run_uuid("simulated", f"{scenario.id}/{plan.seed}/{index}/{faults}{plan.variant}")
    grid = planning_grid(scenario) if grid is None else grid
    execution = plan.simulator.play(scenario, grid, run_seed, plan.faults)
    name = run_name(start, scenario.id, run_id)
    bag_name = name + ROS1_BAG.suffix if plan.fmt == "ros1" else name
    partial = plan.out_dir / f".{name}.partial"  # the run's own: a retry clears what a killed try left
    _remove(partial)
    partial.mkdir(parents=True)
    bag = plan.out_dir / bag_name
    try:
        start_ns = int(start.timestamp()) * 1_000_000_000
        count = write_bag(
            partial / bag_name, plan.fmt, scenario, execution, grid, start_ns, run_seed, None,
            plan.convention, plan.twist_stamped,
        )  # fmt: skip
        recorder = _recorded_run(run_id, scenario, execution, start, bag)
        recorder = replace(recorder, simulator=_info(plan.simulator))
        recorded = partial / (name + ".prov.json")
        recorded.write_text(recorded_prov_json(recorder, scenario), encoding="utf-8")
        os.replace(recorded, plan.out_dir / recorded.name)
        _remove(bag)
        os.replace(partial / bag_name, bag)  # last: a bag in its place is a whole run
    finally:
        _remove(partial)
    return SimulatedRun(run_id, bag, start, run_seed, execution, count)


def _info(simulator: Simulator) -> SimulatorInfo:
    return SimulatorInfo(simulator.name, simulator.version, tuple(simulator.settings.items()))


def _remove(path: Path) -> None:
    if path.is_dir():
        shutil.rmtree(path)
    elif path.exists():
        path.unlink()


def _recorded_run(
    run_id: str, scenario: Scenario, execution: SimulatedExecution, start: dt.datetime, bag: Path
) -> Run:
    """What the method's recorder writes during a run: task executions and actions, no metrics."""

    def at(seconds: float) -> dt.datetime:
        return start + dt.timedelta(seconds=seconds)

    actions = (
        Action(
            ActionId(a.robot, a.task_number, a.subtask_number, a.waypoint_number),
            a.start_pose,
            a.goal,
            ActionStatus.SUCCEEDED if a.status == GoalStatus.SUCCEEDED else ActionStatus.ABORTED,
            at(a.start),
            at(a.end),
            a.outcome if a.status != GoalStatus.SUCCEEDED else None,
        )
        for a in execution.actions
    )
    return recorded_run(run_id, scenario.id, start, at(execution.duration), bag.name, actions)


def scenario_convention(scenario: Scenario) -> str:
    """The convention the robots' types name (the method's when they name none): one per run."""
    named = {r.id: r.signals.convention for r in scenario.robots}
    found = sorted(set(named.values()))
    if len(found) > 1:
        listed = ", ".join(f"{robot}: {name}" for robot, name in named.items())
        raise ExsceError(
            f"the robots of scenario '{scenario.id}' follow different conventions ({listed})",
            remedy=CHOOSE_A_CONVENTION,
        )
    return found[0] if found else "method"
