"""The paths robots drove in a run, in the map frame, read from their bag (for plots).

The report does not know the robots' types, so each robot's pose is taken from
the bag's own evidence, in the order the conventions prefer it: TF ``map →
base_link`` on the namespace's ``tf``, the method's ``robot_pose``, AMCL's
``amcl_pose``, any other pose topic, and last the odometry (which drifts away
from the map).  A robot is a namespace with any of these.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from exsce_dsl.model.conventions import METHOD_TOPICS, POSE_TYPES, TfSource
from exsce_dsl.runs.bags.names import topic_key
from exsce_dsl.runs.bags.reading import bag_topics, read_bag
from exsce_dsl.runs.signals.sources import (
    TF_MESSAGE,
    Chosen,
    RobotSources,
    signal_topic,
    signal_topics,
    signals_wanted,
)

_PREFERRED = (METHOD_TOPICS["pose"].rsplit("/", 1)[-1], "amcl_pose")
_LAST = ("odom",)


@dataclass(frozen=True)
class Trajectory:
    topic: str
    """Where the path was read: a pose topic, or ``/ns/tf (map → base_link)``."""
    t: np.ndarray
    """Seconds since the start of the bag."""
    xy: np.ndarray
    """Positions, shape (n, 2), in the map frame."""


def pose_sources(available: Mapping[str, str]) -> list[RobotSources]:
    """Per namespace of the bag (topic → type) that says where a robot is, its preferred source."""
    spaces: dict[str, list[str]] = {}
    for topic, msgtype in sorted(available.items()):
        absolute = topic_key(topic)  # a bag's relative 'tf' is at the root, as '/tf' is
        if msgtype in POSE_TYPES or (msgtype == TF_MESSAGE and absolute.endswith("/tf")):
            spaces.setdefault(absolute.rsplit("/", 1)[0], []).append(topic)
    found = []
    for ns, topics in sorted(spaces.items()):
        names = {topic_key(t).rsplit("/", 1)[1]: t for t in topics}
        order = [*_PREFERRED, *sorted(set(names) - {*_PREFERRED, *_LAST, "tf"}), *_LAST]
        chosen = [
            Chosen("pose", names[n], available[names[n]])
            for n in order
            if n in names and available[names[n]] in POSE_TYPES
        ]
        tf = TfSource(tf=f"{ns}/tf", tf_static=f"{ns}/tf_static")
        if "tf" in names:
            static = (f"{ns}/tf_static",) if available.get(f"{ns}/tf_static") == TF_MESSAGE else ()
            chosen.insert(0, Chosen("pose", tf=tf, tf_topics=(f"{ns}/tf", *static)))
        if chosen:
            found.append(RobotSources(ns or "/", ns.strip("/"), {"pose": chosen[0]}, ()))
            found += [RobotSources(ns or "/", ns.strip("/"), {"pose": c}, ()) for c in chosen[1:2]]
    return found


def trajectories(path: Path, max_points: int = 2000) -> list[Trajectory]:
    """Each robot's path in the map frame, thinned to at most ``max_points`` positions (first and
    last kept); a robot whose TF has no ``map → base_link`` chain is drawn from its next source."""
    candidates = pose_sources(bag_topics(path))
    if not candidates:
        return []
    data = read_bag(path, signals_wanted(candidates, []))
    found: list[Trajectory] = []
    drawn: set[str] = set()
    for sources in candidates:
        if sources.robot in drawn:
            continue
        problems: list[str] = []
        pose = signal_topics(sources, data, problems).get(signal_topic("pose", sources.namespace))
        if pose is None or not len(pose):
            continue
        drawn.add(sources.robot)
        chosen = sources.chosen["pose"]
        label = f"{chosen.topics[0]} (map → base_link)" if chosen.tf is not None else chosen.topic
        xy = np.column_stack([pose.fields["x"], pose.fields["y"]]).astype(float)
        keep = np.unique(np.linspace(0, len(xy) - 1, min(len(xy), max_points)).round().astype(int))
        found.append(Trajectory(label, pose.t[keep] - data.start, xy[keep]))
    return found
