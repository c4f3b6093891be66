"""Header stamps coarser than a topic's rate do not time it (issue 47, item 6).

A 27 Hz pose whose header stamps are whole seconds (``floor`` of its log time) was timed by
them: 27 messages shared each stamp, every duration was a whole number of seconds and a message
held for 0 s (2,915 violations summing to "0 s").  Stamps are used only when finer than the
topic's rate, else its log times, and a note says which.  The bag is written here with rosbags;
the reference is numpy over the log times rosbags reads.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rosbags.highlevel import AnyReader

from exsce_dsl.lang import load_spec
from exsce_dsl.runs.analyse import analyse_bag
from exsce_dsl.runs.signals.timeline import LOG_TIME

from tests.support.bag_factory import POSE_STAMPED, START_NS, Topic, header, typestore_for, write_bag
from tests.support.yard_spec import FAR_YARD

SPEC = FAR_YARD + """
metric far_out_time for each robot {
  unit s
  reads loc: geometry_msgs/msg/PoseStamped on "/location"
  value duration where loc.pose.position.x > 1.0
}
scenario coarse in yard {
  robots {
    tb: bot namespace "" starts at start
  }
  mission go_far sequential {
    tb does go
  }
}
"""
COUNT = 300
PERIOD_NS = 37_037_037  # 27 Hz
SPEED = 0.25  # m/s along x


def _poses(store: Any) -> Topic:
    """``/location`` at 27 Hz from 0.4 s past a whole second, stamped with whole seconds (in
    the typestore's ROS version: the differential suite writes it in ROS 2 too)."""
    types = store.types
    messages = []
    for i in range(COUNT):
        log_ns = START_NS + 400_000_000 + i * PERIOD_NS
        whole_second = log_ns // 10**9 * 10**9
        x = SPEED * i * PERIOD_NS / 1e9
        pose = types["geometry_msgs/msg/Pose"](
            position=types["geometry_msgs/msg/Point"](x=x, y=0.0, z=0.0),
            orientation=types["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0),
        )
        messages.append(
            (log_ns, types[POSE_STAMPED](header=header(store, whole_second, "map", i), pose=pose))
        )
    return Topic("/location", POSE_STAMPED, messages)


def _reference(bag: Path) -> tuple[np.ndarray, np.ndarray]:
    """Log times (s) and x of every ``/location`` message, as rosbags reads them."""
    times, xs = [], []
    with AnyReader([bag]) as reader:
        for connection, log_ns, raw in reader.messages(
            [c for c in reader.connections if c.topic == "/location"]
        ):
            times.append(log_ns / 1e9)
            xs.append(reader.deserialize(raw, connection.msgtype).pose.position.x)
    return np.array(times), np.array(xs)


def test_coarse_stamps_time_by_log_time(tmp_path: Path) -> None:
    bag = tmp_path / "coarse.bag"
    write_bag(bag, "ros1", [_poses(typestore_for("ros1"))])
    spec = tmp_path / "coarse.exsce"
    spec.write_text(SPEC)
    analysed = analyse_bag(bag, load_spec(spec).scenario())
    values = {v.metric: v.value for v in analysed.run.metrics if v.action is None and v.robot == "tb"}

    t, x = _reference(bag)
    held = np.append(np.diff(t), np.median(np.diff(t)))  # each message holds until the next one
    assert values["far_out_time"] == pytest.approx(float(held[x > 1.0].sum()), rel=1e-6)
    assert values["task_duration"] == pytest.approx(float(t[-1] - t[0]), rel=1e-6)
    assert values["task_duration"] % 1.0 != pytest.approx(0.0, abs=1e-3)  # not whole seconds

    assert analysed.timeline is not None
    (clock,) = [c for c in analysed.timeline.clocks if c.topic == "/location"]
    assert clock.clock == LOG_TIME
    (said,) = [
        p for p in analysed.problems if p.startswith("the stamps of /location are coarser than its rate")
    ]
    assert "timed by log time" in said and "27.0 Hz" in said, said
