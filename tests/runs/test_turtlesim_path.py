"""A user metric over a real recording uses every sample of its topic (issue 47, item 3).

rosbag.js's turtlesim bag: two turtles whose pose (``turtlesim/Pose``: no header, ~62 Hz,
float32, the type defined only in the bag) is recorded for the whole 21.7 s, and whose
``cmd_vel`` is sent only while a key is held.  Without goals, a robot's whole-run window was the
span of its detected signals (here ``cmd_vel`` alone), so a path over the pose lost the steps
before the first key press and after the last: 28.320 m for 28.352 m, 21.116 m for 21.519 m.
The window is the recording; the reference is rosbags' own reading and numpy, written here.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from rosbags.highlevel import AnyReader

from exsce_dsl.lang import load_spec
from exsce_dsl.runs.analyse import analyse_bag

from tests.support.paths import ROOT

TURTLESIM = ROOT / "tests" / "fixtures" / "realbags" / "rosbag.js"
BAGS = ("example.bag", "example-bz2.bag", "example-lz4.bag")

SPEC = """
environment pond {
  area water {
    pose home1 at (5.5, 5.5)
    pose home2 at (6.5, 5.5)
    pose far at (40.0, 40.0)
  }
}
task swim {
  visit far
}
robot type turtle {
  base diff_drive
WINDOW}
metric pose_path for each robot {
  unit m
  reads pose: turtlesim/msg/Pose on "/{ns}/pose"
  value path_length(pose.x, pose.y)
}
scenario turtles in pond {
  robots {
    turtle1: turtle namespace "turtle1" starts at home1
    turtle2: turtle namespace "turtle2" starts at home2
  }
  mission swim_mission parallel {
    turtle1 does swim
    turtle2 does swim
  }
}
"""
WINDOWS = {"goals": "", "whole recording": "  window whole recording\n"}


def reference_path(bag: Path, topic: str) -> float:
    """The sum of the Euclidean steps between consecutive messages of ``topic``, all of them,
    in the x-y plane, as rosbags deserialises them with the bag's own definitions."""
    xs, ys = [], []
    with AnyReader([bag]) as reader:
        for connection, _, raw in reader.messages([c for c in reader.connections if c.topic == topic]):
            message = reader.deserialize(raw, connection.msgtype)
            xs.append(message.x)
            ys.append(message.y)
    x, y = np.array(xs, dtype=np.float64), np.array(ys, dtype=np.float64)
    return float(np.hypot(np.diff(x), np.diff(y)).sum())


@pytest.mark.parametrize("window", WINDOWS)
@pytest.mark.parametrize("name", BAGS)
def test_turtlesim_path_uses_every_sample(name: str, window: str, tmp_path: Path) -> None:
    spec = tmp_path / "turtles.exsce"
    spec.write_text(SPEC.replace("WINDOW", WINDOWS[window]))
    bag = TURTLESIM / name
    run = analyse_bag(bag, load_spec(spec).scenario()).run
    found = {v.robot: v.value for v in run.metrics if v.metric == "pose_path" and v.action is None}
    for robot in ("turtle1", "turtle2"):
        expected = reference_path(bag, f"/{robot}/pose")
        assert found[robot] == pytest.approx(expected, rel=1e-6), (robot, name, window)
    # the figures SOURCES.md gives, so that the reference itself is checked once
    assert reference_path(bag, "/turtle1/pose") == pytest.approx(28.35200, abs=1e-5)
