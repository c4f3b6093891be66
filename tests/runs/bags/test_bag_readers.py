"""The bag formats' readers are a registry (``runs/bags/reading.py``: READERS), tried in order."""

from __future__ import annotations

from pathlib import Path

from exsce_dsl.runs.bags.mcap import MCAP
from exsce_dsl.runs.bags.reading import READERS
from exsce_dsl.runs.bags.ros1 import ROS1
from exsce_dsl.runs.bags.rosbags_fallback import ROSBAGS


def test_readers_are_ros1_then_mcap_then_the_rosbags_fallback() -> None:
    assert READERS == (ROS1, MCAP, ROSBAGS)
    assert [reader.name for reader in READERS] == ["ROS 1", "MCAP", "rosbags"]


def test_each_reader_claims_its_format_and_the_fallback_claims_every_bag(tmp_path: Path) -> None:
    ros1, mcap, db3, folder = tmp_path / "a.bag", tmp_path / "a.mcap", tmp_path / "a.db3", tmp_path / "bag"
    for file in (ros1, mcap, db3):
        file.write_bytes(b"")
    folder.mkdir()
    claimed = {path.name: [r.name for r in READERS if r.claims(path)] for path in (ros1, mcap, db3, folder)}
    assert claimed == {
        "a.bag": ["ROS 1", "rosbags"],
        "a.mcap": ["MCAP", "rosbags"],
        "a.db3": ["rosbags"],
        "bag": ["MCAP", "rosbags"],  # a ROS 2 bag folder: MCAP's if its metadata says so
    }


def test_topics_are_listed_by_the_ros1_index_else_by_rosbags() -> None:
    assert [reader.name for reader in READERS if reader.topics is not None] == ["ROS 1", "rosbags"]
