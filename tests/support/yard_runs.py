"""The two-robot yard of tests/sim/test_sim_conventions.py, simulated in several conventions with
metrics of a test's own, and each run ingested."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from exsce_dsl.lang import load_spec
from exsce_dsl.runs.analyse import AnalysedRun, analyse_bag
from exsce_dsl.sim.executor import Fault
from exsce_dsl.sim.run import simulate

from tests.sim.test_sim_conventions import YARD

SEED = 7


def yard_runs(
    folder: Path, metrics: str, conventions: Sequence[str], faults: Sequence[Fault] = ()
) -> dict[str, tuple[Path, AnalysedRun]]:
    """Convention → the bag of one simulated run of the yard (r1 at the root, r2 in /r2) with
    ``metrics`` added to its specification, and that bag ingested."""
    spec = folder / "yard.exsce"
    spec.write_text(YARD + metrics, encoding="utf-8")
    scenario = load_spec(spec).scenario()
    found = {}
    for convention in conventions:
        (run,) = simulate(scenario, folder / convention, 1, "ros1", SEED, faults, convention=convention)
        found[convention] = (run.bag, analyse_bag(run.bag, scenario))
    return found
