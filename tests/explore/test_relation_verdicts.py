"""What a trial's runs say of a relation: violated when it failed in more than half of them,
inconclusive when the runs that could not judge it (cut short, not covered by their recordings)
could have made it so, else passed.  Hand-made verdicts, counted by hand."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

from exsce_dsl.cli.common import ExitCode
from exsce_dsl.explore.campaign import _violations
from exsce_dsl.model.campaign import CheckedRelation
from exsce_dsl.model.verdicts import Outcome, Verdict
from exsce_dsl.store.open import open_store
from exsce_dsl.store.queries.campaigns import campaign_record, campaigns

ROOT = Path(__file__).resolve().parents[2]
EXSCEC = str(Path(sys.executable).parent / "exscec")
SPEC = "examples/brsu_building_c/scenario_c.exsce"

SPEED = CheckedRelation("max_velocity", "tiago1", "below_max")


def _verdicts(*outcomes: Outcome) -> list[Verdict]:
    return [
        Verdict(f"run{n}", "s", "c", "tiago1-max_velocity", "max_velocity", "tiago1", "below_max", outcome)
        for n, outcome in enumerate(outcomes)
    ]


P, F, U = Outcome.PASSED, Outcome.FAILED, Outcome.INCONCLUSIVE  # U: undecided


def test_a_single_run_cut_short_leaves_its_relation_inconclusive_not_passed() -> None:
    found = _violations(_verdicts(U), 1)
    assert found.checked == (SPEED,) and found.violated == () and found.inconclusive == (SPEED,)


def test_a_majority_failing_violates_and_one_that_undecided_runs_could_make_is_inconclusive() -> None:
    cases = {
        (F, F, P): ("violated", ()),  # 2 of 3 failed
        (F, U, P): ("inconclusive", (SPEED,)),  # 1 failed; with the undecided one, 2 of 3
        (U, U, P): ("inconclusive", (SPEED,)),  # nothing failed, but 2 of 3 could have
        (U, P, P): ("passed", ()),  # 2 of 3 passed: the third cannot change it
        (F, P, P): ("passed", ()),
        (F, P): ("passed", ()),  # half is not more than half, as before
        (U, P): ("passed", ()),
        (F, U): ("inconclusive", (SPEED,)),
    }
    for outcomes, (expected, undecided) in cases.items():
        found = _violations(_verdicts(*outcomes), len(outcomes))
        outcome = "violated" if found.violated else "inconclusive" if found.inconclusive else "passed"
        assert (outcome, found.inconclusive) == (expected, undecided), outcomes
        if found.violated:
            assert found.failing == tuple(
                (f"run{n}", "verdict-tiago1-max_velocity-below_max") for n, o in enumerate(outcomes) if o is F
            )


CUTTING_EXECUTOR = '''\
"""exscec simulate, then each derived scenario's runs marked cut short in their run-time PROV,
as exscec execute marks a run whose mission was cancelled (the base's runs stay whole)."""
import glob, json, subprocess, sys

exscec, spec, scenario, runs, seed, out = sys.argv[1:]
subprocess.run([exscec, "simulate", spec, "--scenario", scenario, "--runs", runs, "--seed", seed, "-o", out], check=True)
if scenario != "scenario_c":
    for path in glob.glob(f"{out}/*.prov.json"):
        document = json.load(open(path))
        for bundle in document["bundle"].values():
            for activity in bundle.get("activity", {}).values():
                if activity.get("prov:type", {}).get("$") == "exsce:run":
                    activity["exsce:mission_status"] = "cancelled"
        json.dump(document, open(path, "w"))
'''


def test_a_campaign_whose_runs_were_cut_short_finds_its_relations_inconclusive_and_exits_3(
    tmp_path: Path,
) -> None:
    """The simulator cannot cut a run short, and the ros1 executor keeps a cut run apart; a user's
    executor can hand one over: here, exscec simulate whose derived runs say 'cancelled'."""
    shutil.copytree(ROOT / "examples", tmp_path / "examples")
    (tmp_path / "cutting.py").write_text(CUTTING_EXECUTOR)
    command = f"{sys.executable} cutting.py {EXSCEC} {{scenario_file}} {{scenario}} {{runs}} {{seed}} {{out}}"
    env = {k: v for k, v in os.environ.items() if not k.startswith("EXSCE_") or k == "EXSCE_CACHE"}
    env |= {"EXSCE_STORE": "store"}
    explored = subprocess.run(
        [EXSCEC, "explore", SPEC, "-n", "1", "-k", "1", "-t", "swap_start_poses", "--no-shrink",
         "--executor-command", command, "-o", "campaign", "--junit", "campaign.xml"],
        cwd=tmp_path, env=env, capture_output=True, text=True, timeout=900,
    )  # fmt: skip
    assert explored.returncode == ExitCode.INCONCLUSIVE, explored.stdout + explored.stderr
    assert "0 relations violated, " in explored.stdout and " inconclusive" in explored.stdout, explored.stdout
    with open_store(str(tmp_path / "store")) as store:
        (plan,) = campaigns(store)
        record = campaign_record(store, plan.id)
    assert record is not None
    (trial,) = record.trials
    assert trial.outcome == "inconclusive" and trial.violated == ()
    assert set(trial.inconclusive) == set(trial.checked)  # one run, cut short: nothing decided
    suite = ET.parse(tmp_path / "campaign.xml").getroot()[0]
    assert (suite.get("failures"), suite.get("skipped")) == ("0", "1")
