"""``exscec demo``: the whole method on the shipped example, from an empty folder to a report.

A thin layer over :mod:`exsce_dsl.api.demo`, which holds the steps (the commands
``docs/tutorial.md`` has a user type), runs them and judges their outcomes; here each step's
command line runs in-process, and what happens is printed.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import click

from exsce_dsl.cli.common import ExitCode, exit_status, reports_errors

if TYPE_CHECKING:
    from exsce_dsl.api.demo import DemoStep


def _refuse_with_ros1(ros1: bool, convention: bool, simulator: bool, ros2: bool = False) -> None:
    """--ros1 (--ros2) plays exsce's stand-in in move_base's (Nav2's) convention: no other
    convention or simulator."""
    if ros1 and ros2:
        raise click.UsageError("--ros1 or --ros2: one live graph")
    flag = "--ros2" if ros2 else "--ros1"
    if (ros1 or ros2) and convention:
        raise click.UsageError(f"{flag} plays the robots in its own convention: leave out --convention")
    if (ros1 or ros2) and simulator:
        raise click.UsageError(f"{flag} plays exsce's stand-in robots: leave out --simulator and --behaviour")


def _where(ros1: bool, convention: str, simulator: str, ros2: bool = False) -> str:
    """What the demo's heading says of where its runs are played."""
    if ros1:
        return " on a live ROS 1 graph"
    if ros2:
        return f" on the live ROS 2 graph of domain {os.environ.get('ROS_DOMAIN_ID') or 0}"
    robots = "" if convention == "method" else f" (robots on {convention}'s topics)"
    return robots + ("" if simulator == "kinematic" else f", runs played by {simulator}")


def run_in_process(argv: Sequence[str]) -> int:
    """Run one exscec command line (the arguments after `exscec`) in this process; its exit status."""
    from exsce_dsl.cli.main import main

    try:
        main.main(list(argv), prog_name="exscec", standalone_mode=False)
    except SystemExit as exc:
        return exc.code if isinstance(exc.code, int) else 1
    except click.ClickException as exc:
        exc.show()
        return exc.exit_code
    return 0


@click.command(epilog=exit_status(failed="a step did not end as expected"))
@click.argument("folder", default="exsce-demo", type=click.Path(file_okay=False))
@click.option(
    "--store", "store_url", help="Use this store instead of the folder's own (e.g. a SPARQL endpoint)."
)
@click.option(
    "--setup-only", is_flag=True, help="Only copy the example into FOLDER/scenarios (for the tutorial)."
)
@click.option(
    "--convention",
    type=click.Choice(["method", "nav2", "move_base"]),
    default="method",
    show_default=True,
    help="Whose topics the robots publish: the example's robot types are given this convention, so "
    "every step runs on Nav2's (or move_base's) topics and types.",
)
@click.option(
    "--ros1",
    is_flag=True,
    help="The loop on a live ROS 1 graph instead: a roscore of the demo's own, exsce's stand-in robots "
    "serving move_base goals, exscec execute recording and judging each run (needs ROS 1: "
    "sh scripts/install-ros1).",
)
@click.option(
    "--ros2",
    is_flag=True,
    help="The loop on the live ROS 2 graph of $ROS_DOMAIN_ID instead: exsce's Nav2 stand-in robots "
    "serving NavigateToPose goals, exscec execute --ros2 recording and judging each run (needs "
    "ROS 2: pip install 'exsce[ros2]' && sh scripts/install-ros2).",
)
@click.option(
    "--simulator",
    default="kinematic",
    show_default=True,
    help="What plays the simulated runs: kinematic, or irsim (IR-SIM, pip install 'exsce[irsim]').",
)
@click.option(
    "--behaviour",
    type=click.Choice(["dash", "rvo", "orca", "sfm"]),
    help="irsim: IR-SIM's behaviour [default: rvo].",
)
@reports_errors
def demo(
    folder: str,
    store_url: str | None,
    setup_only: bool,
    convention: str,
    ros1: bool,
    ros2: bool,
    simulator: str,
    behaviour: str | None,
) -> None:
    """Run the whole method on the shipped example, in a new FOLDER.

    Copies the example (building C of the method, scenario_c with two TIAGo
    robots) into FOLDER/scenarios, then checks and compiles scenario_c into
    the store, simulates and ingests baseline runs, builds the baseline,
    verifies a new run and a run with a fault (which fails, as it should),
    derives a scenario without tiago2 with the oracles it must meet,
    simulates and verifies it, clusters the scenarios and writes the HTML
    report (open FOLDER/report/index.html in a browser).  Each step prints
    the command it runs: docs/tutorial.md walks the same path by hand.

    With --ros1 the runs are executed on a live ROS 1 graph instead
    (docs/live.md walks it by hand): a roscore of the demo's own, the robots
    played by exsce's stand-in in move_base's convention, each run's mission
    dispatched as move_base goals and recorded by rosbag record, baseline
    runs ingested, a new run and one with tiago1 driving too fast executed
    and judged: exscec demo live-demo --ros1 (about three minutes; the test
    suite runs it in tests/execute/test_live_loop.py).  With --ros2 the same
    loop runs on a live ROS 2 graph: the stand-in's robots are Nav2's
    (NavigateToPose), exsce's recorder writes each run's rosbag2 MCAP folder:
    exscec demo ros2-demo --ros2 (about two and a half minutes; the test
    suite runs it in tests/execute/test_ros2_live_loop.py).
    Exits 0 when every step ended as expected (the faulty run failing, the
    others passing), 1 otherwise.

    \b
    Example:
      exscec demo exsce-demo
      exscec demo my-project --setup-only   # only copy the example, to follow docs/tutorial.md
      exscec demo irsim-demo --simulator irsim   # the runs played by IR-SIM
    """
    from exsce_dsl.api.demo import (
        LIVE_ROS2_STEPS,
        LIVE_STEPS,
        STEPS,
        command_hint,
        live_graph,
        run_steps,
        set_up,
        simulated_by,
        summary_lines,
    )

    simulated = simulator != "kinematic" or behaviour is not None
    _refuse_with_ros1(ros1, convention != "method", simulated, ros2)
    target = Path(folder)
    set_up(target, "move_base" if ros1 else "nav2" if ros2 else convention)
    hint = command_hint(Path.cwd())
    if setup_only:
        click.echo(f"copied the example scenarios into {target / 'scenarios'}", err=True)
        if hint:
            click.echo(hint, err=True)
        return
    steps = LIVE_STEPS if ros1 else LIVE_ROS2_STEPS if ros2 else STEPS
    if simulator != "kinematic":
        steps = simulated_by(steps, simulator, behaviour)
    where = _where(ros1, convention, simulator, ros2)
    click.secho(f"exsce demo in {target.resolve()}{where}", bold=True, err=True)
    if hint:
        click.echo(f"{hint}, then 'cd {folder}'", err=True)
    announce = _announcer(len(steps))
    if ros1:
        with live_graph(target) as uri:
            click.echo(f"ROS_MASTER_URI={uri}", err=True)
            run = run_steps(target, run_in_process, store_url, steps, on_step=announce)
    else:
        run = run_steps(target, run_in_process, store_url, steps, on_step=announce)
    _say_summary(summary_lines(run, "docs/live.md" if ros1 or ros2 else "docs/tutorial.md"), hint)
    if not run.as_expected:
        sys.exit(ExitCode.FAILED)


def _announcer(count: int) -> Callable[[int, DemoStep], None]:
    """What says each step as it starts: its number, title and command."""

    def announce(number: int, step: DemoStep) -> None:
        click.secho(f"\n[{number}/{count}] {step.title}", bold=True, err=True)
        click.secho(f"$ {step.command}", fg="cyan", err=True)
        sys.stdout.flush()

    return announce


def _say_summary(lines: list[str], hint: str | None) -> None:
    click.secho(f"\n{lines[0]}", bold=True, err=True)
    for line in lines[1:]:
        click.echo(line, err=True)
    if hint:
        click.echo(f"  {hint}", err=True)


COMMANDS = [demo]
