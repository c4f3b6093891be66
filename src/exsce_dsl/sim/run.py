"""``simulate``: scenario in, bag files out (one per run), deterministic per seed."""

from __future__ import annotations

import datetime as dt
import shutil
import uuid
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np

from exsce_dsl.errors import ExsceError
from exsce_dsl.lang.occupancy import OccupancyGrid, load_occupancy_grid
from exsce_dsl.model import Scenario
from exsce_dsl.model.conventions import Signals
from exsce_dsl.model.runs import Action, ActionId, ActionStatus, Bag, Run, TaskExecution
from exsce_dsl.prov import serialize_prov
from exsce_dsl.prov.run import compile_run
from exsce_dsl.sim.bag import write_bag
from exsce_dsl.sim.conventions import convention_writer
from exsce_dsl.sim.executor import Execution, Fault, GoalStatus, execute
from exsce_dsl.sim.planner import PlanningGrid

FORMATS = ("ros1", "ros2", "mcap")
#: Runs of seed S start at this instant plus S days (modulo SEED_DAYS), one hour apart (no wall clock:
#: same seed, same bytes).  Some ROS 1 message fields are signed 32-bit seconds, so every start stays
#: well before 2038-01-19.
EPOCH = dt.datetime(2026, 1, 1, tzinfo=dt.timezone.utc)
SEED_DAYS = 4_000
_RUN_NAMESPACE = uuid.UUID("7f0f3f5e-5a3c-4c1e-9d8e-6b0e2a1c9d41")


@dataclass(frozen=True)
class SimulatedRun:
    run_id: str  # a uuid
    bag: Path
    start: dt.datetime
    seed: int
    execution: Execution
    messages: int


def simulate(
    scenario: Scenario,
    out_dir: Path,
    runs: int = 1,
    fmt: str = "ros1",
    seed: int = 0,
    faults: Sequence[Fault] = (),
    convention: Signals | str | None = None,
    twist_stamped: bool = False,
) -> Iterator[SimulatedRun]:
    """Play ``scenario`` ``runs`` times and write one bag per run into ``out_dir``.

    ``convention`` (a name or a robot type's :class:`Signals`) says which topics the robots
    publish: the method's, Nav2's or move_base's; None: the one the robots' types name (the
    method's if they name none); ``twist_stamped`` makes the
    navigation stacks' ``cmd_vel`` a TwistStamped (Nav2 from Jazzy on).  Runs in another
    convention than the method's get other run ids, so their bags can share a folder."""
    if fmt not in FORMATS:
        raise ExsceError(f"unknown bag format '{fmt}'; use one of {', '.join(FORMATS)}")
    convention = convention or scenario_convention(scenario)
    written = convention_writer(convention).name
    variant = "" if written == "method" else f"/{written}" + ("/stamped" if twist_stamped else "")
    grid = planning_grid(scenario)
    out_dir.mkdir(parents=True, exist_ok=True)
    for index in range(runs):
        run_seed = seed * 1000 + index
        # days wrap so that every seed gives a time ROS 1 can stamp (see SEED_DAYS)
        start = EPOCH + dt.timedelta(days=seed % SEED_DAYS, hours=index)
        run_id = str(
            uuid.uuid5(
                _RUN_NAMESPACE,
                f"{scenario.id}/{seed}/{index}/{','.join(f.identity for f in faults)}{variant}",
            )
        )
        execution = execute(scenario, grid, run_seed, tuple(faults))
        name = f"{start.strftime('%Y-%m-%dT%H-%M-%S')}_{scenario.id}_run-{run_id[:8]}"
        bag = out_dir / (name + ".bag" if fmt == "ros1" else name)
        if bag.exists():
            shutil.rmtree(bag) if bag.is_dir() else bag.unlink()
        start_ns = int(start.timestamp()) * 1_000_000_000
        count = write_bag(
            bag, fmt, scenario, execution, grid, start_ns, run_seed, None, convention, twist_stamped
        )
        recorder = _recorded_run(run_id, scenario, execution, start, bag)
        out_dir.joinpath(name + ".prov.json").write_text(
            serialize_prov(compile_run(recorder, scenario), "json"), encoding="utf-8"
        )
        yield SimulatedRun(run_id, bag, start, run_seed, execution, count)


def _recorded_run(
    run_id: str, scenario: Scenario, execution: Execution, start: dt.datetime, bag: Path
) -> Run:
    """What the method's recorder writes during a run: task executions and actions, no metrics."""

    def at(seconds: float) -> dt.datetime:
        return start + dt.timedelta(seconds=seconds)

    grouped: dict[tuple[str, int], list[Action]] = {}
    for a in execution.actions:
        status = ActionStatus.SUCCEEDED if a.status == GoalStatus.SUCCEEDED else ActionStatus.ABORTED
        grouped.setdefault((a.robot, a.task_number), []).append(
            Action(
                ActionId(a.robot, a.task_number, a.subtask_number, a.waypoint_number),
                a.start_pose,
                a.goal,
                status,
                at(a.start),
                at(a.end),
            )
        )
    tasks = tuple(TaskExecution(robot, n, tuple(acts)) for (robot, n), acts in grouped.items())
    return Run(run_id, scenario.id, start, at(execution.duration), Bag(bag.name), tasks)


def scenario_convention(scenario: Scenario) -> str:
    """The convention the robots' types name (the method's when they name none): one per run."""
    named = {r.id: r.signals.convention for r in scenario.robots}
    found = sorted(set(named.values()))
    if len(found) > 1:
        listed = ", ".join(f"{robot}: {name}" for robot, name in named.items())
        raise ExsceError(
            f"the robots of scenario '{scenario.id}' follow different conventions ({listed}); the "
            "executor writes one for the whole run: choose it with --convention"
        )
    return found[0] if found else "method"


def planning_grid(scenario: Scenario) -> PlanningGrid:
    env = scenario.environment
    if env.map is not None and env.map.file is not None:
        return _grid_from_file(env.map.file)
    return _open_space(scenario)


@lru_cache(maxsize=4)
def _grid_from_file(path: str) -> PlanningGrid:
    return PlanningGrid.from_map(load_occupancy_grid(Path(path)))


def _open_space(scenario: Scenario) -> PlanningGrid:
    """No map given: an empty grid around every pose of the scenario, 10 m of margin."""
    poses = [p for p in scenario.environment.poses()] + [w for t in scenario.tasks for w in t.waypoints()]
    xs = [p.position.x for p in poses]
    ys = [p.position.y for p in poses]
    resolution = 0.05
    x0, y0 = min(xs) - 10.0, min(ys) - 10.0
    width = int((max(xs) + 10.0 - x0) / resolution) + 1
    height = int((max(ys) + 10.0 - y0) / resolution) + 1
    cells = np.full((height, width), 254, dtype=np.uint8)
    cells[0, :] = cells[-1, :] = cells[:, 0] = cells[:, -1] = 0  # a wall round the edge, for the laser
    return PlanningGrid.from_map(OccupancyGrid(cells, resolution, (x0, y0, 0.0), 0.65, 0.196, False))
