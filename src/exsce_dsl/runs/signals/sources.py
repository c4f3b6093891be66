"""A robot's signals (pose, velocity, laser scan, distance travelled), read from wherever its
robot type's convention puts them, as the same time series for every robot.

DESIGN §2's middle step: :func:`choose_sources` picks, per signal, the first of the
robot type's sources that the bag has (a TF chain, a topic of a type the signal
can be read from); :func:`signals_wanted` says what to decode of those topics;
:func:`signal_topics` turns what was decoded into one topic per signal under a
name no bag topic can have (``/{ns}/~pose``), with the same fields whatever the
source:

- ``pose``: ``x``, ``y``, ``z`` (metres) and ``yaw`` (radians), from an Odometry's
  or a PoseWithCovarianceStamped's ``pose.pose``, a PoseStamped's ``pose``, or
  the TF chain ``fixed → body`` composed from ``tf`` and ``tf_static`` (at the
  header stamps of the chain's fastest transform: a topic's receive time is the
  recorder's, a transform's stamp the robot's; in a simulation both are the
  simulated clock);
- ``velocity``: ``linear.x|y|z`` and ``angular.x|y|z``, from a Twist, a
  TwistStamped's ``twist`` or an Odometry's ``twist.twist``;
- ``scan``: a LaserScan's fields, as its topic has them;
- ``distance``: ``data``, the distance travelled so far: a Float64 of it (the method's),
  or the path length along an odometry's positions.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field, replace

import numpy as np

from exsce_dsl.errors import TfError
from exsce_dsl.model.conventions import (
    DISTANCE_TYPES,
    FLOAT64,
    LASER_SCAN,
    ODOMETRY,
    POSE_STAMPED,
    POSE_TYPES,
    POSE_WITH_COVARIANCE,
    TWIST,
    TWIST_STAMPED,
    VELOCITY_TYPES,
    TfSource,
    TopicSource,
)
from exsce_dsl.model.messages import FieldPath, canonical_type, path_of
from exsce_dsl.model.metrics import expand_topic, signal_pattern
from exsce_dsl.model.robots import Robot
from exsce_dsl.monitor_kit.monitor_core import Signal, Topic, speed
from exsce_dsl.runs.bags.data import BagData, Series, Wanted
from exsce_dsl.runs.bags.decode import TEXTS
from exsce_dsl.runs.signals.tf_poses import EdgeSeries, FrameTree, default_times, pose_at, yaw_from_quaternion

SIGNALS = ("pose", "velocity", "scan", "distance")
TF_MESSAGE = "tf2_msgs/msg/TFMessage"

_POSE_AT = {ODOMETRY: ("pose", "pose"), POSE_WITH_COVARIANCE: ("pose", "pose"), POSE_STAMPED: ("pose",)}
_VELOCITY_AT = {TWIST: (), TWIST_STAMPED: ("twist",), ODOMETRY: ("twist", "twist")}
_AXES = ("x", "y", "z")
_QUATERNION = ("x", "y", "z", "w")
_VELOCITY_KEYS = tuple(f"{part}.{axis}" for part in ("linear", "angular") for axis in _AXES)
_TF_NUMBERS = tuple(
    path_of("transforms", *steps)
    for steps in [
        ("header", "stamp", "sec"),
        ("header", "stamp", "nanosec"),
        *[("transform", "translation", a) for a in _AXES],
        *[("transform", "rotation", a) for a in _QUATERNION],
    ]
)
_TF_TEXTS = (path_of("transforms", "header", "frame_id"), path_of("transforms", "child_frame_id"))


def signal_topic(signal: str, namespace: str) -> str:
    """The name a robot's signal goes under among a run's topics (``~`` is in no bag's topics)."""
    return expand_topic(signal_pattern(signal), namespace)


@dataclass(frozen=True)
class Chosen:
    """Where one signal of one robot is read in this bag: a topic and its type, or a TF chain."""

    signal: str
    topic: str = ""
    msgtype: str = ""
    tf: TfSource | None = None
    tf_topics: tuple[str, ...] = ()
    fallbacks: tuple[Chosen, ...] = ()
    """For a TF chain: the sources after it that the bag has, tried in order when the bag's
    transforms do not compose the chain (its frames are not there)."""
    from_pose: bool = False
    """Estimated from the robot's pose (its source's topics are the pose's), the bag having
    nothing of this signal: a velocity, or a distance travelled."""
    frames: tuple[str, ...] = ()
    """For a TF chain once read: the frames its transforms composed, the fixed frame first."""

    @property
    def tf_chain(self) -> str | None:
        """``map → odom → base_link``: the transforms a TF chain composed (None: not one)."""
        return " → ".join(self.frames) if self.frames else None

    @property
    def topics(self) -> tuple[str, ...]:
        """The bag's topics it is read from (what a metric's sources name)."""
        return self.tf_topics if self.tf is not None else (self.topic,)

    def with_all(self) -> tuple[Chosen, ...]:
        """This source and its fallbacks, in order."""
        return (replace(self, fallbacks=()), *self.fallbacks)


@dataclass(frozen=True)
class RobotSources:
    """The sources chosen for one robot's signals (a signal the bag lacks is not there)."""

    robot: str
    namespace: str
    chosen: Mapping[str, Chosen]
    notes: tuple[str, ...] = ()
    """Why a signal has no source, for the run's problems."""
    used: dict[str, Chosen] = field(default_factory=dict)
    """The source each signal was read from, once read (a TF chain's fallback, maybe)."""
    three_d: bool = False
    """Whether the robot moves in 3-D: its paths are then measured in x-y-z."""


def choose_sources(robot: Robot, available: Mapping[str, str]) -> RobotSources:
    """For each signal, the first of the robot type's sources that ``available`` (the bag's
    topic → type) has."""
    signals = robot.signals
    ns = robot.namespace
    chosen: dict[str, Chosen] = {}
    notes: list[str] = []
    options: dict[str, tuple[tuple[TopicSource | TfSource, ...], tuple[str, ...]]] = {
        "pose": (signals.pose, POSE_TYPES),
        "velocity": (signals.velocity, VELOCITY_TYPES),
        "scan": (signals.scan, (LASER_SCAN,)),
        "distance": (signals.distance, DISTANCE_TYPES),
    }
    for signal, (sources, types) in options.items():
        found = _first_present(signal, sources, types, ns, available)
        if found is not None:
            chosen[signal] = found
            continue
        pose = chosen.get("pose")
        if pose is not None and signal in ("velocity", "distance"):
            chosen[signal] = replace(pose, signal=signal, from_pose=True)
        estimated = signal == "velocity" and signal in chosen
        if sources and not estimated and signal not in chosen:
            tried = ", ".join(_described(s, ns, types, available) for s in sources)
            notes.append(f"robot '{robot.id}' has no {signal} in this bag (looked for {tried})")
        elif estimated:
            tried = ", ".join(_described(s, ns, types, available) for s in sources) or "none named"
            notes.append(
                f"robot '{robot.id}' has no velocity in this bag (looked for {tried}): its speed is "
                "estimated from its pose"
            )
    return RobotSources(robot.id, ns, chosen, tuple(notes), three_d=robot.three_d)


def _first_present(
    signal: str,
    sources: Iterable[TopicSource | TfSource],
    types: tuple[str, ...],
    ns: str,
    available: Mapping[str, str],
) -> Chosen | None:
    present = [c for source in sources if (c := _present(signal, source, types, ns, available)) is not None]
    if not present:
        return None
    first = present[0]
    if first.tf is None:
        return first
    return replace(first, fallbacks=tuple(dict.fromkeys(present[1:])))


def _present(
    signal: str, source: TopicSource | TfSource, types: tuple[str, ...], ns: str, available: Mapping[str, str]
) -> Chosen | None:
    if isinstance(source, TfSource):
        tf, static = expand_topic(source.tf, ns), expand_topic(source.tf_static, ns)
        if available.get(tf) != TF_MESSAGE:
            return None
        topics = (tf, static) if available.get(static) == TF_MESSAGE else (tf,)
        return Chosen(signal, tf=source, tf_topics=topics)
    topic = expand_topic(source.topic, ns)
    msgtype = available.get(topic)
    if msgtype is None or msgtype not in types:
        return None
    if source.msgtype is not None and canonical_type(source.msgtype) != msgtype:
        return None
    return Chosen(signal, topic, msgtype)


def _described(
    source: TopicSource | TfSource, ns: str, types: tuple[str, ...], available: Mapping[str, str]
) -> str:
    """A source looked for, and what the bag has there instead when it has the topic."""
    if isinstance(source, TfSource):
        return f"TF {source.fixed} -> {source.body} on {expand_topic(source.tf, ns)}"
    topic = expand_topic(source.topic, ns)
    there = available.get(topic)
    expected = (canonical_type(source.msgtype),) if source.msgtype else types
    if there is None or there in expected:
        return topic
    return f"{topic}, which carries {there}, not {' or '.join(expected)}"


def signals_wanted(sources: Iterable[RobotSources], scan_paths: Iterable[FieldPath]) -> dict[str, Wanted]:
    """What to decode of each topic the chosen sources read (``scan_paths``: what the metrics read
    of a scan, which is kept as it is)."""
    wanted: dict[str, Wanted] = {}

    def want(topic: str, msgtype: str, paths: Iterable[FieldPath], texts: Iterable[FieldPath] = ()) -> None:
        before = wanted.get(topic, Wanted(msgtype))
        merged_paths = tuple(dict.fromkeys([*before.paths, *paths]))
        merged_texts = tuple(dict.fromkeys([*before.texts, *texts]))
        wanted[topic] = Wanted(msgtype, merged_paths, merged_texts, rows=bool(merged_texts))

    for robot in sources:
        for chosen in (c for first in robot.chosen.values() for c in first.with_all()):
            if chosen.from_pose:
                continue  # computed from the pose, which is read for itself
            if chosen.tf is not None:
                for topic in chosen.tf_topics:
                    want(topic, TF_MESSAGE, _TF_NUMBERS, _TF_TEXTS)
            elif chosen.signal == "pose":
                want(chosen.topic, chosen.msgtype, _pose_paths(chosen.msgtype))
            elif chosen.signal == "velocity":
                want(chosen.topic, chosen.msgtype, _velocity_paths(chosen.msgtype))
            elif chosen.signal == "scan":
                want(chosen.topic, chosen.msgtype, scan_paths)
            elif chosen.msgtype == FLOAT64:
                want(chosen.topic, chosen.msgtype, [path_of("data")])
            else:
                want(chosen.topic, chosen.msgtype, _pose_paths(chosen.msgtype))
    return wanted


def _pose_paths(msgtype: str) -> list[FieldPath]:
    prefix = _POSE_AT[msgtype]
    return [path_of(*prefix, "position", a) for a in _AXES] + [
        path_of(*prefix, "orientation", a) for a in _QUATERNION
    ]


def _velocity_paths(msgtype: str) -> list[FieldPath]:
    prefix = _VELOCITY_AT[msgtype]
    return [path_of(*prefix, *key.split(".")) for key in _VELOCITY_KEYS]


def signal_topics(robot: RobotSources, data: BagData, problems: list[str] | None = None) -> dict[str, Topic]:
    """The robot's signals as topics (:func:`signal_topic` names), from what the bag gave; a TF
    chain the bag's transforms cannot compose passes to the next source, and when none is left
    the signal is left out and ``problems`` says why (without ``problems``: :class:`TfError`).
    ``robot.used`` records the source each signal came from."""
    found: dict[str, Topic] = {}
    for signal, first in robot.chosen.items():
        name = signal_topic(signal, robot.namespace)
        failures: list[tuple[Chosen, str]] = []
        for chosen in first.with_all():
            topic: Topic | None
            try:
                if chosen.tf is not None and not chosen.from_pose:
                    topic, frames = _tf_pose(name, chosen, data)
                    chosen = replace(chosen, frames=frames)
                else:
                    topic = _signal(name, signal, chosen, data, found, robot.three_d)
            except TfError as exc:
                failures.append((chosen, exc.message))
                continue
            if topic is not None:
                found[name] = topic
                pose = robot.used.get("pose")
                if chosen.from_pose and pose is not None:  # estimated from the pose: its chain
                    chosen = replace(chosen, frames=pose.frames)
                robot.used[signal] = chosen
            break
        if name in found or not failures:
            continue
        said = _tf_failures(failures)
        if problems is None:
            raise TfError(said)
        problems.append(f"robot '{robot.robot}': no {signal} from TF on {said}")
    return found


def _tf_failures(failures: list[tuple[Chosen, str]]) -> str:
    """``/tf: no frame ...``, or each chain that was tried with why it failed."""
    topic = failures[0][0].topics[0]
    if len(failures) == 1:
        return f"{topic}: {failures[0][1]}"
    return topic + ": " + "; ".join(f"{c.tf.clause() if c.tf else c.topic}: {why}" for c, why in failures)


def _signal(
    name: str, signal: str, chosen: Chosen, data: BagData, found: Mapping[str, Topic], three_d: bool
) -> Topic | None:
    """One signal from one source (None: the bag gave none of its topic's messages); ``found``:
    the signals computed so far (the pose, for what is estimated from it)."""
    if chosen.from_pose:
        pose = found.get(name.rsplit("~", 1)[0] + "~pose")
        if pose is None:
            return None
        return _speed(name, pose, three_d) if signal == "velocity" else _path(name, pose, three_d)
    series = data.series.get(chosen.topic)
    if series is None:
        return None
    if signal == "pose":
        return _pose(name, series, _POSE_AT[chosen.msgtype])
    if signal == "velocity":
        prefix = ".".join(_VELOCITY_AT[chosen.msgtype])
        fields = {key: series.fields[f"{prefix}.{key}" if prefix else key] for key in _VELOCITY_KEYS}
        if not three_d:  # a planar robot's speed is in x-y: max_velocity is the norm of linear
            fields["linear.z"] = np.zeros(len(series.t))
        return Topic(name, series.t, fields)
    if signal == "distance" and chosen.msgtype != FLOAT64:
        return _distance(name, series, _POSE_AT[chosen.msgtype], three_d)
    return Topic(name, series.t, dict(series.fields))


def _distance(name: str, series: Series, prefix: tuple[str, ...], three_d: bool) -> Topic:
    """The distance travelled so far along a pose topic's path (``data``, as the method's Float64)."""
    at = ".".join(prefix)
    position = {a: series.fields[f"{at}.position.{a}"] for a in _AXES}
    return _path(name, Topic(name, series.t, position), three_d)


def _path(name: str, pose: Topic, three_d: bool) -> Topic:
    """The distance travelled so far along ``pose``'s positions, in x-y (x-y-z when ``three_d``)."""
    axes = _AXES if three_d else _AXES[:2]
    steps = np.sqrt(sum(np.square(np.diff(pose.fields[a])) for a in axes))
    return Topic(name, pose.t, {"data": np.concatenate([[0.0], np.cumsum(steps)])})


def _speed(name: str, pose: Topic, three_d: bool) -> Topic:
    """A velocity estimated from ``pose``: ``linear.x`` the speed along the path (the monitors'
    ``speed``: the straight distance between the positions 0.25 s before and after, over that
    time, so that a centimetre of pose noise costs centimetres per second, not metres); the other
    components 0."""
    axes = _AXES if three_d else _AXES[:2]
    moving = speed(*(Signal(pose.t, pose.fields[a]) for a in axes))
    zeros = np.zeros(len(pose.t))
    fields = {key: zeros for key in _VELOCITY_KEYS}
    fields["linear.x"] = moving.v  # no value (NaN) where the pose has a single time
    return Topic(name, pose.t, fields)


def _pose(name: str, series: Series, prefix: tuple[str, ...]) -> Topic:
    at = ".".join(prefix)
    position = {a: series.fields[f"{at}.position.{a}"] for a in _AXES}
    quaternion = np.stack([series.fields[f"{at}.orientation.{a}"] for a in _QUATERNION], axis=1)
    return Topic(name, series.t, {**position, "yaw": yaw_from_quaternion(quaternion)})


def _tf_pose(name: str, chosen: Chosen, data: BagData) -> tuple[Topic, tuple[str, ...]]:
    """The pose of the chain's body frame in its fixed frame, at the fastest transform's stamps,
    and the frames the chain composed (the fixed frame first)."""
    assert chosen.tf is not None
    edges: dict[tuple[str, str], EdgeSeries] = {}
    for topic in chosen.tf_topics:
        series = data.series.get(topic)
        if series is None:
            continue
        static = topic != chosen.tf_topics[0]
        for edge in _edges(series, static):
            key = (edge.parent, edge.child)
            if key not in edges or not static:  # a transform on both: the dynamic one
                edges[key] = edge
    tree = FrameTree(edges.values())
    fixed, body = chosen.tf.fixed, chosen.tf.body
    times = default_times(tree, fixed, body)
    poses = pose_at(tree, fixed, body, times)
    keep = poses.valid
    if not keep.any():
        raise TfError(f"no time at which every transform of {fixed} -> {body} is known")
    position = poses.position[keep]
    fields = {"x": position[:, 0], "y": position[:, 1], "z": position[:, 2], "yaw": poses.yaw[keep]}
    chain = tree.chain(fixed, body)
    frames = (fixed, *(e.parent for e in chain.up), *(e.child for e in chain.down))
    return Topic(name, poses.times[keep], fields), frames


def _edges(series: Series, static: bool) -> list[EdgeSeries]:
    """One edge series per (parent, child) pair of the TFMessages' transforms."""
    fields = series.fields
    texts = fields[TEXTS] if TEXTS in fields else np.array([], dtype=object)
    parents = fields["transforms.header.frame_id"]
    children = fields["transforms.child_frame_id"]
    held = ~np.isnan(children)
    if not held.any():
        return []
    stamp = fields["transforms.header.stamp.sec"] + fields["transforms.header.stamp.nanosec"] * 1e-9
    translation = np.stack([fields[f"transforms.transform.translation.{a}"][held] for a in _AXES], axis=1)
    rotation = np.stack([fields[f"transforms.transform.rotation.{a}"][held] for a in _QUATERNION], axis=1)
    parent_codes, child_codes, times = parents[held].astype(int), children[held].astype(int), stamp[held]
    pairs = parent_codes * len(texts) + child_codes  # one integer per (parent, child): cheap to sort
    distinct, which = np.unique(pairs, return_inverse=True)
    which = which.ravel()
    edges = []
    for k, pair in enumerate(distinct.tolist()):
        mine = which == k
        parent, child = divmod(pair, len(texts))
        edges.append(
            EdgeSeries(
                str(texts[parent]), str(texts[child]), times[mine], translation[mine], rotation[mine], static
            )
        )
    return edges
