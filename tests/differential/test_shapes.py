"""Issue 47, item 5: every metric on synthetic bags of the shapes real recordings showed (items 1-8
of the issue, interleaved tracks and teleports included), in ROS 1,
ROS 2 sqlite3 and MCAP, against the independent reference of tests/support/reference_path.py:
equal to 1e-6 where both compute, missing with a reason exactly where the reference has no
value.

The bags come from the builders of the tests that found each shape (tests/runs/signals/test_tf_publishers,
test_root_velocity, test_coarse_stamps, test_clock_words, test_whole_run_window, and
tests/support/real_shapes), each with the specification of its test, and the user functions'
metrics added where they apply.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from exsce_dsl.lang import load_spec
from exsce_dsl.runs.analyse import analyse_bag

from tests.runs.segments.test_whole_run_window import SPEC as EARLY_SPEC
from tests.runs.segments.test_whole_run_window import _early_bag as early_bag
from tests.runs.signals.test_clock_words import SPEC as CLOCK_SPEC
from tests.runs.signals.test_clock_words import clock_bag
from tests.runs.signals.test_coarse_stamps import SPEC as COARSE_SPEC
from tests.runs.signals.test_coarse_stamps import _poses as coarse_poses
from tests.runs.signals.test_root_velocity import SPEC as ROOTED_SPEC
from tests.runs.signals.test_root_velocity import _messages as rooted_topics
from tests.runs.signals.test_tf_publishers import SPEC as TF_SPEC
from tests.runs.signals.test_tf_publishers import tf_bag
from tests.runs.test_pose_plausibility import SPEC as PLAUSIBILITY_SPEC
from tests.runs.test_pose_plausibility import _messages as plausibility_topics
from tests.runs.test_turtlesim_path import SPEC as TURTLE_SPEC
from tests.support.bag_factory import (
    LASER_SCAN,
    ODOMETRY,
    TURTLE_POSE,
    Topic,
    series,
    typestore_for,
    write_bag,
)
from tests.support.differential import (
    ODOMETRY_METRICS,
    STORAGES,
    TURTLE_METRICS,
    mismatches,
    odometry_references,
    turtle_references,
)
from tests.support.real_shapes import ROUTE, Route, jackal, ns_of, pose_topic, times, twist
from tests.support.reference_path import (
    Expected,
    Key,
    Recording,
    RobotSources,
    duration_where,
    path_length,
    run_values,
    tf_pose,
    xy,
)
from tests.support.yard_spec import FAR_YARD

FAR = ((50.0, 50.0),)
"""FAR_YARD's one waypoint, which no robot here reaches."""


@dataclass(frozen=True)
class Shape:
    """A shape: how its bag is written (``folder``, ``fmt`` → the bag), its specification, where
    its robots' signals are, and its user metrics' reference."""

    write: Callable[[Path, str], Path]
    spec: str
    robots: list[RobotSources]
    functions: Callable[[Recording], dict[Key, Expected]] = lambda bag: {}


def _tf_functions(bag: Recording) -> dict[Key, Expected]:
    """test_tf_publishers' metrics: the path of base_link in the map through AMCL's post-dated
    ``map → odom``, and of the odometry."""
    planar = tf_pose("map", "odom", "base_link")(bag)
    return {
        ("planar_path", "bot"): Expected(path_length(*xy(planar))),
        ("odom_path", "bot"): Expected(path_length(*xy(bag.samples("/odom"))), ("/odom",)),
    }


def _coarse_bag(folder: Path, fmt: str) -> Path:
    bag = folder / ("coarse.bag" if fmt == "ros1" else "coarse")
    write_bag(bag, fmt, [coarse_poses(typestore_for(fmt))])
    return bag


def _coarse_functions(bag: Recording) -> dict[Key, Expected]:
    location = bag.samples("/location")
    x = xy(location)[0]
    return {("far_out_time", "tb"): Expected(duration_where(location.t, x > 1.0), ("/location",))}


KEYS_HELD = ((2.5, 5.0), (7.0, 9.5), (12.0, 14.5))
"""Seconds of the recording in which the teleop's key is held (it sends ``/cmd_vel`` only then)."""


def _teleop_bag(folder: Path, fmt: str) -> Path:
    """real_shapes' Jackal, its ``/cmd_vel`` sent only while a key is held."""
    topics = []
    for topic in jackal(typestore_for(fmt)):
        if topic.name == "/cmd_vel":
            held = [(t, m) for t, m in topic.messages if any(ns_of(a) <= t <= ns_of(b) for a, b in KEYS_HELD)]
            topic = Topic(topic.name, topic.msgtype, held)
        topics.append(topic)
    bag = folder / ("teleop.bag" if fmt == "ros1" else "teleop")
    write_bag(bag, fmt, topics)
    return bag


def _turtles_bag(folder: Path, fmt: str) -> Path:
    """Two turtles along real_shapes' route (the second 1 m north), their ``turtlesim/Pose`` at
    62.5 Hz (no header, float32), their ``cmd_vel`` at 10 Hz while they drive."""
    store = typestore_for(fmt)
    topics = []
    for k, robot in enumerate(("turtle1", "turtle2")):
        t = times(62.5)
        at = ROUTE.at(t)
        poses = [
            (
                ns_of(s) + k * 1000,
                store.types[TURTLE_POSE](
                    x=float(np.float32(5.5 + at["x"][i])),
                    y=float(np.float32(5.5 + k + at["y"][i])),
                    theta=float(np.float32(at["yaw"][i])),
                    linear_velocity=float(np.float32(at["speed"][i])),
                    angular_velocity=0.0,
                ),
            )
            for i, s in enumerate(t)
        ]
        driving = times(10.0, 2.0, 16.0)
        commands = [
            (ns_of(s), twist(store, v)) for s, v in zip(driving, ROUTE.at(driving)["speed"], strict=True)
        ]
        topics += [
            Topic(f"/{robot}/pose", TURTLE_POSE, poses),
            Topic(f"/{robot}/cmd_vel", "geometry_msgs/msg/Twist", commands),
        ]
    bag = folder / ("turtles.bag" if fmt == "ros1" else "turtles")
    write_bag(bag, fmt, topics, store)
    return bag


def _rooted_bag(folder: Path, fmt: str) -> Path:
    store = typestore_for(fmt)
    bag = folder / ("rooted.bag" if fmt == "ros1" else "rooted")
    write_bag(bag, fmt, rooted_topics(store, velocity=True), store)
    return bag


def _implausible_bag(shape: str) -> Callable[[Path, str], Path]:
    """test_pose_plausibility's root ``/location`` in one of its shapes (``tracks``: two
    estimates alternating 1.8 to 3.8 m apart; ``teleport``: a 5 m jump), beside the robot's own
    ``/velocity``."""

    def write(folder: Path, fmt: str) -> Path:
        store = typestore_for(fmt)
        bag = folder / (f"{shape}.bag" if fmt == "ros1" else shape)
        write_bag(bag, fmt, plausibility_topics(store, shape, True), store)
        return bag

    return write


def _no_location_path(bag: Recording) -> dict[Key, Expected]:
    return {("location_path", "tb"): Expected(None)}


def _two_robots_bag(folder: Path, fmt: str) -> Path:
    """Two odometries crossing (r1 along real_shapes' route at 20 Hz; r2 the other way, at
    15 Hz from 0.3 s), and r1's scan at 10 Hz (8 to 12 beams a message)."""
    store = typestore_for(fmt)
    back = Route([(8.0, 6.0, 0.0), (8.0, 0.0, 0.0), (0.0, 0.0, 0.0)], [0.8, 1.2])
    topics = [
        pose_topic(store, "/r1/odom", ODOMETRY, ROUTE, 20.0, frame="odom"),
        pose_topic(store, "/r2/odom", ODOMETRY, back, 15.0, start=0.3, frame="odom"),
        Topic("/r1/scan", LASER_SCAN, series(store, LASER_SCAN, 180, period_ns=100_000_000)),
    ]
    bag = folder / ("two.bag" if fmt == "ros1" else "two")
    write_bag(bag, fmt, topics, store)
    return bag


TWO_ROBOTS = (
    FAR_YARD
    + """
scenario two in yard {
  robots {
    r1: bot starts at start
    r2: bot starts at far
  }
  mission two_mission parallel {
    r1 does go
    r2 does go
  }
}
"""
)


def _scenario(robot: str) -> str:
    return (
        FAR_YARD
        + f"""
scenario shape in yard {{
  robots {{
    {robot}: bot namespace "" starts at start
  }}
  mission shape_mission sequential {{
    {robot} does go
  }}
}}
"""
    )


JACKAL_ODOM = "/jackal_velocity_controller/odom"
SHAPES = {
    # item 2: /tf from two publishers, AMCL's map -> odom post-dated 1.7 s
    "tf_publishers": Shape(
        lambda folder, fmt: tf_bag(folder, fmt),
        TF_SPEC,
        [
            RobotSources(
                "bot",
                velocity="/odom",
                distance="/odom",
                waypoints=((40.0, 40.0),),
                tf_pose=tf_pose("map", "odom", "base_link"),
            )
        ],
        _tf_functions,
    ),
    # item 6: a 27 Hz pose stamped with whole seconds
    "coarse_stamps": Shape(
        _coarse_bag, COARSE_SPEC, [RobotSources("tb", pose="/location", waypoints=FAR)], _coarse_functions
    ),
    # item 7: a recorder on simulated time (log time from 82.8 s, /clock)
    "simulated_log_clock": Shape(
        lambda folder, fmt: clock_bag(folder, "simulated_log", fmt),
        CLOCK_SPEC + ODOMETRY_METRICS.replace("TOPIC", "odom"),
        [RobotSources("bot", pose="/odom", velocity="/odom", distance="/odom", waypoints=((40.0, 40.0),))],
        odometry_references("bot", "/odom"),
    ),
    # item 7 too: Gazebo's stamps on simulated time from 931.25 s, log time on the wall clock, /clock
    "simulated_stamps": Shape(
        lambda folder, fmt: clock_bag(folder, "gazebo", fmt),
        CLOCK_SPEC + ODOMETRY_METRICS.replace("TOPIC", "odom"),
        [RobotSources("bot", pose="/odom", velocity="/odom", distance="/odom", waypoints=((40.0, 40.0),))],
        odometry_references("bot", "/odom"),
    ),
    # item 8: teleop's cmd_vel, sent only while a key is held
    "event_driven": Shape(
        _teleop_bag,
        _scenario("jackal") + ODOMETRY_METRICS.replace("{ns}/TOPIC", JACKAL_ODOM.lstrip("/")),
        [RobotSources("jackal", pose=JACKAL_ODOM, velocity="/cmd_vel", distance=JACKAL_ODOM, waypoints=FAR)],
        odometry_references("jackal", JACKAL_ODOM),
    ),
    # item 5: a root /location (PoseStamped) and a root /velocity (TwistStamped)
    "root_velocity": Shape(
        _rooted_bag, ROOTED_SPEC, [RobotSources("tb", pose="/location", velocity="/velocity", waypoints=FAR)]
    ),
    # item 4: a root /location alternating between two tracks, and one that teleports: no
    # distance and no path from it (the reference computes nothing from such a pose), the
    # speed from the robot's own /velocity
    **{
        f"implausible_{shape}": Shape(
            _implausible_bag(shape),
            PLAUSIBILITY_SPEC,
            [RobotSources("tb", pose="/location", velocity="/velocity", waypoints=FAR, implausible=True)],
            _no_location_path,
        )
        for shape in ("tracks", "teleport")
    },
    # item 3: turtlesim's Pose: no header, float32
    "headerless_float32": Shape(
        _turtles_bag,
        TURTLE_SPEC.replace("WINDOW", "") + TURTLE_METRICS,
        [RobotSources(r, velocity=f"/{r}/cmd_vel") for r in ("turtle1", "turtle2")],
        turtle_references(("turtle1", "turtle2")),
    ),
    # two robots crossing, one with a scan: the distance between robots, the clearance
    "two_robots": Shape(
        _two_robots_bag,
        TWO_ROBOTS,
        [
            RobotSources(
                "r1",
                pose="/r1/odom",
                velocity="/r1/odom",
                distance="/r1/odom",
                scan="/r1/scan",
                waypoints=FAR,
            ),
            RobotSources("r2", pose="/r2/odom", velocity="/r2/odom", distance="/r2/odom", waypoints=FAR),
        ],
    ),
    # item 1: no goals, the last planned waypoint passed 14 s into 60
    "early_arrival": Shape(
        lambda folder, fmt: early_bag(folder, fmt),
        EARLY_SPEC + ODOMETRY_METRICS.replace("TOPIC", "odom"),
        [
            RobotSources(
                "bot", pose="/odom", velocity="/odom", distance="/odom", waypoints=((8.0, 0.0), (8.0, 6.0))
            )
        ],
        odometry_references("bot", "/odom"),
    ),
}


@pytest.mark.parametrize("fmt", ["ros1", *STORAGES])
@pytest.mark.parametrize("name", list(SHAPES))
def test_every_metric_of_a_shape_is_the_reference(name: str, fmt: str, tmp_path: Path) -> None:
    shape = SHAPES[name]
    bag = shape.write(tmp_path, fmt)
    spec = tmp_path / "shape.exsce"
    spec.write_text(shape.spec)
    run = analyse_bag(bag, load_spec(spec).scenario())
    recording = Recording(bag)
    expected = run_values(recording, shape.robots) | shape.functions(recording)
    wrong = mismatches(run, expected)
    assert not wrong, "\n".join([*wrong, "problems:", *run.problems])
