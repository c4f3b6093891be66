"""Small bags for the tests, written with rosbags' own writers in every format exsce reads.

A bag is a list of :class:`Topic`\\ s (a topic, its message type and its
``(time_ns, message)`` pairs), written by :func:`write_bag` as a ROS 1 bag
(plain, bz2 or lz4 chunks), a ROS 2 sqlite3 folder (plain, or zstd per message
or per file) or a ROS 2 MCAP folder (plain or zstd chunks).  What real bags do
and a reader must cope with is on offer: two connections on one topic (two
publishers), messages written out of time order and spread over many small
chunks, and types that only the bag defines (``turtlesim/msg/Pose``, and
``tf2_msgs/msg/TFMessage`` in ROS 1, which rosbags' noetic store lacks).

rosbags cannot write MCAP chunks compressed with lz4 (its MCAP reader reads them,
its writer only knows zstd), so no format here has them.

Messages are rosbags objects of the format's typestore (:func:`typestore_for`:
ROS 1's ``std_msgs/Header`` has a ``seq``, ROS 2's has not), or bytes already serialised in
the format's encoding (a message copied from another bag); the builders
(:func:`odometry`, :func:`pose_stamped`, :func:`twist_stamped`, :func:`imu`,
:func:`tf_message`, :func:`laser_scan`, :func:`turtle_pose`) make the ``index``-th
message of a series from a seed, the same values every time.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from rosbags.interfaces import Qos, QosDurability, QosHistory, QosLiveliness, QosReliability, QosTime
from rosbags.rosbag1 import Writer as Ros1Writer
from rosbags.rosbag2 import StoragePlugin
from rosbags.rosbag2 import Writer as Ros2Writer
from rosbags.rosbag2.enums import CompressionFormat, CompressionMode
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from exsce_dsl.messages.navigation import ros2_message_definition

TURTLE_POSE = "turtlesim/msg/Pose"
TURTLE_POSE_MSG = """\
float32 x
float32 y
float32 theta
float32 linear_velocity
float32 angular_velocity
"""
TF_MESSAGE = "tf2_msgs/msg/TFMessage"

ODOMETRY = "nav_msgs/msg/Odometry"
POSE_STAMPED = "geometry_msgs/msg/PoseStamped"
TWIST_STAMPED = "geometry_msgs/msg/TwistStamped"
IMU = "sensor_msgs/msg/Imu"
LASER_SCAN = "sensor_msgs/msg/LaserScan"

START_NS = 1_700_000_000_000_000_000
PERIOD_NS = 50_000_000


@dataclass(frozen=True)
class BagFormat:
    """How a bag is written: ROS 1 or 2, its storage and its compression."""

    name: str
    ros: int
    storage: StoragePlugin | None = None
    compression: str | None = None
    """ROS 1: ``bz2`` or ``lz4`` chunks; ROS 2: zstd per ``message``, per ``file``, or the
    ``storage``'s own (MCAP's chunks)."""

    @property
    def cdr(self) -> bool:
        return self.ros == 2


FORMATS = {
    f.name: f
    for f in (
        BagFormat("ros1", 1),
        BagFormat("ros1-bz2", 1, compression="bz2"),
        BagFormat("ros1-lz4", 1, compression="lz4"),
        BagFormat("sqlite3", 2, StoragePlugin.SQLITE3),
        BagFormat("sqlite3-zstd-message", 2, StoragePlugin.SQLITE3, "message"),
        BagFormat("sqlite3-zstd-file", 2, StoragePlugin.SQLITE3, "file"),
        BagFormat("mcap", 2, StoragePlugin.MCAP),
        BagFormat("mcap-zstd", 2, StoragePlugin.MCAP, "storage"),
    )
}


@dataclass(frozen=True)
class Topic:
    """One connection of a bag: ``messages`` are ``(time_ns, message object)``, written in this
    order.  ``publisher`` tells connections of one topic and type apart (ROS 1: its caller id;
    ROS 2: the depth of its offered QoS).  ``msgdef`` is a ROS 1 connection's definition text
    (with ``md5sum``); by default the typestore's ``generate_msgdef``."""

    name: str
    msgtype: str
    messages: Sequence[tuple[int, Any]]
    publisher: int = 0
    msgdef: str | None = None
    md5sum: str | None = None


@dataclass
class WrittenBag:
    """A written bag: the path to open it with, its format, and what was written to it."""

    path: Path
    format: BagFormat
    topics: list[Topic] = field(default_factory=list)

    @property
    def message_count(self) -> int:
        return sum(len(t.messages) for t in self.topics)


# ------------------------------------------------------------------ typestores


def typestore_for(fmt: BagFormat | str) -> Any:
    """A fresh typestore of the format's ROS version, with the types only bags define here
    (turtlesim's Pose; ROS 1's TFMessage) registered, to make messages and write them."""
    bag_format = FORMATS[fmt] if isinstance(fmt, str) else fmt
    store = get_typestore(Stores.ROS1_NOETIC if bag_format.ros == 1 else Stores.ROS2_HUMBLE)
    extra = get_types_from_msg(TURTLE_POSE_MSG, TURTLE_POSE)
    if TF_MESSAGE not in store.fielddefs:
        extra.update(get_types_from_msg("geometry_msgs/TransformStamped[] transforms", TF_MESSAGE))
    store.register(extra)
    return store


# ------------------------------------------------------------------ writing


def write_bag(
    path: Path,
    fmt: BagFormat | str,
    topics: Sequence[Topic],
    store: Any | None = None,
    order: str = "time",
    chunk_bytes: int | None = None,
) -> WrittenBag:
    """Write ``topics`` to a new bag at ``path`` (a ``.bag`` file for ROS 1, a folder for ROS 2).

    ``order``: ``time`` writes every message by time (connections interleaved, ties in topic
    order); ``given`` writes each topic's messages in turn, as listed, so that time goes back
    between connections (and within one, if its list is not sorted).  ``chunk_bytes`` closes a
    chunk (ROS 1, MCAP) once it holds that many bytes, so that a few messages fill many chunks
    (rosbags' own threshold is 1 MiB; for MCAP this reaches into rosbags' MCAP writer).
    """
    bag_format = FORMATS[fmt] if isinstance(fmt, str) else fmt
    store = store if store is not None else typestore_for(bag_format)
    path = Path(path)
    if bag_format.ros == 1:
        _write_ros1(path, bag_format, topics, store, order, chunk_bytes)
    else:
        _write_ros2(path, bag_format, topics, store, order, chunk_bytes)
    return WrittenBag(path, bag_format, list(topics))


def _in_order(topics: Sequence[Topic], order: str) -> list[tuple[int, int, Any]]:
    """(connection index, time, message) in the order to write them."""
    items = [(i, t, m) for i, topic in enumerate(topics) for t, m in topic.messages]
    if order == "time":
        return sorted(items, key=lambda x: (x[1], x[0]))
    if order == "given":
        return items
    raise ValueError(f"unknown order {order!r}: 'time' or 'given'")


def _write_ros1(
    path: Path, fmt: BagFormat, topics: Sequence[Topic], store: Any, order: str, chunk_bytes: int | None
) -> None:
    writer = Ros1Writer(path)
    if fmt.compression is not None:
        writer.set_compression(Ros1Writer.CompressionFormat[fmt.compression.upper()])
    if chunk_bytes is not None:
        writer.chunk_threshold = chunk_bytes
    with writer:
        connections = []
        for topic in topics:
            msgdef, md5sum = topic.msgdef, topic.md5sum
            if msgdef is None or md5sum is None:
                msgdef, md5sum = store.generate_msgdef(topic.msgtype)
            connections.append(
                writer.add_connection(
                    topic.name,
                    topic.msgtype,
                    msgdef=msgdef,
                    md5sum=md5sum,
                    callerid=f"/publisher_{topic.publisher}",
                )
            )
        for i, time_ns, message in _in_order(topics, order):
            writer.write(connections[i], time_ns, _serialised(message, store.serialize_ros1, topics[i].msgtype))


def _serialised(message: Any, serialise: Callable[[Any, str], Any], msgtype: str) -> Any:
    """``message``'s bytes: already serialised (in the bag's encoding), or by ``serialise``."""
    return message if isinstance(message, bytes | bytearray | memoryview) else serialise(message, msgtype)


def _qos(depth: int) -> Qos:
    never = QosTime(0, 0)
    return Qos(
        QosHistory.KEEP_LAST,
        depth,
        QosReliability.RELIABLE,
        QosDurability.VOLATILE,
        never,
        never,
        QosLiveliness.AUTOMATIC,
        never,
        False,
    )


def _write_ros2(
    path: Path, fmt: BagFormat, topics: Sequence[Topic], store: Any, order: str, chunk_bytes: int | None
) -> None:
    assert fmt.storage is not None
    writer = Ros2Writer(path, version=9, storage_plugin=fmt.storage)
    if fmt.compression is not None:
        writer.set_compression(CompressionMode[fmt.compression.upper()], CompressionFormat.ZSTD)
    with writer:
        connections = [
            writer.add_connection(
                topic.name,
                topic.msgtype,
                typestore=store,
                offered_qos_profiles=[_qos(10 + topic.publisher)],
                **_action_definition(store, topic.msgtype),
            )
            for topic in topics
        ]
        for i, time_ns, message in _in_order(topics, order):
            writer.write(connections[i], time_ns, _serialised(message, store.serialize_cdr, topics[i].msgtype))
            storage = writer.storage
            if (
                chunk_bytes is not None
                and hasattr(storage, "close_chunk")
                and storage.chunk.bio.tell() > chunk_bytes
            ):
                storage.close_chunk()


def _action_definition(store: Any, msgtype: str) -> dict[str, str]:
    """An action type's definition and hash, which rosbags' generator does not write."""
    if "/action/" not in msgtype:
        return {}
    return {"msgdef": ros2_message_definition(store, msgtype), "rihs01": store.hash_rihs01(msgtype)}


# ------------------------------------------------------------------ messages


def _rng(seed: int, index: int) -> np.random.Generator:
    return np.random.default_rng([seed, index])


def stamp(store: Any, time_ns: int) -> Any:
    return store.types["builtin_interfaces/msg/Time"](sec=time_ns // 10**9, nanosec=time_ns % 10**9)


def header(store: Any, time_ns: int, frame_id: str, index: int = 0) -> Any:
    """A ``std_msgs/Header`` (with ``seq = index`` in ROS 1)."""
    cls = store.types["std_msgs/msg/Header"]
    extra = {"seq": index} if "seq" in cls.__dataclass_fields__ else {}
    return cls(stamp=stamp(store, time_ns), frame_id=frame_id, **extra)


def vector3(store: Any, values: Sequence[float]) -> Any:
    x, y, z = (float(v) for v in values)
    return store.types["geometry_msgs/msg/Vector3"](x=x, y=y, z=z)


def point(store: Any, values: Sequence[float]) -> Any:
    x, y, z = (float(v) for v in values)
    return store.types["geometry_msgs/msg/Point"](x=x, y=y, z=z)


def quaternion(store: Any, yaw: float) -> Any:
    return store.types["geometry_msgs/msg/Quaternion"](
        x=0.0, y=0.0, z=float(np.sin(yaw / 2)), w=float(np.cos(yaw / 2))
    )


def pose(store: Any, rng: np.random.Generator) -> Any:
    return store.types["geometry_msgs/msg/Pose"](
        position=point(store, rng.uniform(-10, 10, 3)),
        orientation=quaternion(store, rng.uniform(-np.pi, np.pi)),
    )


def twist(store: Any, rng: np.random.Generator) -> Any:
    return store.types["geometry_msgs/msg/Twist"](
        linear=vector3(store, rng.uniform(-1, 1, 3)), angular=vector3(store, rng.uniform(-2, 2, 3))
    )


def odometry(store: Any, index: int, time_ns: int, seed: int = 0, frame_id: str = "odom") -> Any:
    rng = _rng(seed, index)
    t = store.types
    return t[ODOMETRY](
        header=header(store, time_ns, frame_id, index),
        child_frame_id="base_link",
        pose=t["geometry_msgs/msg/PoseWithCovariance"](
            pose=pose(store, rng), covariance=rng.uniform(0, 0.1, 36)
        ),
        twist=t["geometry_msgs/msg/TwistWithCovariance"](
            twist=twist(store, rng), covariance=rng.uniform(0, 0.1, 36)
        ),
    )


def odometry_at(store: Any, index: int, stamp_ns: int, x: float, y: float = 0.0, yaw: float = 0.0) -> Any:
    """An odometry message placing the robot at (``x``, ``y``) facing ``yaw``, its twist zero (the
    tests that use it read the path, not the odometry's own velocity)."""
    t = store.types
    body = t["geometry_msgs/msg/Pose"](position=point(store, (x, y, 0.0)), orientation=quaternion(store, yaw))
    zero = vector3(store, (0.0, 0.0, 0.0))
    return t[ODOMETRY](
        header=header(store, stamp_ns, "odom", index),
        child_frame_id="base_link",
        pose=t["geometry_msgs/msg/PoseWithCovariance"](pose=body, covariance=np.zeros(36)),
        twist=t["geometry_msgs/msg/TwistWithCovariance"](
            twist=t["geometry_msgs/msg/Twist"](linear=zero, angular=zero), covariance=np.zeros(36)
        ),
    )


def pose_stamped(store: Any, index: int, time_ns: int, seed: int = 0, frame_id: str = "map") -> Any:
    return store.types[POSE_STAMPED](
        header=header(store, time_ns, frame_id, index), pose=pose(store, _rng(seed, index))
    )


def twist_stamped(store: Any, index: int, time_ns: int, seed: int = 0, frame_id: str = "base_link") -> Any:
    return store.types[TWIST_STAMPED](
        header=header(store, time_ns, frame_id, index), twist=twist(store, _rng(seed, index))
    )


def imu(store: Any, index: int, time_ns: int, seed: int = 0, frame_id: str = "imu_link") -> Any:
    rng = _rng(seed, index)
    return store.types[IMU](
        header=header(store, time_ns, frame_id, index),
        orientation=quaternion(store, rng.uniform(-np.pi, np.pi)),
        orientation_covariance=rng.uniform(0, 0.01, 9),
        angular_velocity=vector3(store, rng.uniform(-1, 1, 3)),
        angular_velocity_covariance=rng.uniform(0, 0.01, 9),
        linear_acceleration=vector3(store, rng.uniform(-9.9, 9.9, 3)),
        linear_acceleration_covariance=rng.uniform(0, 0.01, 9),
    )


TF_CHILDREN = ("odom", "base_link", "base_laser_link")


def tf_message(store: Any, index: int, time_ns: int, seed: int = 0) -> Any:
    """Three transforms (``map`` → ``odom``, ``odom`` → ``base_link``, ``base_link`` →
    ``base_laser_link``): child frame ids of three lengths, in an order that turns with
    ``index`` so that the same child is not always at the same place."""
    rng = _rng(seed, index)
    t = store.types
    parents = {"odom": "map", "base_link": "odom", "base_laser_link": "base_link"}
    transforms = []
    for k in range(3):
        child = TF_CHILDREN[(k + index) % 3]
        transform = t["geometry_msgs/msg/Transform"](
            translation=vector3(store, rng.uniform(-5, 5, 3)),
            rotation=quaternion(store, rng.uniform(-np.pi, np.pi)),
        )
        transforms.append(
            t["geometry_msgs/msg/TransformStamped"](
                header=header(store, time_ns, parents[child], index),
                child_frame_id=child,
                transform=transform,
            )
        )
    return t[TF_MESSAGE](transforms=transforms)


def laser_scan(store: Any, index: int, time_ns: int, seed: int = 0, frame_id: str = "base_laser_link") -> Any:
    """A scan of 8 to 12 beams (the count changes with ``index``), float32 ranges."""
    rng = _rng(seed, index)
    beams = 8 + index % 5
    return store.types[LASER_SCAN](
        header=header(store, time_ns, frame_id, index),
        angle_min=-1.5,
        angle_max=1.5,
        angle_increment=3.0 / max(beams - 1, 1),
        time_increment=0.0,
        scan_time=0.1,
        range_min=0.05,
        range_max=30.0,
        ranges=rng.uniform(0.1, 30, beams).astype(np.float32),
        intensities=rng.uniform(0, 100, beams).astype(np.float32),
    )


def turtle_pose(store: Any, index: int, time_ns: int, seed: int = 0) -> Any:
    rng = _rng(seed, index)
    x, y, theta, linear, angular = (float(v) for v in rng.uniform(-5, 5, 5).astype(np.float32))
    return store.types[TURTLE_POSE](x=x, y=y, theta=theta, linear_velocity=linear, angular_velocity=angular)


Builder = Callable[..., Any]

BUILDERS: dict[str, Builder] = {
    ODOMETRY: odometry,
    POSE_STAMPED: pose_stamped,
    TWIST_STAMPED: twist_stamped,
    IMU: imu,
    TF_MESSAGE: tf_message,
    LASER_SCAN: laser_scan,
    TURTLE_POSE: turtle_pose,
}
"""Message builders by type: ``builder(store, index, time_ns, seed=...)``."""


def series(
    store: Any,
    msgtype: str,
    count: int,
    seed: int = 0,
    start_ns: int = START_NS,
    period_ns: int = PERIOD_NS,
) -> list[tuple[int, Any]]:
    """``count`` messages of ``msgtype``, one every ``period_ns`` from ``start_ns``."""
    builder = BUILDERS[msgtype]
    return [
        (start_ns + i * period_ns, builder(store, i, start_ns + i * period_ns, seed=seed))
        for i in range(count)
    ]


STANDARD_TOPICS = {
    "/odom": ODOMETRY,
    "/robot_pose": POSE_STAMPED,
    "/cmd_vel": TWIST_STAMPED,
    "/imu": IMU,
    "/tf": TF_MESSAGE,
    "/scan": LASER_SCAN,
    "/turtle1/pose": TURTLE_POSE,
}


def standard_topics(store: Any, count: int = 5, seed: int = 0) -> list[Topic]:
    """One topic of each builder's type, ``count`` messages each, at staggered times."""
    return [
        Topic(name, msgtype, series(store, msgtype, count, seed=seed + k, start_ns=START_NS + k * 1_000_000))
        for k, (name, msgtype) in enumerate(STANDARD_TOPICS.items())
    ]


def two_publishers(store: Any, name: str = "/wheel/odom", count: int = 4, seed: int = 0) -> list[Topic]:
    """Two connections of one topic and type: publisher 0 at even, publisher 1 at odd periods."""
    return [
        Topic(
            name,
            ODOMETRY,
            series(
                store,
                ODOMETRY,
                count,
                seed=seed + p,
                start_ns=START_NS + p * PERIOD_NS,
                period_ns=2 * PERIOD_NS,
            ),
            publisher=p,
        )
        for p in (0, 1)
    ]


def out_of_order(
    store: Any, msgtype: str = TURTLE_POSE, name: str = "/turtle1/pose", count: int = 12
) -> Topic:
    """A topic whose messages are listed latest first: with ``order="given"`` and small chunks,
    each chunk is earlier than the one before it."""
    return Topic(name, msgtype, list(reversed(series(store, msgtype, count))))
