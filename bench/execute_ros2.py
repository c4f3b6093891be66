"""The ROS 2 half of ``bench/execute.py --ros2``: scenario_c executed on a live ROS 2 graph against
exsce's Nav2 stand-in, as ``exscec execute SPEC --ros2 --stand-in --speed-up X`` runs it
(``execute_runs_ros2`` with a stand-in per run, in this process; the recorder a process of its own),
in a DDS domain of its own on loopback.  The same three figures as the ROS 1 half:

1. **Real-time factor** over the mission: simulated seconds (the mission's own record, on
   ``/clock``) / wall seconds from the first goal sent to the last result taken.
2. **Goal dispatch latency**: wall time from a goal's result arriving in this process (rclpy's
   future callback, in the dispatcher's spin) to the same robot's next goal being sent.
3. **Messages published versus recorded** per stand-in topic: published, the stand-in's own
   counts, taken when the recorder said it was subscribed to every published topic and when the
   mission ended (as the PROV is published); recorded, the bag read by rosbags (an independent
   path), the stamped topics' messages whose header stamp falls in that window of samples (exact),
   ``cmd_vel`` (no stamp) one-sided: every one published in the window must be in the bag.

Timestamps are taken by wrapping the navigator's ``send`` and ``_end`` and the dispatcher node's
``publish`` for the benchmark's runs only; nothing else changes.
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Iterator
from contextlib import AbstractContextManager, contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from rosbags.highlevel import AnyReader

from exsce_dsl.execute.ros1.session import ExecutedRun, Options
from exsce_dsl.execute.ros2 import live
from exsce_dsl.execute.ros2.dispatcher_node import Ros2DispatcherNode
from exsce_dsl.execute.ros2.recorder import Ros2Recorder
from exsce_dsl.execute.ros2.session import execute_runs_ros2
from exsce_dsl.execute.ros2.stand_in import Ros2StandIn
from exsce_dsl.model import Pose, Scenario

EVERY = {"odom": 1, "tf": 1, "amcl_pose": 25, "scan": 5}
"""The stamped topics: the stand-in publishes each at every such sample."""
SAMPLE_NS = 20_000_000


@dataclass
class Ros2Figures:
    speed_up: float
    index: int
    mission_sim: float = 0.0
    mission_wall: float = 0.0
    latencies: list[float] = field(default_factory=list)
    published: dict[str, int] = field(default_factory=dict)
    recorded: dict[str, int] = field(default_factory=dict)
    window: tuple[int, int] = (0, 0)
    start_ns: int = 0
    goals: int = 0
    aborted: int = 0

    @property
    def rtf(self) -> float:
        return self.mission_sim / self.mission_wall if self.mission_wall > 0 else math.nan


class _Probe:
    def __init__(self) -> None:
        self.run: Ros2Figures | None = None
        self.stand_in: Ros2StandIn | None = None
        self.first_send: float | None = None
        self.last_end: float | None = None
        self.ended: dict[str, float] = {}
        self.counts: list[tuple[int, dict[str, int]]] = []


PROBE = _Probe()


def _count() -> None:
    stand_in = PROBE.stand_in
    assert stand_in is not None
    with stand_in.lock:
        PROBE.counts.append((stand_in.published, dict(stand_in.counts)))


@contextmanager
def _measuring() -> Iterator[None]:
    """The wrappers in place for the block."""
    send, end = live.Ros2Navigator.send, live.Ros2Navigator._end
    publish, subscribed = Ros2DispatcherNode.publish, Ros2Recorder.wait_subscribed

    def timed_send(self: live.Ros2Navigator, goal: int, robot: str, pose: Pose) -> None:
        now = time.perf_counter()
        PROBE.first_send = PROBE.first_send or now
        if robot in PROBE.ended and PROBE.run is not None:
            PROBE.run.latencies.append(now - PROBE.ended.pop(robot))
        send(self, goal, robot, pose)
        self._robot_of = {**getattr(self, "_robot_of", {}), goal: robot}  # type: ignore[attr-defined]

    def timed_end(self: live.Ros2Navigator, goal: int, outcome: Any) -> None:
        now = time.perf_counter()
        PROBE.last_end = now
        robot = getattr(self, "_robot_of", {}).get(goal)
        if robot is not None:
            PROBE.ended[robot] = now
        end(self, goal, outcome)

    def counted_publish(self: Ros2DispatcherNode, text: str) -> int:
        _count()
        return publish(self, text)

    def counted_subscribed(self: Ros2Recorder, timeout: float = 10.0, published: Any = ()) -> None:
        subscribed(self, timeout, published)
        _count()

    live.Ros2Navigator.send, live.Ros2Navigator._end = timed_send, timed_end  # type: ignore[method-assign]
    Ros2DispatcherNode.publish = counted_publish  # type: ignore[method-assign]
    Ros2Recorder.wait_subscribed = counted_subscribed  # type: ignore[method-assign]
    try:
        yield
    finally:
        live.Ros2Navigator.send, live.Ros2Navigator._end = send, end  # type: ignore[method-assign]
        Ros2DispatcherNode.publish = publish  # type: ignore[method-assign]
        Ros2Recorder.wait_subscribed = subscribed  # type: ignore[method-assign]


def execute_ros2_speed_up(
    scenario: Scenario, folder: Path, runs: int, speed_up: float, seed: int, domain: int
) -> list[Ros2Figures]:
    """``runs`` runs at ``speed_up`` on the ROS 2 domain ``domain``, measured."""
    os.environ["ROS_DOMAIN_ID"] = str(domain)
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    figures: list[Ros2Figures] = []

    def around_run(run: int) -> AbstractContextManager[object]:
        figures.append(Ros2Figures(speed_up, run))
        PROBE.run, PROBE.first_send, PROBE.last_end, PROBE.ended, PROBE.counts = (
            figures[-1],
            None,
            None,
            {},
            [],
        )
        PROBE.stand_in = Ros2StandIn(scenario, seed=seed, speed_up=speed_up, run=run)
        return PROBE.stand_in

    out = folder / f"ros2-x{speed_up:g}"
    with _measuring():
        done = _runs(scenario, out, runs, around_run, figures)
    for run, executed in zip(figures, done, strict=True):
        _count_messages(run, executed)
    return figures


def _runs(
    scenario: Scenario, out: Path, runs: int, around_run: Any, figures: list[Ros2Figures]
) -> list[ExecutedRun]:
    done: list[ExecutedRun] = []

    def one(run: int) -> AbstractContextManager[object]:
        return _after(around_run(run), run)

    @contextmanager
    def _after(stand_in: Any, run: int) -> Iterator[None]:
        with stand_in:
            yield
            current = figures[run]
            current.start_ns = PROBE.stand_in.start_ns if PROBE.stand_in is not None else 0
            if PROBE.first_send is not None and PROBE.last_end is not None:
                current.mission_wall = PROBE.last_end - PROBE.first_send
            (first, before), (last, after) = PROBE.counts[0], PROBE.counts[-1]
            current.window = (first, last)
            current.published = {t: after.get(t, 0) - before.get(t, 0) for t in after if t != "/clock"}

    for run in range(runs):
        done += execute_runs_ros2(scenario, out, 1, Options(), None, lambda _, r=run: one(r), True)
    for run, executed in zip(figures, done, strict=True):
        records = executed.mission.records
        run.mission_sim = max(r.end for r in records) - min(r.start for r in records)
        run.goals = len(records)
        run.aborted = sum(1 for r in records if r.outcome.value != "succeeded")
    return done


def _count_messages(run: Ros2Figures, executed: ExecutedRun) -> None:
    """The bag's messages per stand-in topic: the stamped ones in the counted window of samples."""
    low = run.start_ns + run.window[0] * SAMPLE_NS
    high = run.start_ns + run.window[1] * SAMPLE_NS
    counted = {t: 0 for t in run.published}
    with AnyReader([executed.files.bag]) as reader:
        wanted = [c for c in reader.connections if c.topic in counted]
        for connection, _, raw in reader.messages(connections=wanted):
            name = connection.topic.rsplit("/", 1)[1]
            if name == "cmd_vel":
                counted[connection.topic] += 1
                continue
            if name not in EVERY:
                continue
            message = reader.deserialize(raw, connection.msgtype)
            header = message.transforms[0].header if name == "tf" else message.header
            stamp = header.stamp.sec * 1_000_000_000 + header.stamp.nanosec
            if low < stamp <= high:
                counted[connection.topic] += 1
    run.recorded = counted


def lost(run: Ros2Figures) -> int:
    """Messages published in the window and not in the bag (cmd_vel: one-sided)."""
    return sum(max(0, n - run.recorded.get(t, 0)) for t, n in run.published.items() if _counted(t))


def _counted(topic: str) -> bool:
    return topic.rsplit("/", 1)[1] in {*EVERY, "cmd_vel"}


def report_ros2(
    figures: list[Ros2Figures], ros1_rtf: float, ros1_latencies: list[float]
) -> list[tuple[str, bool]]:
    """Print the ROS 2 figures beside the ROS 1 ones of the same run; the targets and whether met."""
    from statistics import median

    print("\nROS 2 (Jazzy wheels, Fast DDS on loopback): exscec execute --ros2 --stand-in")
    print("  speed-up  run  mission sim s  wall s  RTF    goals (not succeeded)")
    for r in figures:
        print(
            f"  {r.speed_up:>8g}  {r.index:>3}  {r.mission_sim:>13.1f}  {r.mission_wall:>6.1f}  "
            f"{r.rtf:>5.1f}x  {r.goals} ({r.aborted})"
        )
    latencies = sorted(x for r in figures for x in r.latencies)
    p50, p95 = _quantile(latencies, 0.5), _quantile(latencies, 0.95)
    p50_1, p95_1 = _quantile(sorted(ros1_latencies), 0.5), _quantile(sorted(ros1_latencies), 0.95)
    print(
        f"  goal dispatch latency: p50 {p50 * 1e3:.1f} ms, p95 {p95 * 1e3:.1f} ms (ROS 1: p50 "
        f"{p50_1 * 1e3:.1f} ms, p95 {p95_1 * 1e3:.1f} ms)"
    )
    print("  topic                  published  recorded  lost   (speed-up, run)")
    for r in figures:
        for topic in sorted(t for t in r.published if _counted(t)):
            published, recorded = r.published[topic], r.recorded.get(topic, 0)
            print(
                f"  {topic:<22} {published:>9}  {recorded:>8}  {max(0, published - recorded):>4}   "
                f"({r.speed_up:g}, {r.index})"
            )
    checked = []
    for speed_up in sorted({r.speed_up for r in figures}):
        rtfs = [r.rtf for r in figures if r.speed_up == speed_up]
        print(f"  speed-up {speed_up:g}: RTF min {min(rtfs):.1f}x, median {median(rtfs):.1f}x")
        if speed_up >= 10:
            checked.append(
                (
                    f"ROS 2: RTF >= 10x at speed-up {speed_up:g} (median {median(rtfs):.1f}x)",
                    median(rtfs) >= 10,
                )
            )
    print(f"  (ROS 1 in this run: RTF median {ros1_rtf:.1f}x over all its runs)")
    return [
        *checked,
        (f"ROS 2: dispatch latency p95 < 50 ms ({p95 * 1e3:.1f} ms)", p95 < 0.050),
        ("ROS 2: no message lost", sum(lost(r) for r in figures) == 0),
    ]


def _quantile(values: list[float], q: float) -> float:
    if not values:
        return math.nan
    return values[min(len(values) - 1, int(q * len(values)))]
