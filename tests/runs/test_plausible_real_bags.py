"""Clean real recordings pass the plausibility check untouched (issue 47, item 3).

A check that refused real data would trade a wrong number for a missing one: every bag of
``tests/fixtures/realbags`` (a Husky and a Jackal driven outdoors, turtlesim, a Stage simulation)
gets no finding from ``bag info`` nor from ingestion, and keeps its numbers, computed here again
from rosbags' reading and numpy.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from rosbags.highlevel import AnyReader

from exsce_dsl.lang import load_spec
from exsce_dsl.runs.analyse import analyse_bag
from exsce_dsl.runs.bag_info import bag_info_of
from exsce_dsl.runs.signals.plausibility import Velocity, check_poses, speed_bound
from exsce_dsl.runs.spec_draft import draft_spec

from tests.support.paths import ROOT

REALBAGS = ROOT / "tests" / "fixtures" / "realbags"
ALL = sorted(p.relative_to(REALBAGS).as_posix() for p in REALBAGS.rglob("*.bag"))
ODOMETRY = {
    "robot_localization/test1.bag": ("/husky_velocity_controller/odom", 358.79685),
    "robot_localization/test2.bag": ("/jackal_velocity_controller/odom", 84.18181),
    "embag/test.bag": ("/base_pose_ground_truth", None),
}
"""A drafted spec's robot: the odometry its pose and distance come from, and SOURCES.md's path."""


def _odometry_path(bag: Path, topic: str) -> float:
    """The sum of the x-y steps between the odometry's positions, as rosbags reads them."""
    xy = []
    with AnyReader([bag]) as reader:
        for connection, _, raw in reader.messages([c for c in reader.connections if c.topic == topic]):
            position = reader.deserialize(raw, connection.msgtype).pose.pose.position
            xy.append((position.x, position.y))
    steps = np.diff(np.array(xy), axis=0)
    return float(np.hypot(steps[:, 0], steps[:, 1]).sum())


@pytest.mark.parametrize("name", ALL)
def test_real_bags_show_no_plausibility_finding(name: str) -> None:
    assert bag_info_of(REALBAGS / name).plausibility == ()


@pytest.mark.parametrize("name", sorted(ODOMETRY))
def test_real_robots_keep_their_distance(name: str, tmp_path: Path) -> None:
    bag = REALBAGS / name
    spec = tmp_path / "drafted.exsce"
    draft_spec(bag, spec)
    analysed = analyse_bag(bag, load_spec(spec).scenario())
    assert not [p for p in analysed.problems if "no distance or speed" in p or "plausible" in p]
    topic, figure = ODOMETRY[name]
    expected = _odometry_path(bag, topic)
    if figure is not None:
        assert expected == pytest.approx(figure, abs=1e-5)  # SOURCES.md's, so the reference is checked
    (value,) = [v for v in analysed.run.metrics if v.metric == "distance_travelled" and v.action is None]
    assert value.value == pytest.approx(expected, rel=1e-6, abs=1e-9)


@pytest.mark.parametrize("turtle", ["turtle1", "turtle2"])
def test_turtlesim_poses_are_plausible_against_their_commands(turtle: str) -> None:
    """turtlesim's ``Pose`` is no pose type a robot's signal is read from: checked here directly,
    against the largest speed its ``cmd_vel`` commands."""
    t, x, y, commanded = [], [], [], []
    with AnyReader([REALBAGS / "rosbag.js" / "example.bag"]) as reader:
        for topic, found in ((f"/{turtle}/pose", None), (f"/{turtle}/cmd_vel", commanded)):
            for c, time_ns, raw in reader.messages([c for c in reader.connections if c.topic == topic]):
                message = reader.deserialize(raw, c.msgtype)
                if found is None:
                    t.append(time_ns * 1e-9)
                    x.append(message.x)
                    y.append(message.y)
                else:
                    found.append(abs(message.linear.x))
    velocity = Velocity(f"/{turtle}/cmd_vel", max(commanded))
    arrays = [np.array(a, dtype=np.float64) for a in (t, x, y)]
    assert check_poses(f"/{turtle}/pose", arrays[0], arrays[1:], speed_bound(None), velocity) is None
