"""A campaign's figures (counterexamples per 100 executions, executions to the first failure):
counted by hand from trials, from verdicts that did not decide, and from a real campaign with a
planted deadlock that keeps going after its first failure, beside its random baseline."""

from __future__ import annotations

import datetime
import json
import re
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET
from dataclasses import replace
from pathlib import Path

import pytest

from exsce_dsl.errors import ExsceError
from exsce_dsl.explore.campaign import CampaignOptions, _violations, run_campaign
from exsce_dsl.explore.executors import SimulatorExecutor
from exsce_dsl.explore.figures import figures_table, random_baseline
from exsce_dsl.lang import load_spec
from exsce_dsl.model.campaign import CampaignFigures, CampaignPlan, CampaignTrial, CheckedRelation
from exsce_dsl.model.verdicts import Outcome, Verdict
from exsce_dsl.oracles.campaign_junit import campaign_junit_xml
from exsce_dsl.prov.campaign import compile_campaign, compile_trial
from exsce_dsl.store.open import open_store
from exsce_dsl.store.queries.campaigns import campaign_record, campaigns
from exsce_dsl.store.queries.terms import run_query
from exsce_dsl.store.writing import add_prov

ROOT = Path(__file__).resolve().parents[2]
EXSCEC = str(Path(sys.executable).parent / "exscec")
SPEC = "examples/brsu_building_c/scenario_c.exsce"
DEADLOCK = "deadlock-start:tiago1:classroom_c025-w002"
"""Revealed by swapping the start poses of tiago1 and tiago2 (see exsce_dsl.sim.faults)."""

SPEED = CheckedRelation("max_velocity", "tiago1", "below_max")
DURATION = CheckedRelation("task_duration", "tiago1", "invariant")
LONGER = CheckedRelation("task_duration", "tiago1", "increasing")
"""The same check as DURATION: an expected value missed, whichever way the estimate went."""


def _trial(
    number: int, runs: int, violated: tuple[CheckedRelation, ...] = (), inconclusive: tuple[CheckedRelation, ...] = ()
) -> CampaignTrial:
    uuids = tuple(f"run{number}-{i}" for i in range(runs))
    return CampaignTrial("campaign_x", number, f"s{number}", (), uuids, (SPEED, DURATION), violated, (), inconclusive)


def test_the_figures_of_trials_counted_by_hand() -> None:
    trials = [
        _trial(1, 3),
        _trial(2, 2, inconclusive=(DURATION,)),
        _trial(3, 3, violated=(DURATION,)),
        _trial(4, 2),
        _trial(5, 3, violated=(LONGER, SPEED)),
    ]
    figures = CampaignFigures.of(trials)
    # executions 3+2+3+2+3 = 13; trials 3 and 5 violated; the first failure is trial 3's, after
    # 3+2+3 = 8 runs; DURATION and LONGER are one check, so two relations; trial 2 inconclusive
    assert figures == CampaignFigures(
        trials=5,
        executions=13,
        counterexamples=2,
        violated_relations=2,
        inconclusive=1,
        executions_to_first_failure=8,
    )
    assert figures.per_100_executions == pytest.approx(200 / 13)
    none = CampaignFigures.of([_trial(1, 2), _trial(2, 2)])
    assert none.executions_to_first_failure is None and none.per_100_executions == 0.0
    assert CampaignFigures.of([]).per_100_executions is None


def _verdict(run: str, relation: CheckedRelation, outcome: Outcome) -> Verdict:
    return Verdict(run, "s", "", "o", relation.metric, relation.robot, relation.relationship, outcome)


def test_a_relation_neither_failed_nor_passed_in_most_runs_is_inconclusive() -> None:
    P, F, U = Outcome.PASSED, Outcome.FAILED, Outcome.INCONCLUSIVE  # U: undecided
    runs = {
        SPEED: (P, P, U),  # passed in 2 of 3: passed
        DURATION: (F, U, P),  # failed in 1, passed in 1: neither
        CheckedRelation("distance_travelled", "tiago1", "invariant"): (F, F, U),  # failed in 2 of 3: violated
        CheckedRelation("distance_travelled", "tiago2", "invariant"): (U, U, P),  # passed in 1 of 3: neither
    }
    verdicts = [
        _verdict(f"r{i}", relation, o) for relation, outcomes in runs.items() for i, o in enumerate(outcomes)
    ]
    judged = _violations(verdicts, 3)
    assert set(judged.checked) == set(runs)
    assert judged.violated == (CheckedRelation("distance_travelled", "tiago1", "invariant"),)
    assert set(judged.inconclusive) == {DURATION, CheckedRelation("distance_travelled", "tiago2", "invariant")}
    trial = CampaignTrial("c", 1, "s", (), ("r0", "r1", "r2"), judged.checked, (), (), judged.inconclusive)
    assert trial.outcome == "inconclusive"  # neither a counterexample nor a pass
    assert CampaignFigures.of([trial]).counterexamples == 0


def test_the_table_puts_each_campaign_in_a_column() -> None:
    found = CampaignFigures(trials=3, executions=6, counterexamples=2, violated_relations=4, inconclusive=0,
                            executions_to_first_failure=2)  # fmt: skip
    missed = CampaignFigures(trials=3, executions=6, counterexamples=0, violated_relations=0, inconclusive=1,
                             executions_to_first_failure=None)  # fmt: skip
    lines = figures_table([("covering", found), ("random", missed)])
    assert lines[0].split() == ["covering", "random"]
    rows = {line[:22].strip(): line[22:].split() for line in lines[1:]}
    assert rows["per 100 executions"] == ["33.3", "0.0"]  # 100 × 2 / 6
    assert rows["to first failure"] == ["2", "none", "in", "6"]
    assert rows["relations inconclusive"] == ["0", "0"]
    assert rows["inconclusive trials"] == ["0", "1"]


def test_a_random_campaign_has_no_random_baseline_of_its_own() -> None:
    with pytest.raises(ExsceError, match="at random already"):
        random_baseline(CampaignOptions(budget=2, strategy="random"))
    assert random_baseline(CampaignOptions(budget=2, seed=4)) == CampaignOptions(
        budget=2, seed=4, strategy="random", shrink=False
    )


def _campaign_in(store_path: Path, strategy: str) -> tuple[str, list[CampaignTrial]]:
    with open_store(str(store_path)) as store:
        (plan,) = [p for p in campaigns(store) if p.strategy == strategy]
        record = campaign_record(store, plan.id)
    assert record is not None
    return plan.id, list(record.trials)


def _counted(trials: list[CampaignTrial]) -> dict[str, str]:
    """The figures of ``trials``, counted here, as the table prints them."""
    executed, first = 0, None
    for trial in trials:
        executed += len(trial.runs)
        if trial.violated and first is None:
            first = executed
    found = sum(1 for t in trials if t.violated)
    return {
        "executions": str(executed),
        "counterexamples": str(found),
        "per 100 executions": f"{100 * found / executed:.1f}",
        "to first failure": f"none in {executed}" if first is None else str(first),
    }


def test_a_campaign_that_keeps_going_finds_the_deadlock_again_beside_its_random_baseline(
    tmp_path: Path,
) -> None:
    shutil.copytree(ROOT / "examples", tmp_path / "examples")
    store = tmp_path / "store"
    command = [
        EXSCEC, "explore", SPEC, "-n", "3", "-k", "1", "-t", "swap_start_poses", "-t", "reverse_task_order",
        "--fault", DEADLOCK, "--no-shrink", "--compare-random", "-o", "campaign", "--store", str(store),
    ]  # fmt: skip
    done = subprocess.run(command, cwd=tmp_path, capture_output=True, text=True, timeout=900)
    assert done.returncode == 1, done.stdout + done.stderr
    assert "Traceback" not in done.stderr
    covering_id, covering = _campaign_in(store, "covering")
    random_id, random = _campaign_in(store, "random")
    # the whole budget was tried, and each covering draw swaps the start poses: more than one counterexample
    assert len(covering) == 3 and sum(1 for t in covering if t.violated) >= 2
    assert len(random) == 3 and all(len(t.runs) == 1 for t in covering + random)
    table = done.stdout[done.stdout.index("covering") :].splitlines()
    assert table[0].split() == ["covering", "random"]
    rows = {cells[0]: cells[1:] for cells in (re.split(r"\s{2,}", line.strip()) for line in table[1:8])}
    for name, value in _counted(covering).items():
        assert rows[name][0] == value, done.stdout
    for name, value in _counted(random).items():
        assert rows[name][1] == value, done.stdout
    assert rows["derivations tried"] == ["3", "3"]
    assert re.search(r"random baseline campaign_\w+: campaign-random", done.stdout)
    # the store keeps the figures on each campaign's activity
    queried = subprocess.run(
        [EXSCEC, "query", "campaigns", "-f", "json", "--store", str(store)], cwd=tmp_path, capture_output=True,
        text=True, timeout=120,
    )  # fmt: skip
    assert queried.returncode == 0, queried.stderr
    stored = {
        row["campaign"]["value"]: {k: v["value"] for k, v in row.items()}
        for row in json.loads(queried.stdout)["results"]["bindings"]
    }
    for campaign_id, trials in ((covering_id, covering), (random_id, random)):
        counted = _counted(trials)
        assert stored[campaign_id]["executions"] == counted["executions"]
        assert stored[campaign_id]["counterexamples"] == counted["counterexamples"]
        assert f"{float(stored[campaign_id]['per_100_executions']):.1f}" == counted["per 100 executions"]
        first = stored[campaign_id].get("to_first_failure")
        assert (first or f"none in {counted['executions']}") == counted["to first failure"]

    # the same campaign stopped at its first violation: its trials are read back, none run again,
    # and the figures end with the first violating trial
    spec = load_spec(tmp_path / SPEC)
    options = CampaignOptions(
        budget=3, runs_per_scenario=1, transformations=("reverse_task_order", "swap_start_poses"),
        shrink=False, stop_at_violation=True,
    )  # fmt: skip
    with open_store(str(store)) as opened:
        executor = SimulatorExecutor.with_faults([DEADLOCK])
        stopped = run_campaign(opened, spec, tmp_path / SPEC, options, executor, tmp_path / "campaign")
    assert stopped.record.plan.id == covering_id and stopped.executions == 0
    first = next(t.number for t in covering if t.violated)
    assert stopped.figures.trials == first and stopped.figures.counterexamples == 1
    assert str(stopped.figures.executions_to_first_failure) == _counted(covering)["to first failure"]


def test_an_inconclusive_trial_and_the_figures_read_back_from_the_store() -> None:
    plan = CampaignPlan("c_fig", "scenario_c", 3, 0, 2, 1, (), "simulator", "covering", True, 25.0)
    trials = [
        _trial(1, 2, inconclusive=(DURATION,)),
        _trial(2, 2, violated=(SPEED,)),
        _trial(3, 2),
    ]
    trials = [replace(t, campaign="c_fig") for t in trials]
    figures = CampaignFigures.of(trials)
    started = datetime.datetime(2025, 3, 1, 12, 0, tzinfo=datetime.timezone.utc)
    with open_store("memory:") as store:
        add_prov(store, compile_campaign(plan, started), replace=True)
        for trial in trials:
            add_prov(store, compile_trial(trial))
        add_prov(store, compile_campaign(plan, started, figures, started), replace=True)  # as a campaign ends
        record = campaign_record(store, "c_fig")
        (row,) = run_query(store, "campaigns", {})
    assert record is not None and list(record.trials) == trials
    assert [t.outcome for t in record.trials] == ["inconclusive", "violated", "passed"]
    assert record.figures == figures
    # 6 executions, 1 counterexample after 4 of them, 1 trial inconclusive
    stored = {name: None if term is None else term.value for name, term in row.items()}
    assert (stored["executions"], stored["counterexamples"], stored["to_first_failure"]) == ("6", "1", "4")
    assert (stored["inconclusive_trials"], stored["violated_relations"]) == ("1", "1")
    assert float(stored["per_100_executions"] or "nan") == pytest.approx(100 / 6)
    suite = ET.fromstring(campaign_junit_xml(record))[0]
    first = suite.findall("testcase")[0].find("skipped")
    assert first is not None and str(first.get("message")).startswith("inconclusive: tiago1 task_duration invariant")
    assert (suite.get("failures"), suite.get("skipped")) == ("1", "1")
