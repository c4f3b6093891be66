"""Messages wanted whole as objects (a Nav2 robot's global plans, action statuses) are deserialised
when first read (runs.bags.objects.LazyMessage): a stack that replans once a second publishes hundreds
of plans, of which a goal's target needs one."""

from __future__ import annotations

import pytest
from rosbags.typesys import Stores, get_typestore

from exsce_dsl.errors import BagError
from exsce_dsl.runs.bags.objects import LazyMessage, deserialized

STORE = get_typestore(Stores.ROS2_HUMBLE)


def _plan(n: int) -> bytes:
    t = STORE.types
    header = t["std_msgs/msg/Header"](
        stamp=t["builtin_interfaces/msg/Time"](sec=n, nanosec=0), frame_id="map"
    )
    poses = [
        t["geometry_msgs/msg/PoseStamped"](
            header=header,
            pose=t["geometry_msgs/msg/Pose"](
                position=t["geometry_msgs/msg/Point"](x=float(i), y=float(n), z=0.0),
                orientation=t["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0),
            ),
        )
        for i in range(3)
    ]
    return bytes(STORE.serialize_cdr(t["nav_msgs/msg/Path"](header=header, poses=poses), "nav_msgs/msg/Path"))


def test_only_the_messages_read_are_deserialised_and_equal_ones_once() -> None:
    reads: list[bytes] = []

    def read(raw: bytes) -> object:
        reads.append(raw)
        return STORE.deserialize_cdr(raw, "nav_msgs/msg/Path")

    raws = [_plan(1), _plan(2), _plan(2), _plan(3)]
    plans = deserialized(read, raws, lazy="/r1/plan")
    assert all(isinstance(p, LazyMessage) for p in plans) and plans[1] is plans[2]
    assert reads == []
    assert plans[1].poses[-1].pose.position.y == 2.0  # read through, as the object itself
    assert plans[2].header.stamp.sec == 2
    assert reads == [raws[1]]  # one read for the two equal messages, none for the others


def test_without_lazy_every_distinct_message_is_read_at_once() -> None:
    reads: list[bytes] = []

    def read(raw: bytes) -> object:
        reads.append(raw)
        return STORE.deserialize_cdr(raw, "nav_msgs/msg/Path")

    plans = deserialized(read, [_plan(1), _plan(1), _plan(2)])
    assert len(reads) == 2 and plans[0] is plans[1] and plans[2].poses[0].pose.position.y == 2.0


def test_a_message_that_does_not_deserialise_is_a_bag_error_naming_its_topic_when_read() -> None:
    good, bad = _plan(1), _plan(2)[:-20]  # cut short
    plans = deserialized(
        lambda raw: STORE.deserialize_cdr(raw, "nav_msgs/msg/Path"), [good, bad], lazy="/r1/plan"
    )
    assert plans[0].poses[0].pose.position.x == 0.0
    with pytest.raises(BagError, match="/r1/plan does not deserialize"):
        _ = plans[1].poses
