"""Issue 48: a bag holding two versions of one message type is decoded per connection.

A recording made by two nodes built against different versions of a package holds one type name
with two definitions (two md5sums): ``my_pkg/msg/Pose2`` as ``x, y`` from one node and as
``theta, x, y`` from the other.  exsce decoded every connection of a type with the first
definition it met: the second node's ``x`` read its ``theta``, silently.  Each connection is now
decoded by its own definition, in every reader (ROS 1's index, MCAP's, rosbags' fallback).  The
references come from rosbags' deserialisation, with a typestore made per connection from that
connection's own definition.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rosbags.rosbag1 import Reader as Ros1Reader
from rosbags.rosbag2 import StoragePlugin
from rosbags.rosbag2 import Writer as Ros2Writer
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from exsce_dsl.errors import BagError
from exsce_dsl.model.messages import path_of
from exsce_dsl.runs.bag_info import bag_info_of
from exsce_dsl.runs.bags.data import Wanted
from exsce_dsl.runs.bags.reading import read_bag
from exsce_dsl.runs.bags.rosbags_fallback import read_with_rosbags

from tests.support.bag_factory import START_NS, Topic, write_bag

POSE2 = "my_pkg/msg/Pose2"
V1 = "float64 x\nfloat64 y\n"
V2 = "float64 theta\nfloat64 x\nfloat64 y\n"
"""The package's second version: a heading, put first (every field after it moves)."""
OTHER_NAME = "my_pkg/msg/PoseZ"
"""As long as POSE2: a ROS 2 bag is written with it for the second version, then renamed in place."""
COUNT = 40
WANTED = Wanted(POSE2, (path_of("x"), path_of("y")))


def _store(definition: str, name: str = POSE2) -> Any:
    store = get_typestore(Stores.EMPTY)
    store.register(get_types_from_msg(definition, name))
    return store


def _values(version: int) -> list[tuple[int, dict[str, float]]]:
    """The version's messages: version 1 at even 25 ms steps, version 2 at odd ones."""
    found = []
    for i in range(COUNT):
        values = (
            {"x": 1.0 * i, "y": 2.0 * i}
            if version == 1
            else {"theta": 0.1 * i, "x": 100.0 + i, "y": -3.0 * i}
        )
        found.append((START_NS + (2 * i + version - 1) * 25_000_000, values))
    return found


def _messages(version: int, ros: int, name: str = POSE2) -> list[tuple[int, bytes]]:
    """The version's messages, serialised by a typestore of that version."""
    store = _store(V1 if version == 1 else V2, name)
    serialise = store.serialize_ros1 if ros == 1 else store.serialize_cdr
    return [(t, bytes(serialise(store.types[name](**values), name))) for t, values in _values(version)]


def _written(topics: tuple[str, str]) -> dict[str, list[tuple[float, float, float]]]:
    """Per topic, (time, x, y) of every message written, sorted by time."""
    out: dict[str, list[tuple[float, float, float]]] = {}
    for version, topic in enumerate(topics, start=1):
        out.setdefault(topic, []).extend((t / 1e9, v["x"], v["y"]) for t, v in _values(version))
    return {topic: sorted(rows) for topic, rows in out.items()}


def _ros1_bag(path: Path, topics: tuple[str, str]) -> Path:
    """Version 1 on ``topics[0]``, version 2 on ``topics[1]`` (one topic twice: two connections)."""
    written = []
    for version, (topic, publisher) in enumerate(zip(topics, (1, 2), strict=True), start=1):
        msgdef, md5sum = _store(V1 if version == 1 else V2).generate_msgdef(POSE2)
        written.append(Topic(topic, POSE2, _messages(version, 1), publisher, msgdef, md5sum))
    write_bag(path, "ros1", written)
    return path


def _mcap_bag(folder: Path, topics: tuple[str, str]) -> Path:
    """The same as MCAP: rosbags writes one schema per type name, so the second version is
    written as :data:`OTHER_NAME` and renamed in the files, with its type hash (same lengths: no
    offset moves; rosbags writes no CRCs)."""
    writer = Ros2Writer(folder, version=9, storage_plugin=StoragePlugin.MCAP)
    with writer:
        for version, (topic, name) in enumerate(zip(topics, (POSE2, OTHER_NAME), strict=True), start=1):
            store = _store(V1 if version == 1 else V2, name)
            conn = writer.add_connection(topic, name, typestore=store)
            for t, raw in _messages(version, 2, name):
                writer.write(conn, t, raw)
    renamed, named = _store(V2, OTHER_NAME).hash_rihs01(OTHER_NAME), _store(V2).hash_rihs01(POSE2)
    for file in [*folder.glob("*.mcap"), folder / "metadata.yaml"]:
        blob = file.read_bytes().replace(OTHER_NAME.encode(), POSE2.encode())
        file.write_bytes(blob.replace(renamed.encode(), named.encode()))
    return folder


def _reference(path: Path) -> dict[str, list[tuple[float, float, float]]]:
    """Per topic, (time, x, y) of every message of a ROS 1 bag, each connection's deserialised by
    rosbags with a typestore of its own definition, sorted by time."""
    out: dict[str, list[tuple[float, float, float]]] = {}
    with Ros1Reader(path) as reader:
        stores = {c.id: _store(c.msgdef.data, c.msgtype) for c in reader.connections}
        for conn, t, raw in reader.messages():
            message = stores[conn.id].deserialize_ros1(raw, conn.msgtype)
            out.setdefault(conn.topic, []).append((t / 1e9, message.x, message.y))
    return {topic: sorted(rows) for topic, rows in out.items()}


def _assert_read_as(
    path: Path, reference: dict[str, list[tuple[float, float, float]]], fallback: bool = False
) -> None:
    wanted = {topic: WANTED for topic in reference}
    data = read_with_rosbags(path, wanted, None, None) if fallback else read_bag(path, wanted)
    for topic, expected in reference.items():
        series = data.series[topic]
        rows = np.array(expected)
        assert len(series) == len(rows) == (2 * COUNT if len(reference) == 1 else COUNT)
        np.testing.assert_allclose(series.t, rows[:, 0], rtol=0, atol=1e-9)
        assert series.fields["x"].tolist() == rows[:, 1].tolist()
        assert series.fields["y"].tolist() == rows[:, 2].tolist()


@pytest.mark.parametrize("fallback", [False, True], ids=["index", "rosbags"])
def test_two_versions_of_a_type_on_one_topic_decoded_each_by_its_own_definition(
    tmp_path: Path, fallback: bool
) -> None:
    bag = _ros1_bag(tmp_path / "versions.bag", ("/pose", "/pose"))
    assert _reference(bag) == _written(("/pose", "/pose"))
    _assert_read_as(bag, _reference(bag), fallback)
    data = read_bag(bag, {"/pose": WANTED})
    x = data.series["/pose"].fields["x"]
    assert x.max() == 100.0 + COUNT - 1  # the second version's x, not its theta


@pytest.mark.parametrize("fallback", [False, True], ids=["index", "rosbags"])
def test_two_versions_of_a_type_on_two_topics_decoded_each_by_its_own_definition(
    tmp_path: Path, fallback: bool
) -> None:
    bag = _ros1_bag(tmp_path / "versions.bag", ("/old", "/new"))
    _assert_read_as(bag, _reference(bag), fallback)


@pytest.mark.parametrize("topics", [("/pose", "/pose"), ("/old", "/new")], ids=["one-topic", "two-topics"])
def test_two_schemas_of_a_type_in_mcap_decoded_each_by_its_own(
    tmp_path: Path, topics: tuple[str, str]
) -> None:
    # rosbags' ROS 2 reader keeps one definition per type name: the reference is what was written
    bag = _mcap_bag(tmp_path / "versions", topics)
    _assert_read_as(bag, _written(topics))


def test_two_schemas_of_a_type_refused_by_rosbags_never_misread(tmp_path: Path) -> None:
    # where the index reader passes an MCAP bag on, rosbags refuses two definitions of one type
    # (their hashes cannot both match its one): an error, not values decoded by the wrong one
    bag = _mcap_bag(tmp_path / "versions", ("/pose", "/pose"))
    with pytest.raises(BagError, match="my_pkg/msg/Pose2"):
        read_with_rosbags(bag, {"/pose": WANTED}, None, None)


def test_two_versions_read_whole_each_by_its_own_definition(tmp_path: Path) -> None:
    # messages kept as objects (a navigation stack's goals) are deserialised per connection too
    bag = _ros1_bag(tmp_path / "versions.bag", ("/pose", "/pose"))
    data = read_bag(bag, {"/pose": Wanted("**")})
    found = [(t, m.x, m.y) for t, m in data.messages["/pose"]]
    assert [row[1:] for row in found] == [row[1:] for row in _reference(bag)["/pose"]]


def test_bag_info_lists_both_versions_of_a_type(tmp_path: Path) -> None:
    bag = _ros1_bag(tmp_path / "versions.bag", ("/old", "/new"))
    with Ros1Reader(bag) as reader:
        md5s = sorted(c.digest[:8] for c in reader.connections)
    assert len(set(md5s)) == 2
    for topic in bag_info_of(bag).topics:
        assert topic.definition == f"the bag (2 versions: {', '.join(md5s)})"


def test_bag_info_gives_the_rate_of_a_version_rosbags_cannot_read(tmp_path: Path) -> None:
    """Stumble: ``bag info`` showed "-" for the rate of the topic carrying the version rosbags'
    one typestore does not hold; a rate is the log times', whatever the bytes."""
    bag = _ros1_bag(tmp_path / "versions.bag", ("/old", "/new"))
    rates = {t.name: t.rate for t in bag_info_of(bag).topics}
    for version, topic in enumerate(("/old", "/new"), start=1):
        times = np.array([t for t, _ in _values(version)], dtype=float) / 1e9
        assert rates[topic] == pytest.approx((len(times) - 1) / (times[-1] - times[0]), rel=1e-6)
