"""Benchmark: decoding the fields a metric reads, per message type, from ROS 1 and MCAP bags.

Writes one bag per format with rosbags' writers, two minutes of:

  /odom     nav_msgs/msg/Odometry at 50 Hz (frame ids of varying length)
  /tf       tf2_msgs/msg/TFMessage at 100 Hz, 3 transforms (child frame ids of varying length)
  /scan     sensor_msgs/msg/LaserScan at 15 Hz, 720 beams
  /goal     geometry_msgs/msg/PoseStamped at 20 Hz
  /custom   bench_msgs/msg/Nested at 20 Hz: a string, an array of messages each with a
            string and a variable array, a fixed array (defined only in the bag)

then measures, in the same process, on the same file, for each topic:

  (a) rosbags iterating the topic's raw messages without deserializing them;
  (b) rosbags deserializing every message and reading the fields in Python;
  (c) exsce reading the fields (``read_bag``: the decoder generated from the definition).

It prints messages/s for each and the ratios.  Targets: (c) at least 10× (b)
for Odometry and TFMessage, and (c) no slower than 0.5× (a).

    python bench/decode.py [--seconds 120] [--repeat 3] [--keep DIR]
"""

from __future__ import annotations

import argparse
import math
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from rosbags.highlevel import AnyReader
from rosbags.rosbag1 import Writer as Writer1
from rosbags.rosbag2 import StoragePlugin
from rosbags.rosbag2 import Writer as Writer2
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from exsce_dsl.model.messages import FieldPath, Index, Select, path_of
from exsce_dsl.runs.bags.data import Wanted
from exsce_dsl.runs.bags.reading import read_bag

NESTED = {
    "bench_msgs/msg/Item": "string name\nfloat64[] values\nint32 id\n",
    "bench_msgs/msg/Nested": (
        "std_msgs/Header header\nbench_msgs/Item[] items\nfloat32[4] fixed\nuint16 level\n"
    ),
}

TOPICS: dict[str, tuple[str, float, tuple[FieldPath, ...]]] = {
    "/odom": (
        "nav_msgs/msg/Odometry",
        50,
        (
            path_of("pose", "pose", "position", "x"),
            path_of("pose", "pose", "position", "y"),
            path_of("twist", "twist", "linear", "x"),
            path_of("twist", "twist", "linear", "y"),
            path_of("twist", "twist", "angular", "z"),
        ),
    ),
    "/tf": (
        "tf2_msgs/msg/TFMessage",
        100,
        tuple(
            FieldPath(
                ("transforms", Select(("child_frame_id",), "base_footprint"), "transform", "translation", c)
            )
            for c in "xy"
        ),
    ),
    "/scan": (
        "sensor_msgs/msg/LaserScan",
        15,
        (path_of("ranges"), path_of("range_min"), path_of("range_max")),
    ),
    "/goal": (
        "geometry_msgs/msg/PoseStamped",
        20,
        (path_of("pose", "position", "x"), path_of("pose", "position", "y")),
    ),
    "/custom": (
        "bench_msgs/msg/Nested",
        20,
        (
            FieldPath(("items", Index(0), "id")),
            FieldPath(("items",), length=True),
            path_of("fixed"),
            path_of("level"),
        ),
    ),
}


def typestore(ros1: bool) -> Any:
    store = get_typestore(Stores.ROS1_NOETIC if ros1 else Stores.ROS2_HUMBLE)
    types: dict[str, Any] = {}
    for name, text in NESTED.items():
        types.update(get_types_from_msg(text, name))
    if ros1:
        types.update(
            get_types_from_msg("geometry_msgs/TransformStamped[] transforms", "tf2_msgs/msg/TFMessage")
        )
    store.register(types)
    return store


def messages(store: Any, ros1: bool, seconds: float) -> list[tuple[str, str, int, Any]]:
    """(topic, type, time in ns, message) of every message, in time order."""
    T = store.types
    rng = np.random.default_rng(7)
    start = 1_700_000_000 * 10**9
    out: list[tuple[str, str, int, Any]] = []

    def header(t: int, frame: str) -> Any:
        stamp = T["builtin_interfaces/msg/Time"](sec=t // 10**9, nanosec=t % 10**9)
        extra = {"seq": 0} if ros1 else {}
        return T["std_msgs/msg/Header"](stamp=stamp, frame_id=frame, **extra)

    def vec(x: float, y: float, z: float) -> Any:
        return T["geometry_msgs/msg/Vector3"](x=x, y=y, z=z)

    def quat() -> Any:
        return T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0)

    def point(x: float, y: float) -> Any:
        return T["geometry_msgs/msg/Point"](x=x, y=y, z=0.0)

    for topic, (msgtype, rate, _) in TOPICS.items():
        for i in range(int(seconds * rate)):
            t = start + int(i * 1e9 / rate)
            x, y = float(rng.normal()), float(rng.normal())
            frame = "odom" + "_" * (i % 3)
            if topic == "/odom":
                pose = T["geometry_msgs/msg/PoseWithCovariance"](
                    pose=T["geometry_msgs/msg/Pose"](position=point(x, y), orientation=quat()),
                    covariance=np.zeros(36),
                )
                twist = T["geometry_msgs/msg/TwistWithCovariance"](
                    twist=T["geometry_msgs/msg/Twist"](linear=vec(x, y, 0.0), angular=vec(0.0, 0.0, y)),
                    covariance=np.zeros(36),
                )
                msg = T[msgtype](header=header(t, frame), child_frame_id="base_link", pose=pose, twist=twist)
            elif topic == "/tf":
                transforms = [
                    T["geometry_msgs/msg/TransformStamped"](
                        header=header(t, parent),
                        child_frame_id=child,
                        transform=T["geometry_msgs/msg/Transform"](
                            translation=vec(x + k, y, 0.0), rotation=quat()
                        ),
                    )
                    for k, (parent, child) in enumerate(
                        [("map", "odom"), ("odom", "base_footprint"), ("base_footprint", "base_link")]
                    )
                ]
                msg = T[msgtype](transforms=transforms)
            elif topic == "/scan":
                msg = T[msgtype](
                    header=header(t, "laser"),
                    angle_min=-1.5,
                    angle_max=1.5,
                    angle_increment=3.0 / 720,
                    time_increment=0.0,
                    scan_time=1 / 15,
                    range_min=0.05,
                    range_max=25.0,
                    ranges=rng.uniform(0.1, 20.0, 720).astype(np.float32),
                    intensities=np.zeros(0, dtype=np.float32),
                )
            elif topic == "/goal":
                pose = T["geometry_msgs/msg/Pose"](position=point(x, y), orientation=quat())
                msg = T[msgtype](header=header(t, frame), pose=pose)
            else:
                items = [
                    T["bench_msgs/msg/Item"](
                        name="item" * (k + 1), values=np.arange(k + i % 4, dtype=np.float64), id=k
                    )
                    for k in range(1 + i % 3)
                ]
                msg = T[msgtype](
                    header=header(t, frame), items=items, fixed=np.arange(4, dtype=np.float32), level=i % 7
                )
            out.append((topic, msgtype, t, msg))
    out.sort(key=lambda m: m[2])
    return out


def write_ros1(path: Path, seconds: float) -> None:
    store = typestore(ros1=True)
    with Writer1(path) as writer:
        conns = {
            topic: writer.add_connection(topic, msgtype, typestore=store)
            for topic, (msgtype, _, _) in TOPICS.items()
        }
        for topic, msgtype, t, msg in messages(store, True, seconds):
            writer.write(conns[topic], t, store.serialize_ros1(msg, msgtype))


def write_mcap(path: Path, seconds: float) -> None:
    store = typestore(ros1=False)
    with Writer2(path, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        conns = {
            topic: writer.add_connection(topic, msgtype, typestore=store)
            for topic, (msgtype, _, _) in TOPICS.items()
        }
        for topic, msgtype, t, msg in messages(store, False, seconds):
            writer.write(conns[topic], t, store.serialize_cdr(msg, msgtype))


def way_a(bag: Path, topic: str) -> int:
    count = 0
    with AnyReader([bag], default_typestore=get_typestore(Stores.ROS2_HUMBLE)) as reader:
        conns = [c for c in reader.connections if c.topic == topic]
        for _ in reader.messages(connections=conns):
            count += 1
    return count


def _attribute(message: Any, path: FieldPath) -> Any:
    node = message
    for step in path.steps:
        if isinstance(step, str):
            node = getattr(node, step)
        elif isinstance(step, Index):
            node = node[step.position] if len(node) > abs(step.position) else None
        else:
            node = next((e for e in node if getattr(e, step.field[0]) == step.value), None)
        if node is None:
            return None
    return len(node) if path.length else node


def way_b(bag: Path, topic: str) -> int:
    """What a hand-written monitor does: deserialize, read the fields, keep them in lists."""
    paths = TOPICS[topic][2]
    kept: list[list[Any]] = [[] for _ in paths]
    with AnyReader([bag], default_typestore=get_typestore(Stores.ROS2_HUMBLE)) as reader:
        conns = [c for c in reader.connections if c.topic == topic]
        for conn, _, raw in reader.messages(connections=conns):
            msg = reader.deserialize(raw, conn.msgtype)
            for values, path in zip(kept, paths, strict=True):
                values.append(_attribute(msg, path))
    return len(kept[0])


def way_c(bag: Path, topic: str) -> int:
    msgtype, _, paths = TOPICS[topic]
    data = read_bag(bag, {topic: Wanted(msgtype, paths)})
    return len(data.series[topic])


def best(func: Callable[[Path, str], int], bag: Path, topic: str, repeat: int) -> tuple[float, int]:
    times = []
    count = 0
    for _ in range(repeat):
        started = time.perf_counter()
        count = func(bag, topic)
        times.append(time.perf_counter() - started)
    return min(times), count


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--seconds", type=float, default=120.0, help="length of the recording (default 120)")
    parser.add_argument("--repeat", type=int, default=3, help="best of this many runs (default 3)")
    parser.add_argument("--keep", type=Path, help="write the bags here and keep them")
    args = parser.parse_args()
    folder = args.keep or Path(tempfile.mkdtemp(prefix="exsce-bench-decode-"))
    folder.mkdir(parents=True, exist_ok=True)
    bags = {"ROS 1": folder / "decode.bag", "MCAP": folder / "decode_mcap"}
    if not bags["ROS 1"].exists():
        write_ros1(bags["ROS 1"], args.seconds)
    if not bags["MCAP"].exists():
        write_mcap(bags["MCAP"], args.seconds)
    print(f"bags of {args.seconds:.0f} s in {folder}; best of {args.repeat}; messages/s (higher is better)")
    ways = f"{'(a) raw':>10} {'(b) naive':>10} {'(c) exsce':>10}"
    print(f"{'format':7} {'topic':8} {'type':30} {'msgs':>6} {ways} {'c/b':>6} {'c/a':>6}")
    for name, bag in bags.items():
        for topic, (msgtype, _, _) in TOPICS.items():
            rates = []
            count = 0
            for way in (way_a, way_b, way_c):
                seconds, count = best(way, bag, topic, args.repeat)
                rates.append(count / seconds if seconds else math.inf)
            a, b, c = rates
            print(
                f"{name:7} {topic:8} {msgtype:30} {count:6d} {a:10.0f} {b:10.0f} {c:10.0f} "
                f"{c / b:5.1f}× {c / a:5.2f}×"
            )
    print("targets: (c)/(b) ≥ 10× for Odometry and TFMessage; (c)/(a) ≥ 0.5×")


if __name__ == "__main__":
    main()
