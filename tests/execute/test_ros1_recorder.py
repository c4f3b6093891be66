"""The recorder on a real roscore: the real ``rosbag record`` records exactly the listed topics
that are published, every message, from the moment ``start`` returns; ``stop`` closes the bag
(read back with rosbags, not with exsce), also while messages flow; a ``record`` that cannot close
is killed and said so, and leaves no ``.active`` file; what ``record`` cannot be given is refused
before it runs."""

from __future__ import annotations

import os
import signal
from collections.abc import Iterator
from pathlib import Path

import pytest
from rosbags.highlevel import AnyReader

from exsce_dsl.errors import RosGraphError
from exsce_dsl.execute.ros1 import recorder as recorder_module
from exsce_dsl.execute.ros1.graph import free_port
from exsce_dsl.execute.ros1.recorder import Recorder

from tests.support.ros1_graph import Graph, Process, ros1_graph

FIXTURES = Path(__file__).resolve().parents[1] / "fixtures" / "ros1"
PUBLISHER = FIXTURES / "counting_publisher.py"
CLOCK = FIXTURES / "clock_publisher.py"
GO = "/exsce_test/go"
RECORDED = ["/exsce_test/a", "/exsce_test/b", "/exsce_test/silent"]
"""Listed: two topics the publisher publishes, one nobody publishes."""
PUBLISHED = ["/exsce_test/a", "/exsce_test/b", "/exsce_test/unlisted"]


@pytest.fixture
def graph(tmp_path: Path) -> Iterator[Graph]:
    with ros1_graph(tmp_path / "ros", sim_time=False) as running:
        yield running


@pytest.fixture
def recorders() -> Iterator[list[Recorder]]:
    """The recorders a test starts: killed after it if still running, also when it fails."""
    started: list[Recorder] = []
    yield started
    for recorder in started:
        if recorder.process is not None and recorder.process.poll() is None:
            os.killpg(recorder.process.pid, signal.SIGKILL)
            recorder.process.wait(5)


def publisher(graph: Graph, count: int, hz: float) -> Process:
    """The counting publisher, up with its topics advertised at the master, not publishing yet."""
    process = graph.run_python("publisher", PUBLISHER, str(count), str(hz), GO, *PUBLISHED)
    graph.wait_until(
        lambda: all(t in graph.system_state().publishers for t in PUBLISHED),
        "the publisher's topics",
        30,
        [process],
    )
    return process


def numbers(bag: Path) -> dict[str, list[int]]:
    """Topic → the ``data`` of its messages in the bag, in order, deserialised by rosbags."""
    found: dict[str, list[int]] = {}
    with AnyReader([bag]) as reader:
        for connection in reader.connections:
            found.setdefault(connection.topic, [])
        for connection, _, raw in reader.messages():
            found[connection.topic].append(reader.deserialize(raw, connection.msgtype).data)
    return found


def test_record_holds_exactly_the_listed_topics_that_were_published_every_message(
    graph: Graph, tmp_path: Path, recorders: list[Recorder]
) -> None:
    source = publisher(graph, count=60, hz=200)
    bag = tmp_path / "out" / "run.bag"
    recorder = Recorder(graph.uri, RECORDED, bag, tmp_path / "record.log")
    recorders.append(recorder)
    recorder.start(timeout=30)
    subscribed = {t for t, nodes in graph.system_state().subscribers.items() if recorder.node in nodes}
    assert subscribed == set(RECORDED)
    graph.set_param(GO, True)  # publishing starts only now: every message must be in the bag
    graph.wait_until(lambda: "published 60" in source.output(), "the publisher to finish", 30, [source])
    assert recorder.stop(timeout=30) == bag
    assert not bag.with_name("run.bag.active").exists()
    assert sorted(p.name for p in bag.parent.iterdir()) == ["run.bag"]
    assert numbers(bag) == {"/exsce_test/a": list(range(60)), "/exsce_test/b": list(range(60))}
    with AnyReader([bag]) as reader:
        assert {c.msgtype for c in reader.connections} == {"std_msgs/msg/UInt32"}


def test_a_bag_stopped_while_messages_flow_is_whole(
    graph: Graph, tmp_path: Path, recorders: list[Recorder]
) -> None:
    publisher(graph, count=0, hz=500)
    bag = tmp_path / "run.bag"
    with Recorder(graph.uri, RECORDED, bag, tmp_path / "record.log") as recorder:
        recorders.append(recorder)
        recorder.start(timeout=30)
        graph.set_param(GO, True)
        graph.wait_until(
            lambda: (bag.parent / "run.bag.active").stat().st_size > 20_000, "messages recorded", 30
        )
    assert not recorder.running()
    assert not (tmp_path / "run.bag.active").exists()
    recorded = numbers(bag)  # opens: the index was written
    assert set(recorded) == {"/exsce_test/a", "/exsce_test/b"}
    for topic, data in recorded.items():
        assert len(data) > 100, topic
        assert data == list(range(len(data))), f"{topic}: a gap or a reordering in what was recorded"


def test_a_record_that_does_not_close_is_killed_and_leaves_no_active_file(
    graph: Graph, tmp_path: Path, recorders: list[Recorder]
) -> None:
    bag = tmp_path / "run.bag"
    recorder = Recorder(graph.uri, RECORDED, bag, tmp_path / "record.log")
    recorders.append(recorder)
    recorder.start(timeout=30)
    assert recorder.process is not None
    graph.wait_until(recorder.active.exists, "the bag to be opened", 10)
    os.kill(recorder.process.pid, signal.SIGSTOP)  # it cannot act on SIGINT now
    with pytest.raises(
        RosGraphError, match=r"did not close run\.bag within 1 s .* killed: the recording is incomplete"
    ):
        recorder.stop(timeout=1)
    assert recorder.process.poll() is not None
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith("run.bag")) == []


def test_no_master_is_an_error_and_record_is_not_left_running(
    tmp_path: Path, recorders: list[Recorder]
) -> None:
    recorder = Recorder(f"http://127.0.0.1:{free_port()}", RECORDED, tmp_path / "run.bag", tmp_path / "r.log")
    recorders.append(recorder)
    with pytest.raises(RosGraphError, match="no ROS master answers"):
        recorder.start(timeout=2)
    assert recorder.process is not None and recorder.process.poll() is not None
    assert not (tmp_path / "run.bag.active").exists()


@pytest.mark.parametrize(
    ("topics", "bag", "said"),
    [
        (["relative"], "run.bag", "cannot subscribe to 'relative'"),
        (["/a", "/x:=/y"], "run.bag", "cannot subscribe to '/x:=/y'"),
        (["/-O"], "run.bag", "cannot subscribe to '/-O'"),
        (["/a"], "run.mcap", r"writes a file named \*\.bag"),
        (["/a"], "a:=b.bag", "without ':='"),
        ([], "run.bag", "no topic"),
    ],
)
def test_what_record_cannot_be_given_is_refused_before_it_runs(
    tmp_path: Path, topics: list[str], bag: str, said: str
) -> None:
    with pytest.raises(RosGraphError, match=said):
        Recorder("http://127.0.0.1:1", topics, tmp_path / bag, tmp_path / "r.log")


def test_a_missing_record_program_says_what_to_install(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, recorders: list[Recorder]
) -> None:
    monkeypatch.setattr(recorder_module, "RECORD_PROGRAMS", (tmp_path / "lib" / "rosbag" / "record",))
    recorder = Recorder("http://127.0.0.1:1", RECORDED, tmp_path / "run.bag", tmp_path / "r.log")
    recorders.append(recorder)
    with pytest.raises(RosGraphError, match=r"rosbag's record program is missing .*scripts/install-ros1"):
        recorder.start(timeout=1)
    assert recorder.process is None and not list(tmp_path.glob("run.bag*"))


def test_on_simulated_time_recording_starts_with_the_clock_and_keeps_every_message(
    tmp_path: Path, recorders: list[Recorder]
) -> None:
    with ros1_graph(tmp_path / "ros", sim_time=True) as graph:
        graph.run_python("clock", CLOCK, "1000", "100")
        source = publisher(graph, count=40, hz=200)
        bag = tmp_path / "run.bag"
        with Recorder(graph.uri, [*RECORDED, "/clock"], bag, tmp_path / "record.log") as recorder:
            recorders.append(recorder)
            recorder.start(timeout=30)
            graph.set_param(GO, True)
            graph.wait_until(
                lambda: "published 40" in source.output(), "the publisher to finish", 30, [source]
            )
    recorded = numbers_and_times(bag)
    for topic in ("/exsce_test/a", "/exsce_test/b"):
        data, times = recorded[topic]
        assert data == list(range(40)), topic
        assert all(1000 <= t < 1100 for t in times), f"{topic}: log time is not the simulated clock"


def test_on_simulated_time_without_a_clock_start_says_so(tmp_path: Path, recorders: list[Recorder]) -> None:
    with ros1_graph(tmp_path / "ros", sim_time=True) as graph:
        recorder = Recorder(graph.uri, RECORDED, tmp_path / "run.bag", tmp_path / "record.log")
        recorders.append(recorder)
        with pytest.raises(
            RosGraphError, match=r"has not opened the bag.*/use_sim_time is set and nothing publishes /clock"
        ):
            recorder.start(timeout=3)
        assert recorder.process is not None and recorder.process.poll() is not None
        assert not list(tmp_path.glob("run.bag*"))


def numbers_and_times(bag: Path) -> dict[str, tuple[list[int], list[float]]]:
    """Topic → the ``data`` of its UInt32 messages and their log times (s), read by rosbags."""
    found: dict[str, tuple[list[int], list[float]]] = {}
    with AnyReader([bag]) as reader:
        for connection, stamp, raw in reader.messages():
            if connection.msgtype == "std_msgs/msg/UInt32":
                data, times = found.setdefault(connection.topic, ([], []))
                data.append(reader.deserialize(raw, connection.msgtype).data)
                times.append(stamp / 1e9)
    return found
