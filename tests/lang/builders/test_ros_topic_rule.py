"""``check`` applies the ROS monitor generators' topic rule, from one function
(:func:`exsce_dsl.model.names.is_ros_topic`), at the same place (issue 46, item 9).

A name a bag may hold but no ROS node can subscribe to (``ORB-SLAM``) stays readable from bags
(issue 32), so ``check`` warns at the read, and ``generate ros1-monitor``/``ros2-monitor`` refuse
it with an error at that same line and column."""

from __future__ import annotations

from pathlib import Path

import pytest

from exsce_dsl.model.names import is_ros_topic, is_topic_pattern

from tests.support.cli import exscec_here
from tests.support.map_files import write_map
from tests.support.yard_spec import YARD_SPEC

METRIC = """
metric odd_speed for each robot {{
  reads o: nav_msgs/Odometry on "{topic}"
  value max(o.twist.twist.linear.x)
}}
"""


@pytest.mark.parametrize(
    ("topic", "ros"),
    [
        ("/{ns}/odom", True),
        ("/{ns}/base/odom", True),
        ("/{ns}/ORB-SLAM", False),
        ("/{ns}/2d_pose", False),
        ("/{ns}/a__b", False),
        ("/{ns}/x.y", False),
        ("/{ns}/caf\u00e9", False),
        ("/{ns}/$x^^$", False),
        ("/{ns}/../odom", False),
    ],
)
def test_check_applies_the_generators_topic_rule(tmp_path: Path, topic: str, ros: bool) -> None:
    assert is_topic_pattern(topic)  # a name bags may hold
    assert is_ros_topic(topic) is ros
    write_map(tmp_path, "map", size=400)
    spec = tmp_path / "yard.exsce"
    spec.write_text(YARD_SPEC + METRIC.format(topic=topic))
    line = len(YARD_SPEC.splitlines()) + 3  # the reads line
    checked = exscec_here("check", "yard.exsce", cwd=tmp_path)
    assert checked.returncode == 0, checked.stderr
    warned = f"yard.exsce:{line}:3: warning: '{topic}' is no topic a ROS node can subscribe to"
    assert (warned in checked.stderr) is not ros, checked.stderr
    for target in ("ros1-monitor", "ros2-monitor"):
        made = exscec_here("generate", target, "yard.exsce", "-o", f"out-{target}", cwd=tmp_path)
        if ros:
            assert made.returncode == 0, made.stderr
        else:
            assert made.returncode == 2
            assert f"yard.exsce:{line}:3: error: " in made.stderr and "is not a ROS topic name" in made.stderr
            assert "Traceback" not in made.stderr
