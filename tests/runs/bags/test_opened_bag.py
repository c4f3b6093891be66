"""A bag is opened once (issue 49, item 1: the walk enters each step once): ``open_bag`` checks it
and lists its topics from its index; the signals step then reads what it wants of the opened bag,
without coming back to the bags step to open it again."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from rosbags.highlevel import AnyReader

from exsce_dsl.errors import BagError
from exsce_dsl.model.messages import path_of
from exsce_dsl.runs.bags.data import Wanted
from exsce_dsl.runs.bags.reading import bag_topics, open_bag, read_bag

from tests.support.paths import ROOT

HUSKY = ROOT / "tests" / "fixtures" / "realbags" / "robot_localization" / "test1.bag"
ODOM = "/husky_velocity_controller/odom"
WANTED = {ODOM: Wanted("nav_msgs/msg/Odometry", (path_of("pose", "pose", "position", "x"),))}


def _reference_xs() -> tuple[np.ndarray, np.ndarray]:
    """The odometry's log times (s) and x, as rosbags deserialises them (not exsce's reader)."""
    times, xs = [], []
    with AnyReader([HUSKY]) as reader:
        wanted = [c for c in reader.connections if c.topic == ODOM]
        for connection, stamp, raw in reader.messages(connections=wanted):
            times.append(stamp / 1e9)
            xs.append(reader.deserialize(raw, connection.msgtype).pose.pose.position.x)
    return np.array(times), np.array(xs)


def test_an_opened_bag_lists_its_topics_from_its_index() -> None:
    opened = open_bag(HUSKY)
    with AnyReader([HUSKY]) as reader:
        expected = {c.topic: c.msgtype for c in reader.connections}
    assert dict(opened.topics) == expected == dict(bag_topics(HUSKY))


def test_an_opened_bag_reads_what_is_wanted_as_read_bag_does() -> None:
    data = open_bag(HUSKY).read(WANTED)
    times, xs = _reference_xs()
    series = data.series[ODOM]
    assert np.allclose(series.t, times, rtol=0, atol=1e-9)
    assert np.array_equal(series.fields["pose.pose.position.x"], xs)
    again = read_bag(HUSKY, WANTED).series[ODOM]
    assert np.array_equal(again.t, series.t)
    assert np.array_equal(again.fields["pose.pose.position.x"], series.fields["pose.pose.position.x"])


def test_opening_a_bag_that_is_not_there_says_so(tmp_path: Path) -> None:
    missing = tmp_path / "gone.bag"
    with pytest.raises(BagError, match=r"gone\.bag: no such bag"):
        open_bag(missing)
