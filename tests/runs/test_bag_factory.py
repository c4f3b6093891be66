"""The bag factory (:mod:`tests.support.bag_factory`) writes what it says: read back with rosbags' AnyReader,
which takes every type from the bag itself, each bag holds its connections, types and messages
byte for byte, in time order however they were written, compressed as asked."""

from __future__ import annotations

import struct
from collections import Counter
from pathlib import Path

import numpy as np
import pytest
from rosbags.highlevel import AnyReader
from rosbags.rosbag1 import Reader as Ros1Reader
from rosbags.rosbag2 import Reader as Ros2Reader
from rosbags.typesys import Stores, get_typestore

from tests.support import bag_factory as factory

FORMAT_NAMES = list(factory.FORMATS)


def bag_path(folder: Path, fmt: str) -> Path:
    return folder / (f"{fmt}.bag" if factory.FORMATS[fmt].ros == 1 else fmt)


def serialise(fmt: str, store: object, message: object, msgtype: str) -> bytes:
    if factory.FORMATS[fmt].ros == 1:
        return bytes(store.serialize_ros1(message, msgtype))  # type: ignore[attr-defined]
    return bytes(store.serialize_cdr(message, msgtype))  # type: ignore[attr-defined]


def mcap_chunks(path: Path) -> list[tuple[int, int, str]]:
    """(start time, end time, compression) of every chunk record of an MCAP file, read here from
    its bytes (opcode, u64 length, content), not by rosbags."""
    data = path.read_bytes()
    assert data[:8] == b"\x89MCAP0\r\n"
    at = 8
    found = []
    while at < len(data) - 8:
        opcode = data[at]
        (length,) = struct.unpack_from("<Q", data, at + 1)
        content = at + 9
        if opcode == 0x02:  # footer
            break
        if opcode == 0x06:
            start, end = struct.unpack_from("<QQ", data, content)
            (size,) = struct.unpack_from("<I", data, content + 28)
            found.append((start, end, data[content + 32 : content + 32 + size].decode()))
        at = content + length
    return found


@pytest.mark.parametrize("fmt", FORMAT_NAMES)
def test_a_bag_reads_back_with_its_connections_types_and_messages(fmt: str, tmp_path: Path) -> None:
    store = factory.typestore_for(fmt)
    topics = factory.standard_topics(store, count=5) + factory.two_publishers(store)
    bag = factory.write_bag(bag_path(tmp_path, fmt), fmt, topics, store)
    assert bag.message_count == 7 * 5 + 2 * 4
    written = Counter()
    for topic in topics:
        for time_ns, message in topic.messages:
            written[(topic.name, topic.msgtype, time_ns, serialise(fmt, store, message, topic.msgtype))] += 1
    with AnyReader([bag.path]) as reader:
        assert reader.message_count == bag.message_count
        connections = Counter((c.topic, c.msgtype, c.msgcount) for c in reader.connections)
        assert connections == Counter((t.name, t.msgtype, len(t.messages)) for t in topics)
        assert [c.msgtype for c in reader.connections if c.topic == "/wheel/odom"] == [factory.ODOMETRY] * 2
        assert {name: info.msgtype for name, info in reader.topics.items()} == {
            **factory.STANDARD_TOPICS,
            "/wheel/odom": factory.ODOMETRY,
        }
        read = Counter()
        times = []
        for connection, time_ns, raw in reader.messages():
            read[(connection.topic, connection.msgtype, time_ns, bytes(raw))] += 1
            times.append(time_ns)
        assert read == written
        assert times == sorted(times)


@pytest.mark.parametrize("fmt", FORMAT_NAMES)
def test_types_only_the_bag_defines_are_read_from_it(fmt: str, tmp_path: Path) -> None:
    """turtlesim's Pose (and ROS 1's TFMessage) are in no typestore rosbags ships; a reader gets
    them from the bag, and the values come back (float32 exactly)."""
    ros1 = factory.FORMATS[fmt].ros == 1
    shipped = get_typestore(Stores.ROS1_NOETIC if ros1 else Stores.ROS2_HUMBLE).fielddefs
    assert factory.TURTLE_POSE not in shipped
    assert (factory.TF_MESSAGE in shipped) is not ros1
    store = factory.typestore_for(fmt)
    topics = factory.standard_topics(store, count=3)
    bag = factory.write_bag(bag_path(tmp_path, fmt), fmt, topics, store)
    turtles = next(t for t in topics if t.msgtype == factory.TURTLE_POSE)
    with AnyReader([bag.path]) as reader:
        assert reader.typestore.fielddefs[factory.TURTLE_POSE][1] == store.fielddefs[factory.TURTLE_POSE][1]
        poses = [
            reader.deserialize(raw, c.msgtype)
            for c, _, raw in reader.messages(
                [c for c in reader.connections if c.msgtype == factory.TURTLE_POSE]
            )
        ]
        tfs = [
            reader.deserialize(raw, c.msgtype)
            for c, _, raw in reader.messages([c for c in reader.connections if c.topic == "/tf"])
        ]
    assert [(p.x, p.theta, p.angular_velocity) for p in poses] == [
        (m.x, m.theta, m.angular_velocity) for _, m in turtles.messages
    ]
    assert all(np.float32(p.x) == p.x for p in poses)
    children = [[t.child_frame_id for t in m.transforms] for m in tfs]
    assert children == [
        ["odom", "base_link", "base_laser_link"],
        ["base_link", "base_laser_link", "odom"],
        ["base_laser_link", "odom", "base_link"],
    ]
    if ros1:
        assert [t.header.seq for t in tfs[2].transforms] == [2, 2, 2]


@pytest.mark.parametrize("fmt", [f for f in FORMAT_NAMES if f.startswith(("ros1", "mcap"))])
def test_messages_written_out_of_time_order_over_many_chunks(fmt: str, tmp_path: Path) -> None:
    store = factory.typestore_for(fmt)
    late = factory.out_of_order(store, count=12)
    topics = [*factory.two_publishers(store, count=6), late]
    bag = factory.write_bag(bag_path(tmp_path, fmt), fmt, topics, store, order="given", chunk_bytes=100)
    if factory.FORMATS[fmt].ros == 1:
        with Ros1Reader(bag.path) as raw_reader:
            starts = [c.start_time for c in raw_reader.chunk_infos]
    else:
        starts = [start for start, _, _ in mcap_chunks(bag.path / f"{fmt}.mcap")]
    assert len(starts) >= 10
    assert starts != sorted(starts)  # a later chunk starts earlier
    with AnyReader([bag.path]) as reader:
        stamps = [t for _, t, _ in reader.messages()]
        poses = [
            reader.deserialize(raw, c.msgtype)
            for c, _, raw in reader.messages(
                [c for c in reader.connections if c.msgtype == factory.TURTLE_POSE]
            )
        ]
    assert stamps == sorted(t for topic in topics for t, _ in topic.messages)
    assert [p.x for p in poses] == [m.x for _, m in reversed(late.messages)]


@pytest.mark.parametrize("fmt", FORMAT_NAMES)
def test_the_bag_is_compressed_as_asked(fmt: str, tmp_path: Path) -> None:
    store = factory.typestore_for(fmt)
    bag = factory.write_bag(bag_path(tmp_path, fmt), fmt, factory.standard_topics(store, count=2), store)
    compression = factory.FORMATS[fmt].compression
    if factory.FORMATS[fmt].ros == 1:
        data = bag.path.read_bytes()
        assert f"compression={compression or 'none'}".encode() in data
        return
    with Ros2Reader(bag.path) as reader:
        mode, form = reader.compression_mode, reader.compression_format
    if compression in ("message", "file"):
        assert (mode, form) == (compression, "zstd")
    else:
        assert not mode
    files = sorted(p.name for p in bag.path.iterdir())
    if fmt.startswith("mcap"):
        chunks = mcap_chunks(bag.path / f"{fmt}.mcap")
        assert {c for _, _, c in chunks} == {"zstd" if compression == "storage" else ""}
    elif compression == "file":
        assert files == ["metadata.yaml", f"{fmt}.db3.zstd"]
    else:
        assert files == ["metadata.yaml", f"{fmt}.db3"]


def test_builders_are_deterministic_and_differ_by_seed() -> None:
    store = factory.typestore_for("sqlite3")
    for msgtype in factory.BUILDERS:
        first = [bytes(store.serialize_cdr(m, msgtype)) for _, m in factory.series(store, msgtype, 3, seed=1)]
        again = [bytes(store.serialize_cdr(m, msgtype)) for _, m in factory.series(store, msgtype, 3, seed=1)]
        other = [bytes(store.serialize_cdr(m, msgtype)) for _, m in factory.series(store, msgtype, 3, seed=2)]
        assert first == again, msgtype
        assert first != other, msgtype
    scans = [m for _, m in factory.series(store, factory.LASER_SCAN, 6)]
    assert [len(s.ranges) for s in scans] == [8, 9, 10, 11, 12, 8]
    assert all(s.ranges.dtype == np.float32 for s in scans)
