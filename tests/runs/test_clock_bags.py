"""tests/support/clock_bags.py moves a TFMessage's stamps in its bytes; rosbags' own round trip
(deserialise, set each transform's stamp, serialise) must give the same bytes, in both
encodings, whatever the frame names' lengths do to CDR's alignment."""

from __future__ import annotations

from typing import Any

import pytest

from tests.support.bag_factory import typestore_for
from tests.support.clock_bags import _sec_nanosec, _stamps, _transforms_moved

FRAMES = [("map", "odom"), ("odom", "tiago1/base_footprint"), ("b", "laser_"), ("world", "x")]


def _move(seconds: float) -> float:
    return 931.25 + (seconds - 1_700_000_000.0) * 0.5


def _tf(store: Any, stamps: list[tuple[int, int]], ros1: bool) -> Any:
    T = store.types
    transforms = []
    for i, ((frame, child), (sec, nanosec)) in enumerate(zip(FRAMES, stamps, strict=True)):
        seq = {"seq": i} if ros1 else {}  # ROS 1's Header numbers its messages
        time = T["builtin_interfaces/msg/Time"](sec=sec, nanosec=nanosec)
        header = T["std_msgs/msg/Header"](**seq, stamp=time, frame_id=frame)
        transforms.append(
            T["geometry_msgs/msg/TransformStamped"](
                header=header,
                child_frame_id=child,
                transform=T["geometry_msgs/msg/Transform"](
                    translation=T["geometry_msgs/msg/Vector3"](x=1.5 * i, y=-2.0, z=0.25),
                    rotation=T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.6, w=0.8),
                ),
            )
        )
    return T["tf2_msgs/msg/TFMessage"](transforms=transforms)


@pytest.mark.parametrize("fmt", ["ros1", "mcap"])
def test_a_tf_message_moved_in_its_bytes_is_rosbags_round_trip(fmt: str) -> None:
    store = typestore_for(fmt)
    ros1 = fmt == "ros1"
    serialise = store.serialize_ros1 if ros1 else store.serialize_cdr
    deserialise = store.deserialize_ros1 if ros1 else store.deserialize_cdr
    stamps = [(1_700_000_000, 0), (1_700_000_012, 999_999_999), (0, 0), (1_700_000_003, 500_000_000)]
    msgtype = "tf2_msgs/msg/TFMessage"
    raw = serialise(_tf(store, stamps, ros1), msgtype)
    expected = deserialise(raw, msgtype)
    for transform in expected.transforms:
        stamp = transform.header.stamp
        seconds = stamp.sec + stamp.nanosec * 1e-9
        if seconds > 0:  # an unset stamp stays unset
            sec, nanosec = _sec_nanosec(_move(seconds))
            transform.header.stamp = store.types["builtin_interfaces/msg/Time"](sec=sec, nanosec=nanosec)
    moved = _transforms_moved(raw, not ros1, _move)
    assert moved == bytes(serialise(expected, msgtype))
    assert moved != bytes(raw)
    assert _stamps(store, msgtype) == "tf"
