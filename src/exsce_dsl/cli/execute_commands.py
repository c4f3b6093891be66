"""``exscec execute``: a scenario's mission on a live robot stack, recorded, and judged."""

from __future__ import annotations

import sys
from collections import Counter
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from exsce_dsl.cli.common import ExitCode, exit_status, reports_errors
from exsce_dsl.cli.store_commands import store_option
from exsce_dsl.cli.trial_commands import trial_options

if TYPE_CHECKING:
    from exsce_dsl.api.execution import ExecutedRun
    from exsce_dsl.model import Scenario

POLICIES = ("skip-waypoint", "retry-once", "skip-task", "stop-mission")
"""``Policy`` values (``exsce_dsl.execute.outcomes``), spelled here so that ``--help`` imports nothing."""


@dataclass(frozen=True)
class _ExecuteOptions:
    """``exscec execute``'s arguments and options, as click gives them."""

    spec: str
    ros1: bool
    ros2: bool
    scenario_id: str | None
    runs: int
    out_dir: str
    start_master: bool
    policy: str
    server_timeout: float
    goal_timeout: float | None
    stand_in: bool
    seed: int
    faults: tuple[str, ...]
    speed_up: float
    judge: bool
    junit: str | None
    required_pass_rate: float
    confidence: float
    store_url: str | None


@click.command(
    epilog=exit_status(
        passed="every run done (with --verify: every oracle passed)",
        failed="--verify: an oracle failed (several runs: a clause failed or is flaky)",
        inconclusive="--verify: an oracle was inconclusive (a run cut short or not covered by its "
        "recording; several runs: too few to tell), and none failed",
        bad_input="bad input, no ROS master, or an action server that never answered (no bag is left)",
        interrupted="Ctrl-C or SIGTERM: the goals cancelled, the run cut short kept in -o DIR/incomplete/",
    )
)
@click.argument("spec", type=click.Path(dir_okay=False))
@click.option("--ros1", is_flag=True, help="Run on a ROS 1 graph (rospy, actionlib, rosbag).")
@click.option(
    "--ros2",
    is_flag=True,
    help="Run on the ROS 2 graph of $ROS_DOMAIN_ID (rclpy, Nav2's NavigateToPose, a rosbag2 MCAP bag).",
)
@click.option("--scenario", "scenario_id", help="Which scenario, when the file declares several.")
@click.option("--runs", "-n", default=1, show_default=True, type=click.IntRange(1), help="How many runs.")
@click.option(
    "-o",
    "--output",
    "out_dir",
    type=click.Path(file_okay=False),
    default="runs",
    show_default=True,
    help="Folder for each run's .bag, .prov.json and .rosparams (--ros2: bag folder, .prov.json and "
    ".params.yaml).",
)
@click.option(
    "--start-master", is_flag=True, help="With --ros1: start a roscore of our own (else: $ROS_MASTER_URI)."
)
@click.option(
    "--policy",
    type=click.Choice(POLICIES),
    default="skip-waypoint",
    show_default=True,
    help="What a goal that is aborted, rejected or timed out leads to.",
)
@click.option(
    "--server-timeout",
    type=click.FloatRange(min=0, min_open=True),
    default=10.0,
    show_default=True,
    metavar="S",
    help="Wall seconds to wait for every robot's action server.",
)
@click.option(
    "--goal-timeout",
    type=click.FloatRange(min=0, min_open=True),
    metavar="S",
    help="ROS seconds a goal may take when its task and mission say no 'timeout' "
    "[default: 3x the straight line at the speed limit, at least 60].",
)
@click.option(
    "--stand-in",
    "stand_in",
    is_flag=True,
    help="Serve the goals with exsce's stand-in robots (exscec stand-in), started for each run: "
    "the whole loop without a robot.",
)
@click.option(
    "--seed",
    type=int,
    default=0,
    show_default=True,
    help="With --stand-in: run i drives as run i of exscec simulate --seed SEED.",
)
@click.option(
    "--fault",
    "faults",
    multiple=True,
    metavar="FAULT",
    help="With --stand-in: a fault of exscec simulate planted in the stand-in (overspeed:tiago1, ...).",
)
@click.option(
    "--speed-up",
    type=click.FloatRange(min=0, min_open=True),
    default=5.0,  # execute.stand_in.session.DEFAULT_SPEED_UP (a test holds them equal)
    show_default=True,
    help="With --stand-in: simulated time runs this many times faster than wall time.",
)
@click.option("--verify", "judge", is_flag=True, help="Ingest each run's bag and judge it, as exscec verify.")
@click.option("--junit", type=click.Path(dir_okay=False), help="With --verify: a JUnit XML report.")
@trial_options
@store_option
@reports_errors
def execute(**given: Any) -> None:
    """Run a scenario's mission on a live ROS graph, record each run, judge it.

    The scenario goes on the parameter server (/scenario); one actionlib
    client per robot sends its waypoints as move_base goals
    (move_base_msgs/MoveBaseAction on /<namespace>/move_base, in the map
    frame), all robots at once (parallel) or one at a time (sequential);
    rosbag record runs from before the first goal to after the last, on the
    topics the metrics and the robots' conventions need, /tf, /tf_static,
    /clock and /exsce/prov, where the run-time PROV is published (latched).
    Each run leaves <date>_<scenario>_run-<id>.bag, .prov.json and
    .rosparams in -o DIR, moved there only when whole.  Goal times are ROS
    times: simulated time under /use_sim_time.

    Ctrl-C or SIGTERM cancels the active goals, closes the bag and keeps the
    run in DIR/incomplete/ (its PROV says cancelled), where DIR/*.bag does not
    reach it; the exit status is 130.

    With --verify each run is judged as exscec verify judges it, with its
    exit status: 0 every oracle passed, 1 one failed, 3 one was inconclusive
    (a run whose mission stopped is cut short: what it met is inconclusive,
    never passed; a limit it broke fails), 2 bad input.

    On your robot's graph (roscore and each robot's move_base up, and
    $ROS_MASTER_URI exported), three judged runs are
    exscec execute SPEC --ros1 --runs 3 --verify --junit verdicts.xml.
    Several runs with --verify are one trial, as exscec verify --trial
    judges it: a pass rate per clause, and a flaky clause fails (exit 1).
    Without a robot, --stand-in serves the goals with exsce's stand-in
    robots (exscec stand-in: move_base servers, odometry, TF, scans, on
    simulated time), started afresh for each run, with --fault planted.

    With --ros2 the goals go to each robot's Nav2
    (nav2_msgs/action/NavigateToPose on /<namespace>/navigate_to_pose), from
    a node exsce_dispatcher that holds the scenario as its parameters;
    exsce's recorder subscribes to the same topics and writes a rosbag2 MCAP
    folder (metadata.yaml with each topic's QoS and type hash); /clock, when
    something publishes it, is the clock (use_sim_time).  Each run leaves the
    bag folder <date>_<scenario>_run-<id>, .prov.json and .params.yaml.

    \b
    Examples:
      exscec execute examples/brsu_building_c/scenario_c.exsce --ros1 --start-master --stand-in \\
          --fault overspeed:tiago1 -o live-fault/
      exscec execute examples/brsu_building_c/scenario_c.exsce --ros1 --start-master --runs 3 \\
          --policy retry-once --verify --junit verdicts.xml --server-timeout 1 \\
          -o live/  # exits 2: no robot's move_base answers
      exscec execute examples/brsu_building_c/scenario_c.exsce --ros2 --stand-in --fault overspeed:tiago1 \\
          -o live-ros2/
    """
    from exsce_dsl.api import load

    options = _ExecuteOptions(**given)
    if options.ros1 == options.ros2:
        raise click.UsageError("say --ros1 or --ros2: the graph to run on")
    if options.ros2 and options.start_master:
        raise click.UsageError("--start-master goes with --ros1 (a ROS 2 graph has no master)")
    scenario = load(options.spec).scenario(options.scenario_id)
    done = _execute_runs(scenario, options)
    for run in done:
        counts = Counter(r.outcome.value for r in run.mission.records)
        said = ", ".join(f"{n} {outcome}" for outcome, n in sorted(counts.items()))
        click.echo(
            f"wrote {run.files.bag} (mission {run.mission.status.value}: {said or 'no goal'})", err=True
        )
    if options.judge:
        sys.exit(_judge(scenario, [r.files.bag for r in done], options))


def _execute_runs(scenario: Scenario, options: _ExecuteOptions) -> list[ExecutedRun]:
    """The runs on the live graph; interrupted, what was kept is said and the exit status is 130."""
    from exsce_dsl.api import execute_ros1, execute_ros2
    from exsce_dsl.errors import ExecutionInterrupted

    common = {
        "policy": options.policy,
        "server_timeout": options.server_timeout,
        "timeout": options.goal_timeout,
        "stand_in": options.stand_in,
        "seed": options.seed,
        "faults": options.faults,
        "speed_up": options.speed_up,
    }
    try:
        if options.ros2:
            return execute_ros2(scenario, options.out_dir, options.runs, **common)  # type: ignore[arg-type]
        return execute_ros1(
            scenario,
            options.out_dir,
            options.runs,
            start_master=options.start_master,
            **common,  # type: ignore[arg-type]
        )
    except ExecutionInterrupted as stop:
        click.echo(f"error: {stop.message}", err=True)
        if stop.incomplete is not None:
            click.echo(f"kept apart: {stop.incomplete}", err=True)
        for bag in stop.complete:
            click.echo(f"wrote {bag}", err=True)
        sys.exit(ExitCode.INTERRUPTED)


def _judge(scenario: Scenario, bags: list[Path], options: _ExecuteOptions) -> ExitCode:
    """--verify: the bags ingested and judged as exscec verify judges them (several: one trial)."""
    from exsce_dsl.api import open_store, verify
    from exsce_dsl.cli.oracle_commands import report_verification

    with open_store(options.store_url) as store:
        verification = verify(store, scenario, bags)
    if options.runs > 1:
        from exsce_dsl.api import trial_of
        from exsce_dsl.cli.trial_commands import report_trial

        trial = trial_of(verification, options.required_pass_rate, options.confidence)
        return report_trial(trial, False, options.junit)
    return report_verification(verification, False, options.junit)


COMMANDS = [execute]
