"""Topics named as real bags name them (issue 32, item 3): ROS 1 records a name as its node
published it, so a bag may hold relative names (``groundtruth``, ``cmd_vel``) and names that ROS 2
would refuse (``ORB-SLAM``).  No such name stops ingestion; a specification's name reads the bag's
topic with or without the leading slash (both, merged, when a bag holds both); the run's PROV names
the topics as the bag spells them.

The bags: the executor's Nav2 run of a robot at the root, in ROS 1, ROS 2 sqlite3 and MCAP, copied
byte for byte with every topic renamed to its relative name, and a ground truth added on
``groundtruth`` and ``/groundtruth`` and a pose on ``ORB-SLAM``.  The reference values are
rosbags' own deserialisation of the ground truth."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
from rosbags.highlevel import AnyReader
from rosbags.rosbag1 import Reader as Ros1Reader
from rosbags.rosbag1 import Writer as Ros1Writer
from rosbags.rosbag2 import Reader as Ros2Reader
from rosbags.rosbag2 import StoragePlugin
from rosbags.rosbag2 import Writer as Ros2Writer

from exsce_dsl.lang import load_spec
from exsce_dsl.model import Scenario
from exsce_dsl.model.messages import path_of
from exsce_dsl.model.runs import MetricScope, Run
from exsce_dsl.prov import identifiers as ids
from exsce_dsl.prov import serialize_prov
from exsce_dsl.prov.run import compile_run
from exsce_dsl.runs.analyse import analyse_bag
from exsce_dsl.runs.bags.data import Wanted
from exsce_dsl.runs.bags.reading import bag_topics, read_bag
from exsce_dsl.runs.ingest import ingest_bags
from exsce_dsl.runs.signals.trajectories import trajectories
from exsce_dsl.sim.run import simulate
from exsce_dsl.store import queries as q
from exsce_dsl.store.embedded import EmbeddedStore

from tests.support.bag_factory import (
    ODOMETRY,
    POSE_STAMPED,
    Topic,
    odometry,
    pose_stamped,
    series,
    typestore_for,
    write_bag,
)
from tests.support.paths import EXAMPLES

BUILDING = EXAMPLES / "brsu_building_c"
SPEC = f"""
import "{BUILDING}/environment.exsce"
import "{BUILDING}/tasks/deliveries.exsce"

robot type rover {{
  base pmb2
  torso no
  convention nav2
}}

metric ground_x for each robot {{
  unit m
  reads g: nav_msgs/msg/Odometry on "groundtruth"
  value mean(g.pose.pose.position.x)
}}

metric ground_x_max for each robot {{
  unit m
  reads g: nav_msgs/msg/Odometry on "/groundtruth"
  value max(g.pose.pose.position.x)
}}

scenario at_root in brsu_building_c_with_doors {{
  robots {{
    bot: rover namespace "" starts at classroom_c025-w001
  }}
  mission at_root_mission sequential {{
    bot does delivery_a
  }}
}}
"""
FORMATS = {"ros1": "ros1", "sqlite3": "ros2", "mcap": "mcap"}
"""The bag_factory's format name → the executor's."""
GROUND_TRUTH = (("groundtruth", 0), ("/groundtruth", 1))
"""The ground truth's two spellings, each with every other message (the second from 1 on)."""


@pytest.fixture(scope="module")
def scenario(tmp_path_factory: pytest.TempPathFactory) -> Scenario:
    folder = tmp_path_factory.mktemp("topic_names")
    (folder / "at_root.exsce").write_text(SPEC)
    return load_spec(folder / "at_root.exsce").scenario()


def renamed(topic: str) -> str:
    """The name as a ROS 1 node may have published it: relative."""
    return topic.lstrip("/")


def extra_messages(fmt: str, start_ns: int) -> list[tuple[str, str, int, bytes]]:
    """(topic, type, time, bytes): 40 ground truths over 20 s from 5 s in, split between the two
    spellings, and 10 poses on ORB-SLAM."""
    store = typestore_for(fmt)
    serialize = store.serialize_cdr if fmt != "ros1" else store.serialize_ros1
    found = []
    for i in range(40):
        time_ns = start_ns + 5_000_000_000 + i * 500_000_000
        topic = GROUND_TRUTH[i % 2][0]
        found.append((topic, ODOMETRY, time_ns, serialize(odometry(store, i, time_ns, seed=7), ODOMETRY)))
    for i in range(10):
        time_ns = start_ns + 1_000_000_000 * (i + 1)
        found.append(("ORB-SLAM", POSE_STAMPED, time_ns, serialize(pose_stamped(store, i, time_ns), POSE_STAMPED)))
    return found


def copy_ros1(source: Path, target: Path) -> None:
    store = typestore_for("ros1")
    with Ros1Reader(source) as reader, Ros1Writer(target) as writer:
        out = {}
        for conn in reader.connections:
            out[conn.id] = writer.add_connection(
                renamed(conn.topic), conn.msgtype, msgdef=conn.msgdef.data, md5sum=conn.digest,
                callerid=conn.ext.callerid, latching=conn.ext.latching,
            )
        extra = {}
        for topic, msgtype in (("groundtruth", ODOMETRY), ("/groundtruth", ODOMETRY), ("ORB-SLAM", POSE_STAMPED)):
            msgdef, md5sum = store.generate_msgdef(msgtype)
            extra[topic] = writer.add_connection(topic, msgtype, msgdef=msgdef, md5sum=md5sum)
        messages = [(t, out[c.id], raw) for c, t, raw in reader.messages()]
        messages += [(t, extra[topic], raw) for topic, _, t, raw in extra_messages("ros1", reader.start_time)]
        for t, conn, raw in sorted(messages, key=lambda m: m[0]):
            writer.write(conn, t, raw)


def copy_ros2(source: Path, target: Path, fmt: str) -> None:
    store = typestore_for(fmt)
    plugin = StoragePlugin.MCAP if fmt == "mcap" else StoragePlugin.SQLITE3
    with Ros2Reader(source) as reader, Ros2Writer(target, version=9, storage_plugin=plugin) as writer:
        out = {}
        for conn in reader.connections:
            out[conn.id] = writer.add_connection(
                renamed(conn.topic), conn.msgtype, msgdef=conn.msgdef.data, rihs01=conn.digest,
                serialization_format=conn.ext.serialization_format,
                offered_qos_profiles=conn.ext.offered_qos_profiles,
            )
        extra = {
            topic: writer.add_connection(topic, msgtype, typestore=store)
            for topic, msgtype in (("groundtruth", ODOMETRY), ("/groundtruth", ODOMETRY), ("ORB-SLAM", POSE_STAMPED))
        }
        messages = [(t, out[c.id], raw) for c, t, raw in reader.messages()]
        messages += [(t, extra[topic], raw) for topic, _, t, raw in extra_messages(fmt, reader.start_time)]
        for t, conn, raw in sorted(messages, key=lambda m: m[0]):
            writer.write(conn, t, raw)


@pytest.fixture(scope="module", params=list(FORMATS))
def bags(request: pytest.FixtureRequest, scenario: Scenario, tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """The executor's bag as it wrote it, and its copy with the names of a real ROS 1 recording."""
    fmt = request.param
    folder = tmp_path_factory.mktemp(f"bags_{fmt}")
    (run,) = simulate(scenario, folder / "executor", runs=1, fmt=FORMATS[fmt], seed=3, convention="nav2")
    target = folder / ("real.bag" if fmt == "ros1" else "real")
    if fmt == "ros1":
        copy_ros1(run.bag, target)
    else:
        copy_ros2(run.bag, target, fmt)
    return run.bag, target


def broken_copy(bag: Path) -> Path:
    """``bag`` copied with its largest file cut in half (a recording stopped short)."""
    target = bag.with_name(f"broken_{bag.name}")
    if bag.is_dir():
        shutil.copytree(bag, target)
        files = sorted(target.iterdir(), key=lambda f: f.stat().st_size)
        cut = files[-1]
    else:
        shutil.copy(bag, target)
        cut = target
    cut.write_bytes(cut.read_bytes()[: cut.stat().st_size // 2])
    return target


def ground_truth_x(path: Path) -> np.ndarray:
    """The ground truth's x on both spellings, as rosbags deserialises it."""
    with AnyReader([path], default_typestore=typestore_for("ros1" if path.suffix == ".bag" else "sqlite3")) as reader:
        conns = [c for c in reader.connections if c.topic in ("groundtruth", "/groundtruth")]
        assert {c.topic for c in conns} == {"groundtruth", "/groundtruth"}
        return np.array([reader.deserialize(raw, c.msgtype).pose.pose.position.x for c, _, raw in reader.messages(conns)])


def whole(run: Run, metric: str) -> tuple[float, tuple[str, ...]]:
    (value,) = [v for v in run.metrics if v.metric == metric and v.scope is MetricScope.ROBOT]
    return value.value, value.topics


def test_a_bag_of_relative_and_odd_names_ingests(bags: tuple[Path, Path], scenario: Scenario) -> None:
    written, real = bags
    analysed = analyse_bag(real, scenario)
    run = analysed.run
    assert not [p for p in analysed.problems if "missing" in p], analysed.problems
    x = ground_truth_x(real)
    assert len(x) == 40
    mean, topics = whole(run, "ground_x")
    assert mean == pytest.approx(float(np.mean(x)), rel=1e-12)
    assert set(topics) == {"groundtruth", "/groundtruth"}  # the specification's "groundtruth" read both
    top, topics = whole(run, "ground_x_max")
    assert top == pytest.approx(float(np.max(x)), rel=1e-12) and set(topics) == {"groundtruth", "/groundtruth"}
    assert whole(run, "max_velocity")[1] == ("cmd_vel",)  # the bag's spelling, not /cmd_vel
    assert {"cmd_vel", "groundtruth", "/groundtruth"} <= set(run.bag.topics)
    # the names change nothing else: every built-in value is the executor's bag's
    before = {(v.metric, v.robot, v.action): v.value for v in analyse_bag(written, scenario).run.metrics}
    after = {(v.metric, v.robot, v.action): v.value for v in run.metrics if not v.metric.startswith("ground_x")}
    assert after == pytest.approx(before, rel=1e-9)


def test_the_run_prov_and_the_store_name_topics_as_the_bag_does(bags: tuple[Path, Path], scenario: Scenario) -> None:
    real = bags[1]
    run = analyse_bag(real, scenario).run
    provn = serialize_prov(compile_run(run, scenario), "provn")
    assert {"@groundtruth", "groundtruth", "@cmd_vel"} <= {ids.topic_local_name(t) for t in run.bag.topics}
    for topic in run.bag.topics:  # ORB-SLAM too, where the reader lists every topic of the bag
        assert f"entity(topic:{ids.topic_local_name(topic)}," in provn, topic
    with EmbeddedStore(None) as store:
        (result,) = ingest_bags([real], scenario, store)
        assert not result.failed, result.message
        sources = q.metric_sources(store, result.run_id, "ground_x")
        velocity = q.metric_sources(store, result.run_id, "max_velocity")
        alone = store.graph_sizes()
    with EmbeddedStore(None) as store:  # beside a bag that fails, nothing of that one goes in
        done, failed = ingest_bags([real, broken_copy(real)], scenario, store)
        assert not done.failed and failed.failed
        assert store.graph_sizes() == alone
    assert [s.topics for s in sources] == [("/groundtruth", "groundtruth")]
    assert {s.topics for s in velocity} == {("cmd_vel",)} and {s.bag for s in velocity} == {real.name}


def test_the_report_draws_the_same_paths_from_relative_names(bags: tuple[Path, Path]) -> None:
    written, real = bags
    before, after = trajectories(written), trajectories(real)
    assert len(after) == len(before) >= 1  # the root robot's TF path; 'tf', not '/tf'
    for a, b in zip(after, before, strict=True):
        np.testing.assert_array_equal(a.xy, b.xy)


def test_a_ros1_name_that_is_not_utf8_does_not_stop_the_bag(tmp_path: Path) -> None:
    """ROS 1 records any bytes as a topic's name: one that is not UTF-8 is listed with its bytes
    written out (it stopped bag_topics and read_bag with a UnicodeDecodeError)."""
    store = typestore_for("ros1")
    bag = tmp_path / "odd.bag"
    odom = series(store, ODOMETRY, 5)
    write_bag(bag, "ros1", [Topic("/odom", ODOMETRY, odom), Topic("gt\u00e9", ODOMETRY, series(store, ODOMETRY, 5))])
    raw = bag.read_bytes()
    assert raw.count("gt\u00e9".encode()) > 0
    bag.write_bytes(raw.replace("gt\u00e9".encode(), b"gt\xff\xfe"))  # as long: the records stay whole
    assert dict(bag_topics(bag)) == {"/odom": ODOMETRY, "gt\\xff\\xfe": ODOMETRY}
    data = read_bag(bag, {"odom": Wanted(ODOMETRY, (path_of("pose", "pose", "position", "x"),))})
    x = [m.pose.pose.position.x for _, m in odom]
    np.testing.assert_array_equal(data.series["odom"].fields["pose.pose.position.x"], x)
    assert data.spellings == {"odom": ("/odom",)}
