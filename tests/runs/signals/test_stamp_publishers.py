"""Issue 47, item 2: the stamps of a topic are judged per connection (publisher), not per topic.

Two nodes publish one topic: a localiser stamping its poses at about log time, and a second one
that post-dates its stamps (by a tolerance, as AMCL does its transforms) or whose clock goes back
once.  Read as one series, those stamps "go back" every other message: exsce timed the whole
topic by log time and, the topic being the only stamped one, called it a reset of the clock.  Now
each connection's stamps are judged on their own: the odd publisher is a note and its messages are
timed by their log times, the other's by their stamps, no sample left out; a reset is every
stamped publisher going back together.  The references are rosbags' deserialisation per
connection and numpy.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rosbags.highlevel import AnyReader

from exsce_dsl.model.messages import path_of
from exsce_dsl.runs.bags.data import Wanted
from exsce_dsl.runs.bags.reading import bag_topics, read_bag
from exsce_dsl.runs.signals.timeline import (
    HEADER_STAMPS,
    LOG_TIME,
    decide_timeline,
    on_timeline,
    stamp_catalogue,
    with_stamps,
)

from tests.support.bag_factory import (
    PERIOD_NS,
    POSE_STAMPED,
    START_NS,
    Topic,
    pose_stamped,
    typestore_for,
    write_bag,
)

COUNT = 200
"""Messages per publisher: 20 s at 10 Hz each, interleaved."""
POST_DATED = 1.7
BACK = 5.0
SIMULATED_NS = START_NS - 100 * 10**9
"""Subtracted from every stamp of a simulated run (use_sim_time: stamps of about 100 s, no /clock)."""
X = path_of("pose", "position", "x")


def _stamp_of(shape: str, publisher: int, index: int, log_ns: int) -> int:
    """The stamp publisher ``publisher`` gives its ``index``-th message logged at ``log_ns``."""
    late = 5_000_000  # 5 ms of latency
    if publisher == 0 or shape == "fine":
        return log_ns - late
    if shape == "post-dated":
        return log_ns + int(POST_DATED * 1e9)
    if shape == "back":  # this node's clock goes back once, halfway
        return log_ns - late - (int(BACK * 1e9) if index >= COUNT // 2 else 0)
    assert shape == "reset"  # both publishers' clocks go back together (below, for publisher 0 too)
    return log_ns - late - (int(BACK * 1e9) if index >= COUNT // 2 else 0)


def _bag(tmp_path: Path, fmt: str, shape: str, simulated: bool = False) -> Path:
    store = typestore_for(fmt)
    topics = []
    for publisher in (0, 1):
        messages = []
        for i in range(COUNT):
            log_ns = START_NS + (2 * i + publisher) * PERIOD_NS
            stamp_ns = _stamp_of(shape, publisher, i, log_ns)
            if shape == "reset" and publisher == 0 and i >= COUNT // 2:
                stamp_ns -= int(BACK * 1e9)
            stamp_ns -= SIMULATED_NS if simulated else 0
            messages.append((log_ns, pose_stamped(store, 2 * i + publisher, stamp_ns, seed=publisher)))
        topics.append(Topic("/pose", POSE_STAMPED, messages, publisher))
    path = tmp_path / ("two.bag" if fmt == "ros1" else "two")
    write_bag(path, fmt, topics, store)
    return path


def _reference(path: Path, by_log: set[int]) -> tuple[np.ndarray, np.ndarray]:
    """(time, x) of every /pose message, sorted by time: a publisher in ``by_log`` (the rank of
    its connection) timed by its log times, the others by their header stamps; log times of a
    simulated run moved onto its clock by the others' median offset (log time minus stamp)."""
    rows: list[tuple[float, float, float, bool]] = []
    with AnyReader(
        [path], default_typestore=typestore_for("ros1" if path.suffix == ".bag" else "mcap")
    ) as reader:
        ranks = {c.id: rank for rank, c in enumerate(sorted(reader.connections, key=lambda c: c.id))}
        for conn, log_ns, raw in reader.messages():
            message = reader.deserialize(raw, conn.msgtype)
            stamp = message.header.stamp.sec + message.header.stamp.nanosec * 1e-9
            rows.append((log_ns / 1e9, stamp, message.pose.position.x, ranks[conn.id] in by_log))
    offset = float(np.median([log - stamp for log, stamp, _, mine in rows if not mine]))
    if abs(offset) < 300:  # a wall-clock run: log times are its clock
        offset = 0.0
    timed = sorted(((log - offset if mine else stamp), x) for log, stamp, x, mine in rows)
    return np.array([t for t, _ in timed]), np.array([x for _, x in timed])


def _placed(path: Path) -> tuple[Any, Any]:
    types = bag_topics(path)
    wanted = with_stamps({"/pose": Wanted(POSE_STAMPED, (X,))}, types, stamp_catalogue())
    data = read_bag(path, wanted)
    timeline = decide_timeline(data)
    return timeline, on_timeline(data, timeline).series["/pose"]


@pytest.mark.parametrize("simulated", [False, True], ids=["wall-clock", "simulated"])
@pytest.mark.parametrize("fmt", ["ros1", "mcap"])
@pytest.mark.parametrize("shape", ["post-dated", "back"])
def test_one_publisher_off_is_no_reset_and_only_its_messages_use_log_time(
    tmp_path: Path, fmt: str, shape: str, simulated: bool
) -> None:
    path = _bag(tmp_path, fmt, shape, simulated)
    timeline, series = _placed(path)
    assert timeline.jumps == ()  # one publisher's clock is no reset
    clock = next(c for c in timeline.clocks if c.topic == "/pose")
    assert clock.clock == HEADER_STAMPS
    assert len(clock.by_log) == 1
    assert any(clock.by_log[0] in note and "timed by log time" in note for note in timeline.notes)
    assert timeline.simulated == simulated
    times, xs = _reference(path, by_log={1})
    assert len(series) == 2 * COUNT  # no sample left out
    np.testing.assert_allclose(series.t, times, rtol=0, atol=1e-5)
    assert series.fields[X.key].tolist() == xs.tolist()


@pytest.mark.parametrize("fmt", ["ros1", "mcap"])
def test_publishers_that_agree_time_their_topic_by_stamps(tmp_path: Path, fmt: str) -> None:
    path = _bag(tmp_path, fmt, "fine")
    timeline, series = _placed(path)
    clock = next(c for c in timeline.clocks if c.topic == "/pose")
    assert (clock.clock, clock.by_log, timeline.jumps) == (HEADER_STAMPS, (), ())
    times, xs = _reference(path, by_log=set())
    np.testing.assert_allclose(series.t, times, rtol=0, atol=1e-6)
    assert series.fields[X.key].tolist() == xs.tolist()


@pytest.mark.parametrize("fmt", ["ros1", "mcap"])
def test_every_publisher_going_back_together_is_a_reset(tmp_path: Path, fmt: str) -> None:
    path = _bag(tmp_path, fmt, "reset")
    timeline, series = _placed(path)
    assert len(timeline.jumps) == 1
    jump = timeline.jumps[0]
    assert jump.back == pytest.approx(BACK, abs=0.2)
    assert len(jump.together) == 2  # both publishers, named
    assert next(c for c in timeline.clocks if c.topic == "/pose").clock == LOG_TIME
    assert len(series) == 2 * COUNT  # nothing left out after the reset
