"""rosbags' standard definitions, cached between runs (exsce_dsl.messages.typestore_cache)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from rosbags.typesys import Stores, get_typestore

from exsce_dsl.messages import typestore_cache
from exsce_dsl.user_cache import read_cached, write_cached


@pytest.fixture
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    folder = tmp_path / "cache"
    monkeypatch.setenv("EXSCE_CACHE", str(folder))
    return folder


@pytest.mark.parametrize("store", ["ros2_jazzy", "ros2_humble", "ros1_noetic"])
def test_the_cached_definitions_are_rosbags_own(cache: Path, store: str) -> None:
    rosbags = get_typestore(Stores(store)).fielddefs
    assert typestore_cache.standard_fielddefs(store) == rosbags  # written
    [written] = cache.glob(f"typestore-{store}-*.json")
    assert typestore_cache.standard_fielddefs(store) == rosbags  # read back: tuples, lists, Nodetypes
    content = read_cached(written)
    assert content is not None and json.loads(content)["std_msgs/msg/Header"]  # a real file, JSON


def test_the_file_is_what_is_read(cache: Path) -> None:
    typestore_cache.standard_fielddefs("ros2_humble")
    [written] = cache.glob("typestore-ros2_humble-*.json")
    content = read_cached(written)
    assert content is not None
    data = json.loads(content)
    del data["nav_msgs/msg/Odometry"]
    write_cached(written, json.dumps(data).encode())
    assert "nav_msgs/msg/Odometry" not in typestore_cache.standard_fielddefs("ros2_humble")


@pytest.mark.parametrize("text", ["", "not json", "[1, 2]", '{"a/msg/B": [[], [["x", [99, "y"]]]]}'])
def test_a_broken_cache_falls_back_to_rosbags_and_is_rewritten(cache: Path, text: str) -> None:
    typestore_cache.standard_fielddefs("ros1_noetic")
    [written] = cache.glob("typestore-ros1_noetic-*.json")
    write_cached(written, text.encode())
    rosbags = get_typestore(Stores.ROS1_NOETIC).fielddefs
    assert typestore_cache.standard_fielddefs("ros1_noetic") == rosbags
    assert typestore_cache.standard_fielddefs("ros1_noetic") == rosbags  # from the rewritten file
    content = read_cached(written)
    assert content is not None and json.loads(content)["std_msgs/msg/Header"]


def test_a_cache_that_cannot_be_written_is_not_kept(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    blocker = tmp_path / "a_file"
    blocker.write_text("")
    monkeypatch.setenv("EXSCE_CACHE", str(blocker / "cache"))  # a folder inside a file
    assert typestore_cache.standard_fielddefs("ros2_humble") == get_typestore(Stores.ROS2_HUMBLE).fielddefs
    assert not (blocker / "cache").exists()


def test_the_definitions_go_where_every_cache_entry_goes(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("EXSCE_CACHE", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    typestore_cache.standard_fielddefs("ros2_humble")
    assert list((tmp_path / "exsce").glob("typestore-ros2_humble-*.json"))


def test_nothing_is_kept_when_the_cache_is_off(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("EXSCE_CACHE", "")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    assert typestore_cache.standard_fielddefs("ros2_humble") == get_typestore(Stores.ROS2_HUMBLE).fielddefs
    assert not list(tmp_path.iterdir())
