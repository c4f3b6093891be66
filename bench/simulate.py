"""Benchmark: how fast each simulator plays scenario_c, and how many executions a campaign gets
through in an hour.

For each simulator (exsce's kinematic executor; IR-SIM with its ``rvo`` and ``dash`` behaviours)
it plays scenario_c and reports simulated seconds per wall second of the play alone (the
scenario in, the :class:`~exsce_dsl.sim.executor.SimulatedExecution` out), then of the whole
``simulate`` (the bag written, Nav2's topics in MCAP, and its PROV), with scans and without:

- the kinematic executor's scans are always exsce's laser model, ray-marched when the bag is
  written;
- IR-SIM's: ``exsce`` (exsce's laser model on IR-SIM's robot poses), ``irsim`` (IR-SIM's own
  ``lidar2d``, 720 beams at 10 Hz; ``--irsim-lidar`` to measure it: about two wall seconds per
  simulated second on scenario_c, so it is off unless asked) or ``none``.

Then a campaign (``exscec explore examples/irsim_crossing/crossing.exsce -n BUDGET -k 1``,
kinematic and IR-SIM, each on a fresh store) gives executions per hour, its three base runs and
the shrinkings included in the wall time.  The baseline of every ratio is measured in the same
run: real time (1× = as fast as the robots would drive).  Target (issue 50): with scans, at least
20× real time for scenario_c on 2 cores.

    python bench/simulate.py [--budget 6] [--irsim-lidar]

Last measured (2026-12-02, 2 cores shared with another engineer's tests): see docs/irsim.md.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from exsce_dsl.lang import load_spec
from exsce_dsl.maps.planning import planning_grid
from exsce_dsl.sim.run import simulate
from exsce_dsl.sim.simulators import KINEMATIC, IrsimSimulator, Simulator

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "examples" / "brsu_building_c" / "scenario_c.exsce"
CROSSING = ROOT / "examples" / "irsim_crossing" / "crossing.exsce"


def _play(simulator: Simulator) -> tuple[float, float]:
    """(simulated seconds, wall seconds) of playing scenario_c once."""
    scenario = load_spec(SPEC).scenario("scenario_c")
    grid = planning_grid(scenario)
    started = time.perf_counter()
    execution = simulator.play(scenario, grid, 3, ())
    return execution.duration, time.perf_counter() - started


def _simulate(simulator: Simulator, folder: Path) -> tuple[float, float]:
    """(simulated seconds, wall seconds) of ``simulate``: the run played, its bag and PROV written."""
    scenario = load_spec(SPEC).scenario("scenario_c")
    started = time.perf_counter()
    [run] = list(simulate(scenario, folder, 1, "mcap", 3, convention="nav2", simulator=simulator))
    return run.execution.duration, time.perf_counter() - started


def _campaign(simulator: str, budget: int, folder: Path) -> tuple[int, float]:
    """(executions, wall seconds) of a campaign on the crossing example."""
    started = time.perf_counter()
    command = [
        str(Path(sys.executable).with_name("exscec")), "explore", str(CROSSING), "-n", str(budget), "-k", "1",
        "--simulator", simulator, "-o", str(folder / "campaign"), "--store", str(folder / "store"),
    ]  # fmt: skip
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    seconds = time.perf_counter() - started
    if done.returncode not in (0, 1, 3):
        raise SystemExit(f"the {simulator} campaign failed:\n{done.stderr}")
    return budget, seconds


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--budget", type=int, default=6, help="Derivations of each campaign.")
    parser.add_argument("--irsim-lidar", action="store_true", help="Also measure IR-SIM's own lidar.")
    args = parser.parse_args()
    cases: list[tuple[str, Simulator]] = [
        ("kinematic", KINEMATIC),
        ("irsim rvo, scans by exsce", IrsimSimulator("rvo", "exsce")),
        ("irsim rvo, no scans", IrsimSimulator("rvo", "none")),
        ("irsim dash, scans by exsce", IrsimSimulator("dash", "exsce")),
    ]
    if args.irsim_lidar:
        cases.append(("irsim rvo, IR-SIM's lidar", IrsimSimulator("rvo", "irsim")))
    print(f"{'scenario_c':<28} {'simulated s':>11} {'play ×':>8} {'simulate ×':>11}")
    with tempfile.TemporaryDirectory() as scratch:
        _play(KINEMATIC)  # untimed: the map read, numpy and IR-SIM imported
        for label, simulator in cases:
            simulated, playing = _play(simulator)
            _, whole = _simulate(simulator, Path(scratch) / label.replace(" ", "_"))
            print(f"{label:<28} {simulated:>11.1f} {simulated / playing:>7.1f}× {simulated / whole:>10.1f}×")
        print()
        print(f"{'campaign (crossing, -k 1)':<28} {'executions':>11} {'wall s':>8} {'per hour':>11}")
        for name in ("kinematic", "irsim"):
            executions, seconds = _campaign(name, args.budget, Path(scratch) / f"campaign-{name}")
            print(f"{name:<28} {executions:>11} {seconds:>8.0f} {executions * 3600 / seconds:>11.0f}")


if __name__ == "__main__":
    main()
