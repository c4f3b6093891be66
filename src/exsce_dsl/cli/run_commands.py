"""Commands on runs: simulate (bags from the kinematic executor) and ingest (bags into the store)."""

from __future__ import annotations

import sys
from typing import TYPE_CHECKING

import click

from exsce_dsl.cli.common import (
    REMEDIES,
    ExitCode,
    Progress,
    bag_arguments,
    exit_status,
    reports_errors,
    simulator_options,
)
from exsce_dsl.model.conventions import CONVENTIONS

if TYPE_CHECKING:
    from exsce_dsl.api import IngestResult


@click.command(epilog=exit_status(bad_input="bad input, or a run that could not be played"))
@click.argument("spec", type=click.Path(dir_okay=False))
@click.option("--runs", "-n", default=1, show_default=True, type=click.IntRange(1), help="How many runs.")
@click.option(
    "-o",
    "--output",
    "out_dir",
    type=click.Path(file_okay=False),
    default="runs",
    show_default=True,
    help="Folder for the bags.",
)
@click.option(
    "--format",
    "fmt",
    type=click.Choice(["ros1", "ros2", "mcap"]),
    default="ros1",
    show_default=True,
    help="ROS 1 .bag, ROS 2 sqlite3 or MCAP.",
)
@click.option("--seed", default=0, show_default=True, type=int, help="Same seed, same bytes.")
@click.option(
    "--fault",
    "faults",
    multiple=True,
    metavar="NAME[:ARGS]",
    help="A deliberate fault (repeatable). Shown in every run: overspeed:ROBOT, slow:ROBOT, "
    "skip-waypoint:ROBOT[:N], near-collision. Shown only when the scenario has the trigger "
    "(latent, for metamorphic campaigns): slow-area:AREA (40 % speed once in AREA, until the "
    "waypoint), detour:FROM:TO (legs from area FROM to area TO go via the start pose), "
    "deadlock-start:ROBOT:POSE (every robot stands 120 s when ROBOT starts at POSE), "
    "overspeed-many-tasks:N (a robot with more than N tasks drives over 1 m/s), "
    "overspeed-reassigned:TASK:ROBOT (a robot other than ROBOT given TASK drives over 1 m/s).",
)
@click.option("--scenario", "scenario_id", help="Which scenario, when the file declares several.")
@click.option(
    "--convention",
    type=click.Choice(list(CONVENTIONS)),
    help="Which topics the robots publish: the method's, Nav2's or move_base's "
    "[default: the convention the robots' types name, else the method's].",
)
@click.option(
    "--cmd-vel-stamped",
    is_flag=True,
    help="nav2, move_base: cmd_vel as TwistStamped (Nav2 from Jazzy on), not Twist.",
)
@click.option(
    "--cluster",
    "dask_address",
    metavar="ADDRESS",
    help="A Dask scheduler (tcp://host:8786): each run is one task on its workers, which write the "
    "bags into --output themselves, so --output (and the map files) must be the same path on every "
    "worker (a shared filesystem).  The same bags as without.  Default: $EXSCE_DASK_SCHEDULER.",
)
@simulator_options
@reports_errors
def simulate(
    spec: str,
    runs: int,
    out_dir: str,
    fmt: str,
    seed: int,
    faults: tuple[str, ...],
    scenario_id: str | None,
    convention: str | None,
    cmd_vel_stamped: bool,
    dask_address: str | None,
    simulator: str,
    behaviour: str | None,
    scans: str | None,
) -> None:
    """Play a scenario in a simulator and write one bag per run.

    The kinematic executor (the default) plans around the occupied cells of
    the environment's map and drives with bounded speed and acceleration and
    seeded noise.  --simulator irsim plays each run in IR-SIM: the map as
    its obstacle grid, each leg's path planned by exsce, the driving,
    collisions and (with --scans irsim) the scans IR-SIM's (docs/irsim.md);
    it plays the speed faults and skip-waypoint.  Per robot
    namespace the bag holds, by --convention:

    \b
      method     robot_pose, scan, nav_vel, distance_travelled and the
                 waypoint dispatcher's feedback and result
      nav2       tf (odom -> base_link, map -> odom), tf_static, odom,
                 amcl_pose, cmd_vel, scan, plan and navigate_to_pose's
                 status and feedback, one goal per waypoint
      move_base  the same robot topics and move_base's goal, status,
                 feedback and result

    \b
    Latent faults (--fault) stay hidden in scenario_c's runs and show in
    one derivation of it:
      slow-area:classroom_c069                   replace_robot --robot tiago2 --by tiago3
                                                 --start classroom_c069-w001
      detour:classroom_c018:classroom_c022       reverse_waypoint_order --task delivery_a
      deadlock-start:tiago1:classroom_c025-w002  swap_start_poses --robot tiago1 --with tiago2
      overspeed-many-tasks:2                     remove_robot --robot tiago2 --reassign tiago1
      overspeed-reassigned:delivery_a:tiago1     swap_assignment --robot tiago1 --with tiago2

    With --cluster, each run is played by a Dask cluster's worker, which
    writes its bag and .prov.json into --output (a task is tried twice; a
    killed worker's runs go to another).  A run that failed even so is named
    by its index at the end, and the exit status is 2.

    \b
    Example:
      exscec simulate examples/brsu_building_c/scenario_c.exsce --runs 3 -o runs/
      exscec simulate examples/brsu_building_c/scenario_c.exsce --fault overspeed:tiago1 -o runs/faulty/
      exscec simulate examples/brsu_building_c/scenario_c.exsce --convention nav2 --format mcap -o runs/
      exscec simulate examples/brsu_building_c/scenario_c.exsce --simulator irsim -o runs/irsim/
    """
    from exsce_dsl.api import dask_address as scheduler_address
    from exsce_dsl.api import load, simulating

    scenario = load(spec).scenario(scenario_id)
    played = simulating(
        scenario, out_dir, runs, format=fmt, seed=seed, faults=faults, convention=convention,
        cmd_vel_stamped=cmd_vel_stamped, dask_address=scheduler_address(dask_address),
        simulator=simulator, behaviour=behaviour, scans=scans,
    )  # fmt: skip
    with Progress(runs, f"simulating {scenario.id}") as progress:
        for run in played:
            progress.update()
            progress.say(f"wrote {run.bag} ({run.messages} messages, {run.execution.duration:.1f} s)")


@click.command(epilog=exit_status(bad_input="a bag could not be ingested (the others were), or bad input"))
@click.argument("bags", nargs=-1, required=True, type=click.Path())
@click.option(
    "--scenario",
    "spec",
    required=True,
    type=click.Path(dir_okay=False),
    help="The .exsce file of the scenario the bags are runs of.",
)
@click.option("--scenario-id", help="Which scenario, when the file declares several.")
@click.option(
    "--jobs", "-j", default=1, show_default=True, type=click.IntRange(1), help="Bags analysed in parallel."
)
@click.option(
    "--cluster",
    "dask_address",
    metavar="ADDRESS",
    envvar="EXSCE_DASK_SCHEDULER",
    help="A Dask scheduler (tcp://host:8786): its workers read the bags and compute their metrics "
    "instead of --jobs processes; the bags' paths must be the same on every worker (a shared "
    "filesystem).  Default: $EXSCE_DASK_SCHEDULER.",
)
@click.option(
    "--verbose", "-v", is_flag=True, help="Also say which clock each of a bag's topics was timed by."
)
@click.option(
    "--replace",
    is_flag=True,
    help="Analyse bags the store holds as runs of this scenario again, under this spec, and replace "
    "each such run (its graphs, in one transaction; its verdicts are dropped).",
)
@click.option(
    "--strict",
    is_flag=True,
    help="A bag whose run would lack a metric value (a topic not in the bag, no pose, a window "
    "without data) fails, and nothing of it is stored.",
)
@click.option("--store", "store_url", envvar="EXSCE_STORE", help="Store URL (default: .exsce/store).")
@reports_errors
def ingest(
    bags: tuple[str, ...],
    spec: str,
    scenario_id: str | None,
    jobs: int,
    dask_address: str | None,
    verbose: bool,
    replace: bool,
    strict: bool,
    store_url: str | None,
) -> None:
    """Compute the metrics of bags and add each run's provenance to the store.

    Each run is stored wholly or not at all (runs that come faster than one
    by one are committed in groups): a bag that cannot be used is reported
    and nothing of it is written, and the other bags still ingest.  A bag already
    ingested as a run of this scenario (same content) is skipped, unless --replace:
    then it is analysed again (a spec with a new metric, a fixed convention) and its
    run replaced, keeping its id; the run's verdicts are dropped (verify it again).
    A bag may be a run of several scenarios, one run each.  It says the convention it detected for
    each robot whose type names none, and the run's timeline when its stamps are
    simulated time, once for all the bags that share them (-v: for each bag, and
    the clock of every topic).  Exits 2 if any bag failed.  With
    --cluster, a Dask cluster's workers analyse the bags (a task is tried
    twice; a killed worker's tasks go to another) and exscec writes each
    run, as with --jobs.  With --strict, a run that would lack a metric value
    is an error (which values, and why) and is not stored.

    \b
    Examples:
      exscec ingest runs/*.bag --scenario examples/brsu_building_c/scenario_c.exsce
      exscec ingest --replace runs/*.bag --scenario examples/brsu_building_c/scenario_c.exsce
      exscec ingest runs/*.bag --scenario examples/brsu_building_c/scenario_c.exsce --strict
    """
    from exsce_dsl.api import ingest_files, load_cached

    scenario = load_cached(spec).scenario(scenario_id)
    paths = bag_arguments(bags)
    if not paths:
        raise click.UsageError("no bag among the files given")
    said: set[str] = set()
    with Progress(len(paths), "ingesting") as progress:

        def shown(result: IngestResult) -> None:
            progress.update()
            progress.say(f"{'error: ' if result.failed else ''}{result.said(REMEDIES)}")
            for line in result.picked + (result.clocks if verbose else ()):
                if verbose or line not in said:  # what every bag shares is said once
                    progress.say(f"  {line}")
                    said.add(line)
            for problem in result.problems:
                progress.say(f"warning: {result.bag}: {problem}")

        _, tally = ingest_files(
            store_url, scenario, paths, jobs=jobs, on_result=shown, dask_address=dask_address,
            replace=replace, strict=strict,
        )  # fmt: skip
    again = f"{tally.replaced} replaced, " if replace else ""
    click.echo(f"{tally.ingested} ingested, {again}{tally.skipped} skipped, {tally.failed} failed", err=True)
    if tally.failed:
        sys.exit(ExitCode.BAD_INPUT)


COMMANDS = [simulate, ingest]
