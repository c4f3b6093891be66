"""Trials with real executor runs through the real ``exscec``: ``verify --repeat`` of fault-free
runs, a ``--trial`` of clean and over-speed bags, ``exscec flaky`` over what they stored, the
trial's JUnit and the report's pass-rate table.

The yard of tests/oracles/test_verify_e2e (four clean runs make the baseline).  Each clause's
expected outcome is computed here from its counts with scipy's Wilson interval, and the counts
are checked against the per-run verdicts the store holds (pandas, through ``api.verdicts``).
"""

from __future__ import annotations

import json
import shutil
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from scipy.stats import binomtest

from exsce_dsl import api
from exsce_dsl.lang import load_spec
from exsce_dsl.sim.executor import Fault
from exsce_dsl.sim.run import simulate

from tests.support.cli import exscec_here
from tests.support.map_files import write_map
from tests.support.yard_spec import YARD_SPEC

REQUIRED = 0.8
CONFIDENCE = 0.95


def _expected_outcome(passed: int, failed: int) -> str:
    """The trial outcome of a clause by the documented rule, from scipy's Wilson interval."""
    if not passed + failed:
        return "inconclusive"
    ci = binomtest(passed, passed + failed).proportion_ci(confidence_level=CONFIDENCE, method="wilson")
    if ci.low >= REQUIRED:
        return "passed"
    if ci.high < REQUIRED:
        return "failed"
    return "flaky" if passed and failed else "inconclusive"


def _exit_of(outcomes: list[str]) -> int:
    return 1 if {"failed", "flaky"} & set(outcomes) else 3 if "inconclusive" in outcomes else 0


@pytest.fixture(scope="module")
def baseline_yard(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A project folder whose store holds four clean runs and the baseline built from them."""
    folder = tmp_path_factory.mktemp("yard_trials")
    write_map(folder, size=200)
    (folder / "spec.exsce").write_text(YARD_SPEC)
    scenario = load_spec(folder / "spec.exsce").scenario()
    clean = [str(run.bag) for run in simulate(scenario, folder / "baseline", 4, seed=1)]
    assert exscec_here("ingest", *clean, "--scenario", "spec.exsce", cwd=folder).returncode == 0
    built = exscec_here("baseline", "spec.exsce", cwd=folder)
    assert built.returncode == 0, built.stderr
    return folder


@pytest.fixture
def yard(baseline_yard: Path, tmp_path: Path) -> Path:
    """A copy of the project folder, store and all: each test's trials stay its own."""
    return Path(shutil.copytree(baseline_yard, tmp_path / "yard"))


def _stored_counts(folder: Path) -> dict[tuple[str, str, str | None], tuple[int, int, int]]:
    """(oracle, relation, window) → runs passed, failed, inconclusive, from the stored verdicts."""
    with api.open_store(str(folder / ".exsce" / "store")) as store:
        table = api.verdicts(store, "yard_run")
    counts = {}
    for (oracle, relation, window), rows in table.groupby(["oracle", "relation", "window"], dropna=False):
        seen = rows["outcome"].value_counts()
        key = (str(oracle), str(relation), None if window != window else str(window))  # NaN: no window
        counts[key] = (
            int(seen.get("passed", 0)),
            int(seen.get("failed", 0)),
            int(seen.get("inconclusive", 0)),
        )
    return counts


def test_repeated_fault_free_runs_give_each_clause_the_outcome_of_its_counts(yard: Path) -> None:
    done = exscec_here(
        "verify", "--scenario", "spec.exsce", "--repeat", "6", "--seed", "11", "-o", "repeat",
        "--json", "--junit", "trial.xml", cwd=yard,
    )  # fmt: skip
    clauses = json.loads(done.stdout)
    assert len(list((yard / "repeat").glob("*.bag"))) == 6
    stored = _stored_counts(yard)
    assert len(clauses) == len(stored) == 11  # 3 safety clauses per robot or mission, 3 performance per robot
    for c in clauses:
        counts = (c["passed"], c["failed"], c["inconclusive"])
        assert sum(counts) == 6, c
        assert stored[(c["oracle"], c["relation"], c["window"])] == counts  # the runs' own verdicts
        assert c["outcome"] == _expected_outcome(c["passed"], c["failed"]), c
        if c["relation"] in ("below_max", "above_min"):  # nothing unsafe happens without a fault
            assert (c["passed"], c["outcome"]) == (6, "inconclusive")
            assert "16 passing runs show a pass rate of 0.8 at 95 %" in c["reason"]
    assert done.returncode == _exit_of([c["outcome"] for c in clauses]), done.stderr
    root = ET.parse(yard / "trial.xml").getroot()
    assert len(root.findall("testsuite/testcase")) == 11
    assert root.findall("testsuite")[0].get("name") == "yard_run trial of 6 runs"


def test_a_trial_of_clean_and_over_speed_bags_finds_the_clause_flaky(yard: Path) -> None:
    scenario = load_spec(yard / "spec.exsce").scenario()
    clean = [str(r.bag) for r in simulate(scenario, yard / "clean", 3, seed=21)]
    fast = [
        str(r.bag)
        for r in simulate(scenario, yard / "fast", 2, seed=22, faults=(Fault.parse("overspeed:r1"),))
    ]
    done = exscec_here(
        "verify",
        *clean,
        *fast,
        "--scenario",
        "spec.exsce",
        "--trial",
        "--json",
        "--junit",
        "mixed.xml",
        cwd=yard,
    )
    assert done.returncode == 1, done.stderr  # a flaky clause fails the trial
    clauses = {(c["oracle"], c["window"]): c for c in json.loads(done.stdout)}
    speed = clauses[("r1-max_velocity", None)]
    assert (speed["passed"], speed["failed"], speed["inconclusive"], speed["outcome"]) == (3, 2, 0, "flaky")
    ci = binomtest(3, 5).proportion_ci(confidence_level=0.95, method="wilson")
    assert (speed["low"], speed["high"]) == pytest.approx((ci.low, ci.high))
    assert clauses[("r2-max_velocity", None)]["passed"] == 5  # r2 drove as ever
    for c in clauses.values():
        assert c["outcome"] == _expected_outcome(c["passed"], c["failed"]), c

    root = ET.parse(yard / "mixed.xml").getroot()
    (case,) = [c for c in root.iter("testcase") if c.get("name") == "r1 max_velocity below_max"]
    failure = case.find("failure")
    assert failure is not None and failure.get("type") == "flaky"
    props = {p.get("name"): p.get("value") for p in case.iter("property")}
    assert (props["runs"], props["passed"], props["failed"], props["pass_rate"]) == ("5", "3", "2", "0.6000")

    listed = exscec_here("flaky", "yard_run", "--format", "json", cwd=yard)
    assert listed.returncode == 0, listed.stderr
    ranked = json.loads(listed.stdout)
    rates = [c["pass_rate"] for c in ranked]
    assert rates == sorted(rates) and rates[0] == pytest.approx(0.6)  # 3 of 5 is the lowest stored
    top = [c["oracle"] for c in ranked if c["pass_rate"] == rates[0]]
    assert "r1-max_velocity" in top
    table = exscec_here("flaky", cwd=yard).stdout.splitlines()
    assert table[0].split()[:2] == ["scenario", "clause"]
    assert table[1].split()[0] == "yard_run" and table[1].split()[-1] == "flaky"

    with api.open_store(str(yard / ".exsce" / "store")) as store:
        from_api = api.flaky(store, "yard_run")
    assert [(c.key.oracle, c.passed, c.failed) for c in from_api] == [
        (c["oracle"], c["passed"], c["failed"]) for c in ranked
    ]

    assert exscec_here("report", "-o", "report", cwd=yard).returncode == 0
    page = (yard / "report" / "scenario-yard_run.html").read_text()
    rates = page[
        page.index("<h2>Pass rates, lowest first</h2>") : page.index("<h2>Verdicts, failures first</h2>")
    ]
    start = rates.index('<tr class="')
    first_row = rates[start : rates.index("</tr>", start)]
    assert 'class="flaky"' in first_row and 'class="badge flaky"' in first_row
    assert ">0.60<" in first_row and ">[0.23, 0.88]<" in first_row  # scipy: 3 of 5 is [0.231, 0.882]


def test_trials_refuse_what_they_cannot_judge(yard: Path) -> None:
    nothing = exscec_here("verify", "--scenario", "spec.exsce", cwd=yard)
    assert nothing.returncode == 2 and "--repeat N" in nothing.stderr
    seedless = exscec_here("verify", "abcd1234", "--scenario", "spec.exsce", "--seed", "3", cwd=yard)
    assert seedless.returncode == 2 and "--repeat" in seedless.stderr
    rate = exscec_here(
        "verify", "--scenario", "spec.exsce", "--repeat", "2", "--required-pass-rate", "1", cwd=yard
    )
    assert rate.returncode == 2 and "0<x<1" in rate.stderr
    unknown = exscec_here("flaky", "yard_rn", cwd=yard)
    assert unknown.returncode == 2 and "did you mean 'yard_run'?" in unknown.stderr
