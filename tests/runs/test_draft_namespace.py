"""A robot whose topics are all under one namespace is drafted in it, even with TF at the root
(issue 47, item 8): a Gazebo robot under ``/elektron/...`` whose ``/tf`` is global was drafted as a
robot at the root, beside itself in ``elektron``; and its counts agree with their nouns."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from exsce_dsl.api.drafts import init_from_bag
from exsce_dsl.lang import load_spec

from tests.support.bag_factory import (
    LASER_SCAN,
    ODOMETRY,
    PERIOD_NS,
    START_NS,
    TF_MESSAGE,
    Topic,
    laser_scan,
    odometry,
    tf_message,
    twist,
    typestore_for,
    write_bag,
)


def test_robot_under_elektron_is_drafted_in_its_namespace(tmp_path: Path) -> None:
    store = typestore_for("ros1")
    times = [START_NS + i * PERIOD_NS for i in range(60)]
    bag = tmp_path / "gazebo_run.bag"
    topics = [
        Topic("/elektron/odom", ODOMETRY, [(t, odometry(store, i, t)) for i, t in enumerate(times)]),
        Topic(
            "/elektron/cmd_vel",
            "geometry_msgs/msg/Twist",
            [(t, twist(store, np.random.default_rng(i))) for i, t in enumerate(times)],
        ),
        Topic("/elektron/scan", LASER_SCAN, [(t, laser_scan(store, i, t)) for i, t in enumerate(times)]),
        Topic("/tf", TF_MESSAGE, [(t, tf_message(store, i, t)) for i, t in enumerate(times)]),
    ]
    write_bag(bag, "ros1", topics, store)
    draft = init_from_bag(bag, tmp_path / "gazebo_run.exsce")
    assert [(rid, ns) for rid, ns, _ in draft.robots] == [("elektron", "elektron")]
    (robot,) = load_spec(draft.spec).scenario().robots
    assert robot.namespace == "elektron"
    assert 'namespace ""' not in draft.spec.read_text()


def test_counts_agree_with_their_numbers(tmp_path: Path) -> None:
    """ "1 waypoints", "1 topics": a count's noun agrees with its number (wording.counted)."""
    store = typestore_for("ros1")
    times = [START_NS + i * PERIOD_NS for i in range(20)]
    bag = tmp_path / "one_topic.bag"
    write_bag(
        bag, "ros1", [Topic("/odom", ODOMETRY, [(t, odometry(store, i, t)) for i, t in enumerate(times)])]
    )
    text = init_from_bag(bag, tmp_path / "one_topic.exsce").text
    assert "from one_topic.bag: 1 topic, " in text and "1 robot found" in text, text.splitlines()[0]
