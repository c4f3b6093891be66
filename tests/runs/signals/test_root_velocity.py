"""A robot's velocity is found wherever a Twist or TwistStamped of its is (issue 47, item 5).

A TurtleBot recorded with a root ``/location`` (PoseStamped) and a root ``/velocity``
(TwistStamped): detection looked for ``/cmd_vel`` and odometry only, estimated the speed from the
poses, and said it had looked for "none named".  Detection now takes Twist and TwistStamped topics
under the robot's namespace or at the root, and the warning of a robot without any lists what
was looked for.  The bags are written here with rosbags; the reference is rosbags + numpy.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rosbags.highlevel import AnyReader

from exsce_dsl.lang import load_spec
from exsce_dsl.runs.analyse import analyse_bag

from tests.support.bag_factory import (
    POSE_STAMPED,
    START_NS,
    TWIST_STAMPED,
    Topic,
    header,
    typestore_for,
    write_bag,
)
from tests.support.yard_spec import FAR_YARD

SPEC = FAR_YARD + """
scenario rooted in yard {
  robots {
    tb: bot namespace "" starts at start
  }
  mission go_far sequential {
    tb does go
  }
}
"""
COUNT = 200
PERIOD_NS = 37_000_000  # 27 Hz


def _messages(store: Any, velocity: bool) -> list[Topic]:
    """A robot driving along a gentle curve, its poses on ``/location`` and, if ``velocity``,
    the velocity it reports on ``/velocity`` (not the poses' derivative: a speed of its own)."""
    rng = np.random.default_rng(47)
    t = np.arange(COUNT) * PERIOD_NS
    speed = 0.2 + 0.1 * rng.random(COUNT)
    x = np.cumsum(speed) * PERIOD_NS / 1e9
    y = 0.1 * np.sin(x)
    types = store.types
    poses = [
        (
            START_NS + int(ti),
            types[POSE_STAMPED](
                header=header(store, START_NS + int(ti), "map", i),
                pose=types["geometry_msgs/msg/Pose"](
                    position=types["geometry_msgs/msg/Point"](x=float(x[i]), y=float(y[i]), z=0.0),
                    orientation=types["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0),
                ),
            ),
        )
        for i, ti in enumerate(t)
    ]
    topics = [Topic("/location", POSE_STAMPED, poses)]
    if velocity:
        twists = [
            (
                START_NS + int(ti) + 1000,
                types[TWIST_STAMPED](
                    header=header(store, START_NS + int(ti), "base_link", i),
                    twist=types["geometry_msgs/msg/Twist"](
                        linear=types["geometry_msgs/msg/Vector3"](
                            x=float(speed[i]), y=float(0.05 * speed[i]), z=0.0
                        ),
                        angular=types["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.1),
                    ),
                ),
            )
            for i, ti in enumerate(t)
        ]
        topics.append(Topic("/velocity", TWIST_STAMPED, twists))
    return topics


def _bag(folder: Path, fmt: str, velocity: bool) -> Path:
    path = folder / ("rooted.bag" if fmt == "ros1" else "rooted")
    write_bag(path, fmt, _messages(typestore_for(fmt), velocity))
    return path


def _max_speed(bag: Path, topic: str) -> float:
    """The largest |(vx, vy)| of every message on ``topic``, as rosbags reads it."""
    speeds = []
    with AnyReader([bag]) as reader:
        for connection, _, raw in reader.messages([c for c in reader.connections if c.topic == topic]):
            linear = reader.deserialize(raw, connection.msgtype).twist.linear
            speeds.append(np.hypot(linear.x, linear.y))
    return float(np.max(speeds))


def _analysed(tmp_path: Path, bag: Path) -> Any:
    spec = tmp_path / "rooted.exsce"
    spec.write_text(SPEC)
    return analyse_bag(bag, load_spec(spec).scenario())


@pytest.mark.parametrize("fmt", ["ros1", "sqlite3"])
def test_root_velocity_twist_stamped_is_found(fmt: str, tmp_path: Path) -> None:
    bag = _bag(tmp_path, fmt, velocity=True)
    analysed = _analysed(tmp_path, bag)
    (value,) = [v for v in analysed.run.metrics if v.metric == "max_velocity" and v.action is None]
    assert value.value == pytest.approx(_max_speed(bag, "/velocity"), rel=1e-6)
    assert value.topics == ("/velocity",)
    assert value.estimated_from is None
    assert not [p for p in analysed.problems if "has no velocity" in p], analysed.problems


def test_a_robot_without_velocity_is_told_what_was_looked_for(tmp_path: Path) -> None:
    analysed = _analysed(tmp_path, _bag(tmp_path, "ros1", velocity=False))
    (said,) = [p for p in analysed.problems if "has no velocity in this bag" in p]
    assert "none named" not in said
    assert "(looked for /cmd_vel)" in said, said
