"""The differential suite's comparison: a run's whole-run values against the reference of
tests/support/reference_path.py, and the conversion of a ROS 1 bag to ROS 2 sqlite3 and MCAP with
rosbags.

A value is compared at a relative error of 1e-6 where both compute; where the reference says the
data cannot support a number, the run must have no value and a problem naming the metric (and
the robot); a run value the reference does not expect is a mismatch too.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Collection, Mapping
from pathlib import Path

import numpy as np
from rosbags.convert import convert

from exsce_dsl.model.runs import MetricScope
from exsce_dsl.runs.analyse import AnalysedRun

from tests.support.reference_path import (
    Expected,
    Key,
    Recording,
    Samples,
    duration_where,
    path_length,
    position,
    speeds,
    xy,
)

RELATIVE = 1e-6
STORAGES = ("sqlite3", "mcap")
"""The ROS 2 storages each corpus bag is converted to."""


def converted(bag: Path, folder: Path, storage: str) -> Path:
    """``bag`` (ROS 1) written as a ROS 2 bag of ``storage`` by rosbags' converter (version 8:
    the types' definitions travel with it)."""
    target = folder / f"{bag.stem}-{storage}"
    if not target.exists():
        convert([bag], target, storage, 8, None, "file", None, None, [], [], [], [])
    return target


def run_values(run: AnalysedRun) -> dict[Key, tuple[float, tuple[str, ...]]]:
    """The run's values: (metric, robot) → value and topics; a violation duration as
    ``violation_duration/<its safety metric>``, a path segment's value as ``metric@<waypoint>``."""
    found: dict[Key, tuple[float, tuple[str, ...]]] = {}
    for v in run.run.metrics:
        name = v.metric if v.safety_metric is None else f"{v.metric}/{v.safety_metric}"
        if v.scope is MetricScope.SEGMENT and v.action is not None:
            found[(f"{name}@{v.action.waypoint}", v.action.robot)] = (v.value, tuple(v.topics))
        elif v.scope in (MetricScope.ROBOT, MetricScope.MISSION):
            found[(name, v.robot if v.scope is MetricScope.ROBOT else None)] = (v.value, tuple(v.topics))
    return found


def mismatches(
    run: AnalysedRun, expected: Mapping[Key, Expected], left_out: Collection[Key] = ()
) -> list[str]:
    """Every way the run's values differ from ``expected`` (empty: they agree), but for the values
    ``left_out`` (known findings, each named where it is left out)."""
    found = {k: v for k, v in run_values(run).items() if k not in left_out}
    expected = {k: v for k, v in expected.items() if k not in left_out}
    wrong: list[str] = []
    for key, want in sorted(expected.items(), key=lambda kv: (kv[0][0], kv[0][1] or "")):
        metric, robot = key
        got = found.get(key)
        if want.value is None:
            if got is not None:
                wrong.append(f"{key}: exsce {got[0]!r}, the reference has no value")
            elif not _told(run.problems, metric.partition("/")[0].partition("@")[0], robot):
                wrong.append(f"{key}: missing without a reason naming it")
        elif got is None:
            wrong.append(f"{key}: exsce has no value, the reference {want.value!r}")
        elif not math.isclose(got[0], want.value, rel_tol=RELATIVE, abs_tol=1e-12):
            wrong.append(f"{key}: exsce {got[0]!r}, the reference {want.value!r}")
        elif want.topics and got[1] != want.topics:
            wrong.append(f"{key}: exsce read {got[1]}, the reference {want.topics}")
    wrong += [f"{key}: exsce {got[0]!r}, not expected" for key, got in found.items() if key not in expected]
    return wrong


def _told(problems: list[str], metric: str, robot: str | None) -> bool:
    return any(metric in p and (robot is None or f"'{robot}'" in p or f" {robot} " in p) for p in problems)


POSE_LINE = re.compile(r"^\s*pose (\S+) at \(([-\d.]+), ([-\d.]+)\)", re.MULTILINE)
VISIT_LINE = re.compile(r"^\s*visit (.+)$", re.MULTILINE)


def planned_waypoints(spec: str) -> tuple[tuple[float, float], ...]:
    """The waypoints a one-task specification's robot visits, in order (its ``visit`` lines)."""
    poses = {m[1]: (float(m[2]), float(m[3])) for m in POSE_LINE.finditer(spec)}
    names = [n.strip() for line in VISIT_LINE.findall(spec) for n in line.split(",")]
    return tuple(poses[n] for n in names)


# ------------------------------------------------------------------ user metrics and their references

TURTLE_METRICS = """
metric pose_speed for each robot {
  unit m/s
  reads pose: turtlesim/msg/Pose on "/{ns}/pose"
  value max(speed(pose.x, pose.y))
}
metric least_x for each robot {
  unit m
  reads pose: turtlesim/msg/Pose on "/{ns}/pose"
  value min(pose.x)
}
metric most_y for each robot {
  unit m
  reads pose: turtlesim/msg/Pose on "/{ns}/pose"
  value max(pose.y)
}
metric mean_x for each robot {
  unit m
  reads pose: turtlesim/msg/Pose on "/{ns}/pose"
  value mean(pose.x)
}
metric east_time for each robot {
  unit s
  reads pose: turtlesim/msg/Pose on "/{ns}/pose"
  value duration where pose.x > 5.5
}
"""

ODOMETRY_METRICS = """
metric odom_path for each robot {
  unit m
  reads odom: nav_msgs/msg/Odometry on "/{ns}/TOPIC"
  value path_length(odom.pose.pose.position.x, odom.pose.pose.position.y)
}
metric odom_speed for each robot {
  unit m/s
  reads odom: nav_msgs/msg/Odometry on "/{ns}/TOPIC"
  value max(speed(odom.pose.pose.position.x, odom.pose.pose.position.y))
}
metric least_forward for each robot {
  unit m/s
  reads odom: nav_msgs/msg/Odometry on "/{ns}/TOPIC"
  value min(odom.twist.twist.linear.x)
}
metric most_x for each robot {
  unit m
  reads odom: nav_msgs/msg/Odometry on "/{ns}/TOPIC"
  value max(odom.pose.pose.position.x)
}
metric mean_forward for each robot {
  unit m/s
  reads odom: nav_msgs/msg/Odometry on "/{ns}/TOPIC"
  value mean(odom.twist.twist.linear.x)
}
metric brisk_time for each robot {
  unit s
  reads odom: nav_msgs/msg/Odometry on "/{ns}/TOPIC"
  value duration where odom.twist.twist.linear.x > 0.5
}
"""


def _forward(message: object) -> float:
    return float(message.twist.twist.linear.x)  # type: ignore[attr-defined]


def odometry_functions(samples: Samples) -> dict[str, float]:
    """The reference of :data:`ODOMETRY_METRICS` over every message of one odometry."""
    x, y = xy(samples)
    forward = samples.column(_forward)
    return {
        "odom_path": path_length(x, y),
        "odom_speed": float(np.nanmax(speeds(samples.t, x, y))),
        "least_forward": float(forward.min()),
        "most_x": float(x.max()),
        "mean_forward": float(forward.mean()),
        "brisk_time": duration_where(samples.t, forward > 0.5),
    }


def turtle_functions(samples: Samples) -> dict[str, float]:
    """The reference of the turtles' user metrics over every message of one pose topic (float32
    fields, widened to float64)."""
    x, y = (np.array([position(m)[k] for m in samples.messages], dtype=np.float64) for k in (0, 1))
    return {
        "pose_path": path_length(x, y),
        "pose_speed": float(np.nanmax(speeds(samples.t, x, y))),
        "least_x": float(x.min()),
        "most_y": float(y.max()),
        "mean_x": float(x.mean()),
        "east_time": duration_where(samples.t, x > 5.5),
    }


def turtle_references(robots: tuple[str, ...]) -> Callable[[Recording], dict[Key, Expected]]:
    """The reference of the turtles' user metrics (``pose_path`` and :data:`TURTLE_METRICS`)
    of ``robots``, each over ``/{robot}/pose``."""

    def functions(bag: Recording) -> dict[Key, Expected]:
        found: dict[Key, Expected] = {}
        for robot in robots:
            topic = f"/{robot}/pose"
            for name, value in turtle_functions(bag.samples(topic)).items():
                found[(name, robot)] = Expected(value, (topic,))
        return found

    return functions


def odometry_references(robot: str, topic: str) -> Callable[[Recording], dict[Key, Expected]]:
    """The reference of :data:`ODOMETRY_METRICS` of ``robot`` over ``topic``."""

    def functions(bag: Recording) -> dict[Key, Expected]:
        return {(n, robot): Expected(v, (topic,)) for n, v in odometry_functions(bag.samples(topic)).items()}

    return functions
