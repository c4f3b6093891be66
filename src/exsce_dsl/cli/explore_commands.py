"""``exscec explore``: a metamorphic test campaign on a scenario, its violations shrunk."""

from __future__ import annotations

import sys
from contextlib import AbstractContextManager
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from exsce_dsl.cli.common import ExitCode, Progress, exit_status, reports_errors
from exsce_dsl.cli.store_commands import store_option
from exsce_dsl.wording import counted

if TYPE_CHECKING:
    from exsce_dsl.explore.campaign import CampaignOptions, CampaignResult
    from exsce_dsl.explore.executors import Executor


@dataclass(frozen=True)
class _ExploreOptions:
    """``exscec explore``'s arguments and options, as click gives them."""

    spec: str
    scenario_id: str | None
    budget: int
    seed: int
    runs_per_scenario: int
    transformations: tuple[str, ...]
    max_steps: int
    strategy: str
    tolerance: float
    no_shrink: bool
    stop_at_violation: bool
    compare_random: bool
    faults: tuple[str, ...]
    executor_command: str | None
    plugin: str | None
    stand_in: bool
    start_master: bool
    speed_up: float | None
    jobs: int
    dask_address: str | None
    output: str | None
    junit: str | None
    store_url: str | None


@click.command(
    epilog=exit_status(
        passed="every relation checked held",
        failed="a metamorphic relation was violated",
        inconclusive="none was violated, but one was inconclusive: runs that could not judge it "
        "(cut short, not covered by their recordings) could have violated it",
        interrupted="Ctrl-C (and SIGTERM with --executor ros1): the same command goes on where it stopped",
    )
)
@click.argument("spec", type=click.Path(dir_okay=False, exists=True))
@click.option("--scenario-id", help="Which scenario, when the file declares several.")
@click.option("--budget", "-n", required=True, type=click.IntRange(1), help="Derivations to try.")
@click.option("--seed", default=0, show_default=True, type=int, help="Same seed, same derivations.")
@click.option(
    "--runs-per-scenario", "-k", default=3, show_default=True, type=click.IntRange(1),
    help="Runs of each derived scenario; a relation is violated when it fails in more than half.",
)  # fmt: skip
@click.option(
    "--transformations", "-t", multiple=True,
    help="Only these transformations (repeatable) [default: every one].",
)  # fmt: skip
@click.option(
    "--max-steps", default=2, show_default=True, type=click.IntRange(1), help="Steps per derivation."
)
@click.option(
    "--strategy", type=click.Choice(["covering", "random"]), default="covering", show_default=True,
    help="covering: spread the budget over the steps that apply; random: uniform draws.",
)  # fmt: skip
@click.option(
    "--tolerance", default=25.0, show_default=True, type=click.FloatRange(0, min_open=True),
    help="Percent of an expected value a run may be off.",
)  # fmt: skip
@click.option("--no-shrink", is_flag=True, help="Do not shrink the violations found.")
@click.option(
    "--stop-at-violation", is_flag=True,
    help="End the draws at the first trial that violates a relation [default: try the whole "
    "budget, so that counterexamples per 100 executions covers all of it].",
)  # fmt: skip
@click.option(
    "--compare-random", is_flag=True,
    help="Also run the same budget with uniform random draws (same relations, no shrinking; its "
    "files in OUTPUT-random) and print both campaigns' figures side by side.",
)  # fmt: skip
@click.option(
    "--fault", "faults", multiple=True,
    help="Plant a fault in the simulator, or in the stand-in robots of --executor ros1 --stand-in "
    "(repeatable), as exscec simulate --fault: to try a campaign.",
)  # fmt: skip
@click.option(
    "--executor-command",
    help="Run scenarios with this program instead of the simulator; placeholders {scenario_file} "
    "{scenario} {runs} {seed} {out}; it must leave one bag per run in {out}.",
)
@click.option(
    "--executor", "plugin",
    help="Run scenarios with this executor: ros1 (built in: a live ROS 1 graph, with --stand-in) "
    "or an exsce.executors plug-in.",
)  # fmt: skip
@click.option(
    "--stand-in", is_flag=True,
    help="With --executor ros1: exsce's stand-in robots serve the goals, started for each run "
    "(the only robots it drives for now).",
)  # fmt: skip
@click.option(
    "--start-master", is_flag=True,
    help="With --executor ros1: a roscore of the campaign's own, stopped at its end "
    "[default: $ROS_MASTER_URI, else a roscore of its own].",
)  # fmt: skip
@click.option(
    "--speed-up", type=click.FloatRange(0, min_open=True),
    help="With --executor ros1: the stand-in's simulated time runs this many times faster "
    "than wall time [default: 10].",
)  # fmt: skip
@click.option(
    "--jobs", "-j", default=1, show_default=True, type=click.IntRange(1), help="Bags analysed in parallel."
)
@click.option(
    "--cluster",
    "dask_address",
    metavar="ADDRESS",
    help="A Dask scheduler (tcp://host:8786): the simulator's runs are played and every bag is "
    "analysed on its workers, which must see the campaign's folder (--output) at the same path "
    "(a shared filesystem); --executor-command and --executor still run here.  The same campaign "
    "as without.  Default: $EXSCE_DASK_SCHEDULER.",
)
@click.option(
    "--output", "-o", type=click.Path(file_okay=False),
    help="Folder of the campaign's files [default: explore/<campaign id>].",
)  # fmt: skip
@click.option("--junit", type=click.Path(dir_okay=False), help="Also write the campaign as JUnit XML.")
@store_option
@reports_errors
def explore(**given: Any) -> None:
    """Explore derivations of a scenario to find a fault, and shrink what fails.

    Draws BUDGET derivations (compositions of up to --max-steps applicable
    transformations, no two giving the same scenario), derives each with the
    relations its runs must meet (exscec derive --expect), runs it, ingests
    and verifies the runs, and records every trial as provenance in the
    store.  Then each violated relation is shrunk to a smallest derivation
    that still violates it, written to OUTPUT/minimal/ with its criteria.

    The summary gives the campaign's figures: executions (runs of the drawn
    derivations), counterexamples (trials that violated a relation), their
    rate per 100 executions and the executions to the first failure; trials
    neither violated nor passed (verdicts inconclusive) are counted apart.
    --compare-random runs the same budget with uniform random draws as well
    and prints both campaigns' figures in one table.

    The store is the campaign's state: the same command after a kill goes on
    where it stopped, and a larger --budget goes on with the same campaign.
    The base needs 3 stored runs (the campaign runs them if it has fewer).
    A relation is violated when it failed in more than half of a trial's
    runs, and inconclusive (neither passed nor a counterexample) when it
    would be had the runs that could not judge it (cut short, not covered
    by their recordings) failed it.  It exits 0 when every relation held, 1
    when one was violated, 3 when none was but one was inconclusive, 2 on
    bad input.

    With --cluster, a Dask cluster's workers play the simulator's runs (one
    task a run, writing the bags into the campaign's folder) and analyse
    every bag; exscec writes the store.  The campaign, its derivations and
    its verdicts are those it has without --cluster.

    With --executor ros1 --stand-in, every run is played on a live ROS 1
    graph as exscec execute --ros1 --stand-in plays it: move_base goals
    from the dispatcher node, the bag written by rosbag record, exsce's
    stand-in robots (started for each run, run i of a scenario driving as
    run i of exscec simulate with that scenario's seed) serving the goals
    with --fault planted.  The graph is $ROS_MASTER_URI's, else (or with
    --start-master) a roscore the campaign starts once and stops at its
    end.  It drives only the stand-in for now: exsce cannot yet move a real
    stack's robots to each derived scenario's start poses between runs (a
    script that resets your simulator and runs exscec execute --ros1 can
    be an --executor-command).

    \b
    Examples:
      exscec explore examples/brsu_building_c/scenario_c.exsce -n 2 -k 1 -t reverse_waypoint_order
      exscec explore examples/brsu_building_c/scenario_c.exsce -n 1 -k 1 -t swap_start_poses \\
        --fault deadlock-start:tiago1:classroom_c025-w002 -o explore/deadlock --junit campaign.xml  # exits 1
      exscec explore examples/brsu_building_c/scenario_c.exsce -n 2 -k 1 --max-steps 1 --no-shrink \\
        -t swap_start_poses -t reverse_task_order --fault deadlock-start:tiago1:classroom_c025-w002 \\
        --compare-random -o explore/compared  # exits 1
      exscec explore examples/brsu_building_c/scenario_c.exsce -n 1 -k 1 -t swap_start_poses \\
        --executor ros1 --stand-in --start-master \\
        --fault deadlock-start:tiago1:classroom_c025-w002 -o explore/live  # exits 1
    """
    from exsce_dsl.oracles.campaign_junit import campaign_junit

    options = _ExploreOptions(**given)
    result, random, durations = _run_campaigns(options)
    _summary(result, random)
    if options.junit:
        Path(options.junit).write_text(campaign_junit(result.record, durations), encoding="utf-8")
    violated = any(t.violated for t in result.record.trials)
    undecided = any(t.inconclusive for t in result.record.trials)
    sys.exit(ExitCode.FAILED if violated else ExitCode.INCONCLUSIVE if undecided else ExitCode.PASSED)


def _run_campaigns(
    options: _ExploreOptions,
) -> tuple[CampaignResult, CampaignResult | None, dict[str, float]]:
    """The campaign (and its random baseline with --compare-random), each trial said as it ends;
    with --junit, its runs' durations.  Ctrl-C exits 130: the same command goes on from there."""
    from exsce_dsl.errors import ExecutionInterrupted
    from exsce_dsl.explore.campaign import CampaignEvents, run_campaign
    from exsce_dsl.explore.figures import random_baseline
    from exsce_dsl.lang import load_spec
    from exsce_dsl.model.campaign import Trial
    from exsce_dsl.oracles.campaign_junit import run_seconds
    from exsce_dsl.store.open import open_store

    chosen, campaign = _executor(options)
    baseline = random_baseline(campaign) if options.compare_random else None
    parsed = load_spec(options.spec)
    total = options.budget * (2 if baseline else 1)
    with chosen as executor, open_store(options.store_url) as store, Progress(total, "Exploring") as progress:

        def events(who: str) -> CampaignEvents:
            def trial_done(trial: Trial, resumed: bool) -> None:
                shown = trial.violated or trial.inconclusive
                found = f": {'; '.join(r.text for r in shown)}" if shown else ""
                done = " (done before)" if resumed else ""
                budget = options.budget
                progress.say(
                    f"{who}trial {trial.number}/{budget} {trial.scenario} {trial.outcome}{found}{done}"
                )
                progress.update()

            return CampaignEvents(said=progress.say, trial_done=trial_done)

        def run(plan: CampaignOptions, output: str | None, who: str) -> CampaignResult:
            return run_campaign(
                store, parsed, options.spec, plan, executor, output,
                scenario_id=options.scenario_id, events=events(who),
            )  # fmt: skip

        try:
            result = run(campaign, options.output, "")
            random = None
            if baseline is not None:
                where = f"{options.output.rstrip('/')}-random" if options.output else None
                random = run(baseline, where, "random: ")
        except ExecutionInterrupted as stop:  # the campaign goes on where it stopped, run again
            click.echo(f"error: {stop.message}", err=True)
            sys.exit(ExitCode.INTERRUPTED)
        durations = run_seconds(store, result.record) if options.junit else {}
    return result, random, durations


def _executor(options: _ExploreOptions) -> tuple[AbstractContextManager[Executor], CampaignOptions]:
    """What runs the scenarios and the campaign's plan, from the options."""
    from exsce_dsl.explore.campaign import CampaignOptions
    from exsce_dsl.explore.executors import ExecutorOptions, chosen_executor
    from exsce_dsl.parallel.dask_client import dask_address as scheduler_address

    o = options
    address = scheduler_address(o.dask_address)
    given = ExecutorOptions(o.faults, o.stand_in, o.start_master, None, o.speed_up)
    chosen = chosen_executor(o.executor_command, o.plugin, given, address)
    campaign = CampaignOptions(
        budget=o.budget,
        seed=o.seed,
        runs_per_scenario=o.runs_per_scenario,
        max_steps=o.max_steps,
        transformations=o.transformations,
        strategy=o.strategy,
        tolerance=o.tolerance,
        shrink=not o.no_shrink,
        stop_at_violation=o.stop_at_violation,
        jobs=o.jobs,
        dask_address=address,
    )
    return chosen, campaign


def _summary(result: CampaignResult, random: CampaignResult | None) -> None:
    """What the campaign found, its figures (beside the random baseline's) and its shrinkings."""
    from exsce_dsl.explore.figures import figures_table, first_failure, per_100
    from exsce_dsl.oracles.campaign_junit import steps_text

    record, figures = result.record, result.figures
    violated = {r.text for t in record.trials for r in t.violated}
    undecided = {r.text for t in record.trials for r in t.inconclusive} - violated
    tried = len(record.trials)
    found = f"{counted(tried, 'derivation')} tried, {counted(len(violated), 'relation')} violated"
    if undecided:
        found += f", {len(undecided)} inconclusive"
    click.echo(f"campaign {record.plan.id}: {found}")
    click.echo(f"  files: {result.folder}")
    if random is None:
        inconclusive = f"; {figures.inconclusive} inconclusive" if figures.inconclusive else ""
        found = counted(figures.counterexamples, "counterexample")
        click.echo(
            f"  {counted(figures.executions, 'execution')}, {found}"
            f" ({per_100(figures)} per 100 executions), first failure after: {first_failure(figures)}"
            f"{inconclusive}"
        )
    else:
        click.echo(f"  random baseline {random.record.plan.id}: {random.folder}")
        for line in figures_table([(record.plan.strategy, figures), ("random", random.figures)]):
            click.echo(f"  {line}")
    for shrinking in record.shrinkings:
        file = result.minimal_files.get(shrinking.relation.text)
        steps = steps_text(shrinking.minimal_steps)
        click.echo(f"violated: {shrinking.relation.text} (trial {shrinking.trial})")
        count = len(shrinking.minimal_steps)
        click.echo(f"  smallest derivation ({counted(count, 'step')}): {steps}")
        if file is not None:
            bags = result.folder / "runs" / shrinking.minimal
            click.echo(f"  reproduce: exscec verify {bags}/*.bag --scenario {file}")


COMMANDS = [explore]
