"""``exscec stand-in``: the kinematic executor as live ROS 1 or ROS 2 robots, until stopped."""

from __future__ import annotations

import os
import signal
from types import FrameType
from typing import TYPE_CHECKING, Any

import click

from exsce_dsl.cli.common import exit_status, reports_errors

if TYPE_CHECKING:
    from exsce_dsl.model.document import Specification


@click.command("stand-in", epilog=exit_status(passed="stopped with Ctrl-C or SIGTERM"))
@click.argument("spec", type=click.Path(dir_okay=False))
@click.option("--ros1", is_flag=True, help="On a ROS 1 graph, as move_base robots.")
@click.option(
    "--ros2",
    is_flag=True,
    help="On the ROS 2 graph of $ROS_DOMAIN_ID, as Nav2 robots (needs ROS 2: sh scripts/install-ros2).",
)
@click.option("--scenario", "scenario_id", help="Which scenario, when the file declares several.")
@click.option("--seed", default=0, show_default=True, type=int, help="Seeds the speeds, drift and noise.")
@click.option(
    "--fault",
    "faults",
    multiple=True,
    metavar="NAME[:ARGS]",
    help="A deliberate fault, as exscec simulate's (repeatable): overspeed:ROBOT, slow:ROBOT, "
    "skip-waypoint:ROBOT[:N] (its N-th goal aborts), slow-area:AREA, detour:FROM:TO, "
    "deadlock-start:ROBOT:POSE, overspeed-many-tasks:N, overspeed-reassigned:TASK:ROBOT "
    "(near-collision is not played).",
)
@click.option(
    "--speed-up",
    default=5.0,  # execute.stand_in.session.DEFAULT_SPEED_UP (a test holds them equal)
    show_default=True,
    type=click.FloatRange(min=0.0, min_open=True),
    help="Simulated time (/clock) runs this many times faster than wall time.",
)
@click.option(
    "--simulator",
    type=click.Choice(["kinematic", "irsim"]),
    default="kinematic",
    show_default=True,
    help="With --ros2: what drives each goal's leg: the kinematic executor's motion, or IR-SIM "
    "(pip install 'exsce[irsim]').",
)
@click.option(
    "--behaviour",
    type=click.Choice(["dash", "rvo", "orca", "sfm"]),
    help="With --simulator irsim: IR-SIM's behaviour [default: rvo].",
)
@click.option(
    "--start-master",
    is_flag=True,
    help="With --ros1: start a roscore of its own on a free port (printed first), stopped at the "
    "end; else the one at $ROS_MASTER_URI.",
)
@click.option(
    "--log-dir",
    type=click.Path(file_okay=False),
    help="With --ros1: folder for the node's log (and the roscore's) [default: a new temporary "
    "folder, removed when the stand-in stops cleanly].",
)
@reports_errors
def stand_in(
    spec: str,
    ros1: bool,
    ros2: bool,
    scenario_id: str | None,
    seed: int,
    faults: tuple[str, ...],
    speed_up: float,
    simulator: str,
    behaviour: str | None,
    start_master: bool,
    log_dir: str | None,
) -> None:
    """Play a scenario's robots on a live ROS 1 or ROS 2 graph, as move_base or Nav2 robots.

    Per robot namespace: a move_base_msgs/MoveBaseAction server on
    move_base (a goal is planned on the environment's occupancy grid from
    where the robot stands, driven, and succeeds or aborts, with status,
    feedback and result; a cancel stops the robot where it is), odom, tf
    (odom -> base_link, map -> odom, with the odometry's drift),
    tf_static, amcl_pose, scan and cmd_vel, as `exscec simulate
    --convention move_base` writes them.  Between goals the robots stand
    still and every topic keeps publishing.  Time is simulated: the
    stand-in sets /use_sim_time and publishes /clock, --speed-up times
    faster than wall time (slower if it cannot keep up; on a busy machine
    a slower clock keeps rosbag record from losing messages).

    The first line on stdout is ROS_MASTER_URI=URI; it runs until Ctrl-C
    or SIGTERM.  Drive it with any actionlib client, or exscec execute.

    With --ros2 the robots are Nav2's: per namespace a
    nav2_msgs/action/NavigateToPose server on navigate_to_pose (feedback
    with current_pose and distance_remaining; a new goal preempts the
    active one, which aborts; a cancel stops the robot) and a
    FollowWaypoints server on follow_waypoints (a failed waypoint stops the
    goal, missed), the global plan on plan when a goal comes, odom, tf,
    tf_static (transient local), amcl_pose, scan and cmd_vel (Twist), and
    /clock for the graph: start the nodes that use it with use_sim_time.
    The first line on stdout is ROS_DOMAIN_ID=N, the domain of the
    environment (0 when unset).  Drive it with any rclpy or rclcpp action
    client, or exscec execute --ros2.  --simulator irsim drives each
    goal's leg in IR-SIM (its behaviour, kinematics and avoidance of the
    robots standing in the world) instead of the kinematic executor.

    \b
    Example:
      exscec stand-in examples/brsu_building_c/scenario_c.exsce --ros1 --start-master
      exscec stand-in examples/brsu_building_c/scenario_c.exsce --ros1 --start-master \\
          --fault overspeed:tiago1 --speed-up 5   # slower: a busy machine's recorder keeps up
      exscec stand-in examples/brsu_building_c/scenario_c.exsce --ros2 --fault overspeed:tiago1
      exscec stand-in examples/irsim_crossing/crossing.exsce --ros2 --simulator irsim
    """
    from exsce_dsl.api import load
    from exsce_dsl.api import stand_in as play

    _check_graph(
        ros1, ros2, start_master or log_dir is not None, simulator != "kinematic" or behaviour is not None
    )
    loaded = load(spec)

    def terminated(signum: int, frame: FrameType | None) -> None:
        raise KeyboardInterrupt

    previous = signal.signal(signal.SIGTERM, terminated)
    try:  # a stop before the stand-in serves (while it starts) is a stop too (exit 0)
        if ros2:
            _play_ros2(loaded, scenario_id, seed, faults, speed_up, simulator, behaviour)
            return
        with play(
            loaded, scenario=scenario_id, start_master=start_master, seed=seed, faults=faults,
            speed_up=speed_up, log_dir=log_dir,
        ) as running:  # fmt: skip
            click.echo(f"ROS_MASTER_URI={running.master_uri}")
            _serve(running, speed_up)
    except KeyboardInterrupt:
        click.echo("stand-in: stopping", err=True)
    finally:
        signal.signal(signal.SIGTERM, previous)


def _check_graph(ros1: bool, ros2: bool, ros1_options: bool, ros2_options: bool) -> None:
    if ros1 == ros2:
        raise click.UsageError("say --ros1 or --ros2: the graph the stand-in plays on")
    if ros2 and ros1_options:
        raise click.UsageError("--start-master and --log-dir go with --ros1")
    if ros1 and ros2_options:
        raise click.UsageError("--simulator and --behaviour go with --ros2")


def _serve(running: Any, speed_up: float) -> None:
    """Say what is served, then serve until Ctrl-C or SIGTERM: a stop inside the stand-in's block
    ends it cleanly (its temporary logs removed)."""
    try:
        servers = ", ".join(f"{robot} ({action})" for robot, action in running.actions.items())
        click.echo(f"stand-in: {servers} at {speed_up:g}x wall time; Ctrl-C to stop", err=True)
        running.wait()
    except KeyboardInterrupt:
        click.echo("stand-in: stopping", err=True)


def _play_ros2(
    loaded: Specification,
    scenario_id: str | None,
    seed: int,
    faults: tuple[str, ...],
    speed_up: float,
    simulator: str,
    behaviour: str | None,
) -> None:
    from exsce_dsl.api import stand_in_ros2

    with stand_in_ros2(
        loaded, scenario=scenario_id, seed=seed, faults=faults, speed_up=speed_up, simulator=simulator,
        behaviour=behaviour,
    ) as running:  # fmt: skip
        click.echo(f"ROS_DOMAIN_ID={os.environ.get('ROS_DOMAIN_ID') or 0}")
        _serve(running, speed_up)


COMMANDS = [stand_in]
