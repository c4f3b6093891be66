"""Expected values learn from good runs only: an over-speed run in the store does not move them.

The issue's case: ``derive --expect`` gave another expected value once an over-speed run of
scenario_c was stored.  Three fault-free runs of scenario_c and one with tiago1 over its speed
limit (ingested, never verified: the violation measured at ingest is enough to leave it out).
scenario_c without tiago1's way home drives only segments the stored runs observed (classroom_c025
→ c022 → c018), so its expected task duration is the sum of their means: computed here from the
segment values the store holds (read with the store's plain per-run query, not the estimate's),
over the fault-free runs only, and with ``--all-runs`` over every run.
"""

from __future__ import annotations

import json
import math
import re
import shutil
from pathlib import Path

import pytest

from exsce_dsl.derive.waiting import GIVE_WAY
from exsce_dsl.lang import load_spec
from exsce_dsl.sim.executor import Fault
from exsce_dsl.sim.run import simulate

from tests.support.cli import exscec_here
from tests.support.paths import EXAMPLES

LEGS = (("classroom_c025-w001", "classroom_c022-w001"), ("classroom_c022-w001", "classroom_c018-w001"))
"""tiago1's path in scenario_c without navigate_home_1: its start pose, then delivery_a."""
DERIVE = (
    "-t",
    "remove_task",
    "--task",
    "navigate_home_1",
    "--robot",
    "tiago1",
    "--id",
    "c_short",
    "--expect",
)


@pytest.fixture(scope="module")
def project(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, list[str], str]:
    """A project with three fault-free runs of scenario_c and one over-speed run of tiago1 stored."""
    folder = tmp_path_factory.mktemp("good_expectations")
    shutil.copytree(EXAMPLES / "brsu_building_c", folder / "c")
    base = load_spec(folder / "c" / "scenario_c.exsce").scenario("scenario_c")
    clean = [run.bag for run in simulate(base, folder / "clean", 3, seed=1)]
    overspeed = (Fault.parse("overspeed:tiago1"),)
    [fast] = [run.bag for run in simulate(base, folder / "fast", 1, seed=7, faults=overspeed)]
    ingested = exscec_here("ingest", *map(str, [*clean, fast]), "--scenario", "c/scenario_c.exsce", cwd=folder)
    assert ingested.returncode == 0, ingested.stderr
    said = ingested.stdout + ingested.stderr

    def uuid_of(bag: Path) -> str:
        found = re.search(rf"{re.escape(bag.name)}: run ([0-9a-f-]+)", said)
        assert found, said
        return found.group(1)

    return folder, [uuid_of(bag) for bag in clean], uuid_of(fast)


def _leg_durations(folder: Path, runs: list[str]) -> dict[tuple[str, str], list[float]]:
    """tiago1's task_duration on each leg of LEGS, one value per run, as the store holds them."""
    given = [a for run in runs for a in ("-p", f"run={run}")]
    done = exscec_here("query", "run_segment_values", *given, "--format", "json", cwd=folder)
    assert done.returncode == 0, done.stderr
    found: dict[tuple[str, str], list[float]] = {leg: [] for leg in LEGS}
    for row in json.loads(done.stdout)["results"]["bindings"]:
        if row["metric"]["value"] != "task_duration" or row.get("robot", {}).get("value") != "tiago1":
            continue
        leg = (row["start"]["value"].rsplit("/", 1)[-1], row["goal"]["value"].rsplit("/", 1)[-1])
        for start, goal in LEGS:
            if leg[0].startswith(start + "-") and leg[1].startswith(goal + "-"):
                found[(start, goal)].append(float(row["value"]["value"]))
    assert all(len(values) == len(runs) for values in found.values()), found
    return found


def _expected(text: str, metric: str) -> float:
    """tiago1's expected value of ``metric`` in a derived file: its clause's centre, less half the
    time it may give way to tiago2, which shares its runs (exsce_dsl.derive.waiting)."""
    found = re.search(rf"tiago1 {metric} is invariant around ([0-9.]+) ", text)
    assert found, text
    assert f"(tiago1 {GIVE_WAY:g} s, " in text  # the note on the clauses that allow for it
    return float(found.group(1)) - GIVE_WAY / 2


def _sum_of_means(durations: dict[tuple[str, str], list[float]]) -> float:
    return math.fsum(math.fsum(values) / len(values) for values in durations.values())


def test_an_over_speed_run_does_not_move_the_expected_duration(project: tuple[Path, list[str], str]) -> None:
    folder, clean, fast = project
    fault_free = _sum_of_means(_leg_durations(folder, clean))
    every = _sum_of_means(_leg_durations(folder, [*clean, fast]))
    assert abs(fault_free - every) > 2.0  # the over-speed run drives these legs much faster

    derived = exscec_here("derive", "c/scenario_c.exsce", *DERIVE, "-o", "c/good.exsce", cwd=folder)
    assert derived.returncode == 0, derived.stderr
    assert _expected((folder / "c" / "good.exsce").read_text(), "task_duration") == pytest.approx(
        fault_free, abs=0.0015
    )

    everything = exscec_here(
        "derive", "c/scenario_c.exsce", *DERIVE, "--all-runs", "-o", "c/every.exsce", cwd=folder
    )
    assert everything.returncode == 0, everything.stderr
    assert _expected((folder / "c" / "every.exsce").read_text(), "task_duration") == pytest.approx(
        every, abs=0.0015
    )

    for flags, count in (((), 3), (("--all-runs",), 4)):  # each observed segment: drives of how many runs
        shown = exscec_here("expect", "c/good.exsce", *flags, cwd=folder)
        assert shown.returncode == 0, shown.stderr
        observed = [line for line in shown.stdout.splitlines() if "  observed" in line]
        assert observed and all(line.endswith(f"({count} runs)") for line in observed), shown.stdout
