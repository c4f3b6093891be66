"""exsce's ROS 2 recorder (execute/ros2/recorder.py, record_node.py) on a live graph: real
processes, Fast DDS on loopback, a domain per test.

A publisher process (rclpy, :data:`PUBLISHER`) publishes what a run records: odometry at 50 Hz,
a latched ``tf_static`` and PROV message published once before the recorder starts, a
NavigateToPose server's feedback and status, and on simulated time ``/clock``.  The bag is read
back with rosbags' ``AnyReader`` and its deserialisation (not exsce's bag reading), its
metadata.yaml with PyYAML; the reference values are what the publisher published, the reference
hashes rosbags' ROS 2 Jazzy typestore's and, for nav2_msgs, those rosidl wrote when it built them.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest
import yaml
from rosbags.highlevel import AnyReader
from rosbags.interfaces import Qos, QosDurability, QosHistory, QosLiveliness, QosReliability, QosTime
from rosbags.typesys import Stores, get_typestore

from exsce_dsl.errors import ExsceError, RosGraphError
from exsce_dsl.execute.ros2 import RECORDER_NODE, Ros2Recorder
from exsce_dsl.execute.ros2.record_types import adapted_qos
from exsce_dsl.execute.ros2.recorder import DISCOVERY, partial_folder
from exsce_dsl.runs import PROV_TOPIC

from tests.support.paths import ROOT

PUBLISHER = textwrap.dedent(
    """
    import json, sys, time, rclpy
    from rclpy.action import ActionClient, ActionServer
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
    from builtin_interfaces.msg import Time
    from geometry_msgs.msg import TransformStamped
    from nav2_msgs.action import NavigateToPose
    from nav_msgs.msg import Odometry
    from rosgraph_msgs.msg import Clock
    from std_msgs.msg import String
    from tf2_msgs.msg import TFMessage

    mode, count = sys.argv[1], int(sys.argv[2])
    rclpy.init()
    node = rclpy.create_node("exsce_test_publisher")
    latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL, reliability=ReliabilityPolicy.RELIABLE)
    static = node.create_publisher(TFMessage, "/tiago1/tf_static", latched)
    prov = node.create_publisher(String, "/exsce/prov", latched)
    odom = node.create_publisher(Odometry, "/tiago1/odom", 10)
    clock = node.create_publisher(Clock, "/clock", 10)
    transform = TransformStamped()
    transform.header.frame_id, transform.child_frame_id = "tiago1/base_link", "tiago1/laser"
    transform.transform.translation.x = 0.202
    static.publish(TFMessage(transforms=[transform]))
    prov.publish(String(data="prov before the recorder"))

    def execute(handle):
        for left in (3.0, 2.0, 1.0):
            feedback = NavigateToPose.Feedback()
            feedback.distance_remaining = left
            handle.publish_feedback(feedback)
        handle.succeed()
        return NavigateToPose.Result()

    server = ActionServer(node, NavigateToPose, "/tiago1/navigate_to_pose", execute)
    client = ActionClient(node, NavigateToPose, "/tiago1/navigate_to_pose")

    def spin(seconds):
        end = time.monotonic() + seconds
        while True:
            rclpy.spin_once(node, timeout_sec=max(0.0, min(0.005, end - time.monotonic())))
            if time.monotonic() >= end:
                return

    def publish_odom(i):
        message = Odometry()
        message.header.frame_id, message.child_frame_id = "tiago1/odom", "tiago1/base_link"
        message.header.stamp = Time(sec=i, nanosec=7)
        message.pose.pose.position.x = 0.25 * i
        message.twist.twist.linear.x = 0.5
        odom.publish(message)

    print("ready", flush=True)
    recorders = int(sys.stdin.readline())
    # discovery is matched on each side on its own: publish once this side sees the recorders
    # (on simulated time, their clocks' subscriptions to /clock too)
    needed = [(odom, recorders)] + ([(clock, 2 * recorders)] if mode == "sim" else [])
    end = time.monotonic() + 10.0
    while time.monotonic() < end and any(p.get_subscription_count() < n for p, n in needed):
        rclpy.spin_once(node, timeout_sec=0.01)
    # the action's feedback and status writers are the server's own: wait until this node sees the
    # recorders' readers of them, then give the writers a moment to match (a CI run under load
    # once recorded one feedback of three)
    action = "/tiago1/navigate_to_pose/_action/"
    while time.monotonic() < end and any(node.count_subscribers(action + t) < recorders for t in ("feedback", "status")):
        rclpy.spin_once(node, timeout_sec=0.01)
    spin(0.5)
    if mode == "wall":
        for i in range(count):
            publish_odom(i)
            spin(0.02)
        client.wait_for_server(timeout_sec=10.0)
        sent = client.send_goal_async(NavigateToPose.Goal())
        rclpy.spin_until_future_complete(node, sent, timeout_sec=10.0)
        result = sent.result().get_result_async()
        rclpy.spin_until_future_complete(node, result, timeout_sec=10.0)
    else:  # sim: one odometry before the first /clock, then a /clock and an odometry a tick
        publish_odom(-1)
        spin(0.1)
        for i in range(count):
            clock.publish(Clock(clock=Time(sec=1000 + i, nanosec=500)))
            spin(0.05)
            publish_odom(i)
            spin(0.05)
    print("done", flush=True)
    sys.stdin.readline()
    """
)

FEEDBACK = "/tiago1/navigate_to_pose/_action/feedback"
STATUS = "/tiago1/navigate_to_pose/_action/status"
PUBLISHED = ["/clock", "/tiago1/odom", "/tiago1/tf_static", PROV_TOPIC, FEEDBACK, STATUS]
TOPICS = sorted([*PUBLISHED, "/tf"])
"""As recorded_topics gives them: /tf too, which nothing publishes."""
JAZZY = get_typestore(Stores.ROS2_JAZZY)


class Publisher:
    """The publisher process, started ready (its latched messages out) and told when to publish."""

    def __init__(self, mode: str, count: int) -> None:
        self.process = subprocess.Popen(
            [sys.executable, "-c", PUBLISHER, mode, str(count)],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
        )
        assert self.line() == "ready"

    def line(self) -> str:
        assert self.process.stdout is not None
        return self.process.stdout.readline().strip()

    def publish(self, recorders: int = 1) -> None:
        """Publish once ``recorders`` recorders are matched to the publisher; return when done."""
        assert self.process.stdin is not None
        self.process.stdin.write(f"{recorders}\n")
        self.process.stdin.flush()
        assert self.line() == "done"

    def close(self) -> None:
        self.process.kill()
        self.process.wait()


def record_run(bag: Path, mode: str, count: int, use_sim_time: bool = False) -> Ros2Recorder:
    """The publisher's run (``mode``, ``count`` messages) recorded into ``bag``; the stopped recorder."""
    publisher = Publisher(mode, count)
    try:
        with Ros2Recorder(bag, TOPICS, use_sim_time=use_sim_time) as recorder:
            recorder.wait_subscribed(20.0, published=PUBLISHED)
            publisher.publish()
            recorder.stop()
    finally:
        publisher.close()
    return recorder


def built_hash(package: str, kind: str, name: str) -> str:
    """The RIHS01 hash rosidl wrote for ``package/kind/name`` when it built the package here."""
    action = name.split("_")[0] if kind == "action" else name
    found = Path(sys.prefix) / "share" / package / kind / f"{action}.json"
    hashes = json.loads(found.read_text(encoding="utf-8"))["type_hashes"]
    return next(h["hash_string"] for h in hashes if h["type_name"] == f"{package}/{kind}/{name}")


def read_bag(bag: Path) -> dict[str, list[tuple[int, object]]]:
    """Each topic's (log time, message), by rosbags' reader and the definitions in the bag."""
    found: dict[str, list[tuple[int, object]]] = {}
    with AnyReader([bag], default_typestore=JAZZY) as reader:
        for connection, stamp, raw in reader.messages():
            found.setdefault(connection.topic, []).append(
                (stamp, reader.deserialize(raw, connection.msgtype))
            )
    return found


def metadata(bag: Path) -> dict[str, object]:
    info: dict[str, object] = yaml.safe_load((bag / "metadata.yaml").read_text())[
        "rosbag2_bagfile_information"
    ]
    return info


def test_a_run_on_a_live_graph_is_recorded_whole(ros2_env: dict[str, str], tmp_path: Path) -> None:
    """Every message published while recording is in the bag with its values, and the latched
    tf_static and PROV published before the recorder started are there too."""
    bag = tmp_path / "runs" / "run_1"
    before = time.time_ns()
    written = record_run(bag, "wall", 50).written
    after = time.time_ns()
    assert not partial_folder(bag).exists()
    messages = read_bag(bag)
    odom = messages["/tiago1/odom"]
    assert [(m.header.stamp.sec, m.pose.pose.position.x) for _, m in odom] == [
        (i, 0.25 * i) for i in range(50)
    ]
    assert {(m.header.stamp.nanosec, m.twist.twist.linear.x, m.child_frame_id) for _, m in odom} == {
        (7, 0.5, "tiago1/base_link")
    }
    [(_, static)] = messages["/tiago1/tf_static"]
    assert [(t.child_frame_id, t.transform.translation.x) for t in static.transforms] == [
        ("tiago1/laser", 0.202)
    ]
    assert [m.data for _, m in messages[PROV_TOPIC]] == ["prov before the recorder"]
    assert [m.feedback.distance_remaining for _, m in messages[FEEDBACK]] == [3.0, 2.0, 1.0]
    assert 4 in {s.status for _, m in messages[STATUS] for s in m.status_list}  # SUCCEEDED
    stamps = [t for found in messages.values() for t, _ in found]
    assert all(before <= t <= after for t in stamps)
    assert [t for t, _ in odom] == sorted(t for t, _ in odom)
    counts = {topic: len(found) for topic, found in messages.items()}
    assert written == {"/clock": 0, "/tf": 0, **counts}
    assert counts["/tiago1/odom"] == 50 and counts[FEEDBACK] == 3


def test_the_bags_metadata_is_as_rosbag2_writes_it(ros2_env: dict[str, str], tmp_path: Path) -> None:
    """metadata.yaml: MCAP, version 9, each topic's offered QoS (the publishers') and type hash."""
    bag = tmp_path / "run_2"
    record_run(bag, "wall", 3)
    info = metadata(bag)
    assert (info["storage_identifier"], info["version"]) == ("mcap", 9)
    assert [Path(f).suffix for f in info["relative_file_paths"]] == [".mcap"]  # type: ignore[attr-defined]
    topics = {t["topic_metadata"]["name"]: t["topic_metadata"] for t in info["topics_with_message_count"]}  # type: ignore[attr-defined]
    assert sorted(topics) == sorted(PUBLISHED)  # /tf: no publisher, not subscribed
    expected = {
        "/clock": JAZZY.hash_rihs01("rosgraph_msgs/msg/Clock"),
        "/tiago1/odom": JAZZY.hash_rihs01("nav_msgs/msg/Odometry"),
        "/tiago1/tf_static": JAZZY.hash_rihs01("tf2_msgs/msg/TFMessage"),
        PROV_TOPIC: JAZZY.hash_rihs01("std_msgs/msg/String"),
        STATUS: JAZZY.hash_rihs01("action_msgs/msg/GoalStatusArray"),
        FEEDBACK: built_hash("nav2_msgs", "action", "NavigateToPose_FeedbackMessage"),
    }
    assert {t: m["type_description_hash"] for t, m in topics.items()} == expected
    assert topics[FEEDBACK]["type"] == "nav2_msgs/action/NavigateToPose_FeedbackMessage"
    durability = {t: [q["durability"] for q in m["offered_qos_profiles"]] for t, m in topics.items()}
    assert durability == {
        "/clock": ["volatile"],
        "/tiago1/odom": ["volatile"],
        "/tiago1/tf_static": ["transient_local"],
        PROV_TOPIC: ["transient_local"],
        STATUS: ["transient_local"],  # rcl_action's status QoS
        FEEDBACK: ["volatile"],
    }
    odom = topics["/tiago1/odom"]["offered_qos_profiles"][0]
    assert (odom["reliability"], odom["deadline"]) == ("reliable", {"sec": 9223372036, "nsec": 854775807})


def test_exscec_bag_info_reads_the_recorded_bag(ros2_env: dict[str, str], tmp_path: Path) -> None:
    """exsce's own bag reading decodes every topic from the definitions the recorder wrote."""
    bag = tmp_path / "run_3"
    record_run(bag, "wall", 20)
    done = subprocess.run(
        [Path(sys.executable).with_name("exscec"), "bag", "info", "--format", "json", str(bag)],
        capture_output=True,
        text=True,
        env={**os.environ, "PYTHONPATH": str(ROOT / "src")},
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    [info] = json.loads(done.stdout)
    assert info["format"] == "ROS 2 (MCAP)"
    topics = {t["name"]: (t["msgtype"], t["messages"], t["definition"]) for t in info["topics"]}
    assert topics["/tiago1/odom"] == ("nav_msgs/msg/Odometry", 20, "the bag")
    assert topics[FEEDBACK] == ("nav2_msgs/action/NavigateToPose_FeedbackMessage", 3, "the bag")
    assert topics["/tiago1/tf_static"] == ("tf2_msgs/msg/TFMessage", 1, "the bag")


def test_on_sim_time_the_log_times_are_the_clocks(ros2_env: dict[str, str], tmp_path: Path) -> None:
    """Log time is /clock's: each odometry at the clock published before it; nothing before the
    first /clock (the odometry published then is dropped and counted), but the latched
    tf_static received before it is written at its time."""
    bag = tmp_path / "run_4"
    recorder = record_run(bag, "sim", 8, use_sim_time=True)
    messages = read_bag(bag)
    ticks = [(1000 + i) * 10**9 + 500 for i in range(8)]
    odom = messages["/tiago1/odom"]
    assert [(t, m.header.stamp.sec) for t, m in odom] == [(ticks[i], i) for i in range(8)]
    assert recorder.dropped == {"/tiago1/odom": 1}
    assert [t for t, _ in messages["/tiago1/tf_static"]] == [ticks[0]]
    assert {m.clock.sec for _, m in messages["/clock"]} == {1000 + i for i in range(8)}
    assert {t for found in messages.values() for t, _ in found} <= set(ticks)


def test_a_killed_recorder_leaves_no_bag_and_a_terminated_one_a_whole_bag(
    ros2_env: dict[str, str], tmp_path: Path
) -> None:
    publisher = Publisher("wall", 10)
    killed, terminated = tmp_path / "run_killed", tmp_path / "run_terminated"
    try:
        first = Ros2Recorder(killed, TOPICS)
        second = Ros2Recorder(terminated, TOPICS)
        with first, second:
            first.wait_subscribed(20.0, published=PUBLISHED)
            second.wait_subscribed(20.0, published=PUBLISHED)
            publisher.publish(recorders=2)
            assert first.process is not None and second.process is not None
            assert partial_folder(killed).is_dir()  # it writes there, beside the bag's name
            os.killpg(first.process.pid, signal.SIGKILL)
            os.killpg(second.process.pid, signal.SIGTERM)
            assert first.process.wait(10) == -signal.SIGKILL and second.process.wait(10) == 0
            assert not killed.exists()
            with pytest.raises(RosGraphError, match="without a bag"):
                first.stop()
            assert not partial_folder(killed).exists()  # stop removed what the killed one left
            assert second.stop()["/tiago1/odom"] == 10
    finally:
        publisher.close()
    assert len(read_bag(terminated)["/tiago1/odom"]) == 10


def test_a_topic_whose_type_cannot_be_described_is_named(ros2_env: dict[str, str], tmp_path: Path) -> None:
    """NavigateToPose_Result: exsce's typestore has another distro's definition (its hash is not
    the advertised one) and no .msg file describes it: the recorder stops naming it, no bag."""
    script = (
        "import time, rclpy\nfrom nav2_msgs.action import NavigateToPose\nrclpy.init()\n"
        "node = rclpy.create_node('odd')\nnode.create_publisher(NavigateToPose.Result, '/tiago1/result', 1)\n"
        "print('ready', flush=True)\ntime.sleep(30)\n"
    )
    odd = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True)
    bag = tmp_path / "run_5"
    try:
        assert odd.stdout is not None and odd.stdout.readline().strip() == "ready"
        with pytest.raises(
            RosGraphError,
            match=r"/tiago1/result: cannot describe the message type "
            r"nav2_msgs/action/NavigateToPose_Result \(advertised hash RIHS01_",
        ):
            with Ros2Recorder(bag, ["/tiago1/result"]) as recorder:
                recorder.wait_subscribed(20.0, published=["/tiago1/result"])
    finally:
        odd.kill()
        odd.wait()
    assert not bag.exists() and not partial_folder(bag).exists()


def test_a_type_the_typestore_lacks_is_described_from_its_installed_msg(
    ros2_env: dict[str, str], tmp_path: Path
) -> None:
    """nav_msgs/msg/Goals (new in Jazzy, not in rosbags' store): from share/nav_msgs/msg/Goals.msg,
    with the hash the publisher advertises."""
    script = (
        "import sys, rclpy\nfrom nav_msgs.msg import Goals\nfrom geometry_msgs.msg import PoseStamped\n"
        "rclpy.init()\nnode = rclpy.create_node('goals')\n"
        "pub = node.create_publisher(Goals, '/tiago1/goals', 10)\nprint('ready', flush=True)\n"
        "sys.stdin.readline()\ngoal = PoseStamped()\ngoal.pose.position.y = 4.5\n"
        "pub.publish(Goals(goals=[goal]))\nend = __import__('time').monotonic() + 0.3\n"
        "while __import__('time').monotonic() < end: rclpy.spin_once(node, timeout_sec=0.05)\n"
        "print('done', flush=True)\nsys.stdin.readline()\n"
    )
    goals = subprocess.Popen(
        [sys.executable, "-c", script], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True
    )
    bag = tmp_path / "run_6"
    try:
        assert goals.stdout is not None and goals.stdin is not None
        assert goals.stdout.readline().strip() == "ready"
        with Ros2Recorder(bag, ["/tiago1/goals"]) as recorder:
            recorder.wait_subscribed(20.0, published=["/tiago1/goals"])
            goals.stdin.write("go\n")
            goals.stdin.flush()
            assert goals.stdout.readline().strip() == "done"
    finally:
        goals.kill()
        goals.wait()
    [topic] = metadata(bag)["topics_with_message_count"]  # type: ignore[misc]
    assert topic["topic_metadata"]["type_description_hash"] == built_hash("nav_msgs", "msg", "Goals")
    assert "definition from its installed .msg files" in recorder.log.read_text()
    [(_, message)] = read_bag(bag)["/tiago1/goals"]
    assert [g.pose.position.y for g in message.goals] == [4.5]


def test_the_qos_asked_for_is_what_every_publisher_offers() -> None:
    """rosbag2's adaptive QoS: one best-effort publisher makes the subscription best effort (a
    reliable one would not match it), one volatile publisher makes it volatile."""

    def offered(reliability: QosReliability, durability: QosDurability) -> Qos:
        forever = QosTime(9223372036, 854775807)
        return Qos(
            QosHistory.UNKNOWN,
            0,
            reliability,
            durability,
            forever,
            forever,
            QosLiveliness.AUTOMATIC,
            forever,
            False,
        )

    reliable_latched = offered(QosReliability.RELIABLE, QosDurability.TRANSIENT_LOCAL)
    best_effort = offered(QosReliability.BEST_EFFORT, QosDurability.VOLATILE)
    assert adapted_qos([reliable_latched, reliable_latched]) == (True, True)
    assert adapted_qos([reliable_latched, best_effort]) == (False, False)
    assert adapted_qos([offered(QosReliability.RELIABLE, QosDurability.VOLATILE), reliable_latched]) == (
        True,
        False,
    )
    assert adapted_qos([]) == (False, False)


def test_the_recorder_refuses_names_it_cannot_record_and_an_existing_bag(tmp_path: Path) -> None:
    for topics in ([], ["tf"], ["/a b"], ["/{ns}/odom"], ["/tiago1/"], ["/1st"]):
        with pytest.raises(ExsceError):
            Ros2Recorder(tmp_path / "bag", topics)
    (tmp_path / "bag").mkdir()
    with pytest.raises(RosGraphError, match="exists"):
        Ros2Recorder(tmp_path / "bag", ["/tf"]).start()
    assert RECORDER_NODE == "exsce_recorder"


def test_without_rclpy_the_recorder_says_how_to_get_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setitem(sys.modules, "rclpy", None)  # not importable, as in a Python without ROS 2
    with pytest.raises(RosGraphError, match=r"needs rclpy.*scripts/install-ros2.*setup\.bash"):
        Ros2Recorder(tmp_path / "runs" / "run_1", ["/tf"]).start()
    assert list(tmp_path.iterdir()) == []  # nothing started, nothing written


ORPHANED = textwrap.dedent(
    """
    import sys, time
    from pathlib import Path
    from exsce_dsl.execute.ros2 import Ros2Recorder
    recorder = Ros2Recorder(Path(sys.argv[1]), ["/tiago1/odom"])
    recorder.start()
    print("started", flush=True)
    time.sleep(60)
    """
)


def test_a_recorder_whose_starter_died_closes_its_bag_and_ends(
    ros2_env: dict[str, str], tmp_path: Path
) -> None:
    """exscec killed (SIGKILL: no chance to stop the recorder): the recorder, in a session of its
    own, notices it is orphaned, closes a whole bag and ends, rather than record for ever."""
    bag = tmp_path / "run_7"
    starter = subprocess.Popen(
        [sys.executable, "-c", ORPHANED, str(bag)],
        stdout=subprocess.PIPE,
        text=True,
        env={**os.environ, "PYTHONPATH": str(ROOT / "src")},
    )
    assert starter.stdout is not None and starter.stdout.readline().strip() == "started"
    starter.kill()
    starter.wait()
    deadline = time.monotonic() + 10.0
    while not (bag / "metadata.yaml").exists():
        assert time.monotonic() < deadline, "the orphaned recorder did not close its bag"
        time.sleep(0.05)
    assert metadata(bag)["message_count"] == 0 and not partial_folder(bag).exists()
    assert "the process that started the recorder is gone" in (tmp_path / "run_7.record.log").read_text()


def test_without_the_published_topics_the_recorder_is_given_time_to_discover_the_graph(
    ros2_env: dict[str, str], tmp_path: Path
) -> None:
    """Just started, the recorder may not see the graph's publishers yet: a caller that does not
    say which topics are published does not get an answer before DISCOVERY seconds."""
    with Ros2Recorder(tmp_path / "run_8", ["/tiago1/odom"]) as recorder:
        with pytest.raises(RosGraphError, match="not started"):
            Ros2Recorder(tmp_path / "run_9", ["/tf"]).wait_subscribed()
        started = time.monotonic()
        recorder.wait_subscribed(20.0)
        assert time.monotonic() - started >= DISCOVERY - 0.1  # from when it was ready, a moment before
    assert recorder.written == {"/tiago1/odom": 0}


TICKING = textwrap.dedent(
    """
    import sys, time, rclpy
    from builtin_interfaces.msg import Time
    from nav_msgs.msg import Odometry
    from rosgraph_msgs.msg import Clock

    rclpy.init()
    node = rclpy.create_node("exsce_test_ticker")
    odom = node.create_publisher(Odometry, "/tiago1/odom", 1000)  # room for what waits on a stalled reader
    clock = node.create_publisher(Clock, "/clock", 1000)
    print("ready", flush=True)
    sys.stdin.readline()
    end = time.monotonic() + 10.0
    while time.monotonic() < end and (odom.get_subscription_count() < 1 or clock.get_subscription_count() < 2):
        rclpy.spin_once(node, timeout_sec=0.01)
    print("publishing", flush=True)
    for i in range(100):  # a tick of 50 ms of simulated time every 10 ms of wall time: 5x
        stamp = Time(sec=2000 + i // 20, nanosec=(i % 20) * 50_000_000)
        clock.publish(Clock(clock=stamp))
        message = Odometry()
        message.header.stamp = stamp
        odom.publish(message)
        time.sleep(0.01)
    print("done", flush=True)
    sys.stdin.readline()
    """
)


def test_a_stalled_recorder_puts_no_gap_into_a_run_on_sim_time(
    ros2_env: dict[str, str], tmp_path: Path
) -> None:
    """The recorder stopped (SIGSTOP) for 0.6 s of wall time while odometry is published every
    50 ms of simulated time, 5x faster than wall time: every message is in the bag at the
    simulated time it was sent (the /clock sent before it), 50 ms apart, no gap of the 3 s of
    simulated time that the stall lasted (what a time of receipt would show)."""
    bag = tmp_path / "runs" / "stalled"
    ticker = subprocess.Popen(
        [sys.executable, "-c", TICKING], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True
    )
    try:
        assert ticker.stdout is not None and ticker.stdin is not None
        assert ticker.stdout.readline().strip() == "ready"
        with Ros2Recorder(bag, ["/clock", "/tiago1/odom"], use_sim_time=True) as recorder:
            recorder.wait_subscribed(20.0, published=["/clock", "/tiago1/odom"])
            ticker.stdin.write("go\n")
            ticker.stdin.flush()
            assert ticker.stdout.readline().strip() == "publishing"
            assert recorder.process is not None
            time.sleep(0.25)
            os.kill(recorder.process.pid, signal.SIGSTOP)
            time.sleep(0.6)
            os.kill(recorder.process.pid, signal.SIGCONT)
            assert ticker.stdout.readline().strip() == "done"
            time.sleep(0.5)
            recorder.stop()
    finally:
        ticker.kill()
        ticker.wait()
    odometry = read_bag(bag)["/tiago1/odom"]
    assert len(odometry) == 100
    stamps = [stamp for stamp, _ in odometry]
    sent = [m.header.stamp.sec * 1_000_000_000 + m.header.stamp.nanosec for _, m in odometry]
    assert stamps == sent  # each at the /clock sent just before it: the time it was published
    assert set(np.diff(stamps)) == {50_000_000}
