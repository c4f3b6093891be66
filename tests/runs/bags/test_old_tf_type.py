"""ROS 1's old ``tf/tfMessage`` is TF (regression: rosbag.js's turtlesim bag, whose ``/tf`` a
``tf::TransformBroadcaster`` recorded in the old type from two publishers, showed no transform
but the static one, and no robot's pose could be read from it).

The type has the fields of ``tf2_msgs/msg/TFMessage`` under its old name; it is decoded by its
own definition from the bag.  The reference edges are rosbags' own reading, written here.
"""

from __future__ import annotations

from rosbags.highlevel import AnyReader

from exsce_dsl.model.messages import standard_type
from exsce_dsl.runs.bag_info import bag_info_of
from exsce_dsl.runs.bags.reading import bag_topics

from tests.runs.test_turtlesim_path import TURTLESIM

BAG = TURTLESIM / "example.bag"


def test_old_tf_type_is_tf() -> None:
    assert standard_type("tf/tfMessage") == standard_type("tf2_msgs/msg/TFMessage") == "tf2_msgs/msg/TFMessage"
    assert standard_type("geometry_msgs/Twist") == "geometry_msgs/msg/Twist"
    assert bag_topics(BAG)["/tf"] == "tf2_msgs/msg/TFMessage"


def test_turtlesim_old_tf_edges_are_listed() -> None:
    moving: set[tuple[str, str]] = set()
    with AnyReader([BAG]) as reader:
        (kind,) = {c.msgtype for c in reader.connections if c.topic == "/tf"}
        assert kind == "tf/msg/tfMessage"
        for connection, _, raw in reader.messages([c for c in reader.connections if c.topic == "/tf"]):
            for transform in reader.deserialize(raw, connection.msgtype).transforms:
                moving.add((transform.header.frame_id.lstrip("/"), transform.child_frame_id.lstrip("/")))
    assert moving == {("world", "turtle1"), ("world", "turtle2")}
    info = bag_info_of(BAG)
    listed = {(p.lstrip("/"), c.lstrip("/")) for p, c, static in info.tf_edges if not static}
    assert listed == moving
    assert {t.name: t.msgtype for t in info.topics}["/tf"] == "tf/msg/tfMessage"  # shown as recorded
