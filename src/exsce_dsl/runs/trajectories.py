"""The paths robots drove in a run, read from the pose topics of its bag (for plots)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from rosbags.highlevel import AnyReader

from exsce_dsl.model.messages import FieldPath, path_of
from exsce_dsl.runs import ros1_index
from exsce_dsl.runs.bagdata import BagError, Wanted, read_bag, typestore_for

POSITION_FIELDS = {
    "geometry_msgs/msg/PoseWithCovarianceStamped": ("pose", "pose", "position"),
    "geometry_msgs/msg/PoseStamped": ("pose", "position"),
    "nav_msgs/msg/Odometry": ("pose", "pose", "position"),
}
"""Message types that say where a robot is, and the path of the position in each."""


def _xy(msgtype: str) -> tuple[FieldPath, FieldPath]:
    prefix = POSITION_FIELDS[msgtype]
    return path_of(*prefix, "x"), path_of(*prefix, "y")


@dataclass(frozen=True)
class Trajectory:
    topic: str
    t: np.ndarray
    """Seconds since the start of the bag."""
    xy: np.ndarray
    """Positions, shape (n, 2), in the map frame."""


def pose_topics(path: Path) -> dict[str, str]:
    """Topic → message type of the bag's topics that carry a robot's pose."""
    if not path.exists():
        raise BagError(f"{path}: no such bag")
    if path.is_file() and path.suffix == ".bag":
        try:  # a ROS 1 bag's own index: ten times faster than opening it with rosbags
            return {t: m for t, m in ros1_index.connections(path).items() if m in POSITION_FIELDS}
        except ros1_index.UnsupportedBag:
            pass  # rosbags reads what the index reader does not, and reports what is broken
    try:
        with AnyReader([path], default_typestore=typestore_for(path)) as reader:
            return {c.topic: c.msgtype for c in reader.connections if c.msgtype in POSITION_FIELDS}
    except Exception as exc:  # rosbags' readers raise their own errors for corrupt files
        raise BagError(f"{path}: cannot read the bag: {type(exc).__name__}: {exc}") from None


def trajectories(path: Path, max_points: int = 2000) -> list[Trajectory]:
    """Each pose topic's path, thinned to at most ``max_points`` positions (first and last kept)."""
    wanted = pose_topics(path)
    if not wanted:
        return []
    data = read_bag(path, {topic: Wanted(msgtype, _xy(msgtype)) for topic, msgtype in wanted.items()})
    found = []
    for topic, msgtype in sorted(wanted.items()):
        series = data.series.get(topic)
        if series is None or len(series) == 0:
            continue
        x, y = _xy(msgtype)
        xy = np.column_stack([series.fields[x.key], series.fields[y.key]]).astype(float)
        keep = np.unique(np.linspace(0, len(xy) - 1, min(len(xy), max_points)).round().astype(int))
        found.append(Trajectory(topic, series.t[keep] - data.start, xy[keep]))
    return found
