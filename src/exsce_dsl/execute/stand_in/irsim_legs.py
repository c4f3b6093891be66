"""The stand-in's legs driven by IR-SIM (``exscec stand-in --ros2 --simulator irsim``).

:class:`IrsimFleet` is the stand-in's :class:`~.legs.Fleet` but for how a leg is driven: when a
goal comes, the scenario's IR-SIM world (:func:`~exsce_dsl.sim.irsim_world.world_file`, made once)
has every robot put where it stands, the one with the goal handed the planner's path as its goal
queue (as :func:`~exsce_dsl.sim.irsim_play.play_in_irsim` hands it), and IR-SIM steps (0.1 s) until
the robot arrives, collides, makes no progress (Nav2's progress checker: 0.5 m in 10 s) or times
out.  IR-SIM's behaviour (``rvo``...) moves it, with its kinematics, acceleration and its
avoidance of the robots standing in the world; the states are resampled to the stand-in's 50 Hz
samples.  The other robots stand while the leg is worked out: what each does during it is its
own leg's (the kinematic stand-in's simplification too).  Faults: those IR-SIM plays
(:data:`~exsce_dsl.sim.irsim_play.FAULTS_PLAYED`).
"""

from __future__ import annotations

import math
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

from exsce_dsl.errors import ExsceError, PlanningError
from exsce_dsl.execute.stand_in.legs import Fleet, StandInRobot
from exsce_dsl.maps.planning import PlanningGrid
from exsce_dsl.model import Pose, Scenario
from exsce_dsl.sim.faults import Fault
from exsce_dsl.sim.irsim_play import FAULTS_PLAYED, PROGRESS_RADIUS, PROGRESS_TIME, irsim_module, spaced
from exsce_dsl.sim.irsim_world import STEP, check_settings, world_file
from exsce_dsl.sim.motion import DT, Limits, SampledMotion

ABORT_HOLD = 0.5
"""Seconds a robot whose goal IR-SIM gives up stands before the abort (the kinematic stand-in's)."""


class IrsimFleet(Fleet):
    """The scenario's robots, their legs driven in IR-SIM with ``behaviour``."""

    def __init__(
        self,
        scenario: Scenario,
        grid: PlanningGrid,
        seed: int = 0,
        faults: tuple[Fault, ...] = (),
        behaviour: str = "rvo",
        run: int = 0,
    ) -> None:
        refused = sorted({f.kind for f in faults} - set(FAULTS_PLAYED))
        if refused:
            raise ExsceError(
                f"the IR-SIM stand-in does not play the fault(s) {', '.join(refused)} "
                f"(it plays {', '.join(FAULTS_PLAYED)})"
            )
        check_settings(behaviour, "none")
        self.irsim = irsim_module()  # a clear error before anything starts when IR-SIM is missing
        super().__init__(scenario, grid, seed, faults, run=run)
        self.behaviour = behaviour
        self._folder = tempfile.TemporaryDirectory(prefix="exsce-irsim-stand-in-")
        speeds = {name: robot.limits.max_speed for name, robot in self.robots.items()}
        limits = Limits()
        world = world_file(scenario, grid, Path(self._folder.name), behaviour, speeds, None, limits, STEP)
        self.env: Any = self.irsim.make(
            str(world), display=False, headless=True, seed=seed, log_level="CRITICAL"
        )
        self.objects = {obj.name: obj for obj in self.env.robot_list}
        for obj in self.objects.values():
            obj.set_goal(None)

    def close(self) -> None:
        self.env.end(0)
        self._folder.cleanup()

    def _drive(self, robot: StandInRobot, target: Pose) -> tuple[SampledMotion, bool]:
        x, y, yaw = robot.at.truth
        if (robot.name, robot.goals) in self.skip:
            return SampledMotion.hold(x, y, yaw, int(round(ABORT_HOLD / DT))), False
        for name, other in self.robots.items():
            self.objects[name].set_state(list(other.at.truth))
            self.objects[name].set_goal(None)
        obj = self.objects[robot.name]
        try:
            path = spaced(self.grid.cell_path((x, y), (target.position.x, target.position.y)))
        except PlanningError:
            return SampledMotion.hold(x, y, yaw, int(round(ABORT_HOLD / DT))), False
        obj.set_goal([[px, py, target.orientation.yaw] for px, py in (path[1:] or path[-1:])])
        rows, succeeded = self._step_until_decided(obj, path)
        obj.set_goal(None)
        return _resampled(rows), succeeded

    def _step_until_decided(
        self, obj: Any, path: list[tuple[float, float]]
    ) -> tuple[list[tuple[float, ...]], bool]:
        length = sum(math.dist(a, b) for a, b in zip(path, path[1:], strict=False))
        steps = int((2.0 * length / max(float(obj.vel_max[0, 0]), 0.05) + 60.0) / STEP)
        state = obj.state[:, 0]
        rows: list[tuple[float, ...]] = [(float(state[0]), float(state[1]), float(state[2]), 0.0, 0.0)]
        anchor, since = rows[0][:2], 0
        for k in range(1, steps + 1):
            self.env.step()
            state = obj.state[:, 0]
            at = (float(state[0]), float(state[1]))
            rows.append((*at, float(state[2]), float(obj.velocity[0, 0]), float(obj.velocity[1, 0])))
            if obj.arrive_flag and not obj.stop_flag:
                return rows, True
            if math.dist(at, anchor) >= PROGRESS_RADIUS:
                anchor, since = at, k
            if obj.stop_flag or (k - since) * STEP > PROGRESS_TIME:
                return rows, False
        return rows, False


def _resampled(rows: list[tuple[float, ...]]) -> SampledMotion:
    """IR-SIM's states (one per STEP) at the stand-in's samples (one per DT), linearly between."""
    a = np.array(rows, dtype=np.float64)
    t = np.arange(len(a)) * STEP
    at = np.arange(0.0, t[-1] + 1e-9, DT)
    yaw = np.unwrap(a[:, 2])
    columns = [np.interp(at, t, a[:, i]) for i in (0, 1)]
    return SampledMotion(
        columns[0], columns[1], np.interp(at, t, yaw), np.interp(at, t, a[:, 3]), np.interp(at, t, a[:, 4])
    )
