"""The simulators that play a scenario, behind one interface, chosen by name.

A :class:`Simulator` is given a scenario, its planning grid, a seed and deliberate faults, and
plays the scenario once: it hands back a :class:`~exsce_dsl.sim.executor.SimulatedExecution`
(each robot's motion on one clock, the dispatcher's goal events, the actions and, when it has a
sensor of its own, the scans).  Everything after that is shared: the bag in any convention and
format, the run-time PROV, ingest.  Two are built in:

- ``kinematic``: exsce's own kinematic executor (:mod:`exsce_dsl.sim.executor`): grid paths
  driven with bounded speed and acceleration, conflicts between robots repaired as a fleet
  manager would; fast, and every deliberate fault;
- ``irsim``: IR-SIM (``ir-sim`` on PyPI, the ``irsim`` extra), a multi-robot navigation
  simulator nobody here wrote, driving each leg's global path with its own behaviour
  (:mod:`exsce_dsl.sim.irsim_play`).

A package may register more under the entry-point group ``exsce.simulators``: a factory that,
called with no arguments, returns a Simulator.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Protocol, runtime_checkable

from exsce_dsl.errors import ExsceError
from exsce_dsl.maps.planning import PlanningGrid
from exsce_dsl.model import Scenario
from exsce_dsl.plugins import Registry
from exsce_dsl.sim.executor import SimulatedExecution, execute
from exsce_dsl.sim.faults import Fault
from exsce_dsl.sim.irsim_world import STEP, check_settings
from exsce_dsl.suggest import did_you_mean


@runtime_checkable
class Simulator(Protocol):
    """Plays a scenario once."""

    @property
    def name(self) -> str:
        """The simulator's name, as ``--simulator`` takes it and the run's PROV records it."""
        ...

    @property
    def version(self) -> str:
        """The version of the software that played the run."""
        ...

    @property
    def settings(self) -> Mapping[str, str]:
        """What else decided how the runs were played (the run's PROV records it)."""
        ...

    def play(
        self, scenario: Scenario, grid: PlanningGrid, seed: int, faults: tuple[Fault, ...]
    ) -> SimulatedExecution:
        """Play ``scenario`` once: the same seed, the same execution."""
        ...


@dataclass(frozen=True)
class KinematicSimulator:
    """exsce's kinematic executor."""

    name: str = "kinematic"

    @property
    def version(self) -> str:
        from exsce_dsl import __version__

        return __version__

    @property
    def settings(self) -> Mapping[str, str]:
        return {}

    def play(
        self, scenario: Scenario, grid: PlanningGrid, seed: int, faults: tuple[Fault, ...]
    ) -> SimulatedExecution:
        return execute(scenario, grid, seed, faults)


@dataclass(frozen=True)
class IrsimSimulator:
    """IR-SIM, with one of its behaviours and a source of scans
    (:data:`~exsce_dsl.sim.irsim_world.SCAN_SOURCES`)."""

    behaviour: str = "rvo"
    scans: str = "exsce"
    name: str = "irsim"
    step: float = STEP
    """IR-SIM's step in seconds (its default): the run's sample period."""

    def __post_init__(self) -> None:
        check_settings(self.behaviour, self.scans)

    @property
    def version(self) -> str:
        from exsce_dsl.sim.irsim_play import irsim_version

        return irsim_version()

    @property
    def settings(self) -> Mapping[str, str]:
        from exsce_dsl.sim.irsim_play import PATH_SPACING, PROGRESS_RADIUS, PROGRESS_TIME
        from exsce_dsl.sim.irsim_world import GOAL_TOLERANCE
        return {
            "behaviour": self.behaviour,
            "scans": self.scans,
            "step_time": f"{self.step}",
            "collision_mode": "stop",
            "goal_tolerance": f"{GOAL_TOLERANCE}",
            "path_spacing": f"{PATH_SPACING}",
            "progress_checker": f"{PROGRESS_RADIUS} m in {PROGRESS_TIME} s",
        }

    def play(
        self, scenario: Scenario, grid: PlanningGrid, seed: int, faults: tuple[Fault, ...]
    ) -> SimulatedExecution:
        from exsce_dsl.sim.irsim_play import play_in_irsim

        return play_in_irsim(scenario, grid, seed, faults, self.behaviour, self.scans, step=self.step)


KINEMATIC = KinematicSimulator()


def _plugin(name: str, loaded: object) -> Simulator | None:
    if not callable(loaded):
        return None
    made = loaded()
    return made if isinstance(made, Simulator) else None


SIMULATORS: Registry[Simulator] = Registry(
    "simulator", [("kinematic", KINEMATIC), ("irsim", IrsimSimulator())], _plugin, "a simulator factory"
)
"""The simulators chosen by name: the built-ins, then the plug-ins (:mod:`exsce_dsl.plugins`)."""


def simulator_named(name: str, behaviour: str | None = None, scans: str | None = None) -> Simulator:
    """The simulator called ``name``; IR-SIM with ``behaviour`` and ``scans`` when given (the
    others take neither)."""
    known = SIMULATORS.entries()
    if name not in known:
        raise ExsceError(
            f"no simulator '{name}'{did_you_mean(name, list(known))}; the simulators are {', '.join(known)}"
        )
    if name == "irsim":
        defaults = IrsimSimulator()
        return IrsimSimulator(behaviour or defaults.behaviour, scans or defaults.scans)
    if behaviour is not None or scans is not None:
        raise ExsceError(f"the simulator '{name}' takes no behaviour or scan source (IR-SIM does)")
    return known[name]
