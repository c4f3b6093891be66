"""The bag formats' readers are a registry (``runs/bags/reading.py``: BAG_READERS), tried in order
(``readers()``): exsce's, the plug-ins', rosbags' last."""

from __future__ import annotations

import warnings
from collections.abc import Iterator
from pathlib import Path

import pytest

from exsce_dsl.runs.bags.formats import ROS2_METADATA
from exsce_dsl.runs.bags.mcap import MCAP
from exsce_dsl.runs.bags.reading import BAG_READERS, bag_formats, is_bag, readers
from exsce_dsl.runs.bags.ros1 import ROS1
from exsce_dsl.runs.bags.rosbags_fallback import ROSBAGS

from tests.support.plugin_packages import installed_plugins


def test_readers_are_ros1_then_mcap_then_the_rosbags_fallback() -> None:
    assert readers() == (ROS1, MCAP, ROSBAGS)
    assert [reader.name for reader in readers()] == ["ROS 1", "MCAP", "rosbags"]


def test_each_reader_claims_its_format_and_the_fallback_claims_every_bag(tmp_path: Path) -> None:
    ros1, mcap, db3, folder = tmp_path / "a.bag", tmp_path / "a.mcap", tmp_path / "a.db3", tmp_path / "bag"
    for file in (ros1, mcap, db3):
        file.write_bytes(b"")
    folder.mkdir()
    claimed = {path.name: [r.name for r in readers() if r.claims(path)] for path in (ros1, mcap, db3, folder)}
    assert claimed == {
        "a.bag": ["ROS 1", "rosbags"],
        "a.mcap": ["MCAP", "rosbags"],
        "a.db3": ["rosbags"],
        "bag": ["MCAP", "rosbags"],  # a ROS 2 bag folder: MCAP's if its metadata says so
    }


def test_topics_are_listed_by_the_ros1_index_else_by_rosbags() -> None:
    assert [reader.name for reader in readers() if reader.topics is not None] == ["ROS 1", "rosbags"]


FOO_READER = """\
from exsce_dsl.runs.bags.formats import BagFormat
from exsce_dsl.runs.bags.reader import BagReader

FOO = BagFormat("foo", "a foo recording", ".foo", b"FOO!")
reader = BagReader("foo", claims=lambda path: path.suffix == ".foo", read=None, formats=(FOO,))
"""


@pytest.fixture
def foo_reader(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    points = "[exsce.bag_readers]\nfoo = exsce_test_foo:reader\n"
    yield from installed_plugins(tmp_path, monkeypatch, BAG_READERS, "exsce_test_foo", FOO_READER, points)


@pytest.mark.usefixtures("foo_reader")
def test_a_plugin_reader_is_tried_before_rosbags_and_its_format_tells_a_bag(tmp_path: Path) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a good plug-in loads without a word
        order = [reader.name for reader in readers()]
    assert order == ["ROS 1", "MCAP", "foo", "rosbags"]
    assert [f.suffix for f in bag_formats()] == [".bag", ".mcap", ".foo", ".db3"]
    assert is_bag(tmp_path / "run.foo") and not is_bag(tmp_path / "run.bar")


def test_a_ros2_folder_is_a_bag_by_its_metadata(tmp_path: Path) -> None:
    (tmp_path / "folder").mkdir()
    assert not is_bag(tmp_path / "folder")
    (tmp_path / "folder" / ROS2_METADATA).write_text("rosbag2_bagfile_information: {}\n")
    assert is_bag(tmp_path / "folder")
