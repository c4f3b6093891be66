"""Baselines learn from good runs only, and their provenance says which runs were left out and why.

Real runs of the yard (tests/support/yard_spec.py's YARD_SPEC; its baseline needs 4 runs): four clean runs;
a slow run of r1, verified (it fails r1's task duration, and the failed verdict is stored); a
clean run whose run-time PROV says its mission was cancelled (as ``exscec execute`` leaves an
interrupted run); an over-speed run of r1, ingested and never verified.  The baseline is built
from the four clean runs alone: its means are theirs (computed here from their stored values, read
with a query of the test's own), each run left out is in the baseline's PROV with its reason
(asked with SPARQL), and ``--all-runs`` takes every run.
"""

from __future__ import annotations

import datetime as dt
import json
import math
import re
import shutil
import uuid
from pathlib import Path

import pytest

from exsce_dsl.lang import load_spec
from exsce_dsl.model import Scenario
from exsce_dsl.model.runs import Action, ActionId, ActionStatus, RunStatus
from exsce_dsl.prov.recorder import recorded_prov_json, recorded_run
from exsce_dsl.sim.executor import Fault
from exsce_dsl.sim.run import simulate

from tests.support.cli import exscec_here
from tests.support.map_files import write_map
from tests.support.yard_spec import YARD_SPEC

LEFT_OUT = """
SELECT ?run ?scenario ?reason WHERE {
  GRAPH ?g { ?e a exsce:left_out_run ; exsce:run ?run ; exsce:scenario ?scenario ; oracle:reason ?reason }
  FILTER(!CONTAINS(STR(?g), "revision="))
}
"""
USED = """
SELECT ?scenario ?runs WHERE {
  GRAPH ?g { ?e a exsce:baseline_runs ; exsce:scenario ?scenario ; oracle:runs ?runs }
  FILTER(!CONTAINS(STR(?g), "revision="))
}
"""
TASK_DURATIONS = """
SELECT ?run ?value WHERE {
  GRAPH ?g { ?m run:metricType "task_duration" ; exsce:robot "r1" ; exsce:run ?run ; prov:value ?value }
  FILTER(STRENDS(STR(?m), "/r1-task_duration"))  # the robot's whole-run value, not a segment's
}
"""


def _cancelled(bag: Path, folder: Path, scenario: Scenario) -> Path:
    """``bag`` copied into ``folder`` with the run-time PROV of a mission cancelled beside it."""
    folder.mkdir()
    copy = folder / bag.name
    shutil.copyfile(bag, copy)
    start = dt.datetime(2026, 1, 1, tzinfo=dt.timezone.utc)
    robot = scenario.robots[0]
    assert robot.start_pose is not None
    action = Action(ActionId(robot.id, 1, 1, 1), robot.start_pose, robot.start_pose, ActionStatus.ABORTED,
                    start, start + dt.timedelta(seconds=5), outcome="cancelled")  # fmt: skip
    run = recorded_run(str(uuid.uuid4()), scenario.id, start, start + dt.timedelta(seconds=5), copy.name,
                       [action], RunStatus.CANCELLED)  # fmt: skip
    copy.with_suffix(".prov.json").write_text(recorded_prov_json(run, scenario), encoding="utf-8")
    return copy


def _run_of(ingested: str, bag: Path) -> str:
    """The uuid ``exscec ingest`` (or verify) printed for ``bag``."""
    found = re.search(rf"{re.escape(bag.name)}: run ([0-9a-f-]+)", ingested)
    assert found, ingested
    return found.group(1)


def _rows(folder: Path, query: str, *store: str) -> list[dict[str, str]]:
    done = exscec_here("sparql", query, "-f", "json", *store, cwd=folder)
    assert done.returncode == 0, done.stderr
    return [{k: v["value"] for k, v in row.items()} for row in json.loads(done.stdout)["results"]["bindings"]]


@pytest.fixture(scope="module")
def yard(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, Path]]:
    """The project folder and its bags: clean_0..3, slow, cancelled, fast."""
    folder = tmp_path_factory.mktemp("good_runs")
    write_map(folder, size=200)
    (folder / "spec.exsce").write_text(YARD_SPEC)
    scenario = load_spec(folder / "spec.exsce").scenario()
    bags = {f"clean_{i}": run.bag for i, run in enumerate(simulate(scenario, folder / "clean", 4, seed=1))}
    for name, seed, fault in (("slow", 2, "slow:r1"), ("fast", 3, "overspeed:r1")):
        faults = (Fault.parse(fault),)
        bags[name] = next(iter(simulate(scenario, folder / name, 1, seed=seed, faults=faults))).bag
    other = next(iter(simulate(scenario, folder / "other", 1, seed=4))).bag
    bags["cancelled"] = _cancelled(other, folder / "cancelled", scenario)
    return folder, bags


def test_a_baseline_leaves_out_failed_cancelled_and_unsafe_runs_and_says_why(
    yard: tuple[Path, dict[str, Path]],
) -> None:
    folder, bags = yard
    clean = [bags[f"clean_{i}"] for i in range(4)]
    ingested = exscec_here("ingest", *map(str, clean), "--scenario", "spec.exsce", cwd=folder)
    assert ingested.returncode == 0, ingested.stderr
    good = [_run_of(ingested.stderr + ingested.stdout, bag) for bag in clean]
    first = exscec_here("baseline", "spec.exsce", cwd=folder)
    assert first.returncode == 0 and "built from 4 runs\n" in first.stderr, first.stderr

    verified = exscec_here("verify", str(bags["slow"]), "--scenario", "spec.exsce", "--json", cwd=folder)
    assert verified.returncode == 1, verified.stdout + verified.stderr
    failed = sorted({v["oracle"] for v in json.loads(verified.stdout) if v["verdict"] == "failed"})
    assert "r1-task_duration" in failed
    slow = next(v["run"] for v in json.loads(verified.stdout))
    more = exscec_here(
        "ingest", str(bags["cancelled"]), str(bags["fast"]), "--scenario", "spec.exsce", cwd=folder
    )
    assert more.returncode == 0, more.stderr
    cancelled = _run_of(more.stderr + more.stdout, bags["cancelled"])
    fast = _run_of(more.stderr + more.stdout, bags["fast"])

    built = exscec_here("baseline", "spec.exsce", cwd=folder)
    assert built.returncode == 0, built.stderr
    [summary] = [line for line in built.stderr.splitlines() if line.startswith("built from")]
    assert summary.startswith("built from 4 runs; left out 3: "), summary
    assert f"{slow[:8]} (failed {', '.join(failed)} when verified)" in summary
    assert f"{cancelled[:8]} (its mission was cancelled)" in summary
    assert re.search(rf"{fast[:8]} \(max_velocity of r1 above its limit for \d+\.\d s\)", summary), summary

    # the PROV of the baseline: the runs used, and each run left out with why
    left_out = {row["run"]: row["reason"] for row in _rows(folder, LEFT_OUT)}
    assert set(left_out) == {slow, cancelled, fast}
    assert left_out[slow] == f"failed {', '.join(failed)} when verified"
    assert left_out[cancelled] == "its mission was cancelled"
    assert left_out[fast].startswith("max_velocity of r1 above its limit for ")
    assert {row["scenario"] for row in _rows(folder, LEFT_OUT)} == {"yard_run"}
    [used] = _rows(folder, USED)
    assert used["scenario"] == "yard_run" and sorted(used["runs"].split()) == sorted(good)

    # its mean is the clean runs' mean, read from the store with the test's own query
    durations = {row["run"]: float(row["value"]) for row in _rows(folder, TASK_DURATIONS)}
    assert set(durations) == {*good, slow, cancelled, fast}
    clean_mean = math.fsum(durations[r] for r in good) / len(good)
    every_mean = math.fsum(durations.values()) / len(durations)
    assert abs(clean_mean - every_mean) > 1.0  # the slow run alone moves the mean by seconds
    [row] = [line.split() for line in built.stdout.splitlines() if line.startswith("r1-task_duration ")]
    assert float(row[2]) == pytest.approx(clean_mean, rel=1e-3)

    everything = exscec_here("baseline", "spec.exsce", "--all-runs", cwd=folder)
    assert everything.returncode == 0, everything.stderr
    assert "built from 7 runs (every stored run: --all-runs)" in everything.stderr
    [row] = [line.split() for line in everything.stdout.splitlines() if line.startswith("r1-task_duration ")]
    assert float(row[2]) == pytest.approx(every_mean, rel=1e-3)
    assert _rows(folder, LEFT_OUT) == []  # nothing left out this time


def test_no_good_run_left_is_an_error_that_names_the_reasons(
    yard: tuple[Path, dict[str, Path]], tmp_path: Path
) -> None:
    folder, bags = yard
    store = ("--store", str(tmp_path / "store"))
    two = [str(bags["cancelled"]), str(bags["fast"])]
    ingested = exscec_here("ingest", *two, "--scenario", "spec.exsce", *store, cwd=folder)
    assert ingested.returncode == 0, ingested.stderr
    cancelled = _run_of(ingested.stderr + ingested.stdout, bags["cancelled"])
    fast = _run_of(ingested.stderr + ingested.stdout, bags["fast"])
    refused = exscec_here("baseline", "spec.exsce", *store, cwd=folder)
    assert refused.returncode == 2, refused.stdout + refused.stderr
    assert "Traceback" not in refused.stderr
    message = " ".join(refused.stderr.split())
    assert "no good run of scenario 'yard_run' to learn from: every stored run was left out" in message
    assert f"{cancelled[:8]} (its mission was cancelled)" in message
    assert f"{fast[:8]} (max_velocity of r1 above its limit for" in message
    assert "--all-runs" in message
