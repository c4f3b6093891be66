"""Metrics over any message type, from ROS 1, ROS 2 sqlite3 and MCAP bags (issue 17's "done when").

Executor runs of a namespaced robot and of a robot at the root are rewritten
with two more topics per robot: ``nav_msgs/msg/Odometry`` on ``/{ns}/odom``
(built from the run's pose and velocity, with frame ids of varying length, so
messages differ in size) and ``turtlesim/msg/Pose`` on ``/{ns}/turtle``, a type
no typestore knows: its definition is only in the bag.  The user's metrics over
them are checked against values computed from rosbags' own deserialisation of
the same messages, in plain Python loops.
"""

from __future__ import annotations

import math
import shutil
from pathlib import Path
from typing import Any

import pytest
from rosbags.highlevel import AnyReader
from rosbags.rosbag1 import Writer as Writer1
from rosbags.rosbag2 import StoragePlugin
from rosbags.rosbag2 import Writer as Writer2
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from exsce_dsl.lang import load_spec
from exsce_dsl.runs.analyse import analyse_bag

from tests.support.cli import exscec_here
from tests.support.paths import EXAMPLES

TURTLE = "turtlesim/msg/Pose"
TURTLE_MSG = "float32 x\nfloat32 y\nfloat32 theta\nfloat32 linear_velocity\nfloat32 angular_velocity\n"

METRICS = """
metric odom_path for each robot per segment {
  "metres along the odometry's positions"
  unit m
  reads odom: nav_msgs/msg/Odometry on "/{ns}/odom"
  value path_length(odom.pose.pose.position.x, odom.pose.pose.position.y)
}

metric odom_top_speed for each robot {
  unit m/s
  reads odom: nav_msgs/msg/Odometry on "/{ns}/odom"
  value max(norm(odom.twist.twist.linear.x, odom.twist.twist.linear.y))
}

metric turtle_top_speed for each robot {
  unit m/s
  reads turtle: turtlesim/msg/Pose on "/{ns}/turtle"
  value max(abs(turtle.linear_velocity))
}
"""


def _spec(folder: Path, namespace: str) -> Path:
    shutil.copytree(EXAMPLES / "brsu_building_c", folder / "example")
    (folder / "odom_metrics.exsce").write_text(METRICS)
    declared = f' namespace "{namespace}"' if namespace != "tiago1" else ""
    spec = folder / "solo.exsce"
    spec.write_text(
        f"""import "example/environment.exsce"
import "example/robots.exsce"
import "example/tasks/deliveries.exsce"
import "odom_metrics.exsce"

scenario solo in brsu_building_c_with_doors {{
  robots {{
    tiago1: tiago{declared} starts at classroom_c025-w001
  }}
  mission solo_mission parallel {{
    tiago1 does delivery_a
  }}
}}
"""
    )
    return spec


def _typestore(ros1: bool) -> Any:
    store = get_typestore(Stores.ROS1_NOETIC if ros1 else Stores.ROS2_HUMBLE)
    store.register(get_types_from_msg(TURTLE_MSG, TURTLE))
    return store


def _rewrite(source: Path, target: Path, fmt: str, namespace: str) -> None:
    """``source``'s messages and, per pose message, an Odometry and a turtlesim Pose."""
    ros1 = fmt == "ros1"
    store = _typestore(ros1)
    prefix = f"/{namespace}" if namespace else ""
    T = store.types
    with AnyReader([source], default_typestore=store) as reader:
        messages = [(c, t, raw) for c, t, raw in reader.messages()]
        msgtypes = {c.topic: c.msgtype for c in reader.connections}
        velocity = [
            (t, reader.deserialize(raw, c.msgtype)) for c, t, raw in messages if c.topic == f"{prefix}/nav_vel"
        ]
        poses = [
            (t, reader.deserialize(raw, c.msgtype)) for c, t, raw in messages if c.topic == f"{prefix}/robot_pose"
        ]
        store.register({k: v for k, v in reader.typestore.fielddefs.items() if k not in store.fielddefs})
    assert poses and velocity
    written = []
    k = 0
    for n, (t, pose) in enumerate(poses):
        while k + 1 < len(velocity) and velocity[k + 1][0] <= t:
            k += 1
        twist = velocity[k][1]
        header = pose.header
        frame = "odom" + "_x" * (n % 4)  # frame ids of varying length: messages of varying size
        odom = T["nav_msgs/msg/Odometry"](
            header=T["std_msgs/msg/Header"](**{**_fields(header), "frame_id": frame}),
            child_frame_id="base_footprint"[: 4 + n % 10],
            pose=pose.pose,
            twist=T["geometry_msgs/msg/TwistWithCovariance"](twist=twist, covariance=pose.pose.covariance),
        )
        p = pose.pose.pose.position
        turtle = T[TURTLE](
            x=p.x, y=p.y, theta=0.0, linear_velocity=float(twist.linear.x) * (-1) ** n, angular_velocity=0.0
        )
        written += [(t, f"{prefix}/odom", odom, "nav_msgs/msg/Odometry"), (t, f"{prefix}/turtle", turtle, TURTLE)]
    if ros1:
        with Writer1(target) as writer:
            conns = {topic: writer.add_connection(topic, msgtypes[topic], typestore=store) for topic in msgtypes}
            for topic, msgtype in [(f"{prefix}/odom", "nav_msgs/msg/Odometry"), (f"{prefix}/turtle", TURTLE)]:
                conns[topic] = writer.add_connection(topic, msgtype, typestore=store)
            _write(writer, conns, messages, written, lambda m, ty: store.serialize_ros1(m, ty))
    else:
        plugin = StoragePlugin.MCAP if fmt == "mcap" else StoragePlugin.SQLITE3
        with Writer2(target, version=9, storage_plugin=plugin) as writer:
            conns = {}
            for topic, msgtype in msgtypes.items():
                conns[topic] = writer.add_connection(topic, msgtype, typestore=store)
            for topic, msgtype in [(f"{prefix}/odom", "nav_msgs/msg/Odometry"), (f"{prefix}/turtle", TURTLE)]:
                conns[topic] = writer.add_connection(topic, msgtype, typestore=store)
            _write(writer, conns, messages, written, lambda m, ty: store.serialize_cdr(m, ty))


def _fields(message: Any) -> dict[str, Any]:
    return {name: getattr(message, name) for name in message.__dataclass_fields__}


def _write(writer: Any, conns: dict[str, Any], messages: list, written: list, serialize: Any) -> None:  # type: ignore[type-arg]
    for conn, t, raw in messages:
        writer.write(conns[conn.topic], t, raw)
    for t, topic, message, msgtype in written:
        writer.write(conns[topic], t, serialize(message, msgtype))


def _reference(bag: Path, namespace: str, start: float, end: float) -> dict[str, float]:
    """The metrics from rosbags' deserialisation, in plain Python, over the robot's window."""
    prefix = f"/{namespace}" if namespace else ""
    store = _typestore(bag.suffix == ".bag")
    with AnyReader([bag], default_typestore=store) as reader:
        odom = [c for c in reader.connections if c.topic == f"{prefix}/odom"]
        turtle = [c for c in reader.connections if c.topic == f"{prefix}/turtle"]
        odoms = [(t / 1e9, reader.deserialize(raw, c.msgtype)) for c, t, raw in reader.messages(connections=odom)]
        turtles = [(t / 1e9, reader.deserialize(raw, c.msgtype)) for c, t, raw in reader.messages(connections=turtle)]
    odoms = [(t, m) for t, m in odoms if start <= t <= end]
    turtles = [(t, m) for t, m in turtles if start <= t <= end]
    path = 0.0
    for (_, a), (_, b) in zip(odoms, odoms[1:], strict=False):
        pa, pb = a.pose.pose.position, b.pose.pose.position
        path += math.sqrt((pb.x - pa.x) ** 2 + (pb.y - pa.y) ** 2)
    top = max(math.hypot(m.twist.twist.linear.x, m.twist.twist.linear.y) for _, m in odoms)
    turtle_top = max(abs(m.linear_velocity) for _, m in turtles)
    return {"odom_path": path, "odom_top_speed": top, "turtle_top_speed": turtle_top}


@pytest.mark.parametrize("namespace", ["tiago1", ""], ids=["namespaced", "at-the-root"])
@pytest.mark.parametrize("fmt", ["ros1", "ros2", "mcap"])
def test_metrics_over_odometry_and_a_type_known_only_from_the_bag(
    tmp_path: Path, fmt: str, namespace: str
) -> None:
    spec = _spec(tmp_path, namespace)
    result = exscec_here("simulate", str(spec), "--runs", "1", "-o", str(tmp_path / "runs"), "--format", fmt, cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    (source,) = [p for p in (tmp_path / "runs").iterdir() if not p.name.endswith(".prov.json")]
    target = tmp_path / ("rewritten.bag" if fmt == "ros1" else "rewritten")
    _rewrite(source, target, fmt, namespace)
    scenario = load_spec(spec).scenario("solo")
    analysed = analyse_bag(target, scenario)
    values = {m.metric: m for m in analysed.run.metrics if m.robot == "tiago1" and m.action is None}
    assert {"odom_path", "odom_top_speed", "turtle_top_speed"} <= set(values), analysed.problems
    actions = [a for task in analysed.run.tasks for a in task.actions]
    start = min(a.start for a in actions).timestamp()
    end = max(a.end for a in actions).timestamp()
    expected = _reference(target, namespace, start, end)
    for name, value in expected.items():
        assert values[name].value == pytest.approx(value, rel=1e-9), name
    prefix = f"/{namespace}" if namespace else ""
    assert values["odom_path"].topics == (f"{prefix}/odom",)
    assert values["turtle_top_speed"].topics == (f"{prefix}/turtle",)
    assert expected["odom_path"] > 5.0 and expected["turtle_top_speed"] > 0.1  # the run drove somewhere
