"""A robot without goals is measured over its whole recording, in every format: the first message
of the bag to its last, whichever topics exsce reads (regression: ROS 1 and MCAP bags took the
span of the topics read, so turtlesim's 21.700 s recording gave task and mission durations of
21.489 s and embag's Stage bag 0.4 s for 7.589 s, where the same bags as sqlite3 had the
recording).  The reference is the span rosbags reads."""

from __future__ import annotations

from pathlib import Path

import pytest
from rosbags.highlevel import AnyReader

from exsce_dsl.lang import load_spec
from exsce_dsl.model.runs import MetricScope
from exsce_dsl.runs.analyse import analyse_bag

from tests.support.bag_factory import IMU, ODOMETRY, START_NS, Topic, series, typestore_for, write_bag
from tests.support.yard_spec import FAR_YARD

SPEC = FAR_YARD + """
scenario span in yard {
  robots {
    tb: bot namespace "" starts at start
  }
  mission go_far sequential {
    tb does go
  }
}
"""


@pytest.mark.parametrize("fmt", ["ros1", "ros1-lz4", "sqlite3", "mcap"])
def test_whole_run_spans_topics_not_read(fmt: str, tmp_path: Path) -> None:
    """``/imu/data`` (read by no metric) from 0 to 20 s, ``/odom`` from 3 s to 15 s."""
    store = typestore_for(fmt)
    odom = series(store, ODOMETRY, 241, start_ns=START_NS + 3 * 10**9)
    imu = series(store, IMU, 401)
    bag = tmp_path / ("span.bag" if fmt.startswith("ros1") else "span")
    write_bag(bag, fmt, [Topic("/imu/data", IMU, imu), Topic("/odom", ODOMETRY, odom)], store)
    spec = tmp_path / "span.exsce"
    spec.write_text(SPEC)
    run = analyse_bag(bag, load_spec(spec).scenario())
    with AnyReader([bag], default_typestore=typestore_for("sqlite3")) as reader:
        times = [t for _, t, _ in reader.messages()]
    recording = (max(times) - min(times)) / 1e9
    assert recording == pytest.approx(20.0)
    durations = {
        v.metric: v.value
        for v in run.run.metrics
        if v.scope in (MetricScope.ROBOT, MetricScope.MISSION) and v.metric.endswith("_duration")
        and v.safety_metric is None
    }  # fmt: skip
    assert durations == {"task_duration": pytest.approx(recording), "mission_duration": pytest.approx(recording)}
