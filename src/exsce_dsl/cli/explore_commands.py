"""``exscec explore``: a metamorphic test campaign on a scenario, its violations shrunk."""

from __future__ import annotations

import sys
from typing import TYPE_CHECKING, Any

import click

from exsce_dsl.cli.common import REMEDIES, ExitCode, Progress, exit_status, reports_errors, simulator_options
from exsce_dsl.cli.store_commands import store_option

if TYPE_CHECKING:
    from exsce_dsl.api import Exploration, ExploreRequest


@click.command(
    epilog=exit_status(
        passed="every relation checked held",
        failed="a metamorphic relation was violated",
        inconclusive="none was violated, but one was inconclusive: runs that could not judge it "
        "(cut short, not covered by their recordings) could have violated it",
        interrupted="Ctrl-C (and SIGTERM with --executor ros1 or ros2): the same command goes on where it "
        "stopped",
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
    help="Plant a fault in the simulator, or in the stand-in robots of --executor ros1|ros2 --stand-in "
    "(repeatable), as exscec simulate --fault: to try a campaign.",
)  # fmt: skip
@simulator_options
@click.option(
    "--executor-command",
    help="Run scenarios with this program instead of the simulator; placeholders {scenario_file} "
    "{scenario} {runs} {seed} {out}; it must leave one bag per run in {out}.",
)
@click.option(
    "--executor", "plugin",
    help="Run scenarios with this executor: ros1 or ros2 (built in: a live ROS 1 or ROS 2 graph, "
    "with --stand-in) "
    "or an exsce.executors plug-in.",
)  # fmt: skip
@click.option(
    "--stand-in", is_flag=True,
    help="With --executor ros1|ros2: exsce's stand-in robots serve the goals, started for each run "
    "(the only robots it drives for now).",
)  # fmt: skip
@click.option(
    "--start-master", is_flag=True,
    help="With --executor ros1: a roscore of the campaign's own, stopped at its end "
    "[default: $ROS_MASTER_URI, else a roscore of its own].",
)  # fmt: skip
@click.option(
    "--speed-up", type=click.FloatRange(0, min_open=True),
    help="With --executor ros1|ros2: the stand-in's simulated time runs this many times faster "
    "than wall time [default: 5].",
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
    Its first line counts relations (distinct checks violated, and
    inconclusive but never violated), its second trials.  What a derived
    scenario's criteria leave out (a robot given no tasks has no performance
    clause) is said in a note as its trial starts.
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

    With --executor ros2 --stand-in the runs are played on the live ROS 2
    graph of $ROS_DOMAIN_ID as exscec execute --ros2 --stand-in plays them:
    Nav2 NavigateToPose goals, exsce's recorder writing each run's rosbag2
    MCAP folder, exsce's Nav2 stand-in robots serving the goals.

    \b
    Examples:
      exscec explore examples/brsu_building_c/scenario_c.exsce -n 2 -k 1 -t reverse_waypoint_order
      exscec explore examples/brsu_building_c/scenario_c.exsce -n 1 -k 1 -t swap_start_poses \\
        --fault deadlock-start:tiago1:classroom_c025-w002 -o explore/deadlock --junit campaign.xml  # exits 1
      exscec explore examples/brsu_building_c/scenario_c.exsce -n 2 -k 1 --max-steps 1 --no-shrink \\
        -t swap_start_poses -t reverse_task_order --fault deadlock-start:tiago1:classroom_c025-w002 \\
        --compare-random -o explore/compared  # exits 1
      exscec explore examples/irsim_crossing/crossing.exsce -n 4 -k 1 --simulator irsim  # exits 1
      exscec explore examples/brsu_building_c/scenario_c.exsce -n 1 -k 1 -t swap_start_poses \\
        --executor ros1 --stand-in --start-master \\
        --fault deadlock-start:tiago1:classroom_c025-w002 -o explore/live  # exits 1
    """
    from exsce_dsl.api import ExploreRequest

    request = ExploreRequest(**given)
    found = _run_campaigns(request)
    for line in found.summary_lines(REMEDIES):
        click.echo(line)
    undecided = ExitCode.INCONCLUSIVE if found.inconclusive else ExitCode.PASSED
    sys.exit(ExitCode.FAILED if found.violated else undecided)


def _run_campaigns(request: ExploreRequest) -> Exploration:
    """The campaign (and its random baseline with --compare-random), each trial said as it ends.
    Ctrl-C exits 130: the same command goes on from there."""
    from exsce_dsl.api import explore
    from exsce_dsl.errors import ExecutionInterrupted
    from exsce_dsl.model.campaign import CampaignTrial

    with Progress(request.trials, "Exploring") as progress:

        def trial_done(who: str, trial: CampaignTrial, resumed: bool) -> None:
            shown = trial.violated or trial.inconclusive
            found = f": {'; '.join(r.text for r in shown)}" if shown else ""
            done = " (done before)" if resumed else ""
            number = f"{trial.number}/{request.budget}"
            progress.say(f"{who}trial {number} {trial.scenario} {trial.outcome}{found}{done}")
            progress.update()

        try:
            return explore(request, progress.say, trial_done)
        except ExecutionInterrupted as stop:  # the campaign goes on where it stopped, run again
            click.echo(f"error: {stop.message}", err=True)
            sys.exit(ExitCode.INTERRUPTED)


COMMANDS = [explore]
