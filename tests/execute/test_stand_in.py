"""The stand-in robot on a real roscore: an actionlib client drives it, ``rosbag record`` records it.

Each test starts a fresh roscore (``tests/support/ros1_graph.py``), the stand-in of a one-robot
scenario on an open floor (``start_stand_in``), the real ``rosbag record`` and an actionlib
``move_base`` client run by Debian's Python (``tests/fixtures/ros1/move_base_client.py``).  The
bag is read with rosbags, an independent path; reference values are hand calculations (the goal,
the straight distance) or rosbags' own reading of the bag.
"""

from __future__ import annotations

import math
import os
import select
import signal
import subprocess
import sys
import time
import xmlrpc.client
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rosbags.highlevel import AnyReader

from exsce_dsl.execute.stand_in import GoalEnd, Stats, start_stand_in
from exsce_dsl.execute.stand_in.session import NODE
from exsce_dsl.lang import load_spec
from exsce_dsl.sim.faults import Fault
from exsce_dsl.sim.localisation import SCALE_ERROR

from tests.support.cli import run_exscec
from tests.support.ros1_graph import gone, require_ros1, ros1_graph

pytestmark = pytest.mark.ros1

CLIENT = Path(__file__).parents[1] / "fixtures" / "ros1" / "move_base_client.py"
FLOOR = """
environment floor {
  area hall {
    pose hall-a at (0.0, 0.0)
    pose hall-b at (5.0, 0.0)
    pose hall-c at (5.0, 4.0) facing 90.0 deg
  }
}

robot type rover {
  base diff_drive
  convention move_base
}

task go {
  visit hall-b
  visit hall-c
}

scenario floor_run in floor {
  robots {
    rover: rover namespace "rover" starts at hall-a
  }
  mission floor_mission parallel {
    rover does go
  }
}
"""
TOPICS = [
    "/clock",
    *(
        f"/rover/{name}"
        for name in (
            "odom", "tf", "tf_static", "amcl_pose", "cmd_vel", "scan",
            "move_base/goal", "move_base/status", "move_base/feedback", "move_base/result",
        )
    ),
]  # fmt: skip
SUCCEEDED, ABORTED, PREEMPTED = 3, 4, 2
"""actionlib_msgs/GoalStatus codes."""
SAMPLE = 0.02
"""Simulated seconds between two samples of the stand-in's clock (50 Hz)."""
ARRIVED = 0.1
"""Metres from the goal where a succeeded goal leaves the robot's estimate: the localiser's
noise (2 cm standard deviation) and float rounding, nothing of the planner's."""
ODOMETRY_SCALE = SCALE_ERROR[1] + 0.01
"""A path length along the wheel odometry is off the true one by its scale error (at most 3 %),
plus a centimetre's worth of the sampling."""


@dataclass
class Recorded:
    bag: Path
    spec: Path
    client: list[tuple[float, float, int]]
    """What the client printed: each goal's x, y and final status."""
    ended: list[GoalEnd]
    stats: Stats
    """The node's figures once the client is done (half a second before the recording stops)."""
    counted_from: Stats
    """Its figures once the recorder was connected to every topic."""
    clock_start: float
    """Simulated seconds of the node's first sample."""
    wall: float
    """Wall seconds the recording lasted."""

    def messages(self, topic: str) -> list[tuple[int, Any]]:
        with AnyReader([self.bag]) as reader:
            connections = [c for c in reader.connections if c.topic == topic]
            return [(t, reader.deserialize(raw, c.msgtype)) for c, t, raw in reader.messages(connections)]


def drive(
    tmp_path: Path, goals: Sequence[str], faults: Sequence[str] = (), cancel_after: float | None = None
) -> Recorded:
    """Drive the floor's rover to ``goals`` (``x,y,yaw``) and record it all."""
    spec = tmp_path / "floor.exsce"
    spec.write_text(FLOOR)
    scenario = load_spec(spec).scenario(None)
    bag = tmp_path / "stand_in.bag"
    with ros1_graph(tmp_path / "ros") as graph:
        parsed = tuple(Fault.parse(f) for f in faults)
        with start_stand_in(scenario, graph.uri, faults=parsed, log_dir=tmp_path / "stand_in") as stand_in:
            started = time.monotonic()
            recorder = graph.record(bag, TOPICS)
            graph.wait_until(
                lambda: connected(graph.uri, "/exsce_record"), "the recorder's connections", 30.0, [recorder]
            )
            counted_from = stand_in.stats()
            extra = ["--cancel-after", str(cancel_after)] if cancel_after is not None else []
            client = graph.run_python("client", CLIENT, stand_in.actions["rover"], *goals, *extra)
            graph.wait_until(lambda: not client.running(), "the client's goals to end", 60.0, [])
            assert client.popen.returncode == 0, client.output()
            stats = stand_in.stats()
            time.sleep(0.5)  # the robot stands: a few more samples, and those counted reach the bag
            graph.stop_recording(recorder, bag)
            wall = time.monotonic() - started
            ended = stand_in.goals_ended()
    lines = [line.split() for line in client.output().splitlines() if len(line.split()) == 3]
    printed = [(float(x), float(y), int(status)) for x, y, status in lines]
    return Recorded(bag, spec, printed, ended, stats, counted_from, stand_in.start, wall)


def connected(master_uri: str, subscriber: str) -> bool:
    """Whether the stand-in node sends every recorded topic to ``subscriber`` (its bus information,
    over XML-RPC as rosnode asks it): registering a subscription at the master comes first, the
    connection a moment later, and what is published in between is not recorded."""
    code, _, uri = xmlrpc.client.ServerProxy(master_uri).lookupNode("/exsce_tests", NODE)
    if code != 1:
        return False
    code, _, connections = xmlrpc.client.ServerProxy(uri).getBusInfo("/exsce_tests")
    sending = {c[4] for c in connections if c[1] == subscriber and c[2] == "o" and c[5]}
    return code == 1 and {t for t in TOPICS if not t.endswith("/goal")} <= sending  # goals: the client's


def path_length(xs: np.ndarray, ys: np.ndarray) -> float:
    return float(np.hypot(np.diff(xs), np.diff(ys)).sum())


def stamp(message: Any) -> float:
    """A message's header stamp, in seconds."""
    return float(message.header.stamp.sec + message.header.stamp.nanosec * 1e-9)


def odometry(recorded: Recorded) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Header stamp, x, y and forward speed of every odometry message, in order."""
    rows = [
        (stamp(m), m.pose.pose.position.x, m.pose.pose.position.y, m.twist.twist.linear.x)
        for _, m in recorded.messages("/rover/odom")
    ]
    t, x, y, v = np.array(rows).T
    return t, x, y, v


def test_a_goal_on_an_open_floor_is_reached_along_the_straight_line_on_simulated_time(tmp_path: Path) -> None:
    recorded = drive(tmp_path, ["5,0,0"])
    assert recorded.client == [(5.0, 0.0, SUCCEEDED)]
    results = recorded.messages("/rover/move_base/result")
    assert [m.status.status for _, m in results] == [SUCCEEDED]
    amcl = recorded.messages("/rover/amcl_pose")
    last = amcl[-1][1].pose.pose.position
    assert math.hypot(last.x - 5.0, last.y - 0.0) < ARRIVED
    _, x, y, _ = odometry(recorded)
    assert abs(path_length(x, y) - 5.0) < 5.0 * ODOMETRY_SCALE  # the straight line: 5 m
    assert len(recorded.messages("/rover/move_base/feedback")) >= 5  # 5 Hz over a drive of > 8 s
    clock = [m.clock.sec + m.clock.nanosec * 1e-9 for _, m in recorded.messages("/clock")]
    assert clock == sorted(clock)
    assert (clock[-1] - clock[0]) / recorded.wall > 1.0  # simulated time ran faster than the wall's
    assert recorded.stats.real_time_factor > 1.0
    assert [(e.robot, e.outcome) for e in recorded.ended] == [("rover", "succeeded")]
    # exscec ingest reads the bag as the move_base convention has it: the distance is the odometry's
    store = tmp_path / "store"
    done = run_exscec("ingest", str(recorded.bag), "--scenario", str(recorded.spec), "--store", str(store))
    assert done.returncode == 0, done.stderr
    # every stamp on the recorder's clock (tf_static too): the one warning is that the mission's
    # second waypoint, which this drive never sent, was not reached in the recording
    warned = [line for line in done.stderr.splitlines() if "warning" in line]
    assert all("coverage: cut short" in line and "hall-c" in line for line in warned), done.stderr
    from exsce_dsl import api

    with api.open_store(str(store)) as opened:
        table = api.metrics(opened, "floor_run")
    distance = table[(table.metric == "distance_travelled") & (table.robot == "rover")].value
    assert len(distance) == 1
    # the whole odometry path against ingest's goal window: the window's ends fall on the node's
    # 50 Hz ticks, and under load the sample of the goal's (or result's) tick may fall either side
    # of it: at most two 20 ms samples at the leg's speed limit (< 0.6 m/s) apart, 2.4 cm (a
    # loaded CI measured 1.05 cm)
    assert float(distance.iloc[0]) == pytest.approx(path_length(x, y), abs=0.024)


def test_every_message_the_stand_in_counts_while_recording_is_in_the_bag(tmp_path: Path) -> None:
    recorded = drive(tmp_path, ["5,0,0"])
    first, last = (round(s.sim_time / SAMPLE) for s in (recorded.counted_from, recorded.stats))
    assert last - first > 100  # a drive of > 8 simulated seconds was counted
    # each stamped topic is due at every sample, every 25th (2 Hz) or every 5th (10 Hz) of the
    # node's 50 Hz clock, counted from its start: those between the two counts must all be in the bag
    for name, every in (("odom", 1), ("tf", 1), ("amcl_pose", 25), ("scan", 5)):
        topic = f"/rover/{name}"
        messages = [m.transforms[0] if name == "tf" else m for _, m in recorded.messages(topic)]
        samples = sorted(round((stamp(m) - recorded.clock_start) / SAMPLE) for m in messages)
        due = [n for n in range(first + 1, last + 1) if n % every == 0]
        assert [n for n in samples if first < n <= last] == due, topic
        published = recorded.stats.published[topic] - recorded.counted_from.published[topic]
        assert published == len(due), topic
    # cmd_vel (no stamp) at 20 Hz: the node's count is the hand calculation's, and none is missing
    published = recorded.stats.published["/rover/cmd_vel"] - recorded.counted_from.published["/rover/cmd_vel"]
    assert abs(published - (last - first) * SAMPLE / 0.05) <= 1
    assert len(recorded.messages("/rover/cmd_vel")) >= published


def test_overspeed_drives_well_over_one_metre_per_second(tmp_path: Path) -> None:
    recorded = drive(tmp_path, ["5,0,0"], faults=["overspeed:rover"])
    assert recorded.client == [(5.0, 0.0, SUCCEEDED)]
    commanded = [m.linear.x for _, m in recorded.messages("/rover/cmd_vel")]
    *_, measured = odometry(recorded)
    assert max(commanded) > 1.0
    assert max(measured) > 1.0


def test_skip_waypoint_aborts_the_first_goal_where_the_robot_stands(tmp_path: Path) -> None:
    recorded = drive(tmp_path, ["5,0,0", "5,4,1.5708"], faults=["skip-waypoint:rover:1"])
    assert recorded.client == [(5.0, 0.0, ABORTED), (5.0, 4.0, SUCCEEDED)]
    results = recorded.messages("/rover/move_base/result")
    assert [m.status.status for _, m in results] == [ABORTED, SUCCEEDED]
    stamps, x, y, _ = odometry(recorded)
    before = stamps <= stamp(results[0][1])
    assert path_length(x[before], y[before]) == 0.0  # it did not move for the aborted goal
    last = recorded.messages("/rover/amcl_pose")[-1][1].pose.pose.position
    assert math.hypot(last.x - 5.0, last.y - 4.0) < ARRIVED  # straight from hall-a to hall-c
    assert path_length(x, y) == pytest.approx(math.hypot(5.0, 4.0), rel=ODOMETRY_SCALE)


def test_a_cancelled_goal_stops_the_robot_where_it_is(tmp_path: Path) -> None:
    recorded = drive(tmp_path, ["5,0,0"], cancel_after=4.0)
    assert recorded.client == [(5.0, 0.0, PREEMPTED)]
    results = recorded.messages("/rover/move_base/result")
    assert [m.status.status for _, m in results] == [PREEMPTED]
    assert [(e.robot, e.outcome) for e in recorded.ended] == [("rover", "canceled")]
    # the stand-in says at which sample it stopped the robot (the result's stamp is the /clock that
    # rospy last took, which lags the samples published by as much as the machine is loaded)
    stopped_at = recorded.ended[0].time
    stamps, x, y, v = odometry(recorded)
    after = stamps > stopped_at + 1e-6
    assert after.sum() > 10, "the recording went on after the cancel"
    assert 0.1 < path_length(x, y) < 4.0  # it had set off, and stopped well before the goal
    assert path_length(x[after], y[after]) == 0.0
    assert np.all(v[after] == 0.0)
    commanded = [m.linear.x for _, m in recorded.messages("/rover/cmd_vel")]
    assert max(commanded) > 0.3 and commanded[-10:] == [0.0] * 10  # 20 Hz for 5 s after the stop


def test_the_command_serves_until_sigterm_then_stops_the_node_and_its_master(tmp_path: Path) -> None:
    """... and removes its temporary folder of logs (none given) when it stopped cleanly."""
    require_ros1()
    spec = tmp_path / "floor.exsce"
    spec.write_text(FLOOR)
    exscec = Path(sys.executable).with_name("exscec")
    argv = [str(exscec), "stand-in", str(spec), "--ros1", "--start-master"]
    temporary = tmp_path / "tmp"
    temporary.mkdir()
    process = subprocess.Popen(
        argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True,
        env={**os.environ, "TMPDIR": str(temporary)},
    )  # fmt: skip
    try:
        assert process.stdout is not None
        ready, _, _ = select.select([process.stdout], [], [], 60.0)
        assert ready, "no first line within 60 s"
        first = process.stdout.readline().strip()
        assert first.startswith("ROS_MASTER_URI=http://127.0.0.1:"), first
        uri = first.split("=", 1)[1]
        master = xmlrpc.client.ServerProxy(uri)
        code, _, node_uri = master.lookupNode("/exsce_tests", NODE)
        assert code == 1
        _, _, node_pid = xmlrpc.client.ServerProxy(node_uri).getPid("/exsce_tests")
        _, _, master_pid = master.getPid("/exsce_tests")
        publishers = {topic for topic, _ in master.getSystemState("/exsce_tests")[2][0]}
        assert {"/clock", "/rover/move_base/result", "/rover/odom", "/rover/scan"} <= publishers
        assert master.getParam("/exsce_tests", "/use_sim_time")[2] is True
        process.send_signal(signal.SIGTERM)
        assert process.wait(30.0) == 0, process.stderr.read() if process.stderr else ""
        deadline = time.monotonic() + 10.0
        while not (gone(node_pid) and gone(master_pid)) and time.monotonic() < deadline:
            time.sleep(0.1)
        assert gone(node_pid) and gone(master_pid)
        assert not list(temporary.iterdir())
    finally:
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGKILL)
            process.wait()


def test_the_command_wants_ros1_and_a_master(tmp_path: Path) -> None:
    spec = tmp_path / "floor.exsce"
    spec.write_text(FLOOR)
    without = run_exscec("stand-in", str(spec))
    assert without.returncode == 2 and "--ros1" in without.stderr
    temporary = tmp_path / "tmp"
    temporary.mkdir()
    env = {k: v for k, v in os.environ.items() if k != "ROS_MASTER_URI"} | {"TMPDIR": str(temporary)}
    exscec = Path(sys.executable).with_name("exscec")
    unset = subprocess.run(
        [str(exscec), "stand-in", str(spec), "--ros1"], env=env, capture_output=True, text=True, timeout=60
    )
    assert unset.returncode == 2 and "ROS_MASTER_URI is not set" in unset.stderr
    # it failed before it logged anything: no empty log folder is left behind
    assert not list(temporary.iterdir())
