"""The bag formats exsce reads, each a record of all that tells it: suffix, magic bytes, check.

A :class:`BagFormat` is a file format (a ROS 1 bag, an MCAP file, a ROS 2 sqlite3 file); a
ROS 2 bag folder holds :data:`ROS2_METADATA` and files of the formats whose ``in_folder`` is
true.  The readers (:class:`~exsce_dsl.runs.bags.reader.BagReader`) name the formats they read,
and what tells a bag by its name asks them (:func:`~exsce_dsl.runs.bags.reading.is_bag`): no
list of suffixes lives anywhere else (``tests/project/test_bag_formats.py`` holds it).
"""

from __future__ import annotations

import mmap
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

__all__ = [
    "MCAP_FILE",
    "ROS1_BAG",
    "ROS2_METADATA",
    "SQLITE3_FILE",
    "BUILT_IN_FORMATS",
    "BagFormat",
    "is_ros2_folder",
]

Check = Callable[[mmap.mmap, Path], None]
"""Looks at a file of the format mapped into memory, raising FileProblem for what is wrong."""


@dataclass(frozen=True)
class BagFormat:
    """One bag file format: its ``name``, ``what`` it is in words (``a ROS 1 bag``), its
    ``suffix``, its ``magic`` bytes, its ``check`` (a cheap look at headers and indexes, for
    :func:`~exsce_dsl.runs.bags.files.check_bag_file`), and whether a ROS 2 bag folder may hold
    files of it (``in_folder``)."""

    name: str
    what: str
    suffix: str
    """A file of the format must end in it: exsce tells a bag's format by its name, and says so
    when a file's magic bytes are another format's."""
    magic: bytes
    check: Check | None = None
    in_folder: bool = False


def _check_ros1(data: mmap.mmap, path: Path) -> None:
    from exsce_dsl.runs.bags.ros1_file import check_ros1  # it builds on the parsers, which use MAGIC

    check_ros1(data, path)


def _check_mcap(data: mmap.mmap, path: Path) -> None:
    from exsce_dsl.runs.bags.mcap_file import check_mcap

    check_mcap(data, path)


ROS1_BAG = BagFormat("ROS 1", "a ROS 1 bag", ".bag", b"#ROSBAG V2.0\n", _check_ros1)
MCAP_FILE = BagFormat("MCAP", "an MCAP file", ".mcap", b"\x89MCAP0\r\n", _check_mcap, in_folder=True)
SQLITE3_FILE = BagFormat(
    "sqlite3", "a ROS 2 sqlite3 bag file", ".db3", b"SQLite format 3\x00", in_folder=True
)
BUILT_IN_FORMATS = (ROS1_BAG, MCAP_FILE, SQLITE3_FILE)

ROS2_METADATA = "metadata.yaml"
"""What makes a folder a ROS 2 bag: rosbag2 writes it when it closes the bag."""


def is_ros2_folder(path: Path) -> bool:
    """Whether ``path`` is a ROS 2 bag folder (it holds :data:`ROS2_METADATA`)."""
    return path.is_dir() and (path / ROS2_METADATA).is_file()
