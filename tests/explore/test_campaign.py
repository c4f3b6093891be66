"""Campaigns on the shipped scenario_c with the real executor, store and oracles: a planted
fault found and shrunk, the minimal derivation reproducing with ``exscec verify``, a campaign
killed half-way finished by the same command without redoing its trials, and an executor that
is another program."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from exsce_dsl.errors import ExsceError
from exsce_dsl.explore.campaign import CampaignOptions, run_campaign
from exsce_dsl.explore.executors import CommandExecutor
from exsce_dsl.lang import load_spec
from exsce_dsl.model.campaign import CheckedRelation
from exsce_dsl.store.open import open_store
from exsce_dsl.store.queries import derivation_of
from exsce_dsl.store.queries.campaigns import campaign_record, campaigns

ROOT = Path(__file__).resolve().parents[2]
EXSCEC = str(Path(sys.executable).parent / "exscec")
SPEC = "examples/brsu_building_c/scenario_c.exsce"
DEADLOCK = "deadlock-start:tiago1:classroom_c025-w002"
"""Revealed by swapping the start poses of tiago1 and tiago2 (see exsce_dsl.sim.faults)."""


@pytest.fixture
def project(tmp_path: Path) -> Path:
    shutil.copytree(ROOT / "examples", tmp_path / "examples")
    return tmp_path


def _env(project: Path) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if not k.startswith("EXSCE_") or k == "EXSCE_CACHE"}
    return env | {"EXSCE_STORE": str(project / "store")}


def _exscec(project: Path, *args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [EXSCEC, *args], cwd=project, env=_env(project), capture_output=True, text=True, timeout=600
    )


def test_a_planted_deadlock_is_found_shrunk_and_reproduced_by_verify(project: Path) -> None:
    explored = _exscec(
        project, "explore", SPEC, "-n", "1", "-k", "1", "-t", "swap_start_poses", "-t", "reverse_task_order",
        "--fault", DEADLOCK, "-o", "campaign", "--junit", "campaign.xml",
    )  # fmt: skip
    assert explored.returncode == 1, explored.stderr
    assert "Traceback" not in explored.stderr
    with open_store(str(project / "store")) as store:
        (plan,) = campaigns(store)
        record = campaign_record(store, plan.id)
        assert record is not None
        (trial,) = record.trials
        assert len(trial.steps) == 2  # one swap, one reversal: the covering draw takes both names
        assert {name for name, _ in trial.steps} == {"swap_start_poses", "reverse_task_order"}
        assert trial.violated
        # every violated relation was shrunk; the deadlock's own symptom, task durations far off
        # their expected values, to the swap alone (the reversal is not needed)
        assert {s.relation for s in record.shrinkings} == set(trial.violated)
        durations = [s for s in record.shrinkings if s.relation.text.endswith("task_duration invariant")]
        assert len(durations) == 2
        for shrinking in durations:
            assert [name for name, _ in shrinking.minimal_steps] == ["swap_start_poses"]
            assert shrinking.tries[-1].violated and shrinking.tries[-1].steps == shrinking.minimal_steps
        assert all(len(s.minimal_steps) <= 2 for s in record.shrinkings)
        minimal = durations[0].minimal
        derivation = derivation_of(store, minimal)
        assert derivation is not None and [s.transformation for s in derivation.steps] == ["swap_start_poses"]
    file = project / "campaign" / "minimal" / f"{minimal}.exsce"
    assert file.is_file() and f"acceptance for {minimal}" in file.read_text()
    assert (
        f"exscec verify campaign/runs/{minimal}/*.bag --scenario {file.relative_to(project)}"
        in explored.stdout
    )
    # the minimal file reproduces the violation: the runs the campaign made, and new ones
    again = _exscec(project, "verify", *map(str, (project / "campaign" / "runs" / minimal).glob("*.bag")),
                    "--scenario", str(file))  # fmt: skip
    assert again.returncode == 1, again.stdout + again.stderr
    fresh = _exscec(project, "simulate", str(file), "--seed", "77", "--fault", DEADLOCK, "-o", "fresh")
    assert fresh.returncode == 0, fresh.stderr
    judged = _exscec(project, "verify", *map(str, (project / "fresh").glob("*.bag")), "--scenario", str(file))
    assert judged.returncode == 1, judged.stdout
    assert "task_duration" in judged.stdout
    junit = (project / "campaign.xml").read_text()
    assert 'failures="1"' in junit and "swap_start_poses" in junit


def test_a_killed_campaign_goes_on_without_redoing_its_trials(project: Path) -> None:
    command = [
        EXSCEC, "explore", SPEC, "-n", "3", "-k", "1", "--max-steps", "1",
        "-t", "swap_start_poses", "-t", "reverse_waypoint_order", "-o", "campaign",
    ]  # fmt: skip
    process = subprocess.Popen(command, cwd=project, env=_env(project), stderr=subprocess.PIPE, text=True)
    assert process.stderr is not None
    seen = []
    for line in process.stderr:  # not a terminal: one line per trial
        seen.append(line)
        if line.startswith("trial 2/3"):
            process.send_signal(signal.SIGKILL)
            break
    process.wait(timeout=60)
    assert process.returncode == -signal.SIGKILL, "".join(seen)
    bags = sorted((project / "campaign" / "runs").rglob("*.bag"))
    before = {bag: bag.stat().st_mtime_ns for bag in bags}
    assert len(before) == 3 + 2  # the base's three runs, one run of each trial done

    finished = subprocess.run(
        command, cwd=project, env=_env(project), capture_output=True, text=True, timeout=600
    )
    assert finished.returncode in (0, 1), finished.stderr
    lines = finished.stderr.splitlines()
    assert "going on with campaign_" in lines[0] and "2 trial(s) done already" in lines[0]
    assert [line.endswith("(done before)") for line in lines if line.startswith("trial ")] == [
        True,
        True,
        False,
    ]
    for bag, stamp in before.items():
        assert bag.stat().st_mtime_ns == stamp, f"{bag} was made again"
    assert len(list((project / "campaign" / "runs").rglob("*.bag"))) == 3 + 3
    with open_store(str(project / "store")) as store:
        (plan,) = campaigns(store)
        record = campaign_record(store, plan.id)
        assert record is not None
        assert [t.number for t in record.trials] == [1, 2, 3]
        assert len({t.scenario for t in record.trials}) == 3


def test_another_program_can_execute_the_scenarios(project: Path) -> None:
    # the executor is exscec simulate in a process of its own, as a user's simulator would be
    executor = CommandExecutor(
        f"{EXSCEC} simulate {{scenario_file}} --runs {{runs}} --seed {{seed}} -o {{out}}"
    )
    spec = load_spec(project / SPEC)
    options = CampaignOptions(
        budget=1, runs_per_scenario=2, max_steps=1, transformations=("swap_start_poses",)
    )
    with open_store("memory:") as store:
        result = run_campaign(store, spec, project / SPEC, options, executor, project / "c")
        (trial,) = result.record.trials
        assert len(trial.runs) == 2 and trial.checked
        assert result.record.plan.executor.startswith("command: ")
        assert len(list((project / "c" / "runs" / trial.scenario).glob("*.bag"))) == 2


def test_an_executor_command_with_an_unknown_placeholder_is_refused() -> None:
    with pytest.raises(ExsceError, match="placeholder"):
        CommandExecutor("my-sim --scenario {scenario_path}")


def test_a_relation_reads_back_from_its_text() -> None:
    for relation in (
        CheckedRelation("task_duration", "tiago1", "invariant"),
        CheckedRelation("task_duration", "tiago1", "increasing", "scenario_c"),
        CheckedRelation("distance_between_robots", None, "above_min"),
    ):
        assert CheckedRelation.parse(relation.text) == relation
