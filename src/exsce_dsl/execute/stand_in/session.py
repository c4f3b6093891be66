"""The stand-in robot on a live ROS 1 graph: its node started, answered and stopped.

:func:`start_stand_in` sets ``/use_sim_time`` on the master, starts the stand-in node
(``execute/ros1/nodes/stand_in_node.py``, in rospy's Python) with the robots standing at their
start poses, waits until every robot's ``move_base`` action server is up, and answers the node's
goals with legs (:mod:`.legs`) on a thread of its own until the block ends, when the node is
stopped.  The node publishes ``/clock``, ``speed_up`` times faster than wall time (slower when it
cannot keep up: :meth:`StandIn.stats` says how fast it ran).
"""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from queue import Empty, Queue
from typing import Any

from exsce_dsl.errors import ExsceError, RosGraphError
from exsce_dsl.execute.ros1.channel import Message, NodeChannel
from exsce_dsl.execute.ros1.graph import Master
from exsce_dsl.execute.stand_in.legs import Fleet
from exsce_dsl.maps.planning import planning_grid
from exsce_dsl.model import Scenario
from exsce_dsl.model.metrics import expand_topic
from exsce_dsl.sim.faults import Fault

NODE = "/exsce_stand_in"
"""The node's name on the graph."""
STARTUP_TIMEOUT = 60.0
"""Seconds the node may take to come up with every action server."""


@dataclass(frozen=True)
class GoalEnd:
    """A goal the stand-in ended: ``succeeded``, ``aborted`` or ``canceled`` (a cancel, or a new
    goal that preempted it), at ``time`` simulated seconds."""

    robot: str
    goal: str
    outcome: str
    time: float


@dataclass(frozen=True)
class Stats:
    """How far the node got: simulated and wall seconds since it started, messages per topic."""

    sim_time: float
    wall_time: float
    published: dict[str, int]

    @property
    def real_time_factor(self) -> float:
        return self.sim_time / self.wall_time if self.wall_time > 0 else 0.0


class StandIn:
    """A running stand-in: its robots' action servers are up on the master at ``master_uri``."""

    def __init__(self, fleet: Fleet, channel: NodeChannel, master_uri: str) -> None:
        self.fleet, self.channel, self.master_uri = fleet, channel, master_uri
        self.start = 0.0
        """Simulated seconds at which the node's clock started."""
        self.ended: list[GoalEnd] = []
        self._lock = threading.Lock()
        self._stats: Queue[Stats] = Queue()
        self._failure: BaseException | None = None
        self._closing = False
        self._reader: threading.Thread | None = None

    @property
    def actions(self) -> dict[str, str]:
        """Each robot's ``move_base`` action name."""
        return {name: expand_topic("/{ns}/move_base", r.namespace) for name, r in self.fleet.robots.items()}

    def goals_ended(self) -> list[GoalEnd]:
        with self._lock:
            return list(self.ended)

    def stats(self, timeout: float = 10.0) -> Stats:
        """Ask the node how far it got."""
        self.check()
        self.channel.send({"command": "stats"})
        try:
            return self._stats.get(timeout=timeout)
        except Empty:
            self.check()
            raise RosGraphError(f"the stand-in node did not tell its figures within {timeout:g} s") from None

    def check(self) -> None:
        """Raise what stopped the stand-in, if something did."""
        if self._failure is not None:
            if isinstance(self._failure, ExsceError):
                raise self._failure
            raise RosGraphError(f"the stand-in failed: {type(self._failure).__name__}: {self._failure}")

    def wait(self, timeout: float | None = None) -> None:
        """Serve until the node ends (an error saying why) or ``timeout`` seconds have passed."""
        deadline = None if timeout is None else time.monotonic() + timeout
        while self._reader is not None and self._reader.is_alive():
            left = None if deadline is None else deadline - time.monotonic()
            if left is not None and left <= 0:
                return
            self._reader.join(0.5 if left is None else min(0.5, left))
        self.check()

    # -- the node's events, on the reader thread --------------------------------------------

    def serve(self) -> None:
        self._reader = threading.Thread(target=self._serve, name="stand-in", daemon=True)
        self._reader.start()

    def _serve(self) -> None:
        try:
            while True:
                message = self.channel.receive(None)
                if message is not None:
                    self._answer(message)
        except BaseException as e:  # noqa: BLE001  # kept for check(); the node is gone
            if not self._closing:
                self._failure = e

    def _answer(self, message: Message) -> None:
        event = message.get("event")
        if event == "goal":
            leg = self.fleet.leg(
                str(message["robot"]),
                str(message["goal"]),
                float(message["x"]),
                float(message["y"]),
                float(message["yaw"]),
                float(message["time"]),
            )
            self.channel.send(leg.command())
        elif event == "stopped":
            self.fleet.stopped(str(message["robot"]), str(message["goal"]), int(message["sample"]))
            self._ended(message, "canceled")
        elif event == "finished":
            self._ended(message, str(message["outcome"]))
        elif event == "stats":
            published = {str(k): int(v) for k, v in dict(message["published"]).items()}
            self._stats.put(Stats(float(message["sim_time"]), float(message["wall_time"]), published))

    def _ended(self, message: Message, outcome: str) -> None:
        with self._lock:
            self.ended.append(
                GoalEnd(str(message["robot"]), str(message["goal"]), outcome, float(message["time"]))
            )

    def close(self) -> None:
        self._closing = True
        self.channel.close()
        if self._reader is not None:
            self._reader.join(5.0)


DEFAULT_SPEED_UP = 5.0
"""How many times faster than wall time simulated time runs by default (``execute``,
``stand-in`` and ``explore --executor ros1`` alike).  ``rosbag record`` stamps a topic without
a header (``cmd_vel``) when it receives it, on the simulated clock: a recorder kept off a core
for 50 ms shows a gap of speed-up × 50 ms, and a gap over 0.5 s makes the run inconclusive.  At
10 (8.9x reached on a loaded 2-core machine, bench/execute.py) a test suite beside it gave gaps
of 0.53-0.77 s; at 5 the live demo passes with two busy loops on both cores.  At 20 the
recorder lost messages (it queues 100 per topic)."""


@contextmanager
def start_stand_in(
    scenario: Scenario,
    master_uri: str,
    *,
    seed: int = 0,
    faults: Sequence[Fault] = (),
    speed_up: float = DEFAULT_SPEED_UP,
    log_dir: Path,
    run: int = 0,
) -> Iterator[StandIn]:
    """The stand-in robots of ``scenario`` on the master at ``master_uri``, up when the block
    starts, stopped when it ends; the node's log in ``log_dir``.  ``seed`` and ``run``: the
    robots drive as in run ``run`` of ``exscec simulate --seed SEED`` (their speed limits)."""
    if not speed_up > 0:
        raise ExsceError(f"the stand-in's speed-up must be above 0, not {speed_up:g}")
    fleet = Fleet(scenario, planning_grid(scenario), seed, tuple(faults), run=run)
    master = Master(master_uri)
    master.wait(10.0)
    master.set_param("/use_sim_time", True)  # before the node starts: it reads it at its start
    log_dir.mkdir(parents=True, exist_ok=True)
    channel = NodeChannel("stand_in", [], master_uri, log_dir / f"stand_in-{run}.log", log_dir / "ros")
    stand_in = StandIn(fleet, channel, master_uri)
    try:
        channel.send(_setup(fleet, speed_up))
        for leg in fleet.start_legs():
            channel.send(leg.command())
        ready = channel.expect("ready", STARTUP_TIMEOUT)
        stand_in.start = float(ready.get("start", 0.0))
        _wait_for_servers(master, stand_in, STARTUP_TIMEOUT)
        stand_in.serve()
        yield stand_in
        stand_in.check()
    finally:
        stand_in.close()


def _setup(fleet: Fleet, speed_up: float) -> dict[str, Any]:
    laser = fleet.laser
    return {
        "command": "setup",
        "speed_up": speed_up,
        "robots": [{"name": r.name, "ns": r.namespace} for r in fleet.robots.values()],
        "laser": {
            "angle_min": laser.angle_min,
            "angle_max": laser.angle_max,
            "angle_increment": laser.angle_increment,
            "range_min": laser.range_min,
            "range_max": laser.range_max,
        },
    }


def _wait_for_servers(master: Master, stand_in: StandIn, timeout: float) -> None:
    """Until the master lists the node as the publisher of every robot's action result."""
    deadline = time.monotonic() + timeout
    wanted = {f"{action}/result" for action in stand_in.actions.values()}
    while True:
        publishers = master.publishers()
        missing = sorted(t for t in wanted if NODE not in publishers.get(t, set()))
        if not missing:
            return
        if time.monotonic() > deadline:
            raise RosGraphError(f"the stand-in's action servers did not come up: {', '.join(missing)}")
        time.sleep(0.1)
